#pragma once
/// \file scalar/simd.hpp
/// `simd_pack<W>`: W doubles that travel together through nhdyn's generic kernels, so that one
/// evaluation of the same code computes W states (structure of arrays). Arithmetic is lane by
/// lane on a fixed-size array (the compiler vectorises it: -O3 -march=native gives one AVX2 or
/// AVX-512 instruction per operation); sin, cos and sqrt go through xsimd's vectorised
/// functions (Debian's libxsimd-dev, header-only) when the target has a batch of W doubles,
/// and lane by lane through libm otherwise. `simd_width` is the target's native width with
/// xsimd (8 with AVX-512, 4 with AVX2, 2 with SSE2), 4 without it, or -DNHDYN_SIMD_WIDTH=W.
///
/// What it is for: evaluating many states of a computation that does not branch on the
/// values it computes — rne, and the batch entry points of analysis/batch.hpp. The
/// library looks at a scalar's value only through value_of (lane 0 here), is_exact_zero and
/// is_finite_scalar (every lane); a check made on value_of sees lane 0 alone, so the batch
/// entry points run every check that reads a state's values in double, state by state.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>

#if __has_include(<xsimd/xsimd.hpp>)
#include <xsimd/xsimd.hpp>
#define NHDYN_HAVE_XSIMD 1
#endif

#include "traits.hpp"

namespace nhdyn {

#if defined(NHDYN_SIMD_WIDTH)
/// The lanes of the batch entry points, as the build asks (-DNHDYN_SIMD_WIDTH=W).
inline constexpr int simd_width = NHDYN_SIMD_WIDTH;
#elif defined(NHDYN_HAVE_XSIMD)
/// The target's native number of doubles per SIMD register (xsimd's default architecture).
inline constexpr int simd_width = static_cast<int>(xsimd::batch<double>::size);
#else
inline constexpr int simd_width = 4;
#endif

template <int W>
struct simd_pack {
  static_assert(W >= 1 && W <= 16, "simd_pack: 1 to 16 lanes");
  static constexpr int lanes = W;
  /// Uninitialised by default, as a double is (Eigen's temporaries are not zeroed either).
  /// Aligned to the pack's size, at most to what Eigen's heap storage guarantees
  /// (EIGEN_MAX_ALIGN_BYTES: 16 with SSE2, 32 AVX, 64 AVX-512), so a vector of packs is never
  /// under-aligned.
  static constexpr std::size_t alignment = std::max<std::size_t>(
      alignof(double), std::min<std::size_t>(sizeof(double) * (W >= 8 ? 8 : W >= 4 ? 4 : W >= 2 ? 2 : 1),
                                             std::size_t(EIGEN_MAX_ALIGN_BYTES)));
  alignas(alignment) std::array<double, W> v;

  simd_pack() = default;
  simd_pack(double x) { v.fill(x); }  // NOLINT: a double is every lane (as a dual's value)
  static simd_pack load(const double* p) {
    simd_pack r;
    for (int k = 0; k < W; ++k) r.v[k] = p[k];
    return r;
  }
  double& operator[](int k) { return v[static_cast<std::size_t>(k)]; }
  const double& operator[](int k) const { return v[static_cast<std::size_t>(k)]; }

#define NHDYN_SIMD_OP(op)                                                           \
  simd_pack& operator op##=(const simd_pack& b) {                                   \
    for (int k = 0; k < W; ++k) v[k] op## = b.v[k];                                 \
    return *this;                                                                   \
  }                                                                                 \
  friend simd_pack operator op(simd_pack a, const simd_pack& b) { return a op## = b; }
  NHDYN_SIMD_OP(+)
  NHDYN_SIMD_OP(-)
  NHDYN_SIMD_OP(*)
  NHDYN_SIMD_OP(/)
#undef NHDYN_SIMD_OP
  friend simd_pack operator-(simd_pack a) {
    for (int k = 0; k < W; ++k) a.v[k] = -a.v[k];
    return a;
  }
  /// Every lane equal (what Eigen's exact comparisons and nhdyn's exact-zero tests mean).
  friend bool operator==(const simd_pack& a, const simd_pack& b) { return a.v == b.v; }
  friend bool operator!=(const simd_pack& a, const simd_pack& b) { return !(a == b); }

 public:
  // sin, cos, sqrt: xsimd's vectorised functions on a batch of W doubles where the target has
  // one, libm lane by lane otherwise.
#ifdef NHDYN_HAVE_XSIMD
#define NHDYN_SIMD_FN(fn)                                                          \
  friend simd_pack fn(const simd_pack& a) {                                        \
    simd_pack r;                                                                   \
    using B = xsimd::make_sized_batch_t<double, W>;                                \
    if constexpr (!std::is_void_v<B>) {                                            \
      xsimd::fn(B::load_unaligned(a.v.data())).store_unaligned(r.v.data());        \
    } else {                                                                       \
      for (int k = 0; k < W; ++k) r.v[k] = std::fn(a.v[k]);                        \
    }                                                                              \
    return r;                                                                      \
  }
#else
#define NHDYN_SIMD_FN(fn)                                                          \
  friend simd_pack fn(const simd_pack& a) {                                        \
    simd_pack r;                                                                   \
    for (int k = 0; k < W; ++k) r.v[k] = std::fn(a.v[k]);                          \
    return r;                                                                      \
  }
#endif
  NHDYN_SIMD_FN(sin)
  NHDYN_SIMD_FN(cos)
  NHDYN_SIMD_FN(sqrt)
#undef NHDYN_SIMD_FN
  friend simd_pack abs(simd_pack a) {
    for (int k = 0; k < W; ++k) a.v[k] = std::abs(a.v[k]);
    return a;
  }
};

template <int W>
inline constexpr bool flatten_kernels<simd_pack<W>> = true;

template <int W>
struct scalar_traits<simd_pack<W>> {
  /// Lane 0 (see the file comment: checks on values run per state in double).
  static double value(const simd_pack<W>& x) { return x.v[0]; }
  static bool is_exact_zero(const simd_pack<W>& x) {
    for (double a : x.v)
      if (a != 0) return false;
    return true;
  }
  static bool is_finite(const simd_pack<W>& x) {
    for (double a : x.v)
      if (!std::isfinite(a)) return false;
    return true;
  }
};

}  // namespace nhdyn

namespace Eigen {
template <int W>
struct NumTraits<nhdyn::simd_pack<W>> : NumTraits<double> {
  using Real = nhdyn::simd_pack<W>;
  using NonInteger = nhdyn::simd_pack<W>;
  using Nested = nhdyn::simd_pack<W>;
  using Literal = nhdyn::simd_pack<W>;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 0,
    ReadCost = 1,
    AddCost = 1,
    MulCost = 1
  };
  static inline Real epsilon() { return Real(NumTraits<double>::epsilon()); }
  static inline Real dummy_precision() { return Real(NumTraits<double>::dummy_precision()); }
  static inline Real highest() { return Real(NumTraits<double>::highest()); }
  static inline Real lowest() { return Real(NumTraits<double>::lowest()); }
  static inline int digits10() { return NumTraits<double>::digits10(); }
};
template <int W, typename BinaryOp>
struct ScalarBinaryOpTraits<nhdyn::simd_pack<W>, double, BinaryOp> {
  using ReturnType = nhdyn::simd_pack<W>;
};
template <int W, typename BinaryOp>
struct ScalarBinaryOpTraits<double, nhdyn::simd_pack<W>, BinaryOp> {
  using ReturnType = nhdyn::simd_pack<W>;
};
}  // namespace Eigen
