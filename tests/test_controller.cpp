// The robust task-space controller (simulation/controller.hpp) against independent
// references: the closed-form Lyapunov solution, the task acceleration recovered by
// differentiating the forward kinematics numerically, and closed-loop convergence.
#include <catch2/catch.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/simulation/controller.hpp>
#include <nhdyn/simulation/simulation.hpp>

using namespace nhdyn;

TEST_CASE("controller: P solves A_cᵀP + PA_c = −I and matches the per-axis closed form") {
  const double a = 400, b = 40;
  const auto P = lyapunov_P(a * Eigen::Matrix3d::Identity(), b * Eigen::Matrix3d::Identity());
  // Per axis, A = [0 1; −a −b]: q = 1/(2a), r = (1 + a)/(2ab), p = (1 + a)/(2b) + b/(2a).
  for (int i = 0; i < 3; ++i) {
    CHECK(P(i, i) == Approx((1 + a) / (2 * b) + b / (2 * a)).epsilon(1e-12));
    CHECK(P(i, i + 3) == Approx(1 / (2 * a)).epsilon(1e-12));
    CHECK(P(i + 3, i + 3) == Approx((1 + a) / (2 * a * b)).epsilon(1e-12));
  }
  // A non-diagonal pair: the residual of the equation itself.
  Eigen::Matrix3d K0, K1;
  K0 << 300, 20, 0, 20, 400, 10, 0, 10, 500;
  K1 << 40, 5, 0, 5, 30, 0, 0, 0, 45;
  const auto P2 = lyapunov_P(K0, K1);
  Eigen::Matrix<double, 6, 6> Ac = Eigen::Matrix<double, 6, 6>::Zero();
  Ac.topRightCorner<3, 3>().setIdentity();
  Ac.bottomLeftCorner<3, 3>() = -K0;
  Ac.bottomRightCorner<3, 3>() = -K1;
  CHECK((Ac.transpose() * P2 + P2 * Ac + Eigen::Matrix<double, 6, 6>::Identity()).norm() < 1e-9);
  CHECK_THROWS_AS(lyapunov_P(-Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity()), numerical_error);
}

TEST_CASE("controller: δ has norm ρ(e) along −HᵀPe, vanishes at e = 0, and saturates in the boundary layer") {
  const auto robot = presets::paper5<double>();
  vecN<double, 5> q0;
  q0 << -0.23710299623923958, 1.0, 3.141592653589793, 2.058145585963254, 1.2;
  const vecN<double, 5> mask = (vecN<double, 5>() << 0, 0, 0, 1, 1).finished();
  rac_gains g;
  const rac_controller c(robot.chain, robot.constraint, g, q0, mask);
  Eigen::Matrix<double, 6, 1> e;
  e << 0.01, -0.02, 0.005, 0.1, 0.05, -0.03;
  const double rho = 0.2 * e.squaredNorm() + 0.1 * e.norm();
  const Eigen::Vector3d w = -(c.P() * e).tail<3>();
  const Eigen::Vector3d d = c.delta(e);
  CHECK(d.norm() == Approx(rho).epsilon(1e-12));
  CHECK((d / d.norm() + w / w.norm()).norm() < 1e-12);
  CHECK(c.delta(Eigen::Matrix<double, 6, 1>::Zero().eval()).norm() == 0);
  g.robust.epsilon = 10 * w.norm();  // inside the boundary layer: linear in HᵀPe
  const rac_controller cb(robot.chain, robot.constraint, g, q0, mask);
  CHECK((cb.delta(e) - (-rho * w / g.robust.epsilon)).norm() < 1e-12);
}

TEST_CASE("controller: with λ = 0 on the nominal plant, the task acceleration is a_r (eq. 30 inverts exactly)") {
  const auto robot = presets::paper5<double>();
  const kinematics<double, 5> kin(robot.chain);
  const auto fd = nh_forward_dynamics(robot.chain, robot.constraint);
  vecN<double, 5> q;
  q << 0.1, 0.8, 2.5, 1.7, 0.9;
  vecN<double, 4> eta;
  eta << -0.3, 0.2, 0.4, -0.5;
  rac_gains g;
  g.lambda = 0;
  g.use_robust = false;
  const vecN<double, 5> mask = (vecN<double, 5>() << 0, 0, 0, 1, 1).finished();
  const rac_controller c(robot.chain, robot.constraint, g, q, mask);  // posture: z ≠ 0 via kN η
  const circle_reference ref;
  const double t = 3.0;
  const auto rd = ref(t);
  const vec3<double> r = kin.point(q, 5);
  const vecN<double, 4> tau = c(q, eta, r, rd);
  const vecN<double, 4> eta_dot = fd(q, eta, tau);
  // r̈ by central differences of ṙ = J_v(q(s)) q̇(s) along q(s) = q + s q̇ + s²/2 q̈.
  const vecN<double, 5> qd = apply_S(robot.constraint, q, eta);
  const vecN<double, 5> qdd = apply_S(robot.constraint, q, eta_dot) + apply_Sdot(robot.constraint, q, qd, eta);
  const auto rdot = [&](double s) {
    const vecN<double, 5> qs = q + s * qd + 0.5 * s * s * qdd, qds = qd + s * qdd;
    return vec3<double>(kin.jacobian(qs, 5).topRows<3>() * qds);
  };
  const double h = 1e-5;
  const vec3<double> r_ddot = (rdot(h) - rdot(-h)) / (2 * h);
  const vec3<double> v = kin.jacobian(q, 5).topRows<3>() * qd;
  const vec3<double> a_r = rd.rdd + 40 * (rd.rd - v) + 400 * (rd.r - r);
  CHECK((r_ddot - a_r).norm() < 1e-6 * a_r.norm());
}

TEST_CASE("controller: converges to a fixed target on the nominal plant") {
  run_spec s;
  s.name = "regulation";
  s.plant = {};  // nominal: plant == model
  s.reference.radius = 0;
  s.reference.center = Eigen::Vector3d(0.40, 0.85, 0.10);  // 0.19 m from the start tip (0.35, 1, 0)
  s.duration = 4;
  s.tail_from = 3;
  const auto r = simulate(s);
  REQUIRE(r.success);
  const double e0 = r.rows(0, 20), e1 = r.rows(r.rows.rows() - 1, 20);
  CHECK(e0 == Approx(std::sqrt(0.05 * 0.05 + 0.15 * 0.15 + 0.1 * 0.1)).epsilon(1e-9));
  // λ > 0 leaks a little of the posture term into the task: the error falls 1000-fold,
  // not to zero (with λ = 0 it would; see the next check).
  CHECK(e1 < 1e-3 * e0);
  CHECK(r.max_tail_error < 1e-3 * e0);
  s.gains.lambda = 0;
  const auto exact = simulate(s);
  REQUIRE(exact.success);
  CHECK(exact.rows(exact.rows.rows() - 1, 20) < 1e-6 * e0);
}

TEST_CASE("controller: at a singular B (arm pointing straight up) σ₃ = 0 is reported; damped B⁺ stays finite, λ = 0 throws") {
  // With the arm vertical above the shoulder (q₄ = π/2, q₅ = 0) the tip lies on the yaw
  // axis: neither turning nor any arm joint moves it sideways, so B = J_v S has rank 2.
  const auto robot = presets::paper5<double>();
  vecN<double, 5> q0;
  q0 << -0.23710299623923958, 1.0, 3.141592653589793, 2.058145585963254, 1.2;
  const vecN<double, 5> mask = (vecN<double, 5>() << 0, 0, 0, 1, 1).finished();
  vecN<double, 5> q;
  q << 0.2, -0.3, 0.4, 1.5707963267948966, 0.0;
  const rac_controller damped(robot.chain, robot.constraint, rac_gains{}, q0, mask);
  const Eigen::Vector3d sv = damped.task_singular_values(q);
  CHECK(sv(2) < 1e-14 * sv(0));
  // Independent: the tip's lateral direction z₃ = (0, cos q₃, sin q₃) is orthogonal to B's range.
  const Eigen::Vector3d z3(0, std::cos(q(2)), std::sin(q(2)));
  kinematics<double, 5> k(robot.chain);
  const Eigen::Matrix<double, 3, 4> B = k.jacobian(q, 5).topRows<3>() * robot.constraint.S(q);
  CHECK((z3.transpose() * B).norm() < 1e-14);
  // Away from it σ₃ > 0 (the start configuration).
  CHECK(damped.task_singular_values(q0)(2) > 1e-2);

  const vecN<double, 4> eta(0.1, -0.2, 0.3, 0.1);
  const auto ref = circle_reference{}(0.0);
  const vec3<double> r = damped.task_point(q) + vec3<double>(0.01, 0.02, -0.01);
  const vecN<double, 4> tau = damped(q, eta, r, ref);
  CHECK(tau.allFinite());
  rac_gains undamped;
  undamped.lambda = 0;
  const rac_controller c0(robot.chain, robot.constraint, undamped, q0, mask);
  CHECK_THROWS_AS(c0(q, eta, r, ref), numerical_error);
}
