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
  circle_reference target;
  target.radius = 0;
  target.center = Eigen::Vector3d(0.40, 0.85, 0.10);  // 0.19 m from the start tip (0.35, 1, 0)
  s.reference = target;
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

// ---- references (simulation/references.hpp) ----------------------------------------------

namespace {
/// Central differences of f(t) (a vector) at t.
template <class F>
Eigen::VectorXd central(const F& f, double t, double h) {
  return (Eigen::VectorXd(f(t + h)) - Eigen::VectorXd(f(t - h))) / (2 * h);
}
}  // namespace

TEST_CASE("references: the line is rest to rest, its derivatives are the finite differences of its position") {
  line_reference l;
  l.from = Eigen::Vector3d(0.1, -0.2, 0.3), l.to = Eigen::Vector3d(0.5, 0.4, -0.1), l.start = 1, l.end = 3;
  CHECK((l(0.0).r - l.from).norm() == 0);
  CHECK((l(1.0).r - l.from).norm() < 1e-15);
  CHECK((l(3.0).r - l.to).norm() < 1e-15);
  CHECK((l(7.0).r - l.to).norm() == 0);
  CHECK((l(2.0).r - 0.5 * (l.from + l.to)).norm() < 1e-15);  // s(1/2) = 1/2 by symmetry
  for (double t : {1.0, 3.0, 0.5, 5.0}) CHECK(l(t).rd.norm() + l(t).rdd.norm() < 1e-12);
  const double h = 1e-5;
  for (double t : {1.3, 2.0, 2.71}) {
    const auto r = [&](double s) { return l(s).r; };
    const auto rd = [&](double s) { return l(s).rd; };
    CHECK((central(r, t, h) - l(t).rd).norm() < 1e-9);
    CHECK((central(rd, t, h) - l(t).rdd).norm() < 1e-8);
    // on the segment, and moving from `from` to `to`
    CHECK(((l(t).r - l.from).cross(l.to - l.from)).norm() < 1e-15);
    CHECK(l(t).rd.dot(l.to - l.from) > 0);
  }
  // a dual time gives ṙ as the derivative part (the reference is generic over the scalar)
  const auto d = l(dual<double, 1>::variable(2.3, 0));
  for (int i = 0; i < 3; ++i) CHECK(d.r(i).derivative(0) == Approx(l(2.3).rd(i)).epsilon(1e-14));
}

TEST_CASE("references: the clamped cubic spline reproduces a cubic that satisfies its end conditions, and is C2") {
  // p(t) = 3t² − 2t³ has p'(0) = p'(1) = 0: the clamped spline through any samples of it on
  // [0, 1] is p itself (the spline is the unique C² piecewise cubic with those conditions).
  const std::vector<double> times{0, 0.3, 0.45, 0.8, 1};
  Eigen::MatrixXd pts(5, 3);
  const auto p = [](double t) { return Eigen::Vector3d(3 * t * t - 2 * t * t * t, -(3 * t * t - 2 * t * t * t), 0.5); };
  for (int k = 0; k < 5; ++k) pts.row(k) = p(times[std::size_t(k)]).transpose();
  const spline_reference s(times, pts);
  for (double t = 0.013; t < 1; t += 0.0517) {
    CHECK((s(t).r - p(t)).norm() < 1e-14);
    CHECK(std::abs(s(t).rd(0) - (6 * t - 6 * t * t)) < 1e-13);
    CHECK(std::abs(s(t).rdd(0) - (6 - 12 * t)) < 1e-12);
  }
  // arbitrary waypoints: through them, zero velocity at the ends, C² at interior knots, held outside
  Eigen::MatrixXd w(4, 3);
  w << 0, 0, 0, 0.3, -0.1, 0.2, 0.1, 0.4, 0.2, -0.2, 0.2, 0;
  const std::vector<double> tw{0.5, 1.5, 2.0, 4.0};
  const spline_reference q(tw, w);
  for (int k = 0; k < 4; ++k) CHECK((q(tw[std::size_t(k)]).r - w.row(k).transpose()).norm() < 1e-14);
  CHECK(q(0.5).rd.norm() < 1e-14);
  CHECK(q(4.0).rd.norm() < 1e-14);
  CHECK((q(9.0).r - w.row(3).transpose()).norm() == 0);
  CHECK((q(0.0).r - w.row(0).transpose()).norm() == 0);
  const double e = 1e-9;
  for (int k = 1; k < 3; ++k) {
    const double t = tw[std::size_t(k)];
    CHECK((q(t - e).rd - q(t + e).rd).norm() < 1e-7);
    CHECK((q(t - e).rdd - q(t + e).rdd).norm() < 1e-7);
  }
  for (double t : {0.9, 1.7, 3.1}) {
    CHECK((central([&](double x) { return q(x).r; }, t, 1e-5) - q(t).rd).norm() < 1e-8);
    CHECK((central([&](double x) { return q(x).rd; }, t, 1e-5) - q(t).rdd).norm() < 1e-7);
  }
  CHECK_THROWS_WITH(spline_reference({0, 1, 1}, Eigen::MatrixXd::Zero(3, 3)), Catch::Contains("increase strictly"));
  CHECK_THROWS_WITH(spline_reference({0}, Eigen::MatrixXd::Zero(1, 3)), Catch::Contains("at least 2"));
  CHECK_THROWS_WITH(spline_reference({0, 1}, Eigen::MatrixXd::Zero(2, 2)), Catch::Contains("3 numbers"));
}

TEST_CASE("references: a joint spline's task image is r(q_d) with ṙ_d, r̈_d its time derivatives") {
  const auto robot = presets::paper5<double>();
  const kinematics<double, 5> kin(robot.chain);
  Eigen::MatrixXd q(3, 5);
  q << 0, 0, 0, 1.0, 0.5, 0.2, 0.1, 0.3, 1.4, 0.2, 0.4, 0.1, 0.5, 0.9, 0.8;
  const reference_spec spec = joint_spline_reference({0, 1, 2.5}, q);
  const scene_reference ref(spec, kin, 5, vec3<double>::Zero());
  for (double t : {0.4, 1.3, 2.2}) {
    const auto r = ref(t);
    REQUIRE(r.q.size() == 5);
    CHECK((r.r - kin.point(vecN<double, 5>(r.q), 5)).norm() < 1e-15);
    CHECK((central([&](double x) { return ref(x).r; }, t, 1e-5) - r.rd).norm() < 1e-8);
    CHECK((central([&](double x) { return ref(x).rd; }, t, 1e-5) - r.rdd).norm() < 1e-7);
    CHECK((central([&](double x) { return ref(x).q; }, t, 1e-5) - r.qd).norm() < 1e-8);
  }
}

// ---- the computed-torque controller -------------------------------------------------------

namespace {
/// e(t) for ë + 2ω ė + ω² e = 0, e(0) = e0, ė(0) = 0 (critically damped).
double critically_damped(double e0, double w, double t) { return e0 * (1 + w * t) * std::exp(-w * t); }
}  // namespace

TEST_CASE("computed torque: on its own model the joint error obeys ë + k_D ė + k_P e = 0 (holonomic tree)") {
  // puma560 as a tree, no constraint (S = I): τ = M(q) a_q + h exactly cancels the dynamics.
  const tree<double> t = as_tree(presets::puma560<double>());
  const holonomic<dynamic> c{6};
  const tree_kinematics<double> kin(t);
  Eigen::VectorXd qd(6), e0(6);
  qd << 0.1, -0.6, 0.4, 0.3, -0.5, 0.7;
  e0 << 0.1, -0.05, 0.08, -0.1, 0.06, 0.02;
  Eigen::MatrixXd hold(2, 6);
  hold << qd.transpose(), qd.transpose();
  const reference_spec spec = joint_spline_reference({0, 1}, hold);
  const scene_reference ref(spec, kin, 6, vec3<double>::Zero());
  const computed_torque_controller ctrl(t, c, ct_gains{100, 20});
  run_options o;
  o.duration = 1, o.tail_from = 0.5, o.tail_tolerance = 1;
  o.integrator = {method::dopri5, 1e-3, 1e-11, 1e-13};
  const Eigen::VectorXd q0 = qd + e0, eta0 = Eigen::VectorXd::Zero(6);
  const auto r = simulate_robot("ct", t, c, 6, vec3<double>::Zero(), ctrl, ref, q0, eta0, o, t.joint_names());
  INFO((r.failure ? *r.failure : std::string("ok")));
  REQUIRE(r.success);
  double worst = 0;
  for (Eigen::Index i = 0; i < r.rows.rows(); ++i)
    for (int j = 0; j < 6; ++j)
      worst = std::max(worst, std::abs(r.rows(i, 1 + j) - qd(j) - critically_damped(e0(j), 10, r.rows(i, 0))));
  CHECK(worst < 1e-8);
  // and the output's r_d is the task image of q_d (by the DH chain's own kinematics)
  const kinematics<double, 6> dh(presets::puma560<double>());
  CHECK((r.rows.row(r.rows.rows() - 1).segment<3>(1 + 6 + 12 + 3).transpose() - dh.point(vecN<double, 6>(qd), 6)).norm() < 1e-12);
}

TEST_CASE("computed torque: on paper5, the arm follows a moving joint spline with the same error law; the base stays") {
  // The base's reference is where it stands: only the arm moves. S is block-diagonal in
  // (base, arm), so the least-squares η̇ gives the arm a_q exactly.
  run_spec s;
  s.name = "ct-paper5";
  s.plant = {};  // the nominal plant
  s.controller = controller_type::computed_torque;
  s.ct = {225, 30};  // ω = 15 rad/s
  Eigen::MatrixXd w(3, 5);
  w << s.q0.transpose(), s.q0.transpose(), s.q0.transpose();
  w(1, 3) += 0.4, w(1, 4) -= 0.3, w(2, 3) -= 0.2, w(2, 4) += 0.5;
  s.reference = joint_spline_reference({0, 1, 2}, w);
  const kinematics<double, 5> kin(presets::paper5<double>().chain);
  const scene_reference ref(s.reference, kin, 5, vec3<double>::Zero());
  const double e4 = 0.05, e5 = -0.04;
  s.q0(3) += e4, s.q0(4) += e5;
  s.duration = 2.5, s.tail_from = 2, s.tail_tolerance = 1;
  s.integrator = {method::dopri5, 1e-3, 1e-11, 1e-13};
  const auto r = simulate(s);
  INFO((r.failure ? *r.failure : std::string("ok")));
  REQUIRE(r.success);
  double worst = 0, base = 0;
  for (Eigen::Index i = 0; i < r.rows.rows(); ++i) {
    const double t = r.rows(i, 0);
    const auto d = ref(t);
    worst = std::max(worst, std::abs(r.rows(i, 4) - d.q(3) - critically_damped(e4, 15, t)));
    worst = std::max(worst, std::abs(r.rows(i, 5) - d.q(4) - critically_damped(e5, 15, t)));
    for (int j = 0; j < 3; ++j) base = std::max(base, std::abs(r.rows(i, 1 + j) - s.q0(j)));
  }
  CHECK(worst < 1e-8);
  CHECK(base < 1e-12);
  // a task-space reference is refused for it, and a spline of the wrong size
  s.reference = circle_reference{};
  CHECK_THROWS_WITH(simulate(s), Catch::Contains("joint-space reference"));
  s.reference = joint_spline_reference({0, 1}, Eigen::MatrixXd::Zero(2, 4));
  CHECK_THROWS_WITH(simulate(s), Catch::Contains("waypoints of 4 joints"));
}
