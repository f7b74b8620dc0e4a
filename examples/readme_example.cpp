#include <nhdyn/nhdyn.hpp>
#include <iostream>

int main() {
  const auto robot = nhdyn::presets::paper5();            // chain + no-slip constraint
  const auto inverse_dynamics = nhdyn::lift(robot.constraint)    // ζ = (q, η, η̇) → (q, q̇, q̈)
                              | nhdyn::rne(robot.chain)          // holonomic Newton–Euler
                              | nhdyn::project(robot.constraint);// v → τ = (SᵀS)⁻¹Sᵀ v

  Eigen::Matrix<double, 5, 1> q;
  q << 0.0, 1.0, 3.14159, 2.05, 1.2;               // base z, base y, heading, shoulder, elbow
  Eigen::Vector4d eta(0.3, 0.2, -0.5, 0.4);         // forward speed, yaw rate, q̇₄, q̇₅
  Eigen::Vector4d eta_dot(0.5, -0.3, 1.0, -2.0);

  Eigen::Vector4d tau = inverse_dynamics(q, eta, eta_dot);   // forward force, yaw torque, 2 joint torques
  auto fd = nhdyn::nh_forward_dynamics(robot.chain, robot.constraint);
  std::cout << tau.transpose() << "\n" << fd(q, eta, tau).transpose() << "\n";  // recovers η̇
}
