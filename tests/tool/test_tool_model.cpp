// `nhdyn model` and URDF models in the tool (`--model x.urdf`, `--strict`), driven as a user
// would. Expected torques come from the plain reference algorithm (dynamics/reference.hpp),
// not from the kernel the tool runs; expected names from the file itself.
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nhdyn/dynamics/reference.hpp>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/io/json.hpp>
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/io/urdf.hpp>
#include <random>
#include <sstream>

namespace fs = std::filesystem;
using nhdyn::io::json;
using Eigen::VectorXd;

namespace {

const std::string urdf_path = std::string(NHDYN_SOURCE_DIR) + "/tests/urdf/real_style.urdf";

struct run_result {
  int status = -1;
  std::vector<std::string> lines;
  std::string err;
};

run_result run_tool(const std::string& args, const std::string& input = "") {
  static int count = 0;
  const auto dir = fs::temp_directory_path() / ("nhdyn_test_tool_model_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto base = (dir / ("run" + std::to_string(++count))).string();
  std::ofstream(base + ".in", std::ios::binary) << input;
  const std::string cmd = std::string("'") + NHDYN_TOOL_PATH + "' " + args + " < '" + base + ".in' > '" + base +
                          ".out' 2> '" + base + ".err'";
  const int raw = std::system(cmd.c_str());
  REQUIRE(WIFEXITED(raw));
  run_result r;
  r.status = WEXITSTATUS(raw);
  std::ifstream out(base + ".out"), err(base + ".err");
  for (std::string l; std::getline(out, l);) r.lines.push_back(l);
  std::ostringstream e;
  e << err.rdbuf();
  r.err = e.str();
  return r;
}

std::string arr(const VectorXd& v) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + nhdyn::io::format_number(v(i));
  return s + "]";
}

VectorXd field(const std::string& line, const std::string& key) {
  INFO("output line: " << line);
  const json j = json::parse(line);
  REQUIRE(j.contains(key));
  VectorXd v(static_cast<Eigen::Index>(j[key].size()));
  for (std::size_t i = 0; i < j[key].size(); ++i) v(static_cast<Eigen::Index>(i)) = j[key][i].get<double>();
  return v;
}

}  // namespace

TEST_CASE("tool: nhdyn model describes DH models and URDF trees") {
  auto r = run_tool("model --model puma560");
  REQUIRE(r.status == 0);
  REQUIRE(r.lines.size() == 1);
  json j = json::parse(r.lines[0]);
  CHECK(j["name"] == "puma560");
  CHECK(j["dof"] == 6);
  CHECK(j["k"] == 0);
  CHECK(j["joints"].size() == 6);
  CHECK(j["eta"] == j["joints"]);
  CHECK(j["gravity"] == json::array({0, 0, -9.81}));

  r = run_tool("model --model paper5");
  REQUIRE(r.status == 0);
  j = json::parse(r.lines[0]);
  CHECK(j["k"] == 1);
  CHECK(j["eta"].size() == 4);  // v, then the heading joint's rate and the two arm joints
  CHECK(j["eta"][0] == "v");

  r = run_tool("model --model '" + urdf_path + "'");
  REQUIRE(r.status == 0);
  j = json::parse(r.lines[0]);
  CHECK(j["name"] == "real_style");
  CHECK(j["joints"] == json::array({"torso_lift_joint", "head_pan_joint", "head_tilt_joint", "shoulder_joint",
                                    "elbow_joint", "wrist_joint", "gripper_right_finger_joint",
                                    "gripper_left_finger_joint"}));
  // the file's two non-physical inertias: one warning each on stderr; --strict refuses
  CHECK(r.err.find("link 'antenna_link'") != std::string::npos);
  CHECK(r.err.find("link 'sensor_link'") != std::string::npos);
  r = run_tool("model --strict --model '" + urdf_path + "'");
  CHECK(r.status == 1);
  CHECK(r.err.find("antenna_link") != std::string::npos);
  CHECK(r.lines.empty());
}

TEST_CASE("tool: id and fd on a URDF equal the reference rne and invert each other") {
  std::vector<std::string> warnings;
  nhdyn::io::urdf_options o;
  o.warn = [&](const std::string& w) { warnings.push_back(w); };
  const auto t = nhdyn::io::load_urdf(urdf_path, o);
  const int n = t.dof();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<VectorXd> q, qd, qdd;
  std::string input;
  for (int k = 0; k < 10; ++k) {
    q.push_back(VectorXd::NullaryExpr(n, [&] { return u(rng); }));
    qd.push_back(VectorXd::NullaryExpr(n, [&] { return u(rng); }));
    qdd.push_back(VectorXd::NullaryExpr(n, [&] { return u(rng); }));
    input += R"({"q": )" + arr(q.back()) + R"(, "qd": )" + arr(qd.back()) + R"(, "qdd": )" + arr(qdd.back()) + "}\n";
  }
  const auto id = run_tool("id --model '" + urdf_path + "'", input);
  REQUIRE(id.status == 0);
  REQUIRE(id.lines.size() == 10);
  std::string fd_input;
  for (int k = 0; k < 10; ++k) {
    const VectorXd tau = field(id.lines[std::size_t(k)], "tau");
    const VectorXd ref = nhdyn::reference::rne<double>(t, q[std::size_t(k)], qd[std::size_t(k)], qdd[std::size_t(k)]);
    CHECK((tau - ref).norm() <= 1e-12 * std::max(1.0, ref.norm()));
    fd_input += R"({"q": )" + arr(q[std::size_t(k)]) + R"(, "qd": )" + arr(qd[std::size_t(k)]) + R"(, "tau": )" + arr(tau) + "}\n";
  }
  const auto fd = run_tool("fd --model '" + urdf_path + "'", fd_input);
  REQUIRE(fd.status == 0);
  for (int k = 0; k < 10; ++k) {
    const VectorXd a = field(fd.lines[std::size_t(k)], "qdd");
    CHECK((a - qdd[std::size_t(k)]).norm() <= 1e-8 * std::max(1.0, qdd[std::size_t(k)].norm()));
  }
  // a line of the wrong form names the keys; a command that does not take URDF says so
  const auto bad = run_tool("id --model '" + urdf_path + "'", R"({"q": [0], "eta": [0], "eta_dot": [0]})" "\n");
  CHECK(bad.status == 1);
  const auto lin = run_tool("linearize --model '" + urdf_path + "'");
  CHECK(lin.status == 1);
  CHECK(lin.err.find("URDF models and robot files work with") != std::string::npos);
}

TEST_CASE("tool: a robot file (URDF on a planar base, no-slip constraint) in model, id and fd") {
  const std::string file = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/mobile_manipulator.json";
  auto r = run_tool("model --model '" + file + "'");
  REQUIRE(r.status == 0);
  const json j = json::parse(r.lines[0]);
  CHECK(j["dof"] == 19);
  CHECK(j["k"] == 1);
  CHECK(j["joints"][0] == "base_x");
  CHECK(j["joints"][2] == "base_yaw");
  CHECK(j["eta"].size() == 18);
  CHECK(j["eta"][0] == "v");
  CHECK(j["eta"][1] == "omega");
  CHECK(j["eta"][2] == "wheel_left_joint");
  // id through the tool, then fd through the tool, recovers η̇; τ equals Sᵀ(M q̈ + h) by CRBA
  const auto robot = nhdyn::io::load_robot_file(file);
  const auto& c = *robot.constraint;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const VectorXd q = VectorXd::NullaryExpr(19, [&] { return u(rng); });
  const VectorXd eta = VectorXd::NullaryExpr(18, [&] { return u(rng); });
  const VectorXd eta_dot = VectorXd::NullaryExpr(18, [&] { return u(rng); });
  const auto id = run_tool("id --model '" + file + "'",
                           R"({"q": )" + arr(q) + R"(, "eta": )" + arr(eta) + R"(, "eta_dot": )" + arr(eta_dot) + "}\n");
  REQUIRE(id.status == 0);
  const VectorXd tau = field(id.lines[0], "tau");
  const Eigen::MatrixXd S = c.S(q);
  const VectorXd qd = S * eta, qdd = S * eta_dot + c.Sdot(q, qd) * eta;
  const VectorXd ref = S.transpose() * (nhdyn::mass_matrix(robot.model)(q) * qdd + nhdyn::bias(robot.model)(q, qd));
  CHECK((tau - ref).norm() <= 1e-12 * std::max(1.0, ref.norm()));
  const auto fd = run_tool("fd --model '" + file + "'",
                           R"({"q": )" + arr(q) + R"(, "eta": )" + arr(eta) + R"(, "tau": )" + arr(tau) + "}\n");
  REQUIRE(fd.status == 0);
  const VectorXd ed = field(fd.lines[0], "eta_dot");
  CHECK((ed - eta_dot).norm() <= 1e-8 * std::max(1.0, eta_dot.norm()));
}
