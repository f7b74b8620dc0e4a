#pragma once
/// \file analysis/derivatives.hpp
/// Analytic first derivatives of the dynamics of any tree, with or without a constraint, built
/// on the recursive ∂τ/∂(q, q̇, q̈) of rne (dynamics/rne_derivatives.hpp) by the chain rule:
///
/// - `inverse_dynamics_derivatives(t, c)(q, η, η̇)`: τ = P(q) v(q, q̇, q̈) with q̇ = S(q)η,
///   q̈ = S(q)η̇ + Ṡ(q, q̇)η and P = (SᵀE)⁻¹Sᵀ (project ∘ rne ∘ lift). With V_q, V_q̇, M the
///   derivatives of rne at the lifted state,
///
///       ∂τ/∂q = P (V_q + V_q̇ ∂q̇/∂q + M ∂q̈/∂q) + ∂(P v)/∂q|_v
///       ∂τ/∂η = P (V_q̇ S + M ∂q̈/∂η),      ∂τ/∂η̇ = P M S.
///
///   The constraint's own pieces — ∂q̇/∂q, ∂q̈/∂q and ∂(Pv)/∂q along the joints D the
///   constraint depends on (`constraint_depends_on`: a differential drive's or wheeled base's
///   heading, a bicycle's heading and steering; every joint for a user constraint) — come from
///   dual numbers through the constraint's functions alone (O(n) each, no dynamics), and
///   ∂q̈/∂η = Ṡ(q, q̇) + Σ_{j∈D} ∂(Sη)/∂q_j S_j,: with Ṡ the derivative of S(q + ε q̇_D) (one
///   dual lane: Ṡ = Σ_j ∂S/∂q_j q̇_j, the time derivative the constraint concept defines), so
///   every constraint type works as it is (τ too is formed with this Ṡ: for a user constraint
///   whose own Ṡ disagrees with S's derivative, τ follows S). τ's derivatives are formed in
///   m rows from the start (Sᵀ∂v/∂q̇, SᵀM, then the products with S), every product with S or
///   Sᵀ planned from S's nonzeros at the call: the arm's identity columns as block copies, a
///   base's few columns as short sums (O(n²) for the whole Jacobian, about a copy's cost).
/// - `forward_dynamics_derivatives(t)(q, q̇, τ)`: q̈ and ∂q̈/∂q = −M⁻¹ ∂τ/∂q, ∂q̈/∂q̇ =
///   −M⁻¹ ∂τ/∂q̇, ∂q̈/∂τ = M⁻¹ (the implicit-function route: ∂τ/∂· at (q, q̇, FD(q, q̇, τ))).
/// - `forward_dynamics_derivatives(t, c)(q, η, τ)`: η̇ and the state-space A = ∂f/∂x, B = ∂f/∂τ
///   of ẋ = f(x, τ), x = (q, η), f = (S(q)η, η̇): with K = ∂τ/∂η̇, ∂η̇/∂(q, η) = −K⁻¹∂τ/∂(q, η),
///   ∂η̇/∂τ = K⁻¹.
///
/// All take external wrenches after the state (`external_wrenches(t, {…})`). The dual-number
/// linearizers of analysis/linearize.hpp compute the same matrices another way (the tests'
/// reference).
#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <tuple>
#include <vector>

#include "../constraints/constraint.hpp"
#include "../constraints/forward_dynamics.hpp"
#include "../constraints/stages.hpp"
#include "../dynamics/forward_dynamics.hpp"
#include "../dynamics/rne_derivatives.hpp"
#include "../dynamics/tree_factor.hpp"
#include "../scalar/dual.hpp"
#include "linearize.hpp"

namespace nhdyn {

namespace detail {
/// A tag no other function object constructed in this process has (copies keep theirs): a
/// number and the address of its counter (a library loaded twice has two counters).
struct object_tag {
  const void* counter = nullptr;
  std::uint64_t id = 0;
  bool operator==(const object_tag&) const = default;
};
inline object_tag next_object_tag() {
  static std::atomic<std::uint64_t> last{0};
  return {&last, ++last};
}

/// A nonzero S_rc (or Ṡ_rc) of a constraint's S at one q.
template <class T>
struct s_nonzero {
  int r, c;
  T s;
};

/// S and Ṡ at one state as the chain rule's products use them: their nonzeros in column
/// order, and the products Sᵀa and aS planned from them column by column of S — runs of at
/// least four unit columns e_r (value exactly 1) whose c and r both step by one (an arm's
/// identity) as block copies, other columns of one nonzero as one product, the rest as sums.
/// Any constraint: the plan is read off S's values at each call.
template <class T>
struct st_plan {
  struct run {
    int c, r, len;
  };
  std::vector<s_nonzero<T>> nz, nz_dot;  ///< S's and Ṡ's nonzeros, in column order
  std::vector<int> first;                ///< column c's: nz[first[c] … first[c + 1])
  std::vector<run> runs;                 ///< unit columns, in runs of four or more
  std::vector<s_nonzero<T>> singles;     ///< the other columns of one nonzero
  std::vector<int> general;              ///< the columns of none or several
  int rows = -1;

  /// Reads S and Ṡ off Se = S(q + ε q̇) (dual<T, 1> entries: values S, derivatives Ṡ). The
  /// last call's nonzero positions are kept while no nonzero lies outside them — counted over
  /// the whole matrix: the nonzeros at the kept positions equal all of its nonzeros (an entry
  /// zero at a kept position only adds a zero term, which a finite product leaves unchanged;
  /// rne's results are checked finite) — else Se is scanned again.
  template <class SE>
  void read(const SE& Se_in) {
    const auto& Se = Se_in.eval();  // a constraint's S may be an expression (holonomic: I)
    const int n = static_cast<int>(Se.rows()), m = static_cast<int>(Se.cols());
    const auto nonzero = [](const auto& x) { return int(!is_exact_zero(x)); };
    bool keep = n == rows && static_cast<int>(first.size()) == m + 1;
    if (keep) {
      int all = 0, at = 0;
      const auto* p = Se.data();
      for (Eigen::Index k = 0; k < Se.size(); ++k) all += nonzero(p[k].value()) + nonzero(p[k].derivative(0));
      for (auto& e : nz) at += nonzero(e.s = T(Se(e.r, e.c).value()));
      for (auto& e : nz_dot) at += nonzero(e.s = T(Se(e.r, e.c).derivative(0)));
      keep = all == at;
    }
    if (!keep) {
      rows = n;
      nz.clear(), nz_dot.clear();
      for (int c = 0; c < m; ++c)
        for (int r = 0; r < n; ++r) {
          const auto& e = Se(r, c);
          if (nonzero(e.value())) nz.push_back({r, c, T(e.value())});
          if (nonzero(e.derivative(0))) nz_dot.push_back({r, c, T(e.derivative(0))});
        }
      starts(nz, m, first);
    }
    plan(m);
  }
  /// d = Sᵀa (a: n rows, d: a writable expression of m rows and a's columns; both with
  /// contiguous columns).
  template <class A, class Dst>
  void St_times(const A& a, Dst&& d) const {
    static_assert(A::InnerStrideAtCompileTime == 1 && std::decay_t<Dst>::InnerStrideAtCompileTime == 1);
    const Eigen::Index cols = a.cols();
    for (const run& u : runs)
      for (Eigen::Index j = 0; j < cols; ++j) copy_short(&a.coeffRef(u.r, j), u.len, &d.coeffRef(u.c, j));
    for (const auto& e : singles)
      for (Eigen::Index j = 0; j < cols; ++j) d.coeffRef(e.c, j) = e.s * a.coeffRef(e.r, j);
    for (const int c : general) {
      const int k0 = first[std::size_t(c)], k1 = first[std::size_t(c) + 1];
      for (Eigen::Index j = 0; j < cols; ++j) {
        const T* from = &a.coeffRef(0, j);
        T x(0);
        for (int k = k0; k < k1; ++k) x += nz[std::size_t(k)].s * from[nz[std::size_t(k)].r];
        d.coeffRef(c, j) = x;
      }
    }
  }
  /// d = aS (a: n columns, d: a writable expression of a's rows and m columns; both with
  /// contiguous columns).
  template <class A, class Dst>
  void times_S(const A& a, Dst&& d) const {
    static_assert(A::InnerStrideAtCompileTime == 1 && std::decay_t<Dst>::InnerStrideAtCompileTime == 1);
    const int n = static_cast<int>(a.rows());
    for (const run& u : runs)
      for (int k = 0; k < u.len; ++k) copy_short(&a.coeffRef(0, u.r + k), n, &d.coeffRef(0, u.c + k));
    for (const auto& e : singles) {
      const T* from = &a.coeffRef(0, e.r);
      T* to = &d.coeffRef(0, e.c);
      for (int i = 0; i < n; ++i) to[i] = e.s * from[i];
    }
    for (const int c : general) {
      T* to = &d.coeffRef(0, c);
      std::fill_n(to, n, T(0));
      for (int k = first[std::size_t(c)]; k < first[std::size_t(c) + 1]; ++k) {
        const T s = nz[std::size_t(k)].s;
        const T* from = &a.coeffRef(0, nz[std::size_t(k)].r);
        for (int i = 0; i < n; ++i) to[i] += s * from[i];
      }
    }
  }

 private:
  void plan(int m) {
    runs.clear(), singles.clear(), general.clear();
    const auto count = [&](int c) { return first[std::size_t(c) + 1] - first[std::size_t(c)]; };
    const auto unit_row = [&](int c) {  // r when S's column c is e_r, else −1
      if (count(c) != 1) return -1;
      const auto& e = nz[std::size_t(first[std::size_t(c)])];
      return is_exact_zero(T(e.s - T(1))) ? e.r : -1;
    };
    for (int c = 0; c < m;) {
      const int r0 = unit_row(c);
      int len = 1;
      while (r0 >= 0 && c + len < m && unit_row(c + len) == r0 + len) ++len;
      if (r0 >= 0 && len >= 4) {
        runs.push_back({c, r0, len});
        c += len;
        continue;
      }
      for (const int end = c + len; c < end; ++c) {
        if (count(c) == 1)
          singles.push_back(nz[std::size_t(first[std::size_t(c)])]);
        else
          general.push_back(c);
      }
    }
  }
  static void starts(const std::vector<s_nonzero<T>>& z, int m, std::vector<int>& f) {
    f.assign(static_cast<std::size_t>(m) + 1, 0);
    for (const auto& e : z) ++f[static_cast<std::size_t>(e.c) + 1];
    for (int c = 0; c < m; ++c) f[std::size_t(c) + 1] += f[std::size_t(c)];
  }
  /// to[0 … len) = from[0 … len) (not overlapping) in fixed-size chunks of four, the last one
  /// overlapping the one before: for the few dozen entries of a column, Eigen's and memmove's
  /// loops spend more on their set-up and tails than on the copy.
  static void copy_short(const T* from, int len, T* to) {
    using V = Eigen::Matrix<T, 4, 1>;
    if (len < 4) {  // not from the runs (four or more), but safe for any length
      std::copy_n(from, len, to);
      return;
    }
    int i = 0;
    for (; i + 4 <= len; i += 4) Eigen::Map<V>(to + i) = Eigen::Map<const V>(from + i);
    if (i < len) Eigen::Map<V>(to + len - 4) = Eigen::Map<const V>(from + len - 4);
  }
};
/// One dual pass's vectors of K lanes: x = q + Σ ε_k e_j, its lift (xd, xdd), v in duals and
/// the projection Pv (run-time sized; a result's scratch keeps them between calls).
template <class T, int K>
struct dual_lanes {
  vecN<dual<T, K>, Eigen::Dynamic> x, xd, xdd, v, pv;
};
/// `kept` when N is run-time (its storage reused from call to call), else `local` (on the stack).
template <int N, class Kept, class Local>
auto& run_time_or_local(Kept& kept, Local& local) {
  if constexpr (N == Eigen::Dynamic)
    return kept;
  else
    return local;
}
}  // namespace detail

/// τ and ∂τ/∂(q, η, η̇) of the nonholonomic inverse dynamics, and ∂q̇/∂q of the lift
/// (q̇ = S(q)η; the kinematic rows of a state-space model).
template <class T, int M>
struct nh_derivatives_result {
  using scalar_type = T;
  vecN<T, M> tau;
  Eigen::Matrix<T, M, Eigen::Dynamic> dq;  ///< ∂τ/∂q (p × n; p = m but for a constraint with p actuators)
  Eigen::Matrix<T, M, M> deta, deta_dot;   ///< ∂τ/∂η, ∂τ/∂η̇ (p × m)
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> dqd_dq;  ///< ∂(Sη)/∂q (n × n)
  /// rne's derivatives at the lifted state (q, Sη, Sη̇ + Ṡη): ∂v/∂q, ∂v/∂q̇, M and v.
  rne_derivatives_result<T> id;
  /// [∂τ/∂q  ∂τ/∂η  ∂τ/∂η̇], as inverse_dynamics_linearizer gives it.
  Eigen::Matrix<T, M, Eigen::Dynamic> J() const {
    Eigen::Matrix<T, M, Eigen::Dynamic> j(tau.size(), dq.cols() + deta.cols() + deta_dot.cols());
    j << dq, deta, deta_dot;
    return j;
  }
  /// The outputs moved into a new result (no copy), this one keeping its scratch (`work`).
  nh_derivatives_result take_outputs() {
    nh_derivatives_result r;
    r.tau = std::move(tau), r.dq = std::move(dq), r.deta = std::move(deta), r.deta_dot = std::move(deta_dot);
    r.dqd_dq = std::move(dqd_dq), r.id = std::move(id);
    return r;
  }
  /// Scratch of the computation, kept by evaluate for its next call (empty in a result that
  /// operator() returns): S(q + ε q̇) where the constraint writes into a matrix (S_into), S's
  /// and Ṡ's nonzeros and Sᵀ's plan, the constraint's [∂q̇/∂q_j; ∂q̈/∂q_j; ∂(Pv)/∂q_j] for
  /// j ∈ D, W = Sᵀ ∂v/∂q̇, Z = Sᵀ M and, where SᵀE ≠ I, Sᵀ[X_q X_η X_η̇ v].
  struct scratch {
    detail::st_plan<T> st;
    Eigen::Matrix<dual<T, 1>, Eigen::Dynamic, Eigen::Dynamic> se;
    detail::object_tag se_owner;  ///< the function object (or a copy) whose constraint wrote se
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> jd;
    Eigen::Matrix<T, M, Eigen::Dynamic> w, z, stx;
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> solved;  ///< (SᵀE)⁺ stx (p rows)
    /// The inputs in T, the lifted (q̇, q̈), q + ε q̇ and the dual passes' vectors (K = 1, 2, 4
    /// lanes): kept for a run-time-sized constraint (compile-time sizes live on the stack).
    vecN<T, Eigen::Dynamic> q, qd, qdd;
    vecN<T, M> eta, eta_dot;
    vecN<dual<T, 1>, Eigen::Dynamic> q_eps;
    std::tuple<detail::dual_lanes<T, 1>, detail::dual_lanes<T, 2>, detail::dual_lanes<T, 4>> lanes;
  } work;
};


/// ∂τ/∂(q, η, η̇) of the nonholonomic inverse dynamics of a tree and any constraint (see the
/// file comment): `inverse_dynamics_derivatives(t, c)(q, eta, eta_dot [, w])`;
/// `evaluate(q, eta, eta_dot [, w], out)` reuses out's matrices and scratch (inputs and
/// wrenches in the model's scalar).
template <class S, class C>
class inverse_dynamics_derivatives_fn {
 public:
  inverse_dynamics_derivatives_fn(const tree<S>& t, const C& c, rne_options o = {}) : d_(t, o), c_(c), project_(c) {
    if (c.dof() != t.dof())
      throw input_error("inverse_dynamics_derivatives: the constraint is for " + std::to_string(c.dof()) +
                        " joints, model '" + t.name() + "' has " + std::to_string(t.dof()));
    for (int j = 0; j < c.dof(); ++j) {
      dcol_.push_back(constraint_depends_on(c, j) ? static_cast<int>(cols_.size()) : -1);
      if (dcol_.back() >= 0) cols_.push_back(j);
    }
  }
  int dof() const { return c_.dof(); }
  int m() const { return c_.m(); }
  const C& constraint() const { return c_; }
  /// The joints whose columns of ∂q̇/∂q, ∂q̈/∂q and ∂P/∂q are seeded as dual directions.
  const std::vector<int>& constraint_columns() const { return cols_; }

  /// The call: in the model's scalar, evaluate into a result its thread keeps and the outputs
  /// moved out (they are its only allocations); in another scalar, a result of its own.
  template <class Q, class E, class ED>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                  const Eigen::MatrixBase<ED>& eta_dot) const {
    using R = nh_derivatives_result<result_scalar<Q, E, ED>, C::m_at_compile_time>;
    if constexpr (detail::in_scalar<S, Q, E, ED>) {
      return detail::with_kept<R>([&](R& k) { evaluate(q, eta, eta_dot, k); return k.take_outputs(); });
    } else {
      R out;
      run(q, eta, eta_dot, out, [&](const auto& x, const auto& xd, const auto& xdd, auto& r) { r = d_(x, xd, xdd); });
      out.work = {};
      return out;
    }
  }
  template <class Q, class E, class ED, class Kin, class W>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                  const external_wrenches_fn<Kin, W>& w) const {
    using R = nh_derivatives_result<promote_t<result_scalar<Q, E, ED>, W>, C::m_at_compile_time>;
    if constexpr (detail::in_scalar<S, Q, E, ED> && std::is_same_v<W, S>) {
      return detail::with_kept<R>([&](R& k) { evaluate(q, eta, eta_dot, w, k); return k.take_outputs(); });
    } else {
      R out;
      run(q, eta, eta_dot, out,
          [&](const auto& x, const auto& xd, const auto& xdd, auto& r) { r = d_(x, xd, xdd, w); });
      out.work = {};
      return out;
    }
  }
  /// Into a result whose storage (matrices and scratch) is reused from call to call, for
  /// inputs in the model's scalar: no heap allocation once `out` has its sizes, where the
  /// constraint lifts and projects into given storage (every built-in base constraint; a
  /// user constraint's own S products may allocate). `out` must not alias the inputs; after
  /// an exception its contents are unspecified.
  template <class Q, class E, class ED>
    requires detail::in_scalar<S, Q, E, ED>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                nh_derivatives_result<S, C::m_at_compile_time>& out) const {
    run(q, eta, eta_dot, out,
        [&](const auto& x, const auto& xd, const auto& xdd, auto& r) { d_.evaluate(x, xd, xdd, r); });
  }
  /// …with external wrenches in the model's scalar.
  template <class Q, class E, class ED, class Kin>
    requires detail::in_scalar<S, Q, E, ED>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                const external_wrenches_fn<Kin, S>& w, nh_derivatives_result<S, C::m_at_compile_time>& out) const {
    run(q, eta, eta_dot, out,
        [&](const auto& x, const auto& xd, const auto& xdd, auto& r) { d_.evaluate(x, xd, xdd, w, r); });
  }

 private:
  template <class Q, class E, class ED>
  using result_scalar = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename E::Scalar>, typename ED::Scalar>;

  template <class Q, class E, class ED, class T, int M, class D>
  void run(const Eigen::MatrixBase<Q>& q_in, const Eigen::MatrixBase<E>& eta_in, const Eigen::MatrixBase<ED>& eta_dot_in,
           nh_derivatives_result<T, M>& out, const D& derivatives) const {
    constexpr int N = C::n_at_compile_time;
    detail::check_reduced_state(c_, q_in, eta_in, eta_dot_in);
    const int n = c_.dof(), m = c_.m();
    auto& w = out.work;
    using D1 = dual<T, 1>;
    vecN<T, N> q_local, qd_local, qdd_local;  // compile-time sizes: here; run-time: w's
    vecN<D1, N> q_eps_local;
    auto& q = detail::run_time_or_local<N>(w.q, q_local);
    auto& qd = detail::run_time_or_local<N>(w.qd, qd_local);
    auto& qdd = detail::run_time_or_local<N>(w.qdd, qdd_local);
    auto& q_eps = detail::run_time_or_local<N>(w.q_eps, q_eps_local);
    auto& eta = w.eta;
    auto& eta_dot = w.eta_dot;
    q = q_in.template cast<T>();
    eta = eta_in.template cast<T>();
    eta_dot = eta_dot_in.template cast<T>();
    qd.resize(n);
    qdd.resize(n);
    // (q̇, q̈) = (Sη, Sη̇ + Ṡη): the constraint's lift into given storage where it has one,
    // else q̇ here and q̈ from S's and Ṡ's nonzeros below
    constexpr bool lifts_into = requires { c_.lift_into(q, eta, eta_dot, qd, qdd); };
    if constexpr (lifts_into)
      c_.lift_into(q, eta, eta_dot, qd, qdd);
    else
      qd = apply_S(c_, q, eta);
    // S and Ṡ at once: S depends on q_D alone, so Ṡ(q, q̇) = Σ_{j∈D} ∂S/∂q_j q̇_j is the
    // derivative of S(q + ε q̇_D) (one dual lane; the time derivative the concept defines)
    q_eps = q.template cast<D1>();
    for (const int j : cols_) q_eps(j).derivative(0) = qd(j);
    auto& st = w.st;
    if constexpr (has_S_into<C, vecN<D1, N>, decltype(w.se)>) {
      // into the S(q + ε q̇) of this object's (or a copy's) last call, zeros at the first: the
      // constraint writes only the entries that can be nonzero
      if (w.se_owner != id_ || w.se.rows() != n || w.se.cols() != m) {
        w.se.setZero(n, m);
        w.se_owner = id_;
      }
      c_.S_into(q_eps, w.se);
      st.read(w.se);
    } else {
      st.read(c_.S(q_eps));
    }
    // q̈ = Sη̇ + Ṡη (unless lifted above), and rne's derivatives at the lifted state
    if constexpr (!lifts_into) {
      qdd.setZero(n);
      for (const auto& e : st.nz) qdd(e.r) += e.s * eta_dot(e.c);
      for (const auto& e : st.nz_dot) qdd(e.r) += e.s * eta(e.c);
    }
    derivatives(q, qd, qdd, out.id);
    const auto& r = out.id;
    // The constraint's pieces, by duals along q_j for the joints it depends on (j ∈ D): rows
    // [∂q̇/∂q_j; ∂q̈/∂q_j; ∂(P v)/∂q_j] with v held.
    const vecN<T, N>& v = r.tau;
    const int nd = static_cast<int>(cols_.size()), p = actuator_count(c_);
    auto& Jd = w.jd;
    Jd.resize(2 * n + p, nd);
    // Jd: column k is the derivative along q_{D_k}: one dual pass of K lanes per K joints of D
    // (K = 1, 2 or 4: a base's heading, a bicycle's heading and steering, more)
    const auto passes = [&]<int K>(std::integral_constant<int, K>) {
      using DK = dual<T, K>;
      auto& lanes = std::get<detail::dual_lanes<T, K>>(w.lanes);
      vecN<DK, N> x_local, xd_local, xdd_local, v_local;
      auto& x = detail::run_time_or_local<N>(lanes.x, x_local);
      auto& xd = detail::run_time_or_local<N>(lanes.xd, xd_local);
      auto& xdd = detail::run_time_or_local<N>(lanes.xdd, xdd_local);
      x.resize(n);
      xd.resize(n);
      xdd.resize(n);
      const auto put = [&](int row0, int c0, const auto& y) {
        for (Eigen::Index i = 0; i < y.size(); ++i)
          for (int k = 0; k < K && c0 + k < nd; ++k) Jd(row0 + i, c0 + k) = y(i).derivative(k);
      };
      for (int c0 = 0; c0 < nd; c0 += K) {
        for (int i = 0; i < n; ++i) x(i) = DK(q(i));
        for (int k = 0; k < K && c0 + k < nd; ++k) x(cols_[static_cast<std::size_t>(c0 + k)]).derivative(k) = T(1);
        if constexpr (requires { c_.lift_into(x, eta, eta_dot, xd, xdd); }) {
          // the lift in one pass, and P v with its memo, into the lanes' storage (the stages'
          // own `into`, constraints/stages.hpp)
          const auto memo = c_.lift_into(x, eta, eta_dot, xd, xdd);
          auto& vd = detail::run_time_or_local<N>(lanes.v, v_local);
          vd = v.template cast<DK>();
          lanes.pv.resize(p);
          project_.into(x, vd, memo, lanes.pv);
          put(2 * n, c0, lanes.pv);
        } else {
          const vecN<DK, M> e = eta.template cast<DK>(), ed = eta_dot.template cast<DK>();
          xd = apply_S(c_, x, e);
          xdd = apply_S(c_, x, ed);
          xdd += apply_Sdot(c_, x, xd, e);
          put(2 * n, c0, detail::solve_StE(c_, x, apply_St(c_, x, vecN<DK, N>(v.template cast<DK>()))));
        }
        put(0, c0, xd);
        put(n, c0, xdd);
      }
    };
    if (nd == 1)
      passes(std::integral_constant<int, 1>{});
    else if (nd == 2)
      passes(std::integral_constant<int, 2>{});
    else if (nd > 2)
      passes(std::integral_constant<int, 4>{});
    // τ's derivatives = (SᵀE)⁻¹ Sᵀ [X_q  X_η  X_η̇  v] with
    //   X_q = V_q + V_q̇ ∂q̇/∂q + M ∂q̈/∂q (the middle terms in columns D only),
    //   X_η = V_q̇ S + M ∂q̈/∂η, ∂q̈/∂η = ∂(Ṡ(q, Sη)η)/∂η = Ṡ(q, q̇) + Σ_{j∈D} ∂(Sη)/∂q_j S_j,:
    //         (Ṡ = Σ_j ∂S/∂q_j q̇_j is linear in q̇ and S depends on q_D alone),
    //   X_η̇ = M S,
    // in m rows from the start: with W = Sᵀ V_q̇ and Z = Sᵀ M (m × n),
    //   Sᵀ X_q = Sᵀ V_q + W ∂q̇/∂q + Z ∂q̈/∂q,   Sᵀ X_η = W S + Z ∂q̈/∂η,   Sᵀ X_η̇ = Z S,
    // each product with S or Sᵀ a block copy per run of S's unit columns (st_plan).
    auto& W = w.w;
    auto& Z = w.z;
    W.resize(m, n);
    Z.resize(m, n);
    st.St_times(r.dqd, W);
    st.St_times(r.M, Z);
    const auto fill = [&](auto&& Dq, auto&& De, auto&& Ded, auto&& Tau) {
      st.St_times(r.dq, Dq);
      for (int k = 0; k < nd; ++k)
        for (int rr = 0, j = cols_[static_cast<std::size_t>(k)]; rr < n; ++rr) {
          if (const T a1 = Jd(rr, k); !is_exact_zero(a1)) Dq.col(j) += a1 * W.col(rr);
          if (const T a2 = Jd(n + rr, k); !is_exact_zero(a2)) Dq.col(j) += a2 * Z.col(rr);
        }
      st.times_S(W, De);
      for (const auto& e : st.nz_dot) De.col(e.c) += e.s * Z.col(e.r);
      for (const auto& e : st.nz)
        if (const int k = dcol_[std::size_t(e.r)]; k >= 0)
          for (int rr = 0; rr < n; ++rr)
            if (const T a = Jd(rr, k); !is_exact_zero(a)) De.col(e.c) += (a * e.s) * Z.col(rr);
      st.times_S(Z, Ded);
      st.St_times(v, Tau);
    };
    out.tau.resize(p);  // p = m but for a constraint with p actuators (wheeled_base)
    out.dq.resize(p, n);
    out.deta.resize(p, m);
    out.deta_dot.resize(p, m);
    if constexpr (detail::projection_is_St<C, vecN<T, N>>) {
      fill(out.dq, out.deta, out.deta_dot, out.tau);
    } else {
      auto& StX = w.stx;
      auto& X = w.solved;
      StX.resize(m, n + 2 * m + 1);
      fill(StX.leftCols(n), StX.middleCols(n, m), StX.middleCols(n + m, m), StX.col(n + 2 * m));
      if constexpr (requires { c_.solve_actuation_into(q, StX, X); })
        c_.solve_actuation_into(q, StX, X);  // into kept storage (wheeled_base)
      else
        X = detail::solve_StE(c_, q, std::move(StX));
      out.tau = X.col(n + 2 * m);
      out.dq = X.leftCols(n);
      out.deta = X.middleCols(n, m);
      out.deta_dot = X.middleCols(n + m, m);
    }
    out.dqd_dq.setZero(n, n);
    for (int k = 0; k < nd; ++k) {
      const int j = cols_[static_cast<std::size_t>(k)];
      out.dq.col(j) += Jd.col(k).tail(p);
      out.dqd_dq.col(j) = Jd.col(k).head(n);
    }
  }

  rne_derivatives_fn<S> d_;
  C c_;
  project_fn<C> project_;  // P v into given storage (the dual passes)
  detail::object_tag id_ = detail::next_object_tag();  // copies share it: they hold the same constraint
  std::vector<int> cols_;  // D: the joints the constraint depends on
  std::vector<int> dcol_;  // per joint, its index in cols_ (−1 if not in D)
};

template <class S, class C>
inverse_dynamics_derivatives_fn<S, C> inverse_dynamics_derivatives(const tree<S>& t, const C& c,
                                                                   rne_options o = {}) {
  return inverse_dynamics_derivatives_fn<S, C>(t, c, o);
}

/// q̈ and its derivatives (holonomic forward dynamics).
template <class T>
struct fd_derivatives_result {
  Eigen::Matrix<T, Eigen::Dynamic, 1> qdd;
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> dq, dqd, Minv;  ///< ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ = M⁻¹
  /// The inverse dynamics' derivatives at (q, q̇, q̈): ∂τ/∂q, ∂τ/∂q̇ and M (and τ).
  rne_derivatives_result<T> id;
  /// A, B of ẋ = (q̇, q̈), x = (q, q̇), u = τ.
  state_space<T, Eigen::Dynamic, Eigen::Dynamic> state_space_model() const {
    const Eigen::Index n = qdd.size();
    state_space<T, Eigen::Dynamic, Eigen::Dynamic> s;
    s.A.setZero(2 * n, 2 * n);
    s.A.block(0, n, n, n).setIdentity();
    s.A.block(n, 0, n, n) = dq;
    s.A.block(n, n, n, n) = dqd;
    s.B.setZero(2 * n, n);
    s.B.bottomRows(n) = Minv;
    return s;
  }
  /// The outputs moved into a new result (no copy), this one keeping its scratch.
  fd_derivatives_result take_outputs() {
    fd_derivatives_result r;
    r.qdd = std::move(qdd), r.dq = std::move(dq), r.dqd = std::move(dqd), r.Minv = std::move(Minv);
    r.id = std::move(id);
    return r;
  }
  /// Scratch of the computation, kept by evaluate for its next call (empty in a result that
  /// operator() returns): M's factorisation and the right-hand sides [∂τ/∂q  ∂τ/∂q̇  I], and
  /// the forward dynamics' own (M, h, their factor where CRBA + LDLᵀ answers).
  tree_ltl<T> factor;
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rhs;
  forward_dynamics_scratch<T, Eigen::Dynamic> fd;
};

/// ∂q̈/∂(q, q̇, τ) of a tree's forward dynamics: `forward_dynamics_derivatives(t)(q, qd, tau [, w])`.
/// q̈ by forward_dynamics(t) (its checks and its choice of algorithm); M⁻¹ and the products
/// with it by the tree-sparse factorisation M = LᵀL (dynamics/tree_factor.hpp) of the M that
/// rne_derivatives returns (refused, naming the model, when M is not positive definite).
/// `evaluate(q, qd, tau [, w], out)` reuses out's matrices and scratch from call to call
/// (inputs and wrenches in the model's scalar): no heap allocation once out has the tree's size,
/// on trees of any size (the kernels' scratch beyond its stack part is a block the thread keeps,
/// detail/small_buffer.hpp). The call in the model's scalar runs evaluate into a result its
/// thread keeps and moves the outputs out (detail::with_kept): they are its only allocations.
template <class S>
class fd_derivatives_fn {
 public:
  explicit fd_derivatives_fn(const tree<S>& t, rne_options o = {}, fd_options f = {})
      : fd_(t, o, f), d_(t, o), name_(t.name()) {
    std::vector<int> parent;
    for (int i = 0; i < t.dof(); ++i) parent.push_back(t.parent(i));
    sparsity_ = tree_sparsity(parent);
  }
  int dof() const { return d_.dof(); }

  /// The call: in the model's scalar, evaluate into a result its thread keeps and the outputs
  /// moved out (they are its only allocations); in another scalar, a result of its own.
  template <class Q, class QD, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<TAU>& tau) const {
    if constexpr (detail::in_scalar<S, Q, QD, TAU>) {
      using R = fd_derivatives_result<S>;
      return detail::with_kept<R>([&](R& k) { evaluate(q, qd, tau, k); return k.take_outputs(); });
    } else {
      const auto qdd = fd_(q, qd, tau);
      return finish(qdd, d_(q, qd, qdd));
    }
  }
  template <class Q, class QD, class TAU, class Kin, class W>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                  const external_wrenches_fn<Kin, W>& w) const {
    if constexpr (detail::in_scalar<S, Q, QD, TAU> && std::is_same_v<W, S>) {
      using R = fd_derivatives_result<S>;
      return detail::with_kept<R>([&](R& k) { evaluate(q, qd, tau, w, k); return k.take_outputs(); });
    } else {
      const auto qdd = fd_(q, qd, tau, w);
      return finish(qdd, d_(q, qd, qdd, w));
    }
  }
  /// Into a result whose storage is reused (see the class comment). `out` must not alias the
  /// inputs; after an exception its contents are unspecified.
  template <class Q, class QD, class TAU>
    requires detail::in_scalar<S, Q, QD, TAU>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                fd_derivatives_result<S>& out) const {
    fd_.evaluate(q, qd, tau, out.fd, out.qdd);
    d_.evaluate(q, qd, out.qdd, out.id);
    solve(out);
  }
  /// …with external wrenches in the model's scalar.
  template <class Q, class QD, class TAU, class Kin>
    requires detail::in_scalar<S, Q, QD, TAU>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                const external_wrenches_fn<Kin, S>& w, fd_derivatives_result<S>& out) const {
    fd_.evaluate(q, qd, tau, w, out.fd, out.qdd);  // τ + Q_ext in out.fd's scratch: no allocation
    d_.evaluate(q, qd, out.qdd, w, out.id);
    solve(out);
  }

 private:
  template <class QDD, class T>
  fd_derivatives_result<T> finish(const QDD& qdd, rne_derivatives_result<T>&& r) const {
    fd_derivatives_result<T> out;
    out.qdd = qdd.template cast<T>();
    out.id = std::move(r);
    solve(out);
    out.factor = {};  // evaluate's scratch: not carried by a returned result
    out.rhs.resize(0, 0);
    return out;
  }
  template <class T>
  void solve(fd_derivatives_result<T>& out) const {
    const int n = dof();
    const auto& r = out.id;
    using MatX = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
    if constexpr (std::is_floating_point_v<T>) {
      // M⁻¹ [∂τ/∂q  ∂τ/∂q̇  I] by M's sparse LᵀL factorisation (dynamics/tree_factor.hpp):
      // one row operation over the 3n right-hand sides per (body, ancestor) pair
      if (!out.factor.factor(r.M, sparsity_))
        throw numerical_error("forward_dynamics_derivatives: model '" + name_ +
                              "': the mass matrix is not positive definite at this q");
      auto& x = out.rhs;
      x.resize(n, 3 * n);
      x << r.dq, r.dqd, MatX::Identity(n, n);
      out.factor.solve_in_place(x);
      out.dq = -x.leftCols(n);
      out.dqd = -x.middleCols(n, n);
      out.Minv = x.rightCols(n);
    } else {
      out.Minv = ldlt_factor<T, dynamic>(r.M, "the mass matrix").solve(MatX::Identity(n, n));
      out.dq.noalias() = -out.Minv * r.dq;
      out.dqd.noalias() = -out.Minv * r.dqd;
    }
  }

  forward_dynamics_fn<S, dynamic, tree<S>> fd_;
  rne_derivatives_fn<S> d_;
  std::string name_;
  tree_sparsity sparsity_;  // the ancestor lists, for M's sparse factorisation
};

template <class S>
fd_derivatives_fn<S> forward_dynamics_derivatives(const tree<S>& t, rne_options o = {}, fd_options f = {}) {
  return fd_derivatives_fn<S>(t, o, f);
}

/// η̇ and A, B of ẋ = f(x, τ) for x = (q, η), f = (S(q)η, η̇) (see the file comment).
template <class T, int M>
struct nh_fd_derivatives_result {
  vecN<T, M> eta_dot;
  state_space<T, Eigen::Dynamic, M> ss;  ///< A ((n+m) × (n+m)), B ((n+m) × p)
  /// The inverse dynamics' derivatives at (q, η, η̇): ∂τ/∂(q, η, η̇) (K = ∂τ/∂η̇ among them).
  nh_derivatives_result<T, M> id;
  /// Scratch kept by evaluate for its next call (empty in a result that operator() returns):
  /// the forward dynamics' own result (η̇, S(q), M_η; run-time-sized constraints) and K's LU.
  nh_forward_dynamics_result<T, Eigen::Dynamic, M> fd;
  Eigen::PartialPivLU<Eigen::Matrix<T, M, M>> lu;
  detail::redundant_eta_scratch<T> redundant;  ///< with more actuators than η (p > m)
  /// The outputs moved into a new result (no copy), this one keeping its scratch.
  nh_fd_derivatives_result take_outputs() {
    nh_fd_derivatives_result r;
    r.eta_dot = std::move(eta_dot), r.ss = std::move(ss), r.id = id.take_outputs();
    return r;
  }
};

/// A, B of a constrained tree's forward dynamics, analytically:
/// `forward_dynamics_derivatives(t, c)(q, eta, tau [, w])`; `evaluate(q, eta, tau [, w], out)`
/// reuses out's inverse-dynamics matrices and scratch (inputs and wrenches in the model's
/// scalar).
template <class S, class C>
class nh_fd_derivatives_fn {
 public:
  nh_fd_derivatives_fn(const tree<S>& t, const C& c, rne_options o = {})
      : fd_(nh_forward_dynamics(t, c, o)), id_(t, c, o) {}

  /// The call: in the model's scalar, evaluate into a result its thread keeps and the outputs
  /// moved out (they are its only allocations); in another scalar, a result of its own.
  template <class Q, class E, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                  const Eigen::MatrixBase<TAU>& tau) const {
    if constexpr (detail::in_scalar<S, Q, E, TAU>) {
      using R = nh_fd_derivatives_result<S, C::m_at_compile_time>;
      return detail::with_kept<R>([&](R& k) { evaluate(q, eta, tau, k); return k.take_outputs(); });
    } else {
      return own_result(q, tau, fd_(q, eta, tau), [&](const auto& ed) { return id_(q, eta, ed); });
    }
  }
  template <class Q, class E, class TAU, class Kin, class W>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                  const external_wrenches_fn<Kin, W>& w) const {
    if constexpr (detail::in_scalar<S, Q, E, TAU> && std::is_same_v<W, S>) {
      using R = nh_fd_derivatives_result<S, C::m_at_compile_time>;
      return detail::with_kept<R>([&](R& k) { evaluate(q, eta, tau, w, k); return k.take_outputs(); });
    } else {
      return own_result(q, tau, fd_(q, eta, tau, w), [&](const auto& ed) { return id_(q, eta, ed, w); });
    }
  }
  /// Into a result whose storage is reused: no allocation once it has its sizes, where the
  /// constraint is run-time sized, also with more actuators than η (p > m) where it writes E τ
  /// and Sᵀ v into given storage (wheeled_base; detail::redundant_eta_rows). `out` must not
  /// alias the inputs; after an exception its contents are unspecified.
  template <class Q, class E, class TAU>
    requires detail::in_scalar<S, Q, E, TAU>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                nh_fd_derivatives_result<S, C::m_at_compile_time>& out) const {
    evaluate_into(q, eta, tau, out);
  }
  /// …with external wrenches in the model's scalar.
  template <class Q, class E, class TAU, class Kin>
    requires detail::in_scalar<S, Q, E, TAU>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                const external_wrenches_fn<Kin, S>& w, nh_fd_derivatives_result<S, C::m_at_compile_time>& out) const {
    evaluate_into(q, eta, tau, out, w);
  }

 private:
  /// The call in another scalar than the model's: η̇, then id's derivatives there (by `id`)
  /// and A, B into a result of its own, without scratch.
  template <class Q, class TAU, class ED, class Id>
  auto own_result(const Q& q, const TAU& tau, const ED& ed, const Id& id) const {
    auto J = id(ed);
    nh_fd_derivatives_result<typename decltype(J)::scalar_type, C::m_at_compile_time> out;
    out.id = std::move(J);
    finish(q, tau, ed, id_.constraint().S(q), out);
    out.id.work = {};
    out.lu = {};
    out.redundant = {};
    return out;
  }
  /// evaluate, with or without the wrenches (`w...`: none or one).
  template <class Q, class E, class TAU, class... W>
  void evaluate_into(const Q& q, const E& eta, const TAU& tau, nh_fd_derivatives_result<S, C::m_at_compile_time>& out,
                     const W&... w) const {
    if constexpr (C::n_at_compile_time == Eigen::Dynamic) {
      fd_.evaluate(q, eta, tau, w..., out.fd);  // η̇ and S(q) into kept storage
      id_.evaluate(q, eta, out.fd.eta_dot, w..., out.id);
      finish(q, tau, out.fd.eta_dot, out.fd.S, out);
    } else {  // compile-time sizes: on the stack
      const auto ed = fd_(q, eta, tau, w...);
      id_.evaluate(q, eta, ed, w..., out.id);
      finish(q, tau, ed, id_.constraint().S(q), out);
    }
  }
  template <class Q, class TAU, class ED, class Sq, class T, int M>
  void finish(const Q& q, const TAU& tau, const ED& ed, const Sq& s, nh_fd_derivatives_result<T, M>& out) const {
    const int n = id_.dof(), m = id_.m(), p = actuator_count(id_.constraint());
    const auto& J = out.id;
    out.eta_dot = ed.template cast<T>();
    out.ss.A.setZero(n + m, n + m);
    out.ss.B.setZero(n + m, p);
    out.ss.A.topLeftCorner(n, n) = J.dqd_dq;
    out.ss.A.block(0, n, n, m) = s.template cast<T>();
    if (p == m) {
      // −K⁻¹ ∂τ/∂(q, η) and K⁻¹, each solved into its block and negated there (no temporaries)
      out.lu.compute(J.deta_dot);
      auto dq = out.ss.A.block(n, 0, m, n);
      auto deta = out.ss.A.block(n, n, m, m);
      dq = out.lu.solve(J.dq);
      dq = -dq;
      deta = out.lu.solve(J.deta);
      deta = -deta;
      // K⁻¹ in its block: P I, then L's and U's triangular solves in place (what
      // lu.inverse() does, whose assignment to a block goes through temporaries)
      auto k_inv = out.ss.B.bottomRows(m);  // zero (setZero above)
      const auto& perm = out.lu.permutationP().indices();
      for (int j = 0; j < m; ++j) k_inv(perm(j), j) = T(1);
      out.lu.matrixLU().template triangularView<Eigen::UnitLower>().solveInPlace(k_inv);
      out.lu.matrixLU().template triangularView<Eigen::Upper>().solveInPlace(k_inv);
    } else {  // more actuators than η (linearize.hpp, detail::redundant_eta_rows)
      detail::redundant_eta_rows(id_.constraint(), q, s, J.dq, J.deta, J.deta_dot, tau, J.tau, out.ss.A, out.ss.B,
                                 out.redundant);
    }
  }

  decltype(nh_forward_dynamics(std::declval<const tree<S>&>(), std::declval<const C&>())) fd_;
  inverse_dynamics_derivatives_fn<S, C> id_;
};

template <class S, class C>
  requires pfaffian_constraint<C>
nh_fd_derivatives_fn<S, C> forward_dynamics_derivatives(const tree<S>& t, const C& c, rne_options o = {}) {
  return nh_fd_derivatives_fn<S, C>(t, c, o);
}

}  // namespace nhdyn
