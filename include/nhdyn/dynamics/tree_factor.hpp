#pragma once
/// \file dynamics/tree_factor.hpp
/// The sparse factorisation M = LᵀL of a tree's joint-space inertia (Featherstone, *Rigid
/// Body Dynamics Algorithms*, 2008, §6.5, Tables 6.3 and 6.4): L is lower triangular with the
/// tree's sparsity — L(i, j) ≠ 0 only for j = i or j an ancestor of i, λ(i) = parent(i) < i —
/// so factorising costs Σ_i d_i² and a solve 2 Σ_i d_i per right-hand side (d_i: depth of
/// body i) instead of n³/3 and 2n². On a chain it is the dense Cholesky factorisation
/// (upside down: LᵀL, not LLᵀ).
///
/// The right-hand sides are the rows' other index: `solve_in_place(X)` takes X (n × k) and
/// each step of the recursion is one row operation X_j ← X_j − L(i, j) X_i, which runs over
/// the k columns at once (vectorised when X is row-major).
#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace nhdyn {

/// A tree's ancestor lists, flattened: ancestors(i) = λ(i), λ(λ(i)), … (nearest first).
class tree_sparsity {
 public:
  tree_sparsity() = default;
  /// From parent[i] < i (−1 for a root).
  explicit tree_sparsity(const std::vector<int>& parent) : start_{0} {
    const int n = static_cast<int>(parent.size());
    for (int i = 0; i < n; ++i) {
      for (int j = parent[static_cast<std::size_t>(i)]; j >= 0; j = parent[static_cast<std::size_t>(j)]) list_.push_back(j);
      start_.push_back(static_cast<int>(list_.size()));
    }
  }
  int size() const { return static_cast<int>(start_.size()) - 1; }
  /// The ancestors of i, nearest first, as [begin, end).
  const int* begin(int i) const { return list_.data() + start_[static_cast<std::size_t>(i)]; }
  const int* end(int i) const { return list_.data() + start_[static_cast<std::size_t>(i) + 1]; }
  /// Σ_i d_i: the (body, ancestor) pairs.
  int pairs() const { return static_cast<int>(list_.size()); }

 private:
  std::vector<int> start_{0}, list_;
};

template <class T>
class tree_ltl {
 public:
  tree_ltl() = default;
  /// Factorises M (see factor).
  template <class Mat>
  tree_ltl(const Eigen::MatrixBase<Mat>& M, const tree_sparsity& s) {
    factor(M, s);
  }
  /// Factorises M (only the diagonal and the lower triangle's (i, ancestor of i) entries are
  /// read) over the sparsity s, which must outlive the solves; the storage of an earlier
  /// factorisation of the same size is reused. Returns ok(): false when M is not positive
  /// definite along the way.
  template <class Mat>
  bool factor(const Eigen::MatrixBase<Mat>& M, const tree_sparsity& s) {
    using std::sqrt;
    L_ = M;
    s_ = &s;
    ok_ = true;
    const int n = static_cast<int>(L_.rows());
    for (int k = n - 1; k >= 0; --k) {  // Table 6.3
      if (!(L_(k, k) > T(0))) return ok_ = false;
      L_(k, k) = sqrt(L_(k, k));
      const T r = T(1) / L_(k, k);
      for (const int* i = s.begin(k); i != s.end(k); ++i) L_(k, *i) *= r;
      for (const int* i = s.begin(k); i != s.end(k); ++i) {
        const T a = L_(k, *i);
        L_(*i, *i) -= a * a;
        for (const int* j = s.begin(*i); j != s.end(*i); ++j) L_(*i, *j) -= a * L_(k, *j);
      }
    }
    return ok_;
  }
  bool ok() const { return ok_; }
  /// L(i, j) for j = i or an ancestor of i (other entries of the storage are meaningless).
  const T& L(int i, int j) const { return L_(i, j); }

  /// X ← M⁻¹ X (Table 6.4: Lᵀ Y = X from the leaves down, then L X = Y from the roots up),
  /// for a row-major X (each step is then a loop over one contiguous row).
  template <class X>
    requires(bool(X::IsRowMajor) && X::InnerStrideAtCompileTime == 1)
  void solve_in_place(Eigen::MatrixBase<X>& x) const {
    const tree_sparsity& s = *s_;
    const int n = static_cast<int>(L_.rows());
    const Eigen::Index k = x.cols(), stride = x.derived().outerStride();
    T* const d = x.derived().data();
    const auto row = [&](int i) { return d + i * stride; };
    for (int j = n - 1; j >= 0; --j) {
      T* const xj = row(j);
      const T r = T(1) / L_(j, j);
      for (Eigen::Index c = 0; c < k; ++c) xj[c] *= r;
      for (const int* i = s.begin(j); i != s.end(j); ++i) axpy(row(*i), -L_(j, *i), xj, k);
    }
    for (int j = 0; j < n; ++j) {
      T* const xj = row(j);
      for (const int* i = s.begin(j); i != s.end(j); ++i) axpy(xj, -L_(j, *i), row(*i), k);
      const T r = T(1) / L_(j, j);
      for (Eigen::Index c = 0; c < k; ++c) xj[c] *= r;
    }
  }

 private:
  // y ← y + a x over k entries (distinct rows: no overlap)
  static void axpy(T* __restrict y, const T a, const T* __restrict x, Eigen::Index k) {
    for (Eigen::Index c = 0; c < k; ++c) y[c] += a * x[c];
  }

  // row-major: the factorisation walks L's rows (k and its ancestors' rows)
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> L_;
  const tree_sparsity* s_ = nullptr;
  bool ok_ = false;
};

}  // namespace nhdyn
