#pragma once
/// \file scalar/autodiff.hpp
/// Eigen's forward-mode `Eigen::AutoDiffScalar<DerType>` as an nhdyn scalar (DerType a
/// fixed-size vector such as Eigen::Matrix<double, 13, 1>, or Eigen::VectorXd). Eigen
/// already provides NumTraits and the math functions; nhdyn needs only scalar_traits.
/// Like for like (model and state both in the scalar, 13 seeds) it measured faster than
/// nhdyn's own `dual<T, K>` (scalar/dual.hpp; docs/performance.md, "Scalar types"); `dual`
/// is the faster route where the model stays in double and only the state is seeded, as
/// the linearizer does. AutoDiffScalar is here for users whose code already uses it.
///
///     using AD = Eigen::AutoDiffScalar<Eigen::Matrix<double, 4, 1>>;
///     AD x(0.3, 4, 0);   // value 0.3, derivative e_0
#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "traits.hpp"

namespace nhdyn {

template <class DerType>
struct scalar_traits<Eigen::AutoDiffScalar<DerType>> {
  using AD = Eigen::AutoDiffScalar<DerType>;
  static double value(const AD& x) { return value_of(x.value()); }
  static bool is_exact_zero(const AD& x) {
    bool z = x.value() == 0;
    for (Eigen::Index k = 0; k < x.derivatives().size(); ++k) z = z && x.derivatives()(k) == 0;
    return z;
  }
  static bool is_finite(const AD& x) {
    bool ok = std::isfinite(value_of(x.value()));
    for (Eigen::Index k = 0; k < x.derivatives().size(); ++k)
      ok = ok && std::isfinite(value_of(x.derivatives()(k)));
    return ok;
  }
};

}  // namespace nhdyn
