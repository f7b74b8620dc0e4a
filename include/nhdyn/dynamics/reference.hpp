#pragma once
/// \file dynamics/reference.hpp
/// The plain reference algorithms on trees, in Featherstone's names and spatial algebra
/// (Rigid Body Dynamics Algorithms, 2008; "RBDA"): the specification and the test oracle of
/// the fast kernels (dynamics/tree.hpp), not what they run. Unchecked inputs; any scalar.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../model/tree.hpp"
#include "../spatial/spatial.hpp"

namespace nhdyn::reference {

template <class T>
using vecX = Eigen::Matrix<T, Eigen::Dynamic, 1>;
template <class T>
using matX = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;

/// jcalc and the tree's fixed placements: X_PB(q) = X_PJ · joint(q) · X_JB as (R, p), the body
/// frame's axes and origin in its parent's frame (RBDA §4.4, X_i = X_J X_T).
template <class T, class S>
std::pair<mat3<T>, vec3<T>> placement(const body<S>& b, const T& q) {
  const vec3<T> u = b.axis.template cast<T>();
  const mat3<T> RJ = b.joint == joint_type::revolute ? spatial::axis_angle(u, q) : mat3<T>::Identity();
  const vec3<T> pJ = b.joint == joint_type::prismatic ? vec3<T>(u * q) : vec3<T>::Zero();
  const mat3<T> R_PJ = b.R_PJ.template cast<T>();
  return {R_PJ * RJ * b.R_JB.template cast<T>(), b.p_PJ.template cast<T>() + R_PJ * (pJ + RJ * b.p_JB.template cast<T>())};
}

/// The joint's motion subspace S_i in body coordinates: [u; c × u] for a revolute joint about
/// the unit axis u through the point c, [0; u] for a prismatic one (RBDA Table 4.1).
template <class T, class S>
spatial::vec6<T> motion_subspace(const body<S>& b) {
  mat3<T> R_BJ = b.R_JB.template cast<T>();
  R_BJ.transposeInPlace();  // as spatial::motion_transform's Rt (a g++ 12 warning otherwise)
  const vec3<T> u = R_BJ * b.axis.template cast<T>();
  const vec3<T> c = -(R_BJ * b.p_JB.template cast<T>());
  spatial::vec6<T> s;
  if (b.joint == joint_type::revolute)
    s << u, c.cross(u);
  else
    s << vec3<T>::Zero(), u;
  return s;
}

/// Inverse dynamics τ = M(q)q̈ + C(q,q̇)q̇ + g(q) − Σ Jᵀf^x by the recursive Newton–Euler
/// algorithm (RBDA Table 5.1, eqs. 5.7–5.11), gravity as a fictitious base acceleration
/// a_0 = −a_g. `fx` (optional, n entries): the external spatial force on each body, (moment
/// about the body frame's origin; force), in body coordinates — RBDA's ⁱX_0* f^x_i already
/// applied. A joint's armature I_a adds I_a q̈_i to τ_i (the rotor spins with the joint).
template <class T, class S>
vecX<T> rne(const tree<S>& t, const vecX<T>& q, const vecX<T>& qd, const vecX<T>& qdd, bool gravity = true,
            const std::vector<spatial::vec6<T>>* fx = nullptr) {
  using namespace spatial;
  const int n = t.dof();
  std::vector<mat6<T>> X(n);  // ^iX_λ(i)
  std::vector<vec6<T>> Si(n), v(n), a(n), f(n);
  vec6<T> a0 = vec6<T>::Zero();
  if (gravity) a0.template tail<3>() = -t.gravity().template cast<T>();
  for (int i = 0; i < n; ++i) {
    const auto [R, p] = placement(t[i], q(i));
    X[i] = motion_transform(R, p);
    Si[i] = motion_subspace<T>(t[i]);
    const int l = t.parent(i);
    const vec6<T> vl = l < 0 ? vec6<T>::Zero() : v[l];
    const vec6<T> al = l < 0 ? a0 : a[l];
    v[i] = X[i] * vl + Si[i] * qd(i);                                   // (5.7)
    a[i] = X[i] * al + Si[i] * qdd(i) + crm(v[i]) * Si[i] * qd(i);     // (5.8)
    const mat6<T> I = inertia<T>(T(t[i].mass), t[i].com.template cast<T>(), t[i].inertia.template cast<T>());
    f[i] = I * a[i] + crf(v[i]) * I * v[i];                             // (5.9)
    if (fx) f[i] -= (*fx)[i];
  }
  vecX<T> tau(n);
  for (int i = n - 1; i >= 0; --i) {
    tau(i) = Si[i].dot(f[i]) + T(t[i].armature) * qdd(i);              // (5.11)
    if (t.parent(i) >= 0) f[t.parent(i)] += X[i].transpose() * f[i];   // (5.10)
  }
  return tau;
}

/// The joint-space inertia matrix H(q) by the composite-rigid-body algorithm (RBDA Table 6.2):
/// H_ij = 0 unless one of i, j supports the other (bodies on different branches do not couple).
template <class T, class S>
matX<T> crba(const tree<S>& t, const vecX<T>& q) {
  using namespace spatial;
  const int n = t.dof();
  std::vector<mat6<T>> X(n), Ic(n);
  std::vector<vec6<T>> Si(n);
  for (int i = 0; i < n; ++i) {
    const auto [R, p] = placement(t[i], q(i));
    X[i] = motion_transform(R, p);
    Si[i] = motion_subspace<T>(t[i]);
    Ic[i] = inertia<T>(T(t[i].mass), t[i].com.template cast<T>(), t[i].inertia.template cast<T>());
  }
  for (int i = n - 1; i >= 0; --i)
    if (t.parent(i) >= 0) Ic[t.parent(i)] += X[i].transpose() * Ic[i] * X[i];  // composite inertia
  matX<T> H = matX<T>::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    vec6<T> F = Ic[i] * Si[i];
    H(i, i) = Si[i].dot(F) + T(t[i].armature);
    for (int j = i; t.parent(j) >= 0;) {
      F = X[j].transpose() * F;
      j = t.parent(j);
      H(i, j) = H(j, i) = F.dot(Si[j]);
    }
  }
  return H;
}

/// A floating tree's (model/floating.hpp) inverse dynamics with its root as one 6-DoF joint,
/// S = 1₆ (RBDA §4.4, Table 4.1's 6-DoF joint; Pinocchio's free-flyer): the oracle of the
/// trunk-frame map. q = (p_WB, quaternion, q_joints), v = (v_B, ω_B, q̇), a = (v̇_B, ω̇_B, q̈);
/// τ = (f_B, n_B, τ_joints). The root's spatial velocity and acceleration in its own axes are
/// [ω_B; v_B] and [ω̇_B; v̇_B] (a = v̇ in body coordinates: v × v = 0), gravity the world's
/// fictitious acceleration turned into B, ^BX_W a_g = [0; R_WBᵀ g].
template <class T, class S>
vecX<T> rne_floating(const tree<S>& t, const vecX<T>& q, const vecX<T>& v, const vecX<T>& a) {
  using namespace spatial;
  const int n = t.dof();
  std::vector<mat6<T>> X(n);
  std::vector<vec6<T>> Si(n), vb(n), ab(n), f(n);
  const Eigen::Quaternion<T> quat(q(6), q(3), q(4), q(5));  // (w, x, y, z)
  const mat3<T> R_WB = quat.toRotationMatrix();
  const auto body_inertia = [&](int i) {
    return inertia<T>(T(t[i].mass), t[i].com.template cast<T>(), t[i].inertia.template cast<T>());
  };
  vb[5] << v.template segment<3>(3), v.template head<3>();
  ab[5] << a.template segment<3>(3), a.template head<3>();
  ab[5].template tail<3>() -= R_WB.transpose() * t.gravity().template cast<T>();  // a_0 = −a_g
  f[5] = body_inertia(5) * ab[5] + crf(vb[5]) * body_inertia(5) * vb[5];
  for (int i = 6; i < n; ++i) {
    const auto [R, p] = placement(t[i], q(i + 1));
    X[i] = motion_transform(R, p);
    Si[i] = motion_subspace<T>(t[i]);
    const int l = t.parent(i);
    vb[i] = X[i] * vb[l] + Si[i] * v(i);                                    // (5.7)
    ab[i] = X[i] * ab[l] + Si[i] * a(i) + crm(vb[i]) * Si[i] * v(i);        // (5.8)
    f[i] = body_inertia(i) * ab[i] + crf(vb[i]) * body_inertia(i) * vb[i];  // (5.9)
  }
  vecX<T> tau(n);
  for (int i = n - 1; i >= 6; --i) {
    tau(i) = Si[i].dot(f[i]) + T(t[i].armature) * a(i);                    // (5.11)
    f[t.parent(i)] += X[i].transpose() * f[i];                             // (5.10)
  }
  tau.template head<3>() = f[5].template tail<3>();  // the root's joint: S = 1₆, force first
  tau.template segment<3>(3) = f[5].template head<3>();
  return tau;
}

}  // namespace nhdyn::reference
