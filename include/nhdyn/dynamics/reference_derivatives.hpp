#pragma once
/// \file dynamics/reference_derivatives.hpp
/// ∂τ/∂q and ∂τ/∂q̇ of the recursive Newton–Euler algorithm on trees, by differentiating
/// reference::rne (RBDA Table 5.1) by hand, one direction at a time: the plain reference —
/// specification and test oracle — of the analytic derivatives of issue 18, not a fast
/// kernel (O(n²) 6×6 products; Carpentier & Mansard's recursion is the fast one to come).
/// Unchecked inputs; any scalar. ∂τ/∂q̈ is the mass matrix (reference::crba).
///
/// With ∂ = ∂/∂q_j: the joint transform depends on its own coordinate only,
/// ∂(ⁱX_λ)/∂q_i = −(S_i×) ⁱX_λ (S_i in body coordinates: X (s×) X⁻¹ = (Xs)×), so
///
///     ∂v_i = ∂X_i v_λ + X_i ∂v_λ                       (+ S_i for ∂/∂q̇_i)          (5.7)
///     ∂a_i = ∂X_i a_λ + X_i ∂a_λ + (∂v_i×) S_i q̇_i     (+ (v_i×) S_i for ∂/∂q̇_i)   (5.8)
///     ∂f_i = I_i ∂a_i + (∂v_i×*) I_i v_i + (v_i×*) I_i ∂v_i                          (5.9)
///     ∂τ_i = S_iᵀ ∂f_i,   ∂f_λ += ∂X_iᵀ f_i + X_iᵀ ∂f_i                              (5.10–5.11)
///
/// with ∂X_i = −(S_i×) X_i for i = j and 0 otherwise (and ∂X = 0 for q̇). The armature term
/// I_a q̈_i depends on neither. External wrenches are not taken (reference::rne's fx are
/// body-coordinate forces; a world-fixed wrench's would depend on q).
#include <utility>

#include "reference.hpp"

namespace nhdyn::reference {

/// (∂τ/∂q, ∂τ/∂q̇) of rne(t, q, q̇, q̈) (n × n each; column j: the derivative along q_j or q̇_j).
template <class T, class S>
std::pair<matX<T>, matX<T>> rne_derivatives(const tree<S>& t, const vecX<T>& q, const vecX<T>& qd, const vecX<T>& qdd,
                                            bool gravity = true) {
  using namespace spatial;
  const int n = t.dof();
  std::vector<mat6<T>> X(n), I(n);  // ^iX_λ(i), body inertias
  std::vector<vec6<T>> Si(n), v(n), a(n), f(n);
  vec6<T> a0 = vec6<T>::Zero();
  if (gravity) a0.template tail<3>() = -t.gravity().template cast<T>();
  for (int i = 0; i < n; ++i) {  // the rne itself (reference::rne), keeping v, a and the body forces f
    const auto [R, p] = placement(t[i], q(i));
    X[i] = motion_transform(R, p);
    Si[i] = motion_subspace<T>(t[i]);
    I[i] = inertia<T>(T(t[i].mass), t[i].com.template cast<T>(), t[i].inertia.template cast<T>());
    const int l = t.parent(i);
    v[i] = X[i] * (l < 0 ? vec6<T>::Zero() : v[l]) + Si[i] * qd(i);
    a[i] = X[i] * (l < 0 ? a0 : a[l]) + Si[i] * qdd(i) + crm(v[i]) * Si[i] * qd(i);
    f[i] = I[i] * a[i] + crf(v[i]) * I[i] * v[i];
  }
  std::vector<vec6<T>> F(f);  // the forces transmitted to each parent: f_i + Σ children
  for (int i = n - 1; i >= 0; --i)
    if (t.parent(i) >= 0) F[t.parent(i)] += X[i].transpose() * F[i];

  matX<T> dq(n, n), dqd(n, n);
  std::vector<vec6<T>> dv(n), da(n), df(n);
  for (int wrt_rate = 0; wrt_rate < 2; ++wrt_rate)
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {  // forward: ∂v, ∂a, ∂f
        const int l = t.parent(i);
        const vec6<T> vl = l < 0 ? vec6<T>::Zero() : v[l], al = l < 0 ? a0 : a[l];
        const vec6<T> dvl = l < 0 ? vec6<T>::Zero() : dv[l], dal = l < 0 ? vec6<T>::Zero() : da[l];
        dv[i] = X[i] * dvl;
        da[i] = X[i] * dal;
        if (i == j && !wrt_rate) {  // ∂X_i = −(S_i×) X_i
          dv[i] -= crm(Si[i]) * (X[i] * vl);
          da[i] -= crm(Si[i]) * (X[i] * al);
        }
        if (i == j && wrt_rate) dv[i] += Si[i];
        da[i] += crm(dv[i]) * Si[i] * qd(i);
        if (i == j && wrt_rate) da[i] += crm(v[i]) * Si[i];
        df[i] = I[i] * da[i] + crf(dv[i]) * I[i] * v[i] + crf(v[i]) * I[i] * dv[i];
      }
      for (int i = n - 1; i >= 0; --i) {  // backward: ∂τ, and ∂f to the parent
        (wrt_rate ? dqd : dq)(i, j) = Si[i].dot(df[i]);
        const int l = t.parent(i);
        if (l < 0) continue;
        df[l] += X[i].transpose() * df[i];
        if (i == j && !wrt_rate) df[l] += (-crm(Si[i]) * X[i]).transpose() * F[i];
      }
    }
  return {dq, dqd};
}

}  // namespace nhdyn::reference
