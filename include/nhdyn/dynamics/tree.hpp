#pragma once
/// \file dynamics/tree.hpp
/// rne, the mass matrix (CRBA), the bias and the holonomic forward dynamics of a kinematic
/// tree (model/tree.hpp), as function objects generic over the scalar, with the same call
/// forms as the chain versions: `rne(t)(q, qd, qdd)`, `mass_matrix(t)(q)`, `bias(t)(q, qd)`,
/// and (dynamics/forward_dynamics.hpp, included at the end) `forward_dynamics(t)(q, qd, tau)`.
///
/// The kernel is the optimisation of the reference algorithms (dynamics/reference.hpp: RBDA
/// Tables 5.1 and 6.2), tested equal to them. What it changes: each body is computed in its
/// *kernel frame* K_i, the moved joint frame turned once so that the joint axis is z — the
/// joint's motion is then Rz(q) or Tz(q), the joint subspace is a unit vector, and every
/// constant (placement of K_i in K_λ(i), m, m·c, the rotational inertia about K_i's origin) is
/// computed once when the function object is built. Velocities and forces are 3-vectors in
/// those frames (the Luh–Walker–Paul form of the same recursion). The CRBA builds its
/// composites in world axes, each about its own body's origin, and reads M off there
/// (tree_crba_kernel_world); for intervals, duals and multiprecision numbers in the kernel
/// frames (tree_crba_kernel_local).
#include <Eigen/Core>
#include <utility>
#include <vector>

#include "../detail/attributes.hpp"
#include "../detail/ldlt.hpp"
#include "../detail/small_buffer.hpp"
#include "../functional/values.hpp"
#include "../model/floating.hpp"
#include "../model/tree_kernel.hpp"
#include "../spatial/spatial.hpp"
#include "rne.hpp"

namespace nhdyn {

namespace detail {

/// The rne recursion on a tree, into tau: links in T, or in double for T a SIMD pack (the
/// constants broadcast where they are used, not stored once per lane).
template <bool Gravity, bool Velocity, class T, class LS, class Q, class QD, class QDD, class Tau>
void tree_rne_kernel_impl(const std::vector<tree_link<LS>>& L, const vec3<T>& g, const Q& q, const QD& qd,
                          const QDD& qdd, Tau& tau) {
  const int n = static_cast<int>(L.size());
  struct ws {
    mat3<T> R;
    vec3<T> w, dw, a, f, m;
  };
  // on the stack up to 32 KiB of it (170 bodies in double), beyond in a heap block the thread
  // keeps (detail/small_buffer.hpp); not zeroed
  small_buffer<ws, dynamic> s(n);
  const vec3<T> zero = vec3<T>::Zero();
  const vec3<T> a0 = Gravity ? vec3<T>(-g) : zero;
  for (int i = 0; i < n; ++i) {
    const auto& k = L[i];
    auto& c = s[i];
    vec3<T> p;
    kernel_placement(k, T(q(i)), c.R, p);
    const bool root = k.parent < 0;
    const vec3<T>& wl = root ? zero : s[k.parent].w;
    const vec3<T>& dwl = root ? zero : s[k.parent].dw;
    const vec3<T>& al = root ? a0 : s[k.parent].a;
    // the origin of K_i moves with the parent: a = a_λ + ω̇_λ × p + ω_λ × (ω_λ × p)
    vec3<T> ao = al + dwl.cross(p);
    if (Velocity) ao += wl.cross(wl.cross(p));
    c.a = c.R.transpose() * ao;
    c.w = c.R.transpose() * wl;
    c.dw = c.R.transpose() * dwl;
    const T qdi = Velocity ? T(qd(i)) : T(0);
    if (k.revolute) {  // ω̇ += z q̈ + ω_λ × z q̇ (in K_i), ω += z q̇
      if (Velocity) c.dw += vec3<T>(c.w.y() * qdi, -c.w.x() * qdi, T(0));
      c.dw.z() += T(qdd(i));
      if (Velocity) c.w.z() += qdi;
    } else {  // a += z q̈ + 2 ω × z q̇
      c.a.z() += T(qdd(i));
      if (Velocity) c.a += T(2) * qdi * vec3<T>(c.w.y(), -c.w.x(), T(0));
    }
    if (k.has_inertia) {  // F = m a + ω̇ × h + ω × (ω × h);  N = I_o ω̇ + ω × I_o ω + h × a
      c.f = k.m * c.a + c.dw.cross(k.h);
      c.m = k.Io * c.dw + k.h.cross(c.a);
      if (Velocity) {
        c.f += c.w.cross(c.w.cross(k.h));
        c.m += c.w.cross(k.Io * c.w);
      }
    } else {
      c.f = zero;
      c.m = zero;
    }
  }
  for (int i = n - 1; i >= 0; --i) {
    const auto& k = L[i];
    auto& c = s[i];
    T ti = k.revolute ? c.m.z() : c.f.z();
    if (k.has_armature) ti += k.Ia * T(qdd(i));
    tau(i) = ti;  // after the read of q̈_i: tau may be q̈'s own storage (tree_rne_fn on an rvalue ξ)
    if (k.parent >= 0) {
      auto& pc = s[k.parent];
      const vec3<T> f = c.R * c.f;
      vec3<T> p;
      if (k.revolute)
        p = k.p.template cast<T>();
      else
        p = k.p + k.R.col(2) * T(q(i));
      pc.f += f;
      pc.m += c.R * c.m + p.cross(f);
    }
  }
}

/// The same with every call inside it inlined (detail/attributes.hpp) for the scalars of
/// `flatten_kernels` (floating point, SIMD packs) — 15–20 % faster in double on this machine's
/// g++ 12 -O3 (Eigen's small products otherwise stay calls) —, as it is for other scalars,
/// whose code flattening would multiply.
template <bool Gravity, bool Velocity, class T, class LS, class Q, class QD, class QDD, class Tau>
NHDYN_FLATTEN void tree_rne_kernel_flat(const std::vector<tree_link<LS>>& L, const vec3<T>& g, const Q& q,
                                        const QD& qd, const QDD& qdd, Tau& tau) {
  tree_rne_kernel_impl<Gravity, Velocity, T>(L, g, q, qd, qdd, tau);
}
template <bool Gravity, bool Velocity, class T, class LS, class Q, class QD, class QDD, class Tau>
void tree_rne_kernel_on(const std::vector<tree_link<LS>>& L, const vec3<T>& g, const Q& q, const QD& qd,
                        const QDD& qdd, Tau& tau) {
  if constexpr (flatten_kernels<T>)
    tree_rne_kernel_flat<Gravity, Velocity, T>(L, g, q, qd, qdd, tau);
  else
    tree_rne_kernel_impl<Gravity, Velocity, T>(L, g, q, qd, qdd, tau);
}
/// The kernel on maps of the vectors (kernel_vector): one kernel per scalar, whatever Eigen
/// types the caller passes.
template <bool Gravity, bool Velocity, class T, class LS, class Q, class QD, class QDD, class Tau>
void tree_rne_kernel(const std::vector<tree_link<LS>>& L, const vec3<T>& g, const Q& q, const QD& qd, const QDD& qdd,
                     Tau& tau) {
  const kernel_input<dynamic, Q> qi(q);
  const kernel_input<dynamic, QD> qdi(qd);
  const kernel_input<dynamic, QDD> qddi(qdd);
  decltype(auto) out = kernel_vector<dynamic>(tau);
  tree_rne_kernel_on<Gravity, Velocity, T>(L, g, qi.get(), qdi.get(), qddi.get(), out);
}

/// The CRBA's per-body constants as arrays over the bodies, which its loop over bodies reads
/// contiguously (and vectorises): I_o about K_i's origin (entries 00, 11, 22, 01, 02, 12),
/// h = m·c and m, all in K_i. Built once with the function object.
template <class S>
struct crba_constants {
  int n = 0;
  std::vector<S> v;  ///< 10 arrays of n: I00 I11 I22 I01 I02 I12 h0 h1 h2 m
  const S* operator[](int k) const { return v.data() + static_cast<std::ptrdiff_t>(k) * n; }
};

template <class S>
crba_constants<S> make_crba_constants(const std::vector<tree_link<S>>& L) {
  crba_constants<S> c;
  c.n = static_cast<int>(L.size());
  c.v.resize(10 * L.size());
  for (int i = 0; i < c.n; ++i) {
    const auto& k = L[static_cast<std::size_t>(i)];
    const S e[10] = {k.Io(0, 0), k.Io(1, 1), k.Io(2, 2), k.Io(0, 1), k.Io(0, 2), k.Io(1, 2), k.h(0), k.h(1), k.h(2), k.m};
    for (int a = 0; a < 10; ++a) c.v[static_cast<std::size_t>(a * c.n + i)] = e[a];
  }
  return c;
}

/// The composite-rigid-body algorithm in the kernel frames, for the scalars that are not those
/// of `flatten_kernels` (intervals, duals, multiprecision; floating point and SIMD packs have
/// tree_crba_kernel_world below). It builds each composite in its own body's kernel frame, so
/// that an interval's composite is turned by one joint's rotation at a time and M's diagonal is
/// read in that frame: the enclosures stay narrower than when every body's inertia is turned by
/// its whole rotation to the world (2.5–6× narrower in sum on random trees over a box of q;
/// docs/performance.md, note 30). RBDA Table 6.2 in
/// 3-vector form; dynamics/reference.hpp's `crba` is the book's algorithm it optimises, tested
/// equal. One forward pass and one backward pass:
///  - forward: each body's placement (R_i, p_i) in its parent's kernel frame, and the kernel
///    frame's axes in the world, W_i = W_λ R_i, with w_i = W_λ p_i (the step from λ's origin
///    to i's, in world axes);
///  - backward, at body i once its composite (m, h = m c, I_o about K_i's origin) is complete:
///    F_i = Ic_i S_i as a moment n about K_i's origin and a force f (ω = z: f = z × h, n = I_o z;
///    v = z: f = m z, n = h × z), turned to world axes once; then for each ancestor j, the
///    moment about j's origin n + d × f, with d = Σ w_k from i up to j (accumulated step by step,
///    so the positions stay as local as the frames': no far reference point), and
///    H(i, j) = z_j · (n + d × f) for a revolute j, z_j · f for a prismatic one: a cross and a dot
///    per step (9 multiplications) instead of carrying (n, f) through each parent frame (two
///    rotations and a cross: 24);
///  - then the composite goes to the parent's frame: h' = R h + m p, and, with a = R h + (m/2) p,
///    I_o' = R I_o Rᵀ + 2 (p·a) 1 − (a pᵀ + p aᵀ) (the parallel-axis theorem), the symmetric
///    product written as its six entries; on the diagonal 2 (p·a) − 2 a_k p_k is summed as the
///    two other terms (no cancellation, and no widening for intervals).
template <class T, class Q, class Out>
void tree_crba_kernel_local(const std::vector<tree_link<T>>& L, const Q& q, Out& H, bool zero_fill = true) {
  const int n = static_cast<int>(L.size());
  // on the stack up to 32 KiB (110 bodies in double), beyond in a heap block the thread keeps
  // (detail/small_buffer.hpp)
  struct ws {
    mat3<T> R, Io, W;
    vec3<T> p, h, w;
    T m;
  };
  small_buffer<ws, dynamic> s(n);
  for (int i = 0; i < n; ++i) {
    auto& c = s[i];
    kernel_placement(L[i], T(q(i)), c.R, c.p);
    c.m = L[i].m;
    c.h = L[i].h;
    c.Io = L[i].Io;
    const int l = L[i].parent;
    if (l < 0) {
      c.W = c.R;
      c.w.setZero();
    } else {
      c.W.noalias() = s[l].W * c.R;
      c.w.noalias() = s[l].W * c.p;
    }
  }
  if (zero_fill) H.setZero(n, n);
  for (int i = n - 1; i >= 0; --i) {
    auto& c = s[i];
    vec3<T> f, nm;
    if (L[i].revolute) {
      f = vec3<T>(-c.h.y(), c.h.x(), T(0));
      nm = c.Io.col(2);
    } else {
      f = vec3<T>(T(0), T(0), c.m);
      nm = vec3<T>(c.h.y(), -c.h.x(), T(0));
    }
    H(i, i) = L[i].revolute ? nm.z() : f.z();
    if (L[i].has_armature) H(i, i) += L[i].Ia;
    const int l = L[i].parent;
    if (l < 0) continue;
    const vec3<T> fw = c.W * f, nw = c.W * nm;
    vec3<T> d = vec3<T>::Zero();
    for (int j = i; L[j].parent >= 0;) {
      d += s[j].w;
      j = L[j].parent;
      const auto z = s[j].W.col(2);
      H(i, j) = H(j, i) = L[j].revolute ? T(z.dot(nw + d.cross(fw))) : T(z.dot(fw));
    }
    // the composite of i into its parent's frame
    auto& pc = s[l];
    const auto& R = c.R;
    const auto& p = c.p;
    const vec3<T> hr = R * c.h;
    const vec3<T> a = hr + (T(0.5) * c.m) * p;
    const mat3<T> C = R * c.Io;  // R I_o Rᵀ (r, k) = C.row(r) · R.row(k)
    const T i00 = C.row(0).dot(R.row(0)) + T(2) * (p(1) * a(1) + p(2) * a(2));
    const T i11 = C.row(1).dot(R.row(1)) + T(2) * (p(0) * a(0) + p(2) * a(2));
    const T i22 = C.row(2).dot(R.row(2)) + T(2) * (p(0) * a(0) + p(1) * a(1));
    const T i01 = C.row(0).dot(R.row(1)) - a(0) * p(1) - p(0) * a(1);
    const T i02 = C.row(0).dot(R.row(2)) - a(0) * p(2) - p(0) * a(2);
    const T i12 = C.row(1).dot(R.row(2)) - a(1) * p(2) - p(1) * a(2);
    auto& J = pc.Io;
    J(0, 0) += i00;
    J(1, 1) += i11;
    J(2, 2) += i22;
    J(0, 1) += i01;
    J(1, 0) += i01;
    J(0, 2) += i02;
    J(2, 0) += i02;
    J(1, 2) += i12;
    J(2, 1) += i12;
    pc.m += c.m;
    pc.h += hr + c.m * p;
  }
}

/// The composite-rigid-body algorithm for floating point and SIMD packs (the scalars of
/// `flatten_kernels`; RBDA Table 6.2 in 3-vector form;
/// dynamics/reference.hpp's `crba` is the book's algorithm it optimises, tested equal).
/// Composites in world axes, each about its own body's origin, so that no position is far:
///  1. forward, per body: K_i's placement (R_i, p_i) in K_λ, its axes in the world
///     W_i = W_λ R_i, and w_i = W_λ p_i, the step from λ's origin to i's in world axes;
///  2. a loop over the bodies with no dependence between them (vectorised): each body's own
///     inertia turned to world axes, I = W I_o Wᵀ (the symmetric product as its six entries),
///     h = W h, m;
///  3. backward, at body i once its composite (m, h, I about i's origin, world axes) is
///     complete: F_i = Ic_i S_i as a moment n about i's origin and a force f (ω = z_i:
///     f = z × h, n = I z; v = z_i: f = m z, n = h × z), H(i, i) = S_i · F_i; then for each
///     ancestor j, the moment about j's origin n + d × f with d = Σ w_k from i up to j
///     (accumulated step by step: only local steps enter), and H(i, j) = z_j · (n + d × f) for a
///     revolute j, z_j · f for a prismatic one; then the composite moves to λ's origin, with
///     r = w_i and a = h + (m/2) r: h' = h + m r, I' = I + 2 (r·a) 1 − (a rᵀ + r aᵀ) (the
///     parallel-axis theorem; on the diagonal 2 (r·a) − 2 a_k r_k is summed as the two other
///     terms: no cancellation). No rotation in the backward pass: all are world axes.
/// The arrays live in one scratch block (22 scalars a body), written as plain scalars, which
/// g++ 12 and clang 14 both compile to straight-line code; H is written through its data
/// pointer (H is a plain column-major matrix). Both kernels write every entry a branch can make
/// nonzero (H(i, i), H(i, j) and H(j, i) for j an ancestor of i) and, with `zero_fill`, zero H
/// first; without it, H must be n × n and hold zeros everywhere else (mass_matrix_result).
template <class T, class Q, class Out>
void tree_crba_kernel_world(const std::vector<tree_link<T>>& L, const crba_constants<T>& K, const Q& q, Out& H,
                            bool zero_fill = true) {
  static_assert(!Out::IsRowMajor, "H is written as a column-major matrix");
  const int n = static_cast<int>(L.size());
  // on the stack up to 32 KiB (186 bodies in double), beyond in a heap block the thread keeps
  // (detail/small_buffer.hpp); not zeroed
  small_buffer<T, dynamic> s(22 * n);
  const auto arr = [&](int k) { return s.data() + static_cast<std::ptrdiff_t>(k) * n; };
  // W column-major (W[3c + r] = W(r, c)); its third column is the joint axis z in the world
  T* __restrict W[9] = {arr(0), arr(1), arr(2), arr(3), arr(4), arr(5), arr(6), arr(7), arr(8)};
  T* __restrict w[3] = {arr(9), arr(10), arr(11)};
  T* __restrict hc[3] = {arr(12), arr(13), arr(14)};
  T* __restrict Ic[6] = {arr(15), arr(16), arr(17), arr(18), arr(19), arr(20)};  // 00 11 22 01 02 12
  T* __restrict mc = arr(21);
  // 1. forward
  for (int i = 0; i < n; ++i) {
    mat3<T> R;
    vec3<T> p;
    kernel_placement(L[i], T(q(i)), R, p);
    const int l = L[i].parent;
    if (l < 0) {
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) W[3 * c + r][i] = R(r, c);
      w[0][i] = w[1][i] = w[2][i] = T(0);
      continue;
    }
    const T l00 = W[0][l], l10 = W[1][l], l20 = W[2][l], l01 = W[3][l], l11 = W[4][l], l21 = W[5][l], l02 = W[6][l],
            l12 = W[7][l], l22 = W[8][l];
    for (int c = 0; c < 3; ++c) {
      const T x = R(0, c), y = R(1, c), z = R(2, c);
      W[3 * c][i] = l00 * x + l01 * y + l02 * z;
      W[3 * c + 1][i] = l10 * x + l11 * y + l12 * z;
      W[3 * c + 2][i] = l20 * x + l21 * y + l22 * z;
    }
    w[0][i] = l00 * p(0) + l01 * p(1) + l02 * p(2);
    w[1][i] = l10 * p(0) + l11 * p(1) + l12 * p(2);
    w[2][i] = l20 * p(0) + l21 * p(1) + l22 * p(2);
  }
  // 2. each body's own inertia in world axes
  {
    const T *__restrict J00 = K[0], *__restrict J11 = K[1], *__restrict J22 = K[2], *__restrict J01 = K[3],
                        *__restrict J02 = K[4], *__restrict J12 = K[5], *__restrict g0 = K[6], *__restrict g1 = K[7],
                        *__restrict g2 = K[8], *__restrict gm = K[9];
#if defined(__clang__)
#pragma clang loop vectorize(assume_safety)
#elif defined(__GNUC__)
#pragma GCC ivdep
#endif
    for (int i = 0; i < n; ++i) {
      const T a00 = W[0][i], a10 = W[1][i], a20 = W[2][i], a01 = W[3][i], a11 = W[4][i], a21 = W[5][i], a02 = W[6][i],
              a12 = W[7][i], a22 = W[8][i];
      const T j00 = J00[i], j11 = J11[i], j22 = J22[i], j01 = J01[i], j02 = J02[i], j12 = J12[i];
      const T c00 = a00 * j00 + a01 * j01 + a02 * j02, c01 = a00 * j01 + a01 * j11 + a02 * j12,
              c02 = a00 * j02 + a01 * j12 + a02 * j22;  // C = W I_o
      const T c10 = a10 * j00 + a11 * j01 + a12 * j02, c11 = a10 * j01 + a11 * j11 + a12 * j12,
              c12 = a10 * j02 + a11 * j12 + a12 * j22;
      const T c20 = a20 * j00 + a21 * j01 + a22 * j02, c21 = a20 * j01 + a21 * j11 + a22 * j12,
              c22 = a20 * j02 + a21 * j12 + a22 * j22;
      Ic[0][i] = c00 * a00 + c01 * a01 + c02 * a02;  // (W I_o Wᵀ)(r, k) = C.row(r) · W.row(k)
      Ic[1][i] = c10 * a10 + c11 * a11 + c12 * a12;
      Ic[2][i] = c20 * a20 + c21 * a21 + c22 * a22;
      Ic[3][i] = c00 * a10 + c01 * a11 + c02 * a12;
      Ic[4][i] = c00 * a20 + c01 * a21 + c02 * a22;
      Ic[5][i] = c10 * a20 + c11 * a21 + c12 * a22;
      hc[0][i] = a00 * g0[i] + a01 * g1[i] + a02 * g2[i];
      hc[1][i] = a10 * g0[i] + a11 * g1[i] + a12 * g2[i];
      hc[2][i] = a20 * g0[i] + a21 * g1[i] + a22 * g2[i];
      mc[i] = gm[i];
    }
  }
  // 3. backward
  if (zero_fill) H.setZero(n, n);
  T* const Hd = H.data();  // H(r, c) = Hd[r + c n]: clang 14 leaves Eigen's accessor a call here
  for (int i = n - 1; i >= 0; --i) {
    const T z0 = W[6][i], z1 = W[7][i], z2 = W[8][i];
    const T h0 = hc[0][i], h1 = hc[1][i], h2 = hc[2][i];
    const T m = mc[i];
    T f0, f1, f2, n0, n1, n2, Hii;
    if (L[i].revolute) {  // f = z × h, n = I z
      f0 = z1 * h2 - z2 * h1, f1 = z2 * h0 - z0 * h2, f2 = z0 * h1 - z1 * h0;
      n0 = Ic[0][i] * z0 + Ic[3][i] * z1 + Ic[4][i] * z2;
      n1 = Ic[3][i] * z0 + Ic[1][i] * z1 + Ic[5][i] * z2;
      n2 = Ic[4][i] * z0 + Ic[5][i] * z1 + Ic[2][i] * z2;
      Hii = z0 * n0 + z1 * n1 + z2 * n2;
    } else {  // f = m z, n = h × z
      f0 = m * z0, f1 = m * z1, f2 = m * z2;
      n0 = h1 * z2 - h2 * z1, n1 = h2 * z0 - h0 * z2, n2 = h0 * z1 - h1 * z0;
      Hii = m;
    }
    if (L[i].has_armature) Hii += L[i].Ia;
    Hd[i + i * n] = Hii;
    const int l = L[i].parent;
    if (l < 0) continue;
    T d0(0), d1(0), d2(0);
    for (int j = i; L[j].parent >= 0;) {
      d0 += w[0][j], d1 += w[1][j], d2 += w[2][j];
      j = L[j].parent;
      const T y0 = W[6][j], y1 = W[7][j], y2 = W[8][j];
      T v;
      if (L[j].revolute) {
        const T m0 = n0 + (d1 * f2 - d2 * f1), m1 = n1 + (d2 * f0 - d0 * f2), m2 = n2 + (d0 * f1 - d1 * f0);
        v = y0 * m0 + y1 * m1 + y2 * m2;
      } else {
        v = y0 * f0 + y1 * f1 + y2 * f2;
      }
      Hd[i + j * n] = v;
      Hd[j + i * n] = v;
    }
    // the composite of i moves to λ's origin
    const T r0 = w[0][i], r1 = w[1][i], r2 = w[2][i];
    const T hm = T(0.5) * m;
    const T a0 = h0 + hm * r0, a1 = h1 + hm * r1, a2 = h2 + hm * r2;
    Ic[0][l] += Ic[0][i] + T(2) * (r1 * a1 + r2 * a2);
    Ic[1][l] += Ic[1][i] + T(2) * (r0 * a0 + r2 * a2);
    Ic[2][l] += Ic[2][i] + T(2) * (r0 * a0 + r1 * a1);
    Ic[3][l] += Ic[3][i] - a0 * r1 - r0 * a1;
    Ic[4][l] += Ic[4][i] - a0 * r2 - r0 * a2;
    Ic[5][l] += Ic[5][i] - a1 * r2 - r1 * a2;
    mc[l] += m;
    hc[0][l] += h0 + m * r0;
    hc[1][l] += h1 + m * r1;
    hc[2][l] += h2 + m * r2;
  }
}

/// Flattened (every call inside inlined), as rne is for the scalars of `flatten_kernels`.
template <class T, class Q, class Out>
NHDYN_FLATTEN void tree_crba_kernel_flat(const std::vector<tree_link<T>>& L, const crba_constants<T>& K, const Q& q,
                                         Out& H, bool zero_fill) {
  tree_crba_kernel_world<T>(L, K, q, H, zero_fill);
}

}  // namespace detail

/// rne over a tree: `rne(t)(q, qd, qdd)` (see dynamics/rne.hpp for the meaning and options).
template <class S>
class tree_rne_fn : public stage_tag {
 public:
  using model_scalar = S;
  static constexpr int size_at_compile_time = dynamic;

  explicit tree_rne_fn(const tree<S>& t, rne_options o = {})
      : links_(detail::make_tree_links(t)), g_(t.gravity()), n_(t.dof()), opt_(o), floating_(t.floating()) {}

  int dof() const { return n_; }
  /// q's entries: dof() + 1 for a floating tree (model/floating.hpp), else dof().
  int nq() const { return n_ + (floating_ ? 1 : 0); }
  bool floating() const { return floating_; }
  rne_options options() const { return opt_; }
  const vec3<S>& gravity() const { return g_; }
  tree_rne_fn with(rne_options o) const {
    tree_rne_fn r = *this;
    r.opt_ = o;
    return r;
  }

  template <class Q, class QD, class QDD>
    requires scalar<typename Q::Scalar> && scalar<typename QD::Scalar> && scalar<typename QDD::Scalar>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<QDD>& qdd) const {
    using T = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>, typename QDD::Scalar>;
    vecN<T, dynamic> v(n_);
    evaluate(q, qd, qdd, v);
    return v;
  }

  /// With applied forces (external wrenches, dynamics/wrench.hpp): v − Q_ext(q).
  template <class Q, class QD, class QDD, applied_forces F>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                  const F& fx) const {
    return detail::minus_applied<dynamic>((*this)(q, qd, qdd), fx, q);
  }

  /// Pipeline form: ξ = (q, q̇, q̈) → (q, v).
  template <class X>
  generalized_forces<promote_t<S, X>, dynamic> operator()(const joint_state<X, dynamic>& xi) const {
    return {xi.q.template cast<promote_t<S, X>>(), (*this)(xi.q, xi.qd, xi.qdd)};
  }
  /// On a temporary ξ (inside a composition) of the model's scalar: v written over q̈ (no
  /// allocation; the kernel reads q̈_i before it writes v_i), q moved on.
  template <class X>
  generalized_forces<promote_t<S, X>, dynamic> operator()(joint_state<X, dynamic>&& xi) const {
    if constexpr (std::is_same_v<promote_t<S, X>, X>) {
      evaluate(xi.q, xi.qd, xi.qdd, xi.qdd);
      return {std::move(xi.q), std::move(xi.qdd)};
    } else {
      return (*this)(static_cast<const joint_state<X, dynamic>&>(xi));
    }
  }
  /// …and with a memo (what the lift computed for the projection), passed on with (q, v).
  template <class X, class Memo>
  auto operator()(const with_memo<joint_state<X, dynamic>, Memo>& xi) const {
    with_memo<generalized_forces<promote_t<S, X>, dynamic>, Memo> out{
        {xi.q.template cast<promote_t<S, X>>(), (*this)(xi.q, xi.qd, xi.qdd)}, xi.memo};
    return out;
  }
  template <class X, class Memo>
  auto operator()(with_memo<joint_state<X, dynamic>, Memo>&& xi) const {
    using T = promote_t<S, X>;
    if constexpr (std::is_same_v<T, X>) {  // v over q̈, q moves on (no copy)
      evaluate(xi.q, xi.qd, xi.qdd, xi.qdd);
      return with_memo<generalized_forces<T, dynamic>, Memo>{{std::move(xi.q), std::move(xi.qdd)}, std::move(xi.memo)};
    } else {
      auto v = (*this)(xi.q, xi.qd, xi.qdd);
      return with_memo<generalized_forces<T, dynamic>, Memo>{{xi.q.template cast<T>(), std::move(v)}, std::move(xi.memo)};
    }
  }

  const std::vector<detail::tree_link<S>>& links() const { return links_; }

  /// v = rne(q, q̇, q̈) into v (n entries, of the model's and the inputs' scalar; a vector or a
  /// map: no allocation). v may be q̈'s own storage.
  template <class Q, class QD, class QDD, class V>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                Eigen::MatrixBase<V>& v) const {
    using T = typename V::Scalar;
    static_assert(std::is_same_v<T, promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>,
                                              typename QDD::Scalar>>,
                  "v's scalar is the model's and the inputs' promoted scalar");
    detail::check_size(v, n_, "v");
    detail::check_size(qd, n_, "qd");
    detail::check_size(qdd, n_, "qdd");
    if (opt_.velocity) detail::check_finite(qd, "qd");
    detail::check_finite(qdd, "qdd");
    if (floating_) {
      evaluate_floating(q, qd, qdd, v);
      return;
    }
    detail::check_size(q, n_, "q");
    detail::check_finite(q, "q");
    run<T>(g_.template cast<T>(), q, qd, qdd, v);
  }
  /// v = rne(q, q̇, q̈) − Q_ext(q) into v: below.
 private:
  /// The kernel on (q, q̇, q̈) with gravity g.
  template <class T, class Q, class QD, class QDD, class V>
  void run(const vec3<T>& g, const Q& q, const QD& qd, const QDD& qdd, V& v) const {
    const auto go = [&](const std::vector<detail::tree_link<T>>& L) {
      if (opt_.gravity)
        opt_.velocity ? detail::tree_rne_kernel<true, true, T>(L, g, q, qd, qdd, v)
                      : detail::tree_rne_kernel<true, false, T>(L, g, q, qd, qdd, v);
      else
        opt_.velocity ? detail::tree_rne_kernel<false, true, T>(L, g, q, qd, qdd, v)
                      : detail::tree_rne_kernel<false, false, T>(L, g, q, qd, qdd, v);
    };
    if constexpr (std::is_same_v<T, S>)
      go(links_);
    else
      go(detail::cast_links<T>(links_));
    detail::check_overflow(v.derived(), "rne");
  }
  /// A floating tree: the fixed-base tree in the root's frame (model/floating.hpp), q_K and
  /// q̈_K = a − b(v) in stack scratch, gravity turned into the root's axes.
  template <class Q, class QD, class QDD, class V>
  void evaluate_floating(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                         const Eigen::MatrixBase<QDD>& qdd, Eigen::MatrixBase<V>& v) const {
    using T = typename V::Scalar;
    detail::check_floating_configuration(q, n_ + 1, "q");
    detail::small_buffer<T, dynamic> qk_s(n_), ak_s(n_);
    Eigen::Map<vecN<T, dynamic>> qk(qk_s.data(), n_), ak(ak_s.data(), n_);
    detail::trunk_configuration(q, qk);
    ak = qdd.template cast<T>();
    if (opt_.velocity) detail::subtract_root_bias(qd, ak);
    const vec3<T> g = detail::root_rotation<T>(q).transpose() * g_.template cast<T>();
    run<T>(g, qk, qd, ak, v);
  }

 public:
  /// v = rne(q, q̇, q̈) − Q_ext(q) into v (applied forces: external wrenches,
  /// dynamics/wrench.hpp): the call's numbers bit for bit, no allocation (Q_ext in stack
  /// scratch) where the applied forces write into storage, as external_wrenches does.
  template <class Q, class QD, class QDD, applied_forces F, class V>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                const F& fx, Eigen::MatrixBase<V>& v) const {
    evaluate(q, qd, qdd, v);
    detail::add_applied<-1>(fx, q, v);
  }

 private:
  std::vector<detail::tree_link<S>> links_;
  vec3<S> g_;
  int n_;
  rne_options opt_;
  bool floating_ = false;
};

template <class S>
tree_rne_fn<S> rne(const tree<S>& t, rne_options o = {}) {
  return tree_rne_fn<S>(t, o);
}

/// M(q) of a tree, kept from call to call: `mass_matrix(t).evaluate(q, r)`, then `r.matrix()`.
/// A tree's M is zero wherever neither body is the other's ancestor, at every q: its zeros
/// depend on the parent of each body only. The first call into r writes all of M and keeps the
/// tree's parents beside it; the next calls by a tree with the same parents (compared, n
/// integers) write only the entries the branches can make nonzero, and the zeros stay. What
/// that saves is the zero fill of n × n entries: 0.1 µs at n = 48 and 1.5 µs at n = 96, where M
/// no longer fits the L1 cache (docs/performance.md, note 31). The matrix is read-only, so that
/// nothing can spoil its zeros; to factor M in place, use `evaluate(q, H)` into a matrix of your
/// own. Pinocchio's `Data::M` keeps its zeros the same way.
template <class T>
class mass_matrix_result {
 public:
  mass_matrix_result() = default;
  mass_matrix_result(const mass_matrix_result&) = default;
  mass_matrix_result& operator=(const mass_matrix_result&) = default;
  /// A moved-from result is written whole by its next call (Eigen's move may swap storage).
  mass_matrix_result(mass_matrix_result&& o) noexcept : H_(std::move(o.H_)), parents_(std::move(o.parents_)) {
    o.parents_.clear();
  }
  mass_matrix_result& operator=(mass_matrix_result&& o) noexcept {
    H_ = std::move(o.H_);
    parents_ = std::move(o.parents_);
    o.parents_.clear();
    return *this;
  }
  const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>& matrix() const { return H_; }

 private:
  template <class>
  friend class tree_mass_matrix_fn;
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> H_;
  std::vector<int> parents_;  ///< the parents of the tree whose zeros H_ holds (empty: none)
};

/// M(q) of a tree by the composite-rigid-body algorithm: `mass_matrix(t)(q)`.
template <class S>
class tree_mass_matrix_fn : public stage_tag {
 public:
  explicit tree_mass_matrix_fn(const tree<S>& t)
      : links_(detail::make_tree_links(t)), n_(t.dof()), floating_(t.floating()) {
    if constexpr (flatten_kernels<S>) consts_ = detail::make_crba_constants(links_);  // the world-axes kernel's only
    parents_.reserve(links_.size());
    for (const auto& k : links_) parents_.push_back(k.parent);
  }
  int dof() const { return n_; }

  template <class Q>
  auto operator()(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<S, typename Q::Scalar>;
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> H;
    evaluate(q, H);
    return H;
  }
  /// M(q) into H (resized to n × n: no allocation when it is that size already).
  template <class Q, class T>
  void evaluate(const Eigen::MatrixBase<Q>& q, Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>& H) const {
    run(q, H, true);
  }
  /// M(q) into r, writing only the entries the branches can make nonzero when r holds the
  /// zeros of a tree with these parents from an earlier call (mass_matrix_result); no
  /// allocation after r's first call.
  template <class Q, class T>
  void evaluate(const Eigen::MatrixBase<Q>& q, mass_matrix_result<T>& r) const {
    const bool fill = r.parents_ != parents_ || r.H_.rows() != n_ || r.H_.cols() != n_;
    if (fill) r.parents_.clear();  // until M is whole (run checks q before it writes, and may throw)
    run(q, r.H_, fill);
    if (fill) r.parents_ = parents_;
  }

 private:
  template <class Q, class T>
  void run(const Eigen::MatrixBase<Q>& q, Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>& H, bool fill) const {
    static_assert(std::is_same_v<T, promote_t<S, typename Q::Scalar>>, "H's scalar is the model's and q's");
    if (floating_) {  // M of the tree in the root's frame, at q_K (model/floating.hpp): the root's pose drops out
      detail::check_floating_configuration(q, n_ + 1, "q");
      detail::small_buffer<T, dynamic> qk_s(n_);
      Eigen::Map<vecN<T, dynamic>> qk(qk_s.data(), n_);
      detail::trunk_configuration(q, qk);
      kernel(qk, H, fill);
      return;
    }
    detail::check_size(q, n_, "q");
    detail::check_finite(q, "q");
    kernel(q, H, fill);
  }
  template <class Q, class T>
  void kernel(const Eigen::MatrixBase<Q>& q, Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>& H, bool fill) const {
    const detail::kernel_input<dynamic, Q> qi(q.derived());  // one kernel per scalar, whatever q's type
    const auto& qv = qi.get();
    if constexpr (flatten_kernels<T> && std::is_same_v<T, S>)
      detail::tree_crba_kernel_flat<T>(links_, consts_, qv, H, fill);
    else if constexpr (flatten_kernels<T>) {
      const auto L = detail::cast_links<T>(links_);
      detail::tree_crba_kernel_flat<T>(L, detail::make_crba_constants(L), qv, H, fill);
    } else if constexpr (std::is_same_v<T, S>)
      detail::tree_crba_kernel_local<T>(links_, qv, H, fill);
    else
      detail::tree_crba_kernel_local<T>(detail::cast_links<T>(links_), qv, H, fill);
  }

  std::vector<detail::tree_link<S>> links_;
  detail::crba_constants<S> consts_;
  int n_;
  std::vector<int> parents_;  ///< each body's parent: what decides M's zeros (mass_matrix_result)
  bool floating_ = false;
};

template <class S>
tree_mass_matrix_fn<S> mass_matrix(const tree<S>& t) {
  return tree_mass_matrix_fn<S>(t);
}

/// h(q, q̇) = C q̇ + g = rne(q, q̇, 0) of a tree: `bias(t)(q, qd)`.
template <class S>
class tree_bias_fn : public stage_tag {
 public:
  explicit tree_bias_fn(const tree<S>& t, rne_options o = {}) : rne_(t, o) {}
  template <class Q, class QD>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd) const {
    return rne_(q, qd, vecN<typename Q::Scalar, dynamic>::Zero(qd.size()));
  }

 private:
  tree_rne_fn<S> rne_;
};

template <class S>
tree_bias_fn<S> bias(const tree<S>& t, rne_options o = {}) {
  return tree_bias_fn<S>(t, o);
}

}  // namespace nhdyn

// forward_dynamics(tree): the holonomic forward dynamics of chains and trees, in one place.
#include "forward_dynamics.hpp"
