#pragma once
/// \file constraints/forward_dynamics.hpp
/// Constrained (nonholonomic) forward dynamics (paper.md §2):
///
///     M_η = Sᵀ M S,   h_η = Sᵀ rne(q, Sη, Ṡη),   M_η η̇ = Sᵀ E τ − h_η
///
/// and the state derivative (q̇, η̇) = (S η, η̇) for integrators. M_η is built either from a
/// composite-rigid-body pass projected by S (default: measured faster, docs/performance.md)
/// or from m calls of rne with gravity and velocity terms off (q̈ = S e_j).
/// `fd.with(friction(model))` adds the joints' friction to the bias:
/// h_η = Sᵀ(rne(q, Sη, Ṡη) + τ_f(Sη)) (dynamics/terms.hpp).
#include <optional>

#include "../dynamics/friction.hpp"
#include "../dynamics/mass_matrix.hpp"
#include "stages.hpp"

namespace nhdyn {

enum class reduced_inertia_method { crba, rne_columns };

/// Model: a chain<S, N> or a tree<S> (N = dynamic): whatever rne(model) and
/// mass_matrix(model) take.
template <class S, int N, pfaffian_constraint C, class Model = chain<S, N>>
class nh_forward_dynamics_fn : public stage_tag {
  using rne_type = decltype(rne(std::declval<const Model&>(), rne_options{}));
  using mass_matrix_type = decltype(mass_matrix(std::declval<const Model&>()));

 public:
  static constexpr int M = C::m_at_compile_time;

  nh_forward_dynamics_fn(const Model& ch, C c, rne_options o = {},
                         reduced_inertia_method method = reduced_inertia_method::crba)
      : c_(std::move(c)), rne_(ch, o), inertia_rne_(ch, {false, false}), M_(ch), method_(method) {
    if (c_.dof() != ch.dof())
      throw model_error("constraint is over " + std::to_string(c_.dof()) + (std::is_same_v<Model, tree<S>> ? " joints, the tree has " : " joints, the chain has ") +
                        std::to_string(ch.dof()));
  }
  const C& constraint() const { return c_; }

  /// The same forward dynamics with the joints' friction τ_f(q̇) in the bias:
  /// M_η η̇ = SᵀE τ − Sᵀ(rne(q, Sη, Ṡη) + τ_f(Sη)) (τ_f: friction(model), dynamics/friction.hpp).
  nh_forward_dynamics_fn with(friction_fn f) const {
    if (f.dof() != c_.dof())
      throw model_error("nh_forward_dynamics: the friction is of " + std::to_string(f.dof()) + " joints, the model has " +
                        std::to_string(c_.dof()));
    auto r = *this;
    r.friction_ = std::move(f);
    return r;
  }

  /// M_η(q) = Sᵀ M S (m×m).
  template <class Q>
  auto reduced_inertia(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<S, typename Q::Scalar>;
    detail::check_size(q, c_.dof(), "q");
    detail::check_finite(q, "q");
    const int m = c_.m();
    matrix<T, M, M> Me(m, m);
    if (method_ == reduced_inertia_method::crba) {
      Me = detail::project_inertia<T>(c_, q, M_(q));
    } else {
      const vecN<T, N> zero = vecN<T, N>::Zero(c_.dof());
      for (int j = 0; j < m; ++j) {
        vecN<T, M> e = vecN<T, M>::Zero(m);
        e(j) = T(1);
        const vecN<T, N> qdd = apply_S(c_, q, e);
        Me.col(j) = apply_St(c_, q, inertia_rne_(q, zero, qdd));
      }
    }
    return Me;
  }

  /// The 2-norm condition number of M_η(q) (double): how many digits η̇ loses (about
  /// log10 of it). operator() throws numerical_error when it passes 1/ε; a caller that
  /// wants to know before (or to switch to a damped model) asks here.
  template <class Q>
  double reduced_inertia_condition(const Eigen::MatrixBase<Q>& q) const {
    return condition_number(reduced_inertia(q));  // which checks q
  }

  /// h_η = Sᵀ rne(q, Sη, Ṡη).
  template <class Q, class E>
  auto reduced_bias(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta) const {
    detail::check_size(q, c_.dof(), "q");
    detail::check_size(eta, c_.m(), "eta");
    detail::check_finite(q, "q");
    detail::check_finite(eta, "eta");
    using T = promote_t<promote_t<S, typename Q::Scalar>, typename E::Scalar>;
    if constexpr (!has_Sdot_times<C, Q, vecN<T, N>, E> && requires(vecN<T, N>& v) { c_.lift_into(q, eta, eta, v, v); }) {
      // (q̇, Ṡη) in one pass, the lift at η̇ = 0, where the constraint has no structured Ṡη
      // (wheeled_base: its Ṡ would be S's dual derivative, a dense n × m matrix)
      vecN<T, N> qd(c_.dof()), sdeta(c_.dof());
      c_.lift_into(q, eta, vecN<T, M>::Zero(c_.m()), qd, sdeta);
      return apply_St(c_, q, rne_(q, qd, sdeta));
    } else {
      const auto qd = apply_S(c_, q, eta);
      return apply_St(c_, q, rne_(q, qd, apply_Sdot(c_, q, qd, eta)));
    }
  }

  /// η̇ = M_η⁻¹ (SᵀE τ − h_η), τ of the constraint's p actuators (m unless it says otherwise).
  template <class Q, class E, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                  const Eigen::MatrixBase<TAU>& tau) const {
    using T0 = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename E::Scalar>, typename TAU::Scalar>;
    return solve(q, eta, tau, static_cast<const vecN<T0, N>*>(nullptr));
  }
  /// With applied forces (external wrenches, dynamics/wrench.hpp):
  /// η̇ = M_η⁻¹ (SᵀE τ + Sᵀ Q_ext(q) − h_η).
  template <class Q, class E, class TAU, applied_forces F>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                  const F& fx) const {
    detail::check_size(q, c_.dof(), "q");
    const auto Qx = fx.generalized_force(q);
    return solve(q, eta, tau, &Qx);
  }

  /// The state derivative for integrators: x = (q, η) ↦ ẋ = (q̇, η̇) = (S η, η̇), n + m entries.
  template <class Q, class E, class TAU>
  auto state_derivative(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                        const Eigen::MatrixBase<TAU>& tau) const {
    const auto eta_dot = (*this)(q, eta, tau);
    using T = typename decltype(eta_dot)::Scalar;
    constexpr int NX = N == dynamic || M == dynamic ? dynamic : N + M;
    vecN<T, NX> dx(c_.dof() + c_.m());
    dx << apply_S(c_, q, eta).template cast<T>(), eta_dot;
    return dx;
  }

 private:
  /// η̇ for τ and, when Qx is not null, the applied forces' generalized force Q_ext.
  template <class Q, class E, class TAU, class QX>
  auto solve(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
             const QX* Qx) const {
    using T0 = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename E::Scalar>, typename TAU::Scalar>;
    using T = promote_t<T0, typename QX::Scalar>;
    detail::check_size(q, c_.dof(), "q");
    detail::check_size(eta, c_.m(), "eta");
    detail::check_size(tau, actuator_count(c_), "tau");
    detail::check_finite(q, "q");
    detail::check_finite(eta, "eta");
    detail::check_finite(tau, "tau");
    const vecN<T0, M> h = reduced_bias(q, eta);
    vecN<T, M> u;
    constexpr bool has_E = has_input_map<C, Q>;
    if constexpr (has_identity_StE<C>) {
      u = tau.template cast<T>();
    } else if constexpr (has_E) {
      u = (c_.S(q).transpose() * c_.E(q)).template cast<T>() * tau.template cast<T>();
    } else if constexpr (C::orthonormal_S) {
      u = tau.template cast<T>();
    } else {
      const auto Sq = c_.S(q);
      u = (Sq.transpose() * Sq).template cast<T>() * tau.template cast<T>();
    }
    if (Qx) u += apply_St(c_, q, *Qx).template cast<T>();
    if (friction_) u -= apply_St(c_, q, (*friction_)(apply_S(c_, q, eta))).template cast<T>();
    const auto f = ldlt_factor<T, M>(reduced_inertia(q), "the reduced inertia M_η = SᵀMS");
    vecN<T, M> eta_dot = f.solve(u - h.template cast<T>());
    detail::check_overflow(eta_dot, "nh_forward_dynamics");
    return eta_dot;
  }

  C c_;
  rne_type rne_;
  rne_type inertia_rne_;
  mass_matrix_type M_;
  reduced_inertia_method method_;
  std::optional<friction_fn> friction_;
};

template <class S, int N, pfaffian_constraint C>
auto nh_forward_dynamics(const chain<S, N>& ch, const C& c, rne_options o = {},
                         reduced_inertia_method method = reduced_inertia_method::crba) {
  return nh_forward_dynamics_fn<S, N, C>(ch, c, o, method);
}

/// The constrained forward dynamics of a tree (the constraint over its joints in q order).
template <class S, pfaffian_constraint C>
auto nh_forward_dynamics(const tree<S>& t, const C& c, rne_options o = {},
                         reduced_inertia_method method = reduced_inertia_method::crba) {
  return nh_forward_dynamics_fn<S, dynamic, C, tree<S>>(t, c, o, method);
}

}  // namespace nhdyn
