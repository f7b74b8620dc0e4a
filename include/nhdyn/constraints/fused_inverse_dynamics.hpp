#pragma once
/// \file constraints/fused_inverse_dynamics.hpp
/// The one fused path of the nonholonomic inverse dynamics, and `inverse_dynamics(chain, c)`,
/// which uses it for its call (its `evaluate`, on a run-time-sized chain, is the stages'
/// detail::staged_inverse_dynamics). Everything else (the tree form,
/// `inverse_dynamics_with_forces`, user pipelines) is the composition project ∘ rne ∘ lift of
/// constraints/stages.hpp (where run-time sized, with its `evaluate` into storage).
///
/// What it buys (nhdyn_bench `nh_fused/<model>/{fixed, run_time}`, paired, ratio = fused /
/// composition; g++ 12.2.0 -O3 -march=native, 2026-11-25): paper5 0.82 (fixed) and 0.74
/// (run-time sized), a differential drive with 2 arm joints 0.86 / 0.78, with 8: 0.91 / 0.88,
/// with 48: 0.94 / 0.92. It exists because on the paper's robot, what the project's targets
/// are set on, it buys more than the 15 % a fused path must; on long arms it buys less (rne
/// dominates) and is kept only because it is the same code. Its numbers are the composition's
/// bit for bit (tests/test_constraints.cpp; the benchmark checks it too).
#include "stages.hpp"

namespace nhdyn {
namespace detail {

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
    // Run-time sized: on the stack up to 256 joints, beyond in a heap block the thread keeps
    // (detail/small_buffer.hpp). Compile-time sized:
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
  if constexpr (N == C::n_at_compile_time)  // the call fused; run-time sized, evaluate too
    return detail::with_evaluate<S, N, C, false>(detail::scratch_inverse_dynamics<decltype(id), S, C>(std::move(id)));
  else
    return id;
}

}  // namespace nhdyn
