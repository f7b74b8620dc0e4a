#pragma once
/// \file dynamics/tree_factor.hpp
/// The sparse factorisation M = LᵀL of a tree's joint-space inertia (Featherstone, *Rigid
/// Body Dynamics Algorithms*, 2008, §6.5, Tables 6.3 and 6.4): L is lower triangular with the
/// tree's sparsity — L(i, j) ≠ 0 only for j = i or j an ancestor of i, λ(i) = parent(i) < i —
/// so factorising costs about Σ_i d_i²/2 multiply-adds and a solve 2 Σ_i d_i multiply-adds
/// (and 2n scalings) per right-hand side (d_i: the number of ancestors of body i), against
/// n³/6 and n² for a dense Cholesky factorisation. On a chain Σ_i d_i = n(n−1)/2 and it is
/// the dense factorisation (upside down: LᵀL, not LLᵀ); the saving is the tree's branching.
///
/// The right-hand sides are the columns of a row-major X (n × k): `solve_in_place(X)` finishes
/// one row at a time, all k columns at once — the row's updates from its descendants (first
/// sweep) or ancestors (second) gathered in vector registers, 48 columns at a time, and the
/// row stored once. (As one row operation X_i ← X_i − L(j, i) X_j per (body, ancestor) pair,
/// the same arithmetic took 1.9× as long at 48 bodies and 144 columns: a store of the row per
/// pair; g++ 12 -O3 -march=native, AMD EPYC, 2026-11-26.)
#include <Eigen/Core>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace nhdyn {

/// A tree's ancestor lists, flattened: ancestors(i) = λ(i), λ(λ(i)), … (nearest first).
class tree_sparsity {
 public:
  tree_sparsity() = default;
  /// From parent[i] < i (−1 for a root); anything else is refused (std::invalid_argument).
  explicit tree_sparsity(const std::vector<int>& parent) : start_{0} {
    const int n = static_cast<int>(parent.size());
    for (int i = 0; i < n; ++i) {
      const int p = parent[static_cast<std::size_t>(i)];
      if (p < -1 || p >= i)
        throw std::invalid_argument("tree_sparsity: parent[" + std::to_string(i) + "] = " + std::to_string(p) +
                                    " (must be −1 or a body before " + std::to_string(i) + ")");
      for (int j = parent[static_cast<std::size_t>(i)]; j >= 0; j = parent[static_cast<std::size_t>(j)]) list_.push_back(j);
      start_.push_back(static_cast<int>(list_.size()));
    }
    // the descendant lists: the (i, ancestor j) pairs grouped by j, i increasing
    std::vector<int> count(static_cast<std::size_t>(n) + 1, 0);
    for (int j : list_) ++count[static_cast<std::size_t>(j) + 1];
    for (int i = 0; i < n; ++i) count[static_cast<std::size_t>(i) + 1] += count[static_cast<std::size_t>(i)];
    dstart_ = count;
    dlist_.resize(list_.size());
    for (int i = 0; i < n; ++i)
      for (const int* j = begin(i); j != end(i); ++j) dlist_[static_cast<std::size_t>(count[static_cast<std::size_t>(*j)]++)] = i;
  }
  int size() const { return static_cast<int>(start_.size()) - 1; }
  /// The ancestors of i, nearest first, as [begin, end).
  const int* begin(int i) const { return list_.data() + start_[static_cast<std::size_t>(i)]; }
  const int* end(int i) const { return list_.data() + start_[static_cast<std::size_t>(i) + 1]; }
  /// The descendants of j, increasing, as [desc_begin(j), desc_end(j)).
  const int* desc_begin(int j) const { return dlist_.data() + dstart_[static_cast<std::size_t>(j)]; }
  const int* desc_end(int j) const { return dlist_.data() + dstart_[static_cast<std::size_t>(j) + 1]; }
  /// Σ_i d_i: the (body, ancestor) pairs.
  int pairs() const { return static_cast<int>(list_.size()); }

 private:
  std::vector<int> start_{0}, list_, dstart_{0}, dlist_;
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
  /// Factorises M (n × n, n = s.size(); only the diagonal and the lower triangle's
  /// (i, ancestor of i) entries are read) over the sparsity s, which is copied; the storage of
  /// an earlier factorisation of the same size is reused. Returns ok(): false when M is not
  /// positive definite along the way (a pivot ≤ 0 or NaN).
  template <class Mat>
  bool factor(const Eigen::MatrixBase<Mat>& M, const tree_sparsity& s) {
    using std::sqrt;
    if (M.rows() != s.size() || M.cols() != s.size())
      throw std::invalid_argument("tree_ltl: M is " + std::to_string(M.rows()) + " × " + std::to_string(M.cols()) +
                                  ", the tree has " + std::to_string(s.size()) + " bodies");
    const int m = s.size();
    L_.resize(m, m);  // only the entries the factorisation reads (row-major: a row's ancestors together)
    for (int i = 0; i < m; ++i) {
      L_(i, i) = M(i, i);
      for (const int* j = s.begin(i); j != s.end(i); ++j) L_(i, *j) = M(i, *j);
    }
    s_ = s;
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
  /// for a row-major X (each step is then a loop over one contiguous row). Refused
  /// (std::logic_error) without a successful factorisation or with X's rows ≠ n.
  template <class X>
    requires(bool(X::IsRowMajor) && X::InnerStrideAtCompileTime == 1)
  void solve_in_place(Eigen::MatrixBase<X>& x) const {
    const tree_sparsity& s = s_;
    const int n = static_cast<int>(L_.rows());
    if (!ok_ || x.rows() != n)
      throw std::logic_error(!ok_ ? "tree_ltl::solve_in_place: no successful factorisation"
                                  : "tree_ltl::solve_in_place: X has " + std::to_string(x.rows()) + " rows, M " +
                                        std::to_string(n));
    const Eigen::Index k = x.cols(), stride = x.derived().outerStride();
    T* const d = x.derived().data();
    const auto row = [&](int i) { return d + i * stride; };
    // Lᵀ Y = X from the leaves: y_i = (x_i − Σ_{j a descendant of i} L(j, i) y_j) / L(i, i)
    for (int i = n - 1; i >= 0; --i)
      finish_row(row(i), k, T(1) / L_(i, i), s.desc_begin(i), s.desc_end(i), [&](int j) { return L_(j, i); }, row);
    // L X = Y from the roots: x_j = (y_j − Σ_{i an ancestor of j} L(j, i) x_i) / L(j, j)
    for (int j = 0; j < n; ++j)
      finish_row(row(j), k, T(1) / L_(j, j), s.begin(j), s.end(j), [&](int i) { return L_(j, i); }, row);
  }

 private:
  // y ← (y − Σ_{o in [b, e)} l(o) row(o)) · r over k entries: 48, then 8, then 4 at a time
  // in registers (fixed-size Eigen arrays: packets), the last < 4 one by one
  template <class Coef, class Row>
  static void finish_row(T* y, Eigen::Index k, const T r, const int* b, const int* e, const Coef& l, const Row& row) {
    Eigen::Index c0 = blocks<48>(y, 0, k, r, b, e, l, row);
    c0 = blocks<8>(y, c0, k, r, b, e, l, row);
    c0 = blocks<4>(y, c0, k, r, b, e, l, row);
    for (; c0 < k; ++c0) {
      T acc = y[c0];
      for (const int* o = b; o != e; ++o) acc -= l(*o) * row(*o)[c0];
      y[c0] = acc * r;
    }
  }
  template <int W, class Coef, class Row>
  static Eigen::Index blocks(T* y, Eigen::Index c0, Eigen::Index k, const T r, const int* b, const int* e,
                             const Coef& l, const Row& row) {
    using Block = Eigen::Array<T, W, 1>;
    for (; c0 + W <= k; c0 += W) {
      Block acc = Eigen::Map<const Block>(y + c0);
      for (const int* o = b; o != e; ++o) acc -= l(*o) * Eigen::Map<const Block>(row(*o) + c0);
      Eigen::Map<Block>(y + c0) = acc * r;
    }
    return c0;
  }

  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> L_;
  tree_sparsity s_;
  bool ok_ = false;
};

}  // namespace nhdyn
