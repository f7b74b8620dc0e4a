#pragma once
/// \file simulation/simulation.hpp
/// One closed-loop run of paper5.md's experiment: a perturbed plant (paper5 with
/// `paper5_parameters` factors), the robust task-space controller on the nominal model
/// (controller.hpp), a reference, an integrator (integrators.hpp), continuous or sampled
/// control with zero-order hold on τ and measurement noise on r.
///
///     x = (q, η),   ẋ = (S(q) η,  M_η⁻¹(Sᵀ τ − h_η))   on the plant        (paper eq. 1–2)
///     τ = controller(q, η, r_measured, r_d(t))            continuous, or
///     τ(t) = τ_k for t ∈ [t_k, t_k+1), t_k = k / rate     sampled (zero-order hold)
///
/// Under sampling the integration restarts at every sample instant (the right-hand side
/// jumps there). Output rows are taken at a fixed step from the integrator's dense output
/// and hold t, q, η, the τ actually applied, the plant's true r, r_d and ‖r_d − r‖.
///
///     nhdyn::run_spec spec;                 // paper-circle's numbers by default
///     nhdyn::run_result res = nhdyn::simulate(spec);
///     nhdyn::write_csv("paper-circle.csv", res);
#include <charconv>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <fstream>
#include <random>
#include <sstream>

#include "../constraints/forward_dynamics.hpp"
#include "../io/number.hpp"
#include "../robots/presets.hpp"
#include "controller.hpp"
#include "integrators.hpp"

namespace nhdyn {

/// Everything that defines one run (a scene, once parsed): defaults are paper-circle.
struct run_spec {
  std::string name = "paper-circle";
  presets::paper5_parameters<double> plant{{1.1, 1.1, 1.1, 1.1, 1.1}, 1, 1, 1};
  presets::paper5_parameters<double> model{};  ///< the controller's (nominal) model
  rac_gains gains{};
  vecN<double, 5> posture_mask = (vecN<double, 5>() << 0, 0, 0, 1, 1).finished();
  circle_reference reference{};
  vecN<double, 5> q0 = (vecN<double, 5>() << -0.23710299623923958, 1.0, 3.141592653589793,
                        2.058145585963254, 1.2).finished();
  vecN<double, 4> eta0 = vecN<double, 4>::Zero();
  integrator_options integrator{method::dopri5, 2e-3, 1e-5, 1e-7};
  double duration = 20;
  double output_step = 0.01;
  double sample_rate = 0;  ///< Hz; 0 = continuous control
  double noise_sigma = 0;  ///< m, per coordinate of the measured r, per sample
  std::uint64_t seed = 1;
  double tail_from = 15, tail_tolerance = 0.01;  ///< success: max ‖r̃‖ over [tail_from, end] below this
};

/// Columns of a run's output rows (and CSV).
inline const std::vector<std::string>& run_columns() {
  static const std::vector<std::string> c{"t",     "q1",    "q2",    "q3",   "q4",   "q5",   "eta1",
                                          "eta2",  "eta3",  "eta4",  "tau1", "tau2", "tau3", "tau4",
                                          "r_x",   "r_y",   "r_z",   "rd_x", "rd_y", "rd_z", "err"};
  return c;
}

struct run_result {
  std::string name;
  bool success = false;
  std::optional<std::string> failure;  ///< why the run failed (integrator failure or criterion)
  double max_tail_error = NAN;         ///< max ‖r_d − r‖ over output rows with t ≥ tail_from [m]
  double peak_tau = 0;                 ///< max |τ_i| over the output rows and samples
  long steps = 0;                      ///< accepted integrator steps
  double wall_time_s = 0;
  double cpu_time_s = 0;  ///< CPU time of the simulating thread (what a loaded machine does not inflate)
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows;  ///< one row per output time
};

namespace detail {
/// CPU time of the calling thread [s] (POSIX; wall time where unavailable).
inline double thread_cpu_seconds() {
#ifdef CLOCK_THREAD_CPUTIME_ID
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
#else
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
#endif
}

/// Standard normal numbers from mt19937_64 by Box–Muller: the same sequence on every
/// platform (std::normal_distribution's algorithm is implementation-defined).
struct gaussian {
  std::mt19937_64 g;
  std::optional<double> spare;
  explicit gaussian(std::uint64_t seed) : g(seed) {}
  double operator()() {
    if (spare) return std::exchange(spare, std::nullopt).value();
    const double u1 = (double(g() >> 11) + 0.5) * 0x1.0p-53, u2 = double(g() >> 11) * 0x1.0p-53;
    const double rad = std::sqrt(-2 * std::log(u1)), th = 2 * 3.14159265358979323846 * u2;
    spare = rad * std::sin(th);
    return rad * std::cos(th);
  }
};

inline std::string state_text(double t, const vecN<double, 9>& x) {
  std::ostringstream os;
  os.precision(17);
  os << "at t = " << t << " s, state (q, η) = [";
  for (int i = 0; i < 9; ++i) os << (i ? ", " : "") << x(i);
  return os.str() + "]";
}
}  // namespace detail

/// Runs one scene. Never throws for a failing simulation: the result says why it failed.
/// Throws (model_error, input_error) only for a spec that cannot be set up.
inline run_result simulate(const run_spec& s) {
  const auto t_start = std::chrono::steady_clock::now();
  const double cpu_start = detail::thread_cpu_seconds();
  const auto plant = presets::paper5<double>(s.plant);
  const auto nominal = presets::paper5<double>(s.model);
  const kinematics<double, 5> plant_kin(plant.chain);
  const auto fd = nh_forward_dynamics(plant.chain, plant.constraint);
  const rac_controller ctrl(nominal.chain, nominal.constraint, s.gains, s.q0, s.posture_mask);
  if (!(s.duration > 0) || !(s.output_step > 0) || !(s.sample_rate >= 0) || !(s.noise_sigma >= 0))
    throw input_error("scene '" + s.name + "': duration and output step must be > 0, sample rate and noise ≥ 0");
  if (s.noise_sigma > 0 && s.sample_rate == 0)
    throw input_error("scene '" + s.name + "': measurement noise needs a sampled controller (sampling.rate_hz)");

  const long n_out = std::lround(std::floor(s.duration / s.output_step * (1 + 1e-12))) + 1;
  std::vector<double> t_out(static_cast<std::size_t>(n_out));
  for (long i = 0; i < n_out; ++i) t_out[std::size_t(i)] = double(i) * s.output_step;

  run_result res;
  res.name = s.name;
  res.rows.resize(n_out, Eigen::Index(run_columns().size()));
  long rows_done = 0;
  vecN<double, 4> held = vecN<double, 4>::Zero();
  const bool sampled = s.sample_rate > 0;

  const auto tau_of = [&](const auto& t, const auto& x, const vec3<std::decay_t<decltype(t)>>& r_meas) {
    using T = std::decay_t<decltype(t)>;
    return ctrl(vecN<T, 5>(x.template head<5>()), vecN<T, 4>(x.template tail<4>()), r_meas, s.reference(t));
  };
  const auto f = [&](const auto& t, const auto& x) {
    using T = std::decay_t<decltype(t)>;
    const vecN<T, 5> q = x.template head<5>();
    const vecN<T, 4> eta = x.template tail<4>();
    const vecN<T, 4> tau = sampled ? vecN<T, 4>(held.cast<T>()) : tau_of(t, x, plant_kin.point(q, 5));
    vecN<T, 9> dx;
    dx << apply_S(plant.constraint, q, eta), fd(q, eta, tau);
    return dx;
  };
  const auto observe = [&](int i, const vecN<double, 9>& x) {
    const double t = t_out[std::size_t(i)];
    const vecN<double, 5> q = x.head<5>();
    const vec3<double> r = plant_kin.point(q, 5), rd = s.reference(t).r;
    const vecN<double, 4> tau = sampled ? held : tau_of(t, x, r);
    auto row = res.rows.row(i);
    row << t, x.transpose(), tau.transpose(), r.transpose(), rd.transpose(), (rd - r).norm();
    res.peak_tau = std::max(res.peak_tau, tau.cwiseAbs().maxCoeff());
    rows_done = i + 1;
  };

  vecN<double, 9> x;
  x << s.q0, s.eta0;
  double dt = 0;
  std::optional<integration_failure<9>> failure;
  if (!sampled) {
    auto r = integrate<9>(f, x, 0.0, s.duration, s.integrator, t_out, observe, &dt);
    res.steps = r.steps;
    failure = r.failure;
  } else {
    detail::gaussian noise(s.seed);
    const long n_samples = long(std::ceil(s.duration * s.sample_rate * (1 - 1e-12)));
    for (long k = 0; k < n_samples && !failure; ++k) {
      const double tk = double(k) / s.sample_rate;
      const double tk1 = std::min(double(k + 1) / s.sample_rate, s.duration);
      vec3<double> r_meas = plant_kin.point(vecN<double, 5>(x.head<5>()), 5);
      for (int j = 0; j < 3; ++j) r_meas(j) += s.noise_sigma > 0 ? s.noise_sigma * noise() : 0.0;
      try {
        held = tau_of(tk, x, r_meas);
        if (!held.allFinite()) throw numerical_error("the controller's torque is not finite");
      } catch (const std::exception& e) {
        failure = integration_failure<9>{tk, x, std::string("controller: ") + e.what()};
        break;
      }
      res.peak_tau = std::max(res.peak_tau, held.cwiseAbs().maxCoeff());
      // Outputs in [t_k, t_k+1), and the final time in the last piece.
      const std::size_t lo = std::size_t(rows_done);
      std::size_t hi = lo;
      // (an output at a sample instant, up to rounding, belongs to the new sample's piece)
      const double slack = 1e-9 / s.sample_rate;
      while (hi < t_out.size() && (t_out[hi] < tk1 - slack || (k + 1 == n_samples && t_out[hi] <= tk1 + slack))) ++hi;
      std::span<const double> piece(t_out.data() + lo, hi - lo);
      integrator_options opts = s.integrator;  // the step budget is the run's, not each piece's
      opts.max_steps = s.integrator.max_steps - res.steps;
      auto r = integrate<9>(f, x, tk, tk1, opts, piece,
                            [&](int i, const vecN<double, 9>& xi) { observe(int(lo) + i, xi); }, &dt);
      res.steps += r.steps;
      if (r.failure && r.failure->reason.rfind("too many steps", 0) == 0)
        r.failure->reason = "too many steps (more than " + std::to_string(s.integrator.max_steps) + " in the run)";
      failure = r.failure;
      x = r.x;
    }
  }
  res.rows.conservativeResize(rows_done, Eigen::NoChange);
  if (failure) {
    res.failure = failure->reason + " " + detail::state_text(failure->t, failure->x);
  } else {
    double tail = 0;
    bool any = false;
    for (Eigen::Index i = 0; i < res.rows.rows(); ++i)
      if (res.rows(i, 0) >= s.tail_from - 1e-12) {
        tail = std::max(tail, res.rows(i, 20));
        any = true;
      }
    res.max_tail_error = any ? tail : NAN;
    if (!std::isfinite(res.max_tail_error))
      res.failure = "no finite output rows at t ≥ " + std::to_string(s.tail_from) + " s";
    else if (!(res.max_tail_error < s.tail_tolerance)) {
      std::ostringstream os;
      os << "tail error " << res.max_tail_error << " m ≥ " << s.tail_tolerance << " m";
      res.failure = os.str();
    }
  }
  res.success = !res.failure;
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  res.cpu_time_s = detail::thread_cpu_seconds() - cpu_start;
  return res;
}

/// Shortest round-trip decimal form of x (std::to_chars): parsing it gives x back exactly.

/// Writes a run's rows as CSV with a header naming each column (run_columns()).
inline void write_csv(const std::string& path, const run_result& res) {
  std::string text;
  text.reserve(std::size_t(res.rows.rows() + 1) * 24 * 21);
  for (std::size_t j = 0; j < run_columns().size(); ++j) text += (j ? "," : "") + run_columns()[j];
  text += '\n';
  for (Eigen::Index i = 0; i < res.rows.rows(); ++i) {
    for (Eigen::Index j = 0; j < res.rows.cols(); ++j) {
      if (j) text += ',';
      io::append_number(text, res.rows(i, j));
    }
    text += '\n';
  }
  std::ofstream f(path, std::ios::binary);
  if (!f) throw input_error("cannot write '" + path + "'");
  f.write(text.data(), std::streamsize(text.size()));
  if (!f) throw input_error("error writing '" + path + "'");
}

}  // namespace nhdyn
