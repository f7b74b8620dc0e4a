#pragma once
/// \file scalar/sincos.hpp
/// sin and cos of doubles without a library call (used by the kernels and by
/// nhdyn::interval).
#include <cmath>
#include <cstdint>

namespace nhdyn::detail {

/// (sin x, cos x) of a double with |x| ≤ 1e5, branch-free (so a loop over it vectorises):
/// Cody–Waite reduction by π/2 (fdlibm's 33-bit split, exact for these |x|), then fdlibm's
/// __kernel_sin / __kernel_cos minimax polynomials on [−π/4, π/4] and the quadrant.
/// Within 1 ulp of glibc's sin/cos (max. abs. difference 1.1e-16, measured over 10⁶ points
/// per range up to 1e5 — see docs/performance.md); the callers fall back to std::sin/cos
/// beyond |x| = 1e5 and for NaN/Inf.
template <class T>
struct sin_cos {
  T s, c;
};
[[gnu::always_inline]] inline sin_cos<double> sincos_kernel(double x) {
  constexpr double invpio2 = 6.36619772367581382433e-01;
  constexpr double pio2_1 = 1.57079632673412561417e+00;   // π/2, first 33 bits
  constexpr double pio2_1t = 6.07710050650619224932e-11;  // π/2 − pio2_1
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  constexpr double shifter = 6755399441055744.0;  // 1.5·2⁵²: x + shifter − shifter rounds x
  const double k = (x * invpio2 + shifter) - shifter;  // nearest multiple of π/2
  const auto quadrant = static_cast<std::int64_t>(k);
  const double r = (x - k * pio2_1) - k * pio2_1t;  // r ∈ [−π/4, π/4]
  const double z = r * r;
  const double sr = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
  const double hz = 0.5 * z, w = 1.0 - hz;
  const double cr = w + (((1.0 - w) - hz) + z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6))))));
  const bool swap = (quadrant & 1) != 0;
  const double s0 = swap ? cr : sr, c0 = swap ? sr : cr;
  return {(quadrant & 2) ? -s0 : s0, ((quadrant + 1) & 2) ? -c0 : c0};
}
/// sin and cos of n doubles, each |x_i| ≤ 1e5 (sincos_kernel over an array).
inline void sincos_reduced(const double* x, double* s, double* c, int n) {
  for (int i = 0; i < n; ++i) {
    const auto r = sincos_kernel(x[i]);
    s[i] = r.s;
    c[i] = r.c;
  }
}

}  // namespace nhdyn::detail
