// `nhdyn model` and URDF models in the tool (`--model x.urdf`, `--strict`), driven as a user
// would. Expected torques come from the plain reference algorithm (dynamics/reference.hpp),
// not from the kernel the tool runs; expected names from the file itself.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cmath>
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

#include "../support/scratch_dir.hpp"

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
  const auto& dir = nhdyn_test::scratch_dir("tool_model");
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
  // a line of the wrong form names the keys
  const auto bad = run_tool("id --model '" + urdf_path + "'", R"({"q": [0], "eta": [0], "eta_dot": [0]})" "\n");
  CHECK(bad.status == 1);
  // linearize on the URDF: B's q̈ block is M⁻¹ (CRBA), A's q block top-right is I
  const auto lin = run_tool("linearize --model '" + urdf_path + "'",
                            R"({"q": )" + arr(q[0]) + R"(, "qd": )" + arr(qd[0]) + R"(, "tau": )" + arr(qdd[0]) + "}\n");
  REQUIRE(lin.status == 0);
  const json jl = json::parse(lin.lines[0]);
  const Eigen::MatrixXd Minv = nhdyn::mass_matrix(t)(q[0]).inverse();
  double worst = 0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) {
      worst = std::max(worst, std::abs(jl["B"][std::size_t(n + i)][std::size_t(k)].get<double>() - Minv(i, k)));
      CHECK(jl["A"][std::size_t(i)][std::size_t(n + k)].get<double>() == (i == k ? 1.0 : 0.0));
    }
  CHECK(worst <= 1e-9 * Minv.cwiseAbs().maxCoeff());
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
  const auto& c = std::get<nhdyn::differential_drive<double>>(*robot.constraint);
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

TEST_CASE("tool: robot files with each constraint type in model, id, fd, linearize and bound") {
  for (const std::string name : {"mobile_manipulator_wheels", "mobile_manipulator_bicycle", "paper5", "mecanum_arm",
                                 "castor_drive_arm"}) {
    INFO(name);
    const std::string file = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/" + name + ".json";
    const auto robot = nhdyn::io::load_robot_file(file);
    std::visit(
        [&](const auto& c) {
          const int n = c.dof(), m = c.m(), p = nhdyn::actuator_count(c);
          auto r = run_tool("model --model '" + file + "'");
          REQUIRE(r.status == 0);
          const json j = json::parse(r.lines[0]);
          CHECK(j["name"] == name);  // the robot file's "name", not its URDF's
          CHECK(j["k"] == c.k());
          CHECK(j["eta"] == json(robot.eta_names()));
          CHECK(j["tau"] == json(robot.tau_names()));
          CHECK(j["tau"].size() == std::size_t(p));
          if constexpr (requires { c.mobility(); }) {
            CHECK(j["lambda"] == json(c.lambda_names()));
            CHECK(j["mobility"]["degree_of_mobility"] == c.mobility());
            CHECK(j["mobility"]["degree_of_steerability"] == c.steerability());
          }
          std::mt19937_64 rng(11);
          std::uniform_real_distribution<double> u(-0.5, 0.5);
          const VectorXd q = VectorXd::NullaryExpr(n, [&] { return u(rng); });
          const VectorXd eta = VectorXd::NullaryExpr(m, [&] { return u(rng); });
          const VectorXd eta_dot = VectorXd::NullaryExpr(m, [&] { return u(rng); });
          const std::string state = R"({"q": )" + arr(q) + R"(, "eta": )" + arr(eta);
          // id: τ = (SᵀE)⁺Sᵀ(M q̈ + h) by CRBA (the least-norm solution: the inverse when square)
          // and λ from v − Eτ = Aᵀλ
          const auto id = run_tool("id --model '" + file + "'", state + R"(, "eta_dot": )" + arr(eta_dot) + "}\n");
          REQUIRE(id.status == 0);
          const VectorXd tau = field(id.lines[0], "tau"), lambda = field(id.lines[0], "lambda");
          const Eigen::MatrixXd S = c.S(q), E = nhdyn::input_map(c, q), A = c.A(q);
          const VectorXd qd = S * eta, qdd = S * eta_dot + c.Sdot(q, qd) * eta;
          const VectorXd v = nhdyn::mass_matrix(robot.model)(q) * qdd + nhdyn::bias(robot.model)(q, qd);
          const VectorXd ref = (S.transpose() * E).jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(VectorXd(S.transpose() * v));
          REQUIRE(tau.size() == p);
          CHECK((tau - ref).norm() <= 1e-12 * std::max(1.0, ref.norm()));
          CHECK((E * tau + A.transpose() * lambda - v).norm() <= 1e-11 * std::max(1.0, v.norm()));
          // fd inverts id
          const auto fd = run_tool("fd --model '" + file + "'", state + R"(, "tau": )" + arr(tau) + "}\n");
          REQUIRE(fd.status == 0);
          CHECK((field(fd.lines[0], "eta_dot") - eta_dot).norm() <= 1e-8 * std::max(1.0, eta_dot.norm()));
          // linearize: the top-right block of A is S(q); the η̇ rows of B are M_η⁻¹ SᵀE
          const auto lin = run_tool("linearize --model '" + file + "'", state + R"(, "tau": )" + arr(tau) + "}\n");
          REQUIRE(lin.status == 0);
          const json jl = json::parse(lin.lines[0]);
          const Eigen::MatrixXd Meta = S.transpose() * nhdyn::mass_matrix(robot.model)(q) * S;
          const Eigen::MatrixXd Bref = Meta.inverse() * S.transpose() * E;
          double wa = 0, wb = 0;
          for (int i = 0; i < n; ++i)
            for (int k = 0; k < m; ++k) wa = std::max(wa, std::abs(jl["A"][std::size_t(i)][std::size_t(n + k)].get<double>() - S(i, k)));
          for (int i = 0; i < m; ++i)
            for (int k = 0; k < p; ++k) wb = std::max(wb, std::abs(jl["B"][std::size_t(n + i)][std::size_t(k)].get<double>() - Bref(i, k)));
          CHECK(wa <= 1e-14);
          CHECK(wb <= 1e-9 * Bref.cwiseAbs().maxCoeff());
          // bound: a small box around the state encloses id's τ at the state
          const auto box = [](const VectorXd& x, double w) {
            std::string s = "[";
            for (Eigen::Index i = 0; i < x.size(); ++i)
              s += (i ? ", [" : "[") + nhdyn::io::format_number(x(i) - w) + ", " + nhdyn::io::format_number(x(i) + w) + "]";
            return s + "]";
          };
          // bound: boxes around the state enclose id's τ there, and shrink with the box (an
          // interval enclosure converges linearly: 10× narrower box, ≈10× narrower bounds)
          std::vector<double> width;
          for (double w : {1e-3, 1e-4}) {
            const auto b = run_tool("bound --model '" + file + "'", R"({"q": )" + box(q, w) + R"(, "eta": )" + box(eta, w) +
                                                                       R"(, "eta_dot": )" + box(eta_dot, w) + "}\n");
            REQUIRE(b.status == 0);
            const json jb = json::parse(b.lines[0]);
            REQUIRE(jb["tau"].size() == std::size_t(p));
            double widest = 0;
            for (int i = 0; i < p; ++i) {
              const double lo = jb["tau"][std::size_t(i)][0].get<double>(), hi = jb["tau"][std::size_t(i)][1].get<double>();
              CHECK(lo <= tau(i));
              CHECK(hi >= tau(i));
              widest = std::max(widest, hi - lo);
            }
            width.push_back(widest);
          }
          CHECK(width[1] <= 0.2 * width[0]);
        },
        *robot.constraint);
  }
}

TEST_CASE("tool: --lock holds joints of a robot file: model lists them, id equals the full robot's kept entries") {
  const std::string file = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/mobile_manipulator.json";
  const std::string lock = "--lock 'head_*=0.3,arm_7_joint=-0.5'";
  auto r = run_tool("model --model '" + file + "' " + lock);
  REQUIRE(r.status == 0);
  const json j = json::parse(r.lines[0]);
  CHECK(j["dof"] == 16);
  CHECK(j["eta"].size() == 15);
  CHECK(j["locked"] == json::parse(R"({"head_pan_joint": 0.3, "head_tilt_joint": 0.3, "arm_7_joint": -0.5})"));
  for (const auto& name : j["joints"]) CHECK(name.get<std::string>().find("head_") == std::string::npos);
  // the full robot's τ with the locked joints at their positions, zero rate and acceleration
  const auto full = nhdyn::io::load_robot_file(file);
  const auto& c = std::get<nhdyn::differential_drive<double>>(*full.constraint);
  const auto joints = full.model.joint_names();
  const auto eta_full = c.eta_names(joints);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-1, 1);
  VectorXd q = VectorXd::NullaryExpr(19, [&] { return u(rng); });
  VectorXd eta = VectorXd::NullaryExpr(18, [&] { return u(rng); }), eta_dot = eta.reverse();
  std::vector<int> kept_q, kept_eta;
  for (int i = 0; i < 19; ++i) {
    const auto& n = joints[std::size_t(i)];
    if (n.rfind("head_", 0) == 0) q(i) = 0.3;
    else if (n == "arm_7_joint") q(i) = -0.5;
    else kept_q.push_back(i);
  }
  for (int i = 0; i < 18; ++i) {
    const auto& n = eta_full[std::size_t(i)];
    if (n.rfind("head_", 0) == 0 || n == "arm_7_joint") eta(i) = eta_dot(i) = 0;
    else kept_eta.push_back(i);
  }
  const Eigen::MatrixXd S = c.S(q);
  const VectorXd qd = S * eta, qdd = S * eta_dot + c.Sdot(q, qd) * eta;
  const VectorXd ref = S.transpose() * (nhdyn::mass_matrix(full.model)(q) * qdd + nhdyn::bias(full.model)(q, qd));
  const auto pick = [](const VectorXd& v, const std::vector<int>& idx) {
    VectorXd out(static_cast<Eigen::Index>(idx.size()));
    for (std::size_t k = 0; k < idx.size(); ++k) out(Eigen::Index(k)) = v(idx[k]);
    return out;
  };
  const auto id = run_tool("id --model '" + file + "' " + lock, R"({"q": )" + arr(pick(q, kept_q)) + R"(, "eta": )" +
                                                                    arr(pick(eta, kept_eta)) + R"(, "eta_dot": )" +
                                                                    arr(pick(eta_dot, kept_eta)) + "}\n");
  REQUIRE(id.status == 0);
  const VectorXd want = pick(ref, kept_eta);
  CHECK((field(id.lines[0], "tau") - want).norm() <= 1e-12 * std::max(1.0, want.norm()));

  // errors name the culprit
  r = run_tool("model --model '" + file + "' --lock 'base_x=0'");
  CHECK(r.status != 0);
  CHECK(r.err.find("'base_x' belongs to the constraint (differential_drive)") != std::string::npos);
  r = run_tool("model --model '" + file + "' --lock 'gripper_*=0'");
  CHECK(r.status != 0);
  CHECK(r.err.find("'gripper_*' matches no movable joint") != std::string::npos);
  r = run_tool("model --model '" + file + "' --lock 'arm_1_joint'");
  CHECK(r.status == 2);
  CHECK(r.err.find("'arm_1_joint' is not NAME=POSITION") != std::string::npos);
}

TEST_CASE("tool: --lock on DH models (presets, JSON models): the chain's kept entries, its constraint on the kept joints") {
  // puma560 with joints 2 and 5 held: the locked tree's id (tree kernel) = the full chain's
  // (DH kernel) at q2 = 0.3, q5 = -0.4 at rest, rows 1, 3, 4, 6
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto rand = [&](int n) { return VectorXd(VectorXd::NullaryExpr(n, [&] { return u(rng); })); };
  const auto pick = [](const VectorXd& v, const std::vector<int>& idx) {
    VectorXd out(static_cast<Eigen::Index>(idx.size()));
    for (std::size_t k = 0; k < idx.size(); ++k) out(Eigen::Index(k)) = v(idx[k]);
    return out;
  };
  VectorXd q = rand(6), qd = rand(6), qdd = rand(6);
  q(1) = 0.3, q(4) = -0.4, qd(1) = qd(4) = qdd(1) = qdd(4) = 0;
  const std::vector<int> kept{0, 2, 3, 5};
  auto r = run_tool("model --model puma560 --lock 'joint2=0.3,joint5=-0.4'");
  REQUIRE(r.status == 0);
  json j = json::parse(r.lines[0]);
  CHECK(j["dof"] == 4);
  CHECK(j["joints"] == json::parse(R"(["joint1", "joint3", "joint4", "joint6"])"));
  CHECK(j["locked"] == json::parse(R"({"joint2": 0.3, "joint5": -0.4})"));
  auto full = run_tool("id --model puma560", R"({"q": )" + arr(q) + R"(, "qd": )" + arr(qd) + R"(, "qdd": )" + arr(qdd) + "}\n");
  auto held = run_tool("id --model puma560 --lock 'joint[25]=0.3,joint5=-0.4'",
                       R"({"q": )" + arr(pick(q, kept)) + R"(, "qd": )" + arr(pick(qd, kept)) + R"(, "qdd": )" +
                           arr(pick(qdd, kept)) + "}\n");
  // joint[25] matches joint5 too, which the second entry also names: an error naming both
  CHECK(held.status != 0);
  CHECK(held.err.find("joint5") != std::string::npos);
  held = run_tool("id --model puma560 --lock 'joint2=0.3,joint5=-0.4'",
                  R"({"q": )" + arr(pick(q, kept)) + R"(, "qd": )" + arr(pick(qd, kept)) + R"(, "qdd": )" +
                      arr(pick(qdd, kept)) + "}\n");
  REQUIRE(full.status == 0);
  REQUIRE(held.status == 0);
  VectorXd want = pick(field(full.lines[0], "tau"), kept);
  CHECK((field(held.lines[0], "tau") - want).norm() <= 1e-12 * std::max(1.0, want.norm()));

  // paper5 (a differential drive on joints 1-3) as a JSON model file whose own "locked" holds
  // joint 4: its η is (v, ω, q̇5) and τ the full chain's entries for them
  auto m = nhdyn::io::load("paper5");
  m.locked = {{"joint4", 0.6}};
  const auto file = nhdyn_test::scratch_dir("tool_model") / "p5_locked.json";
  nhdyn::io::save_model(m, file);
  VectorXd q5 = rand(5), eta = rand(4), eta_dot = rand(4);
  q5(3) = 0.6, eta(2) = eta_dot(2) = 0;  // η = (v, ω, q̇4, q̇5)
  full = run_tool("id --model paper5", R"({"q": )" + arr(q5) + R"(, "eta": )" + arr(eta) + R"(, "eta_dot": )" + arr(eta_dot) + "}\n");
  held = run_tool("id --model '" + file.string() + "'", R"({"q": )" + arr(pick(q5, {0, 1, 2, 4})) + R"(, "eta": )" +
                                                            arr(pick(eta, {0, 1, 3})) + R"(, "eta_dot": )" +
                                                            arr(pick(eta_dot, {0, 1, 3})) + "}\n");
  REQUIRE(full.status == 0);
  REQUIRE(held.status == 0);
  want = pick(field(full.lines[0], "tau"), {0, 1, 3});
  CHECK((field(held.lines[0], "tau") - want).norm() <= 1e-12 * std::max(1.0, want.norm()));
  r = run_tool("model --model '" + file.string() + "'");
  REQUIRE(r.status == 0);
  j = json::parse(r.lines[0]);
  CHECK(j["locked"] == json::parse(R"({"joint4": 0.6})"));
  CHECK(j["eta"].size() == 3);
  fs::remove(file);

  // the constraint's joints cannot be held; a pattern that matches nothing is named
  r = run_tool("model --model paper5 --lock 'joint3=0'");
  CHECK(r.status != 0);
  CHECK(r.err.find("'joint3' belongs to the constraint (differential_drive)") != std::string::npos);
  r = run_tool("model --model puma560 --lock 'wrist*=0'");
  CHECK(r.status != 0);
  CHECK(r.err.find("'wrist*' matches no movable joint") != std::string::npos);
}

TEST_CASE("tool: --terms on puma560_motors reproduces the Robotics Toolbox's rne(qn, 1, 1); each term off removes its part") {
  // robotics-toolbox-python tests/test_DHRobot.py (test_rne, test_itorque): its rne includes the
  // drives' armature G²J_m q̈, viscous G²B q̇ and Coulomb |G|Tc; qn = (0, π/4, π, 0, π/4, 0).
  const std::string qn = "[0, 0.7853981633974483, 3.141592653589793, 0, 0.7853981633974483, 0]";
  const auto id = [&](const std::string& terms, const std::string& qd, const std::string& qdd) {
    const auto r = run_tool("id --model puma560_motors" + (terms.empty() ? std::string() : " --terms '" + terms + "'"),
                            "{\"q\": " + qn + ", \"qd\": " + qd + ", \"qdd\": " + qdd + "}\n");
    INFO("terms " << terms << ": " << r.err);
    REQUIRE(r.status == 0);
    REQUIRE(r.lines.size() == 1);
    return field(r.lines[0], "tau");
  };
  // to the printed digits: within half a unit of the last one
  const auto printed = [](const VectorXd& x, const std::vector<std::string>& p) {
    REQUIRE(x.size() == Eigen::Index(p.size()));
    for (std::size_t i = 0; i < p.size(); ++i) {
      const auto dot = p[i].find('.');
      const int decimals = dot == std::string::npos ? 0 : int(p[i].size() - dot - 1);
      INFO("entry " << i << ": " << x(Eigen::Index(i)) << " printed " << p[i]);
      CHECK(std::abs(x(Eigen::Index(i)) - std::stod(p[i])) <= 0.5 * std::pow(10.0, -decimals) + 1e-12);
    }
  };
  const std::string o = "[1, 1, 1, 1, 1, 1]", z = "[0, 0, 0, 0, 0, 0]", q123 = "[1, 2, 3, 1, 2, 3]";
  const VectorXd all = id("gravity,velocity,armature,friction", o, o);
  printed(all, {"32.4952", "60.867", "17.7436", "1.45452", "1.29911", "0.713781"});  // rne(qn, 1, 1)
  const VectorXd rtb_qd = id("gravity,velocity,armature,friction", o, z);
  printed(rtb_qd, {"29.1421", "56.5044", "16.3528", "1.26448", "1.12392", "0.519648"});  // rne(qn, 1, 0)
  CHECK(id("all", o, o) == all);
  CHECK(id("friction, armature,velocity,gravity", o, o) == all);  // any order, spaces ignored
  CHECK(id("", o, o) == id("gravity,velocity,armature", o, o));  // the default: no friction

  // Corke's published drive parameters (Puma560.m; typed here, not taken from the preset)
  const double Jm[6] = {200e-6, 200e-6, 200e-6, 33e-6, 33e-6, 33e-6};
  const double G[6] = {-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686};
  const double B[6] = {1.48e-3, .817e-3, 1.38e-3, 71.2e-6, 82.6e-6, 36.7e-6};
  const double Tc_pos[6] = {.395, .126, .132, 11.2e-3, 9.26e-3, 3.96e-3};
  VectorXd armature(6), friction_at_1(6);
  for (int i = 0; i < 6; ++i) {
    armature(i) = G[i] * G[i] * Jm[i];
    friction_at_1(i) = G[i] * G[i] * B[i] + std::abs(G[i]) * Tc_pos[i];
  }
  const auto near = [](const VectorXd& a, const VectorXd& b, double tol) {
    INFO(a.transpose() << "\n vs " << b.transpose());
    CHECK((a - b).cwiseAbs().maxCoeff() <= tol);
  };
  // each term switched off changes exactly its part
  near(all - id("gravity,velocity,friction", o, o), armature, 1e-12);      // G²J_m q̈, q̈ = 1
  near(all - id("gravity,velocity,armature", o, o), friction_at_1, 1e-12);  // G²B + |G|Tc⁺ at q̇ = 1
  // gravity: the toolbox's rne(qn, 0, 0) (friction is 0 at rest, armature at q̈ = 0)
  printed(all - id("velocity,armature,friction", o, o), {"-0.0000", "31.6399", "6.0351", "0.0000", "0.0283", "0"});
  // velocity: C(q, q̇)q̇ = the toolbox's rne(qn, 1, 0) − rne(qn, 0, 0) − the friction at q̇ = 1
  VectorXd gravity(6);
  gravity << 0, 31.6399, 6.0351, 0, 0.0283, 0;
  VectorXd rtb_qd_printed(6);
  rtb_qd_printed << 29.1421, 56.5044, 16.3528, 1.26448, 1.12392, 0.519648;
  near(all - id("gravity,armature,friction", o, o), rtb_qd_printed - gravity - friction_at_1, 1e-4);
  // none: the rigid bodies' M(q) q̈ alone = the toolbox's itorque (M with armature) − G²J_m q̈
  VectorXd itorque(6), qdd(6);
  itorque << 3.1500, 9.4805, 3.6189, 0.1901, 0.3519, 0.5823;
  qdd << 1, 2, 3, 1, 2, 3;
  near(id("none", o, q123), itorque - armature.cwiseProduct(qdd), 0.5e-4 + 1e-12);
  // smooth Coulomb: at q̇ = 1 within 1 − v_s²/(2q̇²) of the exact law (v_s = 0.01: 5e-5 relative)
  const auto r = run_tool("id --model puma560_motors --terms all --smooth-coulomb 0.01",
                          "{\"q\": " + qn + ", \"qd\": " + o + ", \"qdd\": " + o + "}\n");
  REQUIRE(r.status == 0);
  const VectorXd smooth = field(r.lines[0], "tau");
  for (int i = 0; i < 6; ++i) {
    const double coulomb = std::abs(G[i]) * Tc_pos[i];
    CHECK(all(i) - smooth(i) > 0);
    CHECK(all(i) - smooth(i) <= coulomb * 0.5e-4 * 1.01);
  }

  SECTION("errors name the term, exit status 2") {
    for (const std::string bad : {"gravity,bogus", "gravity,,velocity", "gravity,gravity"}) {
      const auto e = run_tool("id --model puma560_motors --terms '" + bad + "'", "");
      CHECK(e.status == 2);
      CHECK(e.err.find("--terms '" + bad + "'") != std::string::npos);
    }
    CHECK(run_tool("id --model puma560_motors --terms gravity --smooth-coulomb 0.1", "").err.find("do not include friction") !=
          std::string::npos);
    CHECK(run_tool("model --model puma560_motors --terms all", "").status == 2);  // model has no terms
  }
}

TEST_CASE("tool: --terms friction in fd, linearize and bound agrees with id's (DH chain and a robot file)") {
  const std::string robot = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/mobile_manipulator_castors.json";
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto rand_vec = [&](int n) {
    VectorXd v(n);
    for (int i = 0; i < n; ++i) v(i) = u(rng);
    return v;
  };
  for (const bool constrained : {false, true}) {
    const std::string spec = constrained ? "'" + robot + "'" : "puma560_motors";
    const auto desc = json::parse(run_tool("model --model " + spec).lines.at(0));
    const int n = desc["dof"], m = int(desc["eta"].size());
    const std::string v = constrained ? "eta" : "qd", a = constrained ? "eta_dot" : "qdd";
    const VectorXd q = rand_vec(n), vel = rand_vec(m), acc = rand_vec(m);
    INFO(spec);
    const auto r_id = run_tool("id --model " + spec + " --terms all",
                               "{\"q\": " + arr(q) + ", \"" + v + "\": " + arr(vel) + ", \"" + a + "\": " + arr(acc) + "}\n");
    REQUIRE(r_id.status == 0);
    const VectorXd tau = field(r_id.lines[0], "tau");
    // fd with friction inverts id with friction; without it, it does not
    const std::string fd_in = "{\"q\": " + arr(q) + ", \"" + v + "\": " + arr(vel) + ", \"tau\": " + arr(tau) + "}\n";
    const auto with = run_tool("fd --model " + spec + " --terms all", fd_in);
    const auto without = run_tool("fd --model " + spec, fd_in);
    REQUIRE(with.status == 0);
    REQUIRE(without.status == 0);
    const VectorXd back = field(with.lines[0], constrained ? "eta_dot" : "qdd");
    CHECK((back - acc).cwiseAbs().maxCoeff() <= 1e-9);
    CHECK((field(without.lines[0], constrained ? "eta_dot" : "qdd") - acc).cwiseAbs().maxCoeff() > 1e-3);
    // linearize with friction (smooth, so differentiable): its B = ∂f/∂τ against central
    // differences of fd with friction in τ (h = 1e-6)
    const std::string smooth = " --terms all --smooth-coulomb 0.05";
    const auto lin = run_tool("linearize --model " + spec + smooth, fd_in);
    REQUIRE(lin.status == 0);
    const json L = json::parse(lin.lines[0]);
    std::string lines;
    const double h = 1e-6;
    for (int j = 0; j < int(tau.size()); ++j)
      for (const double s : {h, -h}) {
        VectorXd t = tau;
        t(j) += s;
        lines += "{\"q\": " + arr(q) + ", \"" + v + "\": " + arr(vel) + ", \"tau\": " + arr(t) + "}\n";
      }
    const auto fd_lines = run_tool("fd --model " + spec + smooth, lines);
    REQUIRE(fd_lines.status == 0);
    const int nx = constrained ? n + m : 2 * n;
    double worst = 0;
    for (int j = 0; j < int(tau.size()); ++j) {
      const VectorXd d = (field(fd_lines.lines[std::size_t(2 * j)], constrained ? "eta_dot" : "qdd") -
                          field(fd_lines.lines[std::size_t(2 * j + 1)], constrained ? "eta_dot" : "qdd")) / (2 * h);
      for (int i = 0; i < m; ++i) worst = std::max(worst, std::abs(L["B"][std::size_t(nx - m + i)][std::size_t(j)].get<double>() - d(i)));
    }
    CHECK(worst <= 1e-5);
    // A's velocity column block carries the friction's slope: it differs from the frictionless one
    const auto lin0 = run_tool("linearize --model " + spec, fd_in);
    REQUIRE(lin0.status == 0);
    CHECK(L["A"] != json::parse(lin0.lines[0])["A"]);
    // bound with friction encloses id's torque at the box's centre
    std::string box = "{";
    for (const auto& [key, x] : {std::pair<std::string, VectorXd>{"q", q}, {v, vel}, {a, acc}}) {
      box += (box.size() > 1 ? ", " : "") + std::string("\"") + key + "\": [";
      for (int i = 0; i < x.size(); ++i)
        box += (i ? ", " : "") + std::string("[") + nhdyn::io::format_number(x(i) - 1e-3) + ", " + nhdyn::io::format_number(x(i) + 1e-3) + "]";
      box += "]";
    }
    const auto b = run_tool("bound --model " + spec + " --terms all", box + "}\n");
    REQUIRE(b.status == 0);
    const json T = json::parse(b.lines[0])["tau"];
    for (int i = 0; i < tau.size(); ++i) {
      CHECK(T[std::size_t(i)][0].get<double>() <= tau(i));
      CHECK(tau(i) <= T[std::size_t(i)][1].get<double>());
    }
  }
}
