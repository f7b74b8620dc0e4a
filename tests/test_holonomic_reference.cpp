// Holonomic dynamics against independent references (issue 2, item 7):
//  (i)  rne, the CRBA mass matrix and the bias against an Euler–Lagrange reference in long
//       double (tests/reference/lagrangian.hpp: M from link Jacobians of its own 4×4 DH
//       kinematics, C from Christoffel symbols of exact ∂M/∂q, g from ∂P/∂q);
//  (ii) power balance q̇ᵀ rne(q, q̇, q̈) = dE/dt, E = kinetic + potential energy, dE/dt exact
//       along the motion;
//  (iv) identities: rne(q, q̇, 0) = bias, M q̈ + bias = rne (CRBA vs RNE), forward dynamics
//       inverts rne, M symmetric positive definite, options gravity/velocity off equal the
//       corresponding Lagrangian terms; float and long double consistent with their precision.
// (iii), Orocos KDL, is in test_kdl_reference.cpp.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nhdyn/nhdyn.hpp>
#include <random>
#include <string>

#include "reference/lagrangian.hpp"
#include "reference/random_chain.hpp"

namespace {

using LD = long double;
using nhdyn_ref::random_vector;
constexpr double tol = 1e-12;  // the agreement, relative, in double

/// ‖x − ref‖∞ / max(‖ref‖∞, floor): norm-wise relative error (ref in long double). The floor
/// keeps a term that is zero by symmetry (a body spinning about a fixed axis has no Coriolis
/// torque) from dividing rounding by rounding; it is set far below the state's dynamics.
template <class A, class B>
double rel(const A& x, const B& ref, long double floor = 0) {
  const LD d = (x.template cast<LD>() - ref.template cast<LD>()).cwiseAbs().maxCoeff();
  const LD s = ref.template cast<LD>().cwiseAbs().maxCoeff();
  return static_cast<double>(d / std::max({s, floor, std::numeric_limits<LD>::min()}));
}

/// The largest error seen in a test case, printed at its end so the numbers can be reported.
struct worst {
  std::string what;
  double e = 0;
  explicit worst(std::string w) : what(std::move(w)) {}
  double operator()(double x) {
    e = std::max(e, x);
    return x;
  }
  ~worst() { std::printf("  max relative error, %-58s %.3g\n", what.c_str(), e); }
};

template <class V>
nhdyn_ref::vec<LD> ld(const V& v) {
  return v.template cast<LD>();
}

/// One chain, many random states: rne (all four option sets), mass matrix and bias against
/// the Lagrangian.
template <int N>
void check_against_lagrangian(const nhdyn::chain<double, N>& c, std::mt19937_64& rng, int states,
                              worst& w_rne, worst& w_terms) {
  const auto ref = nhdyn_ref::from_chain<LD>(c);
  const int n = c.dof();
  const auto id = nhdyn::rne(c);
  const auto id_no_g = id.with({.gravity = false, .velocity = true});
  const auto id_no_v = id.with({.gravity = true, .velocity = false});
  const auto id_none = id.with({.gravity = false, .velocity = false});
  const auto M = nhdyn::mass_matrix(c);
  const auto h = nhdyn::bias(c);
  for (int s = 0; s < states; ++s) {
    const nhdyn::vecN<double, N> q = random_vector(rng, n, -3.1, 3.1), qd = random_vector(rng, n, -2, 2),
                                 qdd = random_vector(rng, n, -3, 3);
    const auto L = nhdyn_ref::terms<LD>(ref, ld(q), ld(qd));
    const nhdyn_ref::vec<LD> Mqdd = L.M * ld(qdd);
    // Floor for terms that vanish by symmetry: 1e-3 of the magnitude of the dynamics here.
    const LD f = 1e-3L * (Mqdd.cwiseAbs().maxCoeff() + L.c.cwiseAbs().maxCoeff() + L.g.cwiseAbs().maxCoeff());
    INFO("chain " << c.name() << " (" << n << " dof), q = " << q.transpose() << ", qd = " << qd.transpose()
                  << ", qdd = " << qdd.transpose());
    CHECK(w_rne(rel(id(q, qd, qdd), nhdyn_ref::vec<LD>(Mqdd + L.c + L.g), f)) < tol);
    CHECK(w_rne(rel(id_no_g(q, qd, qdd), nhdyn_ref::vec<LD>(Mqdd + L.c), f)) < tol);
    CHECK(w_rne(rel(id_no_v(q, qd, qdd), nhdyn_ref::vec<LD>(Mqdd + L.g), f)) < tol);
    CHECK(w_rne(rel(id_none(q, qd, qdd), Mqdd, f)) < tol);
    CHECK(w_terms(rel(M(q), L.M)) < tol);
    CHECK(w_terms(rel(h(q, qd), nhdyn_ref::vec<LD>(L.c + L.g), f)) < tol);
  }
}

/// The random chains of this file: n = 1…8, mixed joints, some with a link of zero mass
/// but rotational inertia, some with a fully massless link (also at the tip).
std::vector<nhdyn::chain<double>> random_chains(std::mt19937_64& rng) {
  std::vector<nhdyn::chain<double>> out;
  for (int n = 1; n <= 8; ++n) {
    out.push_back(nhdyn_ref::random_chain(rng, n));
    out.push_back(nhdyn_ref::random_chain(rng, n, {.prismatic_probability = 0.5, .massless_with_inertia = n / 2}));
    if (n >= 2)
      out.push_back(nhdyn_ref::random_chain(
          rng, n, {.prismatic_probability = 0.3, .massless_with_inertia = n - 1, .fully_massless = n / 2 - 1}));
  }
  out.push_back(nhdyn_ref::random_chain(rng, 4, {.prismatic_probability = 1.0}));  // all prismatic
  out.push_back(nhdyn_ref::random_chain(rng, 4, {.prismatic_probability = 0.0, .fully_massless = 3}));
  return out;
}

}  // namespace

TEST_CASE("rne: paper5 agrees with the independent Lagrangian to 1e-12") {
  std::mt19937_64 rng(1);
  worst w_rne("rne vs Lagrangian, paper5 (all option sets)"), w_terms("M, bias vs Lagrangian, paper5");
  check_against_lagrangian(nhdyn::presets::paper5_chain<double>(), rng, 20, w_rne, w_terms);
  check_against_lagrangian(nhdyn::presets::paper5_chain<double>().dynamic_size(), rng, 10, w_rne, w_terms);
  // Perturbed plants (paper5.md's parameter study): heavier links, longer arm.
  nhdyn::presets::paper5_parameters<double> p;
  p.mass_factor = {1, 1, 1.3, 2.0, 0.5};
  p.d3_factor = 1.2;
  p.a4_factor = 0.8;
  p.a5_factor = 1.5;
  check_against_lagrangian(nhdyn::presets::paper5_chain<double>(p), rng, 10, w_rne, w_terms);
}

TEST_CASE("rne: puma560 agrees with the independent Lagrangian to 1e-12, fixed and run-time sized") {
  std::mt19937_64 rng(2);
  worst w_rne("rne vs Lagrangian, puma560 (all option sets)"), w_terms("M, bias vs Lagrangian, puma560");
  check_against_lagrangian(nhdyn::presets::puma560<double>(), rng, 20, w_rne, w_terms);
  check_against_lagrangian(nhdyn::presets::puma560<double>().dynamic_size(), rng, 20, w_rne, w_terms);
}

TEST_CASE("rne: random mixed chains with massless links agree with the independent Lagrangian") {
  std::mt19937_64 rng(3);
  worst w_rne("rne vs Lagrangian, random chains (all option sets)"), w_terms("M, bias vs Lagrangian, random chains");
  for (const auto& c : random_chains(rng)) {
    check_against_lagrangian(c, rng, 4, w_rne, w_terms);
    if (c.dof() == 3) check_against_lagrangian(c.fixed<3>(), rng, 4, w_rne, w_terms);
    if (c.dof() == 7) check_against_lagrangian(c.fixed<7>(), rng, 4, w_rne, w_terms);
  }
}

TEST_CASE("rne: a link with zero mass but rotational inertia contributes its inertia") {
  // One revolute joint about z₀ carrying only a spinning disk of inertia Izz = 0.7 and no
  // mass: τ = Izz q̈ exactly, with or without gravity (Spong's rigid-body torque).
  nhdyn::link<double> L;
  L.inertia.diagonal() << 0.4, 0.3, 0.7;
  L.com << 0.2, -0.1, 0.3;  // irrelevant when m = 0
  const nhdyn::chain<double> c({L}, Eigen::Vector3d(0, -9.81, 0), "disk");
  Eigen::VectorXd q(1), qd(1), qdd(1);
  q << 0.3;
  qd << 2.0;
  qdd << -1.5;
  CHECK(nhdyn::rne(c)(q, qd, qdd)(0) == Approx(0.7 * -1.5).epsilon(1e-15));
  // Chains where the massless link with inertia sits between massive ones.
  std::mt19937_64 rng(4);
  worst w_rne("rne vs Lagrangian, zero-mass links with inertia"), w_terms("M, bias vs Lagrangian, same");
  for (int n = 2; n <= 6; ++n)
    for (int k = 0; k < n; ++k)
      check_against_lagrangian(nhdyn_ref::random_chain(rng, n, {.massless_with_inertia = k}), rng, 2, w_rne,
                               w_terms);
}

TEST_CASE("rne: power balance qdᵀ·rne(q, qd, qdd) equals dE/dt of kinetic plus potential energy") {
  std::mt19937_64 rng(5);
  worst w("power balance |qdᵀv − dE/dt| / Σ|qd_i v_i|"), w_self("power balance of the reference itself");
  auto check = [&](const auto& c, int states) {
    const auto ref = nhdyn_ref::from_chain<LD>(c);
    const auto id = nhdyn::rne(c);
    const int n = c.dof();
    for (int s = 0; s < states; ++s) {
      const Eigen::VectorXd q = random_vector(rng, n, -3.1, 3.1), qd = random_vector(rng, n, -2, 2),
                            qdd = random_vector(rng, n, -3, 3);
      const Eigen::VectorXd v = id(q, qd, qdd);
      const LD dEdt = nhdyn_ref::energy_rate<LD>(ref, ld(q), ld(qd), ld(qdd));
      const LD scale = (ld(qd).cwiseProduct(ld(v))).cwiseAbs().sum();
      INFO("chain " << c.name() << ", q = " << q.transpose());
      CHECK(w(double(std::abs(LD(qd.dot(v)) - dEdt) / scale)) < tol);
      // The reference's two routes (Euler–Lagrange terms vs energy along the motion) agree.
      const nhdyn_ref::vec<LD> tau = nhdyn_ref::inverse_dynamics<LD>(ref, ld(q), ld(qd), ld(qdd));
      CHECK(w_self(double(std::abs(ld(qd).dot(tau) - dEdt) / scale)) < 1e-16);
    }
  };
  check(nhdyn::presets::paper5_chain<double>().dynamic_size(), 20);
  check(nhdyn::presets::puma560<double>().dynamic_size(), 20);
  for (const auto& c : random_chains(rng)) check(c, 3);
}

TEST_CASE("reference: kinetic energy from link velocities equals ½ qdᵀ M qd") {
  // Validates the reference: M (Jacobian route) against K (velocities along the motion).
  std::mt19937_64 rng(6);
  for (const auto& c : random_chains(rng)) {
    const auto ref = nhdyn_ref::from_chain<LD>(c);
    const nhdyn_ref::vec<LD> q = ld(random_vector(rng, c.dof(), -3, 3)), qd = ld(random_vector(rng, c.dof(), -2, 2));
    const LD K = nhdyn_ref::kinetic_energy<LD>(ref, q, qd);
    const LD K2 = LD(0.5) * qd.dot(nhdyn_ref::mass_matrix<LD>(ref, q) * qd);
    CHECK(std::abs(K - K2) <= 1e-16L * K);
  }
}

TEST_CASE("identities: rne(q, qd, 0) is the bias, M qdd + bias is rne, forward dynamics inverts rne") {
  std::mt19937_64 rng(7);
  worst w_bias("rne(q,qd,0) vs bias"), w_crba("M qdd + bias vs rne"), w_fd("fd(q,qd,rne(q,qd,qdd)) vs qdd / cond(M)"),
      w_eig("eigenvalues of M vs Lagrangian's");
  auto check = [&](const auto& c, int states) {
    using C = std::decay_t<decltype(c)>;
    constexpr int N = C::size_at_compile_time;
    const auto ref = nhdyn_ref::from_chain<LD>(c);
    const int n = c.dof();
    const auto id = nhdyn::rne(c);
    const auto M = nhdyn::mass_matrix(c);
    const auto h = nhdyn::bias(c);
    const auto fd = nhdyn::forward_dynamics(c);
    for (int s = 0; s < states; ++s) {
      const nhdyn::vecN<double, N> q = random_vector(rng, n, -3.1, 3.1), qd = random_vector(rng, n, -2, 2),
                                   qdd = random_vector(rng, n, -3, 3);
      INFO("chain " << c.name() << ", q = " << q.transpose());
      const nhdyn::vecN<double, N> v = id(q, qd, qdd);
      CHECK(w_bias(rel(id(q, qd, nhdyn::vecN<double, N>::Zero(n)), ld(h(q, qd)))) == 0);
      const auto Mq = M(q);
      CHECK(w_crba(rel(Mq * qdd + h(q, qd), ld(v))) < tol);
      CHECK((Mq - Mq.transpose()).cwiseAbs().maxCoeff() == 0);
      // Positive definite, with the Lagrangian's spectrum.
      const Eigen::SelfAdjointEigenSolver<nhdyn_ref::mat<LD>> es(nhdyn_ref::mass_matrix<LD>(ref, ld(q)));
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es_lib(Mq);
      CHECK(es_lib.eigenvalues().minCoeff() > 0);
      CHECK(w_eig(rel(es_lib.eigenvalues(), es.eigenvalues())) < tol);
      const double cond = double(es.eigenvalues().maxCoeff() / es.eigenvalues().minCoeff());
      // Forward dynamics: its error is bounded by c·n·ε·cond(M) (backward stability of LDLᵀ,
      // plus the rounding of v itself, also amplified by cond(M)). c·n ≈ 900 here; observed
      // up to ≈ 110 (clang -O0, without contractions), 60–80 with g++ -O1…-O3.
      CHECK(w_fd(rel(fd(q, qd, v), ld(qdd)) / cond) < 1e-13);
    }
  };
  check(nhdyn::presets::paper5_chain<double>(), 20);
  check(nhdyn::presets::puma560<double>(), 20);
  check(nhdyn::presets::puma560<double>().dynamic_size(), 20);
  // Random chains whose every joint moves mass (M positive definite).
  for (int n = 1; n <= 8; ++n)
    for (int r = 0; r < 3; ++r)
      check(nhdyn_ref::random_chain(rng, n,
                                    {.prismatic_probability = 0.4, .massless_with_inertia = r == 1 && n > 1 ? 0 : -1}),
            3);
}

TEST_CASE("forward dynamics: a chain whose last joint moves nothing is reported as singular") {
  std::mt19937_64 rng(8);
  const auto c = nhdyn_ref::random_chain(rng, 4, {.fully_massless = 3});
  const Eigen::VectorXd q = random_vector(rng, 4, -1, 1), qd = random_vector(rng, 4, -1, 1),
                        tau = random_vector(rng, 4, -1, 1);
  CHECK_THROWS_AS(nhdyn::forward_dynamics(c)(q, qd, tau), nhdyn::numerical_error);
  CHECK_THROWS_WITH(nhdyn::forward_dynamics(c)(q, qd, tau), Catch::Contains("mass matrix"));
}

TEST_CASE("rne: float and long double agree with the long double Lagrangian at their precision") {
  std::mt19937_64 rng(9);
  worst w_f("rne<float> vs Lagrangian / eps(float)"), w_ld("rne<long double> vs Lagrangian / eps(long double)"),
      w_fM("M<float> vs Lagrangian / eps(float)"), w_ldM("M<long double> vs Lagrangian / eps(long double)");
  auto check = [&](const nhdyn::chain<double>& cd, const nhdyn::chain<LD>& cl, int states) {
    const auto cf = cd.cast<float>();
    // References built from the float and long double chains' own data, so that only the
    // algorithms' rounding is measured.
    const auto ref_f = nhdyn_ref::from_chain<LD>(cf);
    const auto ref_l = nhdyn_ref::from_chain<LD>(cl);
    const int n = cd.dof();
    for (int s = 0; s < states; ++s) {
      const Eigen::VectorXf q = random_vector(rng, n, -3, 3).cast<float>(),
                            qd = random_vector(rng, n, -2, 2).cast<float>(),
                            qdd = random_vector(rng, n, -3, 3).cast<float>();
      const nhdyn_ref::vec<LD> ql = ld(q), qdl = ld(qd), qddl = ld(qdd);
      INFO("chain " << cd.name() << ", q = " << q.transpose());
      const double ef = std::numeric_limits<float>::epsilon(), el = double(std::numeric_limits<LD>::epsilon());
      CHECK(w_f(rel(nhdyn::rne(cf)(q, qd, qdd), nhdyn_ref::inverse_dynamics<LD>(ref_f, ql, qdl, qddl)) / ef) < 200);
      CHECK(w_fM(rel(nhdyn::mass_matrix(cf)(q), nhdyn_ref::mass_matrix<LD>(ref_f, ql)) / ef) < 200);
      const nhdyn_ref::vec<LD> vl = nhdyn::rne(cl)(ql, qdl, qddl);
      CHECK(w_ld(rel(vl, nhdyn_ref::inverse_dynamics<LD>(ref_l, ql, qdl, qddl)) / el) < 100);
      CHECK(w_ldM(rel(nhdyn::mass_matrix(cl)(ql), nhdyn_ref::mass_matrix<LD>(ref_l, ql)) / el) < 100);
    }
  };
  // Presets built in long double directly (a cast from double would carry double's π/2).
  check(nhdyn::presets::paper5_chain<double>().dynamic_size(), nhdyn::presets::paper5_chain<LD>().dynamic_size(), 10);
  check(nhdyn::presets::puma560<double>().dynamic_size(), nhdyn::presets::puma560<LD>().dynamic_size(), 10);
  for (int n = 2; n <= 7; ++n) {
    const auto c = nhdyn_ref::random_chain(rng, n, {.massless_with_inertia = 0});
    check(c, c.cast<LD>(), 3);
  }
  // The presets instantiated directly in each scalar.
  const Eigen::Matrix<float, 6, 1> q = Eigen::Matrix<float, 6, 1>::Constant(0.4f);
  const auto pf = nhdyn::presets::puma560<float>();
  CHECK(rel(nhdyn::rne(pf)(q, q, q), nhdyn_ref::inverse_dynamics<LD>(nhdyn_ref::from_chain<LD>(pf), ld(q), ld(q), ld(q))) <
        1e-4);
}

TEST_CASE("rne: joint angles far from zero and long chains agree with the independent Lagrangian") {
  // Angles up to 1e6 rad (argument reduction of sin/cos is exercised) on puma560 and random
  // chains. nhdyn forms θ_i = θ_i⁰ + q_i with a compensated (exact) sum (model/dh_kernel.hpp,
  // correct_angle_sum), so the reference sums the given doubles θ_i⁰ and q_i in long double
  // (error ≤ ulp_ld(1e6) ≈ 1e-13 rad): a double-rounded sum would be off by up to
  // ½ulp(q_i) = 6e-11 rad at 1e6 and this test would see it.
  std::mt19937_64 rng(10);
  worst w_big("rne vs Lagrangian, |q| up to 1e6"), w_long("rne vs Lagrangian, chains of 12, 20 links");
  auto check = [&](const auto& c, double qmax, int states, worst& w) {
    auto ref = nhdyn_ref::from_chain<LD>(c);
    const auto id = nhdyn::rne(c);
    const int n = c.dof();
    for (int s = 0; s < states; ++s) {
      Eigen::VectorXd q = random_vector(rng, n, -qmax, qmax);
      if (s == 0) q.setConstant(qmax);  // the edge of the range exactly
      const Eigen::VectorXd qd = random_vector(rng, n, -2, 2), qdd = random_vector(rng, n, -3, 3);
      INFO("chain " << c.name() << ", q = " << q.transpose());
      CHECK(w(rel(id(q, qd, qdd), nhdyn_ref::inverse_dynamics<LD>(ref, ld(q), ld(qd), ld(qdd)))) < tol);
    }
  };
  for (const double qmax : {10.0, 1e3, 99999.0, 1e5, 1.00001e5, 1e6}) {
    check(nhdyn::presets::puma560<double>().dynamic_size(), qmax, 5, w_big);
    check(nhdyn_ref::random_chain(rng, 5, {.prismatic_probability = 0.0}), qmax, 3, w_big);
    check(nhdyn_ref::random_chain(rng, 5, {.prismatic_probability = 0.0}).fixed<5>(), qmax, 3, w_big);
  }
  check(nhdyn_ref::random_chain(rng, 12, {.massless_with_inertia = 3, .fully_massless = 7}), 3.1, 3, w_long);
  check(nhdyn_ref::random_chain(rng, 20), 3.1, 2, w_long);
}

TEST_CASE("rne: the pipeline form id(joint_state) and velocity = false agree with the Lagrangian") {
  std::mt19937_64 rng(14);
  const auto c = nhdyn::presets::puma560<double>();
  const auto ref = nhdyn_ref::from_chain<LD>(c);
  const auto id = nhdyn::rne(c);
  for (int s = 0; s < 5; ++s) {
    nhdyn::joint_state<double, 6> xi;
    xi.q = random_vector(rng, 6, -3, 3);
    xi.qd = random_vector(rng, 6, -2, 2);
    xi.qdd = random_vector(rng, 6, -3, 3);
    const auto out = id(xi);
    CHECK(out.q == xi.q);
    CHECK(rel(out.v, nhdyn_ref::inverse_dynamics<LD>(ref, ld(xi.q), ld(xi.qd), ld(xi.qdd))) < tol);
    // With velocity = false q̇ is not read (a NaN there is harmless) and v = M q̈ + g.
    Eigen::Matrix<double, 6, 1> nan_qd = Eigen::Matrix<double, 6, 1>::Constant(std::numeric_limits<double>::quiet_NaN());
    const auto no_v = id.with({.gravity = true, .velocity = false});
    CHECK(rel(no_v(xi.q, nan_qd, xi.qdd),
              nhdyn_ref::inverse_dynamics<LD>(ref, ld(xi.q), ld(xi.qd), ld(xi.qdd), true, false)) < tol);
  }
}

TEST_CASE("rne: without gravity the power qdᵀv equals dK/dt of the kinetic energy") {
  // q̇ᵀ rne_{g=0}(q, q̇, q̈) = dK/dt: kinetic energy alone, exact along the motion.
  std::mt19937_64 rng(15);
  worst w("power balance without gravity, / Σ|qd_i v_i|");
  for (const auto& c : random_chains(rng)) {
    auto ref = nhdyn_ref::from_chain<LD>(c);
    ref.gravity.setZero();
    const auto id = nhdyn::rne(c, {.gravity = false, .velocity = true});
    const int n = c.dof();
    for (int s = 0; s < 3; ++s) {
      const Eigen::VectorXd q = random_vector(rng, n, -3, 3), qd = random_vector(rng, n, -2, 2),
                            qdd = random_vector(rng, n, -3, 3);
      const Eigen::VectorXd v = id(q, qd, qdd);
      const LD dKdt = nhdyn_ref::energy_rate<LD>(ref, ld(q), ld(qd), ld(qdd));
      const LD scale = std::max((ld(qd).cwiseProduct(ld(v))).cwiseAbs().sum(), LD(1e-300));
      INFO("chain " << c.name() << ", q = " << q.transpose());
      CHECK(w(double(std::abs(LD(qd.dot(v)) - dKdt) / scale)) < tol);
    }
  }
}
