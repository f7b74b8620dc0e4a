#pragma once
/// \file tests/reference/random_chain.hpp
/// Random but physical test chains and states (seeded, reproducible): random standard-DH
/// rows, mixed revolute/prismatic joints, masses, centres of mass and inertias that satisfy
/// the triangle inequality (I = Q diag(b+c, a+c, a+b) Qᵀ with a, b, c ≥ 0 the second moments
/// of a mass distribution and Q a random rotation), optionally a link with zero mass but
/// rotational inertia and a fully massless link.
#include <Eigen/Geometry>
#include <nhdyn/model/chain.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace nhdyn_ref {

struct random_chain_options {
  double prismatic_probability = 0.3;
  int massless_with_inertia = -1;  ///< index of a link with m = 0, I ≠ 0 (−1: none)
  int fully_massless = -1;         ///< index of a link with m = 0, I = 0 (−1: none)
  bool random_gravity = true;      ///< random direction, |g| = 9.81 (else −9.81 z₀)
};

inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

/// A physical rotational inertia about the centre of mass, in the link frame's axes.
inline Eigen::Matrix3d random_inertia(std::mt19937_64& rng, double mass_scale) {
  const double a = uniform(rng, 0.002, 0.05) * mass_scale, b = uniform(rng, 0.002, 0.05) * mass_scale,
               c = uniform(rng, 0.002, 0.05) * mass_scale;
  const Eigen::Quaterniond Q =
      Eigen::Quaterniond(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1))
          .normalized();
  const Eigen::Matrix3d R = Q.toRotationMatrix();
  Eigen::Matrix3d I = R * Eigen::Vector3d(b + c, a + c, a + b).asDiagonal() * R.transpose();
  return 0.5 * (I + I.transpose());
}

/// A random n-link chain (run-time size).
inline nhdyn::chain<double> random_chain(std::mt19937_64& rng, int n, random_chain_options o = {}) {
  constexpr double pi = std::numbers::pi;
  std::vector<nhdyn::link<double>> L(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    auto& k = L[std::size_t(i)];
    k.joint = uniform(rng, 0, 1) < o.prismatic_probability ? nhdyn::joint_type::prismatic
                                                            : nhdyn::joint_type::revolute;
    k.alpha = uniform(rng, -pi, pi);
    k.a = uniform(rng, -0.5, 0.5);
    k.theta = uniform(rng, -pi, pi);
    k.d = uniform(rng, -0.5, 0.5);
    k.mass = uniform(rng, 0.2, 5.0);
    k.com = Eigen::Vector3d(uniform(rng, -0.3, 0.3), uniform(rng, -0.3, 0.3), uniform(rng, -0.3, 0.3));
    k.inertia = random_inertia(rng, k.mass);
    if (i == o.massless_with_inertia) k.mass = 0;
    if (i == o.fully_massless) {
      k.mass = 0;
      k.inertia.setZero();
    }
  }
  Eigen::Vector3d g(0, 0, -9.81);
  if (o.random_gravity) {
    g = Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    g *= 9.81 / g.norm();
  }
  return nhdyn::chain<double>(L, g, "random" + std::to_string(n));
}

/// A random joint vector of size n with entries in [lo, hi].
inline Eigen::VectorXd random_vector(std::mt19937_64& rng, int n, double lo, double hi) {
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = uniform(rng, lo, hi);
  return v;
}

}  // namespace nhdyn_ref
