/// robot_dynamics (robot_dynamics.hpp), the front end compiled in the library, on every shipped robot
/// file, a URDF without a constraint and the paper's DH model. This program includes only that
/// header and links nhdyn::compiled where it is built (tests/urdf.cmake), so it tests the
/// compiled functions. tests/compiled/ shows that header-only gives the same numbers bit for bit.
/// The checks use physics and a second path, not numbers copied from the code:
///
/// - rne = M q̈ + h; forward_dynamics(rne(q̈)) = q̈;
/// - the derivatives against central differences of the calls they differentiate, and
///   ∂τ/∂q̈ = M, ∂q̈/∂τ · M = I;
/// - A S = 0; lift's q̇ = S η = apply_S; the lifted v = E τ + Aᵀλ (the split of the generalized
///   force); nh_forward_dynamics(inverse_dynamics(η̇)) = η̇;
/// - the top-right block of the state-space A is S (∂(Sη)/∂η), and B against differences;
/// - the call and the form into storage give the same τ bit for bit, and so do
///   inverse_dynamics and inverse_dynamics_with_forces; two threads running every call with
///   scratch of its own (the derivatives) give the same numbers as one;
/// - the errors: wrong sizes, NaN, a nonholonomic call without a constraint, unknown names and
///   files, each naming the robot, the call and what is wrong; the names and their indices.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <nhdyn/robot_dynamics.hpp>

using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

std::string source(const std::string& rel) { return std::string(NHDYN_SOURCE_DIR) + "/" + rel; }

std::vector<std::string> shipped_robot_files() {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(source("examples/robots")))
    if (e.path().extension() == ".json") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

VectorXd wave(int n, double a, double b, double c) {
  VectorXd x(n);
  for (int i = 0; i < n; ++i) x(i) = a * std::sin(b * i + c);
  return x;
}

/// Central differences of f (a vector of x) at x, column by column. h = 1e-4: the truncation
/// error (h²) stays near 1e-8, and the rounding error stays small where M is ill-conditioned
/// (tiago_style: cond(M) = 1e9, so that h = 1e-6 gives 3e-5 from rounding alone).
template <class F>
MatrixXd differences(const F& f, const VectorXd& x, double h = 1e-4) {
  const VectorXd f0 = f(x);
  MatrixXd J(f0.size(), x.size());
  for (int j = 0; j < x.size(); ++j) {
    VectorXd xp = x, xm = x;
    xp(j) += h, xm(j) -= h;
    J.col(j) = (f(xp) - f(xm)) / (2 * h);
  }
  return J;
}

double rel(const MatrixXd& a, const MatrixXd& b) { return (a - b).norm() / (1 + b.norm()); }

/// The holonomic calls' checks on robot r at a state of its size.
void check_holonomic(const nhdyn::robot_dynamics& r) {
  const int n = r.dof();
  // q on the configuration space (a floating base's quaternion unit): the wave from the neutral q
  const VectorXd q = r.integrate(r.neutral_configuration(), wave(n, 0.8, 0.7, 0.3)), qd = wave(n, 1.1, 1.3, 0.1),
                 qdd = wave(n, 0.9, 0.4, 1.7);
  CHECK(q.size() == r.nq());
  CHECK(rel(r.difference(r.neutral_configuration(), q), wave(n, 0.8, 0.7, 0.3)) < 1e-14);
  const VectorXd v = r.rne(q, qd, qdd);
  const MatrixXd M = r.mass_matrix(q);
  const VectorXd h = r.bias(q, qd);
  CHECK(rel(M * qdd + h, v) < 1e-12);
  CHECK(rel(M, M.transpose()) == 0.0);
  CHECK(rel(r.forward_dynamics(q, qd, v), qdd) < 1e-9);
  VectorXd into;
  r.rne(q, qd, qdd, into);
  CHECK(into == v);
  MatrixXd M_into;
  r.mass_matrix(q, M_into);
  CHECK(M_into == M);

  const auto d = r.rne_derivatives(q, qd, qdd);
  CHECK(rel(d.tau, v) < 1e-13);
  CHECK(rel(d.M, M) < 1e-13);
  // ∂τ/∂q in q's tangent space (x ↦ q ⊕ x, which is q + x on a fixed base)
  CHECK(rel(d.dq, differences([&](const VectorXd& x) { return r.rne(r.integrate(q, x), qd, qdd); }, VectorXd::Zero(n))) <
        1e-7);
  CHECK(rel(d.dqd, differences([&](const VectorXd& x) { return r.rne(q, x, qdd); }, qd)) < 1e-7);

  const VectorXd tau = wave(n, 2.0, 0.5, 0.2);
  const auto f = r.forward_dynamics_derivatives(q, qd, tau);
  CHECK(rel(f.qdd, r.forward_dynamics(q, qd, tau)) < 1e-12);
  CHECK(rel(f.Minv * M, MatrixXd::Identity(n, n)) < 1e-9);
  CHECK(rel(f.dq, differences([&](const VectorXd& x) { return r.forward_dynamics(r.integrate(q, x), qd, tau); },
                              VectorXd::Zero(n))) < 1e-6);
  CHECK(rel(f.dqd, differences([&](const VectorXd& x) { return r.forward_dynamics(q, x, tau); }, qd)) < 1e-6);
}

/// The nonholonomic calls' checks.
void check_constrained(const nhdyn::robot_dynamics& r) {
  const int n = r.dof(), m = r.m(), p = r.p();
  REQUIRE(r.constrained());
  REQUIRE(int(r.eta_names().size()) == m);
  REQUIRE(int(r.tau_names().size()) == p);
  // the base's yaw away from 0 and joints away from their zero (a castor's steering too)
  const VectorXd q = wave(n, 0.6, 0.9, 0.4), eta = wave(m, 0.7, 1.1, 0.5), eta_dot = wave(m, 0.5, 0.6, 1.2);
  const MatrixXd S = r.S(q), A = r.A(q), E = r.input_map(q);
  REQUIRE(S.rows() == n);
  REQUIRE(S.cols() == m);
  REQUIRE(A.rows() == r.k());
  REQUIRE(E.cols() == p);
  CHECK((A * S).norm() < 1e-12 * (1 + A.norm() * S.norm()));
  CHECK(rel(r.apply_S(q, eta), S * eta) < 1e-14);

  const auto xi = r.lift(q, eta, eta_dot);
  CHECK(xi.q == q);
  CHECK(rel(xi.qd, S * eta) < 1e-14);
  // q̈ = S η̇ + Ṡ η: Ṡ η by a central difference of S along q̇ = S η
  const double eps = 1e-6;
  const MatrixXd Sdot = (r.S(q + eps * xi.qd) - r.S(q - eps * xi.qd)) / (2 * eps);
  CHECK(rel(xi.qdd, S * eta_dot + Sdot * eta) < 1e-7);

  const VectorXd tau = r.inverse_dynamics(q, eta, eta_dot);
  const auto f = r.inverse_dynamics_with_forces(q, eta, eta_dot);
  CHECK(f.tau == tau);
  REQUIRE(f.lambda.size() == r.k());
  VectorXd into = VectorXd::Constant(3, 99.0);  // another size: resized
  r.inverse_dynamics(q, eta, eta_dot, into);
  CHECK(into == tau);
  const VectorXd v = r.rne(xi.q, xi.qd, xi.qdd);
  CHECK(rel(E * f.tau + A.transpose() * f.lambda, v) < 1e-10);
  CHECK(rel(r.nh_forward_dynamics(q, eta, tau), eta_dot) < 1e-9);

  const auto d = r.inverse_dynamics_derivatives(q, eta, eta_dot);
  CHECK(rel(d.tau, tau) < 1e-12);
  CHECK(rel(d.dq, differences([&](const VectorXd& x) { return r.inverse_dynamics(x, eta, eta_dot); }, q)) < 1e-6);
  CHECK(rel(d.deta, differences([&](const VectorXd& x) { return r.inverse_dynamics(q, x, eta_dot); }, eta)) < 1e-6);
  CHECK(rel(d.deta_dot, differences([&](const VectorXd& x) { return r.inverse_dynamics(q, eta, x); }, eta_dot)) <
        1e-6);

  const VectorXd u = tau + wave(p, 0.3, 0.8, 0.9);
  const auto g = r.nh_forward_dynamics_derivatives(q, eta, u);
  CHECK(rel(g.eta_dot, r.nh_forward_dynamics(q, eta, u)) < 1e-12);
  REQUIRE(g.A.rows() == n + m);
  REQUIRE(g.B.cols() == p);
  CHECK(rel(g.A.block(0, n, n, m), S) < 1e-14);  // ∂(Sη)/∂η
  CHECK(rel(g.B.bottomRows(m), differences([&](const VectorXd& x) { return r.nh_forward_dynamics(q, eta, x); }, u)) <
        1e-6);
  CHECK(rel(g.A.bottomLeftCorner(m, n),
            differences([&](const VectorXd& x) { return r.nh_forward_dynamics(x, eta, u); }, q)) < 1e-6);
}

}  // namespace

TEST_CASE("robot_dynamics: every shipped robot file, holonomic and on its constraint") {
  const auto files = shipped_robot_files();
  REQUIRE(files.size() >= 10);
  int constrained = 0;
  for (const auto& file : files) {
    INFO(file);
    const auto r = nhdyn::robot_dynamics::load(file);
    REQUIRE(int(r.joint_names().size()) == r.dof());
    check_holonomic(r);
    if (r.constrained()) {
      ++constrained;
      check_constrained(r);
    }
  }
  // every shipped robot file names its base constraint, but those of free-flying robots
  int floating = 0;
  for (const auto& file : files) floating += nhdyn::robot_dynamics::load(file).floating() ? 1 : 0;
  CHECK(floating >= 2);
  CHECK(constrained + floating == int(files.size()));
}

TEST_CASE("robot_dynamics: a URDF (no constraint) and the paper's DH model as its tree") {
  const auto urdf = nhdyn::robot_dynamics::load(source("examples/urdf/mobile_manipulator.urdf"));
  CHECK_FALSE(urdf.constrained());
  CHECK(urdf.k() == 0);
  CHECK(urdf.m() == urdf.dof());
  check_holonomic(urdf);
  const VectorXd z = VectorXd::Zero(urdf.dof());
  CHECK_THROWS_WITH(urdf.inverse_dynamics(z, z, z), Catch::Contains("no base constraint") && Catch::Contains("inverse_dynamics"));
  CHECK_THROWS_AS(urdf.S(z), nhdyn::model_error);

  const auto paper5 = nhdyn::robot_dynamics::load("paper5");
  CHECK(paper5.constrained());
  CHECK(paper5.k() == 1);
  check_holonomic(paper5);
  check_constrained(paper5);
}

TEST_CASE("robot_dynamics: bad input is named, with the robot and the call") {
  const auto r = nhdyn::robot_dynamics::load(source("examples/robots/mobile_manipulator_wheels.json"));
  const int n = r.dof(), m = r.m();
  const VectorXd q = VectorXd::Zero(n), e = VectorXd::Zero(m);
  const std::string robot = "robot '" + r.name() + "', ";
  CHECK_THROWS_WITH(r.rne(VectorXd::Zero(n + 1), q, q),
                    robot + "rne: q has " + std::to_string(n + 1) + " entries; the model needs " + std::to_string(n));
  CHECK_THROWS_AS(r.rne(VectorXd::Zero(n + 1), q, q), nhdyn::input_error);
  VectorXd bad = q;
  bad(2) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(r.rne(q, bad, q), Catch::StartsWith(robot + "rne: qd[2] is not finite"));
  CHECK_THROWS_WITH(r.mass_matrix(VectorXd::Zero(2)), Catch::StartsWith(robot + "mass_matrix: q has 2 entries"));
  CHECK_THROWS_WITH(r.inverse_dynamics(q, VectorXd::Zero(m + 2), e), Catch::StartsWith(robot + "inverse_dynamics: eta has "));
  CHECK_THROWS_WITH(r.inverse_dynamics(q, e, VectorXd::Zero(1)), Catch::StartsWith(robot + "inverse_dynamics: eta_dot has 1 "));
  CHECK_THROWS_WITH(r.apply_S(q, VectorXd::Zero(m - 1)), Catch::StartsWith(robot + "apply_S: eta has "));
  CHECK_THROWS_WITH(r.A(bad), Catch::StartsWith(robot + "A: q[2] is not finite"));
  CHECK_THROWS_WITH(r.nh_forward_dynamics_derivatives(q, e, VectorXd::Zero(r.p() + 1)),
                    Catch::StartsWith(robot + "nh_forward_dynamics_derivatives: tau has "));
  CHECK_THROWS_WITH(r.eta_index("no_such_joint"),
                    Catch::StartsWith(robot + "eta_index: no entry named 'no_such_joint'") && Catch::Contains("arm_1_joint"));
  CHECK_THROWS_AS(nhdyn::robot_dynamics::load(source("examples/robots/no_such_file.json")), nhdyn::error);
}

TEST_CASE("robot_dynamics: a JSON file that is neither a robot file nor a model is named as such") {
  const auto dir = std::filesystem::temp_directory_path() / ("nhdyn_rd_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    const std::string path = (dir / name).string();
    std::ofstream(path) << text;
    return path;
  };
  // a robot file whose "urdf" key is misspelt: not the DH parser's complaint about its keys
  const auto typo = write("typo.json", R"({"name": "r", "urdff": "robot.urdf", "base": {"type": "planar"}})");
  CHECK_THROWS_WITH(nhdyn::robot_dynamics::load(typo),
                    "robot '" + typo + "': a JSON object that is neither a robot file (it needs \"urdf\", "
                    "docs/model-format.md) nor a DH model file (it needs \"links\"); its keys: 'base', 'name', 'urdff'");
  CHECK_THROWS_AS(nhdyn::robot_dynamics::load(typo), nhdyn::model_error);
  const auto empty = write("empty.json", "{}");
  CHECK_THROWS_WITH(nhdyn::robot_dynamics::load(empty), Catch::EndsWith("; its keys: none"));
  // not JSON at all: the error names the file and the line
  const auto broken = write("broken.json", "{\n  \"name\": \"r\",\n  \"urdf\" \"robot.urdf\"\n}\n");
  CHECK_THROWS_WITH(nhdyn::robot_dynamics::load(broken), Catch::Contains(broken) && Catch::Contains("line 3"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("robot_dynamics: names and their indices") {
  const auto r = nhdyn::robot_dynamics::load(source("examples/robots/mecanum_arm.json"));
  CHECK(r.name() == "mecanum_arm");
  REQUIRE(r.p() == r.m() + 1);  // four wheels drive the base's three velocities: τ ≠ η's names
  for (int i = 0; i < r.dof(); ++i) CHECK(r.joint_index(r.joint_names()[std::size_t(i)]) == i);
  for (int i = 0; i < r.m(); ++i) CHECK(r.eta_index(r.eta_names()[std::size_t(i)]) == i);
  for (int i = 0; i < r.p(); ++i) CHECK(r.tau_index(r.tau_names()[std::size_t(i)]) == i);
  CHECK(r.joint_names()[0] == "base_x");
  // every actuated joint is a joint, and the call's τ has their number of entries
  for (const auto& name : r.tau_names()) CHECK_NOTHROW(r.joint_index(name));
  const VectorXd q = wave(r.dof(), 0.3, 0.5, 0.1), eta = wave(r.m(), 0.4, 0.9, 0.2);
  CHECK(r.inverse_dynamics(q, eta, eta).size() == r.p());
}

TEST_CASE("robot_dynamics: copies share one model; two threads give one thread's numbers") {
  const auto r = nhdyn::robot_dynamics::load(source("examples/robots/mecanum_arm.json"));
  auto copy = r;
  CHECK(&copy.robot() == &r.robot());
  auto moved = std::move(copy);  // a copy: no robot_dynamics is ever empty
  CHECK(&moved.robot() == &r.robot());
  CHECK(copy.dof() == r.dof());
  const int n = r.dof(), m = r.m(), p = r.p();
  constexpr int K = 60;
  // every call with scratch of its own (the derivatives keep theirs per thread) at K states
  const auto run = [&](const nhdyn::robot_dynamics& x, std::vector<VectorXd>& out) {
    out.clear();
    for (int i = 0; i < K; ++i) {
      const VectorXd q = wave(n, 0.5, 0.3, 0.01 * i), e = wave(m, 1, 0.2, i), ed = wave(m, 1, 0.5, i);
      const VectorXd tau = x.inverse_dynamics(q, e, ed);
      out.push_back(tau);
      out.push_back(x.nh_forward_dynamics(q, e, tau + wave(p, 0.1, 0.4, i)));
      const auto d = x.inverse_dynamics_derivatives(q, e, ed);
      out.push_back(Eigen::Map<const VectorXd>(d.dq.data(), d.dq.size()));
      const auto g = x.nh_forward_dynamics_derivatives(q, e, tau);
      out.push_back(Eigen::Map<const VectorXd>(g.A.data(), g.A.size()));
      const auto h = x.rne_derivatives(q, wave(n, 1, 0.7, i), wave(n, 1, 0.3, i));
      out.push_back(Eigen::Map<const VectorXd>(h.dq.data(), h.dq.size()));
      const auto f = x.forward_dynamics_derivatives(q, wave(n, 1, 0.7, i), wave(n, 1, 0.3, i));
      out.push_back(Eigen::Map<const VectorXd>(f.dqd.data(), f.dqd.size()));
    }
  };
  std::vector<VectorXd> alone, a, b;
  run(r, alone);
  std::thread t1(run, std::cref(r), std::ref(a)), t2(run, std::cref(moved), std::ref(b));
  t1.join(), t2.join();
  REQUIRE(alone.size() == std::size_t(6 * K));
  CHECK(a == alone);
  CHECK(b == alone);
}
