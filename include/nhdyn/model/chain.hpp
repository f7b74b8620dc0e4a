#pragma once
/// \file model/chain.hpp
/// A serial chain: links, gravity, a name. Plain constant data, validated once when built.
/// `chain<S>` has its size at run time; `chain<S, N>` at compile time (N joints), which lets
/// every algorithm run allocation-free on the stack.
#include <Eigen/Core>
#include <bit>
#include <cstdint>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "../errors.hpp"
#include "../scalar/traits.hpp"
#include "link.hpp"

namespace nhdyn {

inline constexpr int dynamic = Eigen::Dynamic;

/// Vector of n joint values (size N at compile time, or dynamic).
template <class S, int N>
using vecN = Eigen::Matrix<S, N, 1>;
template <class S, int R, int C>
using matRC = Eigen::Matrix<S, R, C>;

namespace detail {
template <class S, int N>
struct link_storage {
  using type = std::array<link<S>, static_cast<std::size_t>(N)>;
};
template <class S>
struct link_storage<S, dynamic> {
  using type = std::vector<link<S>>;
};

inline std::string link_where(const std::string& chain_name, std::size_t i) {
  std::ostringstream os;
  os << "model '" << chain_name << "', link " << (i + 1);
  return os.str();
}

/// What is wrong with a joint's friction law, if anything: not finite, or not dissipative
/// (viscous < 0, coulomb_pos < 0 or coulomb_neg > 0).
inline std::optional<std::string> friction_problem(const joint_friction& f) {
  if (!std::isfinite(f.viscous) || !std::isfinite(f.coulomb_pos) || !std::isfinite(f.coulomb_neg))
    return "is not finite (NaN or Inf)";
  std::ostringstream os;
  if (f.viscous < 0) os << "viscous coefficient " << f.viscous << " is negative";
  else if (f.coulomb_pos < 0) os << "Coulomb force at positive speed " << f.coulomb_pos << " is negative";
  else if (f.coulomb_neg > 0) os << "Coulomb force at negative speed " << f.coulomb_neg << " is positive";
  else return std::nullopt;
  os << " (friction must oppose motion)";
  return os.str();
}

/// Throws model_error if link i is not physical. Checks on the double value of each
/// parameter (for intervals: the midpoint; enclosures are the caller's business).
template <class S>
void validate_link(const link<S>& L, const std::string& chain_name, std::size_t i,
                   bool triangle_inequality) {
  const auto where = [&](const char* field) {
    return link_where(chain_name, i) + ", field '" + field + "': ";
  };
  const auto finite = [&](const S& x, const char* field) {
    if (!is_finite_scalar(x)) throw model_error(where(field) + "is not finite (NaN or Inf)");
  };
  finite(L.alpha, "alpha");
  finite(L.a, "a");
  finite(L.theta, "theta");
  finite(L.d, "d");
  finite(L.mass, "mass");
  for (int r = 0; r < 3; ++r) {
    finite(L.com(r), "com");
    for (int c = 0; c < 3; ++c) finite(L.inertia(r, c), "inertia");
  }
  if (value_of(L.mass) < 0) {
    std::ostringstream os;
    os << where("mass") << "is negative (" << value_of(L.mass) << " kg)";
    throw model_error(os.str());
  }
  finite(L.armature, "armature");
  if (value_of(L.armature) < 0) {
    std::ostringstream os;
    os << where("armature") << "is negative (" << value_of(L.armature) << ")";
    throw model_error(os.str());
  }
  if (auto why = friction_problem(L.friction)) throw model_error(where("friction") + *why);
  Eigen::Matrix3d I;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) I(r, c) = value_of(L.inertia(r, c));
  const double scale = std::max(I.cwiseAbs().maxCoeff(), 1e-300);
  const double tol = 1e-9 * scale;
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > tol) {
    std::ostringstream os;
    os << where("inertia") << "is not symmetric (Ixy, Ixz, Iyz differ from Iyx, Izx, Izy)";
    throw model_error(os.str());
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (I + I.transpose()),
                                                    Eigen::EigenvaluesOnly);
  const Eigen::Vector3d e = es.eigenvalues();  // ascending
  if (e(0) < -tol) {
    std::ostringstream os;
    os << where("inertia") << "is not positive semi-definite (smallest principal moment "
       << e(0) << " kg·m²)";
    throw model_error(os.str());
  }
  if (triangle_inequality && e(0) + e(1) < e(2) - tol) {
    std::ostringstream os;
    os << where("inertia") << "violates the triangle inequality of principal moments ("
       << e(0) << " + " << e(1) << " < " << e(2)
       << " kg·m²): no rigid body has it (a published model that has it anyway may be loaded "
          "with validation.triangle_inequality = false)";
    throw model_error(os.str());
  }
}
}  // namespace detail

/// What chain validation enforces beyond finiteness, mass ≥ 0 and a symmetric positive
/// semi-definite inertia (always checked).
struct validation {
  /// Principal moments must satisfy I₁ + I₂ ≥ I₃ (every rigid body does). Some published
  /// models do not (Corke's Puma 560, links 1 and 3); turning this off loads them as published.
  bool triangle_inequality = true;
  /// The inertia about the centre of mass must be positive semi-definite. Trees only (a chain
  /// always checks it): a URDF loaded leniently turns it off after warning (io/urdf.hpp).
  bool positive_semidefinite = true;
};

/// A serial chain of N joints (N = nhdyn::dynamic for a run-time size), in the number type S
/// (any nhdyn::scalar: float, double, multiprecision, duals, intervals…).
template <scalar S, int N = dynamic>
class chain {
 public:
  using scalar_type = S;
  static constexpr int size_at_compile_time = N;
  using links_type = typename detail::link_storage<S, N>::type;

  chain() requires(N == dynamic) = default;

  /// Builds and validates a chain; throws model_error naming the link and field at fault.
  chain(links_type links, vec3<S> gravity, std::string name = "chain", validation v = {})
      : links_(std::move(links)), gravity_(std::move(gravity)), name_(std::move(name)), validation_(v) {
    if (links_.empty()) throw model_error("model '" + name_ + "': a chain needs at least one link");
    for (int r = 0; r < 3; ++r)
      if (!is_finite_scalar(gravity_(r)))
        throw model_error("model '" + name_ + "', field 'gravity': is not finite (NaN or Inf)");
    for (std::size_t i = 0; i < links_.size(); ++i) detail::validate_link(links_[i], name_, i, validation_.triangle_inequality);
  }

  int dof() const { return static_cast<int>(links_.size()); }
  const link<S>& operator[](int i) const { return links_[static_cast<std::size_t>(i)]; }
  const links_type& links() const { return links_; }
  const vec3<S>& gravity() const { return gravity_; }
  const std::string& name() const { return name_; }
  const validation& validation_policy() const { return validation_; }
  auto begin() const { return links_.begin(); }
  auto end() const { return links_.end(); }

  /// The same chain with its numbers converted to scalar U (e.g. double → interval).
  template <class U>
  chain<U, N> cast() const {
    typename chain<U, N>::links_type out{};
    if constexpr (N == dynamic) out.resize(links_.size());
    for (std::size_t i = 0; i < links_.size(); ++i) out[i] = links_[i].template cast<U>();
    return chain<U, N>(std::move(out), gravity_.template cast<U>(), name_, validation_);
  }

  /// The same chain with its size fixed at compile time; throws if it has not M links.
  template <int M>
  chain<S, M> fixed() const {
    if (dof() != M) {
      std::ostringstream os;
      os << "model '" << name_ << "': has " << dof() << " links, not the " << M << " asked for";
      throw model_error(os.str());
    }
    typename chain<S, M>::links_type out{};
    std::copy(links_.begin(), links_.end(), out.begin());
    return chain<S, M>(std::move(out), gravity_, name_, validation_);
  }

  /// The same chain with a run-time size.
  chain<S, dynamic> dynamic_size() const {
    return chain<S, dynamic>(std::vector<link<S>>(links_.begin(), links_.end()), gravity_, name_,
                             validation_);
  }

  /// The same chain with another gravity vector (e.g. zero).
  chain with_gravity(vec3<S> g) const { return chain(links_, std::move(g), name_, validation_); }

 private:
  links_type links_{};
  vec3<S> gravity_ = vec3<S>::Zero();
  std::string name_ = "chain";
  validation validation_{};
};

namespace detail {
[[noreturn, gnu::cold, gnu::noinline]] inline void throw_size(Eigen::Index has, int n, const char* what) {
  std::ostringstream os;
  os << what << " has " << has << " entries; the model needs " << n;
  throw input_error(os.str());
}
/// Throws input_error if v has not n entries.
template <class V>
inline void check_size(const V& v, int n, const char* what) {
  if (v.size() != n) [[unlikely]]
    throw_size(v.size(), n, what);
}
[[noreturn, gnu::cold, gnu::noinline]] inline void throw_not_finite(const char* what, Eigen::Index i, double x) {
  std::ostringstream os;
  os << what << "[" << i << "] is not finite (" << x << ")";
  throw input_error(os.str());
}
/// Whether v's entries begin…end−1 are all finite (false for NaN and ±Inf). For float and
/// double one pass without a branch per entry: an entry is not finite when its exponent bits
/// are all set, tested on the bits as an integer reduction that vectorises even on baseline
/// x86-64 (no floating-point arithmetic, so it is also right under -ffast-math).
template <class V>
inline bool finite_range(const V& v, Eigen::Index begin, Eigen::Index end) {
  using T = typename V::Scalar;
  if constexpr (std::is_same_v<T, double> || std::is_same_v<T, float>) {
    using U = std::conditional_t<std::is_same_v<T, double>, std::uint64_t, std::uint32_t>;
    constexpr U exp_mask = std::is_same_v<T, double> ? U(0x7ff0000000000000ULL) : U(0x7f800000U);
    // (bits & mask) + the exponent's lowest bit carries into the sign bit exactly when every
    // exponent bit is set (NaN, ±Inf): OR over the range, then test that bit
    constexpr U exp_one = exp_mask & ~(exp_mask << 1), top = ~(~U(0) >> 1);
    U any = 0;
#if defined(__clang__)
#pragma clang loop interleave_count(1)  // clang's 4 × 4 lanes leave a short q's entries to a scalar tail
#endif
    for (Eigen::Index i = begin; i < end; ++i) any |= U((std::bit_cast<U>(T(v(i))) & exp_mask) + exp_one);
    return (any & top) == 0;
  } else {
    for (Eigen::Index i = begin; i < end; ++i)
      if (!is_finite_scalar(v(i))) return false;
    return true;
  }
}
/// Throws input_error naming the first non-finite entry of v. For float and double the
/// common case is one pass without a branch per entry.
template <class V>
inline void check_finite(const V& v, const char* what) {
  using T = typename V::Scalar;
  if constexpr (std::is_same_v<T, double> || std::is_same_v<T, float>) {
    if (finite_range(v, 0, v.size())) [[likely]]
      return;
  }
  if constexpr (requires(const T& x) { x.value(); x.derivatives(); x.derivative(0); }) {
    // A dual input (nhdyn::dual): its values are checked here; its derivative parts are
    // seeds, and a non-finite one would reach every result, where the algorithms' result
    // checks report it. This keeps a linearisation's input check at one number per entry.
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (!is_finite_scalar(v(i).value())) [[unlikely]]
        throw_not_finite(what, i, value_of(v(i)));
    return;
  }
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!is_finite_scalar(v(i))) [[unlikely]]
      throw_not_finite(what, i, value_of(v(i)));
  if constexpr (std::is_same_v<T, double> || std::is_same_v<T, float>)  // finite_range saw one that
    throw input_error(std::string(what) + " has an entry that is not finite");  // std::isfinite cannot (-ffinite-math-only)
}
}  // namespace detail

}  // namespace nhdyn
