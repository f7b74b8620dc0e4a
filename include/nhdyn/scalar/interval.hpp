#pragma once
/// \file scalar/interval.hpp
/// `nhdyn::interval`: Boost.Interval over double with outward rounding that does not depend
/// on the floating-point rounding mode or on compiler flags, so every nhdyn algorithm gives a
/// guaranteed enclosure of the exact result over a box of inputs.
///
/// Rounding policy (`outward_rounding`): each operation is computed in the default
/// round-to-nearest mode, whose error is at most half an ulp (IEEE 754), and its result is
/// then moved one ulp outward (down for a lower bound, up for an upper one). This is sound
/// without `-frounding-math` and without switching the FPU mode (which compilers may reorder
/// around). sin/cos/tan/exp/log/atan/sqrt use the C library (glibc: ≤ 1 ulp for these) and
/// move 2 ulps outward; sin and cos are clamped to [−1, 1]. Range reduction of sin/cos is
/// Boost's (by an enclosure of 2π).
///
/// Checking policy: `checking_base` — a NaN bound makes the interval empty, which nhdyn
/// reports as "not finite". An unbounded enclosure (an infinite bound) is also "not finite":
/// every algorithm's result check and the analysis/bounds.hpp functions say so by name.
///
/// nhdyn never compares intervals (Boost's `<` is "certainly less" and throws
/// `interval_lib::comparison_error` when undecided, so a stray comparison shows up as an
/// exception, not as a silently wrong branch); algorithms branch on `value_of(x)`, the midpoint.
///
/// `nhdyn::interval` wraps `boost::numeric::interval<double, policies<outward_rounding,
/// checking_base>>` (see the class comment for why it wraps rather than aliases).
///
///     using I = nhdyn::interval;
///     I m = nhdyn::outward(0.9, 1.1);                  // a factor ±10 %, rounded outward
///     auto tau = nhdyn::rne(chain.cast<I>())(q, qd, qdd);  // encloses τ for every m in it
#include <bit>
#include <Eigen/Core>
#include <boost/numeric/interval.hpp>
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

/// The Boost.Interval type nhdyn's interval is built on (outward rounding, checking_base).
using boost_interval = boost::numeric::interval<
    double, boost::numeric::interval_lib::policies<detail::outward_rounding,
                                                   boost::numeric::interval_lib::checking_base<double>>>;

/// A guaranteed enclosure [lo, hi] of a real number (see the file comment): a thin value
/// wrapper around `boost_interval`. It exists because Boost's interval has an unconstrained
/// converting constructor from any type, which makes Eigen take every matrix for a scalar
/// (`Matrix * Matrix` becomes ambiguous); the wrapper converts only from double and from
/// boost_interval, and forwards all arithmetic and functions to Boost.
class interval {
 public:
  interval() : x_(0.0) {}
  interval(double v) : x_(v) {}  // NOLINT: a point interval, implicit like a real
  interval(double lo, double hi) : x_(lo, hi) {}
  explicit interval(const boost_interval& b) : x_(b) {}

  double lower() const { return x_.lower(); }
  double upper() const { return x_.upper(); }
  double width() const { return x_.upper() - x_.lower(); }
  const boost_interval& boost() const { return x_; }

  interval& operator+=(const interval& o) { x_ += o.x_; return *this; }
  interval& operator-=(const interval& o) { x_ -= o.x_; return *this; }
  interval& operator*=(const interval& o) { x_ *= o.x_; return *this; }
  interval& operator/=(const interval& o) { x_ /= o.x_; return *this; }
  friend interval operator+(const interval& a, const interval& b) { return interval(a.x_ + b.x_); }
  friend interval operator-(const interval& a, const interval& b) { return interval(a.x_ - b.x_); }
  friend interval operator*(const interval& a, const interval& b) { return interval(a.x_ * b.x_); }
  friend interval operator/(const interval& a, const interval& b) { return interval(a.x_ / b.x_); }
  friend interval operator-(const interval& a) { return interval(-a.x_); }
  friend interval operator+(const interval& a) { return a; }

  // Boost's "certainly" comparisons: true or false when decided, else they throw
  // boost::numeric::interval_lib::comparison_error. nhdyn's algorithms never call them.
  friend bool operator<(const interval& a, const interval& b) { return a.x_ < b.x_; }
  friend bool operator>(const interval& a, const interval& b) { return a.x_ > b.x_; }
  friend bool operator<=(const interval& a, const interval& b) { return a.x_ <= b.x_; }
  friend bool operator>=(const interval& a, const interval& b) { return a.x_ >= b.x_; }
  friend bool operator==(const interval& a, const interval& b) { return a.x_ == b.x_; }
  friend bool operator!=(const interval& a, const interval& b) { return a.x_ != b.x_; }

  friend interval sin(const interval& a) { return interval(boost::numeric::sin(a.x_)); }
  friend interval cos(const interval& a) { return interval(boost::numeric::cos(a.x_)); }
  friend interval tan(const interval& a) { return interval(boost::numeric::tan(a.x_)); }
  friend interval sqrt(const interval& a) { return interval(boost::numeric::sqrt(a.x_)); }
  friend interval exp(const interval& a) { return interval(boost::numeric::exp(a.x_)); }
  friend interval log(const interval& a) { return interval(boost::numeric::log(a.x_)); }
  friend interval atan(const interval& a) { return interval(boost::numeric::atan(a.x_)); }
  friend interval abs(const interval& a) { return interval(boost::numeric::abs(a.x_)); }
  friend interval square(const interval& a) { return interval(boost::numeric::square(a.x_)); }
  friend interval pow(const interval& a, int p) { return interval(boost::numeric::pow(a.x_, p)); }
  /// The smallest interval containing a and b.
  friend interval hull(const interval& a, const interval& b) {
    return interval(boost::numeric::hull(a.x_, b.x_));
  }
  /// True if x ∈ a.
  friend bool contains(const interval& a, double x) { return a.lower() <= x && x <= a.upper(); }

 private:
  boost_interval x_;
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

template <>
struct scalar_traits<interval> {
  /// The midpoint (NaN for an empty interval).
  static double value(const interval& x) {
    return boost::numeric::empty(x.boost()) ? std::numeric_limits<double>::quiet_NaN()
                                            : 0.5 * x.lower() + 0.5 * x.upper();
  }
  static bool is_exact_zero(const interval& x) { return x.lower() == 0.0 && x.upper() == 0.0; }
  /// Both bounds finite (an empty or unbounded enclosure is not).
  static bool is_finite(const interval& x) {
    return std::isfinite(x.lower()) && std::isfinite(x.upper()) && x.lower() <= x.upper();
  }
};

inline bool isfinite(const interval& x) { return scalar_traits<interval>::is_finite(x); }

}  // namespace nhdyn

namespace nhdyn {
/// Prints [lo, hi] (17 significant digits; for bounds that must not narrow when printed,
/// see analysis/bounds.hpp, print_outward).
inline std::ostream& operator<<(std::ostream& os, const nhdyn::interval& x) {
  const auto p = os.precision(17);
  os << "[" << x.lower() << ", " << x.upper() << "]";
  os.precision(p);
  return os;
}
}  // namespace nhdyn

namespace Eigen {
template <>
struct NumTraits<nhdyn::interval> : NumTraits<double> {
  using Real = nhdyn::interval;
  using NonInteger = nhdyn::interval;
  using Nested = nhdyn::interval;
  using Literal = nhdyn::interval;
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
template <typename BinaryOp>
struct ScalarBinaryOpTraits<nhdyn::interval, double, BinaryOp> {
  using ReturnType = nhdyn::interval;
};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<double, nhdyn::interval, BinaryOp> {
  using ReturnType = nhdyn::interval;
};
}  // namespace Eigen
