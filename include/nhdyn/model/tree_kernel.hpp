#pragma once
/// \file model/tree_kernel.hpp
/// The constants the tree kernels run on (dynamics/tree.hpp, kinematics/tree.hpp), computed
/// once from a tree: each body in its *kernel frame* K_i, the moved joint frame turned once
/// so that the joint axis is z. The joint's motion is then Rz(q) or Tz(q), and the placement
/// of K_i in K_λ(i), m, m·c and the rotational inertia about K_i's origin are stored once.
#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "../detail/attributes.hpp"
#include "dh_kernel.hpp"
#include "tree.hpp"

namespace nhdyn::detail {

/// A rotation whose third column is the unit vector u (so that A·Rz(q)·Aᵀ turns about u).
template <class S>
mat3<S> align_z(const vec3<S>& u) {
  if (value_of(u.z()) > 1 - 1e-15) return mat3<S>::Identity();
  if (value_of(u.z()) < -1 + 1e-15) return vec3<S>(S(1), S(-1), S(-1)).asDiagonal();
  // x ⟂ u in the plane of u and the world axis u is least aligned with; y = u × x.
  using std::sqrt;
  const int k = std::abs(value_of(u.x())) < std::abs(value_of(u.y())) ? 0 : 1;
  vec3<S> e = vec3<S>::Zero();
  e(k) = S(1);
  vec3<S> x = e - u * u(k);
  x /= sqrt(x.dot(x));
  mat3<S> A;
  A.col(0) = x;
  A.col(1) = u.cross(x);
  A.col(2) = u;
  return A;
}

/// One body's kernel constants (see the file comment), all in the model's scalar.
template <class S>
struct tree_link {
  int parent = -1;
  bool revolute = true;
  bool has_inertia = false;
  mat3<S> R;  ///< K_i's axes in K_λ at q = 0
  vec3<S> p;  ///< K_i's origin in K_λ at q = 0
  S m{0};
  vec3<S> h;  ///< m · centre of mass, in K_i
  mat3<S> Io;  ///< rotational inertia about K_i's origin, K_i's axes
  mat3<S> R_KB;  ///< the body frame's axes in K_i
  vec3<S> p_KB;  ///< the body frame's origin in K_i
  S Ia{0};       ///< the joint's armature (joint-side rotor inertia)
  bool has_armature = false;

  template <class U>
  tree_link<U> cast() const {
    return {parent, revolute, has_inertia, R.template cast<U>(), p.template cast<U>(), U(m),
            h.template cast<U>(), Io.template cast<U>(), R_KB.template cast<U>(), p_KB.template cast<U>(),
            U(Ia), has_armature};
  }
};

template <class S>
std::vector<tree_link<S>> make_tree_links(const tree<S>& t) {
  std::vector<tree_link<S>> out(static_cast<std::size_t>(t.dof()));
  std::vector<mat3<S>> A(out.size());
  for (int i = 0; i < t.dof(); ++i) A[i] = align_z(t[i].axis);
  for (int i = 0; i < t.dof(); ++i) {
    const body<S>& b = t[i];
    auto& k = out[static_cast<std::size_t>(i)];
    k.parent = b.parent;
    k.revolute = b.joint == joint_type::revolute;
    // K_i(0) in K_λ: (A_λᵀ X_JB(λ)) · X_PJ(i) · A_i; the base for λ = −1.
    mat3<S> R0 = b.R_PJ * A[i];
    vec3<S> p0 = b.p_PJ;
    if (b.parent >= 0) {
      const auto& kl = out[static_cast<std::size_t>(b.parent)];
      p0 = kl.R_KB * p0 + kl.p_KB;
      R0 = kl.R_KB * R0;
    }
    k.R = R0;
    k.p = p0;
    k.R_KB = A[i].transpose() * b.R_JB;
    k.p_KB = A[i].transpose() * b.p_JB;
    const vec3<S> c = k.R_KB * b.com + k.p_KB;
    k.m = b.mass;
    k.h = b.mass * c;
    k.Io = k.R_KB * b.inertia * k.R_KB.transpose() + b.mass * (c.dot(c) * mat3<S>::Identity() - c * c.transpose());
    k.has_inertia = value_of(b.mass) != 0 || detail::value_matrix(b.inertia).cwiseAbs().maxCoeff() != 0;
    k.Ia = b.armature;
    k.has_armature = !is_exact_zero(b.armature);
  }
  return out;
}

/// The kernel constants in another scalar (a dual, an interval, a multiprecision number).
template <class T, class S>
std::vector<tree_link<T>> cast_links(const std::vector<tree_link<S>>& links) {
  std::vector<tree_link<T>> out;
  out.reserve(links.size());
  for (const auto& k : links) out.push_back(k.template cast<T>());
  return out;
}

/// (R, p) of K_i(q) in K_λ: R·Rz(q) and p for a revolute joint, R and p + R z q for a prismatic.
/// The link's constants may be in another scalar than q (a SIMD pack's states on double
/// constants: scalar/simd.hpp), which the products broadcast.
template <class T, class LS>
NHDYN_ALWAYS_INLINE void kernel_placement(const tree_link<LS>& k, const T& qi, mat3<T>& R, vec3<T>& p) {
  if (k.revolute) {
    // sincos_kernel for a double (no library call; the chain kernels' numbers), a dual's one
    // sin/cos of its value, an interval's pair, a SIMD pack's own (dh_kernel.hpp)
    const auto sc = sincos_of(qi);
    const T& c = sc.c;
    const T& s = sc.s;
    R.col(0) = c * k.R.col(0) + s * k.R.col(1);
    R.col(1) = c * k.R.col(1) - s * k.R.col(0);
    R.col(2) = k.R.col(2).template cast<T>();
    p = k.p.template cast<T>();
  } else {
    R = k.R.template cast<T>();
    p = k.p + k.R.col(2) * qi;
  }
}

}  // namespace nhdyn::detail
