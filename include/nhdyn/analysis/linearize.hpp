#pragma once
/// \file analysis/linearize.hpp
/// Exact first derivatives of any nhdyn computation by forward-mode duals
/// (scalar/dual.hpp): no step size, no truncation error, rounding error only.
///
/// - `jacobian(f, x)`: ∂f/∂x of any callable f (a user pipeline, a generic lambda) at x.
///   Columns are seeded K at a time (one pass when x has a fixed size ≤ 16).
/// - `central_difference_jacobian(f, x, h)`: the same by central differences (2 evaluations
///   per column, error O(h²) + O(ε/h)), for checks and comparisons.
/// - `linearize_inverse_dynamics(chain, c, q, η, η̇)`: ∂τ/∂ζ of τ = project∘rne∘lift, with
///   ζ = (q, η, η̇) and the blocks ∂τ/∂q, ∂τ/∂η, ∂τ/∂η̇ (= M_η when E = S);
///   `inverse_dynamics_linearizer(chain, c)` is the same as a function object built once.
/// - `linearize_forward_dynamics(chain, c, q, η, τ)`: ẋ = f(x, u) with x = (q, η),
///   f = (S(q)η, η̇(q, η, τ)), u = τ → A = ∂f/∂x, B = ∂f/∂u (from ∂τ/∂ζ by the implicit
///   function theorem); `forward_dynamics_linearizer(chain, c)` built once. For a holonomic chain,
///   `linearize_forward_dynamics(chain, q, q̇, τ)`: x = (q, q̇), f = (q̇, q̈). Both take, after
///   the state, rne_options and the joints' friction (friction(model), dynamics/terms.hpp).
/// - Parameter sensitivities: build the model from dual parameters inside f, e.g.
///       jacobian([&](const auto& p) {
///         using D = typename std::decay_t<decltype(p)>::Scalar;
///         presets::paper5_parameters<D> par{{p(0), p(1), p(2), p(3), p(4)}, p(5), p(6), p(7)};
///         const auto r = presets::paper5<D>(par);
///         return inverse_dynamics(r.chain, r.constraint)(q, eta, eta_dot);
///       }, ones8);
///   or `link_parameter_jacobian(chain, c, q, η, η̇)`: ∂τ/∂(m_i, a_i, d_i, I_xx,i, I_yy,i,
///   I_zz,i) for every link i (columns link by link).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <limits>
#include <optional>
#include <type_traits>
#include <vector>

#include "../constraints/constraint.hpp"
#include "../constraints/forward_dynamics.hpp"
#include "../constraints/stages.hpp"
#include "../dynamics/forward_dynamics.hpp"
#include "../scalar/dual.hpp"

namespace nhdyn {

namespace detail {
/// Dual components per pass: all of x when its size is fixed and ≤ 16, else chunks of 8.
template <int Nx>
inline constexpr int seed_chunk = (Nx != dynamic && Nx <= 16) ? Nx : 8;

template <class Y>
using eigen_vector_of = std::remove_cvref_t<Y>;
}  // namespace detail

namespace detail {
/// Columns `cols` of ∂f/∂x by duals of K components (⌈|cols|/K⌉ passes); every other
/// column is left zero — for columns known to vanish identically.
template <int K, class F, class X>
auto jacobian_columns(const F& f, const Eigen::MatrixBase<X>& x, const int* cols, int ncols) {
  using T = typename X::Scalar;
  constexpr int Nx = X::SizeAtCompileTime;
  using D = dual<T, K>;
  using Y = eigen_vector_of<decltype(f(std::declval<const vecN<D, Nx>&>()))>;
  constexpr int Ny = Y::SizeAtCompileTime;
  const int n = static_cast<int>(x.size());
  Eigen::Matrix<T, Ny, Nx> J;
  vecN<D, Nx> xd(n);
  for (int c0 = 0; c0 < std::max(ncols, 1); c0 += K) {
    for (int i = 0; i < n; ++i) xd(i) = D(T(x(i)));
    for (int k = 0; k < K && c0 + k < ncols; ++k) xd(cols[c0 + k]).derivative(k) = T(1);
    const Y y = f(xd);
    if (c0 == 0) J.setZero(y.size(), n);
    for (Eigen::Index r = 0; r < y.size(); ++r) {
      const D& yr = y(r);  // no copy when f returns duals (the usual case)
      for (int k = 0; k < K && c0 + k < ncols; ++k) J(r, cols[c0 + k]) = yr.derivative(k);
    }
  }
  return J;
}
}  // namespace detail

/// ∂f/∂x at x (rows: f's entries, columns: x's), exact to rounding, by duals. f takes an
/// Eigen vector of duals (same size as x) and returns an Eigen vector whose scalar is a dual
/// (or anything Eigen converts to one); write f generic (auto parameters).
template <class F, class X>
auto jacobian(const F& f, const Eigen::MatrixBase<X>& x) {
  const int n = static_cast<int>(x.size());
  std::vector<int> cols(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) cols[static_cast<std::size_t>(j)] = j;
  return detail::jacobian_columns<detail::seed_chunk<X::SizeAtCompileTime>>(f, x, cols.data(), n);
}

/// ∂f/∂x by central differences (f(x + h e_j) − f(x − h e_j)) / 2h, step h·max(1, |x_j|).
/// f is called with plain vectors of x's scalar.
template <class F, class X>
auto central_difference_jacobian(const F& f, const Eigen::MatrixBase<X>& x, double h) {
  using T = typename X::Scalar;
  constexpr int Nx = X::SizeAtCompileTime;
  using Y = detail::eigen_vector_of<decltype(f(std::declval<const vecN<T, Nx>&>()))>;
  constexpr int Ny = Y::SizeAtCompileTime;
  const int n = static_cast<int>(x.size());
  Eigen::Matrix<T, Ny, Nx> J;
  for (int j = 0; j < n; ++j) {
    using std::abs;
    using std::max;
    const T hj = T(h) * max(T(1), T(abs(T(x(j)))));
    vecN<T, Nx> xp = x, xm = x;
    xp(j) += hj;
    xm(j) -= hj;
    const Y yp = f(xp), ym = f(xm);
    if (j == 0) J.resize(yp.size(), n);
    J.col(j) = (yp - ym) / (T(2) * hj);
  }
  return J;
}

/// ∂τ/∂ζ of the nonholonomic inverse dynamics, ζ = (q, η, η̇) (n + 2m columns).
template <class T, int N, int M>
struct inverse_dynamics_jacobian {
  static constexpr int Z = (N == dynamic || M == dynamic) ? dynamic : N + 2 * M;
  Eigen::Matrix<T, M, Z> J;  ///< [∂τ/∂q  ∂τ/∂η  ∂τ/∂η̇]
  int n = N, m = M;
  auto dq() const { return J.leftCols(n); }
  auto deta() const { return J.middleCols(n, m); }
  auto deta_dot() const { return J.rightCols(m); }
};

namespace detail {
template <int N, int M>
inline constexpr int stacked = (N == dynamic || M == dynamic) ? dynamic : N + 2 * M;

template <int Z, class A, class B, class C>
auto stack3(const A& a, const B& b, const C& c) {
  using T = typename A::Scalar;
  vecN<T, Z> z(a.size() + b.size() + c.size());
  z << a.template cast<T>(), b.template cast<T>(), c.template cast<T>();
  return z;
}
}  // namespace detail

namespace detail {
template <class C>
inline constexpr bool is_differential_drive = false;
template <class Sc, int N>
inline constexpr bool is_differential_drive<differential_drive<Sc, N>> = true;

/// Whether turning a differential drive's heading joint h is a symmetry of its reduced
/// dynamics, so that ∂τ/∂q_h vanishes identically: every joint before h is prismatic (the
/// base only translates up to it), the x and y joints' axes are orthonormal, perpendicular
/// to the heading axis a_h and oriented so that ψ = sign·q_h turns the forward direction
/// with the body (sign·(a_x × a_y) = a_h), every other joint before h slides along a_h, and
/// gravity (when on) is parallel to a_h. Then turning the heading and the whole scene about
/// a_h together changes nothing that τ = (τ_v, τ_ω, …) reads: v is measured along the body's
/// forward direction, and every force on the arm turns with it. Checked on the model's
/// constants to rounding (8ε); any other case — and every model scalar other than a
/// floating-point one — is not skipped.
template <class S, int N, class C>
bool heading_turn_is_symmetry(const chain<S, N>& ch, const C& c, const rne_options& o) {
  if constexpr (!is_differential_drive<C> || !std::is_floating_point_v<S>) {
    return false;
  } else {
    const int h = c.heading;
    if (c.x > h || c.y > h || ch[h].joint != joint_type::revolute) return false;
    // Joint j's axis z_{j−1} in the base frame: R_0 ⋯ R_{j−1} ẑ, R_i = Rz(θ_i) Rx(α_i).
    std::vector<Eigen::Vector3d> axis;
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    for (int j = 0; j <= h; ++j) {
      axis.push_back(R.col(2));
      if (j < h && ch[j].joint != joint_type::prismatic) return false;
      const double th = double(ch[j].theta), al = double(ch[j].alpha);
      R = R * Eigen::AngleAxisd(th, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
          Eigen::AngleAxisd(al, Eigen::Vector3d::UnitX()).toRotationMatrix();
    }
    const double tol = 8 * std::numeric_limits<double>::epsilon();
    const Eigen::Vector3d& ah = axis[std::size_t(h)];
    const Eigen::Vector3d& ax = axis[std::size_t(c.x)];
    const Eigen::Vector3d& ay = axis[std::size_t(c.y)];
    const auto parallel = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
      return a.cross(b).norm() <= tol * a.norm() * b.norm();
    };
    if (std::abs(ax.dot(ah)) > tol || std::abs(ay.dot(ah)) > tol || std::abs(ax.dot(ay)) > tol) return false;
    if ((value_of(c.heading_sign) * ax.cross(ay) - ah).norm() > tol) return false;
    for (int j = 0; j < h; ++j)
      if (j != c.x && j != c.y && !parallel(axis[std::size_t(j)], ah)) return false;
    const Eigen::Vector3d g = ch.gravity().template cast<double>();
    return !o.gravity || g.norm() == 0 || parallel(g, ah);
  }
}
}  // namespace detail

/// ∂τ/∂(q, η, η̇) as a function object: the pipeline project∘rne∘lift is built once (as
/// `inverse_dynamics` is), with a composite-rigid-body pass beside it.
///
///     const nhdyn::inverse_dynamics_linearizer lin(chain, constraint);
///     auto J = lin(q, eta, eta_dot);   // J.J (m × (n + 2m)), J.dq(), J.deta(), J.deta_dot()
///
/// τ is affine in η̇: τ = (SᵀE)⁻¹Sᵀ(M(q)(Sη̇ + Ṡη) + c(q, Sη) + g(q)), so ∂τ/∂η̇ =
/// (SᵀE)⁻¹SᵀM(q)S (= M_η when E = S and SᵀS = I) is taken from the mass matrix (CRBA, as
/// Pinocchio's computeRNEADerivatives takes ∂τ/∂q̈ = M), and one evaluation of the pipeline
/// on duals seeded along (q, η) only, η̇ held constant, gives ∂τ/∂q and ∂τ/∂η.
///
/// Columns known to vanish are not seeded either: ∂τ/∂q_j = 0 for a prismatic joint j that
/// comes before every revolute joint (it translates everything after it, and the dynamics
/// does not change under a translation) when the constraint does not depend on q_j
/// (`differential_drive` depends on its heading joint only; `holonomic` on none; a user
/// constraint on all). A planar base's x and y are such joints. So is a differential
/// drive's heading when turning it is a symmetry (detail::heading_turn_is_symmetry: a
/// planar base under vertical gravity). For paper5: 6 dual directions (q₄, q₅, η) instead
/// of 13. The skipped columns vanish in the full computation (x, y exactly; the heading to
/// rounding, 1e-18 of 10), the seeded ones are the same numbers as with every column seeded,
/// and the η̇ block agrees with it to rounding (tests/test_linearize.cpp checks all three).
///
/// Model: a chain<S, N>, or a tree<S> (N = dynamic). On a tree every column of (q, η) is
/// seeded (the structural zeros above are derived for chains only).
template <class S, int N, class C, class Model = chain<S, N>>
class inverse_dynamics_linearizer {
 public:
  inverse_dynamics_linearizer(const Model& ch, const C& c, rne_options o = {})
      : id_(inverse_dynamics(ch, c, o)), M_(ch), c_(c), n_(c.dof()), m_(c.m()) {
    bool before_revolute = true;
    bool heading_symmetry = false;
    if constexpr (std::is_same_v<Model, chain<S, N>>) heading_symmetry = detail::heading_turn_is_symmetry(ch, c, o);
    for (int j = 0; j < n_ + m_; ++j) {
      if constexpr (std::is_same_v<Model, chain<S, N>>) {
        if (j < n_) before_revolute = before_revolute && ch[j].joint == joint_type::prismatic;
      } else {
        before_revolute = false;
      }
      bool zero = j < n_ && before_revolute && !constraint_depends_on(c, j);
      if constexpr (detail::is_differential_drive<C>) zero = zero || (heading_symmetry && j == c.heading);
      if (!zero) cols_.push_back(j);
    }
  }

  /// The columns of ∂τ/∂ζ seeded as dual directions (of q and η; the others of q are
  /// structurally zero, and the η̇ block comes from the mass matrix).
  const std::vector<int>& computed_columns() const { return cols_; }

  template <class Q, class E, class ED>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                  const Eigen::MatrixBase<ED>& eta_dot) const {
    constexpr int M = C::m_at_compile_time;
    constexpr int X = (N == dynamic || M == dynamic) ? dynamic : N + M;  // x = (q, η)
    if constexpr (N == dynamic) detail::check_size(q, n_, "q");
    detail::check_size(eta, m_, "eta");
    detail::check_size(eta_dot, m_, "eta_dot");
    const int n = n_, m = m_;
    using T = typename Q::Scalar;
    const vecN<T, M> ed = eta_dot.template cast<T>();
    const auto f = [&](const auto& x) {
      using D = typename std::decay_t<decltype(x)>::Scalar;
      const vecN<D, M> edd = ed.template cast<D>();  // constant: no derivative lanes seeded
      if constexpr (X != dynamic)
        return id_(x.template head<N>(), x.template tail<M>(), edd);
      else
        return id_(x.head(n), x.tail(m), edd);
    };
    inverse_dynamics_jacobian<T, N, M> out;
    out.n = n;
    out.m = m;
    vecN<T, X> x(n + m);
    x << q.template cast<T>(), eta.template cast<T>();
    const int nc = static_cast<int>(cols_.size());
    constexpr int K = detail::seed_chunk<X>;
    out.J.resize(actuator_count(c_), n + 2 * m);  // p rows: τ's (m unless the constraint has p actuators)
    // A fixed-size x with two or three vanishing columns (a planar base's x and y, and its
    // heading) gets its own, narrower dual; any other count seeds K at a time.
    bool done = false;
    if constexpr (X != dynamic && K > 3) {
      if (nc == X - 2) {
        out.J.leftCols(n + m) = detail::jacobian_columns<K - 2>(f, x, cols_.data(), nc);
        done = true;
      } else if (nc == X - 3) {
        out.J.leftCols(n + m) = detail::jacobian_columns<K - 3>(f, x, cols_.data(), nc);
        done = true;
      }
    }
    if (!done) out.J.leftCols(n + m) = detail::jacobian_columns<K>(f, x, cols_.data(), nc);
    // ∂τ/∂η̇ = (SᵀE)⁻¹ SᵀM S (q was checked by the dual evaluation above).
    out.J.rightCols(m) = detail::solve_StE(c_, q, detail::project_inertia<T>(c_, q, M_(q)));
    return out;
  }

 private:
  decltype(inverse_dynamics(std::declval<const Model&>(), std::declval<const C&>())) id_;
  decltype(mass_matrix(std::declval<const Model&>())) M_;
  C c_;
  int n_, m_;
  std::vector<int> cols_;
};
template <class S, int N, class C>
inverse_dynamics_linearizer(const chain<S, N>&, const C&, rne_options = {}) -> inverse_dynamics_linearizer<S, N, C>;
template <class S, class C>
inverse_dynamics_linearizer(const tree<S>&, const C&, rne_options = {})
    -> inverse_dynamics_linearizer<S, dynamic, C, tree<S>>;

/// ∂τ/∂(q, η, η̇) at (q, η, η̇), by duals through project∘rne∘lift (builds the pipeline for
/// this one call; keep an inverse_dynamics_linearizer to evaluate many states).
template <class S, int N, class C, class Q, class E, class ED>
auto linearize_inverse_dynamics(const chain<S, N>& ch, const C& c, const Eigen::MatrixBase<Q>& q,
                                const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                                rne_options o = {}) {
  return inverse_dynamics_linearizer<S, N, C>(ch, c, o)(q, eta, eta_dot);
}
/// The same on a tree.
template <class S, class C, class Q, class E, class ED>
auto linearize_inverse_dynamics(const tree<S>& t, const C& c, const Eigen::MatrixBase<Q>& q,
                                const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                                rne_options o = {}) {
  return inverse_dynamics_linearizer(t, c, o)(q, eta, eta_dot);
}

/// ẋ = f(x, u) linearised: A = ∂f/∂x, B = ∂f/∂u.
template <class T, int NX, int NU>
struct state_space {
  Eigen::Matrix<T, NX, NX> A;
  Eigen::Matrix<T, NX, NU> B;
};

namespace detail {
/// The η̇ rows of A and B for p ≠ m actuators (more actuators than η: the least-norm τ of the
/// inverse dynamics). The forward dynamics solves M_η η̇ = B(q) τ − h_η with B = SᵀE (m × p),
/// and the inverse dynamics returns τ_id = P(q)(M_η η̇ + h_η) with B P = I, so M_η = B K for
/// K = ∂τ_id/∂η̇ and, at the forward dynamics' η̇ (where τ may differ from τ_id by a part
/// that B maps to 0),
///
///     ∂η̇/∂x = M_η⁻¹ ((∂B/∂x)(τ − τ_id) − B ∂τ_id/∂x),   ∂η̇/∂τ = M_η⁻¹ B,
///
/// (∂B/∂q)y by duals of q ↦ Sᵀ(q)E(q)y along the joints the constraint depends on. Writes the
/// bottom m rows of A ((n+m) × (n+m)) and B ((n+m) × p); `s` is S(q) (n × m). Every matrix and
/// vector it forms lives in `ws` (redundant_eta_scratch), so that a call into a reused scratch
/// allocates nothing where the constraint writes E τ and Sᵀ v into given storage
/// (E_times_into, St_times_into: wheeled_base); other constraints form E(q) and Sᵀ v anew.
template <class T>
struct redundant_eta_scratch {
  using matrix_type = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
  matrix_type Bq, Me, rhs_q, rhs_eta, dBy;  ///< SᵀE, SᵀE K, (∂B/∂q)y − B ∂τ_id/∂q, B ∂τ_id/∂η, (∂B/∂q)y
  Eigen::PartialPivLU<matrix_type> lu;      ///< of M_η = SᵀE K
  vecN<T, dynamic> y, unit, Ecol;           ///< τ − τ_id; e_a and E e_a (SᵀE's columns)
  vecN<dual<T, 1>, dynamic> qd, yd, e, col;  ///< q + ε e_j, y, E y and Sᵀ E y in duals
};

template <class C, class Q, class Sq, class JQ, class JE, class JD, class Tau, class TauId, class AA, class BB, class T>
void redundant_eta_rows(const C& c, const Q& q, const Sq& s, const JQ& Jq, const JE& Je, const JD& Jd, const Tau& tau,
                        const TauId& tau_id, AA& A, BB& B, redundant_eta_scratch<T>& ws) {
  using D = dual<T, 1>;
  using V = vecN<T, dynamic>;
  using VD = vecN<D, dynamic>;
  const int n = c.dof(), m = c.m(), p = actuator_count(c);
  // B = SᵀE, column by column from E's columns where E is applied in place
  ws.Bq.resize(m, p);
  if constexpr (has_E_times_into<C, Q, V, V>) {
    ws.unit.setZero(p);
    ws.Ecol.resize(n);
    for (int a = 0; a < p; ++a) {
      ws.unit(a) = T(1);
      c.E_times_into(q, ws.unit, ws.Ecol);
      ws.unit(a) = T(0);
      ws.Bq.col(a).noalias() = s.transpose().template cast<T>() * ws.Ecol;
    }
  } else {  // in T, as the inputs' promoted scalar forms it
    ws.Bq = s.transpose().template cast<T>() * input_map(c, q.template cast<T>()).template cast<T>();
  }
  ws.Me.noalias() = ws.Bq * Jd;
  ws.lu.compute(ws.Me);
  ws.y = tau.template cast<T>() - tau_id.template cast<T>();
  ws.dBy.setZero(m, n);
  ws.qd = q.template cast<T>().template cast<D>();
  ws.yd = ws.y.template cast<D>();
  ws.e.resize(n);
  ws.col.resize(m);
  for (int j = 0; j < n; ++j) {
    if (!constraint_depends_on(c, j)) continue;
    ws.qd(j).derivative(0) = T(1);
    if constexpr (has_E_times_into<C, VD, VD, VD>)
      c.E_times_into(ws.qd, ws.yd, ws.e);
    else
      ws.e = input_map(c, ws.qd) * ws.yd;
    apply_St_into(c, ws.qd, ws.e, ws.col);
    ws.qd(j).derivative(0) = T(0);
    for (int i = 0; i < m; ++i) ws.dBy(i, j) = ws.col(i).derivative(0);
  }
  ws.rhs_q = ws.dBy;
  ws.rhs_q.noalias() -= ws.Bq * Jq;
  ws.rhs_eta.noalias() = ws.Bq * Je;
  // each solved into its block, then negated there (no temporaries)
  auto a_q = A.block(n, 0, m, n);
  auto a_eta = A.block(n, n, m, m);
  a_q = ws.lu.solve(ws.rhs_q);
  a_eta = ws.lu.solve(ws.rhs_eta);
  a_eta = -a_eta;
  B.bottomRows(m) = ws.lu.solve(ws.Bq);
}
}  // namespace detail

/// x = (q, η), f = (S(q)η, η̇), u = τ for a constrained robot (paper5: 9 states, 4 inputs):
/// A = ∂f/∂x, B = ∂f/∂u, built once for a chain and constraint (as inverse_dynamics_linearizer)
/// and evaluated at any (q, η, τ).
///
/// From the inverse dynamics, not by differentiating the forward dynamics: η̇ = fd(q, η, τ)
/// is the solution of id(q, η, η̇) = τ, so (implicit function theorem) with K = ∂τ/∂η̇ =
/// (SᵀE)⁻¹M_η, ∂η̇/∂(q, η) = −K⁻¹ ∂τ/∂(q, η) and ∂η̇/∂τ = K⁻¹ — the linearizer's Jacobian
/// at (q, η, fd(q, η, τ)) (duals along q and η only, K from CRBA) and one m×m LU, as
/// Pinocchio's ABA derivatives come from the RNEA ones. The kinematic rows: ∂(Sη)/∂η = S,
/// ∂(Sη)/∂q by duals of the S-product alone, ∂(Sη)/∂τ = 0. The forward dynamics' own
/// checks apply (a non-positive-definite or ill-conditioned M_η is a numerical_error).
/// Model: a chain<S, N> or a tree<S> (N = dynamic).
template <class S, int N, class C, class Model = chain<S, N>>
class forward_dynamics_linearizer {
 public:
  /// `friction`: the joints' friction in the forward dynamics (fd.with(friction), dynamics/
  /// terms.hpp); then every column of ∂(Sη, η̇)/∂(q, η, τ) is taken by duals of the forward
  /// dynamics itself (the inverse-dynamics route below has no friction).
  forward_dynamics_linearizer(const Model& ch, const C& c, rne_options o = {},
                              const std::optional<friction_fn>& friction = std::nullopt)
      : fd_(friction ? nh_forward_dynamics(ch, c, o).with(*friction) : nh_forward_dynamics(ch, c, o)),
        id_(ch, c, o),
        id_tau_(inverse_dynamics(ch, c, o)),
        c_(c),
        friction_(friction.has_value()) {}

  template <class Q, class E, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                  const Eigen::MatrixBase<TAU>& tau) const {
    constexpr int M = C::m_at_compile_time, P = p_of<C>;
    constexpr int NX = (N == dynamic || M == dynamic) ? dynamic : N + M;
    const int n = c_.dof(), m = c_.m(), p = actuator_count(c_);
    if constexpr (N == dynamic) detail::check_size(q, n, "q");
    detail::check_size(eta, m, "eta");
    detail::check_size(tau, p, "tau");
    using T = typename Q::Scalar;
    if (friction_) {  // f(z) = (S(q) η, η̇(q, η, τ)), z = (q, η, τ), by duals
      vecN<T, dynamic> z(n + m + p);
      z << q.template cast<T>(), eta.template cast<T>(), tau.template cast<T>();
      const auto f = [&](const auto& x) {
        using D = typename std::decay_t<decltype(x)>::Scalar;
        const vecN<D, N> qz = x.head(n);
        const vecN<D, M> ez = x.segment(n, m);
        const vecN<D, P> tz = x.tail(p);
        vecN<D, dynamic> xdot(n + m);
        xdot << vecN<D, N>(apply_S(c_, qz, ez)), vecN<D, M>(fd_(qz, ez, tz));
        return xdot;
      };
      const auto J = jacobian(f, z);
      state_space<T, NX, P> out;
      out.A = J.leftCols(n + m);
      out.B = J.rightCols(p);
      return out;
    }
    const vecN<T, N> qt = q.template cast<T>();
    const vecN<T, M> et = eta.template cast<T>();
    const vecN<T, M> eta_dot = fd_(qt, et, tau.template cast<T>());
    const auto J = id_(qt, et, eta_dot);
    state_space<T, NX, P> out;
    out.A.setZero(n + m, n + m);
    out.B.setZero(n + m, p);
    out.A.block(0, 0, n, n) = jacobian(
        [&](const auto& qz) {
          using D = typename std::decay_t<decltype(qz)>::Scalar;
          return vecN<D, N>(apply_S(c_, qz, et.template cast<D>()));
        },
        qt);
    out.A.block(0, n, n, m) = c_.S(qt).template cast<T>();
    if (p == m) {
      const Eigen::PartialPivLU<Eigen::Matrix<T, M, M>> K(Eigen::Matrix<T, M, M>(J.deta_dot()));
      out.A.block(n, 0, m, n + m) = -K.solve(J.J.leftCols(n + m));
      out.B.bottomRows(m) = K.inverse();
    } else {
      const vecN<T, dynamic> tau_id = id_tau_(qt, et, eta_dot);
      detail::redundant_eta_scratch<T> ws;
      const auto s = out.A.block(0, n, n, m);  // S(q), formed above
      detail::redundant_eta_rows(c_, qt, s, J.dq(), J.deta(), J.deta_dot(), tau, tau_id, out.A, out.B, ws);
    }
    return out;
  }

 private:
  nh_forward_dynamics_fn<S, N, C, Model> fd_;
  inverse_dynamics_linearizer<S, N, C, Model> id_;
  decltype(inverse_dynamics(std::declval<const Model&>(), std::declval<const C&>())) id_tau_;
  C c_;
  bool friction_;
};
template <class S, int N, class C>
forward_dynamics_linearizer(const chain<S, N>&, const C&, rne_options = {}) -> forward_dynamics_linearizer<S, N, C>;
template <class S, class C>
forward_dynamics_linearizer(const tree<S>&, const C&, rne_options = {})
    -> forward_dynamics_linearizer<S, dynamic, C, tree<S>>;
template <class S, int N, class C>
forward_dynamics_linearizer(const chain<S, N>&, const C&, rne_options, const std::optional<friction_fn>&)
    -> forward_dynamics_linearizer<S, N, C>;
template <class S, class C>
forward_dynamics_linearizer(const tree<S>&, const C&, rne_options, const std::optional<friction_fn>&)
    -> forward_dynamics_linearizer<S, dynamic, C, tree<S>>;

/// The same for one (q, η, τ) (builds the linearizer for this one call; keep a
/// forward_dynamics_linearizer to evaluate many states).
template <class S, int N, class C, class Q, class E, class TAU>
auto linearize_forward_dynamics(const chain<S, N>& ch, const C& c, const Eigen::MatrixBase<Q>& q,
                                const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                                rne_options o = {}, const std::optional<friction_fn>& friction = std::nullopt) {
  return forward_dynamics_linearizer<S, N, C>(ch, c, o, friction)(q, eta, tau);
}
/// The same on a tree.
template <class S, class C, class Q, class E, class TAU>
auto linearize_forward_dynamics(const tree<S>& t, const C& c, const Eigen::MatrixBase<Q>& q,
                                const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<TAU>& tau,
                                rne_options o = {}, const std::optional<friction_fn>& friction = std::nullopt) {
  return forward_dynamics_linearizer<S, dynamic, C, tree<S>>(t, c, o, friction)(q, eta, tau);
}

/// x = (q, q̇), f = (q̇, q̈), u = τ for a holonomic chain, or a tree (N = dynamic).
template <class Model, class Q, class QD, class TAU, int N = Model::size_at_compile_time>
  requires(std::is_same_v<Model, chain<typename Model::scalar_type, N>> ||
           std::is_same_v<Model, tree<typename Model::scalar_type>>)
auto linearize_forward_dynamics(const Model& ch, const Eigen::MatrixBase<Q>& q,
                                const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                                rne_options o = {}, const std::optional<friction_fn>& friction = std::nullopt) {
  constexpr int Z = N == dynamic ? dynamic : 3 * N;
  constexpr int NX = N == dynamic ? dynamic : 2 * N;
  const int n = ch.dof();
  detail::check_size(q, n, "q");
  detail::check_size(qd, n, "qd");
  detail::check_size(tau, n, "tau");
  const auto fd = friction ? forward_dynamics(ch, o).with(*friction) : forward_dynamics(ch, o);
  const auto f = [&](const auto& z) {
    using D = typename std::decay_t<decltype(z)>::Scalar;
    vecN<D, NX> xdot(2 * n);
    xdot << z.segment(n, n), fd(z.head(n), z.segment(n, n), z.tail(n));
    return xdot;
  };
  using T = typename Q::Scalar;
  const auto J = jacobian(f, detail::stack3<Z>(q.template cast<T>(), qd, tau));
  state_space<T, NX, N> out;
  out.A = J.leftCols(2 * n);
  out.B = J.rightCols(n);
  return out;
}

/// Names of the 6 per-link parameters of link_parameter_jacobian, in column order.
inline constexpr const char* link_parameter_names[6] = {"mass", "a", "d", "Ixx", "Iyy", "Izz"};

/// ∂τ/∂π with π = (m_i, a_i, d_i, I_xx,i, I_yy,i, I_zz,i) for i = 1…n (6n columns, link by
/// link; inertia about the centre of mass, centre of mass held fixed in frame i). τ is the
/// nonholonomic inverse dynamics (a holonomic<N> constraint gives ∂v/∂π of rne).
template <int N, class C, class Q, class E, class ED>
auto link_parameter_jacobian(const chain<double, N>& ch, const C& c, const Eigen::MatrixBase<Q>& q,
                             const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                             rne_options o = {}) {
  const int n = ch.dof();
  Eigen::VectorXd pi(6 * n);
  for (int i = 0; i < n; ++i)
    pi.segment(6 * i, 6) << ch[i].mass, ch[i].a, ch[i].d, ch[i].inertia(0, 0), ch[i].inertia(1, 1),
        ch[i].inertia(2, 2);
  const auto f = [&](const auto& p) {
    using D = typename std::decay_t<decltype(p)>::Scalar;
    typename chain<D, N>::links_type L{};
    if constexpr (N == dynamic) L.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      auto& l = L[static_cast<std::size_t>(i)];
      l = ch[i].template cast<D>();
      l.mass = p(6 * i);
      l.a = p(6 * i + 1);
      l.d = p(6 * i + 2);
      for (int r = 0; r < 3; ++r) l.inertia(r, r) = p(6 * i + 3 + r);
    }
    const chain<D, N> cd(std::move(L), ch.gravity().template cast<D>(), ch.name(), ch.validation_policy());
    return vecN<D, C::m_at_compile_time>(inverse_dynamics(cd, c, o)(q, eta, eta_dot));
  };
  return jacobian(f, pi);
}

}  // namespace nhdyn
