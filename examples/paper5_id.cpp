// The paper's nonholonomic inverse dynamics, τ = project ∘ rne ∘ lift, for paper5 at a
// sample state (paper5.md's start configuration, a driving and turning motion).
#include <cstdio>
#include <nhdyn/nhdyn.hpp>

int main() {
  const auto robot = nhdyn::presets::paper5();
  const auto inverse_dynamics = nhdyn::lift(robot.constraint)   // ζ = (q, η, η̇) → ξ = (q, q̇, q̈)
                              | nhdyn::rne(robot.chain)         // the holonomic algorithm, untouched
                              | nhdyn::project(robot.constraint);  // v → τ = (SᵀS)⁻¹Sᵀ v

  Eigen::Matrix<double, 5, 1> q;
  q << -0.23710299623923958, 1.0, 3.141592653589793, 2.058145585963254, 1.2;
  const Eigen::Vector4d eta(0.31, 0.2, -0.5, 0.4);       // v [m/s], ω [rad/s], q̇₄, q̇₅ [rad/s]
  const Eigen::Vector4d eta_dot(0.5, -0.3, 1.0, -2.0);   // their rates

  const Eigen::Vector4d tau = inverse_dynamics(q, eta, eta_dot);
  const auto forces = nhdyn::inverse_dynamics_with_forces(robot.chain, robot.constraint)(q, eta, eta_dot);

  std::printf("paper5 nonholonomic inverse dynamics (tau = project . rne . lift)\n");
  std::printf("  q       = [% .6f % .6f % .6f % .6f % .6f]\n", q(0), q(1), q(2), q(3), q(4));
  std::printf("  eta     = [% .6f % .6f % .6f % .6f]   (v, omega, qd4, qd5)\n", eta(0), eta(1), eta(2), eta(3));
  std::printf("  eta_dot = [% .6f % .6f % .6f % .6f]\n", eta_dot(0), eta_dot(1), eta_dot(2), eta_dot(3));
  std::printf("  tau     = [% .9f % .9f % .9f % .9f]   (N, N m, N m, N m)\n", tau(0), tau(1), tau(2), tau(3));
  std::printf("  lambda  = [% .9f]   (lateral no-slip force, N)\n", forces.lambda(0));
  return 0;
}
