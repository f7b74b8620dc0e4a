#pragma once
/// \file dynamics/forward_dynamics.hpp
/// Holonomic forward dynamics q̈ = FD(q, q̇, τ) of a chain or a tree, by one of two algorithms:
///
/// - `fd_method::crba_ldlt`: M(q) by the composite-rigid-body algorithm, h by rne, solved by
///   LDLᵀ (detail/ldlt.hpp: refuses a matrix singular by its scaled criterion);
/// - `fd_method::aba`: Featherstone's articulated-body algorithm (dynamics/aba.hpp), O(n),
///   never forming M;
/// - `fd_method::automatic` (default): ABA from `aba_from` joints on (9: on the benchmark's
///   chains CRBA + LDLᵀ is 3–19 % faster at 5 and 6 joints, ABA 17 % faster at 12 and 1.8× at
///   24, docs/performance.md), CRBA + LDLᵀ below — unless M's diagonally scaled pivots show it ill-conditioned (scaled ratio past
///   √(1/ε) of the scalar: 6.7e7 in double, 4.1e3 in float, where LDLᵀ keeps fewer than half
///   the digits): then ABA answers, which is more accurate there (docs/accuracy.md, mass
///   spans). Where LDLᵀ refuses M (not positive definite, or a scaled ratio past 1/ε: no digit
///   left), the refusal stands; `fd_method::aba` asks ABA regardless.
///
/// An optional last argument, external wrenches (dynamics/wrench.hpp), adds their generalized
/// force to τ. `rne_options` drop gravity and/or the velocity terms, for both algorithms;
/// `fd.with(friction(model))` puts the joints' friction on the bias side,
/// q̈ = M⁻¹(τ − h − τ_f(q̇)) (dynamics/terms.hpp: the terms a computation includes).
///
/// `evaluate(q, q̇, τ, ws, q̈)` writes q̈ into a vector the caller reuses, with M, h, M's
/// factor, a zero q̈ for h and (with friction) τ − τ_f(q̇) in a `forward_dynamics_scratch`
/// reused as well: on a chain or a tree of any size, no heap allocation once both have their
/// size (ABA's scratch beyond its stack part, 51 bodies, is a block its thread keeps:
/// detail/small_buffer.hpp).
/// The call runs the same steps in a workspace its thread keeps (detail::thread_kept): in the
/// model's scalar, with friction and applied forces too (those that write into storage, as
/// external_wrenches does), q̈ is its one allocation.
#include <cmath>
#include <optional>

#include "../detail/ldlt.hpp"
#include "../detail/small_buffer.hpp"
#include "aba.hpp"
#include "friction.hpp"
#include "mass_matrix.hpp"
#include "tree.hpp"

namespace nhdyn {

enum class fd_method { automatic, crba_ldlt, aba };

/// How forward_dynamics chooses (see the file comment).
struct fd_options {
  fd_method method = fd_method::automatic;
  int aba_from = 9;                  ///< automatic: ABA from this many joints on
  double aba_scaled_condition = 0;   ///< automatic: ABA past this scaled pivot ratio of M (0: √(1/ε) of T)
};

/// What forward_dynamics_fn::evaluate keeps from call to call: M(q), h(q, q̇) and M's LDLᵀ
/// factor (CRBA + LDLᵀ; ABA needs none of them), and τ − τ_f(q̇) with a friction model (both).
template <class T, int N>
struct forward_dynamics_scratch {
  Eigen::Matrix<T, N, N> M;
  vecN<T, N> h;
  ldlt<T, N> factor;
  vecN<T, N> net;  ///< τ − τ_f(q̇), with a friction model; τ + Q_ext(q) (− τ_f), with applied forces
  vecN<T, N> zero;  ///< q̈ = 0, for h = rne(q, q̇, 0): rne reads vectors from storage (kernel_input)
};

/// Model: chain<S, N> or tree<S> (N = dynamic).
template <class S, int N = dynamic, class Model = chain<S, N>>
class forward_dynamics_fn : public stage_tag {
  using rne_type = decltype(rne(std::declval<const Model&>(), rne_options{}));
  using mass_matrix_type = decltype(mass_matrix(std::declval<const Model&>()));

 public:
  explicit forward_dynamics_fn(const Model& m, rne_options o = {}, fd_options f = {})
      : M_(m), rne_(m, o), opt_(o), fd_(f), n_(m.dof()), nq_(m.dof()) {
    if constexpr (std::is_same_v<Model, tree<S>>) nq_ = m.nq();  // a floating tree's q has one more
    if (f.method != fd_method::crba_ldlt) {
      tree<S> t;
      if constexpr (std::is_same_v<Model, tree<S>>)
        t = m;
      else
        t = as_tree(m);
      if (!o.gravity) t = t.with_gravity(vec3<S>::Zero());
      aba_.emplace(t);
    }
  }
  int dof() const { return n_; }
  /// q's entries: dof() + 1 for a floating tree (model/floating.hpp), else dof().
  int nq() const { return nq_; }
  fd_options options() const { return fd_; }

  /// The 2-norm condition number of M(q) (double).
  template <class Q>
  double mass_matrix_condition(const Eigen::MatrixBase<Q>& q) const {
    return condition_number(M_(q));
  }

  /// The same forward dynamics with the joints' friction on the bias side:
  /// q̈ = M⁻¹(τ − h(q, q̇) − τ_f(q̇)) (τ_f: friction(model), dynamics/friction.hpp).
  forward_dynamics_fn with(friction_fn f) const {
    if (f.dof() != n_)
      throw model_error("forward_dynamics: the friction is of " + std::to_string(f.dof()) + " joints, the model has " +
                        std::to_string(n_));
    auto r = *this;
    r.friction_ = std::move(f);
    return r;
  }
  template <class Q, class QD, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<TAU>& tau) const {
    using X = typename Q::Scalar;
    using T = promote_t<promote_t<promote_t<S, X>, typename QD::Scalar>, typename TAU::Scalar>;
    if constexpr (detail::in_scalar<S, Q, QD, TAU>) {  // evaluate's steps: q̈ the one allocation
      return into_new<S>([&](auto& ws, auto& qdd) { evaluate(q, qd, tau, ws, qdd); });
    } else {
      detail::check_size(tau, n_, "tau");
      detail::check_finite(tau, "tau");
      if (friction_) {  // τ − τ_f(q̇): what is left to accelerate the bodies
        const vecN<T, N> net = tau.template cast<T>() - (*friction_)(qd).template cast<T>();
        return solve<T>(q, qd, net);
      }
      return solve<T>(q, qd, tau);
    }
  }

  /// With applied forces (external wrenches, dynamics/wrench.hpp): q̈ for τ + Q_ext(q).
  template <class Q, class QD, class TAU, applied_forces F>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                  const F& fx) const {
    if constexpr (detail::in_scalar<S, Q, QD, TAU> && std::is_same_v<detail::applied_scalar_t<F, Q>, S>) {
      return into_new<S>([&](auto& ws, auto& qdd) { evaluate(q, qd, tau, fx, ws, qdd); });
    } else {
      detail::check_size(tau, n_, "tau");
      return (*this)(q, qd, detail::plus_applied(tau, fx, q));
    }
  }

  /// q̈ into qdd (resized to n), with M, h, M's factor, a zero q̈ and τ − τ_f in ws: the call's numbers,
  /// bit for bit; storage reused from call to call (see the file comment). Inputs in the model's
  /// scalar; qdd must not alias them.
  template <class Q, class QD, class TAU>
    requires detail::in_scalar<S, Q, QD, TAU>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                forward_dynamics_scratch<S, N>& ws, vecN<S, N>& qdd) const {
    detail::check_size(q, nq_, "q");  // before qdd is resized: an aliased input of the wrong size
    detail::check_size(qd, n_, "qd");
    detail::check_size(tau, n_, "tau");
    detail::check_finite(tau, "tau");
    if (friction_) {  // τ − τ_f(q̇) in ws.net: τ_f first, then τ minus it, entry by entry
      friction_->evaluate(qd, ws.net);
      ws.net = tau - ws.net;
      solve_into(q, qd, ws.net, ws, qdd);
    } else {
      solve_into(q, qd, tau, ws, qdd);
    }
  }
  /// …with applied forces (external wrenches, dynamics/wrench.hpp): q̈ for τ + Q_ext(q), the
  /// call's numbers bit for bit; τ + Q_ext in ws.net, so no allocation where the applied forces
  /// write into storage (external_wrenches does).
  template <class Q, class QD, class TAU, applied_forces F>
    requires detail::in_scalar<S, Q, QD, TAU> && std::is_same_v<detail::applied_scalar_t<F, Q>, S>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                const F& fx, forward_dynamics_scratch<S, N>& ws, vecN<S, N>& qdd) const {
    detail::check_size(q, nq_, "q");
    detail::check_size(qd, n_, "qd");
    detail::check_size(tau, n_, "tau");
    qdd.resize(n_);  // τ + Q_ext here until the solve
    qdd = tau;
    detail::add_applied<+1>(fx, q, qdd);
    detail::check_finite(qdd, "tau");
    if (friction_) {  // (τ + Q_ext) − τ_f(q̇), as the call forms it
      friction_->evaluate(qd, ws.net);
      ws.net = qdd - ws.net;
    } else {
      ws.net = qdd;
    }
    solve_into(q, qd, ws.net, ws, qdd);
  }

 private:
  /// run(ws, q̈) into a new q̈ of scalar T, with a workspace its thread keeps on a run-time size
  /// (detail::thread_kept; a fixed size needs no heap): q̈ is the only allocation.
  template <class T, class Run>
  vecN<T, N> into_new(const Run& run) const {
    vecN<T, N> qdd;
    detail::with_kept<forward_dynamics_scratch<T, N>, N == dynamic>([&](auto& ws) { run(ws, qdd); });
    return qdd;
  }
  /// q̈ = M⁻¹(τ − h) as a new vector (any scalar T: the inputs' promoted one).
  template <class T, class Q, class QD, class TAU>
  vecN<T, N> solve(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau) const {
    return into_new<T>([&](auto& ws, auto& qdd) { solve_into(q, qd, tau, ws, qdd); });
  }
  /// q̈ = M⁻¹(τ − h): CRBA + LDLᵀ or ABA as the options say, into qdd (T: qdd's scalar).
  template <class Q, class QD, class TAU, class T>
  void solve_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                  forward_dynamics_scratch<T, N>& ws, vecN<T, N>& qdd) const {
    using X = typename Q::Scalar;
    qdd.resize(n_);
    if (fd_.method == fd_method::aba || (fd_.method == fd_method::automatic && n_ >= fd_.aba_from))
      return by_aba(q, qd, tau, qdd);
    // in the model's scalar, M and h into ws (no allocation); otherwise as new matrices, M in
    // T (a dual τ makes T a dual while M(q) is not)
    constexpr bool into = std::is_same_v<T, S> && std::is_same_v<X, S> && std::is_same_v<typename QD::Scalar, S>;
    if constexpr (into) {
      ws.h.resize(n_);
      ws.zero.setZero(n_);
      rne_.evaluate(q, qd, ws.zero, ws.h);
      M_.evaluate(q, ws.M);
    } else {
      const auto put = [](auto& to, auto&& from) {  // moved in where the types agree: no copy
        using To = std::decay_t<decltype(to)>;
        if constexpr (std::is_same_v<std::decay_t<decltype(from)>, To>)
          to = std::move(from);
        else
          to = from.template cast<typename To::Scalar>();
      };
      put(ws.h, rne_(q, qd, vecN<X, N>::Zero(n_)));
      put(ws.M, M_(q));
    }
    ldlt_factor_into<T, N>(ws.M, ws.factor, "the mass matrix M(q)");
    const double switch_at = fd_.aba_scaled_condition > 0 ? fd_.aba_scaled_condition : std::sqrt(default_max_pivot_ratio<T>());
    if (fd_.method == fd_method::automatic && 1.0 / ws.factor.min_scaled_pivot > switch_at)
      return by_aba(q, qd, tau, qdd);
    qdd = tau.template cast<T>() - ws.h;
    ws.factor.solve_in_place(qdd);
    detail::check_overflow(qdd, "forward_dynamics");
  }

  /// q̈ by ABA into qdd (in place where its scalar is ABA's own for these inputs).
  template <class Q, class QD, class TAU, class T>
  void by_aba(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
              vecN<T, N>& qdd) const {
    using X = typename QD::Scalar;
    const auto run = [&](const auto& v) {  // v: q̇, or zero without velocity terms
      using V = std::decay_t<decltype(v)>;
      using R = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename V::Scalar>, typename TAU::Scalar>;
      if constexpr (std::is_same_v<R, T>)
        aba_->evaluate(q, v, tau, qdd);
      else
        qdd = (*aba_)(q, v, tau).template cast<T>();
    };
    if (opt_.velocity) return run(qd.derived());  // aba checks q̇
    detail::check_size(qd, n_, "qd");  // without velocity terms q̇ is not read, as in rne
    run(vecN<X, dynamic>::Zero(n_));
  }

  mass_matrix_type M_;
  rne_type rne_;
  rne_options opt_;
  fd_options fd_;
  int n_, nq_;
  std::optional<aba_fn<S>> aba_;
  std::optional<friction_fn> friction_;
};

template <class S, int N>
forward_dynamics_fn<S, N> forward_dynamics(const chain<S, N>& c, rne_options o = {}, fd_options f = {}) {
  return forward_dynamics_fn<S, N>(c, o, f);
}
/// The holonomic forward dynamics of a tree.
template <class S>
forward_dynamics_fn<S, dynamic, tree<S>> forward_dynamics(const tree<S>& t, rne_options o = {}, fd_options f = {}) {
  return forward_dynamics_fn<S, dynamic, tree<S>>(t, o, f);
}
/// The tree form's name before chains and trees shared one class.
template <class S>
using tree_forward_dynamics_fn = forward_dynamics_fn<S, dynamic, tree<S>>;

}  // namespace nhdyn
