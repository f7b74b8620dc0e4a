/// \file work_precision.cpp
/// Work-precision of the integrators on two paper5 problems (docs/accuracy.md, "Integrators"):
///
///   circle:    the paper-circle closed loop (perturbed plant, robust controller), 20 s;
///   unforced:  paper5 with τ = 0 and gravity, from a moving state, 2 s (energy conserved;
///              the swinging arm is chaotic, so state errors grow fast with time).
///
/// For RK4 over step sizes and dopri5 / rosenbrock4 over tolerances: the error of the
/// state (q, η) at the final time against a tight reference (dopri5 at rtol = atol = 1e-13,
/// checked against RK4 at 1e-4 s), the end-effector position error there, the steps, and
/// the best-of-3 wall and CPU times. Then paper-circle's throughput (simulated s per
/// second, CSV included). Prints CSV on stdout:
///
///     problem,method,parameter,steps,state_error,position_error,energy_drift,wall_s,cpu_s
///
/// Run: build-*/examples/work_precision > wp.csv; gnuplot -e "in='wp.csv'; out='wp.png'" scripts/work_precision.gp
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/simulation/free_motion.hpp>
#include <nhdyn/simulation/simulation.hpp>

using namespace nhdyn;

namespace {
struct timing {
  double wall = INFINITY, cpu = INFINITY;
};
/// Best of n of wall and thread-CPU time (the machine may be shared: CPU time is what the
/// code costs; on an idle core wall ≈ CPU).
template <class F>
timing best_of(int n, F&& f) {
  timing best;
  for (int k = 0; k < n; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = detail::thread_cpu_seconds();
    f();
    best.cpu = std::min(best.cpu, detail::thread_cpu_seconds() - c0);
    best.wall = std::min(best.wall, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

/// paper5, unforced (simulation/free_motion.hpp).
using unforced = free_motion<double, 5, differential_drive<double, 5>>;
inline unforced make_unforced() {
  const auto r = presets::paper5<double>();
  return unforced(r.chain, r.constraint);
}

struct outcome {
  vecN<double, 9> x;
  long steps;
  double drift;
};

outcome circle(const integrator_options& o) {
  run_spec s;
  s.integrator = o;
  s.output_step = 20;  // rows at 0 and 20 s only: the integrator's work, not the output's
  const auto r = simulate(s);
  if (!r.success) std::fprintf(stderr, "circle %s failed: %s\n", to_string(o.kind), r.failure->c_str());
  return {r.rows.row(r.rows.rows() - 1).segment<9>(1).transpose(), r.steps, NAN};
}

outcome open_loop(const unforced& u, const integrator_options& o) {
  vecN<double, 9> x0;
  x0 << -0.2, 1.0, 2.8, 1.9, 1.1, 0.5, -0.8, 2.0, -3.0;
  const double E0 = u.energy(x0);
  std::vector<double> out;
  for (int i = 0; i <= 20; ++i) out.push_back(0.1 * i);
  double drift = 0;
  vecN<double, 9> last = x0;
  const auto r = integrate<9>(u.rhs(), x0, 0.0, 2.0, o, out, [&](int, const vecN<double, 9>& x) {
    drift = std::max(drift, std::abs(u.energy(x) - E0));
    last = x;
  });
  if (!r.success()) std::fprintf(stderr, "unforced %s failed: %s\n", to_string(o.kind), r.failure->reason.c_str());
  return {last, r.steps, drift};
}

double position_error(const vecN<double, 9>& a, const vecN<double, 9>& b) {
  static const kinematics<double, 5> kin(presets::paper5_chain<double>({{1.1, 1.1, 1.1, 1.1, 1.1}, 1, 1, 1}));
  return (kin.point(vecN<double, 5>(a.head<5>()), 5) - kin.point(vecN<double, 5>(b.head<5>()), 5)).norm();
}
}  // namespace

int main() {
  const unforced u = make_unforced();
  std::vector<integrator_options> cases;
  for (double h : {8e-3, 4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4}) cases.push_back({method::rk4, h});
  for (double tol : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11})
    cases.push_back({method::dopri5, 2e-3, tol, tol * 1e-2});
  for (double tol : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7}) cases.push_back({method::rosenbrock4, 2e-3, tol, tol * 1e-2});

  std::printf("problem,method,parameter,steps,state_error,position_error,energy_drift,wall_s,cpu_s\n");
  for (const char* problem : {"circle", "unforced"}) {
    const bool is_circle = std::string(problem) == "circle";
    const auto run = [&](const integrator_options& o) { return is_circle ? circle(o) : open_loop(u, o); };
    const outcome ref = run({method::dopri5, 1e-4, 1e-13, 1e-13});
    const outcome check = run({method::rk4, 1e-4});
    std::fprintf(stderr, "%s: reference (dopri5 1e-13) vs rk4 at 1e-4 s: state %.3g, position %.3g m\n", problem,
                 (ref.x - check.x).cwiseAbs().maxCoeff(), position_error(ref.x, check.x));
    for (const auto& o : cases) {
      outcome r{};
      const timing tm = best_of(is_circle && o.kind == method::rosenbrock4 ? 1 : 3, [&] { r = run(o); });
      const double param = o.kind == method::rk4 ? o.step : o.rtol;
      std::printf("%s,%s,%.3g,%ld,%.6g,%.6g,%.6g,%.6g,%.6g\n", problem, to_string(o.kind), param, r.steps,
                  (r.x - ref.x).cwiseAbs().maxCoeff(), position_error(r.x, ref.x), r.drift, tm.wall, tm.cpu);
      std::fflush(stdout);
    }
  }

  // Throughput: paper-circle (dopri5, atol = rtol/100), 10 ms rows, CSV written.
  const auto csv = std::filesystem::temp_directory_path() / "nhdyn_work_precision_circle.csv";
  for (double tol : {1e-4, 1e-5, 1e-6}) {
    run_spec s;
    s.integrator = {method::dopri5, 2e-3, tol, tol * 1e-2};
    run_result res;
    const timing tm = best_of(7, [&] {
      res = simulate(s);
      write_csv(csv.string(), res);
    });
    std::fprintf(stderr,
                 "throughput: paper-circle, dopri5 rtol %.0e: 20 s simulated in %.1f ms CPU (%.1f ms wall) incl. CSV, "
                 "best of 7: %.0fx real time (CPU); tail error %.6g m, %ld steps\n",
                 tol, 1e3 * tm.cpu, 1e3 * tm.wall, 20 / tm.cpu, res.max_tail_error, res.steps);
  }
  std::filesystem::remove(csv);
  return 0;
}
