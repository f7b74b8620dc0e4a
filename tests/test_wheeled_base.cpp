/// Wheeled bases from robot files (issue 14): the constraint types differential_drive,
/// rolling_wheels (a robot file's "wheels") and bicycle on the shipped mobile manipulator and
/// on paper5 as URDF, each checked against references that share no code with the library:
///
/// - A S = 0, SᵀE = I, Ṡ against dual numbers and central differences of S;
/// - the projected Euler–Lagrange equations (tests/reference/lagrangian.hpp, long double):
///   τ = (SᵀE)⁻¹ Sᵀ (M q̈ + C q̇ + g), q̇ = S η, q̈ = S η̇ + Ṡ η, λ from v − Eτ = Aᵀλ;
/// - power: τᵀη = dE/dt (the reference's exact energy rate) and q̇ᵀ(v − Eτ) = 0;
/// - an unforced 10 s simulation (RK4, h = 5 ms): |A q̇| at rounding level, energy kept;
/// - rolling checked by kinematics: the wheel's contact point has zero velocity;
/// - paper5.json (URDF + robot file) = the paper5 preset to 1e-12;
/// - a user constraint coupling a wheel and an arm joint on the tree.
#include <catch2/catch.hpp>
#include <numbers>

#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/kinematics/tree.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>

#include "reference/lagrangian.hpp"
#include "support/visit_only.hpp"

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

/// A random configuration: base pose in a few metres, joints within ±1 rad (or m), the
/// steering joint (if any) within ±1 rad.
VectorXd random_q(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  VectorXd q(n);
  for (int j = 0; j < n; ++j) q(j) = (j < 2 ? 3.0 : 1.0) * u(rng);
  return q;
}
VectorXd random_vec(int n, std::mt19937& rng, double scale = 1) {
  std::uniform_real_distribution<double> u(-scale, scale);
  VectorXd v(n);
  for (int j = 0; j < n; ++j) v(j) = u(rng);
  return v;
}

/// Checks of one constraint's own pieces at random states (no dynamics).
template <class C>
void check_constraint_geometry(const C& c, std::mt19937& rng) {
  const int n = c.dof(), m = c.m(), k = c.k();
  REQUIRE(m + k == n);
  for (int trial = 0; trial < 20; ++trial) {
    const VectorXd q = random_q(n, rng), eta = random_vec(m, rng), v = random_vec(n, rng);
    const MatrixXd A = c.A(q), S = c.S(q), E = input_map(c, q);
    REQUIRE(A.rows() == k);
    REQUIRE(S.cols() == m);
    // A S = 0, and A has full row rank (its rows are independent constraints)
    CHECK((A * S).cwiseAbs().maxCoeff() <= 1e-14 * (1 + A.cwiseAbs().maxCoeff() * S.cwiseAbs().maxCoeff()));
    CHECK(Eigen::JacobiSVD<MatrixXd>(A).singularValues().minCoeff() > 1e-3);
    CHECK(Eigen::JacobiSVD<MatrixXd>(S).singularValues().minCoeff() > 1e-3);
    // SᵀE = I (the projection is Sᵀ v)
    if constexpr (has_identity_StE<C>) CHECK((S.transpose() * E - MatrixXd::Identity(m, m)).cwiseAbs().maxCoeff() <= 1e-15);
    // S_into over S at another q writes every entry nonzero at either q (S itself is S_into
    // over zeros, so only the other q can tell)
    if constexpr (has_S_into<C, VectorXd, MatrixXd>) {
      MatrixXd Si = c.S(VectorXd(random_q(n, rng)));
      c.S_into(q, Si);
      CHECK(Si == S);
    }
    // structured products = dense
    CHECK((apply_S(c, q, eta) - S * eta).cwiseAbs().maxCoeff() <= 1e-14);
    CHECK((apply_St(c, q, v) - S.transpose() * v).cwiseAbs().maxCoeff() <= 1e-14);
    // Ṡ: against S over dual numbers at q + ε q̇, and against central differences
    const VectorXd qd = S * eta;
    const MatrixXd Sd = c.Sdot(q, qd);
    using D = dual<double, 1>;
    vecN<D, dynamic> qq(n);
    for (int j = 0; j < n; ++j) qq(j) = D(q(j), {qd(j)});
    const auto SD = c.S(qq);
    MatrixXd Sd_dual(n, m);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < m; ++j) Sd_dual(i, j) = SD(i, j).derivative(0);
    CHECK((Sd - Sd_dual).cwiseAbs().maxCoeff() <= 1e-14 * (1 + Sd.cwiseAbs().maxCoeff()));
    const double h = 1e-6;
    const MatrixXd Sd_fd = (c.S(VectorXd(q + h * qd)) - c.S(VectorXd(q - h * qd))) / (2 * h);
    CHECK((Sd - Sd_fd).cwiseAbs().maxCoeff() <= 1e-7 * (1 + Sd.cwiseAbs().maxCoeff()));
    CHECK((apply_Sdot(c, q, qd, eta) - Sd * eta).cwiseAbs().maxCoeff() <= 1e-14 * (1 + (Sd * eta).norm()));
    // the lift stage (lift_into where the type has it) = S η, S η̇ + Ṡ η
    const VectorXd eta_dot = random_vec(m, rng);
    const auto xi = lift(c)(q, eta, eta_dot);
    CHECK((VectorXd(xi.qd) - qd).cwiseAbs().maxCoeff() <= 1e-14 * (1 + qd.norm()));
    CHECK((VectorXd(xi.qdd) - (S * eta_dot + Sd * eta)).cwiseAbs().maxCoeff() <= 1e-14 * (1 + (S * eta_dot + Sd * eta).norm()));
  }
}

/// The projected Euler–Lagrange reference in long double: (τ, λ) at (q, η, η̇).
template <class C>
std::pair<VectorXd, VectorXd> projected_euler_lagrange(const nhdyn_ref::model<LD>& ref, const C& c, const VectorXd& q,
                                                       const VectorXd& eta, const VectorXd& eta_dot) {
  const auto cl = [&] {  // the constraint in long double (a user constraint's functions take any scalar)
    if constexpr (requires { c.template cast<LD>(); })
      return c.template cast<LD>();
    else
      return c;
  }();
  const nhdyn_ref::vec<LD> ql = q.cast<LD>(), el = eta.cast<LD>(), edl = eta_dot.cast<LD>();
  const nhdyn_ref::mat<LD> S = cl.S(ql), E = input_map(cl, ql), A = cl.A(ql);
  const nhdyn_ref::vec<LD> qd = S * el;
  // Ṡη by dual numbers of S (not the constraint's Sdot)
  using D = dual<LD, 1>;
  vecN<D, dynamic> qq(ql.size());
  for (Eigen::Index j = 0; j < ql.size(); ++j) qq(j) = D(ql(j), {qd(j)});
  const auto SD = cl.S(qq);
  nhdyn_ref::mat<LD> Sd(S.rows(), S.cols());
  for (Eigen::Index i = 0; i < S.rows(); ++i)
    for (Eigen::Index j = 0; j < S.cols(); ++j) Sd(i, j) = SD(i, j).derivative(0);
  const nhdyn_ref::vec<LD> qdd = S * edl + Sd * el;
  const nhdyn_ref::vec<LD> v =
      nhdyn_ref::mass_matrix<LD>(ref, ql) * qdd + nhdyn_ref::coriolis<LD>(ref, ql, qd) + nhdyn_ref::gravity<LD>(ref, ql);
  const nhdyn_ref::vec<LD> tau = (S.transpose() * E).partialPivLu().solve(S.transpose() * v);
  const nhdyn_ref::vec<LD> lambda = (A * A.transpose()).ldlt().solve(A * (v - E * tau));
  return {tau.cast<double>(), lambda.cast<double>()};
}

double rel(const VectorXd& a, const VectorXd& b) { return (a - b).cwiseAbs().maxCoeff() / (1 + b.cwiseAbs().maxCoeff()); }

}  // namespace

TEST_CASE("wheels and bicycle: A S = 0, SᵀE = I, Ṡ = dual and central-difference derivative of S", "[wheeled]") {
  std::mt19937 rng(14);
  SECTION("on their own, with the base joints anywhere in q and asymmetric wheels") {
    // n = 8: x = 5, y = 1, heading = 6, wheels at 0 and 3, the axle 0.07 m ahead, spin signs ±
    check_constraint_geometry(rolling_wheels<double>(8, 0, 3, 0.09, 0.31, -0.22, 0.07, -1.0, 1.0, 5, 1, 6), rng);
    check_constraint_geometry(rolling_wheels<double>(5, 3, 4, 0.1, 0.25, -0.25), rng);
    check_constraint_geometry(bicycle<double>(7, 2, 1.3, -1.0, 4, 0, 6), rng);
    check_constraint_geometry(bicycle<double>(4, 3, 0.5), rng);
  }
  SECTION("as the shipped robot files read them from the URDF") {
    const auto w = load("mobile_manipulator_wheels.json");
    const auto& c = std::get<rolling_wheels<double>>(*w.constraint);
    CHECK(c.k() == 3);
    CHECK(c.radius == 0.1);
    CHECK(c.left_y == Approx(0.26).margin(1e-15));
    CHECK(c.right_y == Approx(-0.26).margin(1e-15));
    CHECK(c.axle_x == 0.0);
    CHECK(c.left_sign == 1.0);  // rpy (−π/2, 0, 0) with axis z: +y in the root frame
    CHECK(c.right_sign == 1.0);
    check_constraint_geometry(c, rng);
    const auto b = load("mobile_manipulator_bicycle.json");
    const auto& cb = std::get<bicycle<double>>(*b.constraint);
    CHECK(cb.k() == 2);
    CHECK(cb.wheelbase == 0.24);
    CHECK(cb.steer_sign == 1.0);
    check_constraint_geometry(cb, rng);
    const auto d = load("mobile_manipulator.json");
    check_constraint_geometry(std::get<differential_drive<double>>(*d.constraint), rng);
  }
}

TEST_CASE("wheeled robot files: eta names and sizes", "[wheeled]") {
  const auto w = load("mobile_manipulator_wheels.json");
  const auto names = w.eta_names();
  REQUIRE(names.size() == 16);
  CHECK(names[0] == "wheel_left_joint");
  CHECK(names[1] == "wheel_right_joint");
  CHECK(names[2] == "caster_front_swivel_joint");
  CHECK(w.k() == 3);
  const auto b = load("mobile_manipulator_bicycle.json");
  CHECK(b.eta_names()[0] == "v");
  CHECK(b.eta_names()[1] == "caster_front_swivel_joint");
  CHECK(b.eta_names().size() == 17);
  CHECK(load("mobile_manipulator.json").eta_names()[1] == "omega");
}

TEST_CASE("wheeled robots: the paper's method = the projected Euler-Lagrange equations (long double), for each constraint",
          "[wheeled]") {
  std::mt19937 rng(1914);
  for (const std::string file : {"mobile_manipulator.json", "mobile_manipulator_wheels.json", "mobile_manipulator_bicycle.json"}) {
    const auto r = load(file);
    const auto ref = nhdyn_ref::from_tree<LD>(r.model);
    REQUIRE(r.constraint);
    nhdyn_test::visit_only<differential_drive<double>, rolling_wheels<double>, bicycle<double>>(
        *r.constraint, [&](const auto& c) {
          INFO(file);
          const auto id = inverse_dynamics_with_forces(r.model, c);
          const auto fd = nh_forward_dynamics(r.model, c);
          for (int trial = 0; trial < 3; ++trial) {
            const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng), eta_dot = random_vec(c.m(), rng, 2);
            const auto f = id(q, eta, eta_dot);
            const auto [tau, lambda] = projected_euler_lagrange(ref, c, q, eta, eta_dot);
            CHECK(rel(f.tau, tau) <= 1e-12);
            CHECK(rel(f.lambda, lambda) <= 1e-12);
            // the forward dynamics inverts it
            CHECK(rel(fd(q, eta, VectorXd(f.tau)), eta_dot) <= 1e-10);
            // power: the actuators' τᵀη is the rate of the total energy; λ does no work
            const VectorXd qd = apply_S(c, q, eta);
            const VectorXd qdd = VectorXd(apply_S(c, q, eta_dot)) + VectorXd(apply_Sdot(c, q, qd, eta));
            const LD dE = nhdyn_ref::energy_rate<LD>(ref, q.cast<LD>(), qd.cast<LD>(), qdd.cast<LD>());
            CHECK(std::abs(double(dE) - f.tau.dot(eta)) <= 1e-12 * (1 + std::abs(double(dE)) + f.tau.norm() * eta.norm()));
            const VectorXd v = rne(r.model)(q, qd, qdd);
            const VectorXd work_lambda = qd.transpose() * (v - MatrixXd(input_map(c, q)) * f.tau);
            CHECK(std::abs(work_lambda(0)) <= 1e-12 * (1 + v.norm() * qd.norm()));
          }
        });
  }
}

TEST_CASE("wheeled robots: rolling checked by kinematics (contact points do not move)", "[wheeled]") {
  std::mt19937 rng(7);
  SECTION("wheels: each drive wheel's contact point has zero velocity; centre speed r·phi_dot") {
    const auto r = load("mobile_manipulator_wheels.json");
    const auto& c = std::get<rolling_wheels<double>>(*r.constraint);
    const tree_kinematics<double> kin(r.model);
    for (int trial = 0; trial < 10; ++trial) {
      const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng);
      const VectorXd qd = c.S_times(q, eta);
      for (int w : {c.left, c.right}) {
        const MatrixXd J = kin.jacobian(q, w + 1);  // the wheel body's origin: its centre
        const VectorXd tw = J * qd;                 // (v, ω) in the world frame
        const Eigen::Vector3d vc = tw.head(3), om = tw.tail(3);
        const Eigen::Vector3d contact = vc + om.cross(Eigen::Vector3d(0, 0, -c.radius));
        CHECK(contact.norm() <= 1e-13 * (1 + qd.norm()));
        const Eigen::Vector2d fwd(std::cos(q(2)), std::sin(q(2)));
        CHECK(std::abs(fwd.dot(vc.head(2)) - c.radius * qd(w)) <= 1e-13 * (1 + qd.norm()));
      }
    }
  }
  SECTION("bicycle: neither axle slips sideways") {
    const auto r = load("mobile_manipulator_bicycle.json");
    const auto& c = std::get<bicycle<double>>(*r.constraint);
    const tree_kinematics<double> kin(r.model);
    for (int trial = 0; trial < 10; ++trial) {
      const VectorXd q = random_q(c.dof(), rng), eta = random_vec(c.m(), rng);
      const VectorXd qd = c.S_times(q, eta);
      const VectorXd rear = kin.jacobian(q, 3) * qd;  // the root link's origin (the rear axle)
      const VectorXd front = kin.jacobian(q, c.steer + 1) * qd;  // the steering joint's point
      const double psi = q(2), delta = q(c.steer);
      CHECK(std::abs(-std::sin(psi) * rear(0) + std::cos(psi) * rear(1)) <= 1e-13 * (1 + qd.norm()));
      CHECK(std::abs(-std::sin(psi + delta) * front(0) + std::cos(psi + delta) * front(1)) <= 1e-13 * (1 + qd.norm()));
      CHECK(std::abs(std::cos(psi) * rear(0) + std::sin(psi) * rear(1) - eta(0)) <= 1e-13 * (1 + qd.norm()));
    }
  }
}

TEST_CASE("wheeled robots: an unforced 10 s motion keeps A q_dot = 0 and the energy", "[wheeled][long]") {
  // τ = 0: the arm falls under gravity and the base moves in reaction, on its wheels.
  for (const std::string file : {"mobile_manipulator_wheels.json", "mobile_manipulator_bicycle.json"}) {
    const auto r = load(file);
    const auto ref = nhdyn_ref::from_tree<double>(r.model);
    REQUIRE(r.constraint);
    nhdyn_test::visit_only<rolling_wheels<double>, bicycle<double>>(
        *r.constraint, [&](const auto& c) {
          INFO(file);
          const auto fd = nh_forward_dynamics(r.model, c);
          const int n = c.dof(), m = c.m();
          VectorXd q = VectorXd::Zero(n), eta = VectorXd::Zero(m);
          q(0) = 0.5;
          q(2) = 0.3;
          for (int j = 0; j < n; ++j)
            if (r.model[j].joint_name.rfind("arm_", 0) == 0) q(j) = 0.4;  // the arm out of its rest pose
          if constexpr (std::is_same_v<std::decay_t<decltype(c)>, rolling_wheels<double>>) {
            eta(0) = 10.0;  // wheel rates [rad/s]: about 1 m/s, turning
            eta(1) = 8.0;
          } else {
            // 1 m/s, the steering free and turned half a turn (δ = π + 0.05), where it is
            // stable: it swings back to δ = π. δ = 0 is an unstable equilibrium: a steering
            // offset of 1e-15 rad grows until the steering spins and the motion breaks down,
            // and the run stays on it only while M's rounding keeps the steering's
            // acceleration at exactly zero.
            eta(0) = 1.0;
            q(c.steer) = std::numbers::pi + 0.05;
          }
          const VectorXd tau = VectorXd::Zero(m);
          const auto f = [&](const VectorXd& x) {
            VectorXd dx(n + m);
            dx << apply_S(c, x.head(n), x.tail(m)), fd(x.head(n), x.tail(m), tau);
            return dx;
          };
          VectorXd x(n + m);
          x << q, eta;
          const double E0 = nhdyn_ref::energy<double>(ref, VectorXd(x.head(n)), VectorXd(apply_S(c, x.head(n), x.tail(m))));
          const double h = 5e-3;
          double worst = 0, speed = 0;
          for (int step = 0; step < 2000; ++step) {  // 10 s, RK4
            const VectorXd k1 = f(x), k2 = f(x + h / 2 * k1), k3 = f(x + h / 2 * k2), k4 = f(x + h * k3);
            x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
            const VectorXd qd = apply_S(c, x.head(n), x.tail(m));
            worst = std::max(worst, (c.A(x.head(n)) * qd).cwiseAbs().maxCoeff());
            speed = std::max(speed, qd.cwiseAbs().maxCoeff());
          }
          const VectorXd qd = apply_S(c, x.head(n), x.tail(m));
          const double E1 = nhdyn_ref::energy<double>(ref, VectorXd(x.head(n)), qd);
          CHECK(x.allFinite());
          CHECK(worst <= 1e-14 * (1 + speed));
          INFO("energy " << E0 << " J -> " << E1 << " J");
          CHECK(std::abs(E1 - E0) <= 1e-6 * (1 + std::abs(E0)));
          CHECK((x.head(2) - q.head(2)).norm() > 0.5);  // it did travel
        });
  }
}

TEST_CASE("paper5 as URDF + robot file = the paper5 preset to 1e-12", "[wheeled]") {
  const auto r = load("paper5.json");
  const auto& c = std::get<differential_drive<double>>(*r.constraint);
  const auto p = presets::paper5();
  CHECK(r.eta_names() == std::vector<std::string>{"v", "joint3", "joint4", "joint5"});
  const auto id = inverse_dynamics_with_forces(r.model, c);
  const auto id5 = inverse_dynamics_with_forces(p.chain, p.constraint);
  const auto fd = nh_forward_dynamics(r.model, c);
  const auto fd5 = nh_forward_dynamics(p.chain, p.constraint);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    const VectorXd q = random_q(5, rng), eta = random_vec(4, rng), eta_dot = random_vec(4, rng, 3), tau = random_vec(4, rng, 5);
    const auto a = id(q, eta, eta_dot);
    const auto b = id5(nhdyn::vecN<double, 5>(q), nhdyn::vecN<double, 4>(eta), nhdyn::vecN<double, 4>(eta_dot));
    CHECK(rel(a.tau, VectorXd(b.tau)) <= 1e-12);
    CHECK(rel(a.lambda, VectorXd(b.lambda)) <= 1e-12);
    CHECK(rel(fd(q, eta, tau), VectorXd(fd5(nhdyn::vecN<double, 5>(q), nhdyn::vecN<double, 4>(eta), nhdyn::vecN<double, 4>(tau)))) <= 1e-12);
  }
}

TEST_CASE("a user constraint on the tree coupling a wheel and an arm joint", "[wheeled]") {
  // The differential drive's no-slip row, and arm_1 geared to the left wheel by a ratio that
  // depends on arm_2's angle: q̇_arm1 = ρ(q) q̇_wheel_left, ρ = 0.5 cos q_arm2 (k = 2).
  const auto r = load("mobile_manipulator.json");
  const auto& t = r.model;
  const int n = t.dof();
  const auto names = t.joint_names();
  const auto at = [&](const std::string& s) { return int(std::find(names.begin(), names.end(), s) - names.begin()); };
  const int wl = at("wheel_left_joint"), a1 = at("arm_1_joint"), a2 = at("arm_2_joint");
  REQUIRE(a2 < n);
  const auto fA = [=](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    using std::cos;
    using std::sin;
    matrix<T, dynamic, dynamic> A = matrix<T, dynamic, dynamic>::Zero(2, n);
    A(0, 0) = -sin(q(2));
    A(0, 1) = cos(q(2));
    A(1, a1) = T(1);
    A(1, wl) = -T(0.5) * cos(q(a2));
    return A;
  };
  const auto fS = [=](const auto& q) {  // η = (v, ω, the URDF's joints but arm_1)
    using T = typename std::decay_t<decltype(q)>::Scalar;
    using std::cos;
    using std::sin;
    matrix<T, dynamic, dynamic> S = matrix<T, dynamic, dynamic>::Zero(n, n - 2);
    S(0, 0) = cos(q(2));
    S(1, 0) = sin(q(2));
    for (int j = 2, col = 1; j < n; ++j) {
      if (j == a1) continue;
      S(j, col) = T(1);
      if (j == wl) S(a1, col) = T(0.5) * cos(q(a2));
      ++col;
    }
    return S;
  };
  const auto c = make_constraint(n, 2, fA, fS);
  std::mt19937 rng(99);
  check_constraint_geometry(c, rng);
  const auto ref = nhdyn_ref::from_tree<LD>(t);
  const auto id = inverse_dynamics_with_forces(t, c);
  for (int trial = 0; trial < 3; ++trial) {
    const VectorXd q = random_q(n, rng), eta = random_vec(n - 2, rng), eta_dot = random_vec(n - 2, rng);
    const auto f = id(q, eta, eta_dot);
    const auto [tau, lambda] = projected_euler_lagrange(ref, c, q, eta, eta_dot);
    CHECK(rel(f.tau, tau) <= 1e-12);
    CHECK(rel(f.lambda, lambda) <= 1e-12);
  }
}

TEST_CASE("wheeled robot files: errors name the file, the field and the joint", "[wheeled]") {
  const std::string dir = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/x.json";
  const auto err = [&](const std::string& constraint, bool planar = true) {
    const std::string text = std::string("{\"urdf\": \"../urdf/mobile_manipulator.urdf\", ") +
                             (planar ? "\"base\": {\"type\": \"planar\"}, " : "") + "\"constraint\": " + constraint + "}";
    try {
      io::parse_robot_file(text, dir);
    } catch (const model_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  using Catch::Matchers::Contains;
  CHECK_THAT(err(R"({"type": "wheels", "left": "wheel_lft", "right": "wheel_right_joint", "radius": 0.1})"),
             Contains("x.json") && Contains("field 'left'") && Contains("no movable joint named 'wheel_lft'") &&
                 Contains("wheel_left_joint"));
  CHECK_THAT(err(R"({"type": "wheels", "left": "wheel_left_joint", "right": "wheel_right_joint", "radius": 0})"),
             Contains("field 'radius'") && Contains("positive"));
  CHECK_THAT(err(R"({"type": "wheels", "left": "wheel_left_joint", "right": "wheel_right_joint", "radius": -0.1})"),
             Contains("positive"));
  CHECK_THAT(err(R"({"type": "wheels", "left": "caster_front_swivel_joint", "right": "wheel_right_joint", "radius": 0.1})"),
             Contains("field 'left'") && Contains("joint 'caster_front_swivel_joint': its axis") &&
                 Contains("not horizontal and lateral"));
  CHECK_THAT(err(R"({"type": "wheels", "left": "arm_1_joint", "right": "wheel_right_joint", "radius": 0.1})"),
             Contains("not on the root link"));
  CHECK_THAT(err(R"({"type": "wheels", "left": "torso_lift_joint", "right": "wheel_right_joint", "radius": 0.1})"),
             Contains("prismatic"));
  CHECK_THAT(err(R"({"type": "wheels", "left": "wheel_left_joint", "right": "wheel_left_joint", "radius": 0.1})"),
             Contains("the same joint"));
  CHECK_THAT(err(R"({"type": "wheels", "left": "wheel_left_joint", "right": "caster_front_wheel_joint", "radius": 0.1})"),
             Contains("not on the root link"));
  CHECK_THAT(err(R"({"type": "wheels", "left": "wheel_left_joint", "radius": 0.1})"), Contains("field 'right'") && Contains("missing"));
  CHECK_THAT(err(R"({"type": "wheels", "left": "wheel_left_joint", "right": "wheel_right_joint", "radius": 0.1})", false),
             Contains("needs a planar base"));
  CHECK_THAT(err(R"({"type": "bicycle", "steer": "wheel_left_joint", "wheelbase": 0.24})"), Contains("field 'steer'") && Contains("vertical"));
  CHECK_THAT(err(R"({"type": "bicycle", "steer": "caster_front_swivel_joint", "wheelbase": -1})"), Contains("field 'wheelbase'"));
  CHECK_THAT(err(R"({"type": "skid_steer"})"), Contains("unknown constraint type 'skid_steer'") && Contains("wheels, bicycle"));
  CHECK_THAT(err(R"({"type": "differential_drive", "x": "base_x", "y": "base_y", "heading": "base_yaw"})"),
             Contains("leave them out"));
  // the constraint types' own checks
  CHECK_THROWS_WITH(rolling_wheels<double>(5, 3, 4, 0.1, 0.2, 0.2), Contains("track is zero"));
  CHECK_THROWS_WITH(rolling_wheels<double>(5, 3, 3, 0.1, 0.2, -0.2), Contains("must differ"));
  CHECK_THROWS_WITH(bicycle<double>(4, 3, 0.0), Contains("wheelbase must be positive"));
  const bicycle<double> b(4, 3, 0.5);
  CHECK_THROWS_WITH(b.S(Eigen::Vector4d(0, 0, 0, std::acos(0.0))), Contains("at ±90°"));
}

TEST_CASE("bicycle: a misplaced steering joint warns and goes on", "[wheeled]") {
  std::vector<std::string> warnings;
  io::urdf_options o;
  o.warn = [&](const std::string& w) { warnings.push_back(w); };
  const std::string text = R"({"urdf": "../urdf/mobile_manipulator.urdf", "base": {"type": "planar"},
    "constraint": {"type": "bicycle", "steer": "caster_front_swivel_joint", "wheelbase": 0.3}})";
  const auto r = io::parse_robot_file(text, robot_path("x.json"), o);
  CHECK(std::get<bicycle<double>>(*r.constraint).wheelbase == 0.3);
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Matchers::Contains("not on the front axle"));
}

TEST_CASE("robot files: drives by joint name (motor side, joint side) reach the dynamics", "[wheeled]") {
  const auto text = [](const std::string& drives) {
    return R"({"urdf": "../urdf/mobile_manipulator.urdf", "base": {"type": "planar"}, "drives": )" + drives +
           R"(, "constraint": {"type": "wheels", "left": "wheel_left_joint", "right": "wheel_right_joint", "radius": 0.1}})";
  };
  const auto parse = [&](const std::string& drives) {
    return io::parse_robot_file(text(drives), robot_path("drives.json"));
  };
  const auto plain = load("mobile_manipulator_wheels.json");
  const auto driven = parse(R"({"wheel_left_joint": {"motor": {"gear": 20, "inertia": 1e-4, "viscous": 1e-3, "coulomb": 0.01}},
                                "arm_1_joint": {"armature": 0.3, "friction": {"viscous": 2, "coulomb": [1, -0.5]}}})");
  const auto joint = [&](const std::string& name) {
    for (int i = 0; i < driven.model.dof(); ++i)
      if (driven.model[i].joint_name == name) return i;
    return -1;
  };
  const int w = joint("wheel_left_joint");
  REQUIRE(w >= 0);
  CHECK(driven.model[w].armature == Approx(400 * 1e-4).epsilon(1e-15));
  CHECK(driven.model[w].friction_law() == joint_friction{0.4, 0.2, -0.2});
  const int a = joint("arm_1_joint");
  REQUIRE(a >= 0);
  CHECK(driven.model[a].friction_law() == joint_friction{2, 1, -0.5});
  // the left wheel's angle is a coordinate and η's first entry (q̇ = η there, Ṡ's row zero):
  // its rotor adds exactly I_a η̇ to τ_left; the arm joint's adds I_a q̈ to the arm's entry
  const auto& c0 = std::get<rolling_wheels<double>>(*plain.constraint);
  const auto& c1 = std::get<rolling_wheels<double>>(*driven.constraint);
  std::mt19937 rng(19);
  for (int trial = 0; trial < 5; ++trial) {
    const VectorXd q = random_q(c0.dof(), rng), eta = random_vec(c0.m(), rng), eta_dot = random_vec(c0.m(), rng);
    const VectorXd t0 = inverse_dynamics(plain.model, c0)(q, eta, eta_dot);
    const VectorXd t1 = inverse_dynamics(driven.model, c1)(q, eta, eta_dot);
    VectorXd d = t1 - t0;
    CHECK(d(0) == Approx(0.04 * eta_dot(0)).margin(1e-12));
    const VectorXd qdd = VectorXd(apply_S(c1, q, eta_dot)) + VectorXd(apply_Sdot(c1, q, VectorXd(apply_S(c1, q, eta)), eta));
    const auto names = driven.eta_names();
    const int ea = int(std::find(names.begin(), names.end(), "arm_1_joint") - names.begin());
    REQUIRE(ea < c1.m());
    CHECK(d(ea) == Approx(0.3 * qdd(a)).margin(1e-12));
    d(0) = d(ea) = 0;
    CHECK(d.cwiseAbs().maxCoeff() <= 1e-12);
  }
  CHECK_THROWS_WITH(parse(R"({"no_such_joint": {"armature": 1}})"),
                    Catch::Contains("drives, joint 'no_such_joint'") && Catch::Contains("wheel_left_joint"));
  CHECK_THROWS_WITH(parse(R"({"wheel_left_joint": {"armature": -1}})"), Catch::Contains("armature"));
  CHECK_THROWS_WITH(parse(R"({"wheel_left_joint": {"gear": 2}})"), Catch::Contains("gear"));
  CHECK_THROWS_WITH(parse("[1]"), Catch::Contains("drives"));
}
