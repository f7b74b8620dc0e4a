#pragma once
/// \file robots/presets.hpp
/// Ready-made robots.
///
/// - `paper5`: the paper's 5-DOF mobile manipulator, exactly as ../shared/spec/paper5.md
///   pins it down (Table I–II of Salazar-Silva et al.), with its no-lateral-slip constraint.
///   Parameters are boxes; `paper5_parameters` perturbs them as paper5.md says (a mass
///   factor scales that link's inertia with it; a length factor scales the DH parameter and
///   the box edge along it, and the centre of mass and inertia follow).
/// - `puma560`: the Unimation Puma 560 in standard DH with the rigid-body parameters of
///   P. Corke's Robotics Toolbox for MATLAB (`models/mdl_puma560.m`, "params of 8/95"; its
///   reference: P. Corke and B. Armstrong-Hélouvry, "A search for consensus among model
///   parameters reported for the PUMA 560 robot", ICRA 1994, pp. 1608–1613), without the
///   motor inertia Jm, gear ratios G and friction B, Tc that file adds. As published, links 1 and 3 violate the
///   triangle inequality of principal moments, so this preset is built with
///   `validation.triangle_inequality = false` (see model/chain.hpp).
/// - `puma560_motors`: the same arm with the drives that file adds (`puma560_drives`): each
///   joint's armature G²·J_m, viscous friction G²·B and Coulomb friction |G|·Tc⁺, |G|·Tc⁻,
///   joint side. rne gives the rigid body plus armature; `rne(p) + friction(p)` is what the
///   toolbox's own rne computes (its tests' values at qn reproduce: tests/test_drives.cpp).
#include <numbers>
#include <type_traits>

#include "../constraints/constraint.hpp"
#include "../model/chain.hpp"
#include "robot.hpp"

namespace nhdyn::presets {

/// π in S: to S's own precision for float, double and long double (a double π would
/// leave a long double model's α = π/2 off by 6e-17).
template <class S>
S pi_in() {
  if constexpr (std::is_floating_point_v<S>)
    return std::numbers::pi_v<S>;
  else
    return S(std::numbers::pi);
}

/// Multipliers on paper5's plant parameters (1 = nominal).
template <class S = double>
struct paper5_parameters {
  std::array<S, 5> mass_factor{S(1), S(1), S(1), S(1), S(1)};  ///< per link (links 1, 2: massless)
  S d3_factor{1};  ///< d₃ and the platform's height
  S a4_factor{1};  ///< a₄ and link 4's length
  S a5_factor{1};  ///< a₅ and link 5's length
};

/// paper5's chain (5 joints, compile-time sized).
template <class S = double>
chain<S, 5> paper5_chain(const paper5_parameters<S>& p = {}) {
  const S pi = pi_in<S>();
  const S d3 = S(0.237) * p.d3_factor, a4 = S(0.150) * p.a4_factor, a5 = S(0.168) * p.a5_factor;
  const S m3 = S(9.0) * p.mass_factor[2], m4 = S(0.1) * p.mass_factor[3], m5 = S(0.1) * p.mass_factor[4];
  const S w = S(0.050);
  std::array<link<S>, 5> L{};
  L[0] = {joint_type::prismatic, -pi / S(2), S(0), S(0), S(0), S(0), vec3<S>::Zero(), mat3<S>::Zero()};
  L[1] = {joint_type::prismatic, -pi / S(2), S(0), -pi / S(2), S(0), S(0), vec3<S>::Zero(), mat3<S>::Zero()};
  // Platform: a box 0.445 (x₃, length) × d₃ (y₃, height) × 0.393 (z₃, width); frame 3 on
  // its top face, so the centre of mass is half the height below it.
  L[2] = {joint_type::revolute, pi / S(2), S(0), S(0), d3, m3, vec3<S>(S(0), -d3 / S(2), S(0)),
          box_inertia<S>(m3, S(0.445), d3, S(0.393))};
  L[3] = {joint_type::revolute, S(0), a4, S(0), S(0), m4, vec3<S>(-a4 / S(2), S(0), S(0)),
          box_inertia<S>(m4, a4, w, w)};
  L[4] = {joint_type::revolute, S(0), a5, S(0), S(0), m5, vec3<S>(-a5 / S(2), S(0), S(0)),
          box_inertia<S>(m5, a5, w, w)};
  // Links 1 and 2 are massless unless a factor says otherwise (they stay zero).
  return chain<S, 5>(L, vec3<S>(S(-9.81), S(0), S(0)), "paper5");
}

/// paper5's constraint: no lateral slip of the base point, η = (v, ω, q̇₄, q̇₅).
template <class S = double>
differential_drive<S, 5> paper5_constraint() {
  return differential_drive<S, 5>(5, 0, 1, 2, S(0), S(-1));
}

/// The paper's robot: chain and constraint.
template <class S = double>
auto paper5(const paper5_parameters<S>& p = {}) {
  return robot<S, 5, differential_drive<S, 5>>{paper5_chain<S>(p), paper5_constraint<S>()};
}

/// Corke's standard-DH Puma 560 (6 revolute joints), gravity −9.81 m/s² along z₀.
template <class S = double>
chain<S, 6> puma560() {
  const S pi = pi_in<S>();
  const auto I = [](double xx, double yy, double zz) {
    mat3<S> M = mat3<S>::Zero();
    M(0, 0) = S(xx);
    M(1, 1) = S(yy);
    M(2, 2) = S(zz);
    return M;
  };
  const auto c = [](double x, double y, double z) { return vec3<S>(S(x), S(y), S(z)); };
  const auto R = joint_type::revolute;
  std::array<link<S>, 6> L{{
      {R, pi / S(2), S(0), S(0), S(0), S(0), c(0, 0, 0), I(0, 0.35, 0)},
      {R, S(0), S(0.4318), S(0), S(0), S(17.4), c(-0.3638, 0.006, 0.2275), I(0.13, 0.524, 0.539)},
      {R, -pi / S(2), S(0.0203), S(0), S(0.15005), S(4.8), c(-0.0203, -0.0141, 0.070), I(0.066, 0.086, 0.0125)},
      {R, pi / S(2), S(0), S(0), S(0.4318), S(0.82), c(0, 0.019, 0), I(1.8e-3, 1.3e-3, 1.8e-3)},
      {R, -pi / S(2), S(0), S(0), S(0), S(0.34), c(0, 0, 0), I(0.3e-3, 0.4e-3, 0.3e-3)},
      {R, S(0), S(0), S(0), S(0), S(0.09), c(0, 0, 0.032), I(0.15e-3, 0.15e-3, 0.04e-3)},
  }};
  return chain<S, 6>(L, vec3<S>(S(0), S(0), S(-9.81)), "puma560", validation{false});
}

/// The Puma 560's drives as Corke's toolbox publishes them (mdl_puma560.m; Puma560.py of the
/// Python toolbox), motor side: J_m [kg·m²], gear ratio G (signed: the motor turns −G times
/// the joint for G < 0), viscous B [N·m·s/rad] and Coulomb Tc⁺, Tc⁻ [N·m] at the motor.
struct puma560_drives {
  static constexpr std::array<double, 6> Jm{200e-6, 200e-6, 200e-6, 33e-6, 33e-6, 33e-6};
  static constexpr std::array<double, 6> G{-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686};
  static constexpr std::array<double, 6> B{1.48e-3, 0.817e-3, 1.38e-3, 71.2e-6, 82.6e-6, 36.7e-6};
  static constexpr std::array<double, 6> Tc_pos{0.395, 0.126, 0.132, 11.2e-3, 9.26e-3, 3.96e-3};
  static constexpr std::array<double, 6> Tc_neg{-0.435, -0.071, -0.105, -16.9e-3, -14.5e-3, -10.5e-3};
};

/// puma560 with its drives reflected to the joints: armature G²J_m, friction G²B, |G|Tc.
template <class S = double>
chain<S, 6> puma560_motors() {
  const chain<S, 6> arm = puma560<S>();
  std::array<link<S>, 6> L;
  for (int i = 0; i < 6; ++i) {
    using D = puma560_drives;
    const double G = D::G[std::size_t(i)], aG = G < 0 ? -G : G;
    L[std::size_t(i)] = arm[i];
    L[std::size_t(i)].armature = S(G * G * D::Jm[std::size_t(i)]);
    L[std::size_t(i)].friction = {G * G * D::B[std::size_t(i)], aG * D::Tc_pos[std::size_t(i)],
                                  aG * D::Tc_neg[std::size_t(i)]};
  }
  return chain<S, 6>(L, arm.gravity(), "puma560_motors", validation{false});
}

}  // namespace nhdyn::presets
