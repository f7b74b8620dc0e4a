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
///   every constraint type works as it is. The products with S and Sᵀ go over S's nonzeros
///   (a base's few rows and the arm's identity columns: O(n²) for the whole Jacobian).
/// - `forward_dynamics_derivatives(t)(q, q̇, τ)`: q̈ and ∂q̈/∂q = −M⁻¹ ∂τ/∂q, ∂q̈/∂q̇ =
///   −M⁻¹ ∂τ/∂q̇, ∂q̈/∂τ = M⁻¹ (the implicit-function route: ∂τ/∂· at (q, q̇, FD(q, q̇, τ))).
/// - `forward_dynamics_derivatives(t, c)(q, η, τ)`: η̇ and the state-space A = ∂f/∂x, B = ∂f/∂τ
///   of ẋ = f(x, τ), x = (q, η), f = (S(q)η, η̇): with K = ∂τ/∂η̇, ∂η̇/∂(q, η) = −K⁻¹∂τ/∂(q, η),
///   ∂η̇/∂τ = K⁻¹.
///
/// All take external wrenches as a last argument (`external_wrenches(t, {…})`). The dual-number
/// linearizers of analysis/linearize.hpp compute the same matrices another way (the tests'
/// reference).
#include <Eigen/LU>
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
/// Every argument's scalar is S (the evaluate overloads: a reused result is in the model's
/// scalar, and inputs of another are not silently converted to it).
template <class S, class... X>
concept in_scalar = (std::is_same_v<typename X::Scalar, S> && ...);

/// A nonzero S_rc (or Ṡ_rc) of a constraint's S at one q.
template <class T>
struct s_nonzero {
  int r, c;
  T s;
};
}  // namespace detail

/// τ and ∂τ/∂(q, η, η̇) of the nonholonomic inverse dynamics, and ∂q̇/∂q of the lift
/// (q̇ = S(q)η; the kinematic rows of a state-space model).
template <class T, int M>
struct nh_derivatives_result {
  using scalar_type = T;
  vecN<T, M> tau;
  Eigen::Matrix<T, M, Eigen::Dynamic> dq;  ///< ∂τ/∂q (m × n)
  Eigen::Matrix<T, M, M> deta, deta_dot;   ///< ∂τ/∂η, ∂τ/∂η̇ (m × m)
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> dqd_dq;  ///< ∂(Sη)/∂q (n × n)
  /// rne's derivatives at the lifted state (q, Sη, Sη̇ + Ṡη): ∂v/∂q, ∂v/∂q̇, M and v.
  rne_derivatives_result<T> id;
  /// [∂τ/∂q  ∂τ/∂η  ∂τ/∂η̇], as inverse_dynamics_linearizer gives it.
  Eigen::Matrix<T, M, Eigen::Dynamic> J() const {
    Eigen::Matrix<T, M, Eigen::Dynamic> j(tau.size(), dq.cols() + 2 * tau.size());
    j << dq, deta, deta_dot;
    return j;
  }
  /// Scratch of the computation, kept by evaluate for its next call (empty in a result that
  /// operator() returns): S's and Ṡ's nonzeros, the constraint's [∂q̇/∂q_j; ∂q̈/∂q_j;
  /// ∂(Pv)/∂q_j] for j ∈ D, X = [∂v/∂q + …  ∂v/∂η  ∂v/∂η̇  v] (n × (n + 2m + 1)), Xᵀ, XᵀS
  /// and SᵀX.
  struct scratch {
    std::vector<detail::s_nonzero<T>> nz, nz_dot;
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> jd, x, xt, stxt;
    Eigen::Matrix<T, M, Eigen::Dynamic> stx;
  } work;
};


/// ∂τ/∂(q, η, η̇) of the nonholonomic inverse dynamics of a tree and any constraint (see the
/// file comment): `inverse_dynamics_derivatives(t, c)(q, eta, eta_dot [, w])`;
/// `evaluate(q, eta, eta_dot, out)` reuses out's matrices and scratch (inputs in the model's
/// scalar, no wrenches).
template <class S, class C>
class inverse_dynamics_derivatives_fn {
 public:
  inverse_dynamics_derivatives_fn(const tree<S>& t, const C& c, rne_options o = {}) : d_(t, o), c_(c) {
    if (c.dof() != t.dof())
      throw input_error("inverse_dynamics_derivatives: the constraint is for " + std::to_string(c.dof()) +
                        " joints, model '" + t.name() + "' has " + std::to_string(t.dof()));
    for (int j = 0; j < c.dof(); ++j)
      if (constraint_depends_on(c, j)) cols_.push_back(j);
  }
  int dof() const { return c_.dof(); }
  int m() const { return c_.m(); }
  const C& constraint() const { return c_; }
  /// The joints whose columns of ∂q̇/∂q, ∂q̈/∂q and ∂P/∂q are seeded as dual directions.
  const std::vector<int>& constraint_columns() const { return cols_; }

  template <class Q, class E, class ED>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                  const Eigen::MatrixBase<ED>& eta_dot) const {
    nh_derivatives_result<result_scalar<Q, E, ED>, C::m_at_compile_time> out;
    run(q, eta, eta_dot, out, [&](const auto& x, const auto& xd, const auto& xdd, auto& r) { r = d_(x, xd, xdd); });
    out.work = {};
    return out;
  }
  template <class Q, class E, class ED, class Kin, class W>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                  const external_wrenches_fn<Kin, W>& w) const {
    nh_derivatives_result<promote_t<result_scalar<Q, E, ED>, W>, C::m_at_compile_time> out;
    run(q, eta, eta_dot, out,
        [&](const auto& x, const auto& xd, const auto& xdd, auto& r) { r = d_(x, xd, xdd, w); });
    out.work = {};
    return out;
  }
  /// Into a result whose storage (matrices and scratch) is reused from call to call, for
  /// inputs in the model's scalar; the small vectors of the lift and the constraint's dual
  /// pass are still allocated. `out` must not alias the inputs; after an exception its
  /// contents are unspecified.
  template <class Q, class E, class ED>
    requires detail::in_scalar<S, Q, E, ED>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                nh_derivatives_result<S, C::m_at_compile_time>& out) const {
    run(q, eta, eta_dot, out,
        [&](const auto& x, const auto& xd, const auto& xdd, auto& r) { d_.evaluate(x, xd, xdd, r); });
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
    const vecN<T, N> q = q_in.template cast<T>();
    const vecN<T, M> eta = eta_in.template cast<T>(), eta_dot = eta_dot_in.template cast<T>();
    // the lift and rne's derivatives there
    const vecN<T, N> qd = apply_S(c_, q, eta);
    vecN<T, N> qdd = apply_S(c_, q, eta_dot);
    qdd += apply_Sdot(c_, q, qd, eta);
    derivatives(q, qd, qdd, out.id);
    const auto& r = out.id;
    // The constraint's pieces, by duals along q_j for the joints it depends on (j ∈ D): rows
    // [∂q̇/∂q_j; ∂q̈/∂q_j; ∂(P v)/∂q_j] with v held.
    const vecN<T, N>& v = r.tau;
    const auto along_q = [&](const auto& x) {
      using Dl = typename std::decay_t<decltype(x)>::Scalar;
      const vecN<Dl, M> e = eta.template cast<Dl>(), ed = eta_dot.template cast<Dl>();
      const vecN<Dl, N> xd = apply_S(c_, x, e);
      vecN<Dl, N> xdd = apply_S(c_, x, ed);
      xdd += apply_Sdot(c_, x, xd, e);
      const vecN<Dl, M> pv = detail::solve_StE(c_, x, apply_St(c_, x, vecN<Dl, N>(v.template cast<Dl>())));
      Eigen::Matrix<Dl, Eigen::Dynamic, 1> y(2 * n + m);
      y << xd, xdd, pv;
      return y;
    };
    // Jd: column k is the derivative along q_{D_k} (one dual pass per 4 joints of D)
    const int nd = static_cast<int>(cols_.size());
    auto& Jd = out.work.jd;
    Jd.resize(2 * n + m, nd);
    if (nd > 0) {
      using D4 = dual<T, 4>;
      vecN<D4, N> xd(n);
      for (int c0 = 0; c0 < nd; c0 += 4) {
        for (int i = 0; i < n; ++i) xd(i) = D4(q(i));
        for (int k = 0; k < 4 && c0 + k < nd; ++k) xd(cols_[static_cast<std::size_t>(c0 + k)]).derivative(k) = T(1);
        const auto y = along_q(xd);
        for (Eigen::Index rr = 0; rr < y.size(); ++rr)
          for (int k = 0; k < 4 && c0 + k < nd; ++k) Jd(rr, c0 + k) = y(rr).derivative(k);
      }
    }
    // S and Ṡ at once: S depends on q_D alone, so Ṡ(q, q̇) = Σ_{j∈D} ∂S/∂q_j q̇_j is the
    // derivative of S(q + ε q̇_D) (one dual lane; the time derivative the concept defines).
    using D1 = dual<T, 1>;
    vecN<D1, N> q_eps = q.template cast<D1>();
    for (const int j : cols_) q_eps(j).derivative(0) = qd(j);
    const auto S_eps = c_.S(q_eps);
    // S's nonzeros (r, c, S_rc): the products with S and Sᵀ below cost one row or column per
    // nonzero (a base's few rows and the arm's identity), any constraint
    auto& nz = out.work.nz;
    auto& nz_dot = out.work.nz_dot;
    nz.clear(), nz_dot.clear();
    for (int cc = 0; cc < m; ++cc)
      for (int rr = 0; rr < n; ++rr) {
        const D1& e = S_eps(rr, cc);
        if (!is_exact_zero(e.value())) nz.push_back({rr, cc, T(e.value())});
        if (!is_exact_zero(e.derivative(0))) nz_dot.push_back({rr, cc, T(e.derivative(0))});
      }
    // X = [X_q  X_η  X_η̇  v] (n × (n + 2m + 1)), then τ's derivatives = (SᵀE)⁻¹ Sᵀ X (one solve):
    //   X_q = V_q + V_q̇ ∂q̇/∂q + M ∂q̈/∂q (the middle terms in columns D only),
    //   X_η = V_q̇ S + M ∂q̈/∂η, ∂q̈/∂η = ∂(Ṡ(q, Sη)η)/∂η = Ṡ(q, q̇) + Σ_{j∈D} ∂(Sη)/∂q_j S_j,:
    //         (Ṡ = Σ_j ∂S/∂q_j q̇_j is linear in q̇ and S depends on q_D alone),
    //   X_η̇ = M S.
    auto& X = out.work.x;
    X.resize(n, n + 2 * m + 1);
    X.leftCols(n) = r.dq;
    X.rightCols(2 * m + 1).setZero();
    auto Xq = X.leftCols(n);
    auto Xe = X.middleCols(n, m);
    auto Xed = X.middleCols(n + m, m);
    for (int k = 0; k < nd; ++k)
      for (int rr = 0, j = cols_[static_cast<std::size_t>(k)]; rr < n; ++rr) {
        const T a1 = Jd(rr, k), a2 = Jd(n + rr, k);
        if (!is_exact_zero(a1)) Xq.col(j) += a1 * r.dqd.col(rr);
        if (!is_exact_zero(a2)) Xq.col(j) += a2 * r.M.col(rr);
      }
    for (const auto& e : nz) {
      Xe.col(e.c) += e.s * r.dqd.col(e.r);
      Xed.col(e.c) += e.s * r.M.col(e.r);
    }
    for (const auto& e : nz_dot) Xe.col(e.c) += e.s * r.M.col(e.r);
    for (int k = 0; k < nd; ++k)
      for (const auto& e : nz)
        if (e.r == cols_[static_cast<std::size_t>(k)])
          for (int rr = 0; rr < n; ++rr)
            if (!is_exact_zero(Jd(rr, k))) Xe.col(e.c) += (Jd(rr, k) * e.s) * r.M.col(rr);
    X.col(n + 2 * m) = v;
    // Sᵀ X = (Xᵀ S)ᵀ: on Xᵀ each nonzero of S is one vectorised column operation
    auto& Xt = out.work.xt;
    Xt = X.transpose();
    auto& StXt = out.work.stxt;
    StXt.setZero(X.cols(), m);
    for (const auto& e : nz) StXt.col(e.c) += e.s * Xt.col(e.r);
    auto& StX = out.work.stx;
    StX = StXt.transpose();
    StX = detail::solve_StE(c_, q, std::move(StX));
    out.tau = StX.col(n + 2 * m);
    out.dq = StX.leftCols(n);
    out.deta = StX.middleCols(n, m);
    out.deta_dot = StX.middleCols(n + m, m);
    out.dqd_dq.setZero(n, n);
    for (int k = 0; k < nd; ++k) {
      const int j = cols_[static_cast<std::size_t>(k)];
      out.dq.col(j) += Jd.col(k).tail(m);
      out.dqd_dq.col(j) = Jd.col(k).head(n);
    }
  }

  rne_derivatives_fn<S> d_;
  C c_;
  std::vector<int> cols_;
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
  /// Scratch of the computation, kept by evaluate for its next call (empty in a result that
  /// operator() returns): M's factorisation and the right-hand sides [∂τ/∂q  ∂τ/∂q̇  I].
  tree_ltl<T> factor;
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rhs;
};

/// ∂q̈/∂(q, q̇, τ) of a tree's forward dynamics: `forward_dynamics_derivatives(t)(q, qd, tau [, w])`.
/// q̈ by forward_dynamics(t) (its checks and its choice of algorithm); M⁻¹ and the products
/// with it by the tree-sparse factorisation M = LᵀL (dynamics/tree_factor.hpp) of the M that
/// rne_derivatives returns (refused, naming the model, when M is not positive definite).
/// `evaluate(q, qd, tau, out)` reuses out's matrices and scratch from call to call (inputs in
/// the model's scalar, no wrenches); q̈ comes from forward_dynamics as a new vector.
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

  template <class Q, class QD, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<TAU>& tau) const {
    const auto qdd = fd_(q, qd, tau);
    return finish(qdd, d_(q, qd, qdd));
  }
  template <class Q, class QD, class TAU, class Kin, class W>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                  const external_wrenches_fn<Kin, W>& w) const {
    const auto qdd = fd_(q, qd, tau, w);
    return finish(qdd, d_(q, qd, qdd, w));
  }
  /// Into a result whose storage is reused (see the class comment). `out` must not alias the
  /// inputs; after an exception its contents are unspecified.
  template <class Q, class QD, class TAU>
    requires detail::in_scalar<S, Q, QD, TAU>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                fd_derivatives_result<S>& out) const {
    out.qdd = fd_(q, qd, tau);
    d_.evaluate(q, qd, out.qdd, out.id);
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
  state_space<T, Eigen::Dynamic, M> ss;  ///< A ((n+m) × (n+m)), B ((n+m) × m)
  /// The inverse dynamics' derivatives at (q, η, η̇): ∂τ/∂(q, η, η̇) (K = ∂τ/∂η̇ among them).
  nh_derivatives_result<T, M> id;
};

/// A, B of a constrained tree's forward dynamics, analytically:
/// `forward_dynamics_derivatives(t, c)(q, eta, tau [, w])`; `evaluate(q, eta, tau, out)`
/// reuses out's inverse-dynamics matrices and scratch (inputs in the model's scalar, no
/// wrenches).
template <class S, class C>
class nh_fd_derivatives_fn {
 public:
  nh_fd_derivatives_fn(const tree<S>& t, const C& c, rne_options o = {})
      : fd_(nh_forward_dynamics(t, c, o)), id_(t, c, o) {}

  template <class Q, class E, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                  const Eigen::MatrixBase<TAU>& tau) const {
    const auto ed = fd_(q, eta, tau);
    auto J = id_(q, eta, ed);
    nh_fd_derivatives_result<typename decltype(J)::scalar_type, C::m_at_compile_time> out;
    out.id = std::move(J);
    finish(q, ed, out);
    out.id.work = {};
    return out;
  }
  template <class Q, class E, class TAU, class Kin, class W>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                  const external_wrenches_fn<Kin, W>& w) const {
    const auto ed = fd_(q, eta, tau, w);
    auto J = id_(q, eta, ed, w);
    nh_fd_derivatives_result<typename decltype(J)::scalar_type, C::m_at_compile_time> out;
    out.id = std::move(J);
    finish(q, ed, out);
    out.id.work = {};
    return out;
  }
  /// Into a result whose storage is reused. `out` must not alias the inputs; after an
  /// exception its contents are unspecified.
  template <class Q, class E, class TAU>
    requires detail::in_scalar<S, Q, E, TAU>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                nh_fd_derivatives_result<S, C::m_at_compile_time>& out) const {
    const auto ed = fd_(q, eta, tau);
    id_.evaluate(q, eta, ed, out.id);
    finish(q, ed, out);
  }

 private:
  template <class Q, class ED, class T, int M>
  void finish(const Q& q, const ED& ed, nh_fd_derivatives_result<T, M>& out) const {
    const int n = id_.dof(), m = id_.m();
    const auto& J = out.id;
    out.eta_dot = ed.template cast<T>();
    const Eigen::PartialPivLU<Eigen::Matrix<T, M, M>> K(J.deta_dot);
    out.ss.A.setZero(n + m, n + m);
    out.ss.B.setZero(n + m, m);
    out.ss.A.topLeftCorner(n, n) = J.dqd_dq;
    out.ss.A.block(0, n, n, m) = id_.constraint().S(q).template cast<T>();
    out.ss.A.block(n, 0, m, n) = -K.solve(J.dq);
    out.ss.A.block(n, n, m, m) = -K.solve(J.deta);
    out.ss.B.bottomRows(m) = K.inverse();
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
