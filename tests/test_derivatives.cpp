/// Analytic derivatives of the nonholonomic inverse dynamics and of the forward dynamics
/// (analysis/derivatives.hpp) against the dual-number linearizers (analysis/linearize.hpp: the
/// same matrices by forward-mode duals through the whole pipeline) and 50-digit central
/// differences, on paper5 as a tree, the shipped mobile manipulator with each constraint type
/// of its robot files (differential drive, rolling wheels, bicycle), wheeled bases (mecanum:
/// more actuators than η; castors), a user constraint with its own input map, a holonomic arm
/// and random trees, with external wrenches.
#include <catch2/catch.hpp>

#include <nhdyn/analysis/derivatives.hpp>
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/scalar/multiprecision.hpp>
#include <random>

#include "reference/random_tree.hpp"
#include "support/visit_only.hpp"

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
std::string source(const std::string& rel) { return std::string(NHDYN_SOURCE_DIR) + "/" + rel; }
VectorXd random_vec(std::mt19937_64& rng, int n, double r) {
  return VectorXd::NullaryExpr(n, [&] { return nhdyn_ref::uniform(rng, -r, r); });
}
double rel(const MatrixXd& a, const MatrixXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / std::max(1.0, b.lpNorm<Eigen::Infinity>());
}

/// Checks the analytic ∂τ/∂ζ against the dual linearizer and τ against inverse_dynamics, and
/// the analytic A, B against the dual forward_dynamics_linearizer, at a random state.
template <class C>
void check_nh(const tree<double>& t, const C& c, std::mt19937_64& rng, const std::string& what) {
  const int n = c.dof(), m = c.m();
  const VectorXd q = random_vec(rng, n, 1.5), eta = random_vec(rng, m, 1), eta_dot = random_vec(rng, m, 1);
  const auto d = inverse_dynamics_derivatives(t, c)(q, eta, eta_dot);
  const auto ref = inverse_dynamics_linearizer(t, c)(q, eta, eta_dot);
  INFO(what);
  CHECK(rel(d.J(), ref.J) < 1e-12);
  CHECK(rel(d.tau, inverse_dynamics(t, c)(q, eta, eta_dot)) < 1e-13);
  const VectorXd tau = random_vec(rng, actuator_count(c), 5);
  const auto a = forward_dynamics_derivatives(t, c)(q, eta, tau);
  const auto b = forward_dynamics_linearizer(t, c)(q, eta, tau);
  CHECK(rel(a.ss.A, b.A) < 1e-10);
  CHECK(rel(a.ss.B, b.B) < 1e-10);
  CHECK(rel(a.eta_dot, nh_forward_dynamics(t, c)(q, eta, tau)) < 1e-13);
  // evaluate into a result that held another size (every matrix and the scratch), then
  // another state: the same numbers as the call
  nh_derivatives_result<double, C::m_at_compile_time> e;
  nh_fd_derivatives_result<double, C::m_at_compile_time> ef;
  if constexpr (C::m_at_compile_time == Eigen::Dynamic) {
    for (auto* r : {&e, &ef.id}) {
      r->tau.setOnes(m + 2), r->dq.setOnes(m + 2, n + 3), r->deta.setOnes(1, 1), r->deta_dot.setOnes(m + 1, m + 1);
      r->dqd_dq.setOnes(2, 5), r->id.M.setOnes(n + 4, n + 4), r->id.dq.setOnes(1, 1);
      r->work.w.setOnes(3, 3), r->work.z.setOnes(n + 9, 2), r->work.stx.setOnes(m + 3, 1), r->work.jd.setOnes(7, 7);
      r->work.se.setOnes(n + 1, m), r->work.st.nz.resize(3), r->work.st.singles.resize(2);
    }
    ef.ss.A.setOnes(3, 3), ef.ss.B.setOnes(4, 2), ef.eta_dot.setOnes(m + 5);
    auto& x = ef.redundant;  // the p > m scratch, at other sizes too
    x.Bq.setOnes(3, 3), x.Me.setOnes(2, 5), x.rhs_q.setOnes(1, 1), x.rhs_eta.setOnes(4, 4), x.dBy.setOnes(1, 7);
    x.y.setOnes(9), x.unit.setOnes(2), x.Ecol.setOnes(1), x.qd.resize(2), x.yd.resize(5), x.e.resize(1), x.col.resize(6);
  }
  inverse_dynamics_derivatives(t, c).evaluate(VectorXd(2 * q), eta_dot, eta, e);
  forward_dynamics_derivatives(t, c).evaluate(VectorXd(2 * q), eta_dot, tau, ef);
  inverse_dynamics_derivatives(t, c).evaluate(q, eta, eta_dot, e);
  forward_dynamics_derivatives(t, c).evaluate(q, eta, tau, ef);
  CHECK(e.J() == d.J());
  CHECK(e.tau == d.tau);
  CHECK(e.dqd_dq == d.dqd_dq);
  CHECK(ef.ss.A == a.ss.A);
  CHECK(ef.ss.B == a.ss.B);
  CHECK(ef.eta_dot == a.eta_dot);
}
}  // namespace

TEST_CASE("nh derivatives: equal the dual linearizers on paper5, the mobile manipulator's constraints and a user constraint") {
  std::mt19937_64 rng(18);
  const auto p5 = as_tree(presets::paper5<double>().chain);
  const differential_drive<double, dynamic> dd(5, 0, 1, 2, 0.0, -1.0);  // paper5's, sized at run time
  for (int k = 0; k < 3; ++k) check_nh(p5, dd, rng, "paper5");
  for (const char* file : {"mobile_manipulator.json", "mobile_manipulator_wheels.json", "mobile_manipulator_bicycle.json",
                           "mecanum_arm.json", "castor_drive_arm.json", "powered_castors_arm.json"}) {
    const auto r = io::load_robot_file(source("examples/robots/") + file);
    REQUIRE(r.constraint);
    std::visit([&](const auto& c) {
      for (int k = 0; k < 2; ++k) check_nh(r.model, c, rng, file);
    }, *r.constraint);
  }
  // a user constraint (paper5's, given as functions) with an input map E = S·diag(2, 1): SᵀE ≠ I
  const auto user = make_constraint(
      5, 1, [dd](const auto& q) { return dd.A(q); }, [dd](const auto& q) { return dd.S(q); }, nullptr,
      [dd](const auto& q) {
        using T = typename std::decay_t<decltype(q)>::Scalar;
        auto E = dd.S(q).eval();
        E.col(0) *= T(2);
        return Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>(E);
      });
  check_nh(p5, user, rng, "user constraint with E");
  // holonomic: the derivatives of rne itself
  const auto puma = as_tree(presets::puma560<double>());
  check_nh(puma, holonomic<dynamic>{6}, rng, "puma560, holonomic");
}

TEST_CASE("nh derivatives: evaluate follows S's nonzeros as they vanish and reappear, and a result passed between constraints") {
  std::mt19937_64 rng(21);
  const auto p5 = as_tree(presets::paper5<double>().chain);
  const differential_drive<double, dynamic> dd(5, 0, 1, 2, 0.0, -1.0);
  const auto d = inverse_dynamics_derivatives(p5, dd);
  const inverse_dynamics_linearizer lin(p5, dd);
  VectorXd q = random_vec(rng, 5, 1.5);
  const VectorXd eta = random_vec(rng, 4, 1), eta_dot = random_vec(rng, 4, 1);
  nh_derivatives_result<double, Eigen::Dynamic> e;
  // heading 0: sin ψ = 0, so S's (y, v) entry and Ṡ's (x, v) entry vanish; evaluate keeps the
  // nonzero positions of its last call while they cover every nonzero, and reads S again when
  // a nonzero appears outside them (0 → 0.7)
  for (const double h : {0.0, 0.7, 0.0, -1.1, 0.0}) {
    q(2) = h;
    d.evaluate(q, eta, eta_dot, e);
    INFO("heading " << h);
    CHECK(e.J() == d(q, eta, eta_dot).J());
    CHECK(rel(e.J(), lin(q, eta, eta_dot).J) < 1e-12);
  }
  // the same on the mobile manipulator (the arm's unit columns form runs), one function object
  // and one result over several headings for each constraint type
  for (const char* file : {"mobile_manipulator.json", "mobile_manipulator_wheels.json", "mobile_manipulator_bicycle.json",
                           "mecanum_arm.json"}) {
    const auto rf = io::load_robot_file(source("examples/robots/") + file);
    std::visit([&](const auto& c) {
      const int n = c.dof(), m = c.m();
      const auto dm = inverse_dynamics_derivatives(rf.model, c);
      const inverse_dynamics_linearizer lm(rf.model, c);
      VectorXd qm = random_vec(rng, n, 1.5);
      const VectorXd em = random_vec(rng, m, 1), edm = random_vec(rng, m, 1);
      nh_derivatives_result<double, Eigen::Dynamic> r;
      for (const double h : {0.0, 0.7, 0.0, -1.1}) {
        qm(2) = h;  // the planar base's yaw
        dm.evaluate(qm, em, edm, r);
        INFO(file << ", heading " << h);
        CHECK(r.J() == dm(qm, em, edm).J());
        CHECK(rel(r.J(), lm(qm, em, edm).J) < 1e-12);
      }
    }, *rf.constraint);
  }
  // a result passed to another constraint of the same sizes (another layout of the base): its
  // S is not read through the first one's
  const differential_drive<double, dynamic> other(5, 1, 3, 2, 0.0, 1.0);
  const auto d2 = inverse_dynamics_derivatives(p5, other);
  q = random_vec(rng, 5, 1.5);
  for (int k = 0; k < 2; ++k) {
    d2.evaluate(q, eta, eta_dot, e);
    CHECK(e.J() == d2(q, eta, eta_dot).J());
    CHECK(rel(e.J(), inverse_dynamics_linearizer(p5, other)(q, eta, eta_dot).J) < 1e-12);
    d.evaluate(q, eta, eta_dot, e);
    CHECK(e.J() == d(q, eta, eta_dot).J());
  }
}

TEST_CASE("nh derivatives: in 50 digits, equal 50-digit central differences of inverse_dynamics") {
  using M = boost::multiprecision::cpp_bin_float_50;
  using VM = Eigen::Matrix<M, Eigen::Dynamic, 1>;
  std::mt19937_64 rng(50);
  const auto r = io::load_robot_file(source("examples/robots/mobile_manipulator_wheels.json"));
  REQUIRE(r.constraint);
  nhdyn_test::visit_only<rolling_wheels<double>>(*r.constraint, [&](const auto& c) {
    const int n = c.dof(), m = c.m();
    const VM q = random_vec(rng, n, 1.5).cast<M>(), eta = random_vec(rng, m, 1).cast<M>(),
             eta_dot = random_vec(rng, m, 1).cast<M>();
    const auto d = inverse_dynamics_derivatives(r.model, c)(q, eta, eta_dot);
    const auto id = inverse_dynamics(r.model, c);
    const M h("1e-17");
    double worst = 0, scale = 1;
    const auto J = d.J();
    for (int j = 0; j < n + 2 * m; ++j) {
      VM z(n + 2 * m);
      z << q, eta, eta_dot;
      VM zp = z, zm = z;
      zp(j) += h, zm(j) -= h;
      const auto f = [&](const VM& x) { return VM(id(VM(x.head(n)), VM(x.segment(n, m)), VM(x.tail(m)))); };
      const VM col = (f(zp) - f(zm)) / (2 * h);
      for (int i = 0; i < m; ++i) {
        using std::abs;
        worst = std::max(worst, double(abs(J(i, j) - col(i))));
        scale = std::max(scale, double(abs(col(i))));
      }
    }
    INFO("largest difference " << worst << ", scale " << scale);
    CHECK(worst / scale < 1e-28);
  });
}

TEST_CASE("forward dynamics derivatives (holonomic): equal the duals, with armature and external wrenches") {
  std::mt19937_64 rng(7);
  fd_derivatives_result<double> reused;
  for (int n : {30, 1, 3, 7, 16}) {
    std::vector<body<double>> B;
    for (const auto& b : nhdyn_ref::random_tree(rng, n, 0.4, n % 2 == 1)) B.push_back(b);
    for (auto& b : B) b.armature = nhdyn_ref::uniform(rng, 0.0, 0.3);
    const tree<double> t(std::move(B), vec3<double>(0, 0, -9.81), "random tree");
    const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), tau = random_vec(rng, n, 10);
    const auto a = forward_dynamics_derivatives(t)(q, qd, tau);
    const auto b = linearize_forward_dynamics(t, q, qd, tau);
    const auto s = a.state_space_model();
    INFO("n = " << n);
    CHECK(rel(s.A, b.A) < 1e-10);
    CHECK(rel(s.B, b.B) < 1e-10);
    CHECK(rel(a.qdd, forward_dynamics(t)(q, qd, tau)) < 1e-12);
    // evaluate into one result reused across the sizes: the same numbers as the call
    forward_dynamics_derivatives(t).evaluate(q, qd, tau, reused);
    CHECK(reused.dq == a.dq);
    CHECK(reused.dqd == a.dqd);
    CHECK(reused.Minv == a.Minv);
    CHECK(reused.qdd == a.qdd);
    CHECK(reused.id.M == a.id.M);
    // with wrenches: the duals of forward_dynamics(q, qd, tau, w)
    wrench<double> w1, w2;
    w1.body = n, w1.force = random_vec(rng, 3, 20), w1.point = random_vec(rng, 3, 0.3);
    w2.body = 1, w2.moment = random_vec(rng, 3, 5), w2.frame = wrench_frame::body;
    const auto w = external_wrenches(t, {w1, w2});
    const auto aw = forward_dynamics_derivatives(t)(q, qd, tau, w);
    const auto fd = forward_dynamics(t);
    VectorXd x(3 * n);
    x << q, qd, tau;
    const MatrixXd Jw = jacobian(
        [&](const auto& z) {
          using D = typename std::decay_t<decltype(z)>::Scalar;
          return Eigen::Matrix<D, Eigen::Dynamic, 1>(fd(z.head(n), z.segment(n, n), z.tail(n), w));
        },
        x);
    CHECK(rel(aw.dq, Jw.leftCols(n)) < 1e-10);
    CHECK(rel(aw.dqd, Jw.middleCols(n, n)) < 1e-10);
    CHECK(rel(aw.Minv, Jw.rightCols(n)) < 1e-10);
    // evaluate with the wrenches, into the result reused above: the call's numbers
    forward_dynamics_derivatives(t).evaluate(q, qd, tau, w, reused);
    CHECK(reused.dq == aw.dq);
    CHECK(reused.dqd == aw.dqd);
    CHECK(reused.Minv == aw.Minv);
    CHECK(reused.qdd == aw.qdd);
  }
}

TEST_CASE("nh derivatives with external wrenches: equal the duals of lift | rne | w | project; evaluate = the call") {
  std::mt19937_64 rng(23);
  const auto r = io::load_robot_file(source("examples/robots/mobile_manipulator_bicycle.json"));
  REQUIRE(r.constraint);
  nhdyn_test::visit_only<bicycle<double>>(*r.constraint, [&](const auto& c) {
    const tree<double>& t = r.model;
    const int n = c.dof(), m = c.m();
    wrench<double> w1, w2;
    w1.body = n, w1.force = random_vec(rng, 3, 20), w1.point = random_vec(rng, 3, 0.3);
    w2.body = 4, w2.moment = random_vec(rng, 3, 5), w2.force = random_vec(rng, 3, 7), w2.frame = wrench_frame::body;
    const auto w = external_wrenches(t, {w1, w2});
    const VectorXd q = random_vec(rng, n, 1.5), eta = random_vec(rng, m, 1), eta_dot = random_vec(rng, m, 1),
                   tau = random_vec(rng, m, 5);
    const auto d = inverse_dynamics_derivatives(t, c);
    const auto a = d(q, eta, eta_dot, w);
    // the reference: duals through project ∘ (rne − Q_ext) ∘ lift with the same wrenches
    const auto id = lift(c) | rne(t) | w | project(c);
    VectorXd x(n + 2 * m);
    x << q, eta, eta_dot;
    const MatrixXd J = jacobian(
        [&](const auto& z) {
          using D = typename std::decay_t<decltype(z)>::Scalar;
          return Eigen::Matrix<D, Eigen::Dynamic, 1>(id(z.head(n), z.segment(n, m), z.tail(m)));
        },
        x);
    CHECK(rel(a.J(), J) < 1e-12);
    CHECK(rel(a.J(), d(q, eta, eta_dot).J()) > 1e-6);  // the wrenches change the derivatives
    nh_derivatives_result<double, Eigen::Dynamic> e;
    d.evaluate(q, eta, eta_dot, e);  // first without: the scratch of another call
    d.evaluate(q, eta, eta_dot, w, e);
    CHECK(e.J() == a.J());
    CHECK(e.tau == a.tau);
    // the constrained forward dynamics' A, B with the wrenches, and evaluate
    const auto f = forward_dynamics_derivatives(t, c);
    const auto fa = f(q, eta, tau, w);
    nh_fd_derivatives_result<double, Eigen::Dynamic> fe;
    f.evaluate(q, eta, tau, w, fe);
    CHECK(fe.ss.A == fa.ss.A);
    CHECK(fe.ss.B == fa.ss.B);
    CHECK(fe.eta_dot == fa.eta_dot);
    // and rne's own derivatives with the wrenches
    const auto rd = rne_derivatives(t);
    const VectorXd v1 = random_vec(rng, n, 1), v2 = random_vec(rng, n, 1);
    const auto ra = rd(q, v1, v2, w);
    rne_derivatives_result<double> re;
    rd.evaluate(q, v1, v2, w, re);
    CHECK(re.dq == ra.dq);
    CHECK(re.dqd == ra.dqd);
    CHECK(re.M == ra.M);
    CHECK(re.tau == ra.tau);
  });
}

TEST_CASE("derivatives: a constraint for another model, and bad inputs, are refused by name") {
  const auto p5 = as_tree(presets::paper5<double>().chain);
  CHECK_THROWS_WITH(inverse_dynamics_derivatives(p5, holonomic<dynamic>{4}), Catch::Contains("4 joints"));
  const auto d = inverse_dynamics_derivatives(p5, differential_drive<double, dynamic>(5, 0, 1, 2, 0.0, -1.0));
  const VectorXd z4 = VectorXd::Zero(4), z3 = VectorXd::Zero(3);
  CHECK_THROWS_WITH(d(VectorXd::Zero(5).eval(), z3, z4), Catch::Contains("eta"));
  VectorXd q = VectorXd::Zero(5);
  q(2) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(d(q, z4, z4), input_error);
}

TEST_CASE("derivatives' plain calls: the outputs of evaluate into a fresh result, no scratch, also after a call that failed midway") {
  // The calls in double evaluate into a result their thread keeps and move its outputs out;
  // the kept scratch then serves other objects, sizes and constraints, and a call that threw
  // after writing part of it (q̈ overflows once M, h and the factor are formed).
  std::mt19937_64 rng(2026);
  for (const char* file : {"mecanum_arm.json", "castor_drive_arm.json", "mobile_manipulator.json"}) {
    const auto r = io::load_robot_file(source("examples/robots/") + file);
    REQUIRE(r.constraint);
    std::visit([&](const auto& c) {
      const auto& t = r.model;
      const int n = c.dof(), m = c.m(), p = actuator_count(c);
      INFO(file);
      const VectorXd q = random_vec(rng, n, 1.5), eta = random_vec(rng, m, 1), ed = random_vec(rng, m, 1),
                     tau = random_vec(rng, p, 5), qd = random_vec(rng, n, 1), tq = random_vec(rng, n, 5);
      const auto id = inverse_dynamics_derivatives(t, c);
      const auto nfd = forward_dynamics_derivatives(t, c);
      const auto hfd = forward_dynamics_derivatives(t);
      CHECK_THROWS(hfd(q, qd, VectorXd::Constant(n, 1e308)));
      CHECK_THROWS(nfd(q, eta, VectorXd::Constant(p, 1e308)));
      const auto a = id(q, eta, ed);
      const auto b = nfd(q, eta, tau);
      const auto h = hfd(q, qd, tq);
      nh_derivatives_result<double, std::decay_t<decltype(c)>::m_at_compile_time> ea;
      nh_fd_derivatives_result<double, std::decay_t<decltype(c)>::m_at_compile_time> eb;
      fd_derivatives_result<double> eh;
      id.evaluate(q, eta, ed, ea);
      nfd.evaluate(q, eta, tau, eb);
      hfd.evaluate(q, qd, tq, eh);
      CHECK((a.J() == ea.J() && a.tau == ea.tau && a.dqd_dq == ea.dqd_dq && a.id.M == ea.id.M && a.id.dq == ea.id.dq));
      CHECK((b.ss.A == eb.ss.A && b.ss.B == eb.ss.B && b.eta_dot == eb.eta_dot && b.id.J() == eb.id.J()));
      CHECK((h.qdd == eh.qdd && h.dq == eh.dq && h.dqd == eh.dqd && h.Minv == eh.Minv && h.id.M == eh.id.M));
      // a returned result carries its outputs only
      CHECK((a.work.se.size() == 0 && a.work.z.size() == 0 && a.work.q.size() == 0));
      CHECK((b.id.work.z.size() == 0 && b.fd.eta_dot.size() == 0 && b.redundant.y.size() == 0));
      CHECK((h.rhs.size() == 0 && h.fd.M.size() == 0 && h.fd.h.size() == 0));
      // and the outputs are the independent references' (the dual linearizers)
      CHECK(rel(a.J(), inverse_dynamics_linearizer(t, c)(q, eta, ed).J) < 1e-12);
      // (M⁻¹ of a free tree whose wheels and castors are light: A keeps fewer digits, 1.0e-10
      // apart on castor_drive_arm)
      CHECK(rel(h.state_space_model().A, linearize_forward_dynamics(t, q, qd, tq).A) < 1e-9);
    }, *r.constraint);
  }
}
