#pragma once
/// \file detail/dh.hpp
/// Link-frame building blocks shared by kinematics and dynamics: per-link constants
/// precomputed once per model, and the elementary rotations of a standard DH row.
///
/// Notation (docs/notation.md): R_i = Rz(θ_i)·Rx(α_i) maps frame-i coordinates to frame
/// i−1; p_i = the vector o_{i−1} → o_i in frame i = (a_i, d_i sin α_i, d_i cos α_i);
/// z_i = z_{i−1} in frame i = (0, sin α_i, cos α_i).
#include <cmath>
#include <vector>

#include "../model/chain.hpp"

namespace nhdyn::detail {

/// The constants of one link, as the recursions use them.
template <class S>
struct dh_link {
  bool revolute = true;
  bool inert = true;  ///< false: zero mass and zero inertia, the link is skipped
  S ca{1}, sa{0};     ///< cos α_i, sin α_i
  S a{0}, d0{0}, th0{0};
  S m{0};
  vec3<S> h = vec3<S>::Zero();   ///< first moment m_i·c_i, frame i
  mat3<S> Io = mat3<S>::Zero();  ///< rotational inertia about o_i, frame i (parallel axis)
};

template <class S>
dh_link<S> make_dh_link(const link<S>& L) {
  using std::cos;
  using std::sin;
  dh_link<S> k;
  k.revolute = L.joint == joint_type::revolute;
  k.ca = cos(L.alpha);
  k.sa = sin(L.alpha);
  // Exact zeros where α is a multiple of π/2 in double: keeps the planar cases planar.
  if constexpr (std::is_floating_point_v<S>) {
    if (std::abs(k.ca) < 1e-15) k.ca = S(0);
    if (std::abs(k.sa) < 1e-15) k.sa = S(0);
  }
  k.a = L.a;
  k.d0 = L.d;
  k.th0 = L.theta;
  k.m = L.mass;
  k.h = L.mass * L.com;
  const S cc = L.com.squaredNorm();
  k.Io = L.inertia + L.mass * (cc * mat3<S>::Identity() - L.com * L.com.transpose());  // I_o = I_c + m(|c|²1 − ccᵀ)
  bool zero = is_exact_zero(L.mass);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) zero = zero && is_exact_zero(L.inertia(r, c));
  k.inert = !zero;
  return k;
}

template <class S, int N>
struct dh_links {
  using type = std::array<dh_link<S>, static_cast<std::size_t>(N)>;
};
template <class S>
struct dh_links<S, dynamic> {
  using type = std::vector<dh_link<S>>;
};

template <class S, int N>
typename dh_links<S, N>::type make_dh_links(const chain<S, N>& c) {
  typename dh_links<S, N>::type out{};
  if constexpr (N == dynamic) out.resize(static_cast<std::size_t>(c.dof()));
  for (int i = 0; i < c.dof(); ++i) out[static_cast<std::size_t>(i)] = make_dh_link(c[i]);
  return out;
}

/// cos θ_i, sin θ_i and d_i of link i at joint value qi.
template <class T, class S>
struct joint_geometry {
  T ct, st, d;
};
template <class T, class S>
joint_geometry<T, S> geometry(const dh_link<S>& k, const T& qi) {
  using std::cos;
  using std::sin;
  if (k.revolute) {
    const T th = T(k.th0) + qi;
    return {cos(th), sin(th), T(k.d0)};
  }
  const T th = T(k.th0);
  return {cos(th), sin(th), T(k.d0) + qi};
}

/// v in frame i−1 → frame i: R_iᵀ v = Rx(α)ᵀ Rz(θ)ᵀ v.
template <class T, class S>
vec3<T> rot_T(const dh_link<S>& k, const T& ct, const T& st, const vec3<T>& v) {
  const T ux = ct * v.x() + st * v.y();
  const T uy = ct * v.y() - st * v.x();
  return {ux, T(k.ca) * uy + T(k.sa) * v.z(), T(k.ca) * v.z() - T(k.sa) * uy};
}
/// v in frame i → frame i−1: R_i v = Rz(θ) Rx(α) v.
template <class T, class S>
vec3<T> rot(const dh_link<S>& k, const T& ct, const T& st, const vec3<T>& v) {
  const T uy = T(k.ca) * v.y() - T(k.sa) * v.z();
  const T uz = T(k.sa) * v.y() + T(k.ca) * v.z();
  return {ct * v.x() - st * uy, st * v.x() + ct * uy, uz};
}
/// p_i: o_{i−1} → o_i in frame i.
template <class T, class S>
vec3<T> offset(const dh_link<S>& k, const T& d) {
  return {T(k.a), d * T(k.sa), d * T(k.ca)};
}
/// z_{i−1} in frame i.
template <class T, class S>
vec3<T> axis(const dh_link<S>& k) {
  return {T(0), T(k.sa), T(k.ca)};
}

}  // namespace nhdyn::detail
