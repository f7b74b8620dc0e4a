/// wheel_contacts (constraints/wheel_contacts.hpp): wheels touching a floor in 3D, on a floating
/// wheeled-legged quadruped, a two-wheeled balancing base and a mecanum base on a ramp, against
/// independent references: A S = 0; the contact points' material velocity by finite
/// differences of forward kinematics along the manifold; A q̈ + Ȧ q̇ = 0 by differences of A;
/// M q̈ + h = Eτ + Aᵀλ; the least-norm τ against Aghili's null-space projection (PE)⁺P v; the
/// forward dynamics inverting the inverse; the ramp's holding torques against the work of
/// gravity along admissible motions (potential energy from forward kinematics); a planar base
/// against wheeled_base.
#include <catch2/catch.hpp>

#include <Eigen/QR>
#include <nhdyn/constraints/forward_dynamics.hpp>
#include <nhdyn/constraints/stages.hpp>
#include <nhdyn/constraints/wheel_contacts.hpp>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/kinematics/tree.hpp>
#include <nhdyn/model/floating.hpp>
#include <random>

#ifdef NHDYN_HAVE_URDF
#include <nhdyn/io/robot_file.hpp>
#endif

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {
double rel(const MatrixXd& a, const MatrixXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / std::max(1.0, b.lpNorm<Eigen::Infinity>());
}
VectorXd random_vec(std::mt19937_64& rng, int n, double r) {
  std::uniform_real_distribution<double> u(-r, r);
  return VectorXd::NullaryExpr(n, [&] { return u(rng); });
}
Eigen::Matrix3d cylinder(double m, double r, double h, int axis) {
  Eigen::Matrix3d I = Eigen::Matrix3d::Identity() * (m * (3 * r * r + h * h) / 12);
  I(axis, axis) = m * r * r / 2;
  return I;
}
body<double> make_body(const std::string& name, const std::string& joint, int parent, const Vector3d& p, int axis,
                       double m, const Vector3d& com, const Eigen::Matrix3d& I) {
  body<double> b;
  b.name = name;
  b.joint_name = joint;
  b.parent = parent;
  b.p_PJ = p;
  b.axis = Vector3d::Unit(axis);
  b.mass = m;
  b.com = com;
  b.inertia = I;
  return b;
}

/// A wheeled-legged quadruped: a 20 kg trunk, four legs of three joints (HAA about x, HFE and
/// KFE about y) and a wheel at each foot (spin about y, r = 0.1 m): nv = 6 + 16.
tree<double> wheeled_quadruped() {
  auto B = free_flyer_bodies<double>("trunk");
  B[5].mass = 20;
  B[5].inertia = Eigen::Vector3d(0.3, 0.8, 0.9).asDiagonal();
  const char* legs[4] = {"LF", "RF", "LH", "RH"};
  for (int l = 0; l < 4; ++l) {
    const double sx = l < 2 ? 1 : -1, sy = l % 2 == 0 ? 1 : -1;
    const std::string L = legs[l];
    const int base = static_cast<int>(B.size());
    B.push_back(make_body(L + "_hip", L + "_HAA", 5, {0.3 * sx, 0.12 * sy, 0}, 0, 2, {0, 0.05 * sy, 0},
                          cylinder(2, 0.05, 0.1, 1)));
    B.push_back(make_body(L + "_thigh", L + "_HFE", base, {0, 0.1 * sy, 0}, 1, 2, {0, 0, -0.15},
                          cylinder(2, 0.04, 0.3, 2)));
    B.push_back(make_body(L + "_shank", L + "_KFE", base + 1, {0, 0, -0.3}, 1, 1, {0, 0, -0.15},
                          cylinder(1, 0.03, 0.3, 2)));
    B.push_back(make_body(L + "_wheel", L + "_WHEEL", base + 2, {0, 0.05 * sy, -0.3}, 1, 0.5, Vector3d::Zero(),
                          cylinder(0.5, 0.1, 0.04, 1)));
  }
  return tree<double>(std::move(B), {0, 0, -9.81}, "wheeled quadruped");
}
std::vector<wheel> quadruped_wheels() {
  std::vector<wheel> w;
  for (const char* l : {"LF", "RF", "LH", "RH"}) w.push_back({wheel_kind::fixed, std::string(l) + "_WHEEL", "", 0.1, 0});
  return w;
}
/// A configuration of the quadruped with its legs bent and its wheels on the floor z = 0.
VectorXd standing(const tree<double>& t, const wheel_contacts<double>& c, std::mt19937_64& rng) {
  VectorXd q = neutral_configuration(t);
  q.segment<4>(3) = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Vector3d::UnitZ())).coeffs();
  const VectorXd j = random_vec(rng, t.nv(), 0.15);
  for (int l = 0; l < 4; ++l) {
    const int i = 6 + 4 * l;
    q(i + 1) = j(i);
    q(i + 2) = (l < 2 ? 0.5 : -0.5) + j(i + 1);
    q(i + 3) = (l < 2 ? -1.0 : 1.0) + j(i + 2);
    q(i + 4) = 3 * j(i + 3);
  }
  q(2) -= c.gaps(q).mean();  // the trunk lowered until the wheels touch, then each knee (Newton)
  for (int it = 0; it < 8; ++it) {
    const VectorXd g = c.gaps(q);
    for (int l = 0; l < 4; ++l) {
      VectorXd qk = q;
      qk(6 + 4 * l + 3) += 1e-7;
      q(6 + 4 * l + 3) -= g(l) / ((c.gaps(qk)(l) - g(l)) / 1e-7);
    }
  }
  return q;
}

/// The position in the world of the material point of body `body` that is at P (world) at q,
/// at the configuration q1.
Vector3d material_point(const tree_kinematics<double>& kin, const VectorXd& q, int body, const Vector3d& P,
                        const VectorXd& q1) {
  const auto X = kin.frame(q, body);
  const Vector3d p_B = X.R.transpose() * (P - X.p);
  return kin.point(q1, body, p_B);
}
}  // namespace

TEST_CASE("wheel_contacts on a floating wheeled-legged quadruped: rows, eta, A S = 0", "[wheel_contacts]") {
  const auto t = wheeled_quadruped();
  const wheel_contacts<double> c(t, quadruped_wheels());
  CHECK(c.dof() == 22);
  CHECK(c.nq() == 23);
  CHECK(c.k() == 12);
  CHECK(c.rank() == 12);
  CHECK(c.m() == 10);
  CHECK(c.p() == 16);  // the legs' 12 joints and the 4 wheels: not the floating base
  // the rule: the legs' joints are the dependent ones; η is the trunk's twist and the wheels' spins
  const auto eta = c.eta_names(t.joint_names());
  CHECK(eta == std::vector<std::string>{"root_x", "root_y", "root_z", "root_rx", "root_ry", "root_rz", "LF_WHEEL",
                                        "RF_WHEEL", "LH_WHEEL", "RH_WHEEL"});
  CHECK(c.lambda_names()[2] == "LF_WHEEL.normal");
  std::mt19937_64 rng(1);
  const VectorXd q = standing(t, c, rng);
  CHECK(c.gaps(q).cwiseAbs().maxCoeff() < 1e-12);
  const MatrixXd A = c.A(q), S = c.S(q);
  CHECK((A * S).lpNorm<Eigen::Infinity>() < 1e-13);
  // the wheel's material point at P does not move, by forward kinematics along q ⊕ h S η
  const tree_kinematics<double> kin(t);
  const VectorXd qd = S * random_vec(rng, c.m(), 1);
  const Eigen::Matrix3Xd P = c.contact_points(q);
  const double h = 1e-6;
  for (int w = 0; w < 4; ++w) {
    const int body = 6 + 4 * w + 3 + 1;  // the wheel (1-based body index)
    const Vector3d vel = (material_point(kin, q, body, P.col(w), integrate(t, q, VectorXd(h * qd))) -
                          material_point(kin, q, body, P.col(w), integrate(t, q, VectorXd(-h * qd)))) /
                         (2 * h);
    CHECK(vel.norm() < 1e-8);
    // and a motion off S slips: the same wheel's point moves along some row
    CHECK((A.middleRows(3 * w, 3) * VectorXd::Unit(22, 6 + 4 * w)).norm() > 1e-3);
  }
}

TEST_CASE("wheel_contacts: the lift keeps A q̈ + Ȧ q̇ = 0, and the inverse dynamics splits rne into Eτ + Aᵀλ",
          "[wheel_contacts]") {
  const auto t = wheeled_quadruped();
  const wheel_contacts<double> c(t, quadruped_wheels());
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 5; ++trial) {
    const VectorXd q = standing(t, c, rng), eta = random_vec(rng, c.m(), 1), eta_dot = random_vec(rng, c.m(), 2);
    const auto xi = lift(c)(q, eta, eta_dot);
    // d/dt [A(q(t)) v(t)] = 0 along q(t) = q ⊕ (t v + t²/2 a), v(t) = v + t a (central differences)
    const double h = 1e-5;
    const auto Av = [&](double s) {
      const VectorXd x = integrate(t, q, VectorXd(s * xi.qd + 0.5 * s * s * xi.qdd));
      return VectorXd(c.A(x) * (xi.qd + s * xi.qdd));
    };
    CHECK((Av(h) - Av(-h)).norm() / (2 * h) < 1e-7);
    // τ, λ: M q̈ + h = E τ + Aᵀ λ, and λ does no work
    const auto f = inverse_dynamics_with_forces(t, c)(q, eta, eta_dot);
    const VectorXd v = rne(t)(q, xi.qd, xi.qdd);
    CHECK(rel(VectorXd(c.E(q) * f.tau + c.A(q).transpose() * f.lambda), v) < 1e-10);
    CHECK(std::abs(f.lambda.dot(c.A(q) * xi.qd)) < 1e-9 * (1 + f.lambda.norm()));
    CHECK(rel(f.tau, inverse_dynamics(t, c)(q, eta, eta_dot)) == 0);
    // the least-norm τ is Aghili's null-space inverse dynamics (PE)⁺ P v, P = 1 − A⁺A
    const MatrixXd A = c.A(q);
    const MatrixXd Pn = MatrixXd::Identity(22, 22) - A.completeOrthogonalDecomposition().pseudoInverse() * A;
    const MatrixXd PE = Pn * c.E(q);
    CHECK(rel(f.tau, VectorXd(PE.completeOrthogonalDecomposition().solve(Pn * v))) < 1e-9);
    // the forward dynamics inverts it
    CHECK(rel(nh_forward_dynamics(t, c)(q, eta, f.tau), eta_dot) < 1e-8);
    // standing on its wheels, the floor pushes: every normal λ > 0 at rest
    const auto rest = inverse_dynamics_with_forces(t, c)(q, VectorXd::Zero(c.m()), VectorXd::Zero(c.m()));
    CHECK(c.pulling(rest.lambda).empty());
    double up = 0;
    for (int w = 0; w < 4; ++w) up += rest.lambda(3 * w + 2);
    double mass = 0;
    for (const auto& b : t) mass += b.mass;
    CHECK(up == Approx(mass * 9.81).epsilon(1e-9));  // the normal forces carry the weight (level floor)
  }
}

TEST_CASE("wheel_contacts: a two-wheeled balancing base cannot hold its pitch: id names the direction",
          "[wheel_contacts]") {
  auto B = free_flyer_bodies<double>("chassis");
  B[5].mass = 15;
  B[5].com = {0, 0, 0.3};
  B[5].inertia = Eigen::Vector3d(0.5, 0.4, 0.3).asDiagonal();
  B.push_back(make_body("wheel_l", "wheel_l_joint", 5, {0, 0.25, 0}, 1, 1, Vector3d::Zero(), cylinder(1, 0.15, 0.05, 1)));
  B.push_back(make_body("wheel_r", "wheel_r_joint", 5, {0, -0.25, 0}, 1, 1, Vector3d::Zero(), cylinder(1, 0.15, 0.05, 1)));
  B.push_back(make_body("arm", "arm_joint", 5, {0, 0, 0.6}, 1, 2, {0, 0, 0.2}, cylinder(2, 0.03, 0.4, 2)));
  const tree<double> t(std::move(B), {0, 0, -9.81}, "balancing base");
  const wheel_contacts<double> c(t, {{wheel_kind::fixed, "wheel_l_joint", "", 0.15, 0},
                                     {wheel_kind::fixed, "wheel_r_joint", "", 0.15, 0}});
  CHECK(c.k() == 6);
  CHECK(c.rank() == 5);  // the two lateral rows on one axle are one
  CHECK(c.m() == 4);     // forward, yaw, pitch, the arm
  CHECK(c.p() == 3);
  VectorXd q = neutral_configuration(t);
  q(2) = 0.15;
  CHECK(c.gaps(q).cwiseAbs().maxCoeff() < 1e-15);
  CHECK_THROWS_WITH(inverse_dynamics(t, c)(q, VectorXd::Zero(4), VectorXd::Zero(4)),
                    Catch::Contains("cannot produce the motion along eta") && Catch::Contains("root_ry"));
  // the forward dynamics runs regardless: unactuated, the chassis tips over (its centre is above the axle)
  q.segment<4>(3) = Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Vector3d::UnitY())).coeffs();
  const VectorXd ed = nh_forward_dynamics(t, c)(q, VectorXd::Zero(4), VectorXd::Zero(3));
  const auto eta = c.eta_names(t.joint_names());
  const int pitch = int(std::find(eta.begin(), eta.end(), "root_ry") - eta.begin());
  REQUIRE(pitch < 4);
  CHECK(ed(pitch) > 0.1);  // leaning forward (+y rotation tips +x), it falls further forward
}

TEST_CASE("wheel_contacts: a mecanum base held still on a 10 degree ramp, against the work of gravity",
          "[wheel_contacts]") {
  // a 30 kg box on four mecanum wheels (rollers at ±45°), floating; the floor a ramp rising along x
  auto B = free_flyer_bodies<double>("base");
  B[5].mass = 30;
  B[5].com = {0.02, 0, 0.1};
  B[5].inertia = Eigen::Vector3d(0.6, 1.0, 1.3).asDiagonal();
  std::vector<wheel> wheels;
  int i = 0;
  for (const char* n : {"fl", "fr", "rl", "rr"}) {
    const double sx = i < 2 ? 1 : -1, sy = i % 2 == 0 ? 1 : -1;
    B.push_back(make_body(std::string(n) + "_wheel", std::string(n) + "_spin", 5, {0.25 * sx, 0.2 * sy, 0}, 1, 1.2,
                          Vector3d::Zero(), cylinder(1.2, 0.05, 0.05, 1)));
    wheels.push_back({wheel_kind::swedish, std::string(n) + "_spin", "", 0.05, (sx * sy > 0 ? -1 : 1) * std::numbers::pi / 4});
    ++i;
  }
  const tree<double> t(std::move(B), {0, 0, -9.81}, "mecanum on a ramp");
  const double slope = 10 * std::numbers::pi / 180;
  wheel_contacts_options o;
  o.floor = floor_plane::slope(slope);
  const wheel_contacts<double> c(t, wheels, o);
  CHECK(c.k() == 8);
  CHECK(c.rank() == 7);  // four normal rows on three directions (z, roll, pitch)
  CHECK(c.m() == 3);     // x, y and yaw in the ramp's plane
  CHECK(c.p() == 4);     // more actuators than η: the torques of least norm
  // the base parallel to the ramp, its wheels on it
  VectorXd q = neutral_configuration(t);
  q.segment<4>(3) = Eigen::Quaterniond(Eigen::AngleAxisd(-slope, Vector3d::UnitY()) *
                                       Eigen::AngleAxisd(0.3, Vector3d::UnitZ()))
                        .coeffs();
  for (int it = 0; it < 2; ++it) q.head<3>() -= c.gaps(q).mean() * o.floor.normal;
  REQUIRE(c.gaps(q).cwiseAbs().maxCoeff() < 1e-12);
  const auto f = inverse_dynamics_with_forces(t, c)(q, VectorXd::Zero(3), VectorXd::Zero(3));
  CHECK(c.pulling(f.lambda).empty());
  CHECK(f.tau.norm() > 0.1);  // holding it on the slope takes torque
  // virtual work: along each admissible motion S e_j, τ's work is the potential energy's rise
  const tree_kinematics<double> kin(t);
  const auto V = [&](const VectorXd& x) {
    double e = 0;
    for (int b = 0; b < t.dof(); ++b) e -= t[b].mass * t.gravity().dot(kin.point(x, b + 1, t[b].com));
    return e;
  };
  const MatrixXd S = c.S(q), E = c.E(q);
  const double h = 1e-6;
  for (int j = 0; j < 3; ++j) {
    const VectorXd s = S.col(j);
    const double dV = (V(integrate(t, q, VectorXd(h * s))) - V(integrate(t, q, VectorXd(-h * s)))) / (2 * h);
    CHECK((E * f.tau).dot(s) == Approx(dV).margin(1e-7));
  }
  // on a level floor the same base needs no torque to stand
  const wheel_contacts<double> level(t, wheels);
  VectorXd q0 = neutral_configuration(t);
  q0(2) = 0.05;
  CHECK(inverse_dynamics(t, level)(q0, VectorXd::Zero(3), VectorXd::Zero(3)).norm() < 1e-10);
}
