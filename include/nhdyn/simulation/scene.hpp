#pragma once
/// \file simulation/scene.hpp
/// Scenes (one run) and studies (runs over scenes) as JSON files; docs/simulation.md has
/// the format. Every field is optional except where noted; defaults are paper-circle's
/// numbers (paper5.md). Unknown fields are errors naming the field ("scene 'x': unknown
/// field 'controller.K2'"), so a typo never falls back to a default silently.
///
///     scene  = {"name", "description", "robot": "paper5" | robot file, "locked": {"JOINT or GLOB": q},
///               "task": {"frame", "point"},
///               "plant": factors and terms, "model": factors and terms,
///               "controller": {...}, "reference": {...}, "initial": {"q", "eta"},
///               "integrator": {...}, "duration", "sampling": {...}, "noise": {...},
///               "output": {"step"}, "success": {"tail_from", "max_tail_error"}}
///     study  = {"name", "description", "study": {"base": scene | "scene name",
///               "set": {JSON merge patch}, "factors": [{"name", "path", "levels"}]}}
///               → the full factorial over the factors' levels (path: a JSON pointer), or
///               with "monte_carlo": {"runs", "seed"} | {"replay": [seeds]} and factors
///               [{"name", "path", "distribution"}]: runs drawn each from its own seed
///     suite  = {"name", "description", "scenes": [scene | study | suite | "name", …]}
///
///     auto f = nhdyn::scene::open("paper-factorial");   // a shipped scene, or a file path
///     auto runs = nhdyn::scene::expand(f.j, f.dirs);       // its 16 run_specs
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "../io/json.hpp"
#include "simulation.hpp"

namespace nhdyn::scene {

using json = nlohmann::json;

namespace detail {
/// A JSON object at a dotted path, checked against its allowed keys on construction.
struct object {
  const json& j;
  std::string where;  // "scene 'x': "
  std::string path;   // "controller.robust"

  object(const json& j_, std::string where_, std::string path_, std::initializer_list<const char*> allowed)
      : j(j_), where(std::move(where_)), path(std::move(path_)) {
    if (!j.is_object()) throw input_error(where + "field '" + path + "' must be an object");
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || it.key() == a;
      if (!ok) {
        std::string known;
        for (const char* a : allowed) known += (known.empty() ? "" : ", ") + std::string(a);
        throw input_error(where + "unknown field '" + name(it.key()) + "' (known here: " + known + ")");
      }
    }
  }
  std::string name(const std::string& k) const { return path.empty() ? k : path + "." + k; }
  bool has(const char* k) const { return j.contains(k); }
  double number(const char* k, double fallback) const {
    if (!has(k)) return fallback;
    const json& v = j.at(k);
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      throw input_error(where + "field '" + name(k) + "' must be a finite number");
    return v.get<double>();
  }
  std::string text(const char* k, const std::string& fallback) const {
    if (!has(k)) return fallback;
    if (!j.at(k).is_string()) throw input_error(where + "field '" + name(k) + "' must be a string");
    return j.at(k).get<std::string>();
  }
  bool boolean(const char* k, bool fallback) const {
    if (!has(k)) return fallback;
    if (!j.at(k).is_boolean()) throw input_error(where + "field '" + name(k) + "' must be true or false");
    return j.at(k).get<bool>();
  }
  Eigen::VectorXd vector(const char* k, int n) const {
    const json& v = j.at(k);
    if (!v.is_array() || int(v.size()) != n)
      throw input_error(where + "field '" + name(k) + "' must be a list of " + std::to_string(n) + " numbers");
    Eigen::VectorXd x(n);
    for (int i = 0; i < n; ++i) {
      if (!v[std::size_t(i)].is_number() || !std::isfinite(v[std::size_t(i)].get<double>()))
        throw input_error(where + "field '" + name(k) + "', entry " + std::to_string(i) + ": must be a finite number");
      x(i) = v[std::size_t(i)].get<double>();
    }
    return x;
  }
  /// A list of rows of `cols` numbers each (cols < 0: any, the same for every row), at least `min_rows`.
  Eigen::MatrixXd rows(const char* k, int cols, int min_rows) const {
    const json& v = j.at(k);
    const std::string what = "field '" + name(k) + "' must be a list of at least " + std::to_string(min_rows) +
                             " lists of " + (cols < 0 ? std::string("numbers (all of one length)") : std::to_string(cols) + " numbers");
    if (!v.is_array() || int(v.size()) < min_rows || !v[0].is_array() || v[0].empty()) throw input_error(where + what);
    const int c = cols < 0 ? int(v[0].size()) : cols;
    Eigen::MatrixXd x(int(v.size()), c);
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_array() || int(v[i].size()) != c)
        throw input_error(where + what + " (entry " + std::to_string(i) + " has " +
                          (v[i].is_array() ? std::to_string(v[i].size()) : std::string("no")) + " numbers)");
      for (int jj = 0; jj < c; ++jj) {
        const json& e = v[i][std::size_t(jj)];
        if (!e.is_number() || !std::isfinite(e.get<double>()))
          throw input_error(where + "field '" + name(k) + "', entry " + std::to_string(i) + ": must hold finite numbers");
        x(int(i), jj) = e.get<double>();
      }
    }
    return x;
  }
  std::vector<double> list(const char* k, int min_size) const {
    const json& v = j.at(k);
    if (!v.is_array() || int(v.size()) < min_size)
      throw input_error(where + "field '" + name(k) + "' must be a list of at least " + std::to_string(min_size) + " numbers");
    const Eigen::VectorXd x = vector(k, int(v.size()));
    return {x.data(), x.data() + x.size()};
  }
  /// A gain: a number (times I₃) or a list of 3 (a diagonal).
  Eigen::Matrix3d gain(const char* k, const Eigen::Matrix3d& fallback) const {
    if (!has(k)) return fallback;
    if (j.at(k).is_number()) return number(k, 0) * Eigen::Matrix3d::Identity();
    return Eigen::Vector3d(vector(k, 3)).asDiagonal();
  }
  object sub(const char* k, std::initializer_list<const char*> allowed) const {
    static const json empty = json::object();
    return object(has(k) ? j.at(k) : empty, where, name(k), allowed);
  }
};

inline presets::paper5_parameters<double> read_factors(const object& o) {
  presets::paper5_parameters<double> p;
  if (o.has("mass_factor")) {
    const Eigen::VectorXd m = o.vector("mass_factor", 5);
    for (int i = 0; i < 5; ++i) p.mass_factor[std::size_t(i)] = m(i);
  }
  p.d3_factor = o.number("d3_factor", 1);
  p.a4_factor = o.number("a4_factor", 1);
  p.a5_factor = o.number("a5_factor", 1);
  return p;
}
constexpr std::initializer_list<const char*> factor_keys = {"mass_factor", "d3_factor", "a4_factor", "a5_factor",
                                                            "terms", "smooth_coulomb"};
/// plant/model keys for any robot but paper5.
constexpr std::initializer_list<const char*> robot_factor_keys = {"mass_factor", "length_factor", "wheel_radius_factor",
                                                                  "terms", "smooth_coulomb"};

/// The terms (dynamics/terms.hpp) of a plant or model object: "terms" (a list of names,
/// terms::parse; default gravity, velocity, armature) and "smooth_coulomb" (v_s > 0 of the
/// smooth Coulomb law; only with friction in). Errors name the scene and the field.
inline terms read_terms(const object& o) {
  terms t{};
  if (o.has("terms")) {
    const std::string list = o.text("terms", "");
    try {
      t = terms::parse(list);
    } catch (const input_error& e) {
      std::string why = e.what();
      const std::string prefix = "terms '" + list + "': ";  // the field names the list already
      if (why.rfind(prefix, 0) == 0) why.erase(0, prefix.size());
      throw input_error(o.where + "field '" + o.name("terms") + "': " + why);
    }
  }
  if (o.has("smooth_coulomb")) {
    const double v = o.number("smooth_coulomb", 0);
    if (!t.friction)
      throw input_error(o.where + "field '" + o.name("smooth_coulomb") + "': the Coulomb law it smooths needs friction in '" +
                        o.name("terms") + "' (terms: " + t.list() + ")");
    if (!(v > 0)) throw input_error(o.where + "field '" + o.name("smooth_coulomb") + "' must be > 0 (a velocity scale)");
    t.coulomb = coulomb_law::smooth(v);
  }
  return t;
}
}  // namespace detail

/// The shipped robot files' folder: `share/nhdyn/robots` beside the scenes' (robot names in
/// scenes are looked up there after the scene file's own folder).
inline std::filesystem::path shipped_robots_dir(const std::vector<std::filesystem::path>& scene_dirs) {
  for (auto it = scene_dirs.rbegin(); it != scene_dirs.rend(); ++it)
    if (it->filename() == "scenes") return it->parent_path() / "robots";
  return {};
}

/// One run from a scene object (see the file comment). `dirs`: where a robot file it names
/// is looked for (the scene file's folder first).
inline run_spec parse_run(const json& j, const std::vector<std::filesystem::path>& dirs = {}) {
  const std::string name = j.contains("name") && j["name"].is_string() ? j["name"].get<std::string>() : "";
  const std::string where = "scene '" + (name.empty() ? "(unnamed)" : name) + "': ";
  const detail::object o(j, where, "",
                         {"name", "description", "robot", "locked", "task", "plant", "model", "controller", "reference",
                          "initial", "integrator", "duration", "sampling", "noise", "output", "success"});
  run_spec s;
  if (name.empty()) throw input_error(where + "field 'name' (a string) is required");
  s.name = name;
  const std::string robot = o.text("robot", "paper5");
  const bool paper5 = robot == "paper5";
  const auto presets = io::preset_names();
  if (!paper5 && std::find(presets.begin(), presets.end(), robot) != presets.end()) {
    s.robot = robot;  // a preset
  } else if (!paper5) {  // a file: a path (relative to the scene's folder) or a shipped robot's or model's name
    namespace fs = std::filesystem;
    std::error_code ec;
    std::vector<fs::path> tries;
    if (fs::path(robot).is_absolute()) tries.emplace_back(robot);
    for (const auto& d : dirs) tries.push_back(d / robot);
    if (const auto r = shipped_robots_dir(dirs); !r.empty()) {
      tries.push_back(r / (robot + ".json"));
      tries.push_back(r.parent_path() / "models" / (robot + ".json"));
    }
    for (const auto& t : tries)
      if (fs::is_regular_file(t, ec)) {
        s.robot = t.string();
        break;
      }
    if (s.robot == "paper5") {
      std::string looked, known;
      for (const auto& t : tries) looked += (looked.empty() ? "" : ", ") + t.string();
      for (const auto& p : presets) known += ", " + p;
      throw input_error(where + "field 'robot': '" + robot + "' is neither a preset (paper5" + known +
                        ") nor a robot file, URDF or JSON model (looked for " +
                        (looked.empty() ? std::string("nothing: no folder") : looked) + ")");
    }
  }
  if (o.has("locked")) {
    if (paper5)
      throw input_error(where + "field 'locked': paper5 runs on its 5-joint chains (its task is link 5); hold joints of "
                                "a robot file, URDF or JSON model (paper5's robot file: examples/robots/paper5.json)");
    s.locked = io::detail::read_locked(j.at("locked"), io::detail::place{where.substr(0, where.size() - 2)});
  }
  if (!paper5) {
    const auto task = o.sub("task", {"frame", "point"});
    if (!task.has("frame")) throw input_error(where + "field 'task.frame' (a body or frame name carrying r) is required for robot '" + robot + "'");
    s.task_frame = task.text("frame", "");
    if (task.has("point")) s.task_point = task.vector("point", 3);
    // {"NAME": factor, …} at plant/model.<key>
    const auto by_name = [&](const char* k, const char* key, const char* what) {
      std::vector<std::pair<std::string, double>> out;
      if (!o.has(k)) return out;
      const auto f = o.sub(k, detail::robot_factor_keys);
      if (!f.has(key)) return out;
      const json& mf = f.j.at(key);
      if (!mf.is_object())
        throw input_error(where + "field '" + std::string(k) + "." + key + "' must be an object {\"" + what +
                          "\": factor, …} for this robot");
      for (auto it = mf.begin(); it != mf.end(); ++it) {
        if (!it->is_number() || !(it->get<double>() > 0) || !std::isfinite(it->get<double>()))
          throw input_error(where + "field '" + std::string(k) + "." + key + "." + it.key() + "' must be a finite number > 0");
        out.emplace_back(it.key(), it->get<double>());
      }
      return out;
    };
    const auto radius = [&](const char* k) {
      if (!o.has(k)) return 1.0;
      const auto f = o.sub(k, detail::robot_factor_keys);
      const double r = f.number("wheel_radius_factor", 1);
      if (!(r > 0)) throw input_error(where + "field '" + std::string(k) + ".wheel_radius_factor' must be > 0");
      return r;
    };
    s.plant_mass = by_name("plant", "mass_factor", "BODY");
    s.model_mass = by_name("model", "mass_factor", "BODY");
    s.plant_length = by_name("plant", "length_factor", "JOINT");
    s.model_length = by_name("model", "length_factor", "JOINT");
    s.plant_wheel_radius = radius("plant");
    s.model_wheel_radius = radius("model");
    s.plant = s.model = presets::paper5_parameters<double>{};  // not used: no paper5 factors
    if (o.has("plant")) s.plant_terms = detail::read_terms(o.sub("plant", detail::robot_factor_keys));
    if (o.has("model")) s.model_terms = detail::read_terms(o.sub("model", detail::robot_factor_keys));
  } else {
    if (o.has("task")) throw input_error(where + "field 'task': paper5's task point is the origin of link 5 (not settable)");
    // An object with factors gives all four (those not given: 1); one with only the terms keys
    // keeps the default factors (the plant's paper-circle mismatch), so that choosing terms
    // changes nothing else.
    const auto factors_of = [&](const char* k, presets::paper5_parameters<double>& p, terms& t) {
      if (!o.has(k)) return;
      const auto f = o.sub(k, detail::factor_keys);
      const bool only_terms = (f.has("terms") || f.has("smooth_coulomb")) &&
                              !(f.has("mass_factor") || f.has("d3_factor") || f.has("a4_factor") || f.has("a5_factor"));
      if (!only_terms) p = detail::read_factors(f);
      t = detail::read_terms(f);
    };
    factors_of("plant", s.plant, s.plant_terms);
    factors_of("model", s.model, s.model_terms);
  }

  const auto c = o.sub("controller", {"type", "K0", "K1", "lambda", "kN", "kP", "posture_joints", "robust", "kp", "kd"});
  if (const auto type = c.text("type", "task_space"); type == "computed_torque") {
    s.controller = controller_type::computed_torque;
    for (const char* k : {"K0", "K1", "lambda", "kN", "kP", "posture_joints", "robust"})
      if (c.has(k))
        throw input_error(where + "field 'controller." + std::string(k) + "' belongs to the task-space controller (type 'computed_torque' takes kp, kd)");
    s.ct.kp = c.number("kp", s.ct.kp);
    s.ct.kd = c.number("kd", s.ct.kd);
    if (!(s.ct.kp >= 0) || !(s.ct.kd >= 0)) throw input_error(where + "fields 'controller.kp', 'controller.kd' must be ≥ 0");
  } else if (type != "task_space") {
    throw input_error(where + "field 'controller.type' must be 'task_space' or 'computed_torque' (got '" + type + "')");
  } else {
    for (const char* k : {"kp", "kd"})
      if (c.has(k))
        throw input_error(where + "field 'controller." + std::string(k) +
                          "' belongs to the computed-torque controller (controller.type 'computed_torque'); the task-space controller's posture stiffness is 'kP'");
  }
  s.gains.K0 = c.gain("K0", s.gains.K0);
  s.gains.K1 = c.gain("K1", s.gains.K1);
  s.gains.lambda = c.number("lambda", s.gains.lambda);
  s.gains.kN = c.number("kN", s.gains.kN);
  s.gains.kP = c.number("kP", s.gains.kP);
  if (c.has("posture_joints") && !paper5) {
    const json& pj = c.j.at("posture_joints");
    if (!pj.is_array()) throw input_error(where + "field 'controller.posture_joints' must be a list of joint names");
    for (const auto& k : pj) {
      if (!k.is_string()) throw input_error(where + "field 'controller.posture_joints': entries are joint names");
      s.posture_joints.push_back(k.get<std::string>());
    }
  } else if (c.has("posture_joints")) {
    const json& pj = c.j.at("posture_joints");
    if (!pj.is_array()) throw input_error(where + "field 'controller.posture_joints' must be a list of joint numbers 1…5");
    s.posture_mask.setZero();
    for (const auto& k : pj) {
      if (!k.is_number_integer() || k.get<int>() < 1 || k.get<int>() > 5)
        throw input_error(where + "field 'controller.posture_joints': entries are joint numbers 1…5");
      s.posture_mask(k.get<int>() - 1) = 1;
    }
  }
  const auto rb = c.sub("robust", {"enabled", "alpha", "gamma0", "gamma1", "gamma2", "epsilon"});
  s.gains.use_robust = rb.boolean("enabled", true);
  s.gains.robust = {rb.number("alpha", 0), rb.number("gamma0", 0), rb.number("gamma1", 0.1),
                    rb.number("gamma2", 0.2), rb.number("epsilon", 0)};

  const std::string rtype = o.has("reference") && o.j.at("reference").is_object()
                                ? o.sub("reference", {"type", "center", "u", "v", "radius", "period", "phase", "velocity",
                                                      "from", "to", "start", "end", "times", "points", "q"})
                                      .text("type", "circle")
                                : "circle";
  if (rtype == "circle") {
    const auto r = o.sub("reference", {"type", "center", "u", "v", "radius", "period", "phase", "velocity"});
    circle_reference cr;
    if (r.has("center")) cr.center = r.vector("center", 3);
    if (r.has("velocity")) cr.velocity = r.vector("velocity", 3);
    if (r.has("u")) cr.u = r.vector("u", 3);
    if (r.has("v")) cr.v = r.vector("v", 3);
    cr.radius = r.number("radius", cr.radius);
    const double period = r.number("period", 20);
    if (!(period != 0)) throw input_error(where + "field 'reference.period' must not be 0");
    cr.omega = 2 * 3.14159265358979323846 / period;
    cr.phase = r.number("phase", 0);
    s.reference = cr;
  } else if (rtype == "line") {
    const auto r = o.sub("reference", {"type", "from", "to", "start", "end"});
    for (const char* k : {"from", "to", "end"})
      if (!r.has(k)) throw input_error(where + "field 'reference." + std::string(k) + "' is required for a line");
    line_reference l;
    l.from = r.vector("from", 3), l.to = r.vector("to", 3);
    l.start = r.number("start", 0), l.end = r.number("end", 0);
    if (!(l.end > l.start)) throw input_error(where + "field 'reference.end' must be later than 'reference.start'");
    s.reference = l;
  } else if (rtype == "spline" || rtype == "joint_spline") {
    const bool joint = rtype == "joint_spline";
    const char* pts = joint ? "q" : "points";
    const auto r = o.sub("reference", {"type", "times", pts});
    for (const char* k : {"times", pts})
      if (!r.has(k)) throw input_error(where + "field 'reference." + std::string(k) + "' is required for a " + rtype);
    const std::vector<double> times = r.list("times", 2);
    const Eigen::MatrixXd y = r.rows(pts, joint ? (paper5 ? 5 : -1) : 3, 2);
    if (y.rows() != Eigen::Index(times.size()))
      throw input_error(where + "fields 'reference.times' and 'reference." + pts + "': " + std::to_string(times.size()) +
                        " times for " + std::to_string(y.rows()) + " waypoints");
    try {
      if (joint) s.reference = joint_spline_reference(times, y);
      else s.reference = spline_reference(times, y);
    } catch (const input_error& e) {
      throw input_error(where + "field 'reference': " + e.what());
    }
  } else {
    throw input_error(where + "field 'reference.type' must be 'circle', 'line', 'spline' or 'joint_spline' (got '" + rtype + "')");
  }
  if (s.controller == controller_type::computed_torque && !is_joint_space(s.reference))
    throw input_error(where + "the computed-torque controller needs a joint-space reference (reference.type 'joint_spline')");

  const auto init = o.sub("initial", {"q", "eta"});
  if (paper5) {
    if (init.has("q")) s.q0 = init.vector("q", 5);
    if (init.has("eta")) s.eta0 = init.vector("eta", 4);
  } else {  // the sizes are the robot's, checked when it is loaded
    const auto list = [&](const char* k) {
      const json& v = init.j.at(k);
      if (!v.is_array() || v.empty())
        throw input_error(where + "field 'initial." + std::string(k) + "' must be a non-empty list of numbers");
      return init.vector(k, int(v.size()));
    };
    if (init.has("q")) s.q_start = list("q");
    if (init.has("eta")) s.eta_start = list("eta");
  }

  const auto in = o.sub("integrator", {"method", "step", "rtol", "atol", "max_steps", "min_step"});
  s.integrator.kind = method_from_string(in.text("method", to_string(s.integrator.kind)));
  s.integrator.step = in.number("step", s.integrator.step);
  s.integrator.rtol = in.number("rtol", s.integrator.rtol);
  s.integrator.atol = in.number("atol", s.integrator.atol);
  s.integrator.max_steps = long(in.number("max_steps", double(s.integrator.max_steps)));
  s.integrator.min_step = in.number("min_step", s.integrator.min_step);
  if (!(s.integrator.step > 0) || !(s.integrator.rtol > 0) || !(s.integrator.atol > 0) ||
      !(s.integrator.max_steps > 0) || !(s.integrator.min_step >= 0))
    throw input_error(where + "field 'integrator': step, rtol, atol, max_steps must be > 0");

  s.duration = o.number("duration", s.duration);
  const auto sm = o.sub("sampling", {"mode", "rate_hz"});
  const std::string mode = sm.text("mode", sm.has("rate_hz") ? "zoh" : "continuous");
  if (mode == "continuous") {
    if (sm.has("rate_hz")) throw input_error(where + "field 'sampling.rate_hz' needs sampling.mode 'zoh'");
    s.sample_rate = 0;
  } else if (mode == "zoh") {
    s.sample_rate = sm.number("rate_hz", 0);
    if (!(s.sample_rate > 0)) throw input_error(where + "field 'sampling.rate_hz' must be > 0 for mode 'zoh'");
  } else {
    throw input_error(where + "field 'sampling.mode' must be 'continuous' or 'zoh' (got '" + mode + "')");
  }
  const auto nz = o.sub("noise", {"sigma", "seed"});
  s.noise_sigma = nz.number("sigma", 0);
  if (nz.has("seed")) {
    if (!nz.j.at("seed").is_number_integer() || nz.j.at("seed").get<long long>() < 0)
      throw input_error(where + "field 'noise.seed' must be a non-negative integer");
    s.seed = nz.j.at("seed").get<std::uint64_t>();
  }
  s.output_step = o.sub("output", {"step"}).number("step", s.output_step);
  const auto su = o.sub("success", {"tail_from", "max_tail_error"});
  s.tail_from = su.number("tail_from", s.tail_from);
  s.tail_tolerance = su.number("max_tail_error", s.tail_tolerance);
  if (!(s.duration > 0) || !(s.output_step > 0) || !(s.noise_sigma >= 0))
    throw input_error(where + "duration and output.step must be > 0 and noise.sigma ≥ 0");
  return s;
}

/// Where scenes named by name (not by path) are looked for, in order.
using search_path = std::vector<std::filesystem::path>;

/// The shipped scenes' folder: $NHDYN_SCENES_DIR if set, else `share/nhdyn/scenes` beside the
/// running program's `bin/` (the layout of both `cmake --install` and nhdyn's build tree,
/// whose tool is `build/bin/nhdyn`). Never the current directory: a program finds its data
/// wherever it is run from.
inline search_path default_search_path() {
  namespace fs = std::filesystem;
  search_path dirs;
  if (const char* e = std::getenv("NHDYN_SCENES_DIR"); e && *e) dirs.emplace_back(e);
  std::error_code ec;
  if (const auto exe = fs::read_symlink("/proc/self/exe", ec); !ec)
    dirs.push_back(exe.parent_path().parent_path() / "share" / "nhdyn" / "scenes");
  return dirs;
}

/// A scene file's JSON, and where the scene names it uses are looked up: its own folder
/// first, then the search path it was found with.
struct opened {
  json j;
  search_path dirs;
};

namespace detail {
/// dirs with `first` in front.
inline search_path with_first(const std::filesystem::path& first, const search_path& dirs) {
  search_path out{first.empty() ? std::filesystem::path(".") : first};
  out.insert(out.end(), dirs.begin(), dirs.end());
  return out;
}
}  // namespace detail

/// A scene, study or suite from a file path, or a scene's name looked up in `dirs`.
inline opened open(const std::string& name_or_path, const search_path& dirs = default_search_path()) {
  namespace fs = std::filesystem;
  fs::path file;
  std::error_code ec;
  if (fs::is_regular_file(name_or_path, ec)) {
    file = name_or_path;
  } else {
    for (const auto& d : dirs)
      if (fs::is_regular_file(d / (name_or_path + ".json"), ec)) {
        file = d / (name_or_path + ".json");
        break;
      }
  }
  if (file.empty()) {
    std::string looked;
    for (const auto& d : dirs) looked += (looked.empty() ? "" : ", ") + d.string();
    throw input_error("scene '" + name_or_path + "': no such file, and no scene of that name in " +
                      (looked.empty() ? std::string("(no folder)") : looked) +
                      " (shipped scenes: set NHDYN_SCENES_DIR to their folder)");
  }
  std::ifstream f(file);
  std::stringstream text;
  text << f.rdbuf();
  if (!f) throw input_error("scene file '" + file.string() + "': cannot be read");
  return {io::parse_strict<input_error>(text.str(), "scene file '" + file.string() + "': "),
          detail::with_first(file.parent_path(), dirs)};
}

/// open(…)'s JSON alone.
inline json load(const std::string& name_or_path, const search_path& dirs = default_search_path()) {
  return open(name_or_path, dirs).j;
}

namespace detail {
inline std::string level_text(const json& v) {
  if (v.is_number_float()) {
    std::string s;
    io::append_number(s, v.get<double>());
    return s;
  }
  return v.is_string() ? v.get<std::string>() : v.dump();
}

/// Run k's seed in a Monte Carlo study seeded with `seed`: the (k+1)-th output of splitmix64
/// started at `seed` (its finaliser of seed + (k+1)·γ), so that runs are independent streams
/// and any one is reproduced from its seed alone.
inline std::uint64_t run_seed(std::uint64_t seed, std::uint64_t k) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (k + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// A Monte Carlo factor's distribution (docs/simulation.md, "Monte Carlo studies"), drawn
/// from std::mt19937_64 by formulas of its own (the standard library's distributions are
/// implementation-defined): the same numbers on every platform.
struct distribution {
  enum kind_t { uniform, normal, lognormal, integer, choice } kind = uniform;
  double a = 0, b = 1;
  json levels;
  json draw(std::mt19937_64& g) const {
    const auto unit = [&] { return (double(g() >> 11) + 0.5) * 0x1.0p-53; };  // (0, 1]
    const auto index = [&](std::uint64_t count) {  // 0 … count − 1, uniformly (count ≤ 2^53)
      return std::min<std::uint64_t>(count - 1, std::uint64_t(double(g() >> 11) * 0x1.0p-53 * double(count)));
    };
    const auto gauss = [&] {  // Box–Muller, its two uniforms drawn in a fixed order
      const double u1 = unit(), u2 = unit();
      return std::sqrt(-2 * std::log(u1)) * std::cos(2 * 3.14159265358979323846 * u2);
    };
    switch (kind) {
      case uniform: return a + (b - a) * unit();
      case normal: return a + b * gauss();
      case lognormal: return std::exp(a + b * gauss());
      case integer: return std::int64_t(a) + std::int64_t(index(std::uint64_t(b - a) + 1));
      case choice: return levels[std::size_t(index(levels.size()))];
    }
    return nullptr;
  }
};
inline distribution read_distribution(const json& j, const std::string& where) {
  if (!j.is_object() || j.size() != 1)
    throw input_error(where + "must be one of {\"uniform\": [lo, hi]}, {\"normal\": [mean, sd]}, "
                              "{\"lognormal\": [mu, sigma]}, {\"integer\": [lo, hi]}, {\"choice\": [values…]}");
  const std::string k = j.begin().key();
  const json& v = j.begin().value();
  distribution d;
  if (k == "choice") {
    if (!v.is_array() || v.empty()) throw input_error(where + "'choice' needs a non-empty list of values");
    d.kind = distribution::choice;
    d.levels = v;
    return d;
  }
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number() || !std::isfinite(v[0].get<double>()) ||
      !std::isfinite(v[1].get<double>()))
    throw input_error(where + "'" + k + "' needs two finite numbers");
  d.a = v[0].get<double>();
  d.b = v[1].get<double>();
  if (k == "uniform") {
    d.kind = distribution::uniform;
    if (!(d.a <= d.b)) throw input_error(where + "'uniform': needs lo ≤ hi");
  } else if (k == "normal" || k == "lognormal") {
    d.kind = k == "normal" ? distribution::normal : distribution::lognormal;
    if (!(d.b >= 0)) throw input_error(where + "'" + k + "': the spread must be ≥ 0");
  } else if (k == "integer") {
    d.kind = distribution::integer;
    if (d.a != std::floor(d.a) || d.b != std::floor(d.b) || !(d.a <= d.b) || d.b - d.a >= 0x1.0p53 ||
        std::abs(d.a) > 0x1.0p53 || std::abs(d.b) > 0x1.0p53)
      throw input_error(where + "'integer': needs integers lo ≤ hi, |lo|, |hi| and hi − lo below 2^53");
  } else {
    throw input_error(where + "unknown distribution '" + k + "' (known: uniform, normal, lognormal, integer, choice)");
  }
  return d;
}

/// A scene named inside a scene file: a path relative to that file's folder (dirs' first),
/// or a name looked up in dirs; never the current folder.
inline opened open_nested(const std::string& ref, const search_path& dirs) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::path(ref).is_absolute() || dirs.empty()) return open(ref, dirs);
  if (fs::is_regular_file(dirs.front() / ref, ec)) return open((dirs.front() / ref).string(), dirs);
  for (const auto& d : dirs)
    if (fs::is_regular_file(d / (ref + ".json"), ec)) return open((d / (ref + ".json")).string(), dirs);
  std::string looked;
  for (const auto& d : dirs) looked += (looked.empty() ? "" : ", ") + d.string();
  throw input_error("scene '" + ref + "': no such file in " + dirs.front().string() + ", and no scene of that name in " +
                    looked);
}

inline void expand_into(const json& j, std::vector<run_spec>& out, int depth, const search_path& outer) {
  if (depth > 16) throw input_error("scenes nest more than 16 deep (a suite that includes itself?)");
  // A name is looked up in the folder of the file that names it first, then in `outer`.
  search_path dirs = outer;
  json resolved = j;
  if (j.is_string()) {
    auto l = depth == 0 ? open(j.get<std::string>(), outer) : open_nested(j.get<std::string>(), outer);
    resolved = std::move(l.j);
    dirs = std::move(l.dirs);
  }
  if (!resolved.is_object()) throw input_error("a scene must be a JSON object or a scene name");
  const std::string name = resolved.contains("name") && resolved["name"].is_string() ? resolved["name"].get<std::string>()
                                                                                       : std::string("(unnamed)");
  const std::string where = "scene '" + name + "': ";
  if (resolved.contains("scenes")) {
    const object o(resolved, where, "", {"name", "description", "scenes"});
    if (!resolved["scenes"].is_array()) throw input_error(where + "field 'scenes' must be a list");
    for (const auto& s : resolved["scenes"]) expand_into(s, out, depth + 1, dirs);
  } else if (resolved.contains("study")) {
    const object o(resolved, where, "", {"name", "description", "study"});
    const object st = o.sub("study", {"base", "set", "factors", "monte_carlo"});
    if (!st.has("base")) throw input_error(where + "field 'study.base' is required");
    json base = st.j["base"];
    search_path base_dirs = dirs;  // a robot file named in the base resolves from the base's folder
    if (st.j["base"].is_string()) {
      auto opened = open_nested(st.j["base"].get<std::string>(), dirs);
      base = std::move(opened.j);
      base_dirs = std::move(opened.dirs);
    }
    if (!base.is_object() || base.contains("study") || base.contains("scenes"))
      throw input_error(where + "field 'study.base' must be a single scene");
    if (st.has("set")) {
      if (!st.j["set"].is_object()) throw input_error(where + "field 'study.set' must be an object (a JSON merge patch)");
      base.merge_patch(st.j["set"]);
    }
    const json factors = st.has("factors") ? st.j["factors"] : json::array();
    if (!factors.is_array()) throw input_error(where + "field 'study.factors' must be a list");
    const bool monte_carlo = st.has("monte_carlo");
    std::vector<std::size_t> level(factors.size(), 0);
    std::vector<distribution> dists;
    for (std::size_t i = 0; i < factors.size(); ++i) {
      const std::string fw = "study.factors[" + std::to_string(i) + "]";
      const object f(factors[i], where, fw, {"name", "path", monte_carlo ? "distribution" : "levels"});
      if (!f.has("path") || !f.j["path"].is_string())
        throw input_error(where + "field '" + fw + "' needs 'path' (a JSON pointer)");
      if (monte_carlo) {
        if (!f.has("distribution"))
          throw input_error(where + "field '" + fw + "' needs 'distribution' in a Monte Carlo study");
        dists.push_back(read_distribution(f.j["distribution"], where + "field '" + fw + ".distribution': "));
      } else if (!f.has("levels") || !f.j["levels"].is_array() || f.j["levels"].empty()) {
        throw input_error(where + "field '" + fw + "' needs a non-empty list 'levels'");
      }
      // A JSON pointer may index an array past its end (it grows): bound the index so that a
      // typo like /x/100000000000 is an error, not an attempt to allocate it.
      const std::string p = f.j["path"].get<std::string>();
      for (std::size_t a = 0; a < p.size();) {
        const std::size_t b = std::min(p.find('/', a + 1), p.size());
        const std::string token = p.substr(a + 1, b > a ? b - a - 1 : 0);
        if (!token.empty() && token.find_first_not_of("0123456789") == std::string::npos && token.size() > 3)
          throw input_error(where + "field 'study.factors[" + std::to_string(i) + "].path': array index " + token +
                            " is too large (at most 999)");
        a = b;
      }
    }
    const auto set_factor = [&](json& run, std::size_t i, const json& v) {
      try {
        run[json::json_pointer(factors[i]["path"].get<std::string>())] = v;
      } catch (const json::exception& e) {
        throw input_error(where + "field 'study.factors[" + std::to_string(i) + "].path': " + e.what());
      }
    };
    const auto factor_name = [&](std::size_t i) {
      const auto& f = factors[i];
      return f.contains("name") && f["name"].is_string() ? f["name"].get<std::string>() : f["path"].get<std::string>();
    };
    if (monte_carlo) {  // run i: its own seed, its factors drawn from it in order
      const object mc = st.sub("monte_carlo", {"runs", "seed", "replay"});
      std::vector<std::uint64_t> seeds;
      const auto seed_of = [&](const json& v, const std::string& field) {
        if (!v.is_number_integer() || (!v.is_number_unsigned() && v.get<long long>() < 0))
          throw input_error(where + "field '" + field + "' must be a non-negative integer");
        return v.get<std::uint64_t>();
      };
      if (mc.has("replay") && (mc.has("runs") || mc.has("seed")))
        throw input_error(where + "field 'study.monte_carlo': 'replay' lists the seeds to run, without 'runs' or 'seed'");
      if (mc.has("replay")) {  // the runs of these seeds only (a run replayed alone)
        if (!mc.j["replay"].is_array() || mc.j["replay"].empty())
          throw input_error(where + "field 'study.monte_carlo.replay' must be a non-empty list of run seeds");
        for (const auto& v : mc.j["replay"]) seeds.push_back(seed_of(v, "study.monte_carlo.replay"));
      } else {
        const double n = mc.number("runs", 0);
        if (!(n >= 1 && n <= 1e6 && n == std::floor(n)))
          throw input_error(where + "field 'study.monte_carlo.runs' must be an integer in 1…1000000");
        const std::uint64_t seed = mc.has("seed") ? seed_of(mc.j["seed"], "study.monte_carlo.seed") : 1;
        for (std::uint64_t k = 0; k < std::uint64_t(n); ++k) seeds.push_back(run_seed(seed, k));
      }
      const int width = int(std::to_string(seeds.size() - 1).size());
      for (std::size_t k = 0; k < seeds.size(); ++k) {
        json run = base;
        json drawn = json::object();
        std::mt19937_64 g(seeds[k]);
        for (std::size_t i = 0; i < factors.size(); ++i) {
          const json v = dists[i].draw(g);
          set_factor(run, i, v);
          drawn[factor_name(i)] = v;
        }
        std::string idx = std::to_string(k);
        idx.insert(0, std::size_t(width) - std::min(idx.size(), std::size_t(width)), '0');
        run["name"] = name + (mc.has("replay") ? "-seed_" + std::to_string(seeds[k]) : "-" + idx);
        out.push_back(parse_run(run, base_dirs));
        out.back().run_seed = seeds[k];
        out.back().factors = drawn.dump();
      }
      return;
    }
    double runs = 1;
    for (const auto& f : factors) runs *= double(f["levels"].size());
    if (runs > 1e5)
      throw input_error(where + "the study's full factorial has " + std::to_string(runs) + " runs (at most 100000)");
    // Full factorial, first factor slowest (standard order).
    for (bool more = true; more;) {
      json run = base;
      std::string run_name = name;
      json levels = json::object();
      for (std::size_t i = 0; i < factors.size(); ++i) {
        const json& v = factors[i]["levels"][level[i]];
        set_factor(run, i, v);
        levels[factor_name(i)] = v;
        run_name += '-';
        run_name += factor_name(i);
        run_name += '_';
        run_name += level_text(v);
      }
      run["name"] = run_name;
      out.push_back(parse_run(run, base_dirs));
      out.back().factors = levels.dump();
      more = false;
      for (std::size_t i = factors.size(); i-- > 0;) {
        if (++level[i] < factors[i]["levels"].size()) {
          more = true;
          break;
        }
        level[i] = 0;
      }
    }
  } else {
    out.push_back(parse_run(resolved, dirs));
  }
}
}  // namespace detail

/// The runs of a scene (one), a study (its design) or a suite (all of its members'). Scenes
/// it names are looked up in `dirs`.
inline std::vector<run_spec> expand(const json& j, const search_path& dirs = default_search_path()) {
  std::vector<run_spec> out;
  try {
    detail::expand_into(j, out, 0, dirs);
  } catch (const json::exception& e) {  // a shape the checks above missed: still an input error
    throw input_error(std::string("scene: ") + e.what());
  }
  return out;
}

}  // namespace nhdyn::scene
