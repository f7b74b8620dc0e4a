/// Floating bases (model/floating.hpp) against independent references: the manifold operations
/// against their closed forms; rne against the plain algorithm with the root as one 6-DoF joint
/// (reference::rne_floating, S = 1₆); rne, M and ABA against the same robot on a world-fixed
/// chain of six joints (three prismatic, three revolute in Z-Y-X Euler angles) with the
/// velocities and accelerations mapped through that chain's Jacobian; free fall (τ = 0);
/// M a + h = τ; the derivatives against dual numbers along the manifold (q ⊕ ε δ); the
/// kinematics against finite differences along integrate.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <nhdyn/dynamics/aba.hpp>
#include <nhdyn/dynamics/reference.hpp>
#include <nhdyn/dynamics/rne_derivatives.hpp>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/kinematics/tree.hpp>
#include <nhdyn/model/floating.hpp>
#include <nhdyn/model/lock.hpp>
#include <nhdyn/scalar/dual.hpp>
#include <nhdyn/scalar/interval.hpp>
#include <random>

#include "reference/random_tree.hpp"

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
VectorXd random_vec(std::mt19937_64& rng, int n, double r) {
  return VectorXd::NullaryExpr(n, [&] { return nhdyn_ref::uniform(rng, -r, r); });
}
double rel(const MatrixXd& a, const MatrixXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / std::max(1.0, b.lpNorm<Eigen::Infinity>());
}

/// A random floating tree: a random tree (its bodies on the world become the root link's
/// children) under a root link of random inertia.
tree<double> random_floating(std::mt19937_64& rng, int n) {
  const auto t = nhdyn_ref::random_tree(rng, n, 0.4, true);
  const double m = nhdyn_ref::uniform(rng, 2, 20);
  return make_floating(t, m, nhdyn_ref::random_vector(rng, 0.2), nhdyn_ref::random_inertia(rng, m));
}

/// The same robot on a world-fixed chain of six joints: x, y, z along the world's axes, then
/// turns about z, y, x (R_WB = Rz(ψ) Ry(θ) Rx(φ)), the last carrying the root link.
tree<double> euler_tree(const tree<double>& f) {
  std::vector<body<double>> B(f.begin(), f.end());
  for (int i = 0; i < 6; ++i) {
    B[std::size_t(i)].free_flyer = false;
    B[std::size_t(i)].axis = Eigen::Vector3d::Unit(i < 3 ? i : 5 - i);  // x y z, then z y x
  }
  return tree<double>(std::move(B), f.gravity(), "euler");
}

/// The state map from the floating robot to the Euler chain's (q_E, q̇_E, q̈_E), and J_B: the
/// chain's six rates to the root's body twist (v_B, ω_B).
struct euler_state {
  VectorXd q, qd, qdd;
  Eigen::Matrix<double, 6, 6> J_B;
};
euler_state to_euler(const tree<double>& e, const VectorXd& q, const VectorXd& v, const VectorXd& a) {
  const int n = e.dof();
  euler_state s;
  s.q.resize(n);
  const Eigen::Matrix3d R = Eigen::Quaterniond(q(6), q(3), q(4), q(5)).toRotationMatrix();
  const Eigen::Vector3d ang = R.eulerAngles(2, 1, 0);  // R = Rz(ψ) Ry(θ) Rx(φ)
  s.q << q.head<3>(), ang, q.tail(n - 6);
  const tree_kinematics<double> kin(e);
  const Eigen::Matrix<double, 6, 6> J_W = kin.jacobian(s.q, 6).leftCols<6>();  // the root link's origin
  Eigen::Matrix<double, 6, 6> Rt = Eigen::Matrix<double, 6, 6>::Zero();
  Rt.topLeftCorner<3, 3>() = R.transpose();
  Rt.bottomRightCorner<3, 3>() = R.transpose();
  s.J_B = Rt * J_W;
  s.qd = v;
  s.qd.head<6>() = s.J_B.lu().solve(v.head<6>());
  // v̇_B = Rᵀ p̈ − ω_B × v_B and ω̇_B = Rᵀ ω̇_W, with (p̈, ω̇_W) = J_W q̈ + J̇ q̇
  const auto jd = kin.jdot_qdot(s.q, s.qd, 6);
  Eigen::Matrix<double, 6, 1> rhs;
  rhs << R * (a.head<3>() + Eigen::Vector3d(v.segment<3>(3)).cross(Eigen::Vector3d(v.head<3>()))) - jd.linear,
      R * a.segment<3>(3) - jd.angular;
  s.qdd = a;
  s.qdd.head<6>() = J_W.lu().solve(rhs);
  return s;
}
}  // namespace

TEST_CASE("floating base: integrate and difference are each other's inverse and match their closed forms",
          "[floating]") {
  std::mt19937_64 rng(3);
  const auto t = random_floating(rng, 4);
  REQUIRE(t.floating());
  REQUIRE(t.nq() == t.nv() + 1);
  for (int trial = 0; trial < 50; ++trial) {
    const VectorXd q = random_configuration(t, rng);
    const Eigen::Quaterniond Q(q(6), q(3), q(4), q(5));
    // a pure translation: p' = p + R u
    VectorXd v = VectorXd::Zero(t.nv());
    v.head<3>() = random_vec(rng, 3, 2);
    VectorXd q1 = integrate(t, q, v);
    CHECK((q1.head<3>() - (q.head<3>() + Q.toRotationMatrix() * v.head<3>())).norm() <= 1e-14);
    CHECK((q1.segment<4>(3) - q.segment<4>(3)).norm() <= 1e-15);
    // a pure rotation by θ about the unit axis e (in B): Q' = Q ⊗ (sin(θ/2) e, cos(θ/2))
    const Eigen::Vector3d e = nhdyn_ref::random_vector(rng, 1).normalized();
    for (double th : {1e-9, 1e-4, 0.03, 0.7, 2.0, 3.1}) {
      v.setZero();
      v.segment<3>(3) = th * e;
      q1 = integrate(t, q, v);
      const Eigen::Quaterniond E(Eigen::AngleAxisd(th, e));
      const Eigen::Quaterniond Q1 = Q * E;
      CHECK((q1.segment<4>(3) - Q1.coeffs()).norm() <= 2e-15);
      CHECK((q1.head<3>() - q.head<3>()).norm() == 0);
      CHECK(rel(difference(t, q, q1), v) <= 1e-13);
    }
    // any motion, |ω| < π: difference inverts integrate, and joints add
    v = random_vec(rng, t.nv(), 1.5);
    q1 = integrate(t, q, v);
    CHECK(std::abs(q1.segment<4>(3).norm() - 1) <= 1e-15);
    CHECK(rel(difference(t, q, q1), v) <= 1e-13);
    CHECK(rel(q1.tail(t.nq() - 7), VectorXd(q.tail(t.nq() - 7) + v.tail(t.nv() - 6))) == 0);
    // SE(3)'s exponential: a screw along ω (u ∥ ω) advances along the axis by |u| and turns by |ω|
    v.setZero();
    v.head<3>() = 0.4 * e;
    v.segment<3>(3) = 1.3 * e;
    q1 = integrate(t, q, v);
    CHECK((q1.head<3>() - (q.head<3>() + Q.toRotationMatrix() * (0.4 * e))).norm() <= 1e-14);
  }
  // the velocity along integrate(q, s v) at s = 0 is v: ṗ_WB = R v_B (world_velocity)
  const VectorXd q = random_configuration(t, rng), v = random_vec(rng, t.nv(), 1);
  const double h = 1e-6;
  const VectorXd dp = (integrate(t, q, VectorXd(h * v)).head<3>() - integrate(t, q, VectorXd(-h * v)).head<3>()) / (2 * h);
  CHECK((dp - world_velocity(t, q, v).head<3>()).norm() <= 1e-8);
  CHECK(rel(body_velocity(t, q, world_velocity(t, q, v)), v) <= 1e-15);
  CHECK(neutral_configuration(t)(6) == 1);
  CHECK(rel(difference(t, q, q), VectorXd::Zero(t.nv())) == 0);
}

TEST_CASE("floating base: a quaternion that is not unit is refused with its norm named", "[floating]") {
  std::mt19937_64 rng(4);
  const auto t = random_floating(rng, 3);
  VectorXd q = neutral_configuration(t);
  q(6) = 1.1;
  const VectorXd z = VectorXd::Zero(t.nv());
  CHECK_THROWS_WITH(rne(t)(q, z, z), Catch::Contains("norm 1.1") && Catch::Contains("quaternion"));
  CHECK_THROWS_WITH(mass_matrix(t)(q), Catch::Contains("norm 1.1"));
  CHECK_THROWS_WITH(aba(t)(q, z, z), Catch::Contains("norm 1.1"));
  CHECK_THROWS_WITH(integrate(t, q, z), Catch::Contains("norm 1.1"));
  CHECK_THROWS_WITH(rne(t)(z, z, z), Catch::Contains("q has " + std::to_string(t.nv()) + " entries; the model needs " +
                                                     std::to_string(t.nq())));
  // the six bodies in the wrong form, or a body hung from the world, are refused
  std::vector<body<double>> B(t.begin(), t.end());
  B[6].parent = -1;
  CHECK_THROWS_WITH(tree<double>(B, t.gravity(), "bad"), Catch::Contains("attached to the world"));
  B = std::vector<body<double>>(t.begin(), t.end());
  B[3].axis = Eigen::Vector3d::UnitY();
  CHECK_THROWS_WITH(tree<double>(B, t.gravity(), "bad"), Catch::Contains("not in the floating base's form"));
}

TEST_CASE("floating base: rne equals the plain algorithm with the root as one 6-DoF joint", "[floating]") {
  std::mt19937_64 rng(5);
  for (int n : {1, 2, 5, 12, 30}) {
    for (int trial = 0; trial < 4; ++trial) {
      const auto t = random_floating(rng, n);
      const VectorXd q = random_configuration(t, rng), v = random_vec(rng, t.nv(), 2), a = random_vec(rng, t.nv(), 3);
      INFO("n = " << n);
      const VectorXd tau = rne(t)(q, v, a);
      CHECK(rel(tau, reference::rne_floating<double>(t, q, v, a)) <= 1e-12);
      // M a + h = τ, and ABA inverts it
      const MatrixXd M = mass_matrix(t)(q);
      CHECK(rel(M, M.transpose()) == 0);
      CHECK(rel(VectorXd(M * a + bias(t)(q, v)), tau) <= 1e-12);
      CHECK(rel(aba(t)(q, v, tau), a) <= 1e-10);
      CHECK(rel(forward_dynamics(t, {}, {.method = fd_method::crba_ldlt})(q, v, tau), a) <= 1e-10);
      // options: without gravity, without velocity terms
      const VectorXd g_only = rne(t)(q, VectorXd::Zero(t.nv()), VectorXd::Zero(t.nv()));
      CHECK(rel(VectorXd(rne(t, {.gravity = false})(q, v, a) + g_only), tau) <= 1e-12);
      CHECK(rel(VectorXd(rne(t, {.velocity = false})(q, v, a)), VectorXd(M * a + g_only)) <= 1e-12);
    }
  }
}

TEST_CASE("floating base: rne, M and ABA equal the robot on a world-fixed chain of six joints", "[floating]") {
  std::mt19937_64 rng(6);
  for (int n : {1, 3, 8, 20}) {
    for (int trial = 0; trial < 4; ++trial) {
      const auto t = random_floating(rng, n);
      const auto e = euler_tree(t);
      VectorXd q = random_configuration(t, rng);
      const VectorXd v = random_vec(rng, t.nv(), 2), a = random_vec(rng, t.nv(), 3);
      const auto s = to_euler(e, q, v, a);
      if (std::abs(std::cos(s.q(4))) < 0.1) continue;  // near the Euler angles' singularity
      INFO("n = " << n);
      const VectorXd tau = rne(t)(q, v, a), tau_e = rne(e)(s.q, s.qd, s.qdd);
      // power: τ_Eᵀ q̇_E = τᵀ v, so τ_E = Jᵀ τ for the root's six and equal for the joints
      CHECK(rel(VectorXd(s.J_B.transpose() * tau.head<6>()), tau_e.head<6>()) <= 1e-11);
      CHECK(rel(tau.tail(t.nv() - 6), tau_e.tail(t.nv() - 6)) <= 1e-11);
      MatrixXd J = MatrixXd::Identity(t.nv(), t.nv());
      J.topLeftCorner<6, 6>() = s.J_B;
      CHECK(rel(J.transpose() * mass_matrix(t)(q) * J, mass_matrix(e)(s.q)) <= 1e-11);
      CHECK(rel(aba(t)(q, v, tau), a) <= 1e-10);
      CHECK(rel(aba(e)(s.q, s.qd, tau_e), s.qdd) <= 1e-9);
    }
  }
}

TEST_CASE("floating base: a robot in free fall needs no force, and at rest its root carries its weight",
          "[floating]") {
  std::mt19937_64 rng(7);
  const auto t = random_floating(rng, 9);
  const VectorXd q = random_configuration(t, rng);
  const Eigen::Matrix3d R = Eigen::Quaterniond(q(6), q(3), q(4), q(5)).toRotationMatrix();
  VectorXd a = VectorXd::Zero(t.nv());
  a.head<3>() = R.transpose() * t.gravity();  // every body falls with g, nothing turns
  CHECK(rne(t)(q, VectorXd::Zero(t.nv()), a).lpNorm<Eigen::Infinity>() <= 1e-12);
  double m = 0;
  for (const auto& b : t) m += b.mass;
  const VectorXd tau = rne(t)(q, VectorXd::Zero(t.nv()), VectorXd::Zero(t.nv()));
  CHECK((tau.head<3>() + m * R.transpose() * t.gravity()).norm() <= 1e-12 * m * 9.81);
}

TEST_CASE("floating base: the derivatives equal dual numbers along the manifold (q ⊕ ε δ)", "[floating]") {
  std::mt19937_64 rng(8);
  using D = dual<double, 1>;
  for (int n : {2, 7, 15}) {
    const auto t = random_floating(rng, n);
    const int nv = t.nv();
    const VectorXd q = random_configuration(t, rng), v = random_vec(rng, nv, 2), a = random_vec(rng, nv, 3);
    const auto d = rne_derivatives(t)(q, v, a);
    CHECK(rel(d.tau, rne(t)(q, v, a)) <= 1e-13);
    CHECK(rel(d.M, mass_matrix(t)(q)) <= 1e-13);
    MatrixXd dq(nv, nv), dv(nv, nv);
    for (int k = 0; k < nv; ++k) {
      Eigen::Matrix<D, Eigen::Dynamic, 1> delta = Eigen::Matrix<D, Eigen::Dynamic, 1>::Zero(nv);
      delta(k) = D::variable(0.0, 0);
      const auto qk = integrate(t, q, delta);  // q ⊕ ε e_k
      const auto tq = rne(t)(qk, v, a);
      Eigen::Matrix<D, Eigen::Dynamic, 1> vk = v.cast<D>();
      vk(k) = D::variable(v(k), 0);
      const auto tv = rne(t)(q, vk, a);
      for (int r = 0; r < nv; ++r) dq(r, k) = tq(r).derivative(0), dv(r, k) = tv(r).derivative(0);
    }
    INFO("n = " << n);
    CHECK(rel(d.dq, dq) <= 1e-11);
    CHECK(rel(d.dqd, dv) <= 1e-11);
    // and without gravity or velocity terms
    const auto d0 = rne_derivatives(t, {.gravity = false, .velocity = false})(q, v, a);
    CHECK(d0.dqd.lpNorm<Eigen::Infinity>() == 0);
    CHECK(d0.dq.middleCols(3, 3).lpNorm<Eigen::Infinity>() == 0);
  }
}

TEST_CASE("floating base: kinematics places the tree at the root and matches finite differences along integrate",
          "[floating]") {
  std::mt19937_64 rng(9);
  const auto t = random_floating(rng, 10);
  const tree_kinematics<double> kin(t);
  const VectorXd q = random_configuration(t, rng), v = random_vec(rng, t.nv(), 1);
  const Eigen::Matrix3d R = Eigen::Quaterniond(q(6), q(3), q(4), q(5)).toRotationMatrix();
  const auto X = kin.forward(q);
  CHECK((X[6].R - R).norm() <= 1e-15);  // the root link's frame is B
  CHECK((X[6].p - q.head<3>()).norm() == 0);
  CHECK((X[0].R - Eigen::Matrix3d::Identity()).norm() == 0);  // the world
  const Eigen::Vector3d c(0.1, -0.2, 0.05);
  const double h = 1e-5;
  for (int body : {6, 8, 12, 16}) {
    const auto p = [&](double s) { return Eigen::Vector3d(kin.point(integrate(t, q, VectorXd(s * v)), body, c)); };
    const Eigen::Vector3d vel = (p(h) - p(-h)) / (2 * h), acc = (p(h) - 2 * p(0) + p(-h)) / (h * h);
    const Eigen::Matrix<double, 6, Eigen::Dynamic> J = kin.jacobian(q, body, c);
    INFO("body " << body);
    CHECK((J.topRows<3>() * v - vel).norm() <= 1e-8);
    // along integrate(q, s v) the body twist and the rates are constant: a = 0, so p̈ = J̇ v
    CHECK((kin.jdot_qdot(q, v, body, c).linear - acc).norm() <= 2e-4);
  }
}

TEST_CASE("floating base: other scalars — long double, duals and intervals — give the double numbers",
          "[floating]") {
  std::mt19937_64 rng(10);
  const auto t = random_floating(rng, 6);
  const VectorXd q = random_configuration(t, rng), v = random_vec(rng, t.nv(), 2), a = random_vec(rng, t.nv(), 3);
  const VectorXd tau = rne(t)(q, v, a);
  const auto tl = rne(t.cast<long double>())(q.cast<long double>(), v.cast<long double>(), a.cast<long double>());
  CHECK(rel(tl.cast<double>(), tau) <= 1e-13);
  using I = interval;
  const auto ti = rne(t)(q.cast<I>(), v.cast<I>(), a.cast<I>());
  for (int i = 0; i < t.nv(); ++i) {
    CHECK(ti(i).lower() <= tau(i));
    CHECK(tau(i) <= ti(i).upper());
    CHECK(ti(i).upper() - ti(i).lower() <= 1e-9 * std::max(1.0, std::abs(tau(i))));
  }
}

TEST_CASE("floating base: locked joints keep the root, and the root's coordinates cannot be locked", "[floating][lock]") {
  std::mt19937_64 rng(12);
  const auto t = random_floating(rng, 8);
  const std::vector<std::pair<std::string, double>> held{{"joint2", 0.4}, {"joint5", -0.3}};
  const auto lk = lock(t, held);
  REQUIRE(lk.floating());
  CHECK(lk.dof() == t.dof() - 2);
  CHECK(lk.nq() == lk.dof() + 1);
  const auto m = lock_map_of(t, held);
  VectorXd q = random_configuration(t, rng);
  for (const auto& [i, x] : m.locked) q(i + 1) = x;
  const VectorXd qr = m.reduce(q);
  REQUIRE(qr.size() == lk.nq());
  CHECK(rel(m.expand_q(qr), q) == 0);
  const VectorXd v = random_vec(rng, lk.nv(), 2), a = random_vec(rng, lk.nv(), 3);
  CHECK(rel(rne(lk)(qr, v, a), m.reduce(VectorXd(rne(t)(q, m.expand(v), m.expand(a))))) <= 1e-12);
  // "*" locks every joint but the root's six; naming one of them is an error
  CHECK(lock(t, {{"*", 0.0}}).dof() == 6);
  CHECK_THROWS_WITH(lock(t, {{"root_rz", 0.0}}), Catch::Contains("coordinate of the floating base"));
}
