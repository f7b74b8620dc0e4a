// `nhdyn view` and `nhdyn simulate --html` in a real browser (headless chromium driven by
// viewer/test/browser_test.js, puppeteer-core): the page of a shipped scene loads with no
// console error and fetches nothing; the world poses of the robot's links that the page
// computes (three.js and urdf-loader from the URDF text) at three times equal nhdyn's forward
// kinematics of the run's q at those times (tree_kinematics, 1e-9 m); screenshots at two times
// differ and the base's trace is drawn; a URDF with a missing mesh loads and shows the notice;
// a DH preset drawn from its frames; the page of every shipped scene loads without an error.
// The page's size and load time are printed (measured, not asserted: speed targets belong to
// benchmarks).
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nhdyn/io/json.hpp>
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/kinematics/tree.hpp>
#include <sstream>

#include "../support/scratch_dir.hpp"

namespace fs = std::filesystem;
using nhdyn::io::json;

namespace {
struct run_result {
  int status = -1;
  std::string out, err;
};
/// Runs a shell command line, its output in files of `dir`.
run_result shell(const std::string& cmd, const fs::path& dir, const std::string& tag) {
  const std::string out = (dir / (tag + ".out")).string(), err = (dir / (tag + ".err")).string();
  const int raw = std::system((cmd + " > '" + out + "' 2> '" + err + "' < /dev/null").c_str());
  REQUIRE(WIFEXITED(raw));
  run_result r;
  r.status = WEXITSTATUS(raw);
  std::ifstream fo(out), fe(err);
  std::ostringstream so, se;
  so << fo.rdbuf();
  se << fe.rdbuf();
  r.out = so.str(), r.err = se.str();
  return r;
}
fs::path scratch(const std::string& name) {
  const auto d = nhdyn_test::scratch_dir("view") / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
const std::string tool = NHDYN_TOOL_PATH;
const std::string viewer = std::string(NHDYN_SOURCE_DIR) + "/viewer";
std::string browser(const std::string& args) {
  return std::string("CHROMIUM='") + NHDYN_CHROMIUM + "' '" + NHDYN_NODE + "' '" + viewer + "/test/browser_test.js' " + args;
}
/// The CSV's row k (0-based, after the header) as numbers.
std::vector<double> csv_row(const fs::path& csv, int k) {
  std::ifstream f(csv);
  std::string line;
  for (int i = 0; i <= k + 1; ++i) REQUIRE(std::getline(f, line));
  std::vector<double> v;
  std::stringstream s(line);
  for (std::string c; std::getline(s, c, ',');) v.push_back(std::stod(c));
  return v;
}
}  // namespace

TEST_CASE("view: the mobile manipulator's run in headless chromium: links where nhdyn's kinematics puts them") {
  const auto dir = scratch("circle");
  const auto sim = shell("'" + tool + "' simulate mobile-manipulator-circle --out '" + dir.string() + "' --no-plots --html", dir, "simulate");
  INFO(sim.out << sim.err);
  REQUIRE(sim.status == 0);
  const fs::path page = dir / "view.html";
  REQUIRE(fs::is_regular_file(page));
  CHECK(sim.out.find("page: " + page.string()) != std::string::npos);
  const auto size = fs::file_size(page);
  std::cout << "view: the 20 s, 100 Hz run of the 19-coordinate mobile manipulator: a page of " << double(size) / 1e6 << " MB\n";
  const auto b = shell(browser("'" + page.string() + "' --out '" + (dir / "browser").string() + "'"), dir, "browser");
  INFO(b.out << b.err);
  std::cout << b.out;  // the checks, the size and the load time
  REQUIRE(b.status == 0);
  CHECK(b.out.find("not ok") == std::string::npos);

  // the page's link poses at three times = nhdyn's forward kinematics of the run's q there
  std::ifstream pf(dir / "browser" / "poses.json");
  const json P = json::parse(pf);
  const auto robot = nhdyn::io::load_robot_file(std::string(NHDYN_SOURCE_DIR) + "/examples/robots/mobile_manipulator.json");
  const nhdyn::tree_kinematics<double> kin(robot.model);
  const auto joints = robot.model.joint_names();
  REQUIRE(P["joint_names"].get<std::vector<std::string>>() == joints);
  REQUIRE(P["samples"].size() == 3);
  int links = 0;
  double worst = 0, worst_q = 0;
  for (const auto& s : P["samples"]) {
    const std::vector<double> qv = s["q"].get<std::vector<double>>();
    const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(qv.data(), Eigen::Index(qv.size()));
    // the q the page used is the run's at that sample (the CSV's row, as written)
    const auto row = csv_row(dir / "mobile-manipulator-circle.csv", s["index"].get<int>());
    CHECK(row[0] == s["t"].get<double>());
    for (Eigen::Index i = 0; i < q.size(); ++i) worst_q = std::max(worst_q, std::abs(q(i) - row[std::size_t(i + 1)]));
    for (const auto& [link, m] : s["poses"].items()) {
      const auto X = kin.frame(q, link);  // a body, a merged (fixed) link, or the root
      for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(m[std::size_t(4 * c + r)].get<double>() - X.R(r, c)));
        worst = std::max(worst, std::abs(m[std::size_t(12 + c)].get<double>() - X.p(c)));
      }
      ++links;
    }
  }
  INFO(links << " link poses, largest difference " << worst);
  CHECK(links >= 3 * 20);
  CHECK(worst_q == 0);
  CHECK(worst <= 1e-9);
  std::cout << "view: " << links << " link poses at 3 times, largest difference from nhdyn's kinematics " << worst << '\n';
}

TEST_CASE("view: a URDF whose mesh is missing loads with a notice; a pose of a robot file; errors name the culprit") {
  const auto dir = scratch("pose");
  const std::string urdf = viewer + "/test/fixtures/nhdyn_viewer_test/mesh_test.urdf";
  const auto v = shell("'" + tool + "' view --model '" + urdf + "' --out '" + (dir / "mesh.html").string() + "'", dir, "view");
  INFO(v.out << v.err);
  REQUIRE(v.status == 0);
  CHECK(v.err.find("mesh not found, the page draws a stand-in") != std::string::npos);
  const auto b = shell(browser("--missing-mesh '" + (dir / "mesh.html").string() + "' --out '" + (dir / "browser").string() + "'"), dir, "browser");
  INFO(b.out << b.err);
  CHECK(b.status == 0);
  // a pose of a robot file, q given
  const std::string mecanum = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/mecanum_arm.json";
  const auto m = shell("'" + tool + "' view --model '" + mecanum + "' --q 0.5,0.2,0.3,0,0,0,0,0.4,0.3,-0.2,0.1,0 --out '" +
                           (dir / "mecanum.html").string() + "'", dir, "mecanum");
  INFO(m.out << m.err);
  CHECK(m.status == 0);
  CHECK(fs::is_regular_file(dir / "mecanum.html"));
  // errors
  CHECK(shell("'" + tool + "' view", dir, "e1").status == 2);
  const auto q = shell("'" + tool + "' view --model '" + mecanum + "' --q 1,2", dir, "e3");
  CHECK(q.status == 2);
  CHECK(q.err.find("--q has 2 values") != std::string::npos);
  const auto none = shell("'" + tool + "' view '" + (dir / "no_such_folder").string() + "'", dir, "e4");
  CHECK(none.status == 1);
  CHECK(none.err.find("no_such_folder") != std::string::npos);
}

TEST_CASE("view: a DH preset drawn as rods between its frames: each body where nhdyn's kinematics puts it") {
  const auto dir = scratch("dh");
  // puma560 with joint 6 held (the page sets it from the page's "locked"), q of the other five given
  const auto v = shell("'" + tool + "' view --model puma560 --lock joint6=0.7 --q 0.3,-0.5,0.4,0.2,0.6 --out '" +
                           (dir / "puma.html").string() + "'", dir, "view");
  INFO(v.out << v.err);
  REQUIRE(v.status == 0);
  const auto b = shell(browser("'" + (dir / "puma.html").string() + "' --out '" + (dir / "browser").string() + "'"), dir, "browser");
  INFO(b.out << b.err);
  REQUIRE(b.status == 0);
  CHECK(b.out.find("not ok") == std::string::npos);
  std::ifstream pf(dir / "browser" / "poses.json");
  const json P = json::parse(pf);
  REQUIRE(P["joint_names"].get<std::vector<std::string>>() == std::vector<std::string>{"joint1", "joint2", "joint3", "joint4", "joint5"});
  // the full chain as a tree (as_tree: bodies link1..link6 in DH frames 1..6) at q6 = 0.7
  const auto t = nhdyn::as_tree(nhdyn::io::load("puma560").chain);
  const nhdyn::tree_kinematics<double> kin(t);
  Eigen::VectorXd q(6);
  q << 0.3, -0.5, 0.4, 0.2, 0.6, 0.7;
  int bodies = 0;
  double worst = 0;
  for (const auto& [link, m] : P["samples"][0]["poses"].items()) {
    if (link.ends_with("_joint_frame")) continue;  // the moved joint frames the rods hang from
    const auto X = kin.frame(q, link);
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(m[std::size_t(4 * c + r)].get<double>() - X.R(r, c)));
      worst = std::max(worst, std::abs(m[std::size_t(12 + c)].get<double>() - X.p(c)));
    }
    ++bodies;
  }
  INFO(bodies << " bodies, largest difference " << worst);
  CHECK(bodies == 7);  // base, link1..link6
  CHECK(worst <= 1e-9);
  std::cout << "view: puma560 drawn from its DH model, " << bodies << " body poses, largest difference from nhdyn's kinematics "
            << worst << '\n';
}

TEST_CASE("view: the page of each shipped scene loads in headless chromium with no console error") {
  // mobile-manipulator-circle is the first test case's; `paper` is the suite of the three
  // paper scenes; the Monte Carlo study runs 6 of its 1000 runs (a study file naming it)
  const auto dir = scratch("scenes");
  const fs::path mc = dir / "mc-6.json";
  std::ofstream(mc) << R"({"name": "mc-6", "study": {"base": "mobile-manipulator-circle", "set": {"output": {"step": 0.1}},
    "monte_carlo": {"runs": 6, "seed": 2026}, "factors": [
      {"name": "payload", "path": "/plant/mass_factor/arm_7_link", "distribution": {"uniform": [1.0, 2.0]}}]}})";
  const std::vector<std::string> scenes{"paper-circle", "paper-factorial", "paper-noise", "mecanum-sideways-circle",
                                        "puma560-line", "puma560-computed-torque", mc.string()};
  for (const auto& scene : scenes) {
    const std::string tag = fs::path(scene).stem().string();
    const auto out = dir / tag;
    const auto sim = shell("'" + tool + "' simulate '" + scene + "' --out '" + out.string() + "' --no-plots --html", dir, tag + "-sim");
    INFO(scene << ": " << sim.out << sim.err);
    REQUIRE(fs::is_regular_file(out / "view.html"));
    const auto b = shell(browser("'" + (out / "view.html").string() + "' --out '" + (out / "browser").string() + "'"), dir, tag + "-browser");
    INFO(b.out << b.err);
    CHECK(b.status == 0);
    CHECK(b.out.find("not ok") == std::string::npos);
    CHECK(b.out.find("ok - no console error and no page error") != std::string::npos);
    std::cout << "view: " << scene << ": " << fs::file_size(out / "view.html") / 1000 << " kB, "
              << b.out.substr(b.out.find("load: "), b.out.find('\n', b.out.find("load: ")) - b.out.find("load: ")) << '\n';
  }
}
