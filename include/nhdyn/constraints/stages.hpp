#pragma once
/// \file constraints/stages.hpp
/// The paper's method as composable stages (paper.md §2, Theorem 1):
///
///     lift:     ζ = (q, η, η̇) ↦ ξ = W(q) ζ = (q, S η, S η̇ + Ṡ η)                   (eq. 19)
///     rne:      ξ ↦ (q, v),  v = rne(q, q̇, q̈)                    (dynamics/rne.hpp)
///     project:  (q, v) ↦ τ = (Sᵀ E)⁻¹ Sᵀ v   (E = S: (SᵀS)⁻¹Sᵀ v)                  (eq. 18)
///
///     nonholonomic inverse dynamics = project ∘ rne ∘ lift   (in the code, literally)
///
/// (`inverse_dynamics` adds a resize of ξ between lift and rne only when the constraint
/// and the chain are sized differently, e.g. a run-time-sized user constraint on a
/// fixed-size chain; and, run-time sized, it keeps ξ and v in stack scratch rather than heap
/// vectors (detail::scratch_inverse_dynamics). The numbers are the same.)
///
/// and the constraint forces λ = (A Aᵀ)⁻¹ A (v − E τ), which do no work (q̇ᵀAᵀλ = 0).
/// `inverse_dynamics(model, c, o, friction(model))` puts rne + friction in rne's place
/// (the joints' friction, dynamics/terms.hpp).
#include "../detail/ldlt.hpp"
#include "../detail/small_buffer.hpp"
#include "../dynamics/friction.hpp"
#include "../dynamics/rne.hpp"
#include "../dynamics/tree.hpp"
#include "constraint.hpp"
#include <Eigen/LU>
#include <type_traits>
#include <utility>

namespace nhdyn {

template <class C>
using m_of = std::integral_constant<int, C::m_at_compile_time>;

namespace detail {
/// The scalar of a constraint's own numbers (`scalar_type`), or double.
template <class C>
struct constraint_scalar {
  using type = double;
};
template <class C>
  requires requires { typename C::scalar_type; }
struct constraint_scalar<C> {
  using type = typename C::scalar_type;
};
/// The projection's input checks (q and v: n entries each, finite), for a call on (q, v)
/// given by a caller. Inside project ∘ rne ∘ lift they were checked upstream: the stage on a
/// temporary (q, v) checks v's size only.
template <class C, class Q, class V>
void check_projection_input(const C& c, const Q& q, const V& v) {
  check_size(q, constraint_nq(c), "q");
  check_size(v, c.dof(), "v");
  check_finite(q, "q");
  check_finite(v, "v");
}
/// The lift's input checks: sizes n, m, m, then every entry finite.
template <class C, class Q, class E, class ED>
void check_reduced_state(const C& c, const Q& q, const E& eta, const ED& eta_dot) {
  check_size(q, constraint_nq(c), "q");
  check_size(eta, c.m(), "eta");
  check_size(eta_dot, c.m(), "eta_dot");
  check_finite(q, "q");
  check_finite(eta, "eta");
  check_finite(eta_dot, "eta_dot");
}
}  // namespace detail

template <class C>
class lift_fn : public stage_tag {
 public:
  explicit lift_fn(C c) : c_(std::move(c)) {}
  const C& constraint() const { return c_; }

  /// ξ = (q, Sη, Sη̇ + Ṡη).
  template <class Q, class E, class ED>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                  const Eigen::MatrixBase<ED>& eta_dot) const {
    constexpr int N = C::n_at_compile_time;
    detail::check_reduced_state(c_, q, eta, eta_dot);
    using TL = promote_t<promote_t<promote_t<typename detail::constraint_scalar<C>::type, typename Q::Scalar>, typename E::Scalar>,
                         typename ED::Scalar>;
    if constexpr (requires(vecN<TL, N>& v) { c_.lift_into(q, eta, eta_dot, v, v); }) {
      // Written in place (the result is returned without a copy).
      with_memo<joint_state<TL, N>, decltype(c_.lift_into(q, eta, eta_dot, std::declval<vecN<TL, N>&>(),
                                                          std::declval<vecN<TL, N>&>()))>
          xi;
      xi.q = q.template cast<TL>();
      xi.qd.resize(c_.dof());
      xi.qdd.resize(c_.dof());
      xi.memo = c_.lift_into(q, eta, eta_dot, xi.qd, xi.qdd);
      return xi;
    } else {
      auto qd = apply_S(c_, q, eta);
      using T = typename decltype(qd)::Scalar;
      joint_state<T, N> xi;
      xi.q = q.template cast<T>();
      xi.qdd = apply_S(c_, q, eta_dot);  // in place: no temporary for the sum
      xi.qdd += apply_Sdot(c_, q, qd, eta);
      xi.qd = std::move(qd);
      return xi;
    }
  }
  template <class X, int N, int M>
  auto operator()(const reduced_state<X, N, M>& z) const {
    return (*this)(z.q, z.eta, z.eta_dot);
  }
  /// ξ's q̇ and q̈ into qd and qdd (n entries each, one scalar; vectors or maps), where the
  /// constraint lifts into given storage (lift_into); returns its memo. The same checks and
  /// numbers as the call above, without allocating ξ.
  template <class Q, class E, class ED, class QDo, class QDDo>
    requires requires(const C& c, const Q& q, const E& e, const ED& ed, QDo& qd, QDDo& qdd) {
      c.lift_into(q, e, ed, qd, qdd);
    }
  auto into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
            Eigen::MatrixBase<QDo>& qd, Eigen::MatrixBase<QDDo>& qdd) const {
    detail::check_reduced_state(c_, q, eta, eta_dot);
    detail::check_size(qd, c_.dof(), "qd");
    detail::check_size(qdd, c_.dof(), "qdd");
    return c_.lift_into(q, eta, eta_dot, qd, qdd);
  }

 private:
  C c_;
};

template <pfaffian_constraint C>
lift_fn<C> lift(C c) {
  return lift_fn<C>(std::move(c));
}

namespace detail {
/// Whether the projection P = (SᵀE)⁻¹Sᵀ is Sᵀ itself: SᵀS = I and no input map, or SᵀE = I.
template <class C, class Q>
inline constexpr bool projection_is_St = (C::orthonormal_S && !has_input_map<C, Q>) || has_identity_StE<C>;

/// (SᵀE)⁻¹ r, for a right-hand side r of m rows (a vector, or a matrix of columns; taken by
/// value: with SᵀS = I and no E it is the answer, returned without a copy).
template <class C, class Q, class R>
auto solve_StE(const C& c, const Eigen::MatrixBase<Q>& q, R r) {
  using T = typename R::Scalar;
  constexpr int M = C::m_at_compile_time;
  using P = Eigen::Matrix<T, M, R::ColsAtCompileTime>;  // vecN<T, M> for a vector r
  constexpr bool has_E = has_input_map<C, Q>;
  if constexpr (has_solve_actuation<C, Q, R>) {
    // the constraint's own: p actuators, the least weighted norm when p > m (wheeled_base)
    return c.solve_actuation(q, r);
  } else if constexpr (projection_is_St<C, Q> && std::is_same_v<R, P>) {
    return r;
  } else if constexpr (projection_is_St<C, Q>) {
    return P(r);
  } else {
    const auto S = c.S(q);
    if constexpr (!has_E) {
      const matrix<T, M, M> G = (S.transpose() * S).template cast<T>();
      return P(ldlt_factor<T, M>(G, "SᵀS").solve(r));
    } else {
      const matrix<T, M, M> G = (S.transpose() * c.E(q)).template cast<T>();
      // The actuators must produce every admissible motion: SᵀE invertible, and well enough
      // conditioned that the solve keeps a digit (checked on the double values).
      const double kappa = condition_number(G);
      if (!(kappa < 1.0 / 2.220446049250313e-16)) {
        std::ostringstream os;
        os << "SᵀE is " << (std::isinf(kappa) ? "singular" : "numerically singular") << " (condition number "
           << kappa << "): the actuators (E) cannot produce every admissible motion (S)";
        throw numerical_error(os.str());
      }
      return P(Eigen::PartialPivLU<matrix<T, M, M>>(G).solve(r));
    }
  }
}
}  // namespace detail

template <class C>
class project_fn : public stage_tag {
 public:
  explicit project_fn(C c) : c_(std::move(c)) {}
  const C& constraint() const { return c_; }

  /// τ = (SᵀE)⁻¹ Sᵀ v (m entries).
  template <class Q, class V>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) const {
    detail::check_projection_input(c_, q, v);
    return detail::solve_StE(c_, q, apply_St(c_, q, v));
  }
  template <class X, int N>
  auto operator()(const generalized_forces<X, N>& f) const {
    return (*this)(f.q, f.v);
  }
  /// On a temporary (q, v), as inside project ∘ rne ∘ lift: Sᵀv is formed in v's storage
  /// where the constraint can do that (St_times_in_place).
  template <class X, int N>
  auto operator()(generalized_forces<X, N>&& f) const {
    if constexpr (requires { c_.St_times_in_place(f.q, std::move(f.v)); }) {
      detail::check_size(f.v, c_.dof(), "v");
      return detail::solve_StE(c_, f.q, c_.St_times_in_place(f.q, std::move(f.v)));
    } else {
      return (*this)(f.q, f.v);
    }
  }
  /// …and with the lift's memo (sin/cos of the heading), where the constraint takes it.
  template <class X, int N, class Memo>
  auto operator()(with_memo<generalized_forces<X, N>, Memo>&& f) const {
    if constexpr (requires { c_.project_with(f.q, f.v, f.memo); }) {
      // the whole projection from what the lift kept (wheeled_base: S's dependent rows)
      detail::check_size(f.v, c_.dof(), "v");
      return c_.project_with(f.q, f.v, f.memo);
    } else if constexpr (requires { c_.St_times_in_place(f.q, std::move(f.v), f.memo); }) {
      detail::check_size(f.v, c_.dof(), "v");
      if constexpr (C::orthonormal_S && !has_input_map<C, decltype(f.q)>)
        return c_.St_times_in_place(f.q, std::move(f.v), f.memo);  // SᵀS = I: Sᵀv is τ (no copy)
      else
        return detail::solve_StE(c_, f.q, c_.St_times_in_place(f.q, std::move(f.v), f.memo));
    } else {
      return (*this)(static_cast<generalized_forces<X, N>&&>(f));
    }
  }
  /// τ into tau (actuator_count entries, of the promoted scalar) from (q, v) and the lift's
  /// memo: the call above's numbers, bit for bit. Without allocation where the constraint
  /// projects into given storage (wheeled_base's project_into; Sᵀv into given storage where
  /// τ = Sᵀv: differential_drive with the memo, rolling_wheels and bicycle from q); else τ
  /// is formed as the call on (q, v) forms it and copied.
  template <class Q, class V, class Memo, class Tau>
  void into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, const Memo& memo,
            Eigen::MatrixBase<Tau>& tau) const {
    detail::check_size(v, c_.dof(), "v");
    detail::check_size(tau, actuator_count(c_), "tau");
    if constexpr (requires { c_.project_into(q, v, memo, tau); })
      c_.project_into(q, v, memo, tau);
    else if constexpr (C::orthonormal_S && !has_input_map<C, Q> && requires { c_.St_times_into(v, memo, tau); })
      c_.St_times_into(v, memo, tau);  // SᵀS = I: Sᵀv is τ
    else if constexpr (detail::projection_is_St<C, Q> && requires { c_.St_times_into(q, v, tau); })
      c_.St_times_into(q, v, tau);  // SᵀE = I (or SᵀS = I, no E): Sᵀv is τ, as apply_St forms it
    else
      tau = detail::solve_StE(c_, q, apply_St(c_, q, v));
  }

 private:
  C c_;
};

template <pfaffian_constraint C>
project_fn<C> project(C c) {
  return project_fn<C>(std::move(c));
}

namespace detail {
/// What λ's solve keeps from call to call: A(q), AAᵀ, its factor and v − Eτ.
template <class T, int N, int K>
struct lambda_scratch {
  matrix<T, K, N> A;
  matrix<T, K, K> AAt;
  ldlt<T, K> factor;
  vecN<T, N> r;
};
}  // namespace detail

/// (q, v) ↦ (τ, λ): the projection and the constraint forces λ = (AAᵀ)⁻¹ A (v − Eτ).
template <class C>
class constraint_forces_fn : public stage_tag {
 public:
  explicit constraint_forces_fn(C c) : c_(std::move(c)), p_(c_) {}
  const C& constraint() const { return c_; }

  template <class Q, class V>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) const {
    auto tau = p_(q, v);  // checks q and v
    using T = typename decltype(tau)::Scalar;
    constrained_forces<T, C::m_at_compile_time, C::k_at_compile_time> out;
    lambda_into(q, v, tau, out.lambda);
    out.tau = std::move(tau);
    return out;
  }
  template <class X, int N>
  auto operator()(const generalized_forces<X, N>& f) const {
    return (*this)(f.q, f.v);
  }
  /// (τ, λ) into out from (q, v) and the lift's memo: τ as project's `into` forms it (the
  /// inverse dynamics' τ, bit for bit), then λ as the call forms it from that τ. No allocation
  /// once out has its sizes where the constraint projects into given storage and forms A(q) and
  /// E τ there (every built-in base constraint: `A_into`, `E_times_into`, differential_drive's
  /// `A_times_into`); A, AAᵀ and the factor in a scratch the thread keeps.
  template <class Q, class V, class Memo, class T, int M, int K>
  void into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, const Memo& memo,
            constrained_forces<T, M, K>& out) const {
    out.tau.resize(actuator_count(c_));
    p_.into(q, v, memo, out.tau);
    lambda_into(q, v, out.tau, out.lambda);
  }

 private:
  /// λ = (AAᵀ)⁻¹ A (v − Eτ) into lambda (k entries). With E = S (no input map) A E τ = A S τ =
  /// 0, so λ = (AAᵀ)⁻¹ A v, and a constraint with orthonormal rows (AAᵀ = I: differential_drive)
  /// gives A v as a structured product, no matrix formed.
  template <class Q, class V, class Tau, class L>
  void lambda_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, const Tau& tau, L& lambda) const {
    using T = typename L::Scalar;
    constexpr int N = C::n_at_compile_time, K = C::k_at_compile_time;
    if constexpr (requires { c_.lambda_into(q, v, tau, lambda); }) {
      c_.lambda_into(q, v, tau, lambda);  // the constraint's own (wheel_contacts: dependent rows)
    } else if constexpr (!has_input_map<C, Q> && requires { c_.A_times_into(q, v, lambda); }) {
      c_.A_times_into(q, v, lambda);
    } else {
      lambda.resize(c_.k());
      if (c_.k() == 0) return;
      const auto solve = [&](detail::lambda_scratch<T, N, K>& ws) {
        using TA = typename decltype(c_.A(q))::Scalar;  // A's own scalar: into where it is λ's
        if constexpr (std::is_same_v<TA, T> && requires { c_.A_into(q, ws.A); })
          c_.A_into(q, ws.A);
        else
          ws.A = c_.A(q).template cast<T>();
        if constexpr (has_input_map<C, Q>) {
          ws.r.resize(c_.dof());
          if constexpr (has_E_times_into<C, Q, Tau, vecN<T, N>>)
            c_.E_times_into(q, tau, ws.r);
          else
            ws.r = (input_map(c_, q) * tau).template cast<T>();
          ws.r = v.template cast<T>() - ws.r;
        } else {
          ws.r = v.template cast<T>();
        }
        ws.AAt.noalias() = ws.A * ws.A.transpose();
        ldlt_factor_into<T, K>(ws.AAt, ws.factor, "AAᵀ");
        lambda.noalias() = ws.A * ws.r;
        ws.factor.solve_in_place(lambda);
      };
      detail::with_kept<detail::lambda_scratch<T, N, K>, N == dynamic || K == dynamic>(solve);
    }
  }

  C c_;
  project_fn<C> p_;
};

template <pfaffian_constraint C>
constraint_forces_fn<C> constraint_forces(C c) {
  return constraint_forces_fn<C>(std::move(c));
}

/// The nonholonomic inverse dynamics τ(q, η, η̇) = project ∘ rne ∘ lift (Theorem 1).
/// Call it as `id(q, eta, eta_dot)` or `id(reduced_state{…})`.
namespace detail {
/// ξ resized to a chain of N joints (N fixed or dynamic) when the constraint is sized
/// otherwise, e.g. a run-time-sized user constraint on a fixed-size chain.
template <int N>
struct resize_fn : stage_tag {
  template <class X, int M>
  joint_state<X, N> operator()(const joint_state<X, M>& xi) const {
    return {xi.q, xi.qd, xi.qdd};
  }
};
template <class S, int N, class C>
void check_constraint_fits(const chain<S, N>& ch, const C& c) {
  if (c.dof() != ch.dof())
    throw model_error("model '" + ch.name() + "': the constraint is over " + std::to_string(c.dof()) +
                      " joints, the chain has " + std::to_string(ch.dof()));
}
/// out ∘ dyn ∘ lift, with a resize between lift and dyn only where the sizes differ; dyn is
/// rne(ch, o) or a stage in its place (rne + friction).
template <class S, int N, class C, class Dyn, class Out>
auto nh_pipeline_with(const chain<S, N>& ch, const C& c, Dyn dyn, Out out) {
  check_constraint_fits(ch, c);
  if constexpr (C::n_at_compile_time == N)
    return compose(std::move(out), std::move(dyn), lift(c));
  else
    return compose(std::move(out), std::move(dyn), resize_fn<N>{}, lift(c));
}
/// out ∘ rne ∘ lift.
template <class S, int N, class C, class Out>
auto nh_pipeline(const chain<S, N>& ch, const C& c, rne_options o, Out out) {
  return nh_pipeline_with(ch, c, rne(ch, o), std::move(out));
}

/// out ∘ dyn ∘ lift on a tree (run-time sized; a compile-time-sized constraint's ξ resized);
/// dyn is rne(t, o) or a stage in its place.
template <class S, class C, class Dyn, class Out>
auto nh_pipeline_with(const tree<S>& t, const C& c, Dyn dyn, Out out) {
  if (c.dof() != t.dof())
    throw model_error("model '" + t.name() + "': the constraint is over " + std::to_string(c.dof()) +
                      " joints, the tree has " + std::to_string(t.dof()));
  if constexpr (C::n_at_compile_time == dynamic)
    return compose(std::move(out), std::move(dyn), lift(c));
  else
    return compose(std::move(out), std::move(dyn), resize_fn<dynamic>{}, lift(c));
}
/// out ∘ rne ∘ lift on a tree.
template <class S, class C, class Out>
auto nh_tree_pipeline(const tree<S>& t, const C& c, rne_options o, Out out) {
  return nh_pipeline_with(t, c, rne(t, o), std::move(out));
}

/// inverse_dynamics on a tree or a run-time-sized chain (the constraint run-time sized too):
/// the composition project ∘ rne ∘ lift itself (it derives from it: every call form it has,
/// the same numbers), and `evaluate(q, η, η̇, τ)`, the same three stages into storage:
/// lift.into writes ξ's q̇ and q̈ into stack scratch (beyond 256 joints, a heap block the
/// thread keeps), rne.evaluate writes v over q̈, project.into writes τ into the caller's
/// vector. No allocation where the constraint lifts and projects into given storage (every
/// built-in base constraint; wheeled_base with k·|η ∩ W| ≤ 24).
/// inverse_dynamics_with_forces takes the same form, its last stage constraint_forces:
/// `evaluate(q, η, η̇, out)` writes τ and λ into a constrained_forces (its into).
/// Call: whether the call (q, η, η̇) runs evaluate into a new τ; a chain's inverse_dynamics
/// keeps its fused call (constraints/fused_inverse_dynamics.hpp) and gains evaluate only.
template <class Composed, class C, bool Call = true>
struct staged_inverse_dynamics : Composed {
  explicit staged_inverse_dynamics(Composed c) : Composed(std::move(c)) {}

  /// The call: with (q, η, η̇) as vectors whose promoted scalar is τ's, evaluate into a new τ
  /// (its one allocation: the three stages' intermediates stay in evaluate's scratch); any other
  /// call form (a reduced_state, a model of another scalar than the constraint's), or Call
  /// false, the composition's.
  template <class... X>
  decltype(auto) operator()(X&&... x) const {
    if constexpr (Call && call_evaluates<X...>()) {
      using R = std::decay_t<decltype(Composed::operator()(std::forward<X>(x)...))>;
      R out;
      if constexpr (std::is_base_of_v<Eigen::MatrixBase<R>, R>) out.resize(actuator_count(this->f.constraint()));
      evaluate(std::forward<X>(x)..., out);
      return out;
    } else {
      return Composed::operator()(std::forward<X>(x)...);
    }
  }
  /// τ's scalar for (q, η, η̇) of types Q, E, ED: theirs and the constraint's, promoted.
  template <class Q, class E, class ED>
  using tau_scalar = promote_t<promote_t<promote_t<typename constraint_scalar<C>::type, typename Q::Scalar>, typename E::Scalar>,
                               typename ED::Scalar>;
  /// Whether the call with X runs evaluate: three Eigen vectors, the composition's τ a vector
  /// of their and the constraint's promoted scalar (evaluate's own requirement).
  template <class... X>
  static constexpr bool call_evaluates() {
    if constexpr (sizeof...(X) == 3 && (std::is_base_of_v<Eigen::MatrixBase<std::decay_t<X>>, std::decay_t<X>> && ...))
      return evaluates_into<std::decay_t<decltype(std::declval<const Composed&>()(std::declval<X>()...))>, std::decay_t<X>...>();
    else
      return false;
  }
  template <class R, class Q, class E, class ED>
  static constexpr bool evaluates_into() {
    if constexpr (std::is_base_of_v<Eigen::MatrixBase<R>, R>)
      return std::is_same_v<typename R::Scalar, tau_scalar<Q, E, ED>>;
    else if constexpr (requires(R r) { r.tau; r.lambda; })  // constrained_forces: (τ, λ)
      return std::is_same_v<typename decltype(R::tau)::Scalar, tau_scalar<Q, E, ED>>;
    else
      return false;
  }

  /// τ into tau (actuator_count(c) entries, of the promoted scalar of the constraint, q, η
  /// and η̇; a vector or a map): bit for bit the call's τ.
  template <class Q, class E, class ED, class Tau>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                Eigen::MatrixBase<Tau>& tau) const {
    static_assert(std::is_same_v<typename Tau::Scalar, tau_scalar<Q, E, ED>>,
                  "tau's scalar is the promoted scalar of the constraint, q, eta and eta_dot");
    run<typename Tau::Scalar>(q, eta, eta_dot, tau);
  }
  /// (τ, λ) into out (inverse_dynamics_with_forces): bit for bit the call's.
  template <class Q, class E, class ED, class T, int M, int K>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                constrained_forces<T, M, K>& out) const {
    static_assert(std::is_same_v<T, tau_scalar<Q, E, ED>>,
                  "out's scalar is the promoted scalar of the constraint, q, eta and eta_dot");
    run<T>(q, eta, eta_dot, out);
  }

 private:
  /// lift.into, rne.evaluate, then the last stage's into (τ, or τ and λ).
  template <class T, class Q, class E, class ED, class Out>
  void run(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
           Out& out) const {
    const auto& projection = this->f;
    const auto& dynamics = this->g.f;
    const auto& lifting = this->g.g;
    const int n = dynamics.dof();
    small_buffer<T, dynamic, 512> store(2 * n);  // q̇, then q̈ and v
    Eigen::Map<vecN<T, dynamic>> qd(store.data(), n), v(store.data() + n, n);
    const auto memo = lifting.into(q, eta, eta_dot, qd, v);  // q̈ into v's storage
    dynamics.evaluate(q, qd, v, v);                          // v over q̈
    projection.into(q, v, memo, out);
  }
};

/// The composition id, as staged_inverse_dynamics (with evaluate) where the model (a tree, or
/// a chain of N joints) and the constraint are run-time sized and the constraint lifts into given
/// storage (a fixed-size chain's stages allocate nothing already).
template <class S, int N, class C, bool Call = true, class Id>
auto with_evaluate(Id id) {
  constexpr bool lifts_into = requires(const C& k, const vecN<S, dynamic>& x, Eigen::Map<vecN<S, dynamic>>& m) {
    k.lift_into(x, x, x, m, m);
  };
  if constexpr (N == dynamic && C::n_at_compile_time == dynamic && lifts_into)
    return staged_inverse_dynamics<Id, C, Call>(std::move(id));
  else
    return id;
}
}  // namespace detail

/// As inverse_dynamics on a chain (constraints/fused_inverse_dynamics.hpp), returning (τ, λ):
/// with evaluate where the chain and the constraint are run-time sized.
template <class S, int N, pfaffian_constraint C>
auto inverse_dynamics_with_forces(const chain<S, N>& ch, const C& c, rne_options o = {}) {
  return detail::with_evaluate<S, N, C>(detail::nh_pipeline(ch, c, o, constraint_forces(c)));
}

/// The nonholonomic inverse dynamics of a tree: project ∘ rne ∘ lift, the constraint over the
/// tree's joints in q order. With a run-time-sized constraint that lifts into given storage,
/// it also evaluates into a τ the caller reuses (`evaluate(q, eta, eta_dot, tau)`).
template <class S, pfaffian_constraint C>
auto inverse_dynamics(const tree<S>& t, const C& c, rne_options o = {}) {
  return detail::with_evaluate<S, dynamic, C>(detail::nh_tree_pipeline(t, c, o, project(c)));
}
/// As inverse_dynamics on a tree, returning (τ, λ).
template <class S, pfaffian_constraint C>
auto inverse_dynamics_with_forces(const tree<S>& t, const C& c, rne_options o = {}) {
  return detail::with_evaluate<S, dynamic, C>(detail::nh_tree_pipeline(t, c, o, constraint_forces(c)));
}

/// With the joints' friction τ_f(q̇) (dynamics/friction.hpp, dynamics/terms.hpp):
/// project ∘ (rne + friction) ∘ lift, on a chain or a tree (with `evaluate` where the model and
/// the constraint are run-time sized, as without friction).
template <class Model, pfaffian_constraint C>
  requires(std::is_same_v<Model, tree<typename Model::scalar_type>> ||
           std::is_same_v<Model, chain<typename Model::scalar_type, Model::size_at_compile_time>>)
auto inverse_dynamics(const Model& m, const C& c, rne_options o, friction_fn f) {
  using S = typename Model::scalar_type;
  return detail::with_evaluate<S, Model::size_at_compile_time, C>(
      detail::nh_pipeline_with(m, c, rne(m, o) + std::move(f), project(c)));
}
/// As inverse_dynamics with friction, returning (τ, λ).
template <class Model, pfaffian_constraint C>
  requires(std::is_same_v<Model, tree<typename Model::scalar_type>> ||
           std::is_same_v<Model, chain<typename Model::scalar_type, Model::size_at_compile_time>>)
auto inverse_dynamics_with_forces(const Model& m, const C& c, rne_options o, friction_fn f) {
  using S = typename Model::scalar_type;
  return detail::with_evaluate<S, Model::size_at_compile_time, C>(
      detail::nh_pipeline_with(m, c, rne(m, o) + std::move(f), constraint_forces(c)));
}

}  // namespace nhdyn

// inverse_dynamics on a chain: the composition above, with its one fused path.
#include "fused_inverse_dynamics.hpp"
