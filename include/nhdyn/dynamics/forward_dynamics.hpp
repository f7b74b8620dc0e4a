#pragma once
/// \file dynamics/forward_dynamics.hpp
/// Holonomic forward dynamics q̈ = M(q)⁻¹ (τ − h(q, q̇)), M by the composite-rigid-body
/// algorithm, h by rne, solved by LDLᵀ. Throws numerical_error if M is singular (a chain
/// whose last joints move no mass) or too ill-conditioned to give a digit.
#include "../detail/ldlt.hpp"
#include "mass_matrix.hpp"

namespace nhdyn {

template <class S, int N = dynamic>
class forward_dynamics_fn : public stage_tag {
 public:
  explicit forward_dynamics_fn(const chain<S, N>& c, rne_options o = {})
      : M_(c), rne_(c, o) {}

  /// The 2-norm condition number of M(q) (double); operator() throws numerical_error past 1/ε.
  template <class Q>
  double mass_matrix_condition(const Eigen::MatrixBase<Q>& q) const {
    return condition_number(M_(q));
  }

  template <class Q, class QD, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<TAU>& tau) const {
    using X = typename Q::Scalar;
    using T = promote_t<S, X>;
    detail::check_size(tau, rne_.dof(), "tau");
    detail::check_finite(tau, "tau");
    const vecN<T, N> h = rne_(q, qd, vecN<X, N>::Zero(q.size()));
    const auto f = ldlt_factor<T, N>(M_(q), "the mass matrix M(q)");
    vecN<T, N> qdd = f.solve(tau.template cast<T>() - h);
    detail::check_overflow(qdd, "forward_dynamics");
    return qdd;
  }

 private:
  mass_matrix_fn<S, N> M_;
  rne_fn<S, N> rne_;
};

template <class S, int N>
forward_dynamics_fn<S, N> forward_dynamics(const chain<S, N>& c, rne_options o = {}) {
  return forward_dynamics_fn<S, N>(c, o);
}

}  // namespace nhdyn
