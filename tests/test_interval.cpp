// nhdyn::interval's own arithmetic and sin/cos against exact references: every operation's
// enclosure must contain the exact result (computed in 50-digit arithmetic, where the sum,
// difference and product of two doubles are exact and a quotient or a sine is correct to
// far beyond double), for points and boxes over many magnitudes, and stay narrow. The same
// checks run on nhdyn::boost_interval (Boost.Interval's own operations).
#include <catch2/catch.hpp>
#include <nhdyn/scalar/interval.hpp>
#include <nhdyn/scalar/multiprecision.hpp>
#include <random>

namespace {
using nhdyn::mp50;

template <class I>
bool encloses(const I& x, const mp50& exact) {
  return mp50(x.lower()) <= exact && exact <= mp50(x.upper());
}

/// A random double over many magnitudes and both signs (and exact zeros).
double any_double(std::mt19937_64& g) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> e(-60, 60), pick(0, 19);
  if (pick(g) == 0) return 0.0;
  return std::ldexp(u(g), e(g));
}
}  // namespace

TEMPLATE_TEST_CASE("interval: +, -, *, / enclose the exact result of every point of the operands", "[interval]",
                   nhdyn::interval, nhdyn::boost_interval) {
  using I = TestType;
  std::mt19937_64 g(42);
  std::uniform_real_distribution<double> t(0.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    double a0 = any_double(g), a1 = any_double(g), b0 = any_double(g), b1 = any_double(g);
    if (trial % 3 == 0) a1 = a0, b1 = b0;  // points
    const I a(std::min(a0, a1), std::max(a0, a1)), b(std::min(b0, b1), std::max(b0, b1));
    const I s = a + b, d = a - b, p = a * b;
    const I sc = a * b0, ps = b0 * a, as = a + b0, am = a - b0, ma = b0 - a;  // mixed with a double
    for (int k = 0; k < 8; ++k) {
      const double x = k == 0 ? a.lower() : k == 1 ? a.upper() : a.lower() + t(g) * (a.upper() - a.lower());
      const double y = k == 0 ? b.upper() : k == 1 ? b.lower() : b.lower() + t(g) * (b.upper() - b.lower());
      if (!(a.lower() <= x && x <= a.upper() && b.lower() <= y && y <= b.upper())) continue;
      const mp50 X(x), Y(y);
      REQUIRE(encloses(s, X + Y));
      REQUIRE(encloses(d, X - Y));
      REQUIRE(encloses(p, X * Y));
      REQUIRE(encloses(sc, X * mp50(b0)));
      REQUIRE(encloses(ps, X * mp50(b0)));
      REQUIRE(encloses(as, X + mp50(b0)));
      REQUIRE(encloses(am, X - mp50(b0)));
      REQUIRE(encloses(ma, mp50(b0) - X));
      if (b.lower() > 0 || b.upper() < 0) REQUIRE(encloses(a / b, X / Y));
      ++checked;
    }
    // A point operation is a few ulps wide at most (plus nhdyn's 2^-500 floor).
    if (a.lower() == a.upper() && b.lower() == b.upper()) {
      const double ref = a.lower() * b.lower();
      CHECK(p.upper() - p.lower() <= 4 * std::abs(ref) * 2.3e-16 + 1e-150);
    }
  }
  CHECK(checked > 20000);
  // Division by an interval containing 0 is unbounded, not a wrong finite answer.
  const I q = I(1.0, 2.0) / I(-1.0, 1.0);
  CHECK(!nhdyn::isfinite(q));
}

TEMPLATE_TEST_CASE("interval: sin and cos enclose the 50-digit values on every kind of interval", "[interval]",
                   nhdyn::interval, nhdyn::boost_interval) {
  using I = TestType;
  const double pi = 3.14159265358979323846;
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> t(0.0, 1.0);
  std::vector<std::pair<double, double>> boxes;
  // Thin boxes at and next to the extrema and zeros (jπ/2), wider ones across them, wide
  // ones, large arguments (within and beyond the kernel's 1e5), and random ones.
  for (int j = -8; j <= 8; ++j) {
    const double c = j * pi / 2;
    for (double w : {0.0, 1e-15, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 1.0}) {
      boxes.emplace_back(c - w, c + w);
      boxes.emplace_back(c, c + w);
      boxes.emplace_back(c - w, c);
      boxes.emplace_back(c + 2 * w, c + 3 * w);
    }
  }
  for (double c : {1e3, 12345.678, 99999.9, 1e5 + 1, 3e6}) {
    boxes.emplace_back(c, c);
    boxes.emplace_back(c, c + 1e-6);
    boxes.emplace_back(c, c + 2.0);
  }
  boxes.emplace_back(-10.0, 10.0);
  for (int k = 0; k < 400; ++k) {
    const double c = (t(g) - 0.5) * 40, w = std::ldexp(t(g), -static_cast<int>(t(g) * 40));
    boxes.emplace_back(c, c + w);
  }
  double widest_thin = 0;
  for (const auto& [lo, hi] : boxes) {
    const I x(lo, hi);
    const I s = sin(x), c = cos(x);
    REQUIRE(nhdyn::isfinite(s));
    REQUIRE(nhdyn::isfinite(c));
    for (int k = 0; k < 25; ++k) {
      const double p = k == 0 ? lo : k == 1 ? hi : lo + t(g) * (hi - lo);
      if (!(lo <= p && p <= hi)) continue;
      INFO("x = [" << lo << ", " << hi << "], point " << p);
      REQUIRE(encloses(s, sin(mp50(p))));
      REQUIRE(encloses(c, cos(mp50(p))));
    }
    if (lo == hi && std::abs(lo) < 1e5) widest_thin = std::max({widest_thin, s.width(), c.width()});
  }
  // nhdyn::interval: a point's sine and cosine are a few 1e-16 wide (tight as well as
  // sound). Boost reduces large arguments by an enclosure of π, so its width grows with |x|
  // (≈ 1e-10 at |x| = 1e5).
  if constexpr (std::is_same_v<I, nhdyn::interval>)
    CHECK(widest_thin < 3e-15);
  else
    CHECK(widest_thin < 1e-9);
}

TEST_CASE("interval: nhdyn::interval and Boost.Interval agree to a few ulps on an rne-sized expression") {
  const nhdyn::interval a(0.3, 0.30001), b(-1.2, -1.1999);
  const nhdyn::boost_interval A(0.3, 0.30001), B(-1.2, -1.1999);
  const nhdyn::interval r = sin(a) * b + cos(b) * a - a * a / (b * b + 1.0);
  const nhdyn::boost_interval R = sin(A) * B + cos(B) * A - A * A / (B * B + 1.0);
  CHECK(std::abs(r.lower() - R.lower()) < 1e-14);
  CHECK(std::abs(r.upper() - R.upper()) < 1e-14);
  // An empty interval stays empty (NaN bounds), reported as not finite.
  const nhdyn::interval e(2.0, 1.0);
  CHECK(!nhdyn::isfinite(e));
  CHECK(!nhdyn::isfinite(e * a + 1.0));
}

TEMPLATE_TEST_CASE("interval: comparisons are Boost's 'certainly': decided ones true or false, undecided ones throw",
                   "[interval]", nhdyn::interval, nhdyn::boost_interval) {
  using I = TestType;
  const I a(1.0, 2.0), b(3.0, 4.0), c(1.5, 3.5), p(2.0, 2.0);
  CHECK(a < b);
  CHECK_FALSE(b < a);
  CHECK(b > a);
  CHECK(a <= b);
  CHECK(b >= a);
  CHECK_FALSE(a == b);  // disjoint: certainly different
  CHECK(a != b);
  CHECK(p == I(2.0, 2.0));  // equal points: certainly equal
  CHECK_FALSE(p != I(2.0, 2.0));
  using boost::numeric::interval_lib::comparison_error;
  CHECK_THROWS_AS(a < c, comparison_error);  // overlapping: undecided
  CHECK_THROWS_AS(a == c, comparison_error);
  CHECK_THROWS_AS(a != c, comparison_error);
  CHECK_THROWS_AS(a == a, comparison_error);  // a non-degenerate interval against itself
}
