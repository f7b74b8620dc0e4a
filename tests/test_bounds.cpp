// Guaranteed interval bounds: every point of a box must map inside the enclosure (checked
// with 10 000 random points per box, evaluated by the ordinary double code path), bisection
// must tighten, unbounded enclosures and malformed boxes must be reported by name, and the
// decimal printing of bounds must never narrow them (checked exactly in 50-digit arithmetic).
#include <catch2/catch.hpp>
#include <nhdyn/analysis/bounds.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/scalar/multiprecision.hpp>
#include <random>

namespace {
using nhdyn::interval;
using nhdyn::outward_about;
using V5 = Eigen::Matrix<double, 5, 1>;
using V4 = Eigen::Matrix<double, 4, 1>;

template <int N>
nhdyn::box<N> around(const Eigen::Matrix<double, N, 1>& c, double r) {
  nhdyn::box<N> b;
  for (int i = 0; i < N; ++i) b(i) = outward_about(c(i), r);
  return b;
}
template <int N>
Eigen::Matrix<double, N, 1> sample(const nhdyn::box<N>& b, std::mt19937& g) {
  Eigen::Matrix<double, N, 1> x;
  for (int i = 0; i < N; ++i) x(i) = std::uniform_real_distribution<double>(b(i).lower(), b(i).upper())(g);
  return x;
}
template <int N>
double total_width(const nhdyn::vecN<interval, N>& r) {
  double w = 0;
  for (int i = 0; i < N; ++i) w += r(i).width();
  return w;
}

const V5 q0(0.1, -0.2, 0.7, 0.4, -0.9);
const V4 eta0(0.3, 0.5, 1.2, -0.7), etad0(0.2, -0.3, 1.0, 0.5);
}  // namespace

TEST_CASE("bounds: 10000 random states inside paper5 boxes give torques inside the enclosure") {
  const auto r = nhdyn::presets::paper5();
  const auto id = nhdyn::inverse_dynamics(r.chain, r.constraint);
  std::mt19937 g(42);
  struct sizes {
    double q, eta, etad;
    int split;
  };
  for (const sizes s : {sizes{1e-3, 1e-3, 1e-3, 0}, sizes{0.05, 0.1, 0.2, 0}, sizes{0.2, 0.3, 0.5, 3},
                        sizes{0.5, 0.5, 1.0, 6}}) {
    const auto Q = around<5>(q0, s.q);
    const auto H = around<4>(eta0, s.eta), HD = around<4>(etad0, s.etad);
    const auto T = nhdyn::torque_bounds(r.chain, r.constraint, Q, H, HD, s.split);
    int outside = 0;
    for (int k = 0; k < 10000; ++k) {
      const V4 t = id(sample<5>(Q, g), sample<4>(H, g), sample<4>(HD, g));
      for (int i = 0; i < 4; ++i) outside += !contains(T(i), t(i));
    }
    INFO("box radii " << s.q << ", " << s.eta << ", " << s.etad << ", split " << s.split << ": tau in " << T.transpose());
    CHECK(outside == 0);
    // The corners are also inside (the extreme points are where a loose sampler would miss).
    const V4 tc = id(V5(Q.unaryExpr([](const interval& x) { return x.lower(); })),
                     V4(H.unaryExpr([](const interval& x) { return x.upper(); })),
                     V4(HD.unaryExpr([](const interval& x) { return x.lower(); })));
    for (int i = 0; i < 4; ++i) CHECK(contains(T(i), tc(i)));
  }
}

TEST_CASE("bounds: 10000 random parameter and state points inside paper5's +-10 % boxes stay enclosed") {
  std::mt19937 g(7);
  // Every mass ±10 % and the paper's factorial ranges (d₃, a₄, a₅ ±10 %), about a small state box.
  nhdyn::presets::paper5_parameters<interval> P;
  for (auto& f : P.mass_factor) f = nhdyn::outward(0.9, 1.1);
  P.d3_factor = P.a4_factor = P.a5_factor = nhdyn::outward(0.9, 1.1);
  for (double rs : {0.0, 0.05}) {
    const auto Q = around<5>(q0, rs);
    const auto H = around<4>(eta0, rs), HD = around<4>(etad0, rs);
    const auto T = nhdyn::paper5_torque_bounds(P, Q, H, HD, 2);
    int outside = 0;
    for (int k = 0; k < 10000; ++k) {
      std::uniform_real_distribution<double> u(0.9, 1.1);
      nhdyn::presets::paper5_parameters<double> p{{u(g), u(g), u(g), u(g), u(g)}, u(g), u(g), u(g)};
      const auto rr = nhdyn::presets::paper5<double>(p);
      const V4 t = nhdyn::inverse_dynamics(rr.chain, rr.constraint)(sample<5>(Q, g), sample<4>(H, g), sample<4>(HD, g));
      for (int i = 0; i < 4; ++i) outside += !contains(T(i), t(i));
    }
    INFO("state radius " << rs << ": tau in " << T.transpose());
    CHECK(outside == 0);
  }
}

TEST_CASE("bounds: the holonomic Puma 560 and eta_dot enclosures contain 10000 random points") {
  std::mt19937 g(3);
  const auto p = nhdyn::presets::puma560();
  using V6 = Eigen::Matrix<double, 6, 1>;
  const V6 q(0.3, -0.8, 1.1, 0.2, -0.5, 0.9), qd(0.5, -0.3, 0.8, -1.0, 0.4, 0.7), qdd(-0.4, 0.9, 0.3, 0.6, -0.2, 1.1);
  const auto Q = around<6>(q, 0.1), QD = around<6>(qd, 0.2), QDD = around<6>(qdd, 0.2);
  const auto T = nhdyn::torque_bounds(p, Q, QD, QDD, 4);
  const auto id = nhdyn::rne(p);
  int outside = 0;
  for (int k = 0; k < 10000; ++k) {
    const V6 t = id(sample<6>(Q, g), sample<6>(QD, g), sample<6>(QDD, g));
    for (int i = 0; i < 6; ++i) outside += !contains(T(i), t(i));
  }
  CHECK(outside == 0);
  // η̇ over a (q, η, τ) box of paper5.
  const auto r = nhdyn::presets::paper5();
  const V4 tau0 = nhdyn::inverse_dynamics(r.chain, r.constraint)(q0, eta0, etad0);
  const auto Qn = around<5>(q0, 0.02);
  const auto H = around<4>(eta0, 0.05), TAU = around<4>(tau0, 0.05);
  const auto ED = nhdyn::eta_dot_bounds(r.chain, r.constraint, Qn, H, TAU, 3);
  const auto fd = nhdyn::nh_forward_dynamics(r.chain, r.constraint);
  outside = 0;
  for (int k = 0; k < 10000; ++k) {
    const V4 e = fd(sample<5>(Qn, g), sample<4>(H, g), sample<4>(TAU, g));
    for (int i = 0; i < 4; ++i) outside += !contains(ED(i), e(i));
  }
  INFO("eta_dot in " << ED.transpose());
  CHECK(outside == 0);
  for (int i = 0; i < 4; ++i) CHECK(contains(ED(i), etad0(i)));
}

TEST_CASE("bounds: bisection never widens and shrinks the enclosure about linearly") {
  const auto r = nhdyn::presets::paper5();
  const auto Q = around<5>(q0, 0.3);
  const auto H = around<4>(eta0, 0.3), HD = around<4>(etad0, 0.3);
  std::vector<double> w;
  for (int k = 0; k <= 8; k += 2) {
    const auto T = nhdyn::torque_bounds(r.chain, r.constraint, Q, H, HD, k);
    w.push_back(total_width<4>(T));
    INFO("split " << k << ": total width " << w.back());
  }
  for (std::size_t i = 1; i < w.size(); ++i) CHECK(w[i] <= w[i - 1]);
  CHECK(w.back() < 0.7 * w.front());
  // A point box gives a thin enclosure around the double value (measured: ≤ 1.2e-12
  // relative; every operation steps one ulp outward, so widths grow with the operation count).
  const auto P = nhdyn::torque_bounds(r.chain, r.constraint, around<5>(q0, 0), around<4>(eta0, 0), around<4>(etad0, 0));
  const V4 t = nhdyn::inverse_dynamics(r.chain, r.constraint)(q0, eta0, etad0);
  for (int i = 0; i < 4; ++i) {
    CHECK(contains(P(i), t(i)));
    CHECK(P(i).width() < 1e-11 * std::max(1.0, std::abs(t(i))));
  }
}

TEST_CASE("bounds: unbounded enclosures and malformed boxes are reported by name") {
  const auto r = nhdyn::presets::paper5();
  const auto Q = around<5>(q0, 0.1);
  const auto HD = around<4>(etad0, 0.1);
  nhdyn::box<4> huge = around<4>(eta0, 0.1);
  huge(1) = interval(-1e200, 1e200);  // ω² overflows
  CHECK_THROWS_AS(nhdyn::torque_bounds(r.chain, r.constraint, Q, huge, HD), nhdyn::numerical_error);
  CHECK_THROWS_WITH(nhdyn::torque_bounds(r.chain, r.constraint, Q, huge, HD), Catch::Contains("tau") && Catch::Contains("unbounded"));
  nhdyn::box<5> bad = Q;
  bad(3) = interval(1.0, 0.0);  // lo > hi: an empty interval
  CHECK_THROWS_WITH(nhdyn::torque_bounds(r.chain, r.constraint, bad, around<4>(eta0, 0.1), HD), Catch::Contains("q[3]"));
  nhdyn::box<5> nan = Q;
  nan(0) = interval(std::nan(""));
  CHECK_THROWS_AS(nhdyn::torque_bounds(r.chain, r.constraint, nan, around<4>(eta0, 0.1), HD), nhdyn::input_error);
  CHECK_THROWS_WITH(nhdyn::torque_bounds(r.chain, r.constraint, Q, around<4>(eta0, 0.1), HD, -1), Catch::Contains("split"));
  // η̇ over a τ box so large that M_η's enclosure … stays bounded, but η̇ over an exploding
  // τ is reported as unbounded η̇.
  nhdyn::box<4> tau_huge = nhdyn::box<4>::Constant(interval(-1e308, 1e308));
  CHECK_THROWS_WITH(nhdyn::eta_dot_bounds(r.chain, r.constraint, Q, around<4>(eta0, 0.1), tau_huge, 0),
                    Catch::Contains("eta_dot") && Catch::Contains("unbounded"));
}

TEST_CASE("bounds: printed bounds never narrow (exact check in 50 digits)") {
  std::mt19937_64 g(11);
  std::vector<double> xs{0.0, 0.1, -0.1, 0.5, 1.0, -1.0, 1e-300, 4.9e-324, 1.7976931348623157e308, 123456.789, 2.0 / 3.0};
  for (int k = 0; k < 20000; ++k) {
    const double m = std::uniform_real_distribution<double>(-1, 1)(g);
    const int e = std::uniform_int_distribution<int>(-300, 300)(g);
    xs.push_back(std::ldexp(m, e));
    xs.push_back(std::bit_cast<double>(g() & 0x7fefffffffffffffULL));  // any finite double ≥ 0
  }
  int narrowed = 0;
  for (double x : xs) {
    const nhdyn::mp50 lo(nhdyn::format_lower(x).c_str()), hi(nhdyn::format_upper(x).c_str()), xm(x);
    narrowed += !(lo <= xm) + !(hi >= xm);
    // and the widening is at most 2 ulps (one step, one decimal rounding)
    const double back_lo = std::strtod(nhdyn::format_lower(x).c_str(), nullptr);
    CHECK(back_lo >= nhdyn::detail::step_down(nhdyn::detail::step_down(x)));
  }
  CHECK(narrowed == 0);
  CHECK(nhdyn::format_lower(-INFINITY) == "-1e999");
  CHECK(nhdyn::format_upper(INFINITY) == "1e999");
}
