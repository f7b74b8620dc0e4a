/// \file examples/wheeled_robot.cpp
/// A real robot through the paper's method: the shipped 16-joint mobile manipulator (a URDF)
/// on its two drive wheels (a robot file, docs/model-format.md), driven along a turn while its
/// arm moves. Prints, every 0.5 s, the wheel torques, the shoulder torques and the constraint
/// forces λ (the floor's lateral force on the axle, and the two wheels' traction forces).
///
///     wheeled_robot [ROBOT_FILE]     (default: the shipped mobile_manipulator_wheels.json)
///
/// Checks its own answer and exits 1 when wrong: the forward dynamics must give back η̇, and
/// the generalized force must split exactly into actuators and constraint: v = Eτ + Aᵀλ.
///
/// It uses robot_dynamics (robot_dynamics.hpp), the front end compiled in the library: linked with
/// nhdyn::compiled, this file compiles in seconds (docs/performance.md, "Compile times").
#include <cmath>
#include <cstdio>
#include <numbers>
#include <nhdyn/robot_dynamics.hpp>

int main(int argc, char** argv) try {
  const std::string file = argc > 1 ? argv[1] : NHDYN_SOURCE_DIR "/examples/robots/mobile_manipulator_wheels.json";
  const auto robot = nhdyn::robot_dynamics::load(file);
  const auto& names = robot.eta_names();  // η = (left wheel, right wheel, the other joints)
  const int n = robot.dof(), m = robot.m();
  const int shoulder = robot.eta_index("arm_1_joint"), elbow = robot.eta_index("arm_2_joint");
  const int tau_shoulder = robot.tau_index("arm_1_joint"), tau_elbow = robot.tau_index("arm_2_joint");

  // The motion: the wheels speed up to 6 and 9 rad/s (a left turn) over 2 s; the arm's first
  // two joints swing as sin(t), 0.5 sin(2t).
  const double T = 1.0;
  const auto motion = [&](double t, Eigen::VectorXd& eta, Eigen::VectorXd& eta_dot) {
    eta.setZero(m);
    eta_dot.setZero(m);
    const double s = std::min(t / 2, 1.0), sd = t < 2 ? 0.5 : 0.0;  // ramp
    eta(0) = 6 * s, eta_dot(0) = 6 * sd;
    eta(1) = 9 * s, eta_dot(1) = 9 * sd;
    eta(shoulder) = std::cos(t / T), eta_dot(shoulder) = -std::sin(t / T);
    eta(elbow) = std::cos(2 * t), eta_dot(elbow) = -2 * std::sin(2 * t);
  };

  std::printf("%s: %d joints, eta = (%s, %s, ...), k = %d\n", robot.name().c_str(), n, names[0].c_str(),
              names[1].c_str(), robot.k());
  std::printf("  t [s]   x [m]   y [m]  yaw [deg] | tau_L   tau_R   tau_arm1 tau_arm2 [N m] | lambda [N]\n");
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n), eta, eta_dot;
  const double h = 1e-3;
  bool ok = true;
  for (int step = 0; step <= 4000; ++step) {
    const double t = step * h;
    motion(t, eta, eta_dot);
    if (step % 500 == 0) {
      const auto f = robot.inverse_dynamics_with_forces(q, eta, eta_dot);  // project ∘ rne ∘ lift, and λ
      // checks: η̇ back from the forward dynamics; v = Eτ + Aᵀλ with v from rne at the lifted state
      const Eigen::VectorXd back = robot.nh_forward_dynamics(q, eta, f.tau);
      const auto xi = robot.lift(q, eta, eta_dot);
      const Eigen::VectorXd v = robot.rne(xi.q, xi.qd, xi.qdd);
      const Eigen::VectorXd split = robot.input_map(q) * f.tau + robot.A(q).transpose() * f.lambda;
      ok = ok && (back - eta_dot).norm() <= 1e-9 * (1 + eta_dot.norm()) && (split - v).norm() <= 1e-10 * (1 + v.norm());
      std::printf("  %4.1f  %6.3f  %6.3f  %8.2f | %6.3f  %6.3f  %7.3f  %7.3f | %8.3f %8.3f %8.3f\n", t, q(0), q(1),
                  q(2) * 180 / std::numbers::pi, f.tau(0), f.tau(1), f.tau(tau_shoulder), f.tau(tau_elbow), f.lambda(0),
                  f.lambda(1), f.lambda(2));
    }
    q += h * robot.apply_S(q, eta);  // q̇ = S(q) η (explicit Euler)
  }
  if (!ok) {
    std::fprintf(stderr, "wheeled_robot: a check failed (forward dynamics or v = E tau + A^T lambda)\n");
    return 1;
  }
  return 0;
} catch (const nhdyn::error& e) {
  std::fprintf(stderr, "wheeled_robot: %s\n", e.what());
  return 1;
}
