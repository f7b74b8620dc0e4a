#pragma once
/// \file scalar/dual.hpp
/// `dual<T, K>`: forward-mode automatic differentiation with K derivative components held
/// inline (no heap). x = a + Σ b_k ε_k with ε_j ε_k = 0: every operation carries exact
/// first derivatives along K seed directions. Nests (dual<dual<double,1>,1>) for second
/// derivatives, and plugs into Eigen and every nhdyn algorithm.
///
///     using D = nhdyn::dual<double, 1>;
///     D x = D::variable(0.3, 0);        // x = 0.3, dx/dx = 1
///     D y = sin(x) * x;                 // y.value(), y.derivative(0) = cos(.3)·.3 + sin(.3)
#include <Eigen/Core>
#include <array>
#include <bit>
#include <cstdint>
#include <cmath>
#include <ostream>

#include "traits.hpp"

namespace nhdyn {

template <class T, int K>
class dual {
 public:
  using value_type = T;
  static constexpr int size = K;

  constexpr dual() : a_(0), b_{} { b_.fill(T(0)); }
  constexpr dual(double v) : a_(v), b_{} { b_.fill(T(0)); }  // NOLINT: implicit, like a real
  template <class U>
    requires(!std::is_same_v<U, double> && std::is_convertible_v<U, T> && !std::is_same_v<U, dual>)
  constexpr dual(const U& v) : a_(v), b_{} {  // NOLINT
    b_.fill(T(0));
  }
  constexpr dual(const T& v, const std::array<T, K>& d) : a_(v), b_(d) {}

  /// The k-th seed variable: value v, derivative 1 in direction k.
  static dual variable(const T& v, int k) {
    dual x(v);
    x.b_[static_cast<std::size_t>(k)] = T(1);
    return x;
  }

  const T& value() const { return a_; }
  T& value() { return a_; }
  const T& derivative(int k) const { return b_[static_cast<std::size_t>(k)]; }
  T& derivative(int k) { return b_[static_cast<std::size_t>(k)]; }
  const std::array<T, K>& derivatives() const { return b_; }

  dual& operator+=(const dual& o) {
    a_ += o.a_;
    for (int k = 0; k < K; ++k) b_[k] += o.b_[k];
    return *this;
  }
  dual& operator-=(const dual& o) {
    a_ -= o.a_;
    for (int k = 0; k < K; ++k) b_[k] -= o.b_[k];
    return *this;
  }
  dual& operator*=(const dual& o) {
    for (int k = 0; k < K; ++k) b_[k] = b_[k] * o.a_ + a_ * o.b_[k];
    a_ *= o.a_;
    return *this;
  }
  dual& operator/=(const dual& o) {
    const T inv = T(1) / o.a_;
    a_ *= inv;
    for (int k = 0; k < K; ++k) b_[k] = (b_[k] - a_ * o.b_[k]) * inv;
    return *this;
  }
  // Binary operators write a fresh result (no aliasing, no zero fill first): the derivative
  // loops vectorise, which matters for K ≈ 10 (a full Jacobian in one pass).
  friend dual operator+(const dual& x, const dual& y) {
    dual r(uninitialized{});
    r.a_ = x.a_ + y.a_;
    for (int k = 0; k < K; ++k) r.b_[k] = x.b_[k] + y.b_[k];
    return r;
  }
  friend dual operator-(const dual& x, const dual& y) {
    dual r(uninitialized{});
    r.a_ = x.a_ - y.a_;
    for (int k = 0; k < K; ++k) r.b_[k] = x.b_[k] - y.b_[k];
    return r;
  }
  friend dual operator*(const dual& x, const dual& y) {
    dual r(uninitialized{});
    r.a_ = x.a_ * y.a_;
    for (int k = 0; k < K; ++k) r.b_[k] = x.b_[k] * y.a_ + x.a_ * y.b_[k];
    return r;
  }
  friend dual operator/(const dual& x, const dual& y) {
    dual r(uninitialized{});
    const T inv = T(1) / y.a_;
    r.a_ = x.a_ * inv;
    for (int k = 0; k < K; ++k) r.b_[k] = (x.b_[k] - r.a_ * y.b_[k]) * inv;
    return r;
  }
  // Mixed operations with a constant c (anything convertible to T that is not this dual:
  // a double model parameter, or the inner dual of a nested one). They cost K + 1
  // operations, not 2K + 1: the constant has no derivative part.
  template <class U>
    requires(!std::is_same_v<U, dual> && std::is_convertible_v<U, T>)
  friend dual operator*(const dual& x, const U& c) {
    dual r(uninitialized{});
    const T cc(c);
    r.a_ = x.a_ * cc;
    for (int k = 0; k < K; ++k) r.b_[k] = x.b_[k] * cc;
    return r;
  }
  template <class U>
    requires(!std::is_same_v<U, dual> && std::is_convertible_v<U, T>)
  friend dual operator*(const U& c, const dual& x) {
    return x * c;
  }
  template <class U>
    requires(!std::is_same_v<U, dual> && std::is_convertible_v<U, T>)
  friend dual operator/(const dual& x, const U& c) {
    dual r(uninitialized{});
    const T inv = T(1) / T(c);
    r.a_ = x.a_ * inv;
    for (int k = 0; k < K; ++k) r.b_[k] = x.b_[k] * inv;
    return r;
  }
  template <class U>
    requires(!std::is_same_v<U, dual> && std::is_convertible_v<U, T>)
  friend dual operator+(const dual& x, const U& c) {
    dual r = x;
    r.a_ += T(c);
    return r;
  }
  template <class U>
    requires(!std::is_same_v<U, dual> && std::is_convertible_v<U, T>)
  friend dual operator+(const U& c, const dual& x) {
    return x + c;
  }
  template <class U>
    requires(!std::is_same_v<U, dual> && std::is_convertible_v<U, T>)
  friend dual operator-(const dual& x, const U& c) {
    dual r = x;
    r.a_ -= T(c);
    return r;
  }
  template <class U>
    requires(!std::is_same_v<U, dual> && std::is_convertible_v<U, T>)
  friend dual operator-(const U& c, const dual& x) {
    dual r(uninitialized{});
    r.a_ = T(c) - x.a_;
    for (int k = 0; k < K; ++k) r.b_[k] = -x.b_[k];
    return r;
  }
  friend dual operator-(dual x) {
    x.a_ = -x.a_;
    for (auto& d : x.b_) d = -d;
    return x;
  }
  friend dual operator+(const dual& x) { return x; }

  // Comparisons look at values only (used by Eigen internals; nhdyn itself never branches
  // on them).
  friend bool operator==(const dual& x, const dual& y) { return x.a_ == y.a_; }
  friend bool operator!=(const dual& x, const dual& y) { return x.a_ != y.a_; }
  friend bool operator<(const dual& x, const dual& y) { return x.a_ < y.a_; }
  friend bool operator>(const dual& x, const dual& y) { return x.a_ > y.a_; }
  friend bool operator<=(const dual& x, const dual& y) { return x.a_ <= y.a_; }
  friend bool operator>=(const dual& x, const dual& y) { return x.a_ >= y.a_; }

  /// f(x) with f(a) = fa and f'(a) = dfa.
  friend dual chain_rule(const dual& x, const T& fa, const T& dfa) {
    dual r(uninitialized{});
    r.a_ = fa;
    for (int k = 0; k < K; ++k) r.b_[k] = dfa * x.b_[k];
    return r;
  }
  friend dual sin(const dual& x) {
    using std::cos;
    using std::sin;
    return chain_rule(x, sin(x.a_), cos(x.a_));
  }
  friend dual cos(const dual& x) {
    using std::cos;
    using std::sin;
    return chain_rule(x, cos(x.a_), -sin(x.a_));
  }
  friend dual tan(const dual& x) {
    using std::tan;
    const T t = tan(x.a_);
    return chain_rule(x, t, T(1) + t * t);
  }
  friend dual sqrt(const dual& x) {
    using std::sqrt;
    const T s = sqrt(x.a_);
    return chain_rule(x, s, T(0.5) / s);
  }
  friend dual exp(const dual& x) {
    using std::exp;
    const T e = exp(x.a_);
    return chain_rule(x, e, e);
  }
  friend dual log(const dual& x) {
    using std::log;
    return chain_rule(x, log(x.a_), T(1) / x.a_);
  }
  friend dual abs(const dual& x) {
    using std::abs;
    return value_of(x.a_) < 0 ? -x : x;
  }
  friend dual atan(const dual& x) { return chain_rule(x, atan_(x.a_), T(1) / (T(1) + x.a_ * x.a_)); }
  friend dual atan2(const dual& y, const dual& x) {
    using std::atan2;
    const T r2 = x.a_ * x.a_ + y.a_ * y.a_;
    dual r;
    r.a_ = atan2(y.a_, x.a_);
    for (int k = 0; k < K; ++k) r.b_[k] = (x.a_ * y.b_[k] - y.a_ * x.b_[k]) / r2;
    return r;
  }
  friend dual pow(const dual& x, double p) {
    using std::pow;
    return chain_rule(x, pow(x.a_, T(p)), T(p) * pow(x.a_, T(p - 1)));
  }
  friend bool isfinite(const dual& x) {
    if constexpr (std::is_same_v<T, double>) {
      // An IEEE double is finite unless its exponent bits are all ones: one branch-free,
      // vectorisable pass over the K + 1 numbers.
      constexpr std::uint64_t e = 0x7ff0000000000000ULL;
      bool bad = (std::bit_cast<std::uint64_t>(x.a_) & e) == e;
      for (int k = 0; k < K; ++k) bad |= (std::bit_cast<std::uint64_t>(x.b_[k]) & e) == e;
      return !bad;
    } else {
      bool ok = is_finite_scalar(x.a_);
      for (const auto& d : x.b_) ok = ok && is_finite_scalar(d);
      return ok;
    }
  }
  friend std::ostream& operator<<(std::ostream& os, const dual& x) {
    os << x.a_ << " [";
    for (int k = 0; k < K; ++k) os << (k ? ", " : "") << x.b_[k];
    return os << "]";
  }

 private:
  struct uninitialized {};
  explicit dual(uninitialized) {}
  static T atan_(const T& v) {
    using std::atan;
    return atan(v);
  }
  T a_;
  std::array<T, K> b_;
};

template <class T, int K>
struct scalar_traits<dual<T, K>> {
  static double value(const dual<T, K>& x) { return value_of(x.value()); }
  static bool is_exact_zero(const dual<T, K>& x) {
    bool z = nhdyn::is_exact_zero(x.value());
    for (int k = 0; k < K; ++k) z = z && nhdyn::is_exact_zero(x.derivative(k));
    return z;
  }
  static bool is_finite(const dual<T, K>& x) { return isfinite(x); }
};

/// The value part of a dual, or the argument itself for anything else.
template <class X>
const X& real_part(const X& x) {
  return x;
}
template <class T, int K>
const T& real_part(const dual<T, K>& x) {
  return x.value();
}

}  // namespace nhdyn

namespace Eigen {
template <class T, int K>
struct NumTraits<nhdyn::dual<T, K>> : NumTraits<T> {
  using Real = nhdyn::dual<T, K>;
  using NonInteger = nhdyn::dual<T, K>;
  using Nested = nhdyn::dual<T, K>;
  using Literal = nhdyn::dual<T, K>;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = (K + 1) * NumTraits<T>::ReadCost,
    AddCost = (K + 1) * NumTraits<T>::AddCost,
    MulCost = (2 * K + 1) * NumTraits<T>::MulCost
  };
  static inline Real epsilon() { return Real(NumTraits<T>::epsilon()); }
  static inline Real dummy_precision() { return Real(NumTraits<T>::dummy_precision()); }
  static inline Real highest() { return Real(NumTraits<T>::highest()); }
  static inline Real lowest() { return Real(NumTraits<T>::lowest()); }
  static inline int digits10() { return NumTraits<T>::digits10(); }
};
template <class T, int K, typename BinaryOp>
struct ScalarBinaryOpTraits<nhdyn::dual<T, K>, T, BinaryOp> {
  using ReturnType = nhdyn::dual<T, K>;
};
template <class T, int K, typename BinaryOp>
struct ScalarBinaryOpTraits<T, nhdyn::dual<T, K>, BinaryOp> {
  using ReturnType = nhdyn::dual<T, K>;
};
}  // namespace Eigen
