#pragma once
/// \file spatial/spatial.hpp
/// Featherstone's spatial vector algebra (Rigid Body Dynamics Algorithms, 2008, ch. 2) on
/// Eigen, generic over the scalar: what the plain reference algorithms on trees are written
/// in. A motion vector is [ω; v] (angular first, v the velocity of the point at the frame's
/// origin), a force vector [n; f] (moment about the origin first), both in the frame's axes.
#include <Eigen/Core>

#include "../model/link.hpp"

namespace nhdyn::spatial {

template <class S>
using vec6 = Eigen::Matrix<S, 6, 1>;
template <class S>
using mat6 = Eigen::Matrix<S, 6, 6>;

/// S(v): the cross-product matrix, S(v) x = v × x.
template <class S>
mat3<S> skew(const vec3<S>& v) {
  mat3<S> m;
  m << S(0), -v.z(), v.y(), v.z(), S(0), -v.x(), -v.y(), v.x(), S(0);
  return m;
}

/// The motion transform from frame A to frame B, where B's axes are R (in A) and B's origin
/// is p (in A): X = [Rᵀ 0; −Rᵀ S(p) Rᵀ] (RBDA eq. 2.24 with E = Rᵀ, r = p).
template <class S>
mat6<S> motion_transform(const mat3<S>& R, const vec3<S>& p) {
  mat6<S> X = mat6<S>::Zero();
  // not `const mat3<S> Rt = R.transpose()`: g++ 12 at -O1 without NDEBUG warns there
  // (-Wmaybe-uninitialized, in Eigen's aliasing check)
  mat3<S> Rt = R;
  Rt.transposeInPlace();
  X.template topLeftCorner<3, 3>() = Rt;
  X.template bottomRightCorner<3, 3>() = Rt;
  X.template bottomLeftCorner<3, 3>() = -Rt * skew(p);
  return X;
}

/// crm(v) = v×: the motion cross product (RBDA eq. 2.31).
template <class S>
mat6<S> crm(const vec6<S>& v) {
  mat6<S> m = mat6<S>::Zero();
  const mat3<S> w = skew<S>(v.template head<3>());
  m.template topLeftCorner<3, 3>() = w;
  m.template bottomRightCorner<3, 3>() = w;
  m.template bottomLeftCorner<3, 3>() = skew<S>(v.template tail<3>());
  return m;
}

/// crf(v) = v×* = −crm(v)ᵀ: the force cross product (RBDA eq. 2.32).
template <class S>
mat6<S> crf(const vec6<S>& v) {
  return -crm(v).transpose();
}

/// The spatial inertia at a body frame's origin of mass m, centre of mass c and rotational
/// inertia Ic about c: [Ic + m S(c)S(c)ᵀ, m S(c); m S(c)ᵀ, m 1] (RBDA eq. 2.63).
template <class S>
mat6<S> inertia(const S& m, const vec3<S>& c, const mat3<S>& Ic) {
  mat6<S> I;
  const mat3<S> C = skew(c);
  I.template topLeftCorner<3, 3>() = Ic + m * C * C.transpose();
  I.template topRightCorner<3, 3>() = m * C;
  I.template bottomLeftCorner<3, 3>() = m * C.transpose();
  I.template bottomRightCorner<3, 3>() = m * mat3<S>::Identity();
  return I;
}

/// Rotation by angle q about the unit axis u (Rodrigues).
template <class S, class T>
mat3<T> axis_angle(const vec3<S>& u, const T& q) {
  using std::cos;
  using std::sin;
  const T c = cos(q), s = sin(q);
  const mat3<T> K = skew<T>(u.template cast<T>());
  return mat3<T>::Identity() + s * K + (T(1) - c) * K * K;
}

}  // namespace nhdyn::spatial
