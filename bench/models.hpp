#pragma once
/// \file bench/models.hpp
/// The benchmark's models: paper5, puma560, random revolute chains (fixed seed) and
/// differential-drive bases (paper5's base: x, y prismatic, heading revolute, platform)
/// carrying random revolute arms; and benchmark states.
#include <nhdyn/nhdyn.hpp>
#include <random>
#include <string>
#include <vector>

#include "kdl_reference.hpp"

namespace nhdyn_bench {

using nhdyn::chain;
using nhdyn::dynamic;
using nhdyn::link;

/// A physical random link: revolute, α uniform in (−π, π), a, d in [0, 0.4] m, mass in
/// [0.5, 5] kg, com in a 0.2 m cube, inertia of a random box rotated by a random rotation
/// (so it satisfies the triangle inequality).
inline link<double> random_link(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const double pi = 3.14159265358979323846;
  link<double> L;
  L.joint = nhdyn::joint_type::revolute;
  L.alpha = pi * U(rng);
  L.a = 0.2 + 0.2 * U(rng);
  L.theta = pi * U(rng);
  L.d = 0.2 + 0.2 * U(rng);
  L.mass = 2.75 + 2.25 * U(rng);
  L.com = nhdyn::vec3<double>(0.1 * U(rng), 0.1 * U(rng), 0.1 * U(rng));
  const nhdyn::mat3<double> B =
      nhdyn::box_inertia<double>(L.mass, 0.25 + 0.2 * U(rng), 0.25 + 0.2 * U(rng), 0.25 + 0.2 * U(rng));
  const Eigen::Quaterniond r(Eigen::Vector4d(U(rng), U(rng), U(rng), U(rng)).normalized());
  const Eigen::Matrix3d R = r.toRotationMatrix();
  L.inertia = R * B * R.transpose();
  L.inertia = 0.5 * (L.inertia + L.inertia.transpose()).eval();
  return L;
}

/// A revolute chain of n random links, gravity −9.81 along z₀, seed fixed by n.
inline chain<double> random_chain(int n) {
  std::mt19937_64 rng(20260 + static_cast<unsigned>(n));
  std::vector<link<double>> L;
  for (int i = 0; i < n; ++i) L.push_back(random_link(rng));
  return chain<double>(L, nhdyn::vec3<double>(0, 0, -9.81), "rev" + std::to_string(n));
}

/// paper5's base (its links 1–3: x, y, heading with the 9 kg platform) carrying a random
/// revolute arm of `arm` joints; gravity as paper5 (−9.81 along x₀).
inline chain<double> ddrive_arm(int arm) {
  const auto p5 = nhdyn::presets::paper5_chain<double>();
  std::mt19937_64 rng(40260 + static_cast<unsigned>(arm));
  std::vector<link<double>> L{p5[0], p5[1], p5[2]};
  for (int i = 0; i < arm; ++i) L.push_back(random_link(rng));
  return chain<double>(L, p5.gravity(), "ddrive_arm" + std::to_string(arm));
}

/// paper5's constraint on such a base (x = 0, y = 1, heading = 2, heading_sign −1).
template <int N>
nhdyn::differential_drive<double, N> ddrive_constraint(int n) {
  return nhdyn::differential_drive<double, N>(n, 0, 1, 2, 0.0, -1.0);
}

/// A reproducible non-trivial state (q, q̇, q̈) of n joints.
struct state {
  Eigen::VectorXd q, qd, qdd;
};
inline state random_state(int n, unsigned seed = 7) {
  std::mt19937_64 rng(seed + static_cast<unsigned>(n));
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  state s{Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  for (int i = 0; i < n; ++i) {
    s.q(i) = 3.0 * U(rng);
    s.qd(i) = U(rng);
    s.qdd(i) = U(rng);
  }
  return s;
}

/// The DH rows of a chain for the KDL side.
template <int N>
std::vector<kdl::dh_row> kdl_rows(const chain<double, N>& c) {
  std::vector<kdl::dh_row> rows;
  for (int i = 0; i < c.dof(); ++i) {
    const auto& L = c[i];
    kdl::dh_row r{};
    r.prismatic = L.joint == nhdyn::joint_type::prismatic;
    r.alpha = L.alpha;
    r.a = L.a;
    r.theta = L.theta;
    r.d = L.d;
    r.mass = L.mass;
    for (int k = 0; k < 3; ++k) r.com[k] = L.com(k);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) r.inertia[3 * a + b] = L.inertia(a, b);
    rows.push_back(r);
  }
  return rows;
}

}  // namespace nhdyn_bench
