// Built against an installed nhdyn::compiled: the robot-file loader comes from the library (its
// headers only declare it under NHDYN_COMPILED). Loads the installed robot file given as the
// argument (the shipped two-wheeled mobile manipulator) and checks closed forms: 19 joints (the
// planar base's 3 and the URDF's 16), and
// at rest the planar base's x and y need no force against vertical gravity while the arm's
// joints do; robot_dynamics (robot_dynamics.hpp, compiled in the library) gives the same gravity
// torques and, on the constraint, v = E τ + Aᵀλ at a moving state. Exits non-zero on a mismatch.
#include <cmath>
#include <cstdio>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/robot_dynamics.hpp>

#ifndef NHDYN_COMPILED
#error "nhdyn::compiled must bring NHDYN_COMPILED"
#endif

int main(int argc, char** argv) try {
  if (argc != 2) return 2;
  const nhdyn::io::robot_model r = nhdyn::io::load_robot_file(argv[1]);
  const int n = r.model.dof();
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd g = nhdyn::rne(r.model)(z, z, z);
  const auto rd = nhdyn::robot_dynamics::load(argv[1]);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(n, -0.5, 0.7), eta = Eigen::VectorXd::LinSpaced(rd.m(), 1, -1);
  const auto f = rd.inverse_dynamics_with_forces(q, eta, eta.reverse());
  const auto xi = rd.lift(q, eta, eta.reverse());
  const Eigen::VectorXd v = rd.rne(xi.q, xi.qd, xi.qdd);
  const double split = (rd.input_map(q) * f.tau + rd.A(q).transpose() * f.lambda - v).norm() / (1 + v.norm());
  const bool ok = n == 19 && r.constraint.has_value() && g(0) == 0 && g(1) == 0 && g.tail(n - 3).norm() > 1 &&
                  rd.dof() == n && (rd.rne(z, z, z) - g).norm() <= 1e-15 * (1 + g.norm()) && split < 1e-12;
  std::printf("compiled loader: %s, %d joints, gravity torques |g_xy| = %g, |g_arm| = %g, robot_dynamics' split %g: %s\n",
              r.name.c_str(), n, std::hypot(g(0), g(1)), g.tail(n - 3).norm(), split, ok ? "ok" : "MISMATCH");
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::printf("compiled loader: %s\n", e.what());
  return 1;
}
