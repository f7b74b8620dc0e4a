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
#include <concepts>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

#include "../constraints/forward_dynamics.hpp"
#include "../dynamics/terms.hpp"
#include "../io/number.hpp"
#include "../robots/presets.hpp"
#include "controller.hpp"
#include "integrators.hpp"

namespace nhdyn {

/// What a closed-loop run needs beside its plant, controller and reference: integration,
/// sampling, noise, output and the success test (defaults: paper-circle's).
struct run_options {
  integrator_options integrator{method::dopri5, 2e-3, 1e-5, 1e-7};
  double duration = 20;
  double output_step = 0.01;
  double sample_rate = 0;  ///< Hz; 0 = continuous control
  double noise_sigma = 0;  ///< m, per coordinate of the measured r, per sample
  std::uint64_t seed = 1;
  double tail_from = 15, tail_tolerance = 0.01;  ///< success: max ‖r̃‖ over [tail_from, end] below this
  /// Called with the simulated time at every output row, from the simulating thread (a
  /// progress display for long runs); empty: not called. Under run_batch a callback shared
  /// by several specs is called from several threads at once; an exception it throws fails
  /// the run.
  std::function<void(double)> progress{};
};

/// Which controller a scene runs (controller.hpp).
enum class controller_type {
  task_space,      ///< the paper's robust task-space controller (rac_controller)
  computed_torque  ///< joint-space computed torque (computed_torque_controller; needs a joint-space reference)
};

/// Everything that defines one run (a scene, once parsed): defaults are paper-circle.
struct run_spec : run_options {
  std::string name = "paper-circle";
  presets::paper5_parameters<double> plant{{1.1, 1.1, 1.1, 1.1, 1.1}, 1, 1, 1};
  presets::paper5_parameters<double> model{};  ///< the controller's (nominal) model
  controller_type controller = controller_type::task_space;
  rac_gains gains{};     ///< the task-space controller's
  ct_gains ct{};         ///< the computed-torque controller's
  vecN<double, 5> posture_mask = (vecN<double, 5>() << 0, 0, 0, 1, 1).finished();
  reference_spec reference = circle_reference{};
  vecN<double, 5> q0 = (vecN<double, 5>() << -0.23710299623923958, 1.0, 3.141592653589793,
                        2.058145585963254, 1.2).finished();
  vecN<double, 4> eta0 = vecN<double, 4>::Zero();

  // Any robot (scene field "robot" other than "paper5"; simulation/robot_scene.hpp runs it).
  // plant/model, q0, eta0 and posture_mask above are paper5's; for any other robot these are:
  std::string robot = "paper5";  ///< "paper5", a preset's name, or a robot file's, URDF's or JSON model's path
  std::string task_frame;        ///< the body or frame carrying r
  vec3<double> task_point = vec3<double>::Zero();  ///< r in that frame
  Eigen::VectorXd q_start, eta_start;              ///< the initial state (empty: zeros)
  std::vector<std::string> posture_joints;         ///< joints the posture term holds at q_start
  std::vector<std::pair<std::string, double>> plant_mass, model_mass;  ///< mass factors by body name
  std::vector<std::pair<std::string, double>> plant_length, model_length;  ///< joint placement factors by joint name
  double plant_wheel_radius = 1, model_wheel_radius = 1;  ///< factors on the constraint's wheel radius
  /// Joints held at positions, names or globs (scene field "locked"; io::lock_robot): plant
  /// and model are the robot without them; q_start, posture_joints name the kept joints.
  std::vector<std::pair<std::string, double>> locked;

  // Which terms of the equations of motion the plant's forward dynamics and the controller's
  // model include (dynamics/terms.hpp; scene fields plant.terms, model.terms, smooth_coulomb).
  // The default is today's: gravity, velocity and armature, no friction. Any robot; paper5
  // with other terms runs as a tree (simulate_scene), not by `simulate`.
  terms plant_terms{}, model_terms{};

  // Where the run came from in a study (scene.hpp), for summary.json:
  std::optional<std::uint64_t> run_seed;  ///< a Monte Carlo run's seed (replays it alone)
  std::string factors;                    ///< the study's factor values for this run (a JSON object), or empty
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
  std::vector<std::string> columns;  ///< the rows' column names (run_columns for paper5)
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

template <class X>
std::string state_text(double t, const X& x) {
  std::ostringstream os;
  os.precision(17);
  os << "at t = " << t << " s, state (q, η) = [";
  for (int i = 0; i < int(x.size()); ++i) os << (i ? ", " : "") << x(i);
  return os.str() + "]";
}
}  // namespace detail

/// A run_spec's run_options.
inline const run_options& options_of(const run_spec& s) { return s; }

/// Output columns for a robot whose q, η and τ entries have these names: t, q_<joint>…,
/// eta_<name>…, tau_<name>…, r_x, r_y, r_z, rd_x, rd_y, rd_z, err. τ's names default to η's
/// (a constraint with as many actuators as η has entries).
inline std::vector<std::string> run_columns(const std::vector<std::string>& joints, const std::vector<std::string>& eta,
                                            const std::vector<std::string>& tau) {
  std::vector<std::string> c{"t"};
  for (const auto& j : joints) c.push_back("q_" + j);
  for (const auto& e : eta) c.push_back("eta_" + e);
  for (const auto& e : tau) c.push_back("tau_" + e);
  for (const char* x : {"r_x", "r_y", "r_z", "rd_x", "rd_y", "rd_z", "err"}) c.emplace_back(x);
  return c;
}
inline std::vector<std::string> run_columns(const std::vector<std::string>& joints, const std::vector<std::string>& eta) {
  return run_columns(joints, eta, eta);
}

/// One closed-loop run on any constrained plant (see the file comment), with x = (q, η):
///
/// - `fd`: the plant's nh_forward_dynamics (any model, constraint c);
/// - `task(q)`: the plant's true task point r(q) (what is measured, before noise);
/// - `controller(q, η, r_measured, reference(t))` → τ (p entries: the constraint's
///   actuators, m unless it says otherwise), generic over the scalar;
/// - `reference(t)` → task_reference (r_d, ṙ_d, r̈_d).
///
/// N, M: the compile-time sizes of q and η (or `dynamic`). `columns`: the output's column
/// names (1 + n + m + p + 7 of them). The result's times cover the integration and the output. Never throws for a failing simulation: the result says why.
template <int N, int M, class C, class FD, class Task, class Controller, class Reference>
run_result simulate_closed_loop(const std::string& name, const C& c, const FD& fd, const Task& task,
                                const Controller& controller, const Reference& reference, const vecN<double, N>& q0,
                                const vecN<double, M>& eta0, const run_options& s, std::vector<std::string> columns) {
  constexpr int D = N == dynamic || M == dynamic ? dynamic : N + M;
  const auto t_start = std::chrono::steady_clock::now();
  const double cpu_start = detail::thread_cpu_seconds();
  const int n = int(q0.size()), m = int(eta0.size()), p = actuator_count(c);
  if (!(s.duration > 0) || !(s.output_step > 0) || !(s.sample_rate >= 0) || !(s.noise_sigma >= 0))
    throw input_error("scene '" + name + "': duration and output step must be > 0, sample rate and noise ≥ 0");
  if (s.noise_sigma > 0 && s.sample_rate == 0)
    throw input_error("scene '" + name + "': measurement noise needs a sampled controller (sampling.rate_hz)");
  if (c.dof() != n || c.m() != m)
    throw input_error("scene '" + name + "': the initial state has " + std::to_string(n) + " + " + std::to_string(m) +
                      " entries (q, η), the robot " + std::to_string(c.dof()) + " + " + std::to_string(c.m()));
  if (int(columns.size()) != 1 + n + m + p + 7)
    throw input_error("scene '" + name + "': " + std::to_string(columns.size()) + " column names for " +
                      std::to_string(1 + n + m + p + 7) + " columns");

  const long n_out = std::lround(std::floor(s.duration / s.output_step * (1 + 1e-12))) + 1;
  std::vector<double> t_out(static_cast<std::size_t>(n_out));
  for (long i = 0; i < n_out; ++i) t_out[std::size_t(i)] = double(i) * s.output_step;

  run_result res;
  res.name = name;
  res.columns = std::move(columns);
  res.rows.resize(n_out, Eigen::Index(res.columns.size()));
  long rows_done = 0;
  constexpr int P = p_of<C>;
  vecN<double, P> held = vecN<double, P>::Zero(p);
  const bool sampled = s.sample_rate > 0;

  const auto q_of = [&](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    if constexpr (N == dynamic) return vecN<T, N>(x.head(n));
    else return vecN<T, N>(x.template head<N>());
  };
  const auto eta_of = [&](const auto& x) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    if constexpr (M == dynamic) return vecN<T, M>(x.tail(m));
    else return vecN<T, M>(x.template tail<M>());
  };
  const auto tau_of = [&](const auto& t, const auto& x, const vec3<std::decay_t<decltype(t)>>& r_meas) {
    vecN<std::decay_t<decltype(t)>, P> tau = controller(q_of(x), eta_of(x), r_meas, reference(t));
    if (tau.size() != p)
      throw input_error("scene '" + name + "': the controller gave " + std::to_string(tau.size()) + " torques, the robot has " +
                        std::to_string(p) + " actuators");
    return tau;
  };
  const auto f = [&](const auto& t, const auto& x) {
    using T = std::decay_t<decltype(t)>;
    const vecN<T, N> q = q_of(x);
    const vecN<T, M> eta = eta_of(x);
    const vecN<T, P> tau = sampled ? vecN<T, P>(held.template cast<T>()) : tau_of(t, x, vec3<T>(task(q)));
    vecN<T, D> dx(n + m);
    dx << apply_S(c, q, eta), fd(q, eta, tau);
    return dx;
  };
  // Output k of the integration piece under way is row row0 + k (continuous: one piece, row0 = 0).
  // One observer type for both modes, so that the integrators are instantiated once.
  long row0 = 0;
  const auto observe = [&](int k, const vecN<double, D>& x) {
    const long i = row0 + k;
    const double t = t_out[std::size_t(i)];
    const vec3<double> r = task(q_of(x)), rd = reference(t).r;
    const vecN<double, P> tau = sampled ? held : tau_of(t, x, r);
    auto row = res.rows.row(i);
    row << t, x.transpose(), tau.transpose(), r.transpose(), rd.transpose(), (rd - r).norm();
    res.peak_tau = std::max(res.peak_tau, tau.cwiseAbs().maxCoeff());
    rows_done = i + 1;
    if (s.progress) s.progress(t);
  };

  vecN<double, D> x(n + m);
  x << q0, eta0;
  double dt = 0;
  std::optional<integration_failure<D>> failure;
  if (!sampled) {
    auto r = integrate<D>(f, x, 0.0, s.duration, s.integrator, t_out, observe, &dt);
    res.steps = r.steps;
    failure = r.failure;
  } else {
    detail::gaussian noise(s.seed);
    const long n_samples = long(std::ceil(s.duration * s.sample_rate * (1 - 1e-12)));
    for (long k = 0; k < n_samples && !failure; ++k) {
      const double tk = double(k) / s.sample_rate;
      const double tk1 = std::min(double(k + 1) / s.sample_rate, s.duration);
      vec3<double> r_meas = task(q_of(x));
      for (int j = 0; j < 3; ++j) r_meas(j) += s.noise_sigma > 0 ? s.noise_sigma * noise() : 0.0;
      try {
        held = tau_of(tk, x, r_meas);
        if (!held.allFinite()) throw numerical_error("the controller's torque is not finite");
      } catch (const std::exception& e) {
        failure = integration_failure<D>{tk, x, std::string("controller: ") + e.what()};
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
      row0 = long(lo);
      auto r = integrate<D>(f, x, tk, tk1, opts, piece, observe, &dt);
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
    const Eigen::Index err_col = res.rows.cols() - 1;
    double tail = 0;
    bool any = false;
    for (Eigen::Index i = 0; i < res.rows.rows(); ++i)
      if (res.rows(i, 0) >= s.tail_from - 1e-12) {
        tail = std::max(tail, res.rows(i, err_col));
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

namespace detail {
/// The model as terms t want it: armature dropped when out (with_terms), gravity zero when
/// out (velocity and friction are the computation's: rne_options, friction_fn).
template <class Model>
Model model_with_terms(const Model& m, const terms& t) {
  if (t.gravity) return with_terms(m, t);
  return with_terms(m, t).with_gravity(vec3<typename Model::scalar_type>::Zero());
}
/// The model's friction (its joints' laws, t.coulomb) when t has friction in, else none.
template <class Model>
std::optional<friction_fn> friction_with_terms(const Model& m, const terms& t) {
  if (!t.friction) return std::nullopt;
  return friction(m, t.coulomb);
}

/// Throws input_error unless the scene's reference suits its controller and its robot's n joints.
inline void check_reference(const run_spec& s, int n) {
  const std::string where = "scene '" + s.name + "': ";
  if (s.controller == controller_type::computed_torque && !is_joint_space(s.reference))
    throw input_error(where + "the computed-torque controller needs a joint-space reference (reference.type 'joint_spline')");
  if (const auto* j = std::get_if<joint_spline_reference>(&s.reference); j && j->dof() != n)
    throw input_error(where + "field 'reference.q': waypoints of " + std::to_string(j->dof()) + " joints, the robot has " +
                      std::to_string(n));
}

/// f()'s run_result with its wall and CPU times those of the whole call (set-up included).
template <class F>
run_result timed(const F& f) {
  const auto t_start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_seconds();
  run_result r = f();
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  r.cpu_time_s = thread_cpu_seconds() - cpu_start;
  return r;
}
}  // namespace detail

/// Runs one paper5 scene (run_spec): the perturbed plant, the robust controller on the
/// nominal model with r the origin of link 5, by simulate_closed_loop. Never throws for a
/// failing simulation: the result says why it failed. Throws (model_error, input_error) only
/// for a spec that cannot be set up. A function object, `simulate(spec)`, whose call is a
/// template: the closed loop (with its dual-number Jacobian for rosenbrock4) is compiled only
/// where it is called, not by every file that includes this header.
struct simulate_fn {
  template <std::same_as<run_spec> Spec>
  run_result operator()(const Spec& s) const {
    return detail::timed([&] {
      if (s.robot != "paper5")
        throw input_error("scene '" + s.name + "': robot '" + s.robot +
                          "' is not paper5: simulate_scene (simulation/robot_scene.hpp, needs URDF support) runs it");
      if (!(s.plant_terms == terms{}) || !(s.model_terms == terms{}))
        throw input_error("scene '" + s.name + "': fields 'plant.terms', 'model.terms': paper5 with terms other than " +
                          "the default (gravity,velocity,armature) runs as a tree: simulate_scene " +
                          "(simulation/robot_scene.hpp, needs URDF support) runs it");
      detail::check_reference(s, 5);
      const auto plant = presets::paper5<double>(s.plant);
      const auto nominal = presets::paper5<double>(s.model);
      const kinematics<double, 5> plant_kin(plant.chain), model_kin(nominal.chain);
      const auto fd = nh_forward_dynamics(plant.chain, plant.constraint);
      const auto task = [&](const auto& q) { return plant_kin.point(q, 5); };
      const scene_reference ref(s.reference, model_kin, 5, vec3<double>::Zero());
      using C = decltype(plant.constraint);
      const any_controller<double, 5, C> ctrl =
          s.controller == controller_type::task_space
              ? any_controller<double, 5, C>(rac_controller(nominal.chain, nominal.constraint, s.gains, s.q0, s.posture_mask))
              : any_controller<double, 5, C>(computed_torque_controller(nominal.chain, nominal.constraint, s.ct));
      return simulate_closed_loop<5, 4>(s.name, plant.constraint, fd, task, ctrl, ref, s.q0, s.eta0, options_of(s),
                                        run_columns());
    });
  }
};
inline constexpr simulate_fn simulate{};

/// One closed-loop run of any robot (a kinematic tree `plant` with its constraint `c`), with
/// any controller `(q, η, r_measured, reference(t)) → τ` (controller.hpp's, or a user's
/// function object) and any reference: r is the point `point` of body `body` (1-based,
/// tree_kinematics' numbering; tree::find_frame turns a frame name into one) on the plant.
/// Everything the controller knows (its model, constraint, gains) is inside it: plant–model
/// mismatch is a controller built on another tree or constraint. `plant_terms`: the terms of
/// the plant's forward dynamics (dynamics/terms.hpp; default gravity, velocity, armature):
/// armature out drops the joints' armature, gravity and velocity out drop g(q) and C(q, q̇)q̇
/// (rne_options), friction in adds the joints' friction laws (fd.with(friction(plant))).
template <class C, class Controller, class Reference>
run_result simulate_robot(const std::string& name, const tree<double>& plant, const C& c, int body,
                          const vec3<double>& point, const Controller& controller, const Reference& reference,
                          const Eigen::VectorXd& q0, const Eigen::VectorXd& eta0, const run_options& o,
                          const std::vector<std::string>& eta_names, const terms& plant_terms = {}) {
  const tree_kinematics<double> plant_kin(plant);
  std::optional<tree<double>> with_t;  // the plant as its terms want it (the plant itself by default)
  if (!(plant_terms == terms{})) with_t = detail::model_with_terms(plant, plant_terms);
  const tree<double>& dyn = with_t ? *with_t : plant;
  const auto fd = [&] {
    auto f = nh_forward_dynamics(dyn, c, plant_terms.rne());
    if (plant_terms.friction) return f.with(friction(dyn, plant_terms.coulomb));
    return f;
  }();
  const auto task = [&](const auto& q) { return plant_kin.point(q, body, point); };
  const auto joints = plant.joint_names();
  return simulate_closed_loop<dynamic, dynamic>(name, c, fd, task, controller, reference, q0, eta0, o,
                                                run_columns(joints, eta_names, tau_names_of(c, joints, eta_names)));
}

/// The same with the robust task-space controller (controller.hpp) on `nominal` (same
/// constraint), driving that point along `reference`; the posture term holds the joints whose
/// `posture_mask` entry is 1 at q0. `plant_terms` as above; `model_terms`: the terms of the
/// controller's inverse dynamics on `nominal` (armature, gravity, velocity; friction in: the
/// controller compensates the nominal joints' friction laws).
template <class C, class Reference = circle_reference>
run_result simulate_robot(const std::string& name, const tree<double>& plant, const tree<double>& nominal, const C& c,
                          int body, const vec3<double>& point, const Reference& reference, const rac_gains& gains,
                          const Eigen::VectorXd& q0, const Eigen::VectorXd& eta0, const Eigen::VectorXd& posture_mask,
                          const run_options& o, const std::vector<std::string>& eta_names, const terms& plant_terms = {},
                          const terms& model_terms = {}) {
  if (plant.dof() != nominal.dof())
    throw input_error("scene '" + name + "': plant and model have " + std::to_string(plant.dof()) + " and " +
                      std::to_string(nominal.dof()) + " joints");
  if (model_terms == terms{}) {
    const rac_controller ctrl(nominal, c, gains, q0, posture_mask, body, point);
    return simulate_robot(name, plant, c, body, point, ctrl, reference, q0, eta0, o, eta_names, plant_terms);
  }
  const tree<double> model = detail::model_with_terms(nominal, model_terms);
  const rac_controller ctrl(model, c, gains, q0, posture_mask, body, point, model_terms.rne(),
                            detail::friction_with_terms(model, model_terms));
  return simulate_robot(name, plant, c, body, point, ctrl, reference, q0, eta0, o, eta_names, plant_terms);
}

/// Shortest round-trip decimal form of x (std::to_chars): parsing it gives x back exactly.

/// Writes a run's rows as CSV with a header naming each column (res.columns).
inline void write_csv(const std::string& path, const run_result& res) {
  std::string text;
  const auto& cols = res.columns.empty() ? run_columns() : res.columns;
  text.reserve(std::size_t(res.rows.rows() + 1) * 24 * cols.size());
  for (std::size_t j = 0; j < cols.size(); ++j) text += (j ? "," : "") + cols[j];
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
