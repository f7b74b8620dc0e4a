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
  Eigen::Matrix<T, 6, 3> G;     ///< composite world-wrench variation
  bool has_G;
};

/// The kernel (see the file comment). Spatial inertias are kept as (m, h = m c, Ī about the
/// origin): Y x = (Ī x_w + h × x_v, m x_v − h × x_w). A body's Ẏ = v ×* I − I v× + (· ×* I v)
/// is, written out in 3×3 blocks with p = I v = (p_n, p_f) and v = (ω, u),
///     Ẏ = [ω×Ī − Īω× − (u×h× + h×u×) − p_n×,  0;  −2 p_f×,  0]
/// (the upper right block is (ω×h + m u − p_f)× = 0), so Ẏ x depends on x_w alone and a
/// composite Ẏc is 12 numbers: a 3×3 matrix and a momentum. `fx(i, R_i, o_i, Fn, Ff, G,
/// has_G)` subtracts the external forces on body i and adds their variation to G.
template <class T, class Q, class QD, class QDD, class FX>
void tree_rne_derivatives_kernel(const std::vector<tree_link<T>>& L, const vec3<T>& g, bool gravity, const Q& q,
                                 const QD& qd, const QDD& qdd, const FX& fx, rne_derivatives_result<T>& out) {
  const int n = static_cast<int>(L.size());
  out.tau.resize(n);
  out.dq.setZero(n, n);
  out.dqd.setZero(n, n);
  out.M.setZero(n, n);
  small_buffer<rne_deriv_scratch<T>, dynamic> s(n);
  const vec3<T> zero = vec3<T>::Zero();
  const vec3<T> g0 = gravity ? vec3<T>(-g) : zero;  // a_0 = (0, −g)
  for (int i = 0; i < n; ++i) {  // forward: S, v, a, dV, dA, the body's I, Ẏ and f
    const tree_link<T>& k = L[i];
    rne_deriv_scratch<T>& b = s[i];
    mat3<T> R;
    vec3<T> p;
    kernel_placement(k, T(q(i)), R, p);
    const bool root = k.parent < 0;
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
    b.Ib.noalias() -= k.m * b.o * b.o.transpose() + hK * b.o.transpose() + b.o * hK.transpose();
    b.Ib.diagonal().array() += k.m * b.o.squaredNorm() + T(2) * b.o.dot(hK);
    // momentum p = I v, force f = I a + v ×* p
    const vec3<T> pn = b.Ib * b.vw + b.h.cross(b.vv);
    b.pf = k.m * b.vv - b.h.cross(b.vw);
    b.Fn = b.Ib * b.aw + b.h.cross(b.av) + b.vw.cross(pn) + b.vv.cross(b.pf);
    b.Ff = k.m * b.av - b.h.cross(b.aw) + b.vw.cross(b.pf);
    // Ẏ's block: C + Cᵀ (C = ω×Ī) − (h uᵀ + u hᵀ) + 2 (u·h) 1 − p_n×   (u×h× + h×u× = h uᵀ + u hᵀ − 2 u·h 1)
    mat3<T> C;
    for (int c = 0; c < 3; ++c) C.col(c) = b.vw.cross(vec3<T>(b.Ib.col(c)));
    b.Tq = C + C.transpose();
    b.Tq.noalias() -= b.h * b.vv.transpose() + b.vv * b.h.transpose();
    b.Tq.diagonal().array() += T(2) * b.vv.dot(b.h);
    b.Tq -= spatial::skew(pn);
    b.G.setZero();
    b.has_G = false;
    fx(i, b.R, b.o, b.Fn, b.Ff, b.G, b.has_G);
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
    if (b.has_G) {
      u3 = b.G.transpose() * (spatial::vec6<T>() << b.Sw, b.Sv).finished();
      if (k.revolute) {
        const spatial::vec6<T> GS = b.G * b.Sw;
        dFqn -= GS.template head<3>();
        dFqf -= GS.template tail<3>();
      }
    }
    const vec3<T> u2 = b.Tq.transpose() * b.Sw + T(2) * b.pf.cross(b.Sv);  // (Ẏcᵀ S)_w; its linear half is 0
    const auto dot = [](const vec3<T>& aw, const vec3<T>& av, const vec3<T>& bw, const vec3<T>& bv) {
      return T(aw.dot(bw) + av.dot(bv));
    };
    out.tau(i) = dot(b.Sw, b.Sv, b.Fn, b.Ff);
    out.dq(i, i) = dot(b.Sw, b.Sv, dFqn, dFqf);
    out.dqd(i, i) = dot(b.Sw, b.Sv, dFvn, dFvf);
    out.M(i, i) = dot(b.Sw, b.Sv, u1w, u1v);
    if (k.has_armature) {
      out.tau(i) += k.Ia * T(qdd(i));
      out.M(i, i) += k.Ia;
    }
    // for the rows of i's ancestors: + S_i ×* F_i
    dFqn += b.Sw.cross(b.Fn) + b.Sv.cross(b.Ff);
    dFqf += b.Sw.cross(b.Ff);
    // the pairs (i, ancestor j): five dot products each
    for (int j = k.parent; j >= 0; j = L[j].parent) {
      const rne_deriv_scratch<T>& c = s[j];
      out.dq(j, i) = dot(c.Sw, c.Sv, dFqn, dFqf);
      out.dqd(j, i) = dot(c.Sw, c.Sv, dFvn, dFvf);
      T dqij = dot(u1w, u1v, c.dAw, c.dAv) + u2.dot(c.dVw);
      if (b.has_G) dqij -= u3.dot(c.Sw);
      out.dq(i, j) = dqij;
      out.dqd(i, j) = T(2) * dot(u1w, u1v, c.dVw, c.dVv) + u2.dot(c.Sw);
      out.M(i, j) = out.M(j, i) = dot(u1w, u1v, c.Sw, c.Sv);
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
      if (b.has_G) {
        l.G += b.G;
        l.has_G = true;
      }
    }
  }
}

/// The kernel with every call inside it inlined (GCC and Clang) for the scalars of
/// `flatten_kernels` (floating point, SIMD packs): ≈ 20 % faster in double (Eigen's small
/// products otherwise stay calls); other scalars (duals, multiprecision) call the kernel as
/// it is, whose code size flattening would multiply.
template <class T, class Q, class QD, class QDD, class FX>
NHDYN_FLATTEN void tree_rne_derivatives_kernel_flat(const std::vector<tree_link<T>>& L, const vec3<T>& g, bool gravity,
                                                    const Q& q, const QD& qd, const QDD& qdd, const FX& fx,
                                                    rne_derivatives_result<T>& out) {
  tree_rne_derivatives_kernel<T>(L, g, gravity, q, qd, qdd, fx, out);
}
template <class T, class Q, class QD, class QDD, class FX>
void rne_derivatives_dispatch(const std::vector<tree_link<T>>& L, const vec3<T>& g, bool gravity, const Q& q,
                              const QD& qd, const QDD& qdd, const FX& fx, rne_derivatives_result<T>& out) {
  if constexpr (flatten_kernels<T>)
    tree_rne_derivatives_kernel_flat<T>(L, g, gravity, q, qd, qdd, fx, out);
  else
    tree_rne_derivatives_kernel<T>(L, g, gravity, q, qd, qdd, fx, out);
}

/// External wrenches in the kernel: each wrench's spatial force at its body (world, about
/// the origin) subtracted from f, and a world-axes wrench's variation added to G.
template <class T, class W>
struct wrench_forces {
  const std::vector<wrench<W>>* w = nullptr;
  const std::vector<tree_link<T>>* L = nullptr;
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
      : links_(detail::make_tree_links(t)), g_(t.gravity()), n_(t.dof()), opt_(o) {}
  template <int N>
  explicit rne_derivatives_fn(const chain<S, N>& c, rne_options o = {}) : rne_derivatives_fn(as_tree(c), o) {}

  int dof() const { return n_; }

  template <class Q, class QD, class QDD>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<QDD>& qdd) const {
    return run(q, qd, qdd, static_cast<const std::vector<wrench<double>>*>(nullptr));
  }
  template <class Q, class QD, class QDD, class Kin, class W>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                  const external_wrenches_fn<Kin, W>& w) const {
    if (w.dof() != n_)
      throw input_error("rne_derivatives: the external wrenches are for a model of " + std::to_string(w.dof()) +
                        " joints, this one has " + std::to_string(n_));
    return run(q, qd, qdd, &w.wrenches());
  }

  /// Into a result whose matrices are reused: no allocation after the first call of a size, for
  /// trees of up to 32 bodies (the scratch then lives on the stack). `out` must not alias the
  /// inputs.
  template <class Q, class QD, class QDD>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                rne_derivatives_result<S>& out) const {
    check(q, qd, qdd);
    detail::wrench_forces<S, double> fx;
    if (opt_.velocity)
      detail::rne_derivatives_dispatch<S>(links_, g_, opt_.gravity, q, qd, qdd, fx, out);
    else
      detail::rne_derivatives_dispatch<S>(links_, g_, opt_.gravity, q, vecN<S, dynamic>::Zero(n_), qdd, fx, out);
    check_result(out);
  }

 private:
  template <class T>
  static void check_result(const rne_derivatives_result<T>& out) {
    detail::check_overflow(out.tau, "rne_derivatives");
    for (const auto* m : {&out.dq, &out.dqd, &out.M})  // entries in column-major order
      detail::check_overflow(*m, "rne_derivatives (a derivative)");
  }
  template <class Q, class QD, class QDD>
  void check(const Q& q, const QD& qd, const QDD& qdd) const {
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
    const auto go = [&](const std::vector<detail::tree_link<T>>& L) {
      const detail::wrench_forces<T, W> fx{w, &L};
      const vec3<T> g = g_.template cast<T>();
      if (opt_.velocity)
        detail::rne_derivatives_dispatch<T>(L, g, opt_.gravity, q, qd, qdd, fx, out);
      else
        detail::rne_derivatives_dispatch<T>(L, g, opt_.gravity, q, vecN<T, dynamic>::Zero(n_), qdd, fx, out);
    };
    if constexpr (std::is_same_v<T, S>) {
      go(links_);
    } else {
      go(detail::cast_links<T>(links_));
    }
    check_result(out);
    return out;
  }

  std::vector<detail::tree_link<S>> links_;
  vec3<S> g_;
  int n_;
  rne_options opt_;
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
