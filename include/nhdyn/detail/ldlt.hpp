#pragma once
/// \file detail/ldlt.hpp
/// A scalar-generic LDLᵀ factorisation without pivoting, for symmetric positive-definite
/// matrices (joint-space and reduced inertias). It never branches on a generic scalar's
/// comparison, so it runs over intervals and duals; it checks pivots on their double
/// value and reports a (near-)singular matrix with a condition estimate.
#include <Eigen/Core>
#include <cmath>
#include <sstream>
#include <string>

#include "../errors.hpp"
#include "../scalar/traits.hpp"

namespace nhdyn {

template <class T, int N>
struct ldlt {
  Eigen::Matrix<T, N, N> L;  // unit lower triangle below the diagonal, D on it
  double min_pivot = 0, max_pivot = 0;

  /// Ratio of the largest to the smallest pivot: a cheap lower estimate of cond(M).
  double pivot_ratio() const { return min_pivot > 0 ? max_pivot / min_pivot : INFINITY; }

  template <class B>
  Eigen::Matrix<T, N, B::ColsAtCompileTime> solve(const Eigen::MatrixBase<B>& b) const {
    const int n = static_cast<int>(L.rows());
    Eigen::Matrix<T, N, B::ColsAtCompileTime> x = b.template cast<T>();
    for (int c = 0; c < x.cols(); ++c) {
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < i; ++j) x(i, c) -= L(i, j) * x(j, c);
      for (int i = 0; i < n; ++i) x(i, c) /= L(i, i);
      for (int i = n - 1; i >= 0; --i)
        for (int j = i + 1; j < n; ++j) x(i, c) -= L(j, i) * x(j, c);
    }
    return x;
  }
};

/// Factorises symmetric positive-definite M (only the lower triangle is read). Throws
/// numerical_error naming `what` if a pivot is not positive or the pivot ratio exceeds
/// max_ratio (default: 1/ε of double, where the solution has no correct digit left).
template <class T, int N>
ldlt<T, N> ldlt_factor(const Eigen::Matrix<T, N, N>& M, const char* what = "matrix",
                       double max_ratio = 1.0 / 2.220446049250313e-16) {
  const int n = static_cast<int>(M.rows());
  ldlt<T, N> f;
  f.L = M;
  double dmin = INFINITY, dmax = 0;
  for (int j = 0; j < n; ++j) {
    for (int k = 0; k < j; ++k) f.L(j, j) -= f.L(j, k) * f.L(j, k) * f.L(k, k);
    const double dj = value_of(f.L(j, j));
    if (!(dj > 0) || !std::isfinite(dj)) {
      std::ostringstream os;
      os << what << " is not positive definite (pivot " << j << " = " << dj << ")";
      throw numerical_error(os.str());
    }
    dmin = std::min(dmin, dj);
    dmax = std::max(dmax, dj);
    for (int i = j + 1; i < n; ++i) {
      for (int k = 0; k < j; ++k) f.L(i, j) -= f.L(i, k) * f.L(j, k) * f.L(k, k);
      f.L(i, j) /= f.L(j, j);
    }
  }
  f.min_pivot = dmin;
  f.max_pivot = dmax;
  if (dmax / dmin > max_ratio) {
    std::ostringstream os;
    os << what << " is numerically singular (pivot ratio " << dmax / dmin
       << " exceeds " << max_ratio << ")";
    throw numerical_error(os.str());
  }
  return f;
}

}  // namespace nhdyn
