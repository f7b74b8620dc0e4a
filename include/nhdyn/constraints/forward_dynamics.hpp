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
#include "../detail/small_buffer.hpp"
#include "stages.hpp"

namespace nhdyn {

enum class reduced_inertia_method { crba, rne_columns };

/// What `nh_forward_dynamics_fn::evaluate` writes: η̇ and the quantities that form it, in
/// storage the caller reuses from call to call (no allocation after the first call of a size,
/// docs/api.md §8). T: the model's and the inputs' promoted scalar.
template <class T, int N = dynamic, int M = dynamic>
struct nh_forward_dynamics_result {
  vecN<T, M> eta_dot;               ///< η̇ = M_η⁻¹ (SᵀE τ − h_η)
  matrix<T, N, M> S;                ///< S(q), n × m
  matrix<T, N, N> mass;             ///< M(q), n × n (reduced_inertia_method::crba; else not written)
  matrix<T, M, M> reduced_inertia;  ///< M_η = Sᵀ M S, m × m
  ldlt<T, M> factor;                ///< M_η's LDLᵀ (factor.pivot_ratio(): a cheap lower bound of cond M_η)
  vecN<T, M> reduced_bias;          ///< h_η = Sᵀ (rne(q, Sη, Ṡη) + τ_f(Sη) − Q_ext(q))
  vecN<T, M> actuation;             ///< SᵀE τ: M_η η̇ = actuation − reduced_bias
  vecN<T, N> qd;                    ///< q̇ = S η
  // scratch (no meaning between calls)
  vecN<T, N> sdeta, v;
  vecN<T, N> applied;  ///< Q_ext(q) of the applied forces, when given
  matrix<T, N, M> MS;
  detail::column_pattern<N, M> pattern;
};

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
    detail::check_size(q, constraint_nq(c_), "q");
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

  /// h_η = Sᵀ rne(q, Sη, Ṡη): the forward dynamics' own h_η (without friction and applied
  /// forces), by the same steps as evaluate, so the two agree bit for bit.
  template <class Q, class E>
  auto reduced_bias(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta) const {
    detail::check_size(q, constraint_nq(c_), "q");
    detail::check_size(eta, c_.m(), "eta");
    detail::check_finite(q, "q");
    detail::check_finite(eta, "eta");
    using T = promote_t<promote_t<S, typename Q::Scalar>, typename E::Scalar>;
    nh_forward_dynamics_result<T, N, M> r;
    form_S(q, r);
    bias_into(q, eta, r);
    r.reduced_bias.resize(c_.m());
    r.pattern.St_times(r.S, r.v, r.reduced_bias);
    return std::move(r.reduced_bias);
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
    if constexpr (N == dynamic || M == dynamic) {  // evaluate into a result its thread keeps, Q_ext too
      using T0 = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename E::Scalar>, typename TAU::Scalar>;
      using result = nh_forward_dynamics_result<promote_t<T0, detail::applied_scalar_t<F, Q>>, N, M>;
      return detail::with_kept<result>([&](result& kept) {
        evaluate(q, eta, tau, fx, kept);
        return kept.eta_dot;
      });
    } else {
      detail::check_size(q, constraint_nq(c_), "q");
      const auto Qx = fx.generalized_force(q);
      return solve(q, eta, tau, &Qx);
    }
  }

  /// η̇ into `out.eta_dot`, with M(q), S(q), M_η, its factor, h_η and SᵀEτ beside it (the
  /// result's fields), in storage reused from call to call: no heap allocation after the first
  /// call of a size on a tree, with every constraint a robot file makes (differential_drive,
  /// rolling_wheels, bicycle, wheeled_base) and the crba method (default), with or without
  /// friction and applied forces. `holonomic`'s and `user_constraint`'s S(q) and the rne_columns
  /// method allocate their own results. The same numbers as the plain call, bit for bit (the
  /// plain call is this into a result its thread keeps). `out` must not alias the inputs.
  template <class Q, class E, class TAU, class T>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                nh_forward_dynamics_result<T, N, M>& out) const {
    solve_into(q, eta, tau, static_cast<const vecN<T, N>*>(nullptr), out);
  }
  /// …with applied forces: Q_ext(q) into the result's `applied` (no allocation where the
  /// applied forces write into storage, as external_wrenches does, and Q_ext's scalar is T).
  template <class Q, class E, class TAU, applied_forces F, class T>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                const F& fx, nh_forward_dynamics_result<T, N, M>& out) const {
    detail::check_size(q, constraint_nq(c_), "q");
    if constexpr (std::is_same_v<detail::applied_scalar_t<F, Q>, T>) {
      out.applied.resize(c_.dof());
      detail::generalized_force_into(fx, q, out.applied);
      solve_into(q, eta, tau, &out.applied, out);
    } else {
      const auto Qx = fx.generalized_force(q);
      solve_into(q, eta, tau, &Qx, out);
    }
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
  /// η̇ for τ and, when Qx is not null, the applied forces' generalized force Q_ext: evaluate's
  /// steps into a result its thread keeps for the next call where sizes are run-time ones (one
  /// per scalar and size; a nested call, from a friction model say, takes a result of its
  /// own), so that η̇, copied out, is the call's one allocation; fixed sizes need no heap.
  template <class Q, class E, class TAU, class QX>
  auto solve(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
             const QX* Qx) const {
    using T0 = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename E::Scalar>, typename TAU::Scalar>;
    using result = nh_forward_dynamics_result<promote_t<T0, typename QX::Scalar>, N, M>;
    return detail::with_kept<result, N == dynamic || M == dynamic>([&](result& out) {
      solve_into(q, eta, tau, Qx, out);
      return out.eta_dot;
    });
  }

  /// S(q) into out.S (zeros, then the entries the constraint writes, or the constraint's S(q))
  /// and its nonzero pattern.
  template <class Q, class T>
  void form_S(const Eigen::MatrixBase<Q>& q, nh_forward_dynamics_result<T, N, M>& out) const {
    if constexpr (has_S_into<C, Q, matrix<T, N, M>>) {
      out.S.setZero(c_.dof(), c_.m());
      c_.S_into(q, out.S);
    } else {
      out.S = c_.S(q).template cast<T>();
    }
    out.pattern.scan(out.S);
  }
  /// q̇ = Sη and Ṡη into out.qd and out.sdeta, by one lift at η̇ = 0 into given storage where
  /// the constraint has it (wheeled_base has no other Ṡη: its Ṡ would be S's dual derivative,
  /// a dense n × m matrix); then v = rne(q, q̇, Ṡη) into out.v.
  template <class Q, class E, class T>
  void bias_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                 nh_forward_dynamics_result<T, N, M>& out) const {
    const int n = c_.dof();
    out.qd.resize(n);
    out.sdeta.resize(n);
    if constexpr (requires { c_.lift_into(q, eta, out.eta_dot, out.qd, out.sdeta); }) {
      out.eta_dot.setZero(c_.m());
      c_.lift_into(q, eta, out.eta_dot, out.qd, out.sdeta);
    } else {
      out.qd = apply_S(c_, q, eta).template cast<T>();
      out.sdeta = apply_Sdot(c_, q, out.qd, eta).template cast<T>();
    }
    if constexpr (requires { rne_.evaluate(q, out.qd, out.sdeta, out.v); }) {
      out.v.resize(n);
      rne_.evaluate(q, out.qd, out.sdeta, out.v);
    } else {
      out.v = rne_(q, out.qd, out.sdeta).template cast<T>();
    }
  }

  /// The forward dynamics into out: S(q); M(q) (CRBA) and M_η = SᵀMS over S's nonzeros;
  /// h_η = Sᵀ(rne(q, Sη, Ṡη) + τ_f − Q_ext) with (q̇, Ṡη) from one lift at η̇ = 0; SᵀEτ; then
  /// LDLᵀ of M_η and the solve, each into out's storage.
  template <class Q, class E, class TAU, class QX, class T>
  void solve_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                  const QX* Qx, nh_forward_dynamics_result<T, N, M>& out) const {
    using T0 = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename E::Scalar>, typename TAU::Scalar>;
    static_assert(std::is_same_v<T, promote_t<T0, typename QX::Scalar>>,
                  "the result's scalar is the model's and the inputs' promoted scalar");
    detail::check_size(q, constraint_nq(c_), "q");
    detail::check_size(eta, c_.m(), "eta");
    detail::check_size(tau, actuator_count(c_), "tau");
    detail::check_finite(q, "q");
    detail::check_finite(eta, "eta");
    detail::check_finite(tau, "tau");
    const int n = c_.dof(), m = c_.m();
    form_S(q, out);
    // M(q) and M_η = SᵀMS
    out.reduced_inertia.resize(m, m);
    if (method_ == reduced_inertia_method::crba) {
      if constexpr (std::is_same_v<T, promote_t<S, typename Q::Scalar>> && requires { M_.evaluate(q, out.mass); })
        M_.evaluate(q, out.mass);
      else
        out.mass = M_(q).template cast<T>();
      if constexpr (M != dynamic && has_St_M_S<C, Q, matrix<T, N, N>>) {
        out.reduced_inertia = c_.St_M_S(q, out.mass).template cast<T>();  // structured, fixed-size
      } else {
        out.MS.resize(n, m);
        out.pattern.St_M_S(out.S, out.mass, out.MS, out.reduced_inertia);
      }
    } else {
      out.reduced_inertia = reduced_inertia(q).template cast<T>();
    }
    bias_into(q, eta, out);
    if (friction_) friction_->add_to(out.qd, out.v);  // out.v += τ_f(q̇): no new vector
    if (Qx) out.v -= Qx->template cast<T>();
    out.reduced_bias.resize(m);
    out.pattern.St_times(out.S, out.v, out.reduced_bias);
    // SᵀE τ (sdeta's storage holds E τ or S τ)
    out.actuation.resize(m);
    if constexpr (has_identity_StE<C>) {
      out.actuation = tau.template cast<T>();
    } else if constexpr (has_input_map<C, Q>) {
      if constexpr (has_E_times_into<C, Q, TAU, vecN<T, N>>)
        c_.E_times_into(q, tau, out.sdeta);
      else
        out.sdeta.noalias() = input_map(c_, q).template cast<T>() * tau.template cast<T>();
      out.pattern.St_times(out.S, out.sdeta, out.actuation);
    } else if constexpr (C::orthonormal_S) {
      out.actuation = tau.template cast<T>();
    } else {
      out.sdeta.noalias() = out.S * tau.template cast<T>();
      out.pattern.St_times(out.S, out.sdeta, out.actuation);
    }
    ldlt_factor_into(out.reduced_inertia, out.factor, "the reduced inertia M_η = SᵀMS");
    out.eta_dot = out.actuation - out.reduced_bias;
    out.factor.solve_in_place(out.eta_dot);
    detail::check_overflow(out.eta_dot, "nh_forward_dynamics");
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
