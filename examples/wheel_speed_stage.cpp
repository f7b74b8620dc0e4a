/// \file examples/wheel_speed_stage.cpp
/// Inserting your own stages in the nonholonomic inverse dynamics of paper5.
///
/// The library's pipeline is   lift | rne | project : (q, η, η̇) ↦ τ,   with
/// η = (v, ω, q̇₄, q̇₅) and τ = (forward force F, yaw torque T, shoulder, elbow torques).
/// A robot with two driven wheels (radius r, track width b) is commanded in wheel speeds
/// and drives wheel torques, so we add one stage on each side:
///
///     wheels_in:  (ω_R, ω_L) ↦ v = r(ω_R + ω_L)/2,  ω = r(ω_R − ω_L)/b   (and their rates)
///     wheels_out: (F, T) ↦ τ_R = r(F/2 + T/b),  τ_L = r(F/2 − T/b)
///
/// (wheels_out is the transpose of wheels_in, so the power τ_R ω_R + τ_L ω_L = F v + T ω.)
#include <cmath>
#include <cstdio>
#include <nhdyn/nhdyn.hpp>

int main() {
  using V4 = Eigen::Matrix<double, 4, 1>;
  using V5 = Eigen::Matrix<double, 5, 1>;
  const auto robot = nhdyn::presets::paper5();
  const double r = 0.08, b = 0.36;  // wheel radius, track width [m]

  // (q, wheel and arm speeds, their rates) -> ζ = (q, η, η̇).
  const auto wheels_in = nhdyn::stage([r, b](const V5& q, const V4& w, const V4& w_dot) {
    const auto to_eta = [r, b](const V4& x) {
      return V4(r * (x(0) + x(1)) / 2, r * (x(0) - x(1)) / b, x(2), x(3));
    };
    return nhdyn::reduced_state<double, 5, 4>{q, to_eta(w), to_eta(w_dot)};
  });
  // τ = (F, T, τ₄, τ₅) -> (τ_R, τ_L, τ₄, τ₅).
  const auto wheels_out = nhdyn::stage([r, b](const V4& tau) {
    return V4(r * (tau(0) / 2 + tau(1) / b), r * (tau(0) / 2 - tau(1) / b), tau(2), tau(3));
  });

  const auto id = wheels_in | nhdyn::lift(robot.constraint) | nhdyn::rne(robot.chain) |
                  nhdyn::project(robot.constraint) | wheels_out;

  const V5 q(-0.23710299623923958, 1.0, 3.141592653589793, 2.058145585963254, 1.2);  // paper5 start
  const V4 w(5.0, 3.0, 0.2, -0.1);      // ω_R, ω_L [rad/s], q̇₄, q̇₅ [rad/s]
  const V4 w_dot(2.0, -1.0, 0.5, 0.3);  // their rates [rad/s²]
  const V4 tau = id(q, w, w_dot);

  std::printf("wheel torques  tau_R = %9.5f N m, tau_L = %9.5f N m\n", tau(0), tau(1));
  std::printf("arm torques    tau_4 = %9.5f N m, tau_5 = %9.5f N m\n", tau(2), tau(3));
  // The same power on both sides of the wheel stages.
  const V4 tau_eta = (nhdyn::lift(robot.constraint) | nhdyn::rne(robot.chain) |
                      nhdyn::project(robot.constraint))(wheels_in(q, w, w_dot));
  const V4 eta = wheels_in(q, w, w_dot).eta;
  const double p_wheels = tau.dot(w), p_eta = tau_eta.dot(eta);
  std::printf("power: wheels+arm %.12f W, (F, T)-side %.12f W\n", p_wheels, p_eta);
  return std::abs(p_wheels - p_eta) <= 1e-12 * (1 + std::abs(p_eta)) ? 0 : 1;  // the stages conserve power
}
