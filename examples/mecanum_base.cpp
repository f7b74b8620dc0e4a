/// \file examples/mecanum_base.cpp
/// Every wheeled base through one constraint (`wheeled_base`, docs/theory.md §11): the shipped
/// mecanum base with a 5-joint arm (a youBot, examples/robots/mecanum_arm.json) slides
/// sideways while it turns a little and its arm swings. Prints, every 0.25 s, the wheel rates
/// the floor dictates, the four wheel torques (the least-norm split: four wheels drive three
/// base velocities) and the rollers' forces λ.
///
///     mecanum_base [ROBOT_FILE]     (default: the shipped mecanum_arm.json; its joint layout)
///
/// Checks its own answer and exits 1 when wrong: the forward dynamics of τ gives η̇ back, and
/// so does the forward dynamics of τ plus any torques that cancel in SᵀE (they only squeeze
/// the base), which have a larger norm.
#include <cstdio>
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/nhdyn.hpp>

int main(int argc, char** argv) try {
  const std::string file = argc > 1 ? argv[1] : NHDYN_SOURCE_DIR "/examples/robots/mecanum_arm.json";
  const nhdyn::io::robot_model robot = nhdyn::io::load_robot_file(file);
  const auto& c = std::get<nhdyn::wheeled_base<double>>(robot.constraint.value());
  const auto eta = robot.eta_names(), tau = robot.tau_names();
  std::printf("%s: n = %d, k = %d, m = %d, p = %d; mobility %d, steerability %d\n", robot.name.c_str(), c.dof(), c.k(),
              c.m(), c.p(), c.mobility(), c.steerability());
  std::printf("  eta = (%s, %s, %s, ...)   tau = (%s, ...)\n", eta[0].c_str(), eta[1].c_str(), eta[2].c_str(), tau[0].c_str());

  const auto id = nhdyn::inverse_dynamics_with_forces(robot.model, c);  // project ∘ rne ∘ lift, and λ
  const auto fd = nhdyn::nh_forward_dynamics(robot.model, c);
  const int n = c.dof(), m = c.m();
  // The motion: sideways at 0.3 m/s (world y) after a 1 s ramp, turning at 0.2 rad/s; the
  // arm's first joint swings.
  const auto motion = [&](double t, Eigen::VectorXd& e, Eigen::VectorXd& ed) {
    e.setZero(m), ed.setZero(m);
    const double s = std::min(t, 1.0), sd = t < 1 ? 1.0 : 0.0;
    e(1) = 0.3 * s, ed(1) = 0.3 * sd;
    e(2) = 0.2 * s, ed(2) = 0.2 * sd;
    e(3) = 0.5 * std::cos(2 * t), ed(3) = -std::sin(2 * t);
  };
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n), e, ed;
  bool ok = true;
  const double h = 1e-3;
  std::printf("  t [s]  base y  yaw  | wheel rates [rad/s]            | wheel torques [N m]           | roller forces [N]\n");
  for (int step = 0; step <= 2000; ++step) {
    const double t = step * h;
    motion(t, e, ed);
    const Eigen::VectorXd qd = nhdyn::apply_S(c, q, e);
    if (step % 250 == 0) {
      const auto f = id(q, e, ed);
      ok = ok && (fd(q, e, Eigen::VectorXd(f.tau)) - ed).norm() <= 1e-9 * (1 + ed.norm());
      // torques that SᵀE maps to zero: the same motion, a larger norm
      const Eigen::MatrixXd B = c.S(q).transpose() * c.E(q);
      const Eigen::VectorXd squeeze = Eigen::FullPivLU<Eigen::MatrixXd>(B).kernel().col(0);
      const Eigen::VectorXd other = f.tau + 5 * squeeze;
      ok = ok && (fd(q, e, other) - ed).norm() <= 1e-9 * (1 + ed.norm()) && other.norm() > f.tau.norm();
      std::printf("  %4.2f  %6.3f %5.2f | %6.2f %6.2f %6.2f %6.2f | %6.3f %6.3f %6.3f %6.3f | %6.2f %6.2f %6.2f %6.2f\n", t, q(1),
                  q(2), qd(3), qd(4), qd(5), qd(6), f.tau(0), f.tau(1), f.tau(2), f.tau(3), f.lambda(0), f.lambda(1),
                  f.lambda(2), f.lambda(3));
    }
    q += h * qd;  // q̇ = S(q) η (explicit Euler)
  }
  if (!ok) {
    std::fprintf(stderr, "mecanum_base: a check failed (the forward dynamics does not give eta_dot back)\n");
    return 1;
  }
  return 0;
} catch (const nhdyn::error& e) {
  std::fprintf(stderr, "mecanum_base: %s\n", e.what());
  return 1;
}
