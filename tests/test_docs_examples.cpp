// The code snippets of docs/api.md, compiled and checked. Each TEST_CASE holds one snippet
// (the code between "snippet" and "end snippet" is the code the page shows) followed by
// checks of what the page claims about it against a relation independent of the code
// under test: closed forms (planar two-link arm, a pendulum, paper5 with a massless arm),
// finite differences, hand-written S and Ṡ from paper5.md, power balance.
#include <catch2/catch.hpp>
#include <cmath>
#include <nhdyn/analysis/bounds.hpp>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/io/json.hpp>
#include <nhdyn/kinematics/tree.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/model/lock.hpp>
#ifdef NHDYN_HAVE_URDF
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/io/urdf.hpp>
#include <nhdyn/robot_dynamics.hpp>
#endif
#include <numbers>
#include <random>
#include <string>
#include <vector>
#include <Eigen/Geometry>

namespace {

using vec2 = Eigen::Vector2d;
using vec4 = Eigen::Vector4d;
using vec5 = Eigen::Matrix<double, 5, 1>;

// The planar elbow arm of Spong, Hutchinson & Vidyasagar (2006) §7.4.2 in closed form:
// links of length l, mass m, centre of mass lc from the joint, inertia I about z at the
// centre of mass, gravity −g along y₀.
struct planar2 {
  double l1 = 0.5, l2 = 0.4, m1 = 3.0, m2 = 2.0, w = 0.05, g = 9.81;
  double lc1() const { return l1 / 2; }
  double lc2() const { return l2 / 2; }
  double I1() const { return m1 * (l1 * l1 + w * w) / 12; }  // box about z: m(a² + b²)/12
  double I2() const { return m2 * (l2 * l2 + w * w) / 12; }
  Eigen::Matrix2d M(const vec2& q) const {
    const double c2 = std::cos(q(1));
    const double d11 = m1 * lc1() * lc1() + m2 * (l1 * l1 + lc2() * lc2() + 2 * l1 * lc2() * c2) + I1() + I2();
    const double d12 = m2 * (lc2() * lc2() + l1 * lc2() * c2) + I2();
    const double d22 = m2 * lc2() * lc2() + I2();
    Eigen::Matrix2d D;
    D << d11, d12, d12, d22;
    return D;
  }
  vec2 tau(const vec2& q, const vec2& qd, const vec2& qdd) const {
    const double h = -m2 * l1 * lc2() * std::sin(q(1));
    const double phi2 = m2 * lc2() * g * std::cos(q(0) + q(1));
    const double phi1 = (m1 * lc1() + m2 * l1) * g * std::cos(q(0)) + phi2;
    const vec2 c(2 * h * qd(0) * qd(1) + h * qd(1) * qd(1), -h * qd(0) * qd(0));
    return M(q) * qdd + c + vec2(phi1, phi2);
  }
};

// docs/theory.md §3, transcribed from the page with explicit matrices (R_i formed, no
// shared code with detail::rne_kernel): the forward and backward passes as written there.
Eigen::VectorXd rne_as_documented(const nhdyn::chain<double>& ch, const Eigen::VectorXd& q,
                                  const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd, bool gravity) {
  using Eigen::Matrix3d;
  using Eigen::Vector3d;
  const int n = ch.dof();
  const Vector3d zhat(0, 0, 1);
  Vector3d w = Vector3d::Zero(), dw = Vector3d::Zero();
  Vector3d a = gravity ? Vector3d(-ch.gravity()) : Vector3d::Zero();  // a_0 = −g
  std::vector<Matrix3d> R(n);
  std::vector<Vector3d> p(n), z(n), F(n), N(n);
  for (int i = 0; i < n; ++i) {
    const auto& L = ch[i];
    const bool rev = L.joint == nhdyn::joint_type::revolute;
    const double th = L.theta + (rev ? q(i) : 0.0), d = L.d + (rev ? 0.0 : q(i));
    R[i] = Eigen::AngleAxisd(th, zhat).toRotationMatrix() * Eigen::AngleAxisd(L.alpha, Vector3d::UnitX()).toRotationMatrix();
    p[i] = Vector3d(L.a, d * std::sin(L.alpha), d * std::cos(L.alpha));
    z[i] = Vector3d(0, std::sin(L.alpha), std::cos(L.alpha));
    const Matrix3d Rt = R[i].transpose();
    if (rev) {
      dw = Rt * (dw + zhat * qdd(i) + w.cross(zhat * qd(i)));
      w = Rt * (w + zhat * qd(i));
      a = Rt * a + dw.cross(p[i]) + w.cross(w.cross(p[i]));
    } else {
      w = Rt * w;
      dw = Rt * dw;
      a = Rt * a + z[i] * qdd(i) + dw.cross(p[i]) + w.cross(w.cross(p[i])) + 2 * qd(i) * w.cross(z[i]);
    }
    const Vector3d h = L.mass * L.com;
    const Matrix3d Io = L.inertia + L.mass * (L.com.squaredNorm() * Matrix3d::Identity() - L.com * L.com.transpose());
    F[i] = L.mass * a + dw.cross(h) + w.cross(w.cross(h));
    N[i] = Io * dw + w.cross(Io * w) + h.cross(a);
  }
  Eigen::VectorXd v(n);
  Vector3d f = Vector3d::Zero(), m = Vector3d::Zero();
  for (int i = n - 1; i >= 0; --i) {
    if (i + 1 < n) {
      f = R[i + 1] * f;
      m = R[i + 1] * m;
    }
    f += F[i];
    m += p[i].cross(f) + N[i];
    v(i) = ch[i].joint == nhdyn::joint_type::revolute ? z[i].dot(m) : z[i].dot(f);
  }
  return v;
}

double rel(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}
double relm(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

}  // namespace

TEST_CASE("docs/api.md §2: a chain built from DH rows and rigid-body parameters gives the closed-form planar-arm dynamics") {
  const planar2 ref;
  // snippet
  using nhdyn::joint_type;
  const double l1 = 0.5, l2 = 0.4, m1 = 3.0, m2 = 2.0, w = 0.05;
  std::vector<nhdyn::link<double>> links{
      // joint, α, a, θ offset, d offset, mass, com (frame i), inertia about com (frame i)
      {joint_type::revolute, 0, l1, 0, 0, m1, {-l1 / 2, 0, 0}, nhdyn::box_inertia(m1, l1, w, w)},
      {joint_type::revolute, 0, l2, 0, 0, m2, {-l2 / 2, 0, 0}, nhdyn::box_inertia(m2, l2, w, w)},
  };
  const nhdyn::chain<double> arm(links, {0, -9.81, 0}, "planar2");  // run-time size
  const auto arm2 = arm.fixed<2>();                                 // compile-time size

  const auto id = nhdyn::rne(arm);
  const Eigen::VectorXd q = vec2(0.3, -0.8), qd = vec2(1.1, -0.4), qdd = vec2(-0.5, 2.0);
  const Eigen::VectorXd v = id(q, qd, qdd);  // v = M(q)q̈ + C(q, q̇)q̇ + g(q)
  // end snippet
  CHECK(rel(v, ref.tau(q, qd, qdd)) < 1e-13);
  const vec2 v2 = nhdyn::rne(arm2)(vec2(q), vec2(qd), vec2(qdd));
  CHECK(rel(v2, v) < 1e-15);
}

#ifdef NHDYN_HAVE_URDF
TEST_CASE("docs/api.md §2: a URDF tree: gravity torques, branch-sparse M, a merged frame, a DH chain as a tree") {
  const std::string dir = NHDYN_SOURCE_DIR;
  // snippet (the path made absolute: the test runs in any folder)
  const nhdyn::tree<double> arm = nhdyn::io::load_urdf(dir + "/examples/urdf/mobile_manipulator.urdf");
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(arm.dof());
  const Eigen::VectorXd g = nhdyn::rne(arm)(q, q, q);            // gravity torques
  const Eigen::MatrixXd M = nhdyn::mass_matrix(arm)(q);            // CRBA, branch-sparse
  Eigen::VectorXd v(arm.dof());  Eigen::MatrixXd H;                // reused from call to call:
  nhdyn::rne(arm).evaluate(q, q, q, v);                            //   no allocation (a Map works too)
  nhdyn::mass_matrix(arm).evaluate(q, H);                          //   H sized n × n by its first call
  nhdyn::mass_matrix_result<double> Mr;                            // M kept between calls: its zeros
  nhdyn::mass_matrix(arm).evaluate(q, Mr);                         //   written by the first call only;
  const Eigen::MatrixXd& M2 = Mr.matrix();                         //   read-only (see below)
  const nhdyn::tree_kinematics<double> kin(arm);
  const auto tool = kin.frame(q, "tool_frame");                    // a merged fixed link, by name
  const auto t5 = nhdyn::as_tree(nhdyn::presets::paper5_chain());  // a DH chain is a tree
  // end snippet
  CHECK(arm.dof() == 16);
  // the evaluate forms give the calls' numbers, bit for bit
  CHECK(v == g);
  CHECK(H == M);
  CHECK(M2 == M);
  // gravity torques = −Σ J_cᵀ m g, from the kinematics
  Eigen::VectorXd grav = Eigen::VectorXd::Zero(arm.dof());
  for (int i = 0; i < arm.dof(); ++i)
    grav -= kin.jacobian(q, i + 1, arm[i].com).topRows<3>().transpose() * (arm[i].mass * arm.gravity());
  CHECK(rel(g, grav) < 1e-12);
  // the arm and the head are on different branches: they do not couple
  CHECK(M(arm.body_index("arm_1_link"), arm.body_index("head_pan_link")) == 0.0);
  // the tool frame is 0.08 + 0.15 m along arm_7_link's z axis
  const auto a7 = kin.frame(q, "arm_7_link");
  CHECK(rel(tool.p, a7.p + a7.R * Eigen::Vector3d(0, 0, 0.23)) < 1e-15);
  const Eigen::VectorXd q5 = Eigen::VectorXd::LinSpaced(5, 0.1, 0.9);
  CHECK(rel(nhdyn::rne(t5)(q5, q5, q5), nhdyn::rne(nhdyn::presets::paper5_chain())(q5, q5, q5)) < 1e-13);
}
#endif

#ifdef NHDYN_HAVE_URDF
TEST_CASE("docs/api.md §2: locked joints: a smaller tree, the map between the two") {
  const nhdyn::tree<double> arm = nhdyn::io::load_urdf(std::string(NHDYN_SOURCE_DIR) + "/examples/urdf/mobile_manipulator.urdf");
  // snippet
  const nhdyn::tree<double> small = nhdyn::lock(arm, {{"caster_*", 0.0}, {"head_pan_joint", 0.3}});
  // small.joint_names(): the 11 others, in their order; "caster_front_wheel_link" etc. stay named frames
  const nhdyn::lock_map map = nhdyn::lock_map_of(arm, {{"caster_*", 0.0}, {"head_pan_joint", 0.3}});
  // map.kept: the full q's indices of small's joints; map.expand_q(q_small): the full q
  // end snippet
  CHECK(small.dof() == 11);
  CHECK(small.find_frame("caster_front_wheel_link").body == -1);  // the castors hang from the base
  const Eigen::VectorXd qs = Eigen::VectorXd::LinSpaced(11, -0.6, 0.6);
  const Eigen::VectorXd q = map.expand_q(qs);
  CHECK(q(arm.body_index("head_pan_link")) == 0.3);
  // the tool frame stands where the full tree has it
  const nhdyn::tree_kinematics<double> kf(arm), ks(small);
  CHECK(rel(ks.frame(qs, "tool_frame").p, kf.frame(q, "tool_frame").p) < 1e-14);
  // gravity torques: the kept rows of the full tree's
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(11);
  CHECK(rel(nhdyn::rne(small)(qs, z, z), map.reduce(nhdyn::rne(arm)(q, map.expand(z), map.expand(z)))) < 1e-12);
}
#endif

#ifdef NHDYN_HAVE_URDF
TEST_CASE("docs/api.md §6: any wheels: a mecanum base's least-norm wheel torques") {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> U(-1, 1);
  const auto random = [&](int n) { return Eigen::VectorXd(Eigen::VectorXd::NullaryExpr(n, [&] { return U(rng); })); };
  const Eigen::VectorXd q = random(12), eta = random(8), eta_dot = random(8);
  const std::string dir = NHDYN_SOURCE_DIR;
  // snippet (the path made absolute: the test runs in any folder)
  nhdyn::io::urdf_options planar;
  planar.planar_base = true;  // q = (base_x, base_y, base_yaw, the URDF's joints)
  const nhdyn::tree<double> t = nhdyn::io::load_urdf(dir + "/examples/urdf/mecanum_arm.urdf", planar);
  const double r = 0.0475, g = std::numbers::pi / 4;  // rollers at ±45°
  const nhdyn::wheeled_base<double> mecanum(t, {{nhdyn::wheel_kind::swedish, "wheel_fl_joint", "", r, -g},
                                                {nhdyn::wheel_kind::swedish, "wheel_fr_joint", "", r, g},
                                                {nhdyn::wheel_kind::swedish, "wheel_rl_joint", "", r, g},
                                                {nhdyn::wheel_kind::swedish, "wheel_rr_joint", "", r, -g}});
  // k = 4, η = (base_x, base_y, base_yaw, the arm's 5): m = 8; τ = the 4 wheels and the arm: p = 9
  const auto id = nhdyn::inverse_dynamics(t, mecanum);   // project ∘ rne ∘ lift, as for every constraint
  const Eigen::VectorXd tau = id(q, eta, eta_dot);       // the wheels' torques of least norm
  // end snippet
  CHECK(mecanum.k() == 4);
  CHECK(mecanum.m() == 8);
  CHECK(mecanum.p() == 9);
  CHECK(tau.size() == 9);
  CHECK(mecanum.eta_names(t.joint_names())[1] == "base_y");
  // SᵀE τ = Sᵀ v with v = rne at the lifted state, and τ ⟂ null(SᵀE) (the least norm)
  const Eigen::MatrixXd S = mecanum.S(q), E = mecanum.E(q), B = S.transpose() * E;
  const auto xi = nhdyn::lift(mecanum)(q, eta, eta_dot);
  const Eigen::VectorXd v = nhdyn::rne(t)(xi.q, xi.qd, xi.qdd);
  CHECK(rel(B * tau, S.transpose() * v) < 1e-12);
  const Eigen::MatrixXd N = Eigen::FullPivLU<Eigen::MatrixXd>(B).kernel();
  REQUIRE(N.cols() == 1);
  CHECK(std::abs(N.col(0).dot(tau)) < 1e-12 * (1 + tau.norm()));
  // the shipped robot file builds the same constraint
  const auto file = nhdyn::io::load_robot_file(dir + "/examples/robots/mecanum_arm.json");
  CHECK(rel(nhdyn::inverse_dynamics(file.model, std::get<nhdyn::wheeled_base<double>>(*file.constraint))(q, eta, eta_dot), tau) < 1e-15);
}
#endif

#ifdef NHDYN_HAVE_URDF
TEST_CASE("docs/api.md §11: robot_dynamics gives the template API's numbers, and v = E tau + A^T lambda") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  const auto random = [&](int n) { return Eigen::VectorXd(Eigen::VectorXd::NullaryExpr(n, [&] { return U(rng); })); };
  const Eigen::VectorXd q = random(12), eta = random(8), eta_dot = random(8);
  Eigen::VectorXd tau_reused;
  const std::string dir = NHDYN_SOURCE_DIR;
  // snippet (the path made absolute: the test runs in any folder)
  const auto robot = nhdyn::robot_dynamics::load(dir + "/examples/robots/mecanum_arm.json");
  // a preset, a URDF, a robot file or a JSON model; robot.dof() = n, m(), k(), p(), the names
  const Eigen::VectorXd tau = robot.inverse_dynamics(q, eta, eta_dot);  // project ∘ rne ∘ lift
  const auto f = robot.inverse_dynamics_with_forces(q, eta, eta_dot);   // f.tau, f.lambda
  const Eigen::VectorXd eta_dot_back = robot.nh_forward_dynamics(q, eta, f.tau);  // = eta_dot
  const auto xi = robot.lift(q, eta, eta_dot);                           // xi.q, xi.qd, xi.qdd
  const Eigen::VectorXd v = robot.rne(xi.q, xi.qd, xi.qdd);              // = E τ + Aᵀλ
  const Eigen::MatrixXd M = robot.mass_matrix(q), E = robot.input_map(q), A = robot.A(q);
  const auto lin = robot.nh_forward_dynamics_derivatives(q, eta, f.tau);  // lin.A, lin.B: ẋ = f(x, τ)
  robot.inverse_dynamics(q, eta, eta_dot, tau_reused);                   // into storage, no allocation
  // end snippet
  CHECK(robot.dof() == 12);
  CHECK(robot.m() == 8);
  CHECK(robot.k() == 4);
  CHECK(robot.p() == 9);
  CHECK(tau_reused == tau);
  CHECK(f.tau == tau);
  CHECK(rel(eta_dot_back, eta_dot) < 1e-9);
  CHECK(rel(E * f.tau + A.transpose() * f.lambda, v) < 1e-10);
  CHECK(relm(M, M.transpose()) < 1e-15);
  CHECK(lin.A.rows() == 20);
  CHECK(lin.B.cols() == 9);
  // the template API on the same file: the same τ (compiled in the library or here)
  const auto file = nhdyn::io::load_robot_file(dir + "/examples/robots/mecanum_arm.json");
  const auto& c = std::get<nhdyn::wheeled_base<double>>(*file.constraint);
  CHECK(rel(nhdyn::inverse_dynamics(file.model, c)(q, eta, eta_dot), tau) < 1e-15);
  CHECK(relm(nhdyn::mass_matrix(file.model)(q), M) < 1e-15);
}
#endif

TEST_CASE("docs/api.md §2: an unphysical link is refused with a message naming the model, link and field") {
  // snippet
  nhdyn::link<double> bad;
  bad.mass = -1.0;
  try {
    nhdyn::chain<double> c({bad}, {0, 0, -9.81}, "oops");
  } catch (const nhdyn::model_error& e) {
    // e.what(): "model 'oops', link 1, field 'mass': is negative (-1 kg)"
    // end snippet
    CHECK(std::string(e.what()).find("model 'oops', link 1, field 'mass'") != std::string::npos);
    return;
  }
  FAIL("no model_error thrown");
}

TEST_CASE("docs/api.md §3a: choosing the terms: the forward dynamics with friction invert the inverse dynamics with it") {
  const auto puma = nhdyn::presets::puma560_motors();
  const auto p5 = nhdyn::presets::paper5<double>();
  const auto& robot = p5.chain;
  const auto& c = p5.constraint;
  // snippet
  const auto t = nhdyn::terms::parse("gravity,velocity,armature,friction");  // any order; or "all", "none"
  const auto model = nhdyn::with_terms(puma, t);       // puma, or without_armature(puma) when armature is out
  const auto fr = nhdyn::friction(model, t.coulomb);   // t.coulomb: exact unless set to coulomb_law::smooth(v_s)
  const auto id = nhdyn::rne(model, t.rne()) + fr;     // t.rne(): rne_options{gravity, velocity}
  const auto fd = nhdyn::forward_dynamics(model, t.rne()).with(fr);  // q̈ = M⁻¹(τ − h − τ_f(q̇)): inverts id
  const auto rob = nhdyn::with_terms(robot, t);        // a robot with a constraint c, likewise
  const auto nh_id = nhdyn::inverse_dynamics(rob, c, t.rne(), nhdyn::friction(rob, t.coulomb));  // project ∘ (rne + τ_f) ∘ lift
  const auto nh_fd = nhdyn::nh_forward_dynamics(rob, c, t.rne()).with(nhdyn::friction(rob, t.coulomb));
  // end snippet
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(6, -1, 1), qd = Eigen::VectorXd::LinSpaced(6, 0.5, -0.7),
                        qdd = Eigen::VectorXd::LinSpaced(6, 1, 2);
  CHECK(rel(fd(q, qd, id(q, qd, qdd)), qdd) < 1e-10);
  // the friction is in: G²B + |G|Tc⁺ of joint 1 at q̇ = 0.5 (Corke's drive parameters)
  CHECK(std::abs((id(q, qd, qdd) - nhdyn::rne(puma)(q, qd, qdd))(0) -
                 (62.6111 * 62.6111 * 1.48e-3 * 0.5 + 62.6111 * 0.395)) < 1e-12);
  const Eigen::Vector<double, 5> q5(0.1, -0.2, 0.3, 0.4, -0.5);
  const Eigen::Vector4d eta(0.3, -0.1, 0.5, 0.2), eta_dot(-0.4, 0.2, 0.1, 0.3);
  CHECK(rel(nh_fd(q5, eta, nh_id(q5, eta, eta_dot)), eta_dot) < 1e-10);
}

TEST_CASE("docs/api.md §3: rne options drop gravity and velocity terms as the closed form says") {
  const planar2 ref;
  const auto arm = nhdyn::chain<double>(
      {{nhdyn::joint_type::revolute, 0, 0.5, 0, 0, 3.0, {-0.25, 0, 0}, nhdyn::box_inertia(3.0, 0.5, 0.05, 0.05)},
       {nhdyn::joint_type::revolute, 0, 0.4, 0, 0, 2.0, {-0.2, 0, 0}, nhdyn::box_inertia(2.0, 0.4, 0.05, 0.05)}},
      {0, -9.81, 0});
  const vec2 q(0.3, -0.8), qd(1.1, -0.4), qdd(-0.5, 2.0);
  // snippet
  const auto id = nhdyn::rne(arm);
  const auto inertial = id.with({.gravity = false, .velocity = false});  // v = M(q) q̈
  const auto gravity = nhdyn::rne(arm, {.gravity = true, .velocity = false});
  const Eigen::VectorXd Mqdd = inertial(q, qd, qdd);
  const Eigen::VectorXd g = gravity(q, qd, vec2::Zero());  // g(q); q̇ is not read
  const Eigen::MatrixXd M = nhdyn::mass_matrix(arm)(q);    // CRBA
  const Eigen::VectorXd h = nhdyn::bias(arm)(q, qd);       // C(q, q̇)q̇ + g(q) = rne(q, q̇, 0)
  const Eigen::VectorXd qdd_back = nhdyn::forward_dynamics(arm)(q, qd, id(q, qd, qdd));
  // end snippet
  CHECK(rel(Mqdd, ref.M(q) * qdd) < 1e-13);
  CHECK(rel(g, ref.tau(q, vec2::Zero(), vec2::Zero())) < 1e-13);
  CHECK((M - ref.M(q)).norm() < 1e-13);
  CHECK(rel(h, ref.tau(q, qd, vec2::Zero())) < 1e-13);
  CHECK(rel(qdd_back, qdd) < 1e-12);
}

TEST_CASE("docs/api.md §4: kinematics gives paper5's start tip, and its Jacobian and J̇q̇ match finite differences") {
  // snippet
  const auto robot = nhdyn::presets::paper5();
  const nhdyn::kinematics k(robot.chain);
  vec5 q;
  q << -0.23710299623923958, 1.0, std::numbers::pi, 2.058145585963254, 1.2;  // paper5.md's start
  const Eigen::Vector3d tip = k.point(q, 5);            // origin of frame 5, in frame 0
  const auto X = k.forward(q);                          // frames 0…5: X[i].R, X[i].p
  const Eigen::Matrix<double, 6, 5> J = k.jacobian(q, 5);  // [J_v; J_ω], frame 0
  const vec5 qd(0.2, -0.1, 0.3, 0.5, -0.7);
  const auto Jdqd = k.jdot_qdot(q, qd, 5);              // .linear, .angular
  // end snippet
  CHECK((tip - Eigen::Vector3d(0.35, 1.0, 0.0)).norm() < 1e-9);
  CHECK((X[5].p - tip).norm() == 0.0);
  const double h = 1e-6;
  for (int j = 0; j < 5; ++j) {
    vec5 dq = vec5::Zero();
    dq(j) = h;
    const Eigen::Vector3d fd = (k.point(vec5(q + dq), 5) - k.point(vec5(q - dq), 5)) / (2 * h);
    CHECK((J.col(j).head<3>() - fd).norm() < 1e-8);
  }
  // J̇q̇ = d/dt (J q̇) along q(t) = q + t q̇ with q̇ constant.
  const Eigen::Matrix<double, 6, 1> fd =
      (k.jacobian(vec5(q + h * qd), 5) * qd - k.jacobian(vec5(q - h * qd), 5) * qd) / (2 * h);
  CHECK((Jdqd.linear - fd.head<3>()).norm() < 1e-8);
  CHECK((Jdqd.angular - fd.tail<3>()).norm() < 1e-8);
}

TEST_CASE("docs/api.md §5: rne runs on float, long double and duals; the dual derivative matches finite differences") {
  const auto robot = nhdyn::presets::paper5();
  const vec5 q(0.3, -0.2, 0.5, 0.8, -1.0), qd(0.4, 0.1, 0.2, 1.0, -0.5), qdd(0.3, -0.2, -0.1, 2.0, 1.0);
  // snippet
  const auto id_f = nhdyn::rne(robot.chain.cast<float>());
  const Eigen::Matrix<float, 5, 1> v_f = id_f(q.cast<float>(), qd.cast<float>(), qdd.cast<float>());

  using D = nhdyn::dual<double, 5>;  // 5 derivative directions, held inline
  Eigen::Matrix<D, 5, 1> qx;
  for (int j = 0; j < 5; ++j) qx(j) = D::variable(q(j), j);  // seed ∂/∂q_j
  const auto v_d = nhdyn::rne(robot.chain)(qx, qd.cast<D>(), qdd.cast<D>());  // model double, state dual
  // v_d(i).value() = v_i,   v_d(i).derivative(j) = ∂v_i/∂q_j
  // end snippet
  const vec5 v = nhdyn::rne(robot.chain)(q, qd, qdd);
  CHECK((v_f.cast<double>() - v).norm() < 1e-4 * std::max(1.0, v.norm()));
  const auto id_ld = nhdyn::rne(robot.chain.cast<long double>());
  const Eigen::Matrix<long double, 5, 1> v_ld =
      id_ld(q.cast<long double>(), qd.cast<long double>(), qdd.cast<long double>());
  CHECK((v_ld.cast<double>() - v).norm() < 1e-12 * std::max(1.0, v.norm()));
  const double h = 1e-6;
  for (int j = 0; j < 5; ++j) {
    vec5 dq = vec5::Zero();
    dq(j) = h;
    const vec5 fd = (nhdyn::rne(robot.chain)(vec5(q + dq), qd, qdd) - nhdyn::rne(robot.chain)(vec5(q - dq), qd, qdd)) / (2 * h);
    for (int i = 0; i < 5; ++i) {
      CHECK(v_d(i).value() == Approx(v(i)).margin(1e-15));
      CHECK(v_d(i).derivative(j) == Approx(fd(i)).margin(1e-7));
    }
  }
}

TEST_CASE("docs/api.md §6: paper5's constraint has the A and S of paper5.md, A S = 0, and Ṡ matches finite differences") {
  const vec5 q(0.3, -0.2, 0.7, 0.8, -1.0), qd(0.1, 0.2, -0.6, 0.4, 0.3);
  // snippet
  const auto c = nhdyn::presets::paper5_constraint();  // = differential_drive<double,5>(5, 0, 1, 2, 0, −1)
  const auto A = c.A(q);           // 1×5: [sin q₃, cos q₃, 0, 0, 0]
  const auto S = c.S(q);           // 5×4
  const auto Sdot = c.Sdot(q, qd); // 5×4, Ṡ = Σ_j ∂S/∂q_j q̇_j
  // c.k() = 1, c.m() = 4, c.dof() = 5
  // end snippet
  const double s = std::sin(q(2)), co = std::cos(q(2));
  Eigen::Matrix<double, 1, 5> A_ref;
  A_ref << s, co, 0, 0, 0;
  Eigen::Matrix<double, 5, 4> S_ref = Eigen::Matrix<double, 5, 4>::Zero();
  S_ref(0, 0) = co;
  S_ref(1, 0) = -s;
  S_ref(2, 1) = S_ref(3, 2) = S_ref(4, 3) = 1;
  CHECK((A - A_ref).norm() < 1e-15);
  CHECK((S - S_ref).norm() < 1e-15);
  CHECK((A * S).norm() < 1e-15);
  CHECK(c.k() == 1);
  CHECK(c.m() == 4);
  CHECK(c.dof() == 5);
  const double h = 1e-6;
  const Eigen::Matrix<double, 5, 4> fd = (c.S(vec5(q + h * qd)) - c.S(vec5(q - h * qd))) / (2 * h);
  CHECK((Sdot - fd).norm() < 1e-9);
}

TEST_CASE("docs/api.md §6: wheeled bases: the wheels' and the bicycle's S give the closed-form planar motions") {
  const int n = 6;  // x, y, heading, two wheels (or a steering joint and one more), an arm joint
  // snippet
  // two drive wheels (joints 3, 4) of radius 0.1 m at y = ±0.26 m on an axle through the base
  // origin; k = 3, η = (φ̇_left, φ̇_right, the other joints' rates)
  const nhdyn::rolling_wheels<double> wheels(n, 3, 4, 0.1, 0.26, -0.26);
  // a car-like base: steering joint 3, wheelbase 0.24 m; k = 2, η = (v, δ̇, the others' rates)
  const nhdyn::bicycle<double> car(n, 3, 0.24);
  // end snippet
  CHECK(wheels.k() == 3);
  CHECK(car.k() == 2);
  Eigen::Matrix<double, 6, 1> q;
  q << 1.0, -2.0, 0.4, 0.3, -0.7, 0.2;
  // both wheels at 2 rad/s: straight ahead at r·φ̇ = 0.2 m/s along the heading, no turning
  Eigen::VectorXd qd = wheels.S(q) * Eigen::Vector3d(2, 2, 0);
  CHECK(qd(0) == Approx(0.2 * std::cos(0.4)));
  CHECK(qd(1) == Approx(0.2 * std::sin(0.4)));
  CHECK(qd(2) == Approx(0).margin(1e-15));
  // opposite rates: turning on the spot at ω = r(φ̇_R − φ̇_L)/track = 0.1·4/0.52
  qd = wheels.S(q) * Eigen::Vector3d(-2, 2, 0);
  CHECK(qd.head(2).norm() == Approx(0).margin(1e-15));
  CHECK(qd(2) == Approx(0.4 / 0.52));
  // the bicycle at v = 1 m/s and steering angle q₃ = 0.3: ψ̇ = tan(0.3) / 0.24
  qd = car.S(q) * Eigen::Vector4d(1, 0, 0, 0);
  CHECK(qd(2) == Approx(std::tan(0.3) / 0.24));
  CHECK(Eigen::Vector2d(qd(0), qd(1)).norm() == Approx(1));
}

TEST_CASE("docs/api.md §7: the pipeline's τ equals Sᵀ·rne(q, Sη, Sη̇ + Ṡη) with S and Ṡ written by hand") {
  // snippet
  const auto robot = nhdyn::presets::paper5();
  const auto& c = robot.constraint;

  // The three stages, each a function object; compose them either way.
  const auto lift = nhdyn::lift(c);        // ζ = (q, η, η̇) ↦ ξ = (q, Sη, Sη̇ + Ṡη)   (eq. 19)
  const auto rne = nhdyn::rne(robot.chain);  // ξ ↦ (q, v)
  const auto project = nhdyn::project(c);  // (q, v) ↦ τ = (SᵀS)⁻¹Sᵀv               (eq. 18)
  const auto id_pipe = lift | rne | project;                      // reads as the data flows
  const auto id_compose = nhdyn::compose(project, rne, lift);     // reads as mathematics
  const auto id = nhdyn::inverse_dynamics(robot.chain, c);        // the same composition

  const vec5 q(0.3, -0.2, std::numbers::pi / 6, std::numbers::pi / 4, -std::numbers::pi / 3);
  const vec4 eta(0.5, 0.2, 1.0, -0.5), eta_dot(0.4, -0.1, 2.0, 1.0);  // η = (v, ω, q̇₄, q̇₅)
  const vec4 tau = id(q, eta, eta_dot);  // (forward force, yaw torque, shoulder, elbow)

  const auto xi = lift(q, eta, eta_dot);  // joint_state: xi.q, xi.qd, xi.qdd
  const auto f = rne(xi);                 // generalized_forces: f.q, f.v
  const vec4 tau_staged = project(f);
  // end snippet

  // Independent: S and Ṡ by hand from paper5.md, the relation of Theorem 1 with SᵀS = I.
  const double s = std::sin(q(2)), co = std::cos(q(2)), w = eta(1), v = eta(0);
  Eigen::Matrix<double, 5, 4> S = Eigen::Matrix<double, 5, 4>::Zero(), Sdot = S;
  S(0, 0) = co;
  S(1, 0) = -s;
  S(2, 1) = S(3, 2) = S(4, 3) = 1;
  Sdot(0, 0) = -s * w;  // d/dt cos q₃, q̇₃ = ω
  Sdot(1, 0) = -co * w;
  const vec5 qd = S * eta, qdd = S * eta_dot + Sdot * eta;
  const vec4 tau_hand = S.transpose() * nhdyn::rne(robot.chain)(q, qd, qdd);
  CHECK((xi.qd - qd).norm() < 1e-15);
  CHECK((xi.qdd - qdd).norm() < 1e-15);
  CHECK((tau - tau_hand).norm() < 1e-13 * tau_hand.norm());
  CHECK((tau_staged - tau).norm() == 0.0);
  CHECK((id_pipe(q, eta, eta_dot) - tau).norm() == 0.0);
  CHECK((id_compose(q, eta, eta_dot) - tau).norm() == 0.0);
  // Hand check of the lift, as docs/theory.md §7 does it: q̈₁ = v̇ cos q₃ − v ω sin q₃.
  CHECK(xi.qdd(0) == Approx(eta_dot(0) * co - v * w * s).epsilon(1e-14));
}

TEST_CASE("docs/api.md §7: with a massless arm, τ and λ are the platform's closed-form forces") {
  // paper5 with links 4 and 5 massless: the platform (9 kg, centre of mass on the yaw axis)
  // needs τ = (m v̇, I_yaw ω̇, 0, 0) and a lateral force λ = −m v ω (its centripetal force).
  nhdyn::presets::paper5_parameters<double> p;
  p.mass_factor[3] = p.mass_factor[4] = 0.0;
  const auto robot = nhdyn::presets::paper5(p);
  const vec5 q(0.3, -0.2, 0.7, 0.8, -1.0);
  const vec4 eta(0.5, 0.2, 1.0, -0.5), eta_dot(0.4, -0.1, 2.0, 1.0);
  // snippet
  const auto with_forces = nhdyn::inverse_dynamics_with_forces(robot.chain, robot.constraint);
  const auto tl = with_forces(q, eta, eta_dot);  // tl.tau (4), tl.lambda (1)
  // end snippet
  const double m = 9.0, I_yaw = m * (0.445 * 0.445 + 0.393 * 0.393) / 12;
  CHECK(tl.tau(0) == Approx(m * eta_dot(0)).epsilon(1e-13));
  CHECK(tl.tau(1) == Approx(I_yaw * eta_dot(1)).epsilon(1e-13));
  CHECK(std::abs(tl.tau(2)) < 1e-14);
  CHECK(std::abs(tl.tau(3)) < 1e-14);
  CHECK(tl.lambda(0) == Approx(-m * eta(0) * eta(1)).epsilon(1e-13));
}

TEST_CASE("docs/api.md §7: a user stage maps wheel speeds in and wheel torques out, conserving power") {
  const auto robot = nhdyn::presets::paper5();
  const auto& c = robot.constraint;
  const vec5 q(0.3, -0.2, 0.7, 0.8, -1.0);
  // snippet
  // Wheel radius r and track b: (v, ω) = J (φ̇_R, φ̇_L); wheel torques = Jᵀ (force, yaw torque).
  const double r = 0.1, b = 0.4;
  Eigen::Matrix4d J = Eigen::Matrix4d::Identity();
  J.topLeftCorner<2, 2>() << r / 2, r / 2, r / b, -r / b;
  const auto wheels_in = nhdyn::stage([J](const vec5& q, const vec4& phi_dot, const vec4& phi_ddot) {
    return nhdyn::reduced_state<double, 5, 4>{q, J * phi_dot, J * phi_ddot};
  });
  const auto wheels_out = nhdyn::stage([J](const vec4& tau) { return vec4(J.transpose() * tau); });
  const auto id_wheels = wheels_in | nhdyn::lift(c) | nhdyn::rne(robot.chain) | nhdyn::project(c) | wheels_out;
  const vec4 phi_dot(6.0, 4.0, 1.0, -0.5), phi_ddot(3.0, 5.0, 2.0, 1.0);  // (φ̇_R, φ̇_L, q̇₄, q̇₅)
  const vec4 wheel_tau = id_wheels(q, phi_dot, phi_ddot);  // (τ_R, τ_L, shoulder, elbow)
  // end snippet
  const vec4 eta = J * phi_dot;
  const vec4 tau = nhdyn::inverse_dynamics(robot.chain, c)(q, eta, vec4(J * phi_ddot));
  CHECK(eta(0) == Approx(r * (6.0 + 4.0) / 2));
  CHECK(eta(1) == Approx(r * (6.0 - 4.0) / b));
  CHECK(wheel_tau.dot(phi_dot) == Approx(tau.dot(eta)).epsilon(1e-13));  // same power
  CHECK(wheel_tau(0) + wheel_tau(1) == Approx(r * tau(0)).epsilon(1e-13));
}

TEST_CASE("docs/api.md §6: a user constraint from plain functions gives paper5's τ, with Ṡ by duals") {
  const auto robot = nhdyn::presets::paper5();
  const vec5 q0(0.3, -0.2, 0.7, 0.8, -1.0), qd0(0.1, 0.2, -0.6, 0.4, 0.3);
  // snippet
  // paper5's constraint written by hand: generic lambdas, so they also run on duals.
  const auto fA = [](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    using std::cos, std::sin;
    Eigen::Matrix<T, -1, -1> A = Eigen::Matrix<T, -1, -1>::Zero(1, 5);
    A(0, 0) = sin(q(2));
    A(0, 1) = cos(q(2));
    return A;
  };
  const auto fS = [](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    using std::cos, std::sin;
    Eigen::Matrix<T, -1, -1> S = Eigen::Matrix<T, -1, -1>::Zero(5, 4);
    S(0, 0) = cos(q(2));
    S(1, 0) = -sin(q(2));
    S(2, 1) = S(3, 2) = S(4, 3) = T(1);
    return S;
  };
  const auto c = nhdyn::make_constraint(5, 1, fA, fS);  // n = 5 joints, k = 1 row; Ṡ by duals
  const auto chain = robot.chain.dynamic_size();       // user constraints are run-time sized
  const auto id = nhdyn::inverse_dynamics(chain, c);
  const Eigen::VectorXd q = vec5(0.3, -0.2, 0.7, 0.8, -1.0);
  const Eigen::VectorXd eta = vec4(0.5, 0.2, 1.0, -0.5), eta_dot = vec4(0.4, -0.1, 2.0, 1.0);
  const Eigen::VectorXd tau = id(q, eta, eta_dot);
  // end snippet
  const vec4 tau_builtin = nhdyn::inverse_dynamics(robot.chain, robot.constraint)(q0, vec4(eta), vec4(eta_dot));
  CHECK((tau - tau_builtin).norm() < 1e-13 * tau_builtin.norm());
  Eigen::MatrixXd Sdot_hand = Eigen::MatrixXd::Zero(5, 4);
  Sdot_hand(0, 0) = -std::sin(q0(2)) * qd0(2);
  Sdot_hand(1, 0) = -std::cos(q0(2)) * qd0(2);
  CHECK((c.Sdot(q, Eigen::VectorXd(qd0)) - Sdot_hand).norm() < 1e-15);
}

TEST_CASE("docs/api.md §8: constrained forward dynamics inverts the inverse dynamics; both ways of building M_η agree") {
  const vec5 q(0.3, -0.2, 0.7, 0.8, -1.0);
  const vec4 eta(0.5, 0.2, 1.0, -0.5), eta_dot(0.4, -0.1, 2.0, 1.0);
  // snippet
  const auto robot = nhdyn::presets::paper5();
  const auto fd = nhdyn::nh_forward_dynamics(robot.chain, robot.constraint);  // CRBA projected by S
  const vec4 tau = nhdyn::inverse_dynamics(robot.chain, robot.constraint)(q, eta, eta_dot);
  const vec4 eta_dot_back = fd(q, eta, tau);            // η̇ = M_η⁻¹(SᵀS τ − h_η)
  const Eigen::Matrix4d M_eta = fd.reduced_inertia(q);  // Sᵀ M S
  const vec4 h_eta = fd.reduced_bias(q, eta);           // Sᵀ rne(q, Sη, Ṡη)
  const auto fd_cols = nhdyn::nh_forward_dynamics(robot.chain, robot.constraint, {},
                                                  nhdyn::reduced_inertia_method::rne_columns);
  const vec5 qdot = nhdyn::apply_S(robot.constraint, q, eta);  // the state derivative (q̇, η̇) = (Sη, η̇)
  // end snippet
  CHECK((eta_dot_back - eta_dot).norm() < 1e-10);
  const auto S = robot.constraint.S(q);
  CHECK((M_eta - S.transpose() * nhdyn::mass_matrix(robot.chain)(q) * S).norm() < 1e-14);
  CHECK((fd_cols.reduced_inertia(q) - M_eta).norm() < 1e-13);
  CHECK((M_eta * eta_dot + h_eta - tau).norm() < 1e-12);
  CHECK((qdot - S * eta).norm() < 1e-15);
  // M_η(0, 0) is the whole robot's mass: driving forward moves every link.
  CHECK(M_eta(0, 0) == Approx(9.2).epsilon(1e-14));
}

TEST_CASE("docs/api.md §9: wrong sizes and non-finite inputs are errors that say what is wrong") {
  const auto arm = nhdyn::presets::puma560().dynamic_size();
  // snippet
  const auto id = nhdyn::rne(arm);  // arm: presets::puma560().dynamic_size()
  try {
    id(Eigen::VectorXd::Zero(5), Eigen::VectorXd::Zero(6), Eigen::VectorXd::Zero(6));
  } catch (const nhdyn::input_error& e) {
    // e.what(): "q has 5 entries; the model needs 6"
    // end snippet
    CHECK(std::string(e.what()) == "q has 5 entries; the model needs 6");
  }
  CHECK_THROWS_AS(id(Eigen::VectorXd::Zero(5), Eigen::VectorXd::Zero(6), Eigen::VectorXd::Zero(6)), nhdyn::input_error);
  // Compile-time-sized models check sizes too.
  const auto id5 = nhdyn::rne(nhdyn::presets::paper5().chain);
  CHECK_THROWS_AS(id5(Eigen::VectorXd::Zero(4), Eigen::VectorXd::Zero(5), Eigen::VectorXd::Zero(5)), nhdyn::input_error);
  Eigen::VectorXd qd = Eigen::VectorXd::Zero(6);
  qd(2) = std::nan("");
  CHECK_THROWS_AS(id(Eigen::VectorXd::Zero(6), qd, Eigen::VectorXd::Zero(6)), nhdyn::error);
  CHECK_THROWS_WITH(id(Eigen::VectorXd::Zero(6), qd, Eigen::VectorXd::Zero(6)), Catch::Contains("qd[2]"));
}

TEST_CASE("docs/theory.md §3: the link-frame recursion as written there reproduces rne on random chains") {
  std::mt19937 gen(20261121);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 2 + trial % 7;
    std::vector<nhdyn::link<double>> links(static_cast<std::size_t>(n));
    for (auto& L : links) {
      L.joint = u(gen) > 0 ? nhdyn::joint_type::revolute : nhdyn::joint_type::prismatic;
      L.alpha = 3 * u(gen);
      L.a = u(gen);
      L.theta = 3 * u(gen);
      L.d = u(gen);
      L.mass = 1.5 + u(gen);
      L.com = Eigen::Vector3d(u(gen), u(gen), u(gen)) * 0.3;
      const Eigen::Matrix3d Rr = Eigen::Quaterniond(Eigen::Vector4d(u(gen), u(gen), u(gen), u(gen)).normalized()).toRotationMatrix();
      L.inertia = Rr * nhdyn::box_inertia(L.mass, 1.2 + u(gen), 1.2 + u(gen), 1.2 + u(gen)) * Rr.transpose();
    }
    if (trial % 5 == 0) links[1].mass = 0, links[1].com.setZero(), links[1].inertia.setZero();  // skipped link
    const nhdyn::chain<double> ch(links, Eigen::Vector3d(u(gen), u(gen), -9.81), "random");
    Eigen::VectorXd q(n), qd(n), qdd(n);
    for (int i = 0; i < n; ++i) q(i) = 2 * u(gen), qd(i) = 2 * u(gen), qdd(i) = 2 * u(gen);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
    const Eigen::VectorXd v = nhdyn::rne(ch)(q, qd, qdd);
    CHECK(rel(v, rne_as_documented(ch, q, qd, qdd, true)) < 1e-13);
    // velocity = false: the same recursion with q̇ = 0 (ω ≡ 0); gravity = false: a_0 = 0.
    CHECK(rel(nhdyn::rne(ch, {.gravity = true, .velocity = false})(q, qd, qdd), rne_as_documented(ch, q, zero, qdd, true)) < 1e-13);
    CHECK(rel(nhdyn::rne(ch, {.gravity = false, .velocity = true})(q, qd, qdd), rne_as_documented(ch, q, qd, qdd, false)) < 1e-13);
    // (★) of theory.md §3: rne(q, q̇, q̈) = M(q) q̈ + rne(q, q̇, 0).
    CHECK(rel(v, nhdyn::mass_matrix(ch)(q) * qdd + nhdyn::rne(ch)(q, qd, zero)) < 1e-12);
  }
}

TEST_CASE("docs/api.md §2: a model read from JSON text gives the pendulum's closed form, and errors name the link and field") {
  // snippet
  // #include <nhdyn/io/json.hpp>  (needs nlohmann-json3-dev)
  const std::string text = R"({"name": "pendulum", "gravity": [0, -9.81, 0],
    "links": [{"joint": "revolute", "alpha": 0, "a": 0.7, "theta": 0, "d": 0, "mass": 2,
               "com": [0, 0, 0], "inertia": [[0, 0, 0], [0, 0, 0], [0, 0, 0]]}]})";
  const nhdyn::io::model<double> m = nhdyn::io::parse_model(text, "inline");
  // m.chain: chain<double> (run-time size); m.constraint: std::optional<differential_drive<double>>
  const Eigen::VectorXd v = nhdyn::rne(m.chain)(Eigen::VectorXd::Constant(1, 0.4), Eigen::VectorXd::Constant(1, -1.3),
                                                Eigen::VectorXd::Constant(1, 0.9));
  const auto p5 = nhdyn::io::load("paper5");  // a preset name, or a file: io::load("examples/models/paper5.json")
  // end snippet
  // A point mass m at the tip of a massless rod l: τ = m l² q̈ + m g l cos q.
  CHECK(v(0) == Approx(2 * 0.7 * 0.7 * 0.9 + 2 * 9.81 * 0.7 * std::cos(0.4)).epsilon(1e-14));
  CHECK(!m.constraint.has_value());
  REQUIRE(p5.constraint.has_value());
  const vec5 q(0.3, -0.2, 0.7, 0.8, -1.0), qd(0.1, 0.2, -0.6, 0.4, 0.3), qdd(0.5, -0.4, 0.2, 1.0, -2.0);
  const auto robot = nhdyn::presets::paper5();
  const Eigen::VectorXd v5 = nhdyn::rne(p5.chain)(Eigen::VectorXd(q), Eigen::VectorXd(qd), Eigen::VectorXd(qdd));
  CHECK(rel(v5, nhdyn::rne(robot.chain)(q, qd, qdd)) < 1e-15);
  CHECK((p5.constraint->A(q) - robot.constraint.A(q)).norm() < 1e-15);
  try {
    nhdyn::io::parse_model(R"({"name": "x", "gravity": [0, 0, -9.81], "links": [{"joint": "revolute",
      "alpha": 0, "a": 0.7, "theta": 0, "d": 0, "mass": 2, "com": [0, 0],
      "inertia": [[0, 0, 0], [0, 0, 0], [0, 0, 0]]}]})", "inline");
    FAIL("no model_error thrown");
  } catch (const nhdyn::model_error& e) {
    CHECK_THAT(e.what(), Catch::Contains("link 1, field 'com'"));
  }
}

TEST_CASE("docs/api.md §10: the linearizer, the state-space linearisation and torque bounds") {
  const vec5 q(0.3, -0.2, 0.7, 0.8, -1.0);
  const vec4 eta(0.5, 0.2, 1.0, -0.5), eta_dot(0.4, -0.1, 2.0, 1.0);
  const vec4 tau(3.0, -1.0, 2.0, 0.5);
  // snippet
  // #include <nhdyn/analysis/linearize.hpp>, <nhdyn/analysis/bounds.hpp>
  const auto robot = nhdyn::presets::paper5();
  // ∂τ/∂(q, η, η̇) by duals, the pipeline built once (like inverse_dynamics):
  const nhdyn::inverse_dynamics_linearizer lin(robot.chain, robot.constraint);
  const auto J = lin(q, eta, eta_dot);  // J.J: 4 × 13; J.dq(), J.deta(), J.deta_dot() (= M_η)
  // ẋ = f(x, u) with x = (q, η), u = τ: A = ∂f/∂x (9 × 9), B = ∂f/∂u (9 × 4).
  const auto ss = nhdyn::linearize_forward_dynamics(robot.chain, robot.constraint, q, eta, tau);
  // …or built once for many states (MPC, gain scheduling): the same A, B.
  const nhdyn::forward_dynamics_linearizer fdlin(robot.chain, robot.constraint);
  const auto ss2 = fdlin(q, eta, tau);
  // Every τ for every state in a box (±0.01 about the state), rounded outward; 2 bisections.
  nhdyn::box<5> Q;
  nhdyn::box<4> H, HD;
  for (int i = 0; i < 5; ++i) Q(i) = nhdyn::outward_about(q(i), 0.01);
  for (int i = 0; i < 4; ++i) H(i) = nhdyn::outward_about(eta(i), 0.01), HD(i) = nhdyn::outward_about(eta_dot(i), 0.01);
  const nhdyn::box<4> T = nhdyn::torque_bounds(robot.chain, robot.constraint, Q, H, HD, 2);
  // T(i).lower() ≤ τ_i ≤ T(i).upper() at every point of the box
  // end snippet
  const auto id = nhdyn::inverse_dynamics(robot.chain, robot.constraint);
  const auto fd = nhdyn::nh_forward_dynamics(robot.chain, robot.constraint);
  // ∂τ/∂η̇ = M_η (the composite-rigid-body path), ∂τ/∂q by central differences.
  CHECK(relm(J.deta_dot(), fd.reduced_inertia(q)) < 1e-13);
  for (int j = 0; j < 5; ++j) {
    const double h = 1e-6;
    vec5 qp = q, qm = q;
    qp(j) += h, qm(j) -= h;
    const vec4 d = (id(qp, eta, eta_dot) - id(qm, eta, eta_dot)) / (2 * h);
    CHECK(rel(J.dq().col(j), d) < 1e-7);
  }
  CHECK(ss2.A == ss.A);
  CHECK(ss2.B == ss.B);
  // B = [0; M_η⁻¹] (τ enters η̇ only, through M_η⁻¹ since E = S, SᵀS = I).
  CHECK(ss.B.topRows(5).cwiseAbs().maxCoeff() == 0.0);
  CHECK(relm(ss.B.bottomRows(4), Eigen::Matrix4d(fd.reduced_inertia(q).inverse())) < 1e-12);
  std::mt19937_64 g(5);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (int k = 0; k < 2000; ++k) {
    vec5 qs = q;
    vec4 es = eta, eds = eta_dot;
    for (int i = 0; i < 5; ++i) qs(i) += u(g);
    for (int i = 0; i < 4; ++i) es(i) += u(g), eds(i) += u(g);
    const vec4 t = id(qs, es, eds);
    for (int i = 0; i < 4; ++i) REQUIRE((T(i).lower() <= t(i) && t(i) <= T(i).upper()));
  }
}
