#pragma once
/// \file dynamics/rne_derivatives.hpp
/// ∂τ/∂q, ∂τ/∂q̇ and ∂τ/∂q̈ = M of the inverse dynamics of a tree in one recursive pass,
/// O(n·depth), generic over the scalar, with armature and external wrenches:
/// `rne_derivatives(t)(q, qd, qdd)` and `rne_derivatives(t)(q, qd, qdd, w)`.
///
/// The algorithm is Carpentier & Mansard's (RSS 2018, "Analytical derivatives of rigid body
/// dynamics algorithms", Alg. 1): every spatial quantity in world coordinates about the world
/// origin, where a motion subspace S_j moves with every joint before it, ∂S_k/∂q_j = S_j × S_k
/// (j ⪯ k), and so does everything fixed on body k. Split each derivative along q_j into that
/// rigid turn about S_j and what is left (δ_j):
///
///     δ_j v_k = dV_j = v_λ(j) × S_j                 δ_j a_k = dA_j + dV_j × v_k,
///     dA_j = a_λ(j) × S_j + v_λ(j) × dV_j           (a includes gravity: a_0 = −a_g)
///     δ_j f_k = I_k dA_j + Ẏ_k dV_j,    Ẏ_k = v_k ×* I_k − I_k v_k× + (· ×* I_k v_k)
///
/// and along q̇_j: ∂v_k = S_j, ∂a_k = 2 dV_j + S_j × v_k, ∂f_k = I_k 2dV_j + Ẏ_k S_j. The
/// rigid turn of τ_i = S_iᵀ F_i (F_i = Σ of f over i's subtree) cancels when both S_i and F_i
/// turn (S_iᵀ (S_j ×* F) + (S_j × S_i)ᵀ F = 0), so with the composites Y_i = Σ I_k and
/// Ẏc_i = Σ Ẏ_k over i's subtree:
///
///     j ⪯ i:  ∂τ_i/∂q_j = S_iᵀ (Y_i dA_j + Ẏc_i dV_j),   ∂τ_i/∂q̇_j = S_iᵀ (Y_i 2dV_j + Ẏc_i S_j)
///     i ≺ j:  ∂τ_i/∂q_j = S_iᵀ (Y_j dA_j + Ẏc_j dV_j + S_j ×* F_j),  ∂τ_i/∂q̇_j = S_iᵀ (Y_j 2dV_j + Ẏc_j S_j)
///
/// and M_ij = S_iᵀ Y_i S_j (j ⪯ i), + the armature on the diagonal. A wrench fixed on body k
/// in body axes turns rigidly (nothing more); one given in world axes (force f, moment m at
/// the body point p) does not turn with the body: δ_j of its spatial force (m + p × f, f) is
/// G_k ω_j with G_k = [p× f× + m×; f×] (ω_j: S_j's angular part), summed over subtrees as Y.
///
/// The plain reference (dynamics/reference_derivatives.hpp: the textbook RNEA differentiated
/// by hand, one direction at a time) is the oracle; tests/test_rne_derivatives.cpp checks this
/// kernel against it, dual numbers and 50-digit central differences.
#include <Eigen/Core>
#include <vector>

#include "../detail/attributes.hpp"
#include "../detail/small_buffer.hpp"
#include "../functional/values.hpp"
#include "../model/floating.hpp"
#include "../model/tree.hpp"
#include "../model/tree_kernel.hpp"
#include "../spatial/spatial.hpp"
#include "rne.hpp"
#include "wrench.hpp"

namespace nhdyn {

/// τ and its first derivatives at (q, q̇, q̈): ∂τ/∂q (dq), ∂τ/∂q̇ (dqd), ∂τ/∂q̈ = M(q) (M).
template <class T>
struct rne_derivatives_result {
  Eigen::Matrix<T, Eigen::Dynamic, 1> tau;
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> dq, dqd, M;
};

namespace detail {

/// One body's scratch: world coordinates about the world origin, motion vectors as their
/// angular (w) and linear (v) halves, force vectors as moment (n) and force (f).
template <class T>
struct rne_deriv_scratch {
  mat3<T> R;                    ///< K_i's axes
  vec3<T> o;                    ///< K_i's origin
  vec3<T> Sw, Sv;               ///< S_i
  vec3<T> vw, vv, aw, av;       ///< v_i, a_i (a with gravity)
  vec3<T> dVw, dVv, dAw, dAv;   ///< dV_i, dA_i
  // composites over i's subtree (after the backward pass reaches i)
  T m;
  vec3<T> h;                    ///< Σ m c
  mat3<T> Ib;                   ///< Σ rotational inertia about the origin
  mat3<T> Tq;                   ///< Ẏc = [Tq, 0; −2 (pf×), 0]
  vec3<T> pf;                   ///< Σ linear momentum
  vec3<T> Fn, Ff;               ///< F_i
  bool has_G;                   ///< whether G (a world-axes wrench's variation) is nonzero in i's subtree
};

/// The kernel (see the file comment). Spatial inertias are kept as (m, h = m c, Ī about the
/// origin): Y x = (Ī x_w + h × x_v, m x_v − h × x_w). A body's Ẏ = v ×* I − I v× + (· ×* I v)
/// is, written out in 3×3 blocks with p = I v = (p_n, p_f) and v = (ω, u),
///     Ẏ = [ω×Ī − Īω× − (u×h× + h×u×) − p_n×,  0;  −2 p_f×,  0]
/// (the upper right block is (ω×h + m u − p_f)× = 0), so Ẏ x depends on x_w alone and a
/// composite Ẏc is 12 numbers: a 3×3 matrix and a momentum. `fx(i, R_i, o_i, Fn, Ff, G,
/// has_G)` subtracts the external forces on body i and adds their variation to G (only when
/// `fx.world()`: G is stored only then).
///
/// Returns, for float and double, whether the sum of every entry of ∂τ/∂q, ∂τ/∂q̇ and M is
/// finite — then each entry is (a NaN or ±Inf cannot sum to a finite number), and the caller
/// need not read the n² entries again; false otherwise (and for other scalars): check them.
///
/// Speed (double, g++ 12 -O3 -march=native, a random 48-body tree; harness, 2026-11-26):
/// Ī's parallel-axis terms and Ẏ's block are written out entry by entry — as Eigen
/// expressions (sums of outer products) they went through temporaries, ≈ 12 % of the call;
/// the sum above replaces a second pass over the three matrices (≈ 8 %); the ancestor walk
/// reads a packed parent array, not the links (performance.md, note 14).
template <class T, class Q, class QD, class QDD, class FX>
bool tree_rne_derivatives_kernel(const std::vector<tree_link<T>>& L, const vec3<T>& g, bool gravity, const Q& q,
                                 const QD& qd, const QDD& qdd, const FX& fx, rne_derivatives_result<T>& out) {
  const int n = static_cast<int>(L.size());
  out.tau.resize(n);
  out.dq.setZero(n, n);
  out.dqd.setZero(n, n);
  out.M.setZero(n, n);
  small_buffer<rne_deriv_scratch<T>, dynamic> s(n);
  // for float and double, the sum of every derivative and M's entries: finite only if each is
  constexpr bool summed = std::is_same_v<T, double> || std::is_same_v<T, float>;
  T sum = T(0);
  small_buffer<int, dynamic, 256> par(n);  // the parents, packed (the ancestor walks below)
  // the composite world-wrench variations G, only where such wrenches exist
  const bool world = fx.world();
  small_buffer<Eigen::Matrix<T, 6, 3>, dynamic> Gs(world ? n : 0);
  Eigen::Matrix<T, 6, 3> no_G;
  const vec3<T> zero = vec3<T>::Zero();
  const vec3<T> g0 = gravity ? vec3<T>(-g) : zero;  // a_0 = (0, −g)
  for (int i = 0; i < n; ++i) {  // forward: S, v, a, dV, dA, the body's I, Ẏ and f
    const tree_link<T>& k = L[i];
    rne_deriv_scratch<T>& b = s[i];
    mat3<T> R;
    vec3<T> p;
    kernel_placement(k, T(q(i)), R, p);
    const bool root = k.parent < 0;
    par[i] = k.parent;
    if (root) {
      b.R = R;
      b.o = p;
    } else {
      const rne_deriv_scratch<T>& l = s[k.parent];
      b.R.noalias() = l.R * R;
      b.o.noalias() = l.o + l.R * p;
    }
    const vec3<T> z = b.R.col(2);
    if (k.revolute) {
      b.Sw = z;
      b.Sv = b.o.cross(z);
    } else {
      b.Sw = zero;
      b.Sv = z;
    }
    const vec3<T>& lw = root ? zero : s[k.parent].vw;
    const vec3<T>& lv = root ? zero : s[k.parent].vv;
    const vec3<T>& law = root ? zero : s[k.parent].aw;
    const vec3<T>& lav = root ? g0 : s[k.parent].av;
    // dV = v_λ × S;  dA = a_λ × S + v_λ × dV
    b.dVw = lw.cross(b.Sw);
    b.dVv = lw.cross(b.Sv) + lv.cross(b.Sw);
    b.dAw = law.cross(b.Sw) + lw.cross(b.dVw);
    b.dAv = law.cross(b.Sv) + lav.cross(b.Sw) + lw.cross(b.dVv) + lv.cross(b.dVw);
    const T qdi = T(qd(i)), qddi = T(qdd(i));
    b.vw = lw + b.Sw * qdi;
    b.vv = lv + b.Sv * qdi;
    b.aw = law + b.Sw * qddi + b.dVw * qdi;  // v × S = v_λ × S
    b.av = lav + b.Sv * qddi + b.dVv * qdi;
    // the rigid-body inertia about the world origin: m, h = m c, Ī (parallel axes from K_i's origin)
    const vec3<T> hK = b.R * k.h;
    b.m = k.m;
    b.h = hK + k.m * b.o;
    mat3<T> IoRt;
    IoRt.noalias() = k.Io * b.R.transpose();
    b.Ib.noalias() = b.R * IoRt;
    const vec3<T> mo = k.m * b.o;
    const T shift = mo.dot(b.o) + T(2) * b.o.dot(hK);
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) b.Ib(r, c) -= mo(r) * b.o(c) + hK(r) * b.o(c) + b.o(r) * hK(c);
    b.Ib(0, 0) += shift, b.Ib(1, 1) += shift, b.Ib(2, 2) += shift;
    // momentum p = I v, force f = I a + v ×* p
    const vec3<T> pn = b.Ib * b.vw + b.h.cross(b.vv);
    b.pf = k.m * b.vv - b.h.cross(b.vw);
    b.Fn = b.Ib * b.aw + b.h.cross(b.av) + b.vw.cross(pn) + b.vv.cross(b.pf);
    b.Ff = k.m * b.av - b.h.cross(b.aw) + b.vw.cross(b.pf);
    // Ẏ's block: C + Cᵀ (C = ω×Ī) − (h uᵀ + u hᵀ) + 2 (u·h) 1 − p_n×   (u×h× + h×u× = h uᵀ + u hᵀ − 2 u·h 1)
    mat3<T> C;
    for (int c = 0; c < 3; ++c) C.col(c) = b.vw.cross(vec3<T>(b.Ib.col(c)));
    const T uh2 = T(2) * b.vv.dot(b.h);
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) b.Tq(r, c) = C(r, c) + C(c, r) - b.h(r) * b.vv(c) - b.vv(r) * b.h(c);
    b.Tq(0, 0) += uh2, b.Tq(1, 1) += uh2, b.Tq(2, 2) += uh2;
    b.Tq(0, 1) += pn(2), b.Tq(1, 0) -= pn(2), b.Tq(0, 2) -= pn(1), b.Tq(2, 0) += pn(1), b.Tq(1, 2) += pn(0), b.Tq(2, 1) -= pn(0);
    Eigen::Matrix<T, 6, 3>& G = world ? Gs[i] : no_G;
    if (world) G.setZero();
    b.has_G = false;
    fx(i, b.R, b.o, b.Fn, b.Ff, G, b.has_G);
  }
  for (int i = n - 1; i >= 0; --i) {  // backward: τ, the rows and columns of i, composites
    const tree_link<T>& k = L[i];
    rne_deriv_scratch<T>& b = s[i];
    // Y x for the composite Y_i
    const auto Yw = [&](const vec3<T>& xw, const vec3<T>& xv) { return vec3<T>(b.Ib * xw + b.h.cross(xv)); };
    const auto Yv = [&](const vec3<T>& xw, const vec3<T>& xv) { return vec3<T>(b.m * xv - b.h.cross(xw)); };
    const vec3<T> u1w = Yw(b.Sw, b.Sv), u1v = Yv(b.Sw, b.Sv);  // Y S
    // ∂F along q̇_i: Y 2dV + Ẏc S;  along q_i: Y dA + Ẏc dV (− G ω_i)
    vec3<T> dFvn = T(2) * Yw(b.dVw, b.dVv) + b.Tq * b.Sw;
    vec3<T> dFvf = T(2) * Yv(b.dVw, b.dVv) - T(2) * b.pf.cross(b.Sw);
    vec3<T> dFqn = Yw(b.dAw, b.dAv) + b.Tq * b.dVw;
    vec3<T> dFqf = Yv(b.dAw, b.dAv) - T(2) * b.pf.cross(b.dVw);
    vec3<T> u3 = zero;
    if (world && b.has_G) {
      const Eigen::Matrix<T, 6, 3>& G = Gs[i];
      u3 = G.transpose() * (spatial::vec6<T>() << b.Sw, b.Sv).finished();
      if (k.revolute) {
        const spatial::vec6<T> GS = G * b.Sw;
        dFqn -= GS.template head<3>();
        dFqf -= GS.template tail<3>();
      }
    }
    const vec3<T> u2 = b.Tq.transpose() * b.Sw + T(2) * b.pf.cross(b.Sv);  // (Ẏcᵀ S)_w; its linear half is 0
    const auto dot = [](const vec3<T>& aw, const vec3<T>& av, const vec3<T>& bw, const vec3<T>& bv) {
      return T(aw(0) * bw(0) + aw(1) * bw(1) + aw(2) * bw(2) + (av(0) * bv(0) + av(1) * bv(1) + av(2) * bv(2)));
    };
    out.tau(i) = dot(b.Sw, b.Sv, b.Fn, b.Ff);
    out.dq(i, i) = dot(b.Sw, b.Sv, dFqn, dFqf);
    out.dqd(i, i) = dot(b.Sw, b.Sv, dFvn, dFvf);
    out.M(i, i) = dot(b.Sw, b.Sv, u1w, u1v);
    if (k.has_armature) {
      out.tau(i) += k.Ia * T(qdd(i));
      out.M(i, i) += k.Ia;
    }
    if constexpr (summed) sum += (out.dq(i, i) + out.dqd(i, i)) + out.M(i, i);
    // for the rows of i's ancestors: + S_i ×* F_i
    {
      const T f0 = b.Fn(0), f1 = b.Fn(1), f2 = b.Fn(2), g0 = b.Ff(0), g1 = b.Ff(1), g2 = b.Ff(2);
      const T w0 = b.Sw(0), w1 = b.Sw(1), w2 = b.Sw(2), v0 = b.Sv(0), v1 = b.Sv(1), v2 = b.Sv(2);
      dFqn(0) += w1 * f2 - w2 * f1 + (v1 * g2 - v2 * g1);
      dFqn(1) += w2 * f0 - w0 * f2 + (v2 * g0 - v0 * g2);
      dFqn(2) += w0 * f1 - w1 * f0 + (v0 * g1 - v1 * g0);
      dFqf(0) += w1 * g2 - w2 * g1;
      dFqf(1) += w2 * g0 - w0 * g2;
      dFqf(2) += w0 * g1 - w1 * g0;
    }
    // the pairs (i, ancestor j): five dot products each
    for (int j = k.parent; j >= 0; j = par[j]) {
      const rne_deriv_scratch<T>& c = s[j];
      const T y0 = dot(c.Sw, c.Sv, dFqn, dFqf), y1 = dot(c.Sw, c.Sv, dFvn, dFvf);
      const T y2 = dot(u1w, u1v, c.dAw, c.dAv) + (u2.dot(c.dVw) - u3.dot(c.Sw));  // u3 = 0 without G
      const T y3 = T(2) * dot(u1w, u1v, c.dVw, c.dVv) + u2.dot(c.Sw), y4 = dot(u1w, u1v, c.Sw, c.Sv);
      out.dq(j, i) = y0;
      out.dqd(j, i) = y1;
      out.dq(i, j) = y2;
      out.dqd(i, j) = y3;
      out.M(i, j) = out.M(j, i) = y4;
      if constexpr (summed) sum += (y0 + y1) + (y2 + y3) + y4;
    }
    if (k.parent >= 0) {
      rne_deriv_scratch<T>& l = s[k.parent];
      l.m += b.m;
      l.h += b.h;
      l.Ib += b.Ib;
      l.Tq += b.Tq;
      l.pf += b.pf;
      l.Fn += b.Fn;
      l.Ff += b.Ff;
      if (world && b.has_G) {
        Gs[k.parent] += Gs[i];
        l.has_G = true;
      }
    }
  }
  if constexpr (summed)
    return finite_range(Eigen::Matrix<T, 1, 1>(sum), 0, 1);
  else
    return false;
}

/// The kernel with every call inside it inlined (GCC and Clang) for the scalars of
/// `flatten_kernels` (floating point, SIMD packs): ≈ 20 % faster in double (Eigen's small
/// products otherwise stay calls); other scalars (duals, multiprecision) call the kernel as
/// it is, whose code size flattening would multiply.
template <class T, class Q, class QD, class QDD, class FX>
NHDYN_FLATTEN bool tree_rne_derivatives_kernel_flat(const std::vector<tree_link<T>>& L, const vec3<T>& g, bool gravity,
                                                    const Q& q, const QD& qd, const QDD& qdd, const FX& fx,
                                                    rne_derivatives_result<T>& out) {
  return tree_rne_derivatives_kernel<T>(L, g, gravity, q, qd, qdd, fx, out);
}
template <class T, class Q, class QD, class QDD, class FX>
bool rne_derivatives_on(const std::vector<tree_link<T>>& L, const vec3<T>& g, bool gravity, const Q& q, const QD& qd,
                        const QDD& qdd, const FX& fx, rne_derivatives_result<T>& out) {
  if constexpr (flatten_kernels<T>)
    return tree_rne_derivatives_kernel_flat<T>(L, g, gravity, q, qd, qdd, fx, out);
  else
    return tree_rne_derivatives_kernel<T>(L, g, gravity, q, qd, qdd, fx, out);
}
/// The kernel on maps of the vectors (kernel_vector): one kernel per scalar and applied
/// forces, whatever Eigen types the caller passes.
template <class T, class Q, class QD, class QDD, class FX>
bool rne_derivatives_dispatch(const std::vector<tree_link<T>>& L, const vec3<T>& g, bool gravity, const Q& q,
                              const QD& qd, const QDD& qdd, const FX& fx, rne_derivatives_result<T>& out) {
  const kernel_input<dynamic, Q> qi(q);
  const kernel_input<dynamic, QD> qdi(qd);
  const kernel_input<dynamic, QDD> qddi(qdd);
  return rne_derivatives_on<T>(L, g, gravity, qi.get(), qdi.get(), qddi.get(), fx, out);
}

/// External wrenches in the kernel: each wrench's spatial force at its body (world, about
/// the origin) subtracted from f, and a world-axes wrench's variation added to G.
template <class T, class W>
struct wrench_forces {
  const std::vector<wrench<W>>* w = nullptr;
  const std::vector<tree_link<T>>* L = nullptr;
  /// Whether a wrench is given in world axes (only those vary with q beyond the rigid turn).
  bool world() const {
    if (w)
      for (const auto& x : *w)
        if (x.frame != wrench_frame::body) return true;
    return false;
  }
  void operator()(int i, const mat3<T>& R, const vec3<T>& o, vec3<T>& fn, vec3<T>& ff, Eigen::Matrix<T, 6, 3>& G,
                  bool& has_G) const {
    if (!w) return;
    for (const auto& x : *w) {
      if (x.body != i + 1) continue;
      const tree_link<T>& k = (*L)[i];
      const vec3<T> p = o + R * (k.p_KB + k.R_KB * x.point.template cast<T>());  // the point, world
      vec3<T> F = x.force.template cast<T>(), Mo = x.moment.template cast<T>();
      if (x.frame == wrench_frame::body) {
        const mat3<T> Rb = R * k.R_KB;
        F = Rb * F;
        Mo = Rb * Mo;
      } else {  // δ_j (m + p × f, f) = [p× f× + m×; f×] ω_j
        const mat3<T> Fx = spatial::skew(F);
        G.template topRows<3>() += spatial::skew(p) * Fx + spatial::skew(Mo);
        G.template bottomRows<3>() += Fx;
        has_G = true;
      }
      fn -= Mo + p.cross(F);
      ff -= F;
    }
  }
};

}  // namespace detail

/// ∂τ/∂(q, q̇, q̈) of a tree's inverse dynamics: `rne_derivatives(t)(q, qd, qdd)` returns
/// rne_derivatives_result {tau, dq, dqd, M}; `(q, qd, qdd, w)` with external wrenches
/// (`w = external_wrenches(t, {…})`: τ = rne − Q_ext(q) and its derivatives). Inputs checked
/// (sizes, finite) as rne's; rne_options' gravity and velocity are honoured (without velocity
/// terms, q̇ is taken as zero and ∂τ/∂q̇ = 0). A chain is differentiated as its tree.
template <class S>
class rne_derivatives_fn {
 public:
  explicit rne_derivatives_fn(const tree<S>& t, rne_options o = {})
      : links_(detail::make_tree_links(t)), g_(t.gravity()), n_(t.dof()), opt_(o), floating_(t.floating()) {}
  template <int N>
  explicit rne_derivatives_fn(const chain<S, N>& c, rne_options o = {}) : rne_derivatives_fn(as_tree(c), o) {}

  int dof() const { return n_; }
  /// q's entries: dof() + 1 for a floating tree (model/floating.hpp), else dof().
  int nq() const { return n_ + (floating_ ? 1 : 0); }

  template <class Q, class QD, class QDD>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<QDD>& qdd) const {
    return run(q, qd, qdd, static_cast<const std::vector<wrench<double>>*>(nullptr));
  }
  template <class Q, class QD, class QDD, class Kin, class W>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                  const external_wrenches_fn<Kin, W>& w) const {
    check_wrenches(w);
    return run(q, qd, qdd, &w.wrenches());
  }

  /// Into a result whose matrices are reused: no allocation after the first call of a size, on
  /// trees of any size (the scratch lives on the stack up to 55 bodies, 32 KiB; beyond, in a
  /// heap block the thread keeps, detail/small_buffer.hpp). `out` must not alias the inputs.
  template <class Q, class QD, class QDD>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                rne_derivatives_result<S>& out) const {
    evaluate_with(q, qd, qdd, detail::wrench_forces<S, double>{}, out);
  }
  /// …with external wrenches in the model's scalar.
  template <class Q, class QD, class QDD, class Kin>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                const external_wrenches_fn<Kin, S>& w, rne_derivatives_result<S>& out) const {
    check_wrenches(w);
    evaluate_with(q, qd, qdd, detail::wrench_forces<S, S>{&w.wrenches(), &links_}, out);
  }

 private:
  template <class Kin, class W>
  void check_wrenches(const external_wrenches_fn<Kin, W>& w) const {
    if (w.dof() != n_)
      throw input_error("rne_derivatives: the external wrenches are for a model of " + std::to_string(w.dof()) +
                        " joints, this one has " + std::to_string(n_));
    if (floating_)
      throw input_error("rne_derivatives: external wrenches on a floating tree are not supported yet "
                        "(differentiate rne(q, v, a) and the wrenches' joint forces apart)");
  }
  template <class Q, class QD, class QDD, class FX>
  void evaluate_with(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                     const FX& fx, rne_derivatives_result<S>& out) const {
    check(q, qd, qdd);
    if (floating_) {
      floating(q, qd, qdd, links_, out);
      return;
    }
    const bool finite =
        opt_.velocity
            ? detail::rne_derivatives_dispatch<S>(links_, g_, opt_.gravity, q, qd, qdd, fx, out)
            : detail::rne_derivatives_dispatch<S>(links_, g_, opt_.gravity, q, vecN<S, dynamic>::Zero(n_), qdd, fx, out);
    check_result(out, finite);
  }
  /// A floating tree (model/floating.hpp): the fixed-base tree's derivatives in the root's
  /// frame at (q_K, v, a − b(v)), g_K = R_WBᵀ g, then the root's six columns in the tangent
  /// space of q (q ⊕ δ, δ in the root's frame, as Pinocchio differentiates):
  ///   ∂τ/∂δ_p = 0 (the root's position enters nothing in its own frame);
  ///   ∂τ/∂δ_θ = −M_{:,v} [g_K]× (only gravity turns with the root: g_K(δ) = g_K + [g_K]× δ_θ,
  ///             and gravity acts as the root's linear acceleration −g_K);
  ///   ∂τ/∂v_root += −M_{:,0…5} ∂b/∂v (the bias inside q̈_K).
  template <class T, class Q, class QD, class QDD>
  void floating(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                const std::vector<detail::tree_link<T>>& L, rne_derivatives_result<T>& out) const {
    detail::small_buffer<T, dynamic> qk_s(n_), ak_s(n_);
    Eigen::Map<vecN<T, dynamic>> qk(qk_s.data(), n_), ak(ak_s.data(), n_);
    detail::trunk_configuration(q, qk);
    ak = qdd.template cast<T>();
    if (opt_.velocity) detail::subtract_root_bias(qd, ak);
    const vec3<T> g = detail::root_rotation<T>(q).transpose() * g_.template cast<T>();
    const detail::wrench_forces<T, double> none{};
    const bool finite =
        opt_.velocity ? detail::rne_derivatives_dispatch<T>(L, g, opt_.gravity, qk, qd, ak, none, out)
                      : detail::rne_derivatives_dispatch<T>(L, g, opt_.gravity, qk, vecN<T, dynamic>::Zero(n_), ak, none, out);
    out.dq.leftCols(3).setZero();
    if (opt_.gravity) {
      const mat3<T> G = spatial::skew<T>(g);
      out.dq.middleCols(3, 3).noalias() = -(out.M.leftCols(3) * G);
    } else {
      out.dq.middleCols(3, 3).setZero();
    }
    if (opt_.velocity) out.dqd.leftCols(6).noalias() -= out.M.leftCols(6) * detail::root_bias_jacobian<T>(qd);
    check_result(out, finite);
  }
  /// `finite`: the kernel's sum of the matrices' entries was finite, so each is.
  template <class T>
  static void check_result(const rne_derivatives_result<T>& out, bool finite) {
    detail::check_overflow(out.tau, "rne_derivatives");
    if (finite) return;
    for (const auto* m : {&out.dq, &out.dqd, &out.M})  // entries in column-major order
      detail::check_overflow(*m, "rne_derivatives (a derivative)");
  }
  template <class Q, class QD, class QDD>
  void check(const Q& q, const QD& qd, const QDD& qdd) const {
    if (floating_)
      detail::check_floating_configuration(q, n_ + 1, "q");
    else
      detail::check_size(q, n_, "q");
    detail::check_size(qd, n_, "qd");
    detail::check_size(qdd, n_, "qdd");
    detail::check_finite(q, "q");
    if (opt_.velocity) detail::check_finite(qd, "qd");
    detail::check_finite(qdd, "qdd");
  }

  template <class Q, class QD, class QDD, class W>
  auto run(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
           const std::vector<wrench<W>>* w) const {
    using T = promote_t<promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>,
                                  typename QDD::Scalar>,
                        W>;
    check(q, qd, qdd);
    rne_derivatives_result<T> out;
    if (floating_) {
      if (w) throw input_error("rne_derivatives: external wrenches on a floating tree are not supported yet");
      if constexpr (std::is_same_v<T, S>)
        floating(q, qd, qdd, links_, out);
      else
        floating(q, qd, qdd, detail::cast_links<T>(links_), out);
      return out;
    }
    const auto go = [&](const std::vector<detail::tree_link<T>>& L) {
      const detail::wrench_forces<T, W> fx{w, &L};
      const vec3<T> g = g_.template cast<T>();
      return opt_.velocity
                 ? detail::rne_derivatives_dispatch<T>(L, g, opt_.gravity, q, qd, qdd, fx, out)
                 : detail::rne_derivatives_dispatch<T>(L, g, opt_.gravity, q, vecN<T, dynamic>::Zero(n_), qdd, fx, out);
    };
    bool finite;
    if constexpr (std::is_same_v<T, S>)
      finite = go(links_);
    else
      finite = go(detail::cast_links<T>(links_));
    check_result(out, finite);
    return out;
  }

  std::vector<detail::tree_link<S>> links_;
  vec3<S> g_;
  int n_;
  rne_options opt_;
  bool floating_ = false;
};

template <class S>
rne_derivatives_fn<S> rne_derivatives(const tree<S>& t, rne_options o = {}) {
  return rne_derivatives_fn<S>(t, o);
}
template <class S, int N>
rne_derivatives_fn<S> rne_derivatives(const chain<S, N>& c, rne_options o = {}) {
  return rne_derivatives_fn<S>(as_tree(c), o);
}

}  // namespace nhdyn
