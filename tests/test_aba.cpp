/// The articulated-body forward dynamics (dynamics/aba.hpp) against independent references:
/// CRBA + LDLᵀ (the mass matrix route), the inverse dynamics it must invert, ∂q̈/∂τ = M⁻¹ by
/// dual numbers, interval enclosure, and 50-digit CRBA + LDLᵀ on chains whose masses span
/// 1e-9 to 1e6 kg (both routes, with the scaled singularity test of detail/ldlt.hpp).
#include <catch2/catch.hpp>

#include <Eigen/Cholesky>
#include <nhdyn/dynamics/aba.hpp>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/scalar/interval.hpp>
#include <nhdyn/scalar/multiprecision.hpp>
#include <limits>
#include <memory>
#include <random>
#include <thread>

#include "reference/random_tree.hpp"

using namespace nhdyn;
using Eigen::VectorXd;

namespace {
VectorXd random_vec(std::mt19937_64& rng, int n, double r) {
  return VectorXd::NullaryExpr(n, [&] { return nhdyn_ref::uniform(rng, -r, r); });
}
double rel(const VectorXd& a, const VectorXd& b) { return (a - b).lpNorm<Eigen::Infinity>() / std::max(1.0, b.lpNorm<Eigen::Infinity>()); }

/// A chain (no branches) of n bodies whose masses span 1e-9…1e6 kg: `order` 0 heavy at the
/// base, 1 light at the base, 2 shuffled; rotational inertias scale with each mass.
tree<double> mass_span_chain(std::mt19937_64& rng, int n, int order) {
  auto t = nhdyn_ref::random_tree(rng, n, 0.0, false);
  std::vector<body<double>> B(t.begin(), t.end());
  std::vector<double> e(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) e[std::size_t(i)] = 6.0 - 15.0 * i / (n - 1);  // log10 m: 6 … −9
  if (order == 1) std::reverse(e.begin(), e.end());
  if (order == 2) std::shuffle(e.begin(), e.end(), rng);
  for (int i = 0; i < n; ++i) {
    auto& b = B[std::size_t(i)];
    b.mass = std::pow(10.0, e[std::size_t(i)]);
    b.inertia = nhdyn_ref::random_inertia(rng, b.mass);
  }
  return tree<double>(std::move(B), t.gravity(), "mass span");
}
}  // namespace

TEST_CASE("aba = CRBA + LDLT forward dynamics and inverts rne, on random trees of 1-40 bodies", "[aba]") {
  std::mt19937_64 rng(15);
  for (int n : {1, 2, 3, 5, 8, 13, 21, 40}) {
    for (int trial = 0; trial < 4; ++trial) {
      const auto t = nhdyn_ref::random_tree(rng, n, 0.4, trial % 2 == 0);
      const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), tau = random_vec(rng, n, 5);
      const VectorXd a = aba(t)(q, qd, tau);
      const VectorXd b = forward_dynamics(t, {}, {.method = fd_method::crba_ldlt})(q, qd, tau);
      INFO("n = " << n);
      CHECK(rel(a, b) <= 1e-10);
      CHECK(rel(VectorXd(rne(t)(q, qd, a)), tau) <= 1e-10);
      // the kernel (kernel frames, 3×3 blocks) is the book's algorithm (6×6, RBDA Table 7.1);
      // measured: worst 4.8e-13 from CRBA + LDLᵀ over these trees, the 6×6 reference 1.2e-12
      CHECK(rel(reference::aba<double>(t, q, qd, tau), a) <= 1e-10);
    }
  }
}

TEST_CASE("aba into reused storage (evaluate) gives the call's numbers, also over τ's own storage and beyond the stack scratch", "[aba]") {
  std::mt19937_64 rng(31);
  for (int n : {3, 16, 80}) {  // 80 bodies: the kernel's scratch beyond its stack part (51 in double)
    const auto t = nhdyn_ref::random_tree(rng, n, 0.4, true);
    const auto fd = aba(t);
    VectorXd a(n);
    for (int s = 0; s < 2; ++s) {  // the same storage twice
      const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), tau = random_vec(rng, n, 5);
      INFO("n = " << n);
      const VectorXd want = fd(q, qd, tau);
      // an independent check that the call itself is right (the 6×6 book algorithm)
      CHECK(rel(reference::aba<double>(t, q, qd, tau), want) <= 1e-10);
      fd.evaluate(q, qd, tau, a);
      CHECK(a == want);  // bit for bit
      VectorXd w = tau;  // q̈ over τ's own storage
      fd.evaluate(q, qd, w, w);
      CHECK(w == want);
      double buf[80];  // into a map of the caller's storage
      Eigen::Map<VectorXd> mv(buf, n);
      fd.evaluate(q, qd, tau, mv);
      CHECK(mv == want);
    }
    VectorXd wrong(n + 1);
    CHECK_THROWS_WITH(fd.evaluate(VectorXd::Zero(n), VectorXd::Zero(n), VectorXd::Zero(n), wrong),
                      Catch::Contains("qdd") && Catch::Contains(std::to_string(n)));
  }
}

TEST_CASE("scratch beyond the stack: a block its thread keeps, one per nested buffer, elements fresh on reuse", "[aba]") {
  using detail::small_buffer;
  struct counted {
    int v = 7;  // not trivial: each element must come default-initialised, new or reused
  };
  const counted* outer = nullptr;
  {
    small_buffer<counted, dynamic, 4> a(10);  // beyond its 4 inline elements: a heap block
    outer = a.data();
    for (int i = 0; i < 10; ++i) CHECK(a[i].v == 7);
    for (int i = 0; i < 10; ++i) a[i].v = -1;
    {
      small_buffer<counted, dynamic, 4> b(10);  // while a holds its block: a block of its own
      CHECK(b.data() != a.data());
      for (int i = 0; i < 10; ++i) CHECK(b[i].v == 7);
    }
    small_buffer<counted, dynamic, 4> small(3);  // within the inline capacity
    CHECK(small[2].v == 7);
  }
  // memory of a's size held meanwhile, so that malloc could not give a's memory back to c:
  // c finds a's block only in the thread's list
  const auto hold = std::make_unique<counted[]>(10);
  {
    small_buffer<counted, dynamic, 4> c(8);  // a's block again (the last given back), fresh
    CHECK(c.data() == outer);
    for (int i = 0; i < 8; ++i) CHECK(c[i].v == 7);
  }
  // Each thread has its own blocks: ABA on an 80-body tree (beyond its 51-body stack part)
  // in two threads at once gives the single-threaded q̈ bit for bit in both.
  std::mt19937_64 rng(77);
  const auto t = nhdyn_ref::random_tree(rng, 80, 0.4, true);
  const VectorXd q = random_vec(rng, 80, 2), qd = random_vec(rng, 80, 2), tau = random_vec(rng, 80, 5);
  const VectorXd want = aba(t)(q, qd, tau);
  VectorXd got[2];
  {
    std::thread th[2];
    for (int k = 0; k < 2; ++k)
      th[k] = std::thread([&, k] {
        VectorXd a(80);
        for (int r = 0; r < 20; ++r) aba(t).evaluate(q, qd, tau, a);
        got[k] = a;
      });
    for (auto& x : th) x.join();
  }
  CHECK(got[0] == want);
  CHECK(got[1] == want);
}

TEST_CASE("a plain call's kept workspace: the thread's own, one per nested call, each thread its own", "[aba]") {
  using detail::thread_kept;
  const std::vector<int>* first = nullptr;
  {
    thread_kept<std::vector<int>> a;
    (*a).assign(5, 1);
    first = &*a;
    {
      thread_kept<std::vector<int>> b;  // nested while a is borrowed: its own, empty
      CHECK(&*b != first);
      CHECK((*b).empty());
      (*b).push_back(9);
    }
  }
  {
    thread_kept<std::vector<int>> c;  // the thread's object again, as the last call left it
    CHECK(&*c == first);
    CHECK(*c == std::vector<int>(5, 1));
  }
  const std::vector<int>* other = nullptr;
  bool other_empty = false;
  std::thread([&] {  // Catch's assertions stay on the test's thread
    thread_kept<std::vector<int>> d;
    other = &*d;
    other_empty = (*d).empty();
  }).join();
  CHECK(other != first);
  CHECK(other_empty);
  // a call that keeps one (CRBA + LDLT's M, h and factor), over trees of different sizes in
  // turn: the numbers of evaluate into a fresh workspace each time (test_wheel_kinds does the
  // constrained forward dynamics' call over every robot file in turn)
  std::mt19937_64 rng(78);
  for (const int n : {12, 3, 30, 12}) {
    const auto t = nhdyn_ref::random_tree(rng, n, 0.4, true);
    const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), tau = random_vec(rng, n, 5);
    const auto fd = forward_dynamics(t, {}, {.method = fd_method::crba_ldlt});
    forward_dynamics_scratch<double, dynamic> ws;
    VectorXd want;
    fd.evaluate(q, qd, tau, ws, want);
    CHECK(fd(q, qd, tau) == want);
  }
}

TEST_CASE("aba far from the world origin: translating the whole tree leaves q̈ unchanged", "[aba]") {
  // A physics invariant (uniform gravity): the robot 1e5…1e6 m from the origin moves as at it.
  // The kernel keeps each body's origin (not the world's), so nothing grows with the distance.
  std::mt19937_64 rng(1541);
  for (int n : {3, 12, 30}) {
    const auto t = nhdyn_ref::random_tree(rng, n, 0.4, true);
    std::vector<body<double>> B(t.begin(), t.end());
    for (auto& b : B)
      if (b.parent < 0) b.p_PJ += vec3<double>(3e5, -1e6, 2e5);
    const tree<double> far(std::move(B), t.gravity(), "far");
    const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), tau = random_vec(rng, n, 5);
    INFO("n = " << n);
    CHECK(rel(aba(far)(q, qd, tau), aba(t)(q, qd, tau)) <= 1e-12);
  }
}

TEST_CASE("aba on other scalars: float, long double, duals (dq̈/dτ = M⁻¹) and intervals (enclosure)", "[aba]") {
  std::mt19937_64 rng(16);
  const auto t = nhdyn_ref::random_tree(rng, 9, 0.4, true);
  const int n = t.dof();
  const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), tau = random_vec(rng, n, 5);
  const VectorXd a = aba(t)(q, qd, tau);
  const auto af = aba(t.cast<float>())(q.cast<float>().eval(), qd.cast<float>().eval(), tau.cast<float>().eval());
  CHECK(rel(af.cast<double>(), a) <= 1e-3);
  const auto al = aba(t.cast<long double>())(q.cast<long double>().eval(), qd.cast<long double>().eval(),
                                              tau.cast<long double>().eval());
  CHECK(rel(al.cast<double>(), a) <= 1e-11);
  // ∂q̈/∂τ_j = column j of M⁻¹ (CRBA), by a dual in τ_j
  const Eigen::MatrixXd Minv = mass_matrix(t)(q).inverse();
  using D = dual<double, 1>;
  for (int j = 0; j < n; ++j) {
    vecN<D, dynamic> td = tau.cast<D>();
    td(j) = D(tau(j), {1.0});
    const auto ad = aba(t)(q, qd, td);
    VectorXd col(n), val(n);
    for (int i = 0; i < n; ++i) {
      col(i) = ad(i).derivative(0);
      val(i) = ad(i).value();
    }
    CHECK(rel(val, a) <= 1e-15);  // the dual's value part: the double arithmetic, reordered
    CHECK(rel(col, Minv.col(j)) <= 1e-10);
  }
  // an interval evaluation at the point state encloses the double result
  const auto ai = aba(t)(q.cast<interval>().eval(), qd.cast<interval>().eval(), tau.cast<interval>().eval());
  for (int i = 0; i < n; ++i) {
    CHECK(ai(i).lower() <= a(i));
    CHECK(ai(i).upper() >= a(i));
  }
}

TEST_CASE("chains whose masses span 1e-9 to 1e6 kg: aba and CRBA + LDLT against a 50-digit reference", "[aba]") {
  // What is determined: the error of any method in double is at least ≈ κ_s·ε, κ_s the
  // condition number of M scaled by its diagonal (LDLᵀ is invariant under that scaling, and
  // the exact M rounded once already costs that much, docs/accuracy.md). Heavy base → light
  // tip and shuffled masses have κ_s ≤ 1e7 here: both methods must give 1e-6. Light base →
  // heavy tip has κ_s up to 1e15: a 1e-9 kg link carrying 1e6 kg, ill-conditioned in itself.
  std::mt19937_64 rng(17);
  double worst_aba_ok = 0, worst_crba_ok = 0;
  for (int n : {4, 8, 16, 32}) {
    for (int order = 0; order < 3; ++order) {
      for (int trial = 0; trial < 3; ++trial) {
        const auto t = mass_span_chain(rng, n, order);
        const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 1), tau = random_vec(rng, n, 1);
        // the reference: CRBA + LDLᵀ in 50 digits (no ABA code), from the same double model
        const vecN<mp50, dynamic> qm = q.cast<mp50>(), qdm = qd.cast<mp50>(), taum = tau.cast<mp50>();
        const auto Mm = reference::crba<mp50>(t, qm);
        const auto hm = reference::rne<mp50>(t, qm, qdm, vecN<mp50, dynamic>(vecN<mp50, dynamic>::Zero(n)));
        const vecN<mp50, dynamic> ref_m = Mm.ldlt().solve(vecN<mp50, dynamic>(taum - hm));
        VectorXd ref(n);
        for (int i = 0; i < n; ++i) ref(i) = static_cast<double>(ref_m(i));
        const Eigen::MatrixXd M = mass_matrix(t)(q);
        const VectorXd s = M.diagonal().cwiseSqrt().cwiseInverse();
        const double kappa_s = condition_number(Eigen::MatrixXd(s.asDiagonal() * M * s.asDiagonal()));
        const double eps = std::numeric_limits<double>::epsilon();
        const double allowed = std::max(1e-6, 1e3 * kappa_s * eps);
        const auto err = [&](const VectorXd& x) { return (x - ref).lpNorm<Eigen::Infinity>() / ref.lpNorm<Eigen::Infinity>(); };
        INFO("n = " << n << ", order " << order << ", scaled condition " << kappa_s);
        const double ea = err(aba(t)(q, qd, tau));
        CHECK(ea <= allowed);
        if (kappa_s * eps <= 1e-9) {
          CHECK(ea <= 1e-6);
          worst_aba_ok = std::max(worst_aba_ok, ea);
        }
        // CRBA + LDLᵀ with the scaled test: answers unless scaled-singular, with the same bound
        if (kappa_s < 0.01 / eps) {
          const double ec = err(forward_dynamics(t, {}, {.method = fd_method::crba_ldlt})(q, qd, tau));
          CHECK(ec <= allowed);
          if (kappa_s * eps <= 1e-9) worst_crba_ok = std::max(worst_crba_ok, ec);
        }
      }
    }
  }
  CHECK(worst_aba_ok <= 1e-6);
  CHECK(worst_crba_ok <= 1e-6);
}

TEST_CASE("aba refuses only a truly singular or non-finite problem, and says which joint", "[aba]") {
  std::mt19937_64 rng(18);
  auto t = nhdyn_ref::random_tree(rng, 4, 0.0, false);
  std::vector<body<double>> B(t.begin(), t.end());
  B[3].mass = 0;  // a massless, inertia-free leaf: nothing moves with joint 3
  B[3].inertia.setZero();
  const tree<double> s(std::move(B), t.gravity(), "singular");
  const VectorXd z = VectorXd::Zero(4);
  CHECK_THROWS_WITH(aba(s)(z, z, z), Catch::Matchers::Contains("joint3") && Catch::Matchers::Contains("singular"));
  VectorXd bad = z;
  bad(2) = std::nan("");
  CHECK_THROWS_WITH(aba(t)(bad, z, z), Catch::Matchers::Contains("q"));
  CHECK_THROWS_WITH(aba(t)(z, VectorXd::Zero(3), z), Catch::Matchers::Contains("qd"));
}

TEST_CASE("forward_dynamics picks ABA or CRBA + LDLT as documented, with the same answers", "[aba]") {
  std::mt19937_64 rng(1540);
  const auto same = [](const VectorXd& a, const VectorXd& b) { return (a - b).cwiseAbs().maxCoeff() == 0.0; };
  for (int n : {6, 8, 9, 40}) {  // around the default aba_from (9)
    const auto t = nhdyn_ref::random_tree(rng, n, 0.3, true);
    const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), tau = random_vec(rng, n, 5);
    const VectorXd by_aba = forward_dynamics(t, {}, {.method = fd_method::aba})(q, qd, tau);
    const VectorXd by_crba = forward_dynamics(t, {}, {.method = fd_method::crba_ldlt})(q, qd, tau);
    const VectorXd automatic = forward_dynamics(t)(q, qd, tau);
    INFO("n = " << n);
    CHECK(same(by_aba, aba(t)(q, qd, tau)));
    CHECK(rel(by_aba, by_crba) <= 1e-9);
    CHECK(same(automatic, n >= fd_options{}.aba_from ? by_aba : by_crba));
    // options: without gravity and velocity terms, both algorithms agree
    for (rne_options o : {rne_options{false, true}, rne_options{true, false}, rne_options{false, false}}) {
      const VectorXd a = forward_dynamics(t, o, {.method = fd_method::aba})(q, qd, tau);
      const VectorXd b = forward_dynamics(t, o, {.method = fd_method::crba_ldlt})(q, qd, tau);
      CHECK(rel(a, b) <= 1e-9);
      CHECK(rel(VectorXd(rne(t, o)(q, qd, a)), tau) <= 1e-9);
    }
    // chains: the same rule (a chain's forward dynamics runs ABA on it as a tree)
    if (n == 6) {
      const auto p = presets::puma560();
      const VectorXd q6 = random_vec(rng, 6, 2), qd6 = random_vec(rng, 6, 1), t6 = random_vec(rng, 6, 5);
      CHECK(same(forward_dynamics(p, {}, {.method = fd_method::aba})(q6, qd6, t6), aba(as_tree(p))(q6, qd6, t6)));
      CHECK(rel(forward_dynamics(p)(q6, qd6, t6), aba(as_tree(p))(q6, qd6, t6)) <= 1e-10);
    }
  }
  // ill-conditioned M (a light base carrying heavy links: scaled pivot ratio past √(1/ε)):
  // automatic answers by ABA, the more accurate of the two there
  const auto light = mass_span_chain(rng, 16, 1);
  const VectorXd q = random_vec(rng, 16, 2), qd = random_vec(rng, 16, 1), tau = random_vec(rng, 16, 5);
  const auto M = mass_matrix(light)(q);
  const double ratio = 1.0 / ldlt_factor<double, dynamic>(M).min_scaled_pivot;
  REQUIRE(ratio > 6.8e7);
  CHECK(same(forward_dynamics(light)(q, qd, tau), aba(light)(q, qd, tau)));
  // a joint that moves nothing: CRBA + LDLT refuses, so does ABA, naming the joint
  std::vector<body<double>> B{body<double>{}};
  B[0].name = "b";
  B[0].joint_name = "idle";
  const tree<double> idle(B, vec3<double>(0, 0, -9.81), "idle");
  CHECK_THROWS_WITH(forward_dynamics(idle, {}, {.method = fd_method::aba})(VectorXd::Zero(1), VectorXd::Zero(1), VectorXd::Ones(1)),
                    Catch::Contains("joint 'idle'") && Catch::Contains("singular"));
  CHECK_THROWS_WITH(forward_dynamics(idle)(VectorXd::Zero(1), VectorXd::Zero(1), VectorXd::Ones(1)),
                    Catch::Contains("mass matrix M(q) is not positive definite"));
}

TEST_CASE("forward_dynamics evaluate into a reused scratch: the call's numbers bit for bit, by either algorithm", "[aba]") {
  std::mt19937_64 rng(2712);
  const auto same = [](const VectorXd& a, const VectorXd& b) { return a.size() == b.size() && (a - b).cwiseAbs().maxCoeff() == 0.0; };
  forward_dynamics_scratch<double, dynamic> ws;  // reused across sizes, algorithms and options
  VectorXd qdd;
  for (int n : {40, 6, 12, 1, 8}) {
    const auto t = nhdyn_ref::random_tree(rng, n, 0.3, true);
    const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), tau = random_vec(rng, n, 5);
    for (fd_method m : {fd_method::automatic, fd_method::aba, fd_method::crba_ldlt})
      for (rne_options o : {rne_options{}, rne_options{false, true}, rne_options{true, false}, rne_options{false, false}}) {
        const auto fd = forward_dynamics(t, o, {.method = m});
        INFO("n = " << n << ", method " << int(m) << ", gravity " << o.gravity << ", velocity " << o.velocity);
        fd.evaluate(q, qd, tau, ws, qdd);
        CHECK(same(qdd, fd(q, qd, tau)));
        // both, against the chosen route rebuilt from its parts (zero tolerance): ABA on the
        // tree as the options make it, or LDLᵀ of CRBA's M solving τ − rne(q, q̇, 0)
        VectorXd expect;
        if (m == fd_method::aba || (m == fd_method::automatic && n >= fd_options{}.aba_from))
          expect = aba(o.gravity ? t : t.with_gravity(vec3<double>::Zero()))(q, o.velocity ? qd : VectorXd::Zero(n), tau);
        else
          expect = ldlt_factor<double, dynamic>(mass_matrix(t)(q)).solve(VectorXd(tau - rne(t, o)(q, qd, VectorXd::Zero(n))));
        CHECK(same(qdd, expect));
        // and with friction on the bias side: τ − τ_f(q̇) solved the same way
        const auto fdf = fd.with(viscous_friction(VectorXd::Constant(n, 0.7)));
        fdf.evaluate(q, qd, tau, ws, qdd);
        CHECK(same(qdd, fdf(q, qd, tau)));
        CHECK(rel(qdd, fd(q, qd, VectorXd(tau - 0.7 * qd))) <= 1e-12);
      }
    // sizes and values checked as the call checks them, naming the argument
    CHECK_THROWS_WITH(forward_dynamics(t).evaluate(q, qd, VectorXd::Zero(n + 1), ws, qdd), Catch::Contains("tau"));
    VectorXd bad = tau;
    bad(0) = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(forward_dynamics(t).evaluate(q, qd, bad, ws, qdd), Catch::Contains("tau"));
  }
  // an ill-conditioned M (scaled pivot ratio past √(1/ε)): the switch to ABA, from the factor
  // in the scratch
  const auto light = mass_span_chain(rng, 16, 1);
  const VectorXd q16 = random_vec(rng, 16, 2), qd16 = random_vec(rng, 16, 1), t16 = random_vec(rng, 16, 5);
  REQUIRE(1.0 / ldlt_factor<double, dynamic>(mass_matrix(light)(q16)).min_scaled_pivot > 6.8e7);
  forward_dynamics(light, {}, {.aba_from = 100}).evaluate(q16, qd16, t16, ws, qdd);
  CHECK(same(qdd, aba(light)(q16, qd16, t16)));
  // a dual τ through the LDLᵀ route (M and h in double, then cast): the double call's values
  // and ∂q̈/∂τ_0 = M⁻¹'s first column
  {
    const auto t = nhdyn_ref::random_tree(rng, 6, 0.3, true);
    const VectorXd q = random_vec(rng, 6, 2), qd = random_vec(rng, 6, 2), tau = random_vec(rng, 6, 5);
    const auto fd = forward_dynamics(t, {}, {.method = fd_method::crba_ldlt});
    using D = dual<double, 1>;
    vecN<D, dynamic> td = tau.cast<D>();
    td(0) = D(tau(0), {1.0});
    const auto qd_dual = fd(q, qd, td);
    VectorXd val(6), col(6);
    for (int i = 0; i < 6; ++i) val(i) = qd_dual(i).value(), col(i) = qd_dual(i).derivative(0);
    CHECK(rel(val, fd(q, qd, tau)) <= 1e-15);
    CHECK(rel(col, mass_matrix(t)(q).inverse().col(0)) <= 1e-10);
  }
  // a chain (fixed size, 6 joints: CRBA + LDLᵀ): its call's numbers, and the route rebuilt
  // from the chain's own M and rne (zero tolerance)
  const auto p = presets::puma560();
  Eigen::Matrix<double, 6, 1> q6 = random_vec(rng, 6, 2), qd6 = random_vec(rng, 6, 1), t6 = random_vec(rng, 6, 5), out6;
  forward_dynamics_scratch<double, 6> ws6;
  const auto fdp = forward_dynamics(p);
  fdp.evaluate(q6, qd6, t6, ws6, out6);
  CHECK(same(out6, fdp(q6, qd6, t6)));
  const Eigen::Matrix<double, 6, 1> h6 = rne(p)(q6, qd6, Eigen::Matrix<double, 6, 1>::Zero());
  CHECK(same(out6, ldlt_factor<double, 6>(mass_matrix(p)(q6)).solve(Eigen::Matrix<double, 6, 1>(t6 - h6))));
  // …and run-time sized (M and h into the scratch by the chain's rne and CRBA evaluate)
  const auto pd = p.dynamic_size();
  const auto fdr = forward_dynamics(pd);
  fdr.evaluate(VectorXd(q6), VectorXd(qd6), VectorXd(t6), ws, qdd);
  CHECK(same(qdd, out6));
  // the chain's rne and CRBA evaluate: their calls' numbers, into storage of another size first
  VectorXd v(6);
  Eigen::MatrixXd H = Eigen::MatrixXd::Ones(2, 3);
  const VectorXd qdd6 = random_vec(rng, 6, 3);
  rne(pd).evaluate(VectorXd(q6), VectorXd(qd6), qdd6, v);
  CHECK(same(v, rne(pd)(VectorXd(q6), VectorXd(qd6), qdd6)));
  mass_matrix(pd).evaluate(VectorXd(q6), H);
  CHECK((H.rows() == 6 && H == mass_matrix(pd)(VectorXd(q6))));
  VectorXd wrong(5);
  CHECK_THROWS_WITH(rne(pd).evaluate(VectorXd(q6), VectorXd(qd6), qdd6, wrong), Catch::Contains("v"));
  // with friction, τ − τ_f in the scratch: the call's numbers, and the route rebuilt from the
  // parts (τ_f by the friction model)
  const auto fric = viscous_friction(VectorXd::Constant(6, 0.7));
  const auto fdrf = fdr.with(fric);
  fdrf.evaluate(VectorXd(q6), VectorXd(qd6), VectorXd(t6), ws, qdd);
  CHECK(same(qdd, fdrf(VectorXd(q6), VectorXd(qd6), VectorXd(t6))));
  CHECK(same(qdd, fdr(VectorXd(q6), VectorXd(qd6), VectorXd(VectorXd(t6) - fric(VectorXd(qd6))))));
}
