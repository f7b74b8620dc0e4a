// Built against an installed nhdyn::compiled: the robot-file loader comes from the library (its
// headers only declare it under NHDYN_COMPILED). Loads the installed robot file given as the
// argument (the shipped two-wheeled mobile manipulator) and checks closed forms: 19 joints (the
// planar base's 3 and the URDF's 16), and
// at rest the planar base's x and y need no force against vertical gravity while the arm's
// joints do. Exits non-zero on a mismatch.
#include <cmath>
#include <cstdio>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/io/robot_file.hpp>

#ifndef NHDYN_COMPILED
#error "nhdyn::compiled must bring NHDYN_COMPILED"
#endif

int main(int argc, char** argv) try {
  if (argc != 2) return 2;
  const nhdyn::io::robot_model r = nhdyn::io::load_robot_file(argv[1]);
  const int n = r.model.dof();
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd g = nhdyn::rne(r.model)(z, z, z);
  const bool ok = n == 19 && r.constraint.has_value() && g(0) == 0 && g(1) == 0 && g.tail(n - 3).norm() > 1;
  std::printf("compiled loader: %s, %d joints, gravity torques |g_xy| = %g, |g_arm| = %g: %s\n", r.name.c_str(), n,
              std::hypot(g(0), g(1)), g.tail(n - 3).norm(), ok ? "ok" : "MISMATCH");
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::printf("compiled loader: %s\n", e.what());
  return 1;
}
