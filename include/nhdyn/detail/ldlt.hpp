#pragma once
/// \file detail/ldlt.hpp
/// A scalar-generic LDLᵀ factorisation without pivoting, for symmetric positive-definite
/// matrices (joint-space and reduced inertias). It never branches on a generic scalar's
/// comparison, so it runs over intervals and duals; it checks pivots on their double
/// value and reports a (near-)singular matrix, judged after diagonal scaling.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <type_traits>
#include <sstream>
#include <string>

#include "../errors.hpp"
#include "../scalar/traits.hpp"

namespace nhdyn {

template <class T, int N>
struct ldlt {
  Eigen::Matrix<T, N, N> L;  // unit lower triangle below the diagonal, D on it
  double min_pivot = 0, max_pivot = 0;
  /// The smallest pivot of the diagonally scaled matrix, d_j / M_jj ∈ (0, 1]: 1/it is a lower
  /// bound of the scaled condition number, which is what a solve loses digits to.
  double min_scaled_pivot = 1;

  /// Ratio of the largest to the smallest pivot: a cheap lower estimate of cond(M).
  double pivot_ratio() const { return min_pivot > 0 ? max_pivot / min_pivot : INFINITY; }

  template <class B>
  Eigen::Matrix<T, N, B::ColsAtCompileTime> solve(const Eigen::MatrixBase<B>& b) const {
    Eigen::Matrix<T, N, B::ColsAtCompileTime> x = b.template cast<T>();
    solve_in_place(x);
    return x;
  }
  /// x ← M⁻¹ x (each column), in x's storage: no allocation.
  template <class X>
  void solve_in_place(Eigen::MatrixBase<X>& x) const {
    const int n = static_cast<int>(L.rows());
    for (int c = 0; c < x.cols(); ++c) {
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < i; ++j) x(i, c) -= L(i, j) * x(j, c);
      for (int i = 0; i < n; ++i) x(i, c) /= L(i, i);
      for (int i = n - 1; i >= 0; --i)
        for (int j = i + 1; j < n; ++j) x(i, c) -= L(j, i) * x(j, c);
    }
  }
};

/// 1/ε of T's precision (for float 1.7e7, double 4.5e15, a 50-digit type 1e50; for types
/// without numeric_limits — duals, intervals — that of double): the pivot ratio past which a
/// solve in T has no correct digit left.
template <class T>
double default_max_pivot_ratio() {
  if constexpr (std::numeric_limits<T>::is_specialized && !std::numeric_limits<T>::is_integer &&
                std::is_convertible_v<decltype(std::numeric_limits<T>::epsilon()), double>)
    return 1.0 / static_cast<double>(std::numeric_limits<T>::epsilon());
  else
    return 1.0 / 2.220446049250313e-16;
}

/// Factorises symmetric positive-definite M (only the lower triangle is read). Throws
/// numerical_error naming `what` if a pivot is not positive (M is not positive definite), or
/// if M is numerically singular by a *scaled* criterion: the pivots of the diagonally scaled
/// matrix D^{-1/2} M D^{-1/2} (D = diag M), d_j / M_jj ∈ (0, 1], have a ratio beyond
/// max_ratio (default: 1/ε of T). Scaling first is what makes the test judge the problem and
/// not its units: a chain whose masses span 1e-9…1e6 kg from the base out has cond M ≈ 1e15
/// and more, yet LDLᵀ without pivoting solves it to full accuracy when the scaled matrix is
/// well conditioned (van der Sluis; Demmel, Applied Numerical Linear Algebra §2.4).
/// pivot_ratio() keeps the unscaled ratio, a cheap lower bound of cond(M).
/// `ldlt_factor_into(M, f)` factorises into f, whose storage is reused (no allocation when f.L
/// is M's size already); `ldlt_factor(M)` returns a new factor.
template <class T, int N>
void ldlt_factor_into(const Eigen::Matrix<T, N, N>& M, ldlt<T, N>& f, const char* what = "matrix",
                      double max_ratio = default_max_pivot_ratio<T>()) {
  const int n = static_cast<int>(M.rows());
  f.L = M;
  double dmin = INFINITY, dmax = 0, smin = INFINITY;
  int jmin = 0;
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
    const double sj = dj / value_of(M(j, j));  // the scaled pivot (M_jj ≥ d_j > 0)
    if (sj < smin) {
      smin = sj;
      jmin = j;
    }
    for (int i = j + 1; i < n; ++i) {
      for (int k = 0; k < j; ++k) f.L(i, j) -= f.L(i, k) * f.L(j, k) * f.L(k, k);
      f.L(i, j) /= f.L(j, j);
    }
  }
  f.min_pivot = dmin;
  f.max_pivot = dmax;
  f.min_scaled_pivot = smin;
  if (1.0 / smin > max_ratio) {
    std::ostringstream os;
    os << what << " is numerically singular (scaled pivot " << jmin << " = " << smin << ": the diagonally scaled "
       << "matrix's pivot ratio " << 1.0 / smin << " exceeds " << max_ratio << ")";
    throw numerical_error(os.str());
  }
}
template <class T, int N>
ldlt<T, N> ldlt_factor(const Eigen::Matrix<T, N, N>& M, const char* what = "matrix",
                       double max_ratio = default_max_pivot_ratio<T>()) {
  ldlt<T, N> f;
  ldlt_factor_into(M, f, what, max_ratio);
  return f;
}

/// The 2-norm condition number σ_max/σ_min of a square matrix, computed in double from the
/// entries' values (value_of): what a caller checks before trusting a solve with it (∞ if
/// singular, NaN if an entry is not finite). For a symmetric positive-definite matrix it is
/// λ_max/λ_min; ldlt::pivot_ratio() is a cheaper lower bound of it.
template <class Derived>
double condition_number(const Eigen::MatrixBase<Derived>& A) {
  const Eigen::MatrixXd a = A.unaryExpr([](const auto& x) { return value_of(x); }).template cast<double>();
  if (!a.allFinite()) return NAN;
  if (a.size() == 0) return 1.0;
  const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(a).singularValues();  // descending
  return s(s.size() - 1) > 0 ? s(0) / s(s.size() - 1) : INFINITY;
}

}  // namespace nhdyn
