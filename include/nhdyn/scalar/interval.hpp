#pragma once
/// \file scalar/interval.hpp
/// Interval arithmetic with outward rounding that does not depend on the floating-point
/// rounding mode or on compiler flags, so every nhdyn algorithm gives a guaranteed enclosure
/// of the exact result over a box of inputs. Two scalar types:
///
/// - `nhdyn::interval` — nhdyn's own, for speed: +, −, ×, ÷, sin and cos written here
///   (branch-light, inlined), every other function (tan, exp, log, atan, sqrt, pow, the
///   "certainly" comparisons, and sin/cos of wide arguments) through Boost.Interval.
/// - `nhdyn::boost_interval` — Boost.Interval itself (`boost::numeric::interval` with the
///   rounding policy below), every operation Boost's. The two give the same kind of
///   guarantee; tests/test_scalar_types.cpp runs the typed identities over both, and
///   tests/test_bounds.cpp checks that both enclose.
///
/// Rounding. Each operation is computed in the default round-to-nearest mode, whose error is
/// at most half an ulp (IEEE 754), and its result is moved outward past the next double:
/// `nhdyn::interval` by pred(x) = x − (φ|x| + η), succ(x) = x + (φ|x| + η) with
/// φ = 2⁻⁵³(1 + 2⁻⁵²), η = 2⁻⁵⁰⁰ (Rump, Zimmermann, Boldo & Melquiond, "Computing
/// predecessor and successor in rounding to nearest", BIT 49, 2009: the result is at least
/// one ulp beyond x, with or without a fused multiply–add), `boost_interval` by stepping
/// one ulp through the bit pattern. sin and cos of `nhdyn::interval`: on a piece where both
/// are monotonic (|x| ≤ 1e5, the piece decided with a 1e-9 safety margin), the endpoint
/// values of scalar/sincos.hpp's kernel (fdlibm's polynomials, error < 1 ulp ≤ 2.3e-16) widened
/// by 4.5e-16 and then outward, clamped to [−1, 1]; otherwise Boost's. Library functions of
/// `boost_interval` use the C library (glibc: ≤ 1 ulp) and move 2 ulps outward.
///
/// Empty and unbounded. An interval with a NaN bound is empty (Boost's `checking_base`); an
/// infinite bound is unbounded. Both are "not finite": every algorithm's result check and
/// the analysis/bounds.hpp functions say so by name. Division by an interval that contains
/// 0 gives [−∞, +∞].
///
/// nhdyn never compares intervals (Boost's `<` is "certainly less" and throws
/// `interval_lib::comparison_error` when undecided, so a stray comparison shows up as an
/// exception, not as a silently wrong branch); algorithms branch on `value_of(x)`, the midpoint.
///
///     using I = nhdyn::interval;
///     I m = nhdyn::outward(0.9, 1.1);                  // a factor ±10 %, rounded outward
///     auto tau = nhdyn::rne(chain.cast<I>())(q, qd, qdd);  // encloses τ for every m in it
#include <bit>
#include <Eigen/Core>
#include <boost/numeric/interval.hpp>
#include <utility>

#include "sincos.hpp"
#include <cmath>
#include <cstdint>
#include <limits>
#include <ostream>

#include "traits.hpp"

namespace nhdyn {

namespace detail {

/// The next double towards −∞ (r itself if r is ±∞ or NaN: an infinite bound stays so).
inline double step_down(double r) {
  if (!std::isfinite(r)) return r;
  if (r == 0.0) return -std::numeric_limits<double>::denorm_min();
  const auto b = std::bit_cast<std::uint64_t>(r);
  return std::bit_cast<double>(r > 0 ? b - 1 : b + 1);
}
/// The next double towards +∞.
inline double step_up(double r) { return -step_down(-r); }

/// Boost.Interval rounding policy: round-to-nearest, then one ulp outward (see file comment).
struct outward_rounding {
  using T = double;
  using unprotected_rounding = outward_rounding;
  using rounding_mode = int;
  static void get_rounding_mode(rounding_mode&) {}
  static void set_rounding_mode(rounding_mode) {}
  static void upward() {}
  static void downward() {}
  static void to_nearest() {}
  static const T& to_int(const T& x) { return x; }
  static const T& force_rounding(const T& x) { return x; }
  void init() {}

  template <class U>
  static T conv_down(const U& v) {
    const T r = static_cast<T>(v);
    if constexpr (std::is_integral_v<U>) {
      return static_cast<U>(r) == v ? r : step_down(r);
    } else {
      return static_cast<U>(r) <= v ? r : step_down(r);
    }
  }
  template <class U>
  static T conv_up(const U& v) {
    const T r = static_cast<T>(v);
    if constexpr (std::is_integral_v<U>) {
      return static_cast<U>(r) == v ? r : step_up(r);
    } else {
      return static_cast<U>(r) >= v ? r : step_up(r);
    }
  }
  static T add_down(T x, T y) { return step_down(x + y); }
  static T add_up(T x, T y) { return step_up(x + y); }
  static T sub_down(T x, T y) { return step_down(x - y); }
  static T sub_up(T x, T y) { return step_up(x - y); }
  static T mul_down(T x, T y) { return step_down(x * y); }
  static T mul_up(T x, T y) { return step_up(x * y); }
  static T div_down(T x, T y) { return step_down(x / y); }
  static T div_up(T x, T y) { return step_up(x / y); }
  static T median(T x, T y) { return 0.5 * x + 0.5 * y; }
  static T sqrt_down(T x) { return step_down(std::sqrt(x)); }
  static T sqrt_up(T x) { return step_up(std::sqrt(x)); }
  static T int_down(T x) { return std::floor(x); }
  static T int_up(T x) { return std::ceil(x); }

  static T down2(T r) { return step_down(step_down(r)); }
  static T up2(T r) { return step_up(step_up(r)); }
  static T sin_down(T x) { return std::max(-1.0, down2(std::sin(x))); }
  static T sin_up(T x) { return std::min(1.0, up2(std::sin(x))); }
  static T cos_down(T x) { return std::max(-1.0, down2(std::cos(x))); }
  static T cos_up(T x) { return std::min(1.0, up2(std::cos(x))); }
  static T tan_down(T x) { return down2(std::tan(x)); }
  static T tan_up(T x) { return up2(std::tan(x)); }
  static T exp_down(T x) { return std::max(0.0, down2(std::exp(x))); }
  static T exp_up(T x) { return up2(std::exp(x)); }
  static T log_down(T x) { return down2(std::log(x)); }
  static T log_up(T x) { return up2(std::log(x)); }
  static T atan_down(T x) { return down2(std::atan(x)); }
  static T atan_up(T x) { return up2(std::atan(x)); }
};

}  // namespace detail

/// The Boost.Interval type (outward rounding, checking_base) behind `boost_interval`.
using boost_interval_base = boost::numeric::interval<
    double, boost::numeric::interval_lib::policies<detail::outward_rounding,
                                                   boost::numeric::interval_lib::checking_base<double>>>;

/// Boost.Interval as an nhdyn scalar: a thin value wrapper around `boost_interval_base`. It
/// exists because Boost's interval has an unconstrained converting constructor from any
/// type, which makes Eigen take every matrix for a scalar (`Matrix * Matrix` becomes
/// ambiguous); the wrapper converts only from double and from boost_interval_base, and
/// forwards all arithmetic and functions to Boost.
class boost_interval {
 public:
  boost_interval() : x_(0.0) {}
  boost_interval(double v) : x_(v) {}  // NOLINT: a point interval, implicit like a real
  boost_interval(double lo, double hi) : x_(lo, hi) {}
  explicit boost_interval(const boost_interval_base& b) : x_(b) {}

  double lower() const { return x_.lower(); }
  double upper() const { return x_.upper(); }
  double width() const { return x_.upper() - x_.lower(); }
  const boost_interval_base& boost() const { return x_; }

  boost_interval& operator+=(const boost_interval& o) { x_ += o.x_; return *this; }
  boost_interval& operator-=(const boost_interval& o) { x_ -= o.x_; return *this; }
  boost_interval& operator*=(const boost_interval& o) { x_ *= o.x_; return *this; }
  boost_interval& operator/=(const boost_interval& o) { x_ /= o.x_; return *this; }
  friend boost_interval operator+(const boost_interval& a, const boost_interval& b) { return boost_interval(a.x_ + b.x_); }
  friend boost_interval operator-(const boost_interval& a, const boost_interval& b) { return boost_interval(a.x_ - b.x_); }
  friend boost_interval operator*(const boost_interval& a, const boost_interval& b) { return boost_interval(a.x_ * b.x_); }
  friend boost_interval operator/(const boost_interval& a, const boost_interval& b) { return boost_interval(a.x_ / b.x_); }
  friend boost_interval operator-(const boost_interval& a) { return boost_interval(-a.x_); }
  friend boost_interval operator+(const boost_interval& a) { return a; }

  // Boost's "certainly" comparisons: true or false when decided, else they throw
  // boost::numeric::interval_lib::comparison_error. nhdyn's algorithms never call them.
  friend bool operator<(const boost_interval& a, const boost_interval& b) { return a.x_ < b.x_; }
  friend bool operator>(const boost_interval& a, const boost_interval& b) { return a.x_ > b.x_; }
  friend bool operator<=(const boost_interval& a, const boost_interval& b) { return a.x_ <= b.x_; }
  friend bool operator>=(const boost_interval& a, const boost_interval& b) { return a.x_ >= b.x_; }
  // == and != call Boost's member operators by name: C++20's reversed candidates make
  // `a.x_ == b.x_` ambiguous in clang's eyes (-Wambiguous-reversed-operator); same function.
  friend bool operator==(const boost_interval& a, const boost_interval& b) { return a.x_.operator==(b.x_); }
  friend bool operator!=(const boost_interval& a, const boost_interval& b) { return a.x_.operator!=(b.x_); }

  friend boost_interval sin(const boost_interval& a) { return boost_interval(boost::numeric::sin(a.x_)); }
  friend boost_interval cos(const boost_interval& a) { return boost_interval(boost::numeric::cos(a.x_)); }
  friend boost_interval tan(const boost_interval& a) { return boost_interval(boost::numeric::tan(a.x_)); }
  friend boost_interval sqrt(const boost_interval& a) { return boost_interval(boost::numeric::sqrt(a.x_)); }
  friend boost_interval exp(const boost_interval& a) { return boost_interval(boost::numeric::exp(a.x_)); }
  friend boost_interval log(const boost_interval& a) { return boost_interval(boost::numeric::log(a.x_)); }
  friend boost_interval atan(const boost_interval& a) { return boost_interval(boost::numeric::atan(a.x_)); }
  friend boost_interval abs(const boost_interval& a) { return boost_interval(boost::numeric::abs(a.x_)); }
  friend boost_interval square(const boost_interval& a) { return boost_interval(boost::numeric::square(a.x_)); }
  friend boost_interval pow(const boost_interval& a, int p) { return boost_interval(boost::numeric::pow(a.x_, p)); }
  /// The smallest interval containing a and b.
  friend boost_interval hull(const boost_interval& a, const boost_interval& b) {
    return boost_interval(boost::numeric::hull(a.x_, b.x_));
  }
  /// True if x ∈ a.
  friend bool contains(const boost_interval& a, double x) { return a.lower() <= x && x <= a.upper(); }

 private:
  boost_interval_base x_;
};

namespace detail {
/// Below x by at least one ulp, for any x (Rump et al. 2009; see the file comment):
/// x − (φ|x| + η). Rump's η is the smallest subnormal; any larger η is as sound and only
/// widens more, and η = 2⁻⁵⁰⁰ (3e-151) keeps the bounds of near-zero quantities (a joint at
/// rest: [−η, η]) and their products normal numbers — subnormal arithmetic costs x86 about
/// 100 cycles per operation. Finite x; −∞ stays, +∞ gives NaN (reported as unbounded).
[[gnu::always_inline]] inline double pred(double x) {
  constexpr double phi = 0x1.0000000000001p-53, eta = 0x1p-500;
  return x - (std::abs(x) * phi + eta);
}
[[gnu::always_inline]] inline double succ(double x) {
  constexpr double phi = 0x1.0000000000001p-53, eta = 0x1p-500;
  return x + (std::abs(x) * phi + eta);
}
}  // namespace detail

/// nhdyn's interval (see the file comment): [lo, hi] as two doubles, arithmetic here,
/// library functions through Boost.Interval.
class interval {
 public:
  interval() : lo_(0.0), hi_(0.0) {}
  interval(double v) : lo_(v), hi_(v) {}  // NOLINT: a point interval, implicit like a real
  /// [lo, hi]; empty (NaN bounds) unless lo ≤ hi.
  interval(double lo, double hi) : lo_(lo), hi_(hi) {
    if (!(lo <= hi)) lo_ = hi_ = std::numeric_limits<double>::quiet_NaN();
  }
  explicit interval(const boost_interval_base& b) : lo_(b.lower()), hi_(b.upper()) {}
  explicit interval(const boost_interval& b) : interval(b.boost()) {}

  double lower() const { return lo_; }
  double upper() const { return hi_; }
  double width() const { return hi_ - lo_; }
  /// The same interval as Boost's type.
  boost_interval_base boost() const {
    return (lo_ != lo_) ? boost_interval_base::empty() : boost_interval_base(lo_, hi_, true);
  }

  interval& operator+=(const interval& o) { return *this = *this + o; }
  interval& operator-=(const interval& o) { return *this = *this - o; }
  interval& operator*=(const interval& o) { return *this = *this * o; }
  interval& operator/=(const interval& o) { return *this = *this / o; }

  [[gnu::always_inline]] friend interval operator+(const interval& a, const interval& b) {
    return raw(detail::pred(a.lo_ + b.lo_), detail::succ(a.hi_ + b.hi_));
  }
  [[gnu::always_inline]] friend interval operator-(const interval& a, const interval& b) {
    return raw(detail::pred(a.lo_ - b.hi_), detail::succ(a.hi_ - b.lo_));
  }
  [[gnu::always_inline]] friend interval operator*(const interval& a, const interval& b) {
    const double p1 = a.lo_ * b.lo_, p2 = a.lo_ * b.hi_, p3 = a.hi_ * b.lo_, p4 = a.hi_ * b.hi_;
    return raw(detail::pred(std::min(std::min(p1, p2), std::min(p3, p4))),
               detail::succ(std::max(std::max(p1, p2), std::max(p3, p4))));
  }
  [[gnu::always_inline]] friend interval operator/(const interval& a, const interval& b) {
    if (!(b.lo_ > 0.0 || b.hi_ < 0.0)) {  // 0 ∈ b (or b empty)
      const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
      return (b.lo_ != b.lo_ || a.lo_ != a.lo_) ? raw(nan, nan) : raw(-inf, inf);
    }
    const double p1 = a.lo_ / b.lo_, p2 = a.lo_ / b.hi_, p3 = a.hi_ / b.lo_, p4 = a.hi_ / b.hi_;
    return raw(detail::pred(std::min(std::min(p1, p2), std::min(p3, p4))),
               detail::succ(std::max(std::max(p1, p2), std::max(p3, p4))));
  }
  // Mixed with a double constant c (a model parameter): two products, not four.
  [[gnu::always_inline]] friend interval operator*(const interval& a, double c) {
    const double p1 = a.lo_ * c, p2 = a.hi_ * c;
    return raw(detail::pred(std::min(p1, p2)), detail::succ(std::max(p1, p2)));
  }
  [[gnu::always_inline]] friend interval operator*(double c, const interval& a) { return a * c; }
  [[gnu::always_inline]] friend interval operator+(const interval& a, double c) {
    return raw(detail::pred(a.lo_ + c), detail::succ(a.hi_ + c));
  }
  [[gnu::always_inline]] friend interval operator+(double c, const interval& a) { return a + c; }
  [[gnu::always_inline]] friend interval operator-(const interval& a, double c) {
    return raw(detail::pred(a.lo_ - c), detail::succ(a.hi_ - c));
  }
  [[gnu::always_inline]] friend interval operator-(double c, const interval& a) {
    return raw(detail::pred(c - a.hi_), detail::succ(c - a.lo_));
  }
  [[gnu::always_inline]] friend interval operator/(const interval& a, double c) { return a / interval(c); }
  [[gnu::always_inline]] friend interval operator-(const interval& a) { return raw(-a.hi_, -a.lo_); }
  [[gnu::always_inline]] friend interval operator+(const interval& a) { return a; }

  // Boost's "certainly" comparisons: true or false when decided, else they throw
  // boost::numeric::interval_lib::comparison_error. nhdyn's algorithms never call them.
  friend bool operator<(const interval& a, const interval& b) { return a.boost() < b.boost(); }
  friend bool operator>(const interval& a, const interval& b) { return a.boost() > b.boost(); }
  friend bool operator<=(const interval& a, const interval& b) { return a.boost() <= b.boost(); }
  friend bool operator>=(const interval& a, const interval& b) { return a.boost() >= b.boost(); }
  friend bool operator==(const interval& a, const interval& b) { return a.boost().operator==(b.boost()); }
  friend bool operator!=(const interval& a, const interval& b) { return a.boost().operator!=(b.boost()); }

  /// (sin a, cos a) together, from one evaluation of the kernel at each end (see the file
  /// comment for how they are enclosed).
  friend std::pair<interval, interval> sincos_pair(const interval& a) {
    std::pair<interval, interval> r;
    if (in_kernel_range(a)) {
      const auto fl = detail::sincos_kernel(a.lo_), fh = detail::sincos_kernel(a.hi_);
      // sin is monotonic between its extrema π/2 + jπ, cos between jπ.
      if (!monotonic_piece(a, 0.5, fl.s, fh.s, r.first)) r.first = interval(boost::numeric::sin(a.boost()));
      if (!monotonic_piece(a, 0.0, fl.c, fh.c, r.second)) r.second = interval(boost::numeric::cos(a.boost()));
      return r;
    }
    return {interval(boost::numeric::sin(a.boost())), interval(boost::numeric::cos(a.boost()))};
  }
  friend interval sin(const interval& a) { return sincos_pair(a).first; }
  friend interval cos(const interval& a) { return sincos_pair(a).second; }
  friend interval tan(const interval& a) { return interval(boost::numeric::tan(a.boost())); }
  friend interval sqrt(const interval& a) { return interval(boost::numeric::sqrt(a.boost())); }
  friend interval exp(const interval& a) { return interval(boost::numeric::exp(a.boost())); }
  friend interval log(const interval& a) { return interval(boost::numeric::log(a.boost())); }
  friend interval atan(const interval& a) { return interval(boost::numeric::atan(a.boost())); }
  friend interval abs(const interval& a) { return interval(boost::numeric::abs(a.boost())); }
  friend interval square(const interval& a) { return interval(boost::numeric::square(a.boost())); }
  friend interval pow(const interval& a, int p) { return interval(boost::numeric::pow(a.boost(), p)); }
  /// The smallest interval containing a and b.
  friend interval hull(const interval& a, const interval& b) {
    return interval(boost::numeric::hull(a.boost(), b.boost()));
  }
  /// True if x ∈ a.
  friend bool contains(const interval& a, double x) { return a.lo_ <= x && x <= a.hi_; }

 private:
  [[gnu::always_inline]] static interval raw(double lo, double hi) {
    interval r;
    r.lo_ = lo;
    r.hi_ = hi;
    return r;
  }
  static bool in_kernel_range(const interval& a) {
    return std::abs(a.lo_) <= 1e5 && std::abs(a.hi_) <= 1e5 && a.lo_ <= a.hi_;
  }
  /// f = sin (shift 1/2) or cos (shift 0) over a, given the kernel's f at both ends: when
  /// t = x/π − shift lies in one (j, j + 1) for all of a, 1e-9 clear of both ends (t is
  /// computed with an error below 1e-10 for |x| ≤ 1e5), f is monotonic on a. Returns false
  /// (use Boost) otherwise.
  static bool monotonic_piece(const interval& a, double shift, double vl, double vh, interval& r);

  double lo_, hi_;
};

/// [lo, hi] widened by one ulp each side: encloses the real numbers lo and hi stood for
/// before they were rounded to double (e.g. the decimal 0.1 read from text).
inline interval outward(double lo, double hi) {
  return interval(detail::step_down(lo), detail::step_up(hi));
}
/// [x − r, x + r]·(outward): a box side of half-width r about x.
inline interval outward_about(double x, double r) {
  return interval(detail::step_down(x - r), detail::step_up(x + r));
}
/// [x(1 − f), x(1 + f)] (outward): a relative variation of ±f (f = 0.1 for ±10 %).
inline interval relative(double x, double f) {
  const double a = x * (1 - f), b = x * (1 + f);
  return outward(std::min(a, b), std::max(a, b));
}

namespace detail {
template <class I>
struct interval_traits {
  /// The midpoint (NaN for an empty interval).
  static double value(const I& x) {
    return x.lower() != x.lower() ? std::numeric_limits<double>::quiet_NaN() : 0.5 * x.lower() + 0.5 * x.upper();
  }
  static bool is_exact_zero(const I& x) { return x.lower() == 0.0 && x.upper() == 0.0; }
  /// An interval encloses a set of values (scalar/traits.hpp, `enclosure_scalar`).
  static constexpr bool is_enclosure = true;
  /// Both bounds finite (an empty or unbounded enclosure is not).
  static bool is_finite(const I& x) {
    return std::isfinite(x.lower()) && std::isfinite(x.upper()) && x.lower() <= x.upper();
  }
};
}  // namespace detail

template <>
struct scalar_traits<interval> : detail::interval_traits<interval> {};
template <>
struct scalar_traits<boost_interval> : detail::interval_traits<boost_interval> {};

inline bool isfinite(const interval& x) { return scalar_traits<interval>::is_finite(x); }
inline bool isfinite(const boost_interval& x) { return scalar_traits<boost_interval>::is_finite(x); }

inline bool interval::monotonic_piece(const interval& a, double shift, double vl, double vh, interval& r) {
  constexpr double inv_pi = 0.31830988618379067154, margin = 1e-9;
  const double tl = a.lo_ * inv_pi - shift, th = a.hi_ * inv_pi - shift;
  const double jl = std::floor(tl), jh = std::floor(th);
  if (jl != jh || tl - jl < margin || jl + 1 - th < margin) return false;
  // On an even piece f decreases (sin over (π/2, 3π/2), cos over (0, π)); on an odd one it
  // increases.
  const bool decreasing = std::fmod(jl, 2.0) == 0.0;
  const double a0 = decreasing ? vh : vl, b0 = decreasing ? vl : vh;
  constexpr double err = 4.5e-16;  // ≥ twice the kernel's error bound (< 1 ulp ≤ 2.3e-16)
  r = raw(std::max(-1.0, detail::pred(a0 - err)), std::min(1.0, detail::succ(b0 + err)));
  return true;
}

}  // namespace nhdyn

namespace nhdyn {
/// Prints [lo, hi] (17 significant digits; for bounds that must not narrow when printed,
/// see analysis/bounds.hpp, format_lower and format_upper).
inline std::ostream& operator<<(std::ostream& os, const nhdyn::interval& x) {
  const auto p = os.precision(17);
  os << "[" << x.lower() << ", " << x.upper() << "]";
  os.precision(p);
  return os;
}
inline std::ostream& operator<<(std::ostream& os, const nhdyn::boost_interval& x) {
  return os << nhdyn::interval(x);
}
}  // namespace nhdyn

namespace Eigen {
namespace nhdyn_detail {
template <class I>
struct interval_num_traits : NumTraits<double> {
  using Real = I;
  using NonInteger = I;
  using Nested = I;
  using Literal = I;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 2,
    AddCost = 8,
    MulCost = 16
  };
  static inline Real epsilon() { return Real(NumTraits<double>::epsilon()); }
  static inline Real dummy_precision() { return Real(NumTraits<double>::dummy_precision()); }
  static inline Real highest() { return Real(NumTraits<double>::highest()); }
  static inline Real lowest() { return Real(NumTraits<double>::lowest()); }
  static inline int digits10() { return NumTraits<double>::digits10(); }
};
}  // namespace nhdyn_detail
template <>
struct NumTraits<nhdyn::interval> : nhdyn_detail::interval_num_traits<nhdyn::interval> {};
template <>
struct NumTraits<nhdyn::boost_interval> : nhdyn_detail::interval_num_traits<nhdyn::boost_interval> {};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<nhdyn::interval, double, BinaryOp> {
  using ReturnType = nhdyn::interval;
};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<double, nhdyn::interval, BinaryOp> {
  using ReturnType = nhdyn::interval;
};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<nhdyn::boost_interval, double, BinaryOp> {
  using ReturnType = nhdyn::boost_interval;
};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<double, nhdyn::boost_interval, BinaryOp> {
  using ReturnType = nhdyn::boost_interval;
};
}  // namespace Eigen
