#pragma once
/// \file model/link.hpp
/// One link of a serial chain: a standard Denavit–Hartenberg row (Spong's convention,
/// A_i = Rz(θ_i)·Tz(d_i)·Tx(a_i)·Rx(α_i)) and the link's rigid-body parameters.
#include <Eigen/Core>
#include <string>

namespace nhdyn {

template <class S>
using vec3 = Eigen::Matrix<S, 3, 1>;
template <class S>
using mat3 = Eigen::Matrix<S, 3, 3>;

enum class joint_type { revolute, prismatic };

inline const char* to_string(joint_type j) {
  return j == joint_type::revolute ? "revolute" : "prismatic";
}

/// A joint's friction, joint side (what the drive must add to move the joint; friction
/// stages, dynamics/friction.hpp): viscous·q̇, plus coulomb_pos while q̇ > 0 and coulomb_neg
/// while q̇ < 0 (coulomb_pos ≥ 0 ≥ coulomb_neg; equal magnitudes for symmetric friction).
/// Units: N·m·s/rad and N·m for a revolute joint, N·s/m and N for a prismatic one.
struct joint_friction {
  double viscous = 0;
  double coulomb_pos = 0;
  double coulomb_neg = 0;
  bool operator==(const joint_friction&) const = default;
};

/// Link i of a chain. Joint i moves link i about / along z_{i-1}:
/// a revolute joint sets θ_i = theta + q_i, a prismatic one d_i = d + q_i.
template <class S>
struct link {
  joint_type joint = joint_type::revolute;
  S alpha{0};  ///< α_i [rad]: twist about x_i
  S a{0};      ///< a_i [m]: length along x_i
  S theta{0};  ///< θ_i [rad]: the joint angle offset (revolute) or the angle (prismatic)
  S d{0};      ///< d_i [m]: the offset along z_{i-1} (prismatic) or the distance (revolute)
  S mass{0};   ///< m_i [kg]
  vec3<S> com = vec3<S>::Zero();      ///< p_{o_i c_i} in frame i [m]
  mat3<S> inertia = mat3<S>::Zero();  ///< I about the centre of mass, in frame i's axes [kg·m²]
  /// Joint-side rotor inertia of the drive (armature), G²·J_m for a motor of inertia J_m
  /// behind a gear of ratio G [kg·m² or kg]: adds armature·q̈_i to τ_i and to M's diagonal.
  S armature{0};
  joint_friction friction{};  ///< used by friction stages only (rne is friction-free)

  template <class U>
  link<U> cast() const {
    return {joint, U(alpha), U(a), U(theta), U(d), U(mass), com.template cast<U>(),
            inertia.template cast<U>(), U(armature), friction};
  }
};

/// Inertia of a solid box of mass m and edges (ex, ey, ez) along x, y, z about its centre.
template <class S>
mat3<S> box_inertia(S m, S ex, S ey, S ez) {
  mat3<S> I = mat3<S>::Zero();
  I(0, 0) = m * (ey * ey + ez * ez) / S(12);
  I(1, 1) = m * (ex * ex + ez * ez) / S(12);
  I(2, 2) = m * (ex * ex + ey * ey) / S(12);
  return I;
}

}  // namespace nhdyn
