// Built against an installed nhdyn (find_package(nhdyn), nhdyn::nhdyn). Checks two results
// against closed forms and exits non-zero on a mismatch.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/version.hpp>

int main() {
  int failures = 0;
  if (std::strcmp(nhdyn::version_string, NHDYN_EXPECTED_VERSION) != 0) {
    std::printf("nhdyn/version.hpp says %s, the package %s: MISMATCH\n", nhdyn::version_string, NHDYN_EXPECTED_VERSION);
    ++failures;
  }
  const auto check = [&](const char* what, double got, double want, double tol) {
    const bool ok = std::abs(got - want) <= tol * std::max(1.0, std::abs(want));
    std::printf("%-44s got % .15g  want % .15g  %s\n", what, got, want, ok ? "ok" : "MISMATCH");
    failures += !ok;
  };

  // A point mass m at the tip of a massless rod of length l, swinging about z₀ with
  // gravity −g along y₀: τ = m l² q̈ + m g l cos q.
  const double m = 2.0, l = 0.7, g = 9.81, q = 0.4, qd = -1.3, qdd = 0.9;
  nhdyn::link<double> rod;
  rod.joint = nhdyn::joint_type::revolute;
  rod.a = l;
  rod.mass = m;  // com at o_1 (the tip), no rotational inertia
  const nhdyn::chain<double, 1> pendulum({rod}, {0.0, -g, 0.0}, "pendulum");
  const auto tau = nhdyn::rne(pendulum)(Eigen::Matrix<double, 1, 1>(q), Eigen::Matrix<double, 1, 1>(qd),
                                        Eigen::Matrix<double, 1, 1>(qdd));
  check("pendulum: rne = m l² q̈ + m g l cos q", tau(0), m * l * l * qdd + m * g * l * std::cos(q), 1e-13);

  // paper5.md: at the start configuration the tip (origin of frame 5) is at (0.35, 1, 0).
  const auto robot = nhdyn::presets::paper5();
  Eigen::Matrix<double, 5, 1> q0;
  q0 << -0.23710299623923958, 1.0, 3.141592653589793, 2.058145585963254, 1.2;
  const Eigen::Vector3d tip = nhdyn::kinematics(robot.chain).point(q0, 5);
  check("paper5: start tip x", tip.x(), 0.35, 1e-9);
  check("paper5: start tip y", tip.y(), 1.0, 1e-9);
  check("paper5: start tip z", tip.z(), 0.0, 1e-9);

  std::printf("nhdyn install consumer: %s\n", failures ? "FAILED" : "ok");
  return failures ? 1 : 0;
}
