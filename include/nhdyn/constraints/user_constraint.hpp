#pragma once
/// \file constraints/user_constraint.hpp
/// `user_constraint` (`make_constraint`): a constraint given by plain functions of q; Ṡ by
/// duals when not given.
#include <functional>
#include <sstream>
#include <utility>

#include "../scalar/dual.hpp"
#include "concept.hpp"

namespace nhdyn {

/// A constraint given by plain functions of q (generic lambdas, so that they run on any
/// scalar): fA(q) → k×n, fS(q) → n×m, optionally fSdot(q, q̇) → n×m and fE(q) → n×m.
/// Without fSdot, Ṡ = Σ_j ∂S/∂q_j q̇_j is the derivative part of fS at the dual q + ε q̇.
template <class FA, class FS, class FSdot = std::nullptr_t, class FE = std::nullptr_t>
struct user_constraint {
  static constexpr int n_at_compile_time = dynamic;
  static constexpr int k_at_compile_time = dynamic;
  static constexpr int m_at_compile_time = dynamic;
  static constexpr bool orthonormal_S = false;
  int n_, k_;
  FA fA;
  FS fS;
  FSdot fSdot{};
  FE fE{};

  int dof() const { return n_; }
  int k() const { return k_; }
  int m() const { return n_ - k_; }

  template <class Q>
  auto A(const Eigen::MatrixBase<Q>& q) const {
    using T = typename Q::Scalar;
    detail::check_size(q, n_, "q");
    matrix<T, dynamic, dynamic> a = fA(vecN<T, dynamic>(q));
    check(a, k_, n_, "A(q)");
    return a;
  }
  template <class Q>
  auto S(const Eigen::MatrixBase<Q>& q) const {
    using T = typename Q::Scalar;
    detail::check_size(q, n_, "q");
    matrix<T, dynamic, dynamic> s = fS(vecN<T, dynamic>(q));
    check(s, n_, n_ - k_, "S(q)");
    return s;
  }
  template <class Q>
  auto E(const Eigen::MatrixBase<Q>& q) const {
    using T = typename Q::Scalar;
    if constexpr (std::is_same_v<FE, std::nullptr_t>) {
      return S(q);
    } else {
      detail::check_size(q, n_, "q");
      matrix<T, dynamic, dynamic> e = fE(vecN<T, dynamic>(q));
      check(e, n_, n_ - k_, "E(q)");
      return e;
    }
  }
  template <class Q, class QD>
  auto Sdot(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd) const {
    using T = promote_t<typename Q::Scalar, typename QD::Scalar>;
    detail::check_size(q, n_, "q");
    detail::check_size(qd, n_, "qd");
    if constexpr (!std::is_same_v<FSdot, std::nullptr_t>) {
      matrix<T, dynamic, dynamic> s =
          fSdot(vecN<T, dynamic>(q.template cast<T>()), vecN<T, dynamic>(qd.template cast<T>()));
      check(s, n_, n_ - k_, "Sdot(q, qd)");
      return s;
    } else {
      using D = dual<T, 1>;
      vecN<D, dynamic> qq(q.size());
      for (Eigen::Index j = 0; j < q.size(); ++j) qq(j) = D(T(q(j)), {T(qd(j))});
      const matrix<D, dynamic, dynamic> s = fS(qq);
      check(s, n_, n_ - k_, "S(q)");
      return matrix<T, dynamic, dynamic>(s.unaryExpr([](const D& d) { return d.derivative(0); }));
    }
  }

 private:
  template <class Mat>
  static void check(const Mat& a, int r, int c, const char* what) {
    if (a.rows() != r || a.cols() != c) {
      std::ostringstream os;
      os << "user_constraint: " << what << " is " << a.rows() << "×" << a.cols() << ", expected "
         << r << "×" << c;
      throw input_error(os.str());
    }
  }
};

/// Builds a user constraint over n joints with k constraint rows.
template <class FA, class FS>
auto make_constraint(int n, int k, FA fA, FS fS) {
  return user_constraint<FA, FS>{n, k, std::move(fA), std::move(fS)};
}
template <class FA, class FS, class FSdot>
auto make_constraint(int n, int k, FA fA, FS fS, FSdot fSdot) {
  return user_constraint<FA, FS, FSdot>{n, k, std::move(fA), std::move(fS), std::move(fSdot)};
}
template <class FA, class FS, class FSdot, class FE>
auto make_constraint(int n, int k, FA fA, FS fS, FSdot fSdot, FE fE) {
  return user_constraint<FA, FS, FSdot, FE>{n, k, std::move(fA), std::move(fS), std::move(fSdot),
                                            std::move(fE)};
}

}  // namespace nhdyn
