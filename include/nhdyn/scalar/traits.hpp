#pragma once
/// \file scalar/traits.hpp
/// What a number type must provide to run nhdyn's algorithms, and the one customisation
/// point through which the library looks at a generic scalar's value.
///
/// A scalar plugs in the way Eigen custom scalars do: arithmetic operators, `sin`/`cos`/
/// `sqrt` found by argument-dependent lookup (or in `std`), an `Eigen::NumTraits`
/// specialisation. nhdyn never branches on `a < b` of a generic scalar (an interval's
/// comparison is not a bool); it branches only on `scalar_traits<S>::value(x)`, a double
/// that says "roughly where this number is" (midpoint of an interval, real part of a dual).
#include <cmath>
#include <concepts>
#include <type_traits>

namespace nhdyn {

/// Customisation point: specialise for a new number type (see scalar/dual.hpp,
/// scalar/interval.hpp, scalar/multiprecision.hpp).
template <class S>
struct scalar_traits {
  /// A double that represents x for printing, diagnostics and branching.
  static double value(const S& x) { return static_cast<double>(x); }
  /// True only if x is exactly zero in every component (a dual whose derivative is
  /// non-zero is not zero: a massless link differentiated w.r.t. its mass is not skipped).
  static bool is_exact_zero(const S& x) { return x == S(0); }
  /// True if every component of x is finite.
  static bool is_finite(const S& x) {
    using std::isfinite;
    return isfinite(x);
  }
};

/// The double value of a scalar: the only way nhdyn looks at a generic scalar.
template <class S>
double value_of(const S& x) {
  return scalar_traits<S>::value(x);
}
template <class S>
bool is_exact_zero(const S& x) {
  return scalar_traits<S>::is_exact_zero(x);
}
template <class S>
bool is_finite_scalar(const S& x) {
  return scalar_traits<S>::is_finite(x);
}

namespace detail::scalar_math {
// sin, cos, sqrt as the algorithms call them: `using std::sin; sin(x)` — std's for the
// built-in types, the type's own (found by argument-dependent lookup) for every other.
using std::cos;
using std::sin;
using std::sqrt;
template <class S>
concept has_math = requires(const S& a) {
                     { sin(a) } -> std::convertible_to<S>;
                     { cos(a) } -> std::convertible_to<S>;
                     { sqrt(a) } -> std::convertible_to<S>;
                   };
}  // namespace detail::scalar_math

/// What a number type must provide: field arithmetic, construction from double, sin, cos
/// and sqrt (in std or by argument-dependent lookup), and the customisation point above
/// (its value, exact zero and finiteness). Integers are not scalars: the algorithms divide.
/// The model types (chain, link) and the state arguments of the algorithms require it.
template <class S>
concept scalar = std::copyable<S> && std::constructible_from<S, double> && !std::is_integral_v<S> &&
                 detail::scalar_math::has_math<S> &&
                 requires(S a, S b) {
                   { a + b } -> std::convertible_to<S>;
                   { a - b } -> std::convertible_to<S>;
                   { a * b } -> std::convertible_to<S>;
                   { a / b } -> std::convertible_to<S>;
                   { -a } -> std::convertible_to<S>;
                   { value_of(a) } -> std::convertible_to<double>;
                   { is_exact_zero(a) } -> std::convertible_to<bool>;
                   { is_finite_scalar(a) } -> std::convertible_to<bool>;
                 };

/// A scalar that encloses a set of values (an interval: scalar_traits<S>::is_enclosure), for
/// which an algorithm may choose a formulation that keeps the enclosure tight (e.g. a linear
/// solve preconditioned by the inverse of its midpoint matrix, constraints/wheeled_base.hpp).
template <class S>
concept enclosure_scalar = requires { requires scalar_traits<S>::is_enclosure; };

/// Whether kernels inline every call they make for this scalar (detail/attributes.hpp's
/// NHDYN_FLATTEN): the built-in floating-point types and SIMD packs (scalar/simd.hpp), whose
/// operations are a few instructions each; not duals, intervals or multiprecision numbers,
/// whose code flattening would multiply.
template <class S>
inline constexpr bool flatten_kernels = std::is_floating_point_v<S>;

/// The scalar of a computation that mixes a model scalar M with a state scalar X
/// (double model with dual state gives dual; interval model with double state gives
/// interval): the one the other converts to.
template <class M, class X>
struct promote {
  using type = std::conditional_t<std::is_same_v<M, X>, M,
                                  std::conditional_t<std::is_convertible_v<M, X>, X, M>>;
};
template <class M, class X>
using promote_t = typename promote<M, X>::type;

namespace detail {
/// Every argument's scalar is S (the evaluate forms: a reused result is in the model's scalar,
/// and inputs of another are not silently converted to it).
template <class S, class... X>
concept in_scalar = (std::is_same_v<typename X::Scalar, S> && ...);
}  // namespace detail

}  // namespace nhdyn
