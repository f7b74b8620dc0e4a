#pragma once
/// \file dynamics/mass_matrix.hpp
/// The joint-space inertia matrix M(q) by the composite-rigid-body algorithm
/// (Walker & Orin 1982; Featherstone 2008, §6.2) in link frames, and the bias
/// h(q, q̇) = C(q, q̇) q̇ + g(q) = rne(q, q̇, 0).
///
/// Composite body i (links i…n) is kept as (m, h = m·c, I about o_i) in frame i. The
/// motion of joint i, seen at o_i in frame i, is s_i = (z_i ; z_i × p_i) (revolute) or
/// (0 ; z_i) (prismatic); the momentum of composite i moving with s_i is carried down the
/// chain as a force/moment pair and M_ji = z_jᵀ n (revolute j) or z_jᵀ f (prismatic j).
#include "rne.hpp"

namespace nhdyn {

namespace detail {
/// A symmetric 3×3 matrix as six plain scalars (xx, yy, zz, xy, xz, yz).
template <class T>
struct sym3 {
  T xx, yy, zz, xy, xz, yz;
};

/// R I Rᵀ for R = Rz(θ) Rx(α) (frame i → frame i−1): two plane rotations of a symmetric
/// matrix, 2×2 block by 2×2 block.
template <class C, class A, class T>
[[gnu::always_inline]] inline sym3<T> rot_sym(const C& ca, const C& sa, const A& ct, const A& st, const sym3<T>& I) {
  // Rx(α): the (y, z) block turns, x stays.
  const T p = ca * I.yy - sa * I.yz, r = sa * I.yy + ca * I.yz;  // rows of Rx·I, columns y
  const T u = ca * I.yz - sa * I.zz, t = sa * I.yz + ca * I.zz;  //                columns z
  const T yy = p * ca - u * sa, yz = p * sa + u * ca, zz = r * sa + t * ca;
  const T xy = ca * I.xy - sa * I.xz, xz = sa * I.xy + ca * I.xz;
  // Rz(θ): the (x, y) block turns, z stays.
  const T P = ct * I.xx - st * xy, Rr = st * I.xx + ct * xy;
  const T U = ct * xy - st * yy, Tt = st * xy + ct * yy;
  return {T(P * ct - U * st), T(Rr * st + Tt * ct), zz, T(P * st + U * ct), T(ct * xz - st * yz), T(st * xz + ct * yz)};
}

/// One composite body (links i…n): mass, first moment m·c and rotational inertia about o_i,
/// in frame i.
template <class T>
struct composite {
  T m;
  v3<T> h;
  sym3<T> I;
};
}  // namespace detail

template <class S, int N = dynamic>
class mass_matrix_fn : public stage_tag {
 public:
  explicit mass_matrix_fn(const chain<S, N>& c) : links_(detail::make_dh_links(c)), n_(c.dof()) {}
  int dof() const { return n_; }

  /// M(q), n×n symmetric positive (semi-)definite.
  template <class Q>
  auto operator()(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<S, typename Q::Scalar>;
    detail::check_size(q, n_, "q");
    detail::check_finite(q, "q");
    Eigen::Matrix<T, N, N> M(n_, n_);
    fill(q, M);
    return M;
  }
  /// M(q) into M, resized to n×n (no allocation once it has that size): the call's numbers,
  /// bit for bit. q in the model's scalar.
  template <class Q>
    requires std::is_same_v<typename Q::Scalar, S>
  void evaluate(const Eigen::MatrixBase<Q>& q, Eigen::Matrix<S, N, N>& M) const {
    detail::check_size(q, n_, "q");
    detail::check_finite(q, "q");
    M.resize(n_, n_);
    fill(q, M);
  }

 private:
  /// The kernel, then the drives' rotor inertias (link::armature) on the diagonal.
  template <class Q, class Out>
  void fill(const Eigen::MatrixBase<Q>& q, Out& M) const {
    using T = typename Out::Scalar;
    const detail::kernel_input<N, Q> qi(q.derived());  // one kernel per scalar and size
    kernel<T>(qi.get(), M);
    for (int i = 0; i < n_; ++i)
      if (links_[std::size_t(i)].has_armature) M(i, i) += T(links_[std::size_t(i)].Ia);
  }

  /// Written on plain scalars (detail::v3, detail::sym3), like the rne kernel: the joint
  /// angles in one batch, model constants (cos α, sin α, p, m, h, I_o) in the model's scalar.
  ///
  /// Composite body i (links i…n) is kept as (m, h = m·c, I about o_i) in frame i. The
  /// motion of joint i, seen at o_i in frame i, is s_i = (z_i ; z_i × p_i) (revolute) or
  /// (0 ; z_i) (prismatic); the momentum of composite i moving with s_i is carried down the
  /// chain as a force/moment pair and M_ji = z_jᵀ n (revolute j) or z_jᵀ f (prismatic j).
  /// Links before the first revolute joint (a mobile base's x and y) only translate: their
  /// columns and rows need forces only, so their composites keep the mass alone.
  template <class T, class Q, class Out>
  void kernel(const Eigen::MatrixBase<Q>& q, Out& M) const {
    using namespace detail;
    using K = std::remove_cvref_t<decltype(links_[0].ca)>;  // the model's scalar
    const int n = n_;
    small_buffer<T, N> cs(n), sn(n);
    joint_angles<T, N>(links_, q, n, cs.data(), sn.data());
    // A prismatic joint's constant angle: for a floating-point T the link constants cos θ⁰,
    // sin θ⁰ (the rne kernel uses them: both algorithms then see the same rotations).
    if constexpr (std::is_floating_point_v<T>)
      for (int i = 0; i < n; ++i)
        if (const auto& k = links_[std::size_t(i)]; !k.revolute) cs[i] = T(k.ct0), sn[i] = T(k.st0);
    const auto rot_of = [&](int i, const v3<T>& v) __attribute__((always_inline)) {  // R_i v: frame i → i−1
      const auto& k = links_[std::size_t(i)];
      return rot(k.ca, k.sa, cs[i], sn[i], v);
    };
    const auto offset_of = [&](int i) __attribute__((always_inline)) {  // p_i (o_{i−1} → o_i), frame i
      const auto& k = links_[std::size_t(i)];
      if (k.revolute) return v3<T>{T(k.p0[0]), T(k.p0[1]), T(k.p0[2])};
      const T d(k.d0 + q(i));
      return v3<T>{T(k.a), T(d * k.sa), T(d * k.ca)};
    };
    int prefix = 0;
    while (prefix < n && !links_[std::size_t(prefix)].revolute) ++prefix;

    small_buffer<composite<T>, N> C(n);
    for (int i = 0; i < n; ++i) {
      const auto& k = links_[std::size_t(i)];
      C[i].m = T(k.m);
      C[i].h = v3<T>{T(k.hs[0]), T(k.hs[1]), T(k.hs[2])};
      C[i].I = sym3<T>{T(k.Is[0]), T(k.Is[1]), T(k.Is[2]), T(k.Is[3]), T(k.Is[4]), T(k.Is[5])};
    }
    // Composite inertias, tip to base: body i's (m, h, I_o) moves into frame i−1, about o_{i−1}:
    // I_{o'} = R I Rᵀ + (2 h·p + m|p|²) 1 − (p hᵀ + h pᵀ + m p pᵀ) with h ← R h, p the offset
    // o_{i−1} → o_i in frame i−1, and h' = h + m p.
    for (int i = n - 1; i > 0; --i) {
      const auto& c = C[i];
      auto& c0 = C[i - 1];
      c0.m += c.m;
      if (i - 1 < prefix) continue;  // a translating link: only its composite mass is read
      const auto& k = links_[std::size_t(i)];
      const v3<T> p = rot_of(i, offset_of(i));
      const v3<T> h = rot_of(i, c.h);
      const sym3<T> I = rot_sym(k.ca, k.sa, cs[i], sn[i], c.I);
      const v3<T> mp = c.m * p;
      const T diag = T(2) * (h.x * p.x + h.y * p.y + h.z * p.z) + (mp.x * p.x + mp.y * p.y + mp.z * p.z);
      const v3<T> w = h + h + mp;  // the diagonal of p hᵀ + h pᵀ + m p pᵀ is p ∘ (2h + m p)
      c0.I.xx += I.xx + diag - p.x * w.x;
      c0.I.yy += I.yy + diag - p.y * w.y;
      c0.I.zz += I.zz + diag - p.z * w.z;
      c0.I.xy += I.xy - (p.x * h.y + h.x * p.y + mp.x * p.y);
      c0.I.xz += I.xz - (p.x * h.z + h.x * p.z + mp.x * p.z);
      c0.I.yz += I.yz - (p.y * h.z + h.y * p.z + mp.y * p.z);
      c0.h = c0.h + h + mp;
    }
    // Columns: the momentum of composite i moving with joint i, carried to the base.
    for (int i = 0; i < n; ++i) {
      const auto& k = links_[std::size_t(i)];
      const auto& c = C[i];
      const v3<K> z{K(0), k.sa, k.ca};
      v3<T> f, nn;
      if (i < prefix) {
        f = v3<T>{T(0), T(c.m * k.sa), T(c.m * k.ca)};
      } else if (k.revolute) {
        const v3<K> p{k.p0[0], k.p0[1], k.p0[2]};
        const v3<K> u = cross(z, p);
        f = scale(c.m, z_as<T>(u)) + c_cross(z, c.h);
        nn = v3<T>{T(c.I.xx * z.x + c.I.xy * z.y + c.I.xz * z.z), T(c.I.xy * z.x + c.I.yy * z.y + c.I.yz * z.z),
                   T(c.I.xz * z.x + c.I.yz * z.y + c.I.zz * z.z)} +
             cross_c(c.h, u);
      } else {
        f = v3<T>{T(0), T(c.m * k.sa), T(c.m * k.ca)};
        nn = cross_c(c.h, z);
      }
      // Walk down: at joint j the pair is about o_{j−1} after adding p_j × f.
      for (int j = i; j >= 0; --j) {
        const auto& kj = links_[std::size_t(j)];
        if (j < i) {
          f = rot_of(j + 1, f);
          if (j >= prefix) nn = rot_of(j + 1, nn);
        }
        T mji;
        if (j < prefix) {
          mji = T(kj.sa * f.y + kj.ca * f.z);
        } else {
          if (kj.revolute)
            nn = nn + c_cross(v3<K>{kj.p0[0], kj.p0[1], kj.p0[2]}, f);
          else
            nn = nn + cross(offset_of(j), f);
          mji = kj.revolute ? T(kj.sa * nn.y + kj.ca * nn.z) : T(kj.sa * f.y + kj.ca * f.z);
        }
        M(j, i) = mji;
        M(i, j) = mji;
      }
    }
  }

  typename detail::dh_links<S, N>::type links_;
  int n_;
};

template <class S, int N>
mass_matrix_fn<S, N> mass_matrix(const chain<S, N>& c) {
  return mass_matrix_fn<S, N>(c);
}

/// h(q, q̇) = C(q, q̇) q̇ + g(q) = rne(q, q̇, 0).
template <class S, int N = dynamic>
class bias_fn : public stage_tag {
 public:
  explicit bias_fn(const chain<S, N>& c, rne_options o = {}) : rne_(c, o) {}
  template <class Q, class QD>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd) const {
    using X = typename Q::Scalar;
    return rne_(q, qd, vecN<X, N>::Zero(q.size()));
  }

 private:
  rne_fn<S, N> rne_;
};

template <class S, int N>
bias_fn<S, N> bias(const chain<S, N>& c, rne_options o = {}) {
  return bias_fn<S, N>(c, o);
}

}  // namespace nhdyn
