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
#include "../detail/ldlt.hpp"
#include "../dynamics/rne.hpp"
#include "../dynamics/tree.hpp"
#include "constraint.hpp"
#include <Eigen/LU>

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
  check_size(q, c.dof(), "q");
  check_size(v, c.dof(), "v");
  check_finite(q, "q");
  check_finite(v, "v");
}
/// The lift's input checks: sizes n, m, m, then every entry finite.
template <class C, class Q, class E, class ED>
void check_reduced_state(const C& c, const Q& q, const E& eta, const ED& eta_dot) {
  check_size(q, c.dof(), "q");
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

 private:
  C c_;
};

template <pfaffian_constraint C>
lift_fn<C> lift(C c) {
  return lift_fn<C>(std::move(c));
}

namespace detail {
/// (SᵀE)⁻¹ r, for a right-hand side r of m rows (a vector, or a matrix of columns; taken by
/// value: with SᵀS = I and no E it is the answer, returned without a copy).
template <class C, class Q, class R>
auto solve_StE(const C& c, const Eigen::MatrixBase<Q>& q, R r) {
  using T = typename R::Scalar;
  constexpr int M = C::m_at_compile_time;
  using P = Eigen::Matrix<T, M, R::ColsAtCompileTime>;  // vecN<T, M> for a vector r
  constexpr bool has_E = has_input_map<C, Q>;
  if constexpr (C::orthonormal_S && !has_E && std::is_same_v<R, P>) {
    return r;
  } else if constexpr (C::orthonormal_S && !has_E) {
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
    if constexpr (requires { c_.St_times_in_place(f.q, std::move(f.v), f.memo); }) {
      detail::check_size(f.v, c_.dof(), "v");
      if constexpr (C::orthonormal_S && !has_input_map<C, decltype(f.q)>)
        return c_.St_times_in_place(f.q, std::move(f.v), f.memo);  // SᵀS = I: Sᵀv is τ (no copy)
      else
        return detail::solve_StE(c_, f.q, c_.St_times_in_place(f.q, std::move(f.v), f.memo));
    } else {
      return (*this)(static_cast<generalized_forces<X, N>&&>(f));
    }
  }

 private:
  C c_;
};

template <pfaffian_constraint C>
project_fn<C> project(C c) {
  return project_fn<C>(std::move(c));
}

/// (q, v) ↦ (τ, λ): the projection and the constraint forces λ = (AAᵀ)⁻¹ A (v − Eτ).
template <class C>
class constraint_forces_fn : public stage_tag {
 public:
  explicit constraint_forces_fn(C c) : c_(std::move(c)), p_(c_) {}

  template <class Q, class V>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) const {
    const auto tau = p_(q, v);  // checks q and v
    using T = typename decltype(tau)::Scalar;
    constexpr int M = C::m_at_compile_time, K = C::k_at_compile_time;
    constrained_forces<T, M, K> out;
    if constexpr (!has_input_map<C, Q> && requires { c_.A_times(q, v); }) {
      // E = S: A E τ = A S τ = 0, so λ = (AAᵀ)⁻¹ A v, and a constraint with orthonormal rows
      // (AAᵀ = I: differential_drive) gives it as a structured product, no matrix formed.
      out.lambda = c_.A_times(q, v);
      out.tau = tau;
      return out;
    }
    const auto A = c_.A(q);
    const vecN<T, C::n_at_compile_time> r = v.template cast<T>() - (input_map(c_, q) * tau).template cast<T>();
    const matrix<T, K, K> AAt = (A * A.transpose()).template cast<T>();
    out.lambda = c_.k() == 0 ? vecN<T, K>(0)
                             : vecN<T, K>(ldlt_factor<T, K>(AAt, "AAᵀ").solve((A.template cast<T>() * r).eval()));
    out.tau = tau;
    return out;
  }
  template <class X, int N>
  auto operator()(const generalized_forces<X, N>& f) const {
    return (*this)(f.q, f.v);
  }

 private:
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
/// out ∘ rne ∘ lift, with a resize between lift and rne only where the sizes differ.
template <class S, int N, class C, class Out>
auto nh_pipeline(const chain<S, N>& ch, const C& c, rne_options o, Out out) {
  check_constraint_fits(ch, c);
  if constexpr (C::n_at_compile_time == N)
    return compose(std::move(out), rne(ch, o), lift(c));
  else
    return compose(std::move(out), rne(ch, o), resize_fn<N>{}, lift(c));
}

/// Whether inverse_dynamics over a chain of model scalar S can take the call (q, η, η̇) on
/// stack scratch: a constraint that lifts into given storage (lift_into),
/// projects with the lift's memo (St_times) and has SᵀS = I and no E, and a state whose
/// scalar T the model's promotes to itself (double on double, dual or interval on double).
template <class S, class C, class Q, class E, class ED>
constexpr bool fusable_inverse_dynamics() {
  constexpr auto is_vec = []<class X>() { return std::is_base_of_v<Eigen::MatrixBase<X>, X>; };
  if constexpr (!(is_vec.template operator()<Q>() && is_vec.template operator()<E>() && is_vec.template operator()<ED>())) {
    return false;
  } else {
    using T = promote_t<promote_t<promote_t<typename constraint_scalar<C>::type, typename Q::Scalar>, typename E::Scalar>,
                        typename ED::Scalar>;
    using Mp = Eigen::Map<vecN<T, dynamic>>;
    // Compile-time sized, only for a floating-point state: for double it removes the stage
    // values' copies (store-forwarding stalls), but duals and intervals ran 25–35 % slower on
    // the scratch maps than through the composition (bench_scalar, 2026-11-24).
    return std::is_same_v<promote_t<S, T>, T> && C::orthonormal_S && !has_input_map<C, Q> &&
           (C::n_at_compile_time == dynamic || std::is_floating_point_v<T>) &&
           requires(const C& c, const Q& q, const E& e, const ED& ed, Mp& m) { c.St_times(m, c.lift_into(q, e, ed, m, m)); };
  }
}

/// inverse_dynamics (chain and constraint both run-time sized, or both of one compile-time
/// size): the composition project ∘ rne ∘ lift itself
/// (it derives from it: the same stages, and every call form the composition has), except
/// that the call (q, η, η̇), where the constraint allows (fusable_inverse_dynamics), runs
/// the same three stages with ξ's q̇, q̈ and v in stack scratch instead of three heap
/// vectors: lift_into writes q̇ and q̈, rne overwrites q̈ with v, St_times forms τ with the
/// lift's sin/cos of the heading. Only τ is allocated, as a run-time-sized rne allocates
/// only v. The numbers are the composition's, bit for bit (tests/test_constraints.cpp).
template <class Composed, class S, class C>
struct scratch_inverse_dynamics : Composed {
  explicit scratch_inverse_dynamics(Composed c) : Composed(std::move(c)) {}

  template <class... X>
  decltype(auto) operator()(X&&... x) const {
    if constexpr (sizeof...(X) == 3) {
      if constexpr (fusable_inverse_dynamics<S, C, std::remove_cvref_t<X>...>()) return on_scratch(x...);
      else return Composed::operator()(std::forward<X>(x)...);
    } else {
      return Composed::operator()(std::forward<X>(x)...);
    }
  }

 private:
  template <class Q, class E, class ED>
  auto on_scratch(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                  const Eigen::MatrixBase<ED>& eta_dot) const {
    const C& c = this->f.constraint();  // project
    const auto& r = this->g.f;          // rne (this->g.g is the lift)
    using T = promote_t<promote_t<promote_t<typename constraint_scalar<C>::type, typename Q::Scalar>, typename E::Scalar>,
                        typename ED::Scalar>;
    constexpr bool in_rne = std::is_floating_point_v<T> && requires(const sin_cos<T>& p, vecN<T, dynamic>& m) {
      c.template lift_angle<T>(q);
      c.lift_angle_form();
      c.lift_into(eta, eta_dot, m, m, p);
    };
    if constexpr (in_rne) {
      // Sizes here; finiteness by rne: every input entry v does not depend on it checks, the
      // rest make v non-finite (rne_fn::check_unseen). Its error names q̇ or q̈: the caller
      // gave η and η̇, so on an error they are checked first, by name. (Without velocity
      // terms rne reads no q̇, so η is checked here.)
      if (r.options().velocity) {
        check_size(q, c.dof(), "q");
        check_size(eta, c.m(), "eta");
        check_size(eta_dot, c.m(), "eta_dot");
      } else {
        check_reduced_state(c, q, eta, eta_dot);
      }
    } else {
      check_reduced_state(c, q, eta, eta_dot);  // the lift's checks
    }
    const int n = c.dof();
    constexpr int NC = C::n_at_compile_time;
    // Run-time sized: on the stack up to 256 joints, beyond on the heap. Compile-time sized:
    // on the stack, and q̇, q̈, v never move between stages (a fixed-size Eigen "move" is a
    // copy, and a vector load of just-stored scalars stalls store-to-load forwarding).
    using buffer = std::conditional_t<NC == dynamic, small_buffer<T, dynamic, 256>, small_buffer<T, NC>>;
    buffer qd_store(n), v_store(n);
    Eigen::Map<vecN<T, NC>> qd(qd_store.data(), n), v(v_store.data(), n);
    if constexpr (in_rne) {
      // The lift runs inside rne (its prelude), after rne's joint angles: ψ's sin/cos is a
      // joint's own when ψ = ±θ_j exactly (paper5: ψ = −θ₃), else one more in their batch.
      // The same numbers as lift_into's own sin/cos (the same kernel on the same sum, and
      // sin(−x) = −sin x, cos(−x) = cos x exactly); 2026-11-24, paired nh/rne on paper5,
      // run-time sized: 1.31 → 1.25 (one more angle in the batch: 1.28).
      sin_cos<T> memo;
      try {
        r.overwrite_qdd(q, qd, v,
                        lift_prelude<C, E, ED, decltype(qd)>(c, r.links(), q, eta.derived(), eta_dot.derived(), qd, v, memo));
      } catch (const error&) {
        check_reduced_state(c, q, eta, eta_dot);  // a non-finite input, by the caller's name
        throw;                                    // else rne's own error (an overflow)
      }
      return c.St_times(v, memo);
    } else {
      const auto memo = c.lift_into(q, eta, eta_dot, qd, v);  // q̈ into v's storage
      r.overwrite_qdd(q, qd, v);                               // v over q̈
      return c.St_times(v, memo);
    }
  }
  /// The lift as rne's prelude (rne_kernel): ψ's sin/cos from rne's joint angles, then
  /// (q̇, q̈) = lift_into(η, η̇, sin/cos ψ) and the sin/cos kept as the projection's memo.
  template <class Cx, class E, class ED, class Mp>
  struct lift_prelude {
    using T = typename Mp::Scalar;
    template <class Links, class Q>
    lift_prelude(const Cx& c_, const Links& links, const Eigen::MatrixBase<Q>& q, const E& e, const ED& ed, Mp& qd_,
                 Mp& qdd_, sin_cos<T>& memo_)
        : c(c_), eta(e), eta_dot(ed), qd(qd_), qdd(qdd_), memo(memo_) {
      const auto f = c.lift_angle_form();
      const auto& k = links[static_cast<std::size_t>(f.joint)];
      if (k.revolute && value_of(f.sign) * value_of(k.th0) == value_of(f.offset)) {
        joint = f.joint;  // ψ = sign·(θ⁰ + q_j) = sign·θ_j
        sign = T(value_of(f.sign));
      } else {
        angle = c.template lift_angle<T>(q);
      }
    }
    bool extra_angle(angle_sum<T>& a) const {
      if (joint >= 0) return false;
      a = angle;
      return true;
    }
    void operator()(const T* cs, const T* sn) const {
      const int j = joint >= 0 ? joint : static_cast<int>(qd.size());
      memo = c.lift_into(eta, eta_dot, qd, qdd, sin_cos<T>{joint >= 0 ? T(sign * sn[j]) : sn[j], cs[j]});
    }
    const Cx& c;
    const E& eta;
    const ED& eta_dot;
    Mp& qd;
    Mp& qdd;
    sin_cos<T>& memo;
    angle_sum<T> angle{T(0), T(0)};
    int joint = -1;
    T sign = T(1);
  };
};
}  // namespace detail

template <class S, int N, pfaffian_constraint C>
auto inverse_dynamics(const chain<S, N>& ch, const C& c, rne_options o = {}) {
  auto id = detail::nh_pipeline(ch, c, o, project(c));
  if constexpr (N == C::n_at_compile_time)
    return detail::scratch_inverse_dynamics<decltype(id), S, C>(std::move(id));
  else
    return id;
}

/// As inverse_dynamics, returning (τ, λ).
template <class S, int N, pfaffian_constraint C>
auto inverse_dynamics_with_forces(const chain<S, N>& ch, const C& c, rne_options o = {}) {
  return detail::nh_pipeline(ch, c, o, constraint_forces(c));
}

namespace detail {
/// out ∘ rne ∘ lift on a tree (run-time sized; a compile-time-sized constraint's ξ resized).
template <class S, class C, class Out>
auto nh_tree_pipeline(const tree<S>& t, const C& c, rne_options o, Out out) {
  if (c.dof() != t.dof())
    throw model_error("model '" + t.name() + "': the constraint is over " + std::to_string(c.dof()) +
                      " joints, the tree has " + std::to_string(t.dof()));
  if constexpr (C::n_at_compile_time == dynamic)
    return compose(std::move(out), rne(t, o), lift(c));
  else
    return compose(std::move(out), rne(t, o), resize_fn<dynamic>{}, lift(c));
}
}  // namespace detail

/// The nonholonomic inverse dynamics of a tree: project ∘ rne ∘ lift, the constraint over the
/// tree's joints in q order.
template <class S, pfaffian_constraint C>
auto inverse_dynamics(const tree<S>& t, const C& c, rne_options o = {}) {
  return detail::nh_tree_pipeline(t, c, o, project(c));
}
/// As inverse_dynamics on a tree, returning (τ, λ).
template <class S, pfaffian_constraint C>
auto inverse_dynamics_with_forces(const tree<S>& t, const C& c, rne_options o = {}) {
  return detail::nh_tree_pipeline(t, c, o, constraint_forces(c));
}

}  // namespace nhdyn
