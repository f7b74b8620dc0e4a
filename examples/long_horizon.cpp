/// \file long_horizon.cpp
/// Long-horizon study (issue 6, docs/accuracy.md "Numerical stability"): paper5 unforced
/// (τ = 0, gravity on, no friction) for a given time (default 1000 s) from a moving start,
/// with each integrator of simulation/integrators.hpp over steps / tolerances. Prints one
/// markdown table row per run: energy drift max_t |E(t) − E(0)| / |E(0)| (the exact motion
/// conserves E: the constraint forces do no work), the constraint residual
/// max_t |A(q) q̇| with q̇ = S(q) η, the accepted steps and the wall time.
///
///     long_horizon [T_END=1000] [--quick]      (--quick: only the cheaper runs)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/simulation/free_motion.hpp>
#include <nhdyn/simulation/integrators.hpp>
#include <vector>

using namespace nhdyn;

namespace {
/// paper5, unforced (simulation/free_motion.hpp).
using unforced = free_motion<double, 5, differential_drive<double, 5>>;
inline unforced make_unforced() {
  const auto r = presets::paper5<double>();
  return unforced(r.chain, r.constraint);
}
}  // namespace

int main(int argc, char** argv) {
  double t_end = 1000;
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) quick = true;
    else t_end = std::atof(argv[i]);
  }
  const unforced u = make_unforced();
  vecN<double, 9> x0;
  x0 << -0.2, 1.0, 2.8, 1.9, 1.1, 0.5, -0.8, 2.0, -3.0;  // driving, turning, arm swinging
  const double E0 = u.energy(x0);
  std::vector<double> out;
  for (int i = 0; i <= int(t_end); ++i) out.push_back(double(i));  // every second
  struct run {
    method m;
    double step, tol;
    bool slow;
  };
  std::vector<run> runs{{method::rk4, 1e-2, 0, false},        {method::rk4, 1e-3, 0, false},
                        {method::dopri5, 1e-3, 1e-6, false},  {method::dopri5, 1e-3, 1e-8, false},
                        {method::dopri5, 1e-3, 1e-10, true},  {method::rosenbrock4, 1e-3, 1e-6, true},
                        {method::rosenbrock4, 1e-3, 1e-8, true}};
  std::printf("paper5 unforced, %.0f s, E(0) = %.6f J\n\n", t_end, E0);
  std::printf("| integrator | step / tolerance | energy drift max|ΔE|/|E0| | |ΔE|/|E0| at t_end | constraint residual max|A S η| | steps | wall time [s] |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const auto& r : runs) {
    if (quick && r.slow) continue;
    double drift = 0, last = 0, residual = 0;
    const auto t0 = std::chrono::steady_clock::now();
    const auto res = integrate<9>(u.rhs(), x0, 0.0, t_end, {r.m, r.step, r.tol, r.tol}, out,
                                  [&](int, const vecN<double, 9>& x) {
                                    last = std::abs(u.energy(x) - E0) / std::abs(E0);
                                    drift = std::max(drift, last);
                                    residual = std::max(residual, u.constraint_residual(x));
                                  });
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    char setting[64];
    if (r.m == method::rk4) std::snprintf(setting, sizeof setting, "h = %.0e s", r.step);
    else std::snprintf(setting, sizeof setting, "rtol = atol = %.0e", r.tol);
    if (!res.success()) {
      std::printf("| %s | %s | failed at t = %.3f: %s | | | %ld | %.1f |\n", to_string(r.m), setting, res.failure->t,
                  res.failure->reason.c_str(), res.steps, wall);
      continue;
    }
    std::printf("| %s | %s | %.1e | %.1e | %.1e | %ld | %.1f |\n", to_string(r.m), setting, drift, last, residual,
                res.steps, wall);
    std::fflush(stdout);
  }
}
