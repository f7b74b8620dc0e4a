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
template <class T>
mat3<T> skew(const vec3<T>& v) {
  mat3<T> S;
  S << T(0), -v.z(), v.y(), v.z(), T(0), -v.x(), -v.y(), v.x(), T(0);
  return S;
}
template <class T>
struct composite {
  T m{0};
  vec3<T> h = vec3<T>::Zero();
  mat3<T> I = mat3<T>::Zero();
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
    const int n = n_;
    struct frame {
      T ct, st, d;
    };
    detail::small_buffer<frame, N> fr(n);
    detail::small_buffer<detail::composite<T>, N> C(n);
    for (int i = 0; i < n; ++i) {
      const auto [ct, st, d] = detail::geometry(links_[std::size_t(i)], T(q(i)));
      fr[i] = {ct, st, d};
      const auto& k = links_[std::size_t(i)];
      C[i].m = T(k.m);
      C[i].h = k.h.template cast<T>();
      C[i].I = k.Io.template cast<T>();
    }
    // Composite inertias, tip to base: move body i's (m, h, I_o) into frame i−1 about o_{i−1}.
    for (int i = n - 1; i > 0; --i) {
      const auto& k = links_[std::size_t(i)];
      const auto& c = C[i];
      const vec3<T> p = detail::rot(k, fr[i].ct, fr[i].st, detail::offset<T>(k, fr[i].d));  // o_{i−1}→o_i, frame i−1
      const vec3<T> h = detail::rot(k, fr[i].ct, fr[i].st, c.h);
      mat3<T> R;
      R.col(0) = detail::rot(k, fr[i].ct, fr[i].st, vec3<T>(T(1), T(0), T(0)));
      R.col(1) = detail::rot(k, fr[i].ct, fr[i].st, vec3<T>(T(0), T(1), T(0)));
      R.col(2) = detail::rot(k, fr[i].ct, fr[i].st, vec3<T>(T(0), T(0), T(1)));
      const mat3<T> Sp = detail::skew(p), Sh = detail::skew(h);
      // I_{o'} = R I_o Rᵀ − S(h)S(p) − S(p)S(h) − m S(p)S(p)
      C[i - 1].I += R * c.I * R.transpose() - Sh * Sp - Sp * Sh - c.m * Sp * Sp;
      C[i - 1].h += h + c.m * p;
      C[i - 1].m += c.m;
    }
    Eigen::Matrix<T, N, N> M(n, n);
    for (int i = 0; i < n; ++i) {
      const auto& k = links_[std::size_t(i)];
      const auto& c = C[i];
      const vec3<T> z = detail::axis<T>(k);
      const vec3<T> p = detail::offset<T>(k, fr[i].d);
      // Momentum of composite i under unit motion of joint i, about o_i in frame i.
      vec3<T> f, nn;
      if (k.revolute) {
        const vec3<T> u = z.cross(p);
        f = c.m * u + z.cross(c.h);
        nn = c.I * z + c.h.cross(u);
      } else {
        f = c.m * z;
        nn = c.h.cross(z);
      }
      // Walk down: at joint j the pair is about o_{j−1} after adding p_j × f.
      for (int j = i; j >= 0; --j) {
        const auto& kj = links_[std::size_t(j)];
        if (j < i) {
          const auto& k1 = links_[std::size_t(j + 1)];
          f = detail::rot(k1, fr[j + 1].ct, fr[j + 1].st, f);
          nn = detail::rot(k1, fr[j + 1].ct, fr[j + 1].st, nn);
        }
        nn += detail::offset<T>(kj, fr[j].d).cross(f);
        const vec3<T> zj = detail::axis<T>(kj);
        M(j, i) = kj.revolute ? T(nn.dot(zj)) : T(f.dot(zj));
        M(i, j) = M(j, i);
      }
    }
    return M;
  }

 private:
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
