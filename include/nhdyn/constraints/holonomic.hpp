#pragma once
/// \file constraints/holonomic.hpp
/// `holonomic<N>`: no constraint (S = I, k = 0), for the holonomic forms of every stage.
#include "concept.hpp"

namespace nhdyn {

/// No constraint: S = I (m = n), A is 0×n.
template <int N = dynamic>
struct holonomic {
  static constexpr int n_at_compile_time = N;
  static constexpr int k_at_compile_time = N == dynamic ? dynamic : 0;
  static constexpr int m_at_compile_time = N;
  int n = N == dynamic ? 0 : N;

  int dof() const { return n; }
  int k() const { return 0; }
  int m() const { return n; }
  bool depends_on(int) const { return false; }
  template <class Q>
  auto A(const Eigen::MatrixBase<Q>&) const {
    return matrix<typename Q::Scalar, k_at_compile_time, N>(0, n);
  }
  template <class Q>
  auto S(const Eigen::MatrixBase<Q>&) const {
    return matrix<typename Q::Scalar, N, N>::Identity(n, n);
  }
  template <class Q, class QD>
  auto Sdot(const Eigen::MatrixBase<Q>&, const Eigen::MatrixBase<QD>&) const {
    return matrix<typename Q::Scalar, N, N>::Zero(n, n);
  }
  template <class Q, class E>
  auto S_times(const Eigen::MatrixBase<Q>&, const Eigen::MatrixBase<E>& eta) const {
    return vecN<promote_t<typename Q::Scalar, typename E::Scalar>, N>(
        eta.template cast<promote_t<typename Q::Scalar, typename E::Scalar>>());
  }
  template <class Q, class V>
  auto St_times(const Eigen::MatrixBase<Q>&, const Eigen::MatrixBase<V>& v) const {
    return vecN<promote_t<typename Q::Scalar, typename V::Scalar>, N>(
        v.template cast<promote_t<typename Q::Scalar, typename V::Scalar>>());
  }
  template <class Q, class QD, class E>
  auto Sdot_times(const Eigen::MatrixBase<Q>&, const Eigen::MatrixBase<QD>&,
                  const Eigen::MatrixBase<E>& eta) const {
    return vecN<promote_t<typename Q::Scalar, typename E::Scalar>, N>::Zero(eta.size());
  }
  template <class Q, class T>
  vecN<T, N> St_times_in_place(const Eigen::MatrixBase<Q>&, vecN<T, N>&& v) const {
    return std::move(v);
  }
  static constexpr bool orthonormal_S = true;  // SᵀS = I: the projection is Sᵀ
};

}  // namespace nhdyn
