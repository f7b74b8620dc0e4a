#pragma once
/// \file constraints/concept.hpp
/// Pfaffian (velocity) constraints A(q) q̇ = 0 on a chain of n joints, with a basis S(q) of
/// the admissible velocities (A S = 0), its derivative Ṡ(q, q̇) and the actuator input map
/// E(q) (default S):
///
///     q̇ = S(q) η,   q̈ = S(q) η̇ + Ṡ(q, q̇) η,   v = E(q) τ + A(q)ᵀ λ        (paper eq. 1–2)
///
/// A constraint type provides `dof()` (n), `k()`, `m()` and, templated on the scalar,
/// `A(q)` (k×n), `S(q)` (n×m), `Sdot(q, qd)` (n×m). Optionally `E(q)` (n×m), and the
/// structured products `S_times(q, η)`, `St_times(q, v)`, `Sdot_times(q, q̇, η)` and
/// `St_M_S(q, M)` (the reduced inertia SᵀMS of a symmetric M) that avoid forming matrices,
/// and `S_into(q, s)` (S written over a matrix that holds S at another q, only where it can
/// be nonzero); the free functions below fall back to the dense forms.
///
/// Built in: `holonomic` (S = I, k = 0), `differential_drive` (any x, y, heading triple of
/// joints, forward axis a parameter), `rolling_wheels` (a planar base on two drive wheels
/// whose angles are coordinates, k = 3), `bicycle` (a car-like base with a steered front
/// wheel, k = 2), `user_constraint` (plain functions of q; Ṡ by duals when not given).
///
/// This header: the `pfaffian_constraint` concept, its optional parts, and uniform access.
/// One header per built-in constraint type: holonomic.hpp, differential_drive.hpp,
/// rolling_wheels.hpp, bicycle.hpp, user_constraint.hpp; constraint.hpp includes them all.
#include <concepts>
#include <string>
#include <vector>
#include "../model/chain.hpp"

namespace nhdyn {

template <class S, int R, int C>
using matrix = Eigen::Matrix<S, R, C>;


/// What every constraint type provides (docs/api.md §6): its sizes at compile time (or
/// `dynamic`) and at run time, and, on any scalar, A(q) (k×n), S(q) (n×m) and Ṡ(q, q̇) (n×m).
/// Everything else is optional and has a named concept below; the stages take any
/// `pfaffian_constraint`, and the free functions use the optional parts where present.
template <class C>
concept pfaffian_constraint = requires(const C& c, const vecN<double, C::n_at_compile_time>& q) {
  { C::n_at_compile_time } -> std::convertible_to<int>;
  { C::k_at_compile_time } -> std::convertible_to<int>;
  { C::m_at_compile_time } -> std::convertible_to<int>;
  { c.dof() } -> std::convertible_to<int>;
  { c.k() } -> std::convertible_to<int>;
  { c.m() } -> std::convertible_to<int>;
  c.A(q);
  c.S(q);
  c.Sdot(q, q);
};

/// Optional: an input map E(q) (n×m) other than S (v = E τ + Aᵀ λ).
template <class C, class Q>
concept has_input_map = requires(const C& c, const Q& q) { c.E(q); };
/// Optional: q̇ = S η without forming S.
template <class C, class Q, class E>
concept has_S_times = requires(const C& c, const Q& q, const E& eta) { c.S_times(q, eta); };
/// Optional: S(q) written into a matrix s (n × m) that holds zeros or S at another q of the
/// same constraint (no allocation, no zeroing): every call writes the same set of entries,
/// whatever q, and that set covers every entry that is nonzero at any q.
template <class C, class Q, class Mat>
concept has_S_into = requires(const C& c, const Q& q, Mat& s) { c.S_into(q, s); };
/// Optional: Sᵀ v without forming S.
template <class C, class Q, class V>
concept has_St_times = requires(const C& c, const Q& q, const V& v) { c.St_times(q, v); };
/// Optional: Sᵀ v into given storage (m entries) without forming S or a new vector.
template <class C, class Q, class V, class Out>
concept has_St_times_into = requires(const C& c, const Q& q, const V& v, Out& out) { c.St_times_into(q, v, out); };
/// Optional: E τ into given storage (n entries) without forming E (wheeled_base: τ at the
/// actuated joints, zeros elsewhere).
template <class C, class Q, class Tau, class Out>
concept has_E_times_into = requires(const C& c, const Q& q, const Tau& tau, Out& out) { c.E_times_into(q, tau, out); };
/// Optional: Ṡ η without forming Ṡ.
template <class C, class Q, class QD, class E>
concept has_Sdot_times = requires(const C& c, const Q& q, const QD& qd, const E& eta) { c.Sdot_times(q, qd, eta); };
/// Optional: the reduced inertia Sᵀ M S of a symmetric M, structured.
template <class C, class Q, class MM>
concept has_St_M_S = requires(const C& c, const Q& q, const MM& M) { c.St_M_S(q, M); };
/// Optional: a constraint whose input map selects the joints whose rates η holds, so that
/// SᵀE = I and the projection is τ = Sᵀ v (`static constexpr bool StE_identity = true`:
/// rolling_wheels, bicycle).
template <class C>
concept has_identity_StE = requires { requires C::StE_identity; };
/// Optional: p actuators other than m (`p()`, `p_at_compile_time`; E is n × p), and τ from
/// r = Sᵀv by the constraint itself: `solve_actuation(q, r)` returns the τ (p entries, or
/// columns for a matrix r) that solves SᵀE τ = r — with p > m the one of least weighted norm
/// (wheeled_base).
template <class C, class Q, class R>
concept has_solve_actuation = requires(const C& c, const Q& q, const R& r) { c.solve_actuation(q, r); };
template <class C>
concept has_actuator_count = requires(const C& c) {
  { c.p() } -> std::convertible_to<int>;
  { C::p_at_compile_time } -> std::convertible_to<int>;
};
/// Optional: which joints A, S, Ṡ, E depend on (else: all).
template <class C>
concept has_depends_on = requires(const C& c, int j) { c.depends_on(j); };

// ---- uniform access: structured products where the constraint has them, dense otherwise.

/// q's entries: the constraint's `nq()` where it has one (a floating base's q has one entry
/// more than q̇, model/floating.hpp: wheel_contacts), else n.
template <class C>
int constraint_nq(const C& c) {
  if constexpr (requires { c.nq(); })
    return c.nq();
  else
    return c.dof();
}

/// p, the number of actuators (τ's entries): the constraint's `p()` where it has one, else m.
template <class C>
int actuator_count(const C& c) {
  if constexpr (has_actuator_count<C>)
    return c.p();
  else
    return c.m();
}
/// Names of τ's entries: the constraint's `tau_names(joints)` where it has them (wheeled_base:
/// the actuated joints), else η's names `eta`.
template <class C>
std::vector<std::string> tau_names_of(const C& c, const std::vector<std::string>& joints, const std::vector<std::string>& eta) {
  if constexpr (requires { c.tau_names(joints); })
    return c.tau_names(joints);
  else
    return eta;
}
/// p at compile time (`dynamic` if not known): the constraint's, else m's.
template <class C>
inline constexpr int p_of = [] {
  if constexpr (has_actuator_count<C>)
    return C::p_at_compile_time;
  else
    return C::m_at_compile_time;
}();

/// Whether A, S, Ṡ or E may depend on q_j: a constraint's `depends_on(j)` where it has one,
/// else true.
template <class C>
bool constraint_depends_on(const C& c, int j) {
  if constexpr (has_depends_on<C>)
    return c.depends_on(j);
  else
    return true;
}

namespace detail {
/// The n×m matrix whose column c is f(e_c), e_c the c-th unit vector of m entries in T: a
/// constraint's dense S or Ṡ from its structured product (S_times, Sdot_times).
template <class T, int N, int M, class F>
matrix<T, N, M> columns_of(int n, int m, const F& f) {
  matrix<T, N, M> s(n, m);
  vecN<T, M> e = vecN<T, M>::Zero(m);
  for (int c = 0; c < m; ++c) {
    e(c) = T(1);
    s.col(c) = f(e);
    e(c) = T(0);
  }
  return s;
}

/// S(q) as a matrix from a constraint's S_into: zeros, then the entries that can be nonzero.
template <class C, class Q>
auto S_by_S_into(const C& c, const Eigen::MatrixBase<Q>& q) {
  using T = promote_t<typename C::scalar_type, typename Q::Scalar>;
  using Mat = matrix<T, C::n_at_compile_time, C::m_at_compile_time>;
  Mat s = Mat::Zero(c.dof(), c.m());
  c.S_into(q, s);
  return s;
}

/// A(q) as a new matrix (k × n) from a constraint's A_into.
template <class C, class Q>
auto A_by_A_into(const C& c, const Eigen::MatrixBase<Q>& q) {
  matrix<promote_t<typename C::scalar_type, typename Q::Scalar>, C::k_at_compile_time, C::n_at_compile_time> a;
  c.A_into(q, a);
  return a;
}

/// The entries of an n × m matrix S that the products below read, by column: column c's rows
/// are rows[start[c]] … rows[start[c + 1] − 1]. For a floating-point S they are its nonzero
/// entries (a term 0·x adds nothing where x is finite: the products equal the dense ones up to
/// rounding order), else every entry (a dual or an interval whose value is 0 may carry a
/// derivative or a width). Storage is fixed-size when n and m are.
template <int N, int M>
struct column_pattern {
  static constexpr int NM = N == dynamic || M == dynamic ? dynamic : N * M;
  Eigen::Matrix<int, NM, 1> rows;
  Eigen::Matrix<int, M == dynamic ? dynamic : M + 1, 1> start;

  template <class SM>
  void scan(const Eigen::MatrixBase<SM>& S) {
    using T = typename SM::Scalar;
    const int n = static_cast<int>(S.rows()), m = static_cast<int>(S.cols());
    if (rows.size() != n * m) rows.resize(n * m);
    if (start.size() != m + 1) start.resize(m + 1);
    int k = 0;
    for (int c = 0; c < m; ++c) {
      start(c) = k;
      if constexpr (std::is_floating_point_v<T>) {
        for (int i = 0; i < n; ++i) {  // branch-free: S's zeros are not predictable
          rows(k) = i;
          k += S(i, c) != T(0);
        }
      } else {
        for (int i = 0; i < n; ++i) rows(k++) = i;
      }
    }
    start(m) = k;
  }
  /// out = Sᵀ v (m entries): O(nonzeros of S).
  template <class SM, class V, class Out>
  void St_times(const Eigen::MatrixBase<SM>& S, const Eigen::MatrixBase<V>& v, Eigen::MatrixBase<Out>& out) const {
    for (int c = 0; c + 1 < start.size(); ++c) {
      typename Out::Scalar a(0);
      for (int k = start(c); k < start(c + 1); ++k) a += S(rows(k), c) * v(rows(k));
      out(c) = a;
    }
  }
  /// Me = Sᵀ M S for a symmetric n × n M (m × m, exactly symmetric), through MS (n × m scratch):
  /// MS's column b = Σ M's columns j of S's column b's nonzeros, then Me(a, b) for a ≥ b.
  /// O(n·nnz(S) + m·nnz(S)) against the dense O(n²m).
  template <class SM, class MM, class WS, class ME>
  void St_M_S(const Eigen::MatrixBase<SM>& S, const Eigen::MatrixBase<MM>& Mq, Eigen::MatrixBase<WS>& MS,
              Eigen::MatrixBase<ME>& Me) const {
    using T = typename ME::Scalar;
    const int m = static_cast<int>(start.size()) - 1;
    for (int b = 0; b < m; ++b) {
      auto col = MS.col(b);
      col.setZero();
      for (int k = start(b); k < start(b + 1); ++k) col += S(rows(k), b) * Mq.col(rows(k));
    }
    for (int b = 0; b < m; ++b)
      for (int a = b; a < m; ++a) {
        T e(0);
        for (int k = start(a); k < start(a + 1); ++k) e += S(rows(k), a) * MS(rows(k), b);
        Me(a, b) = e;
        Me(b, a) = e;
      }
  }
};

/// Sᵀ M S in the scalar T for a symmetric M: the constraint's structured `St_M_S` when it has
/// one (differential_drive: O(n²)), else S's nonzero columns against M (column_pattern:
/// O(n·nnz(S)), the dense product's O(n²m) where S is dense).
template <class T, class C, class Q, class MM>
matrix<T, C::m_at_compile_time, C::m_at_compile_time> project_inertia(const C& c, const Eigen::MatrixBase<Q>& q,
                                                                      const Eigen::MatrixBase<MM>& M) {
  if constexpr (has_St_M_S<C, Q, MM>) {
    return c.St_M_S(q, M).template cast<T>();
  } else {
    constexpr int N = C::n_at_compile_time, Mc = C::m_at_compile_time;
    const matrix<T, N, Mc> S = c.S(q).template cast<T>();
    column_pattern<N, Mc> p;
    p.scan(S);
    matrix<T, N, Mc> MS(S.rows(), S.cols());
    matrix<T, Mc, Mc> Me(S.cols(), S.cols());
    p.St_M_S(S, M.template cast<T>(), MS, Me);
    return Me;
  }
}
}  // namespace detail

template <class C, class Q>
auto input_map(const C& c, const Eigen::MatrixBase<Q>& q) {
  if constexpr (has_input_map<C, Q>)
    return c.E(q);
  else
    return c.S(q);
}
template <class C, class Q, class E>
auto apply_S(const C& c, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta) {
  if constexpr (has_S_times<C, Q, E>)
    return c.S_times(q, eta);
  else
    return vecN<promote_t<typename Q::Scalar, typename E::Scalar>, C::n_at_compile_time>(c.S(q) * eta);
}
template <class C, class Q, class V>
auto apply_St(const C& c, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) {
  if constexpr (has_St_times<C, Q, V>)
    return c.St_times(q, v);
  else
    return vecN<promote_t<typename Q::Scalar, typename V::Scalar>, C::m_at_compile_time>(c.S(q).transpose() * v);
}
/// Sᵀ v into out (m entries; a vector or a map): without allocation where the constraint has
/// St_times_into and out has the scalar apply_St would return, else through apply_St.
template <class C, class Q, class V, class Out>
void apply_St_into(const C& c, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, Eigen::MatrixBase<Out>& out) {
  using R = typename decltype(apply_St(c, q, v))::Scalar;
  if constexpr (has_St_times_into<C, Q, V, Out> && std::is_same_v<typename Out::Scalar, R>)
    c.St_times_into(q, v, out);
  else
    out = apply_St(c, q, v);
}
template <class C, class Q, class QD, class E>
auto apply_Sdot(const C& c, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                const Eigen::MatrixBase<E>& eta) {
  if constexpr (has_Sdot_times<C, Q, QD, E>)
    return c.Sdot_times(q, qd, eta);
  else
    return vecN<promote_t<promote_t<typename Q::Scalar, typename QD::Scalar>, typename E::Scalar>,
                C::n_at_compile_time>(c.Sdot(q, qd) * eta);
}

}  // namespace nhdyn
