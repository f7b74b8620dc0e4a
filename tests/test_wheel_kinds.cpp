/// Every wheeled base (`wheeled_base`): fixed, steered, castor and Swedish wheels, any number,
/// driven or passive, one constraint read off the tree's kinematics. Checked against references
/// that share no code with the kernel:
///
/// - A against the reference rows (tree_kinematics' Jacobian of each contact point), A S = 0;
/// - the contact points' velocities from finite differences of forward-kinematics positions:
///   zero along every constrained direction;
/// - the lift's analytic q̈ = S η̇ + Ṡ η with Ṡ by dual numbers of S, and by central differences;
/// - τ and λ against the projected Euler–Lagrange equations in long double, with the least
///   weighted-norm τ from a pseudo-inverse; M q̈ + h = E τ + Aᵀλ with A q̈ + Ȧ q̇ = 0 for id and fd;
/// - power: λ does no work, the actuators' power is the energy's rate; an unforced 10 s motion
///   of each shipped base keeps |A q̇| at rounding level and its energy (error falling as RK4's h⁴);
/// - a mecanum base turns its wheels at the textbook mecanum rates (Lynch and Park, eq. 13.10);
/// - `wheels` = `wheeled_base` with the same two fixed wheels (τ, λ, η̇ to 1e-12);
/// - the closed-form rows of wheels on one body = the general kernel (S, q̈, τ, λ), also with
///   scaled radii (A S = 0);
/// - inverse_dynamics' `evaluate` into a reused τ (and its call) = the composition's τ bit for bit, for every
///   robot file's constraint (the two paths share the stages, not the storage);
/// - rank, mobility and the errors: coaxial rows kept once, skid-steer and immobile bases
///   reported, a singular configuration and missing actuators named.
#include <catch2/catch.hpp>

#include <nhdyn/analysis/derivatives.hpp>
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/kinematics/tree.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>
#include <sstream>

#include "reference/lagrangian.hpp"

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::VectorXd;
using LD = long double;

namespace {

std::string robot_path(const std::string& name) { return std::string(NHDYN_SOURCE_DIR) + "/examples/robots/" + name; }

io::robot_model load(const std::string& name) {
  io::urdf_options o;
  o.strict = true;
  return io::load_robot_file(robot_path(name), o);
}
const wheeled_base<double>& base_of(const io::robot_model& r) { return std::get<wheeled_base<double>>(*r.constraint); }

/// Every shipped robot file (examples/robots): each base constraint type and every wheeled_base.
const char* const every_robot_file[] = {"paper5.json",                      "mobile_manipulator.json",
                                        "mobile_manipulator_wheels.json",   "mobile_manipulator_bicycle.json",
                                        "mobile_manipulator_castors.json",  "mecanum_arm.json",
                                        "omni3_arm.json",                   "castor_drive_arm.json",
                                        "powered_castors_arm.json",         "tiago_style.json"};

const std::vector<std::string> shipped = {"mecanum_arm.json", "omni3_arm.json", "castor_drive_arm.json",
                                          "powered_castors_arm.json", "mobile_manipulator_castors.json"};

VectorXd random_vec(int n, std::mt19937& rng, double scale = 1) {
  std::uniform_real_distribution<double> u(-scale, scale);
  VectorXd v(n);
  for (int j = 0; j < n; ++j) v(j) = u(rng);
  return v;
}
/// A configuration: the base within a few metres, every angle anywhere.
VectorXd random_q(int n, std::mt19937& rng) {
  VectorXd q = random_vec(n, rng, 3.0);
  q(2) = random_vec(1, rng, 3.1)(0);
  return q;
}
double rel(const VectorXd& a, const VectorXd& b) { return (a - b).cwiseAbs().maxCoeff() / (1 + b.cwiseAbs().maxCoeff()); }

/// A URDF of a box base on the floor with the wheels given as (kind, x, y, yaw of the spin
/// axis from +y, radius, trail) — the robots of the rank and mobility tests.
struct test_wheel {
  std::string kind;
  double x, y, yaw = 0, r = 0.1, trail = 0.04;
};
std::string base_urdf(const std::vector<test_wheel>& ws) {
  std::ostringstream o;
  o << "<robot name=\"test_base\"><link name=\"base_footprint\"/>"
    << "<joint name=\"f\" type=\"fixed\"><parent link=\"base_footprint\"/><child link=\"base_link\"/><origin xyz=\"0 0 0.2\"/></joint>"
    << "<link name=\"base_link\"><inertial><mass value=\"20\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1.5\"/></inertial></link>";
  const auto body = [](double m) {
    std::ostringstream b;
    b << "<inertial><mass value=\"" << m << "\"/><inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial>";
    return b.str();
  };
  for (std::size_t i = 0; i < ws.size(); ++i) {
    const auto& w = ws[i];
    const std::string n = "w" + std::to_string(i);
    std::string parent = "base_link";
    double x = w.x, y = w.y, z = w.r - 0.2;
    if (w.kind == "steered" || w.kind == "castor") {
      const double up = 0.05;  // the vertical joint 5 cm above the wheel centre
      o << "<joint name=\"" << n << "_steer\" type=\"continuous\"><parent link=\"base_link\"/><child link=\"" << n
        << "_fork\"/><origin xyz=\"" << x << " " << y << " " << z + up << "\"/><axis xyz=\"0 0 1\"/></joint>"
        << "<link name=\"" << n << "_fork\">" << body(0.3) << "</link>";
      parent = n + "_fork";
      x = w.kind == "castor" ? -w.trail : 0, y = 0, z = -up;
    }
    o << "<joint name=\"" << n << "_spin\" type=\"continuous\"><parent link=\"" << parent << "\"/><child link=\"" << n
      << "_wheel\"/><origin xyz=\"" << x << " " << y << " " << z << "\" rpy=\"0 0 " << w.yaw << "\"/><axis xyz=\"0 1 0\"/></joint>"
      << "<link name=\"" << n << "_wheel\">" << body(1.0) << "</link>";
  }
  o << "<joint name=\"arm\" type=\"revolute\"><parent link=\"base_link\"/><child link=\"arm_link\"/><origin xyz=\"0 0 0.3\"/>"
    << "<axis xyz=\"0 1 0\"/><limit lower=\"-3\" upper=\"3\" effort=\"10\" velocity=\"2\"/></joint>"
    << "<link name=\"arm_link\"><inertial><origin xyz=\"0 0 0.2\"/><mass value=\"3\"/><inertia ixx=\"0.04\" ixy=\"0\" ixz=\"0\" "
    << "iyy=\"0.04\" iyz=\"0\" izz=\"0.01\"/></inertial></link></robot>";
  return o.str();
}
tree<double> planar_tree(const std::vector<test_wheel>& ws) {
  io::urdf_options o;
  o.planar_base = true;
  return io::parse_urdf(base_urdf(ws), "test_base.urdf", o);
}
std::vector<wheel> wheels_of(const std::vector<test_wheel>& ws, double gamma = 0) {
  std::vector<wheel> out;
  for (std::size_t i = 0; i < ws.size(); ++i) {
    const std::string n = "w" + std::to_string(i);
    wheel w;
    w.kind = ws[i].kind == "fixed" ? wheel_kind::fixed : ws[i].kind == "steered" ? wheel_kind::steered
             : ws[i].kind == "castor"                  ? wheel_kind::castor
                                                       : wheel_kind::swedish;
    w.spin = n + "_spin";
    if (w.kind == wheel_kind::steered || w.kind == wheel_kind::castor) w.steer = n + "_steer";
    w.radius = ws[i].r;
    if (w.kind == wheel_kind::swedish) w.roller_angle = gamma;
    out.push_back(w);
  }
  return out;
}
wheeled_base_options quiet(wheeled_base_options o = {}) {
  o.warn = [](const std::string& m) { FAIL("unexpected warning: " << m); };
  return o;
}

/// τ of least Σ w τ² with SᵀE τ = Sᵀ v, and λ from v − E τ = Aᵀ λ, in long double by the
/// projected Euler–Lagrange equations and a pseudo-inverse (JacobiSVD), Ṡ by duals of S.
std::pair<VectorXd, VectorXd> projected_euler_lagrange(const nhdyn_ref::model<LD>& ref, const wheeled_base<double>& c,
                                                       const VectorXd& q, const VectorXd& eta, const VectorXd& eta_dot) {
  const auto cl = c.cast<LD>();
  using ML = nhdyn_ref::mat<LD>;
  using VL = nhdyn_ref::vec<LD>;
  const VL ql = q.cast<LD>(), el = eta.cast<LD>(), edl = eta_dot.cast<LD>();
  const ML S = cl.S(ql), E = cl.E(ql), A = cl.A(ql);
  const VL qd = S * el;
  using D = dual<LD, 1>;
  vecN<D, dynamic> qq(ql.size());
  for (Eigen::Index j = 0; j < ql.size(); ++j) qq(j) = D(ql(j), {qd(j)});
  const auto SD = cl.S(qq);
  ML Sd(S.rows(), S.cols());
  for (Eigen::Index i = 0; i < S.rows(); ++i)
    for (Eigen::Index j = 0; j < S.cols(); ++j) Sd(i, j) = SD(i, j).derivative(0);
  const VL qdd = S * edl + Sd * el;
  const VL v = nhdyn_ref::mass_matrix<LD>(ref, ql) * qdd + nhdyn_ref::coriolis<LD>(ref, ql, qd) + nhdyn_ref::gravity<LD>(ref, ql);
  // least Σ w τ²: τ = W^{-1/2} (SᵀE W^{-1/2})⁺ Sᵀ v
  const int p = c.p();
  VL wi(p);
  for (int a = 0; a < p; ++a) wi(a) = 1 / std::sqrt(LD(c.weights()[std::size_t(a)]));
  const ML B = S.transpose() * E * wi.asDiagonal();
  const VL tau = wi.asDiagonal() * VL(B.jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(VL(S.transpose() * v)));
  const VL lambda = (A * A.transpose()).ldlt().solve(A * (v - E * tau));
  return {tau.cast<double>(), lambda.cast<double>()};
}

}  // namespace

TEST_CASE("wheeled_base: the shipped bases' sizes, eta, tau and lambda names, mobility", "[wheel_kinds]") {
  struct expect {
    std::string file;
    int n, k, p, mobility, steerability;
    std::vector<std::string> eta_head;
  };
  for (const auto& e : std::vector<expect>{
           {"mecanum_arm.json", 12, 4, 9, 3, 0, {"base_x", "base_y", "base_yaw", "arm_1_joint"}},
           {"omni3_arm.json", 11, 3, 8, 3, 0, {"base_x", "base_y", "base_yaw", "arm_1_joint"}},
           {"castor_drive_arm.json", 15, 7, 8, 2, 0, {"wheel_left_joint", "wheel_right_joint", "arm_shoulder_pan_joint"}},
           {"powered_castors_arm.json", 19, 8, 16, 3, 0, {"base_x", "base_y", "base_yaw", "torso_lift_joint"}},
           {"mobile_manipulator_castors.json", 19, 7, 12, 2, 0, {"wheel_left_joint", "wheel_right_joint", "torso_lift_joint"}}}) {
    INFO(e.file);
    const auto r = load(e.file);
    const auto& c = base_of(r);
    CHECK(c.dof() == e.n);
    CHECK(c.k() == e.k);
    CHECK(c.m() == e.n - e.k);
    CHECK(c.p() == e.p);
    CHECK(c.mobility() == e.mobility);
    CHECK(c.steerability() == e.steerability);
    CHECK(c.mobility_note().empty());
    const auto eta = r.eta_names();
    REQUIRE(eta.size() == std::size_t(e.n - e.k));
    for (std::size_t i = 0; i < e.eta_head.size(); ++i) CHECK(eta[i] == e.eta_head[i]);
    // the castors' joints are neither in η nor actuated by default
    const auto tau = c.tau_names(r.model.joint_names());
    for (const auto& t : tau) CHECK(t.rfind("base_", 0) != 0);
    if (e.file != "powered_castors_arm.json")
      for (const auto& t : tau) CHECK(t.find("caster") == std::string::npos);
    CHECK(int(c.lambda_names().size()) == e.k);
  }
  // the two coaxial drive wheels' lateral rows are kept once: lateral, rolling, rolling, then the castors'
  const auto names = base_of(load("castor_drive_arm.json")).lambda_names();
  CHECK(names == std::vector<std::string>{"wheel_left_joint.lateral", "wheel_left_joint.rolling", "wheel_right_joint.rolling",
                                          "caster_front_wheel_joint.lateral", "caster_front_wheel_joint.rolling",
                                          "caster_rear_wheel_joint.lateral", "caster_rear_wheel_joint.rolling"});
}

TEST_CASE("wheeled_base: A = the reference rows from tree_kinematics; A S = 0; S_into over another q's S = S", "[wheel_kinds]") {
  std::mt19937 rng(31);
  for (const auto& file : shipped) {
    INFO(file);
    const auto r = load(file);
    const auto& c = base_of(r);
    for (int trial = 0; trial < 10; ++trial) {
      const VectorXd q = random_q(c.dof(), rng);
      const MatrixXd A = c.A(q), S = c.S(q);
      const MatrixXd Aref = wheeled_base<double>::reference_A(r.model, c, q);
      CHECK((A - Aref).cwiseAbs().maxCoeff() <= 1e-14);
      CHECK((A * S).cwiseAbs().maxCoeff() <= 1e-13 * (1 + S.cwiseAbs().maxCoeff()));
      // the rows are independent, and S's columns a basis of A's null space
      CHECK(Eigen::JacobiSVD<MatrixXd>(A).singularValues().minCoeff() > 1e-3);
      CHECK(Eigen::FullPivLU<MatrixXd>(S).rank() == c.m());
      MatrixXd Si = c.S(VectorXd(random_q(c.dof(), rng)));
      c.S_into(q, Si);
      CHECK(Si == S);
      const VectorXd eta = random_vec(c.m(), rng), v = random_vec(c.dof(), rng);
      CHECK((apply_S(c, q, eta) - S * eta).cwiseAbs().maxCoeff() <= 1e-13 * (1 + (S * eta).norm()));
      CHECK((apply_St(c, q, v) - S.transpose() * v).cwiseAbs().maxCoeff() <= 1e-13 * (1 + v.norm() * S.norm()));
    }
  }
}

TEST_CASE("wheeled_base: contact points do not move along any constrained direction (finite differences of positions)",
          "[wheel_kinds]") {
  std::mt19937 rng(5);
  for (const auto& file : shipped) {
    INFO(file);
    const auto r = load(file);
    const auto& c = base_of(r);
    const tree_kinematics<double> kin(r.model);
    const auto joints = r.model.joint_names();
    for (int trial = 0; trial < 5; ++trial) {
      const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng);
      const VectorXd qd = c.S(q) * eta;
      for (const auto& row : c.rows()) {
        const wheel& w = c.wheels()[std::size_t(row.wheel)];
        const int spin = int(std::find(joints.begin(), joints.end(), w.spin) - joints.begin());
        // the wheel body's material point at the contact at q: the centre (its spin joint's
        // origin, the body's origin in these URDFs) minus r e_z
        const auto X = kin.frame(q, spin + 1);
        const Eigen::Vector3d P = X.p - w.radius * Eigen::Vector3d::UnitZ();
        const Eigen::Vector3d p_local = X.R.transpose() * (P - X.p);
        const double h = 1e-5;
        const Eigen::Vector3d v = (kin.point(VectorXd(q + h * qd), spin + 1, p_local) - kin.point(VectorXd(q - h * qd), spin + 1, p_local)) / (2 * h);
        // the row's floor-plane direction at q, from the spin joint's axis (in its body's frame for
        // a URDF, whose body frame is the joint frame)
        const Eigen::Vector3d a = X.R * r.model[spin].axis;
        REQUIRE(std::hypot(a.x(), a.y()) > 0.999);
        const Eigen::Vector3d f = a.cross(Eigen::Vector3d::UnitZ()).normalized(), l = Eigen::Vector3d::UnitZ().cross(f);
        const Eigen::Vector3d u = row.kind == wheel_row::lateral ? l
                                  : row.kind == wheel_row::rolling
                                      ? f
                                      : Eigen::Vector3d(std::cos(w.roller_angle) * l + std::sin(w.roller_angle) * f);
        CHECK(std::abs(u.dot(v)) <= 1e-8 * (1 + qd.norm()));
        CHECK(std::abs(v.z()) <= 1e-8 * (1 + qd.norm()));
      }
    }
  }
}

TEST_CASE("wheeled_base: the lift's analytic q_ddot = S eta_dot + Sdot eta with Sdot by duals and by central differences",
          "[wheel_kinds]") {
  std::mt19937 rng(8);
  for (const auto& file : shipped) {
    INFO(file);
    const auto r = load(file);
    const auto& c = base_of(r);
    for (int trial = 0; trial < 10; ++trial) {
      const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng);
      const MatrixXd S = c.S(q);
      const VectorXd qd = S * eta;
      const MatrixXd Sd = c.Sdot(q, qd);
      const double h = 1e-6;
      const MatrixXd Sd_fd = (c.S(VectorXd(q + h * qd)) - c.S(VectorXd(q - h * qd))) / (2 * h);
      CHECK((Sd - Sd_fd).cwiseAbs().maxCoeff() <= 1e-7 * (1 + Sd.cwiseAbs().maxCoeff()));
      const auto xi = lift(c)(q, eta, eta_dot);
      CHECK(rel(xi.qd, qd) <= 1e-14);
      CHECK(rel(xi.qdd, S * eta_dot + Sd * eta) <= 1e-13);
    }
  }
}

TEST_CASE("wheeled_base: tau and lambda = the projected Euler-Lagrange equations with the least-norm tau (long double); "
          "the Lagrange-multiplier form holds for id and fd; power",
          "[wheel_kinds]") {
  std::mt19937 rng(1996);
  for (const auto& file : shipped) {
    INFO(file);
    const auto r = load(file);
    const auto& c = base_of(r);
    const auto ref = nhdyn_ref::from_tree<LD>(r.model);
    const auto refd = nhdyn_ref::from_tree<double>(r.model);
    const auto id = inverse_dynamics_with_forces(r.model, c);
    const auto id_plain = inverse_dynamics(r.model, c);  // project ∘ rne ∘ lift with the lift's factors
    const auto fd = nh_forward_dynamics(r.model, c);
    for (int trial = 0; trial < 3; ++trial) {
      const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng, 2);
      const auto f = id(q, eta, eta_dot);
      REQUIRE(f.tau.size() == c.p());
      REQUIRE(f.lambda.size() == c.k());
      CHECK(rel(id_plain(q, eta, eta_dot), f.tau) <= 1e-14);
      const auto [tau, lambda] = projected_euler_lagrange(ref, c, q, eta, eta_dot);
      CHECK(rel(f.tau, tau) <= 1e-11);
      CHECK(rel(f.lambda, lambda) <= 1e-11);
      // M q̈ + h = E τ + Aᵀ λ and A q̈ + Ȧ q̇ = 0 (the reference's M, C, g; Ȧq̇ by duals of A)
      const MatrixXd S = c.S(q), A = c.A(q), E = c.E(q);
      const VectorXd qd = S * eta, qdd = S * eta_dot + c.Sdot(q, qd) * eta;
      const MatrixXd M = nhdyn_ref::mass_matrix<double>(refd, q);
      const VectorXd hq = nhdyn_ref::coriolis<double>(refd, q, qd) + nhdyn_ref::gravity<double>(refd, q);
      const VectorXd res = M * qdd + hq - E * f.tau - A.transpose() * f.lambda;
      CHECK(res.cwiseAbs().maxCoeff() <= 1e-9 * (1 + (M * qdd).norm() + hq.norm()));
      using D = dual<double, 1>;
      vecN<D, dynamic> qq(c.dof());
      for (int j = 0; j < c.dof(); ++j) qq(j) = D(q(j), {qd(j)});
      const auto AD = c.A(qq);
      MatrixXd Ad(c.k(), c.dof());
      for (int i = 0; i < c.k(); ++i)
        for (int j = 0; j < c.dof(); ++j) Ad(i, j) = AD(i, j).derivative(0);
      CHECK((A * qdd + Ad * qd).cwiseAbs().maxCoeff() <= 1e-12 * (1 + qdd.norm() + qd.norm()));
      // the forward dynamics of the least-norm τ gives η̇ back; of another τ with the same SᵀEτ too
      CHECK(rel(fd(q, eta, VectorXd(f.tau)), eta_dot) <= 1e-9);
      if (c.p() > c.m()) {
        const MatrixXd B = S.transpose() * E;
        const Eigen::FullPivLU<MatrixXd> lu(B);
        const MatrixXd N = lu.kernel();
        REQUIRE(N.cols() == c.p() - c.m());
        const VectorXd other = f.tau + N * random_vec(int(N.cols()), rng, 50);
        CHECK(rel(fd(q, eta, other), eta_dot) <= 1e-9);
        CHECK(other.squaredNorm() > f.tau.squaredNorm());  // the least norm
      }
      // power: λ does no work; τ's power is the energy's rate
      CHECK(std::abs(qd.dot(A.transpose() * f.lambda)) <= 1e-12 * (1 + f.lambda.norm() * qd.norm()));
      const LD dE = nhdyn_ref::energy_rate<LD>(ref, q.cast<LD>(), qd.cast<LD>(), qdd.cast<LD>());
      const double power = f.tau.dot(E.transpose() * qd);
      CHECK(std::abs(double(dE) - power) <= 1e-10 * (1 + std::abs(double(dE)) + f.tau.norm() * qd.norm()));
    }
  }
}

TEST_CASE("inverse_dynamics on a tree: evaluate into a reused tau = the composition's tau bit for bit, for every "
          "robot file's constraint, in double and in duals; its errors name tau, eta and eta_dot",
          "[wheel_kinds]") {
  std::mt19937 rng(2026);
  for (const char* file : every_robot_file) {
    INFO(file);
    const auto r = load(file);
    std::visit(
        [&](const auto& c) {
          const auto id = inverse_dynamics(r.model, c);
          const auto composition = lift(c) | rne(r.model) | project(c);  // ξ, v and τ as new vectors
          const int p = actuator_count(c);
          VectorXd tau = VectorXd::Constant(p, 7.0);  // reused across the states: every entry rewritten
          for (int trial = 0; trial < 3; ++trial) {
            const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng, 2);
            id.evaluate(q, eta, eta_dot, tau);
            const VectorXd call = composition(q, eta, eta_dot);
            REQUIRE(call.size() == p);
            CHECK((tau.array() == call.array()).all());
            const VectorXd id_call = id(q, eta, eta_dot);  // evaluate into a new τ
            CHECK((id_call.array() == call.array()).all());
            // into a block of a larger matrix (a map: the caller's own storage)
            MatrixXd out = MatrixXd::Zero(p, 2);
            Eigen::Map<VectorXd> col(out.col(1).data(), p);
            id.evaluate(q, eta, eta_dot, col);
            CHECK((out.col(1).array() == call.array()).all());
            CHECK(out.col(0).isZero(0));
          }
          using D = dual<double, 1>;
          {  // a tree of duals with the double constraint: the composition's path (τ's scalar is
             // not evaluate's), the double τ's values within rounding (the general kernels')
            const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng);
            const VectorXd t0 = id(q, eta, eta_dot);
            const vecN<D, dynamic> tt = inverse_dynamics(r.model.cast<D>(), c)(q, eta, eta_dot);
            REQUIRE(tt.size() == p);
            for (int j = 0; j < p; ++j) CHECK(std::abs(tt(j).value() - t0(j)) <= 1e-12 * (1 + t0.norm()));
          }
          // duals along η: the same numbers and derivatives as the composition's
          const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng);
          vecN<D, dynamic> ed(c.m());
          for (int j = 0; j < c.m(); ++j) ed(j) = D(eta(j), {j == 0 ? 1.0 : 0.0});
          vecN<D, dynamic> td(p);
          id.evaluate(q, ed, ed, td);
          const vecN<D, dynamic> cd = composition(q, ed, ed);
          for (int j = 0; j < p; ++j) {
            CHECK(td(j).value() == cd(j).value());
            CHECK(td(j).derivative(0) == cd(j).derivative(0));
          }
          // errors: the caller's names
          VectorXd short_tau(p + 1), bad = eta;
          CHECK_THROWS_WITH(id.evaluate(q, eta, eta_dot, short_tau), Catch::Matchers::Contains("tau has"));
          CHECK_THROWS_WITH(id.evaluate(q, VectorXd(eta.head(c.m() - 1)), eta_dot, tau), Catch::Matchers::Contains("eta has"));
          bad(0) = std::numeric_limits<double>::quiet_NaN();
          CHECK_THROWS_WITH(id.evaluate(q, eta, bad, tau), Catch::Matchers::Contains("eta_dot[0] is not finite"));
        },
        *r.constraint);
  }
}

TEST_CASE("wheeled_base past the lift's inline memo (k |eta ∩ W| > 24): a drive axle and five castors; evaluate = the "
          "call bit for bit, tau and lambda = the projected Euler-Lagrange equations, the memo copied and moved",
          "[wheel_kinds]") {
  // k = 3 (the axle) + 5 × 2 (the castors) = 13 rows, mobility 2: S_D has 13 × 2 = 26 entries,
  // past the memo's 24 inline ones (its block then comes from the thread's scratch_blocks)
  const std::vector<test_wheel> ws = {{"fixed", 0, 0.3},          {"fixed", 0, -0.3},         {"castor", 0.5, 0.3},
                                      {"castor", 0.5, -0.3},      {"castor", -0.5, 0.3},      {"castor", -0.5, -0.3},
                                      {"castor", 0.6, 0}};
  const tree<double> t = planar_tree(ws);
  const wheeled_base<double> c(t, wheels_of(ws), quiet());
  REQUIRE(c.k() == 13);
  REQUIRE(c.mobility() == 2);
  const auto ref = nhdyn_ref::from_tree<LD>(t);
  const auto id = inverse_dynamics(t, c);
  const auto idf = inverse_dynamics_with_forces(t, c);
  const auto fd = nh_forward_dynamics(t, c);
  nh_forward_dynamics_result<double> into;
  std::mt19937 rng(26);
  VectorXd tau = VectorXd::Constant(c.p(), 7.0);
  for (int trial = 0; trial < 3; ++trial) {
    const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng, 2);
    id.evaluate(q, eta, eta_dot, tau);
    const VectorXd call = id(q, eta, eta_dot);
    CHECK((tau.array() == call.array()).all());
    const auto f = idf(q, eta, eta_dot);
    const auto [tau_ref, lambda_ref] = projected_euler_lagrange(ref, c, q, eta, eta_dot);
    CHECK(rel(call, tau_ref) <= 1e-11);
    CHECK(rel(f.lambda, lambda_ref) <= 1e-11);
    fd.evaluate(q, eta, call, into);
    CHECK(rel(into.eta_dot, eta_dot) <= 1e-9);
    CHECK((into.eta_dot.array() == fd(q, eta, call).array()).all());
    // the memo: copies and moves keep S_D; the projection with any of them = the call's τ
    VectorXd qd(c.dof()), qdd(c.dof());
    auto m1 = c.lift_into(q, eta, eta_dot, qd, qdd);
    const VectorXd v = rne(t)(q, qd, qdd);
    auto m2 = m1;              // a copy: a block of its own
    auto m3 = std::move(m1);   // a move: the block changes hands
    decltype(m2) m4;
    m4 = m2;                   // copy-assigned over an empty memo
    m2 = std::move(m3);        // move-assigned over a copy
    CHECK((c.project_with(q, v, m2).array() == call.array()).all());
    CHECK((c.project_with(q, v, m4).array() == call.array()).all());
  }
}

TEST_CASE("nh_forward_dynamics on a tree: evaluate into one reused result = the plain call bit for bit, for every "
          "robot file's constraint; η̇ against dense SᵀMS and Eigen's LDLT, and against the inverse dynamics",
          "[wheel_kinds]") {
  std::mt19937 rng(2027);
  nh_forward_dynamics_result<double> out;  // one result for every file: sizes change from file to file
  nh_forward_dynamics_result<dual<double, 1>> dout;
  for (const char* file : every_robot_file) {
    INFO(file);
    const auto r = load(file);
    std::visit(
        [&](const auto& c) {
          const auto fd = nh_forward_dynamics(r.model, c);
          const auto id = inverse_dynamics(r.model, c);
          const int n = c.dof(), m = c.m(), p = actuator_count(c);
          for (int trial = 0; trial < 3; ++trial) {
            const VectorXd q = random_q(n, rng), eta = random_vec(m, rng), eta_dot = random_vec(m, rng, 2);
            const VectorXd tau = id(q, eta, eta_dot);
            fd.evaluate(q, eta, tau, out);
            const VectorXd call = fd(q, eta, tau);  // into the result its thread keeps
            REQUIRE(out.eta_dot.size() == m);
            CHECK((out.eta_dot.array() == call.array()).all());
            nh_forward_dynamics_result<double> fresh;  // no earlier file's sizes or numbers
            fd.evaluate(q, eta, tau, fresh);
            CHECK((fresh.eta_dot.array() == call.array()).all());
            // the inverse dynamics' τ gives back its η̇ (the least-norm τ too: SᵀEτ is what it solves)
            CHECK((out.eta_dot - eta_dot).norm() <= 1e-9 * (1 + eta_dot.norm()));
            // the fields against dense products of the constraint's own S(q), E(q) and the CRBA's M(q)
            const MatrixXd S = c.S(q), E = input_map(c, q), M = mass_matrix(r.model)(q);
            CHECK((out.S.array() == S.array()).all());
            CHECK((out.mass.array() == M.array()).all());
            const MatrixXd Me = S.transpose() * M * S;
            CHECK((out.reduced_inertia - Me).norm() <= 1e-13 * Me.norm());
            // h_η: reduced_bias takes evaluate's steps (bit for bit); against Sᵀ rne(q, Sη, Ṡη)
            // with S dense and Ṡη by the constraint's Ṡ (S's derivative, not the lift's Ȧq̇)
            const VectorXd h = fd.reduced_bias(q, eta);
            CHECK((out.reduced_bias.array() == h.array()).all());
            const VectorXd qd = S * eta;
            const VectorXd h_ref = S.transpose() * rne(r.model)(q, qd, VectorXd(apply_Sdot(c, q, qd, eta)));
            CHECK((h - h_ref).norm() <= 1e-12 * (1 + h_ref.norm()));
            const VectorXd u = S.transpose() * E * tau;
            CHECK((out.actuation - u).norm() <= 1e-12 * (1 + u.norm()));
            const VectorXd ref = Me.ldlt().solve(u - h);
            CHECK((out.eta_dot - ref).norm() <= 1e-9 * (1 + ref.norm()));
          }
          // duals along τ_0, into a dual result reused across the files: values and derivatives
          // as the plain call's, and ∂η̇/∂τ_0 = M_η⁻¹ SᵀE e_0 by Eigen's LDLT of the dense M_η
          using D = dual<double, 1>;
          const VectorXd q = random_q(n, rng), eta = random_vec(m, rng), tau = random_vec(p, rng, 3);
          vecN<D, dynamic> td(p);
          for (int j = 0; j < p; ++j) td(j) = D(tau(j), {j == 0 ? 1.0 : 0.0});
          fd.evaluate(q, eta, td, dout);
          const vecN<D, dynamic> dc = fd(q, eta, td);
          const MatrixXd S = c.S(q), E = input_map(c, q), M = mass_matrix(r.model)(q);
          const VectorXd b0 = (S.transpose() * M * S).ldlt().solve(S.transpose() * E.col(0));
          REQUIRE(dout.eta_dot.size() == m);
          for (int j = 0; j < m; ++j) {
            CHECK(dout.eta_dot(j).value() == dc(j).value());
            CHECK(dout.eta_dot(j).derivative(0) == dc(j).derivative(0));
            CHECK(std::abs(dout.eta_dot(j).derivative(0) - b0(j)) <= 1e-9 * (1 + b0.norm()));
          }
          // errors: the caller's names
          VectorXd bad = eta;
          bad(0) = std::numeric_limits<double>::quiet_NaN();
          CHECK_THROWS_WITH(fd.evaluate(q, eta, VectorXd(tau.head(p - 1)), out), Catch::Matchers::StartsWith("tau has"));
          CHECK_THROWS_WITH(fd.evaluate(q, bad, tau, out), Catch::Matchers::StartsWith("eta[0] is not finite"));
          CHECK_THROWS_WITH(fd.evaluate(VectorXd(q.head(n - 1)), eta, tau, out), Catch::Matchers::StartsWith("q has"));
        },
        *r.constraint);
  }
}

TEST_CASE("wheeled_base: the forward dynamics' A, B (analytic and by duals) = central differences of the forward dynamics",
          "[wheel_kinds]") {
  // with more actuators than η (mecanum, powered castors) ∂η̇/∂x has the term (∂B/∂x)(τ − τ_id):
  // the finite differences of nh_forward_dynamics itself are the reference both are held to
  std::mt19937 rng(77);
  for (const auto& file : {"mecanum_arm.json", "powered_castors_arm.json", "castor_drive_arm.json"}) {
    INFO(file);
    const auto r = load(file);
    const auto& c = base_of(r);
    const int n = c.dof(), m = c.m(), p = c.p();
    const VectorXd q = random_q(n, rng), eta = random_vec(m, rng), tau = random_vec(p, rng, 5);
    const auto fd = nh_forward_dynamics(r.model, c);
    const auto an = forward_dynamics_derivatives(r.model, c)(q, eta, tau);
    const auto du = forward_dynamics_linearizer(r.model, c)(q, eta, tau);
    const double h = 1e-6;
    MatrixXd A(m, n + m), B(m, p);
    for (int j = 0; j < n + m; ++j) {
      VectorXd qp = q, qm = q, ep = eta, em = eta;
      (j < n ? qp(j) : ep(j - n)) += h;
      (j < n ? qm(j) : em(j - n)) -= h;
      A.col(j) = (fd(qp, ep, tau) - fd(qm, em, tau)) / (2 * h);
    }
    for (int j = 0; j < p; ++j) {
      VectorXd tp = tau, tm = tau;
      tp(j) += h, tm(j) -= h;
      B.col(j) = (fd(q, eta, tp) - fd(q, eta, tm)) / (2 * h);
    }
    const double sa = 1 + A.cwiseAbs().maxCoeff(), sb = 1 + B.cwiseAbs().maxCoeff();
    CHECK((an.ss.A.bottomRows(m) - A).cwiseAbs().maxCoeff() <= 1e-6 * sa);
    CHECK((an.ss.B.bottomRows(m) - B).cwiseAbs().maxCoeff() <= 1e-7 * sb);
    CHECK((du.A.bottomRows(m) - A).cwiseAbs().maxCoeff() <= 1e-6 * sa);
    CHECK((du.B.bottomRows(m) - B).cwiseAbs().maxCoeff() <= 1e-7 * sb);
    CHECK((an.ss.A - du.A).cwiseAbs().maxCoeff() <= 1e-9 * sa);
  }
}

TEST_CASE("wheeled_base: weights choose among the torques that produce the motion", "[wheel_kinds]") {
  const auto r = load("mecanum_arm.json");
  wheeled_base_options o = quiet();
  o.weights = {{"wheel_fl_joint", 4.0}, {"wheel_rr_joint", 0.25}};
  const wheeled_base<double> c(r.model, base_of(r).wheels(), o);
  std::mt19937 rng(3);
  const auto ref = nhdyn_ref::from_tree<LD>(r.model);
  const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng);
  const auto f = inverse_dynamics_with_forces(r.model, c)(q, eta, eta_dot);
  const auto [tau, lambda] = projected_euler_lagrange(ref, c, q, eta, eta_dot);
  CHECK(rel(f.tau, tau) <= 1e-11);
  const VectorXd plain = inverse_dynamics(r.model, base_of(r))(q, eta, eta_dot);
  CHECK(rel(f.tau, plain) > 1e-3);  // the weights moved the torques
  CHECK(std::abs(f.tau(0)) < std::abs(plain(0)));  // …off the heavily weighted wheel
}

TEST_CASE("wheeled_base: a mecanum base turns its wheels at the textbook mecanum rates", "[wheel_kinds]") {
  // Lynch and Park, Modern Robotics eq. 13.10: with the body twist (ω, v_x, v_y), half-length
  // l and half-width w, φ̇ = (v_x ∓ v_y ∓ (l + w) ω)/r: front-left (−, −), front-right (+, +),
  // rear-left (+, −), rear-right (−, +)
  const auto r = load("mecanum_arm.json");
  const auto& c = base_of(r);
  const double R = 0.0475, l = 0.228, w = 0.158;
  std::mt19937 rng(45);
  const auto joints = r.model.joint_names();
  const auto at = [&](const std::string& j) { return int(std::find(joints.begin(), joints.end(), j) - joints.begin()); };
  for (int trial = 0; trial < 10; ++trial) {
    const VectorXd q = random_q(c.dof(), rng);
    VectorXd eta = random_vec(c.m(), rng);  // η = (ẋ, ẏ, ψ̇, arm): the world-frame base velocity
    const double psi = q(2), vx = std::cos(psi) * eta(0) + std::sin(psi) * eta(1), vy = -std::sin(psi) * eta(0) + std::cos(psi) * eta(1),
                 om = eta(2);
    const VectorXd qd = c.S(q) * eta;
    CHECK(qd(at("wheel_fl_joint")) == Approx((vx - vy - (l + w) * om) / R).epsilon(1e-12));
    CHECK(qd(at("wheel_fr_joint")) == Approx((vx + vy + (l + w) * om) / R).epsilon(1e-12));
    CHECK(qd(at("wheel_rl_joint")) == Approx((vx + vy - (l + w) * om) / R).epsilon(1e-12));
    CHECK(qd(at("wheel_rr_joint")) == Approx((vx - vy + (l + w) * om) / R).epsilon(1e-12));
  }
}

TEST_CASE("wheeled_base: 'wheels' = wheeled_base with the same two fixed wheels (tau, lambda, eta_dot to 1e-12)", "[wheel_kinds]") {
  const auto r = load("mobile_manipulator_wheels.json");
  const auto& rw = std::get<rolling_wheels<double>>(*r.constraint);
  const wheeled_base<double> wb(r.model, {{wheel_kind::fixed, "wheel_left_joint", "", 0.1}, {wheel_kind::fixed, "wheel_right_joint", "", 0.1}},
                                quiet());
  REQUIRE(wb.k() == 3);
  REQUIRE(wb.eta_names(r.model.joint_names()) == rw.eta_names(r.model.joint_names()));
  REQUIRE(wb.tau_names(r.model.joint_names()) == rw.eta_names(r.model.joint_names()));
  const auto id1 = inverse_dynamics_with_forces(r.model, rw);
  const auto id2 = inverse_dynamics_with_forces(r.model, wb);
  const auto fd1 = nh_forward_dynamics(r.model, rw);
  const auto fd2 = nh_forward_dynamics(r.model, wb);
  std::mt19937 rng(12);
  for (int trial = 0; trial < 20; ++trial) {
    const VectorXd q = random_q(rw.dof(), rng), eta = random_vec(rw.m(), rng), eta_dot = random_vec(rw.m(), rng);
    const auto a = id1(q, eta, eta_dot), b = id2(q, eta, eta_dot);
    CHECK(rel(b.tau, a.tau) <= 1e-12);
    CHECK(rel(b.lambda, a.lambda) <= 1e-12);
    const VectorXd tau = random_vec(rw.m(), rng, 5);
    CHECK(rel(fd2(q, eta, tau), fd1(q, eta, tau)) <= 1e-12);
  }
}

TEST_CASE("wheeled_base: wheels on one planar body take the closed-form kernel, which gives the general kernel's S, "
          "q_ddot, tau and lambda", "[wheel_kinds]") {
  // The general kernel (frames along each wheel's path) runs for any scalar but the model's: a
  // long-double q (S, the lift) or duals of zero derivative (τ, λ: the same double arithmetic
  // through every stage) take it on the same model. Both kernels against each other, on bases
  // whose wheels hang from the body directly (mecanum, omni, an axle) or through swivel joints
  // (castors), with scaled radii.
  const auto r = load("mobile_manipulator_wheels.json");
  const wheeled_base<double> axle(r.model, {{wheel_kind::fixed, "wheel_left_joint", "", 0.1},
                                            {wheel_kind::fixed, "wheel_right_joint", "", 0.1}}, quiet());
  std::vector<std::pair<std::string, io::robot_model>> models;
  for (const auto& f : shipped) models.emplace_back(f, load(f));
  std::mt19937 rng(41);
  const auto check = [&](const wheeled_base<double>& c, const tree<double>& t) {
    const auto id = inverse_dynamics_with_forces(t, c);
    using D = dual<double, 1>;
    const auto id_general = [&](const VectorXd& q, const VectorXd& eta, const VectorXd& eta_dot) {
      const auto f = id(q.cast<D>().eval(), eta.cast<D>().eval(), eta_dot.cast<D>().eval());
      struct {
        VectorXd tau, lambda;
      } out{f.tau.unaryExpr([](const D& x) { return x.value(); }), f.lambda.unaryExpr([](const D& x) { return x.value(); })};
      return out;
    };
    const auto relm = [](const MatrixXd& a, const MatrixXd& b) {
      return (a - b).cwiseAbs().maxCoeff() / (1 + b.cwiseAbs().maxCoeff());
    };
    for (int trial = 0; trial < 10; ++trial) {
      const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng);
      const Eigen::Matrix<LD, Eigen::Dynamic, 1> ql = q.cast<LD>();
      const MatrixXd S = c.S(q);
      CHECK(relm(S, MatrixXd(c.S(ql).cast<double>())) <= 5e-15);
      CHECK((c.A(q) * S).cwiseAbs().maxCoeff() <= 1e-13 * (1 + S.cwiseAbs().maxCoeff()));  // with scaled radii too
      const auto xi = lift(c)(q, eta, eta_dot);
      const auto xl = lift(c)(ql, eta.cast<LD>().eval(), eta_dot.cast<LD>().eval());
      CHECK(rel(xi.qd, VectorXd(xl.qd.cast<double>())) <= 5e-15);
      CHECK(rel(xi.qdd, VectorXd(xl.qdd.cast<double>())) <= 2e-14);
      // τ and λ then differ from the general kernel's by rounding only, no more than the general
      // kernel's own double and long-double results differ on the castor bases (the projected
      // Euler–Lagrange test above checks both against the reference)
      const auto a = id(q, eta, eta_dot);
      const auto b = id_general(q, eta, eta_dot);
      CHECK(rel(a.tau, b.tau) <= 1e-14);
      CHECK(rel(a.lambda, b.lambda) <= 2e-12);  // λ: 6e-13 between double and duals on castor_drive_arm with one kernel on both sides
    }
  };
  for (const auto& [file, m] : models) {
    INFO(file);
    const auto& c = base_of(m);
    CHECK(c.wheels_on_one_body());
    check(c, m.model);
    const auto scaled = c.with_radius_factor(1.07);  // the constants follow the radii
    CHECK(scaled.wheels_on_one_body());
    check(scaled, m.model);
    CHECK(c.cast<LD>().wheels_on_one_body());
  }
  INFO("the axle");
  CHECK(axle.wheels_on_one_body());
  check(axle, r.model);
}

TEST_CASE("wheeled_base: an unforced 10 s motion of each shipped base keeps A q_dot = 0 and the energy, whose error falls as RK4's h^4", "[wheel_kinds][long]") {
  for (const auto& file : shipped) {
    INFO(file);
    const auto r = load(file);
    const auto& c = base_of(r);
    // without gravity: under gravity the arms' light outer links whip at ~90 rad/s and
    // 5000 rad/s² when they swing through (omni3_arm at 0.5 s), which RK4 at a few ms does not
    // resolve; gravity's work is checked by the power test above
    const auto model = r.model.with_gravity({0, 0, 0});
    const auto ref = nhdyn_ref::from_tree<double>(model);
    const auto fd = nh_forward_dynamics(model, c);
    const int n = c.dof(), m = c.m();
    VectorXd q = VectorXd::Zero(n);
    q(0) = 0.5, q(2) = 0.3;
    std::mt19937 rng(10);
    VectorXd eta = random_vec(m, rng, 0.5);
    const auto joints = r.model.joint_names();
    for (int i = 0; i < m; ++i)  // set the base moving: 0.5 m/s or a few rad/s of wheel
      if (joints[std::size_t(c.eta_joints()[std::size_t(i)])].find("wheel") != std::string::npos) eta(i) = 5.0 + i;
    const VectorXd tau = VectorXd::Zero(c.p());
    const auto f = [&](const VectorXd& x) {
      VectorXd dx(n + m);
      dx << apply_S(c, x.head(n), x.tail(m)), fd(x.head(n), x.tail(m), tau);
      return dx;
    };
    VectorXd x0(n + m);
    x0 << q, eta;
    const auto energy = [&](const VectorXd& x) {
      return nhdyn_ref::energy<double>(ref, VectorXd(x.head(n)), VectorXd(apply_S(c, x.head(n), x.tail(m))));
    };
    const double E0 = energy(x0);
    // RK4 for 10 s at h = 4 ms, and for its first 2 s at 8 ms: RK4's energy error falls as h⁴
    // (16× per halving), so the drift is the integrator's; a wrong Ṡ or λ would leave an error
    // that does not fall
    double worst = 0, speed = 0, err8 = 0, err4_2s = 0;
    VectorXd x = x0;
    for (const double h : {8e-3, 4e-3}) {
      x = x0;
      const int steps = int((h > 5e-3 ? 2 : 10) / h + 0.5);
      for (int step = 1; step <= steps; ++step) {
        const VectorXd k1 = f(x), k2 = f(x + h / 2 * k1), k3 = f(x + h / 2 * k2), k4 = f(x + h * k3);
        x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
        const VectorXd qd = apply_S(c, x.head(n), x.tail(m));
        worst = std::max(worst, (c.A(x.head(n)) * qd).cwiseAbs().maxCoeff());
        speed = std::max(speed, qd.cwiseAbs().maxCoeff());
        if (std::abs(step * h - 2) < h / 2) (h > 5e-3 ? err8 : err4_2s) = std::abs(energy(x) - E0);
      }
    }
    const double err10 = std::abs(energy(x) - E0);
    CHECK(x.allFinite());
    CHECK(worst <= 1e-13 * (1 + speed));
    INFO("energy " << E0 << " J; error after 2 s " << err8 << " J (h = 8 ms), " << err4_2s << " J (4 ms); after 10 s "
                   << err10 << " J (4 ms)");
    CHECK(err10 <= 1e-8 * (1 + std::abs(E0)));
    // h⁴: 16× smaller (8× asked), unless already at rounding (1e-11 of the energy)
    CHECK((err4_2s <= err8 / 8 || err4_2s <= 1e-11 * (1 + std::abs(E0))));
    CHECK((x.head(2) - q.head(2)).norm() > 0.05);  // it did travel
  }
}

TEST_CASE("wheeled_base: rank and mobility of classic layouts", "[wheel_kinds]") {
  SECTION("a car: a fixed rear axle and one steered front wheel (mobility 1, steerability 1)") {
    const std::vector<test_wheel> ws = {{"fixed", 0, 0.3}, {"fixed", 0, -0.3}, {"steered", 0.8, 0}};
    const wheeled_base<double> c(planar_tree(ws), wheels_of(ws), quiet());
    CHECK(c.k() == 5);  // one lateral row for the axle, three rolling rows, the front's lateral row
    CHECK(c.mobility() == 1);
    CHECK(c.steerability() == 1);
    CHECK(c.eta_names(planar_tree(ws).joint_names()) == std::vector<std::string>{"w2_steer", "w2_spin", "arm"});
  }
  SECTION("skid-steer: four fixed wheels on two axles move only along a line") {
    const std::vector<test_wheel> ws = {{"fixed", 0.3, 0.3}, {"fixed", 0.3, -0.3}, {"fixed", -0.3, 0.3}, {"fixed", -0.3, -0.3}};
    const wheeled_base<double> c(planar_tree(ws), wheels_of(ws), quiet());
    CHECK(c.k() == 6);  // two lateral rows (one per axle) and four rolling rows
    CHECK(c.mobility() == 1);
    CHECK(c.mobility_note().find("as a differential drive") != std::string::npos);
  }
  SECTION("three fixed wheels not on one axle cannot move") {
    // two parallel axles (x = ±0.3) allow only a translation along x, which the third wheel's
    // axle (along x) forbids: no instantaneous centre of rotation is common to the three
    const std::vector<test_wheel> ws = {{"fixed", 0.3, 0.3, 0.0}, {"fixed", -0.3, 0.3, 0.0}, {"fixed", 0, -0.3, 1.5707963267948966}};
    const wheeled_base<double> c(planar_tree(ws), wheels_of(ws), quiet());
    CHECK(c.mobility() == 0);
    CHECK(c.mobility_note().find("cannot move") != std::string::npos);
    CHECK(c.m() == 1);  // only the arm
  }
  SECTION("omni wheels at 90° and a castor base are omnidirectional") {
    // the spin axes radial (yaw θ − 90° turns the wheel's +y axis to the direction θ of its place)
    const double t = 2.0943951023931953, h = 1.5707963267948966;
    const std::vector<test_wheel> ws = {{"swedish", 0.3, 0, -h}, {"swedish", 0.3 * std::cos(t), 0.3 * std::sin(t), t - h},
                                        {"swedish", 0.3 * std::cos(-t), 0.3 * std::sin(-t), -t - h}};
    const wheeled_base<double> c(planar_tree(ws), wheels_of(ws, 1.5707963267948966), quiet());
    CHECK(c.mobility() == 3);
    CHECK(c.k() == 3);
  }
}

TEST_CASE("wheeled_base: errors name the wheel, the joint and the configuration", "[wheel_kinds]") {
  const auto msg = [](const auto& f) {
    try {
      f();
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  using Catch::Matchers::Contains;
  SECTION("a castor without a trail") {
    std::vector<test_wheel> ws = {{"fixed", 0, 0.3}, {"fixed", 0, -0.3}, {"castor", 0.5, 0}};
    ws[2].trail = 0;
    CHECK_THAT(msg([&] { wheeled_base<double>(planar_tree(ws), wheels_of(ws), quiet()); }),
               Contains("w2_spin") && Contains("no trail"));
  }
  SECTION("a Swedish wheel with rollers along its axis, an unknown joint, a steered wheel without its joint") {
    const std::vector<test_wheel> ws = {{"swedish", 0.3, 0}, {"swedish", -0.3, 0.3}, {"swedish", -0.3, -0.3}};
    CHECK_THAT(msg([&] { wheeled_base<double>(planar_tree(ws), wheels_of(ws, 0.0), quiet()); }), Contains("roller_angle"));
    auto w = wheels_of(ws, 0.5);
    w[1].spin = "nope";
    CHECK_THAT(msg([&] { wheeled_base<double>(planar_tree(ws), w, quiet()); }), Contains("'nope'") && Contains("w1_spin"));
    w = wheels_of(ws, 0.5);
    w[0].kind = wheel_kind::steered;
    CHECK_THAT(msg([&] { wheeled_base<double>(planar_tree(ws), w, quiet()); }), Contains("steer joint"));
  }
  SECTION("a spin axis that is not horizontal, a swivel axis that is not vertical") {
    const std::vector<test_wheel> ws = {{"fixed", 0, 0.3}, {"fixed", 0, -0.3}};
    tree<double> t = planar_tree(ws);
    auto bodies = t.bodies();
    for (auto& b : bodies)
      if (b.joint_name == "w0_spin") b.axis = Eigen::Vector3d(0, 0.6, 0.8);
    const tree<double> tilted(bodies, t.gravity(), t.name(), t.validation_policy(), t.root_name(), t.frames());
    CHECK_THAT(msg([&] { wheeled_base<double>(tilted, wheels_of(ws), quiet()); }), Contains("w0_spin") && Contains("not horizontal"));
  }
  SECTION("eta of the wrong size or that does not determine the motion; too few actuators") {
    const auto r = load("castor_drive_arm.json");
    wheeled_base_options o = quiet();
    o.eta = {"wheel_left_joint"};
    CHECK_THAT(msg([&] { wheeled_base<double>(r.model, base_of(r).wheels(), o); }), Contains("eta has 1 entries"));
    o.eta = base_of(r).eta_names(r.model.joint_names());
    o.eta[0] = "base_x", o.eta[1] = "base_y";  // the axle's lateral row binds ẋ and ẏ: they are not independent
    CHECK_THAT(msg([&] { wheeled_base<double>(r.model, base_of(r).wheels(), o); }), Contains("not independent"));
    wheeled_base_options a = quiet();
    a.actuated = {"wheel_left_joint"};
    CHECK_THAT(msg([&] { wheeled_base<double>(r.model, base_of(r).wheels(), a); }), Contains("not actuated"));
    a.actuated = base_of(r).tau_names(r.model.joint_names());
    a.actuated.erase(a.actuated.begin());  // the right wheel alone cannot turn and drive
    CHECK_THAT(msg([&] { wheeled_base<double>(r.model, base_of(r).wheels(), a); }), Contains("cannot produce"));
  }
  SECTION("a configuration where eta does not determine the motion names the configuration and the wheels") {
    // a car whose η holds the base's x rate: with the front wheel turned across the rear
    // axle's line (δ = 90°) the base cannot move along its own x, so at heading 0 ẋ is not free
    const std::vector<test_wheel> ws = {{"fixed", 0, 0.3}, {"fixed", 0, -0.3}, {"steered", 0.8, 0}};
    const tree<double> t = planar_tree(ws);
    wheeled_base_options o = quiet();
    o.eta = {"base_x", "w2_steer", "arm"};
    const wheeled_base<double> c(t, wheels_of(ws), o);
    VectorXd q = VectorXd::Zero(c.dof());
    CHECK_NOTHROW(c.S(q));
    const auto names = t.joint_names();
    q(int(std::find(names.begin(), names.end(), "w2_steer") - names.begin())) = 1.5707963267948966;
    const std::string m = msg([&] { (void)c.S(q); });
    CHECK_THAT(m, Contains("w2_steer = 1.5708") && Contains("w2_spin (steered)") && Contains("do not determine"));
  }
  SECTION("robot files: the file, the wheel and the field") {
    const std::string dir = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/";
    const auto parse = [&](const std::string& constraint) {
      return msg([&] {
        io::parse_robot_file("{\"urdf\": \"../urdf/castor_drive_arm.urdf\", \"base\": {\"type\": \"planar\"}, \"constraint\": " + constraint + "}",
                             dir + "bad.json");
      });
    };
    CHECK_THAT(parse(R"({"type": "wheeled_base", "wheels": [{"kind": "mecanum", "spin": "wheel_left_joint", "radius": 0.1}]})"),
               Contains("bad.json") && Contains("wheels[0]") && Contains("unknown wheel kind 'mecanum'"));
    CHECK_THAT(parse(R"({"type": "wheeled_base", "wheels": [{"kind": "castor", "spin": "caster_front_wheel_joint", "radius": 0.025}]})"),
               Contains("wheels[0]") && Contains("swivel"));
    CHECK_THAT(parse(R"({"type": "wheeled_base", "wheels": [{"kind": "swedish", "spin": "wheel_left_joint", "radius": 0.1, "roller_angle": 120}]})"),
               Contains("roller_angle"));
    CHECK_THAT(parse(R"({"type": "wheeled_base", "wheels": [{"kind": "fixed", "spin": "wheel_left_joint", "radius": 0.0985}], "weights": {"wheel_left_joint": -1}})"),
               Contains("bad.json") && Contains("weight"));
  }
}

TEST_CASE("wheeled_base: a wheel that does not touch the floor warns and goes on", "[wheel_kinds]") {
  std::vector<test_wheel> ws = {{"fixed", 0, 0.3}, {"fixed", 0, -0.3}};
  std::vector<std::string> said;
  wheeled_base_options o;
  o.warn = [&](const std::string& m) { said.push_back(m); };
  auto w = wheels_of(ws);
  w[0].radius = 0.12;  // the centre is 0.1 m above the floor
  const wheeled_base<double> c(planar_tree(ws), w, o);
  REQUIRE(said.size() == 1);
  CHECK(said[0].find("w0_spin") != std::string::npos);
  CHECK(said[0].find("does not touch the floor") != std::string::npos);
}

TEST_CASE("inverse_dynamics with friction on a tree: evaluate and the call = lift | (rne + friction) | project, "
          "the friction's share its projection", "[wheel_kinds]") {
  std::mt19937 rng(2027);
  for (const char* file : {"mecanum_arm.json", "mobile_manipulator.json", "powered_castors_arm.json"}) {
    const auto r = load(file);
    std::visit([&](const auto& c) {
      const auto& t = r.model;
      const int n = t.dof(), p = actuator_count(c);
      std::vector<joint_friction> laws;
      for (int j = 0; j < n; ++j) laws.push_back({0.3 + 0.05 * j, 0.2, -0.15});
      const friction_fn fr(laws, coulomb_law::smooth(0.05));
      const auto id = inverse_dynamics(t, c, {}, fr);
      const auto by_hand = lift(c) | (rne(t) + fr) | project(c);  // ξ, v, τ_f and τ as new vectors
      VectorXd tau = VectorXd::Constant(p, 7.0);
      for (int k = 0; k < 3; ++k) {
        INFO(file << ", state " << k);
        const VectorXd q = random_q(n, rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng);
        id.evaluate(q, eta, eta_dot, tau);
        const VectorXd want = by_hand(q, eta, eta_dot);
        CHECK((tau.array() == want.array()).all());
        CHECK((id(q, eta, eta_dot).array() == want.array()).all());
        // the friction's share is its projection, P linear: τ − τ(no friction) = P τ_f(Sη)
        const VectorXd share = project(c)(q, fr(VectorXd(c.S(q) * eta)));
        CHECK((tau - VectorXd(inverse_dynamics(t, c)(q, eta, eta_dot)) - share).cwiseAbs().maxCoeff() <=
              1e-9 * (1 + tau.cwiseAbs().maxCoeff()));
      }
    }, *r.constraint);
  }
}

TEST_CASE("inverse_dynamics_with_forces on a tree: evaluate into reused (tau, lambda) = the call; tau = "
          "inverse_dynamics' bit for bit; lambda = the composition's and makes v = E tau + A^T lambda",
          "[wheel_kinds]") {
  std::mt19937 rng(2028);
  constrained_forces<double> out;  // reused across the robot files: sizes change
  out.tau = VectorXd::Constant(40, 7.0), out.lambda = VectorXd::Constant(1, 7.0);
  for (const char* file : every_robot_file) {
    INFO(file);
    const auto r = load(file);
    std::visit([&](const auto& c) {
      const auto& t = r.model;
      const int n = t.dof();
      std::vector<joint_friction> laws(std::size_t(n), joint_friction{0.25, 0.1, -0.1});
      const friction_fn fr(laws, coulomb_law::smooth(0.05));
      const auto run = [&](const auto& idf, const auto& id, const auto& by_hand, const auto& dyn) {
        for (int trial = 0; trial < 3; ++trial) {
          const VectorXd q = random_q(n, rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng, 2);
          idf.evaluate(q, eta, eta_dot, out);
          const auto call = idf(q, eta, eta_dot);
          CHECK((out.tau.array() == call.tau.array()).all());
          CHECK((out.lambda.array() == call.lambda.array()).all());
          const VectorXd tau = id(q, eta, eta_dot);
          CHECK((out.tau.array() == tau.array()).all());
          const auto hand = by_hand(q, eta, eta_dot);  // the stages' calls: τ without the lift's memo
          REQUIRE(hand.lambda.size() == c.k());
          CHECK((out.lambda - VectorXd(hand.lambda)).cwiseAbs().maxCoeff() <= 1e-10 * (1 + out.lambda.cwiseAbs().maxCoeff()));
          // v = E τ + Aᵀ λ: v the stationary robot's rne at the lifted state
          const VectorXd qd = apply_S(c, q, eta);
          const VectorXd qdd = c.S(q) * eta_dot + apply_Sdot(c, q, qd, eta);
          const VectorXd v = dyn(q, qd, qdd);
          const VectorXd recon = input_map(c, q) * out.tau + c.A(q).transpose() * out.lambda;
          CHECK((recon - v).cwiseAbs().maxCoeff() <= 1e-9 * (1 + v.cwiseAbs().maxCoeff()));
        }
      };
      run(inverse_dynamics_with_forces(t, c), inverse_dynamics(t, c), lift(c) | rne(t) | constraint_forces(c),
          [&](const auto& q, const auto& qd, const auto& qdd) { return VectorXd(rne(t)(q, qd, qdd)); });
      run(inverse_dynamics_with_forces(t, c, {}, fr), inverse_dynamics(t, c, {}, fr),
          lift(c) | (rne(t) + fr) | constraint_forces(c),
          [&](const auto& q, const auto& qd, const auto& qdd) { return VectorXd(rne(t)(q, qd, qdd) + fr(qd)); });
    }, *r.constraint);
  }
}
