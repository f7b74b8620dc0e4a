#pragma once
/// \file io/robot_file.hpp
/// Robot files: a JSON object that names a URDF and says how the robot moves on the floor
/// (docs/model-format.md, "Robot files"). Needs nhdyn::json and nhdyn::urdf.
///
///     {"name": "...", "urdf": "robot.urdf",              (the path relative to this file)
///      "gravity": [0, 0, -9.81],                          (optional, this default)
///      "base": {"type": "planar"},                        (optional; absent: fixed base)
///      "constraint": {...},                               (optional)
///      "locked": {"NAME or GLOB": position, ...}}         (optional: joints held, model/lock.hpp)
///
/// A planar base puts q = (base_x, base_y, base_yaw, the URDF's joints): the root link's pose
/// on the floor. The constraints (docs/model-format.md and docs/theory.md give A, S, Ṡ):
///
/// - `{"type": "differential_drive"}` (planar base): the root link's origin cannot slip along
///   the root link's y axis; η = (v, ω, the URDF's joint rates); k = 1. With the URDF's own
///   base joints instead of a planar base: `"x"`, `"y"`, `"heading"` name them, with optional
///   `"heading_sign"` (±1) and `"forward_offset"` [rad] as differential_drive takes them.
/// - `{"type": "wheels", "left": J, "right": J, "radius": r}` (planar base): two drive
///   wheels, continuous joints on the root link with horizontal lateral axes, roll without
///   slipping, and the axle does not slip sideways; η = (φ̇_L, φ̇_R, other joint rates);
///   k = 3 (rolling_wheels, its geometry read from the URDF).
/// - `{"type": "bicycle", "steer": J, "wheelbase": L}` (planar base): rear axle at the root
///   link's origin, the steered front wheel (vertical joint J) L ahead; neither axle slips
///   sideways; η = (v, δ̇, other joint rates); k = 2.
/// - `{"type": "wheeled_base", "wheels": [{"kind": "fixed" | "steered" | "castor" | "swedish",
///   "spin": J, …}, …], "eta": […], "actuated": […], "weights": {…}}` (planar base): any set of
///   wheels, each rim point at the floor not slipping (wheeled_base, docs/model-format.md).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "../config.hpp"
#include "../constraints/constraint.hpp"
#include "../model/lock.hpp"
#include "json.hpp"
#include "urdf.hpp"

namespace nhdyn::io {

/// A robot file's constraint: one of the built-in types a robot file can name.
using robot_constraint = base_constraint;

/// A robot loaded from a robot file: its tree and, when the file gives one, its constraint.
struct robot_model {
  tree<double> model;
  std::optional<robot_constraint> constraint;
  std::string name;
  /// Where the constraint came from (the file's "constraint" object, its path, whether the
  /// base is planar): constraint_on reads it again on another tree.
  json constraint_source{};
  std::string path{};
  bool planar_base = false;
  /// The joints held by "locked" (or lock_robot), by name with their positions, in the full
  /// tree's q order; `model` is the tree without them.
  std::vector<std::pair<std::string, double>> locked{};

  /// Names of η's entries: the constraint's (`eta_names` of its type), or the joint names.
  std::vector<std::string> eta_names() const {
    const auto joints = model.joint_names();
    if (!constraint) return joints;
    return std::visit([&](const auto& c) { return c.eta_names(joints); }, *constraint);
  }
  /// Names of τ's entries: the actuated joints of a wheeled_base, else η's names.
  std::vector<std::string> tau_names() const {
    const auto joints = model.joint_names();
    if (!constraint) return joints;
    return std::visit([&](const auto& c) { return tau_names_of(c, joints, c.eta_names(joints)); }, *constraint);
  }
  /// k, the number of constraint rows (0 without a constraint).
  int k() const {
    return constraint ? std::visit([](const auto& c) { return c.k(); }, *constraint) : 0;
  }
};

/// The robot r with the joints that `locks` names or globs held at the given positions
/// (model/lock.hpp's lock on its tree); its constraint is read again on the smaller tree. A
/// joint the constraint involves (the planar base's, a wheel's, a castor's) cannot be
/// locked: model_error naming it and the constraint. `where` begins every message.
template <class = void>
robot_model lock_robot(robot_model r, const std::vector<std::pair<std::string, double>>& locks,
                       const std::string& where);
/// A JSON model (a DH chain, its optional differential_drive, its "locked" joints) as a
/// robot: the chain as a tree (as_tree: joints joint1…, bodies link1…, the base `base`), the
/// constraint on it with the same joint indices, and the locked joints held (lock_robot:
/// a joint of the constraint cannot be). A DH chain with joints held is no longer a DH chain;
/// this is how the tool, scenes and Python load a model file with "locked". `where` begins
/// the messages about the locked joints.
template <class = void>
robot_model as_robot(const model<double>& m, const std::string& where = "locked: ");
/// The robot file's text; `path` locates the URDF (relative paths from its folder) and names
/// the file in messages.
template <class = void>
robot_model parse_robot_file(const std::string& text, const std::string& path, urdf_options opt = {});
/// r's constraint read again on the tree t (r's joints, other placements: a plant whose link
/// lengths differ from the file's), so that the geometry a constraint takes from the URDF
/// (the wheels' positions) follows t. Warnings were given when r was loaded: none again.
/// Empty when r has no constraint.
template <class = void>
std::optional<robot_constraint> constraint_on(const robot_model& r, const tree<double>& t);
/// The robot file at `path`.
template <class = void>
robot_model load_robot_file(const std::string& path, urdf_options opt = {});
/// The robot that `spec` names, whatever it is: a preset (io::preset_names), a URDF (`.urdf`:
/// no constraint), a robot file (a JSON object with "urdf") or a JSON model (a DH chain, as a
/// tree: as_robot). The loader of scenes, robot_dynamics and the tool's robot arguments. A JSON
/// object with neither "urdf" nor "links" is model_error naming its keys.
template <class = void>
robot_model load_robot(const std::string& spec);

#if NHDYN_DEFINES(NHDYN_PART_IO)
namespace detail {
/// Index (q order) of the joint named by field `f` of a constraint object; errors list the
/// movable joints.
inline int named_joint(const json& c, const tree<double>& t, const place& at, std::string_view f) {
  const std::string name = string_field(c[std::string(f)], at, f);
  const auto joints = t.joint_names();
  for (int i = 0; i < t.dof(); ++i)
    if (joints[std::size_t(i)] == name) return i;
  std::string known;
  for (const auto& j : joints) known += (known.empty() ? "" : ", ") + j;
  throw model_error(at.field(f) + "no movable joint named '" + name + "' (movable joints: " + known + ")");
}

/// A joint fixed to the root link (its parent is the planar base's moving body): its axis
/// and origin in the root link's frame.
struct joint_on_root {
  Eigen::Vector3d axis, origin;
};
inline joint_on_root joint_on_root_link(const tree<double>& t, int j, const place& at, std::string_view f,
                                        std::string_view what) {
  const auto& b = t[j];
  if (t.parent(j) != 2)
    throw model_error(at.field(f) + "joint '" + b.joint_name + "' is not on the root link '" + t[2].name +
                      "' (its parent is '" + (t.parent(j) < 0 ? t.root_name() : t[t.parent(j)].name) + "'): " +
                      std::string(what) + " must be mounted on the base (directly or through fixed joints)");
  if (b.joint != joint_type::revolute)
    throw model_error(at.field(f) + "joint '" + b.joint_name + "' is prismatic; " + std::string(what) +
                      " needs a revolute or continuous joint");
  return {b.R_PJ * b.axis, b.p_PJ};
}

/// The sign (±1) of an axis that must lie along ±e (within 1e-3 per component; beyond
/// 1e-9 a warning: a URDF's rpy written as 1.5708 is common and harmless).
inline double axis_sign(const Eigen::Vector3d& a, int e, const std::string& where, std::string_view need,
                        const urdf_options& opt) {
  double off = 0;
  for (int i = 0; i < 3; ++i)
    if (i != e) off = std::max(off, std::abs(a(i)));
  std::ostringstream os;
  os << where << "its axis in the root link's frame is (" << a.x() << ", " << a.y() << ", " << a.z()
     << "), not " << need;
  if (off > 1e-3) throw model_error(os.str());
  if (off > 1e-9) {
    os << " to " << off << "; taken as exact";
    opt.warning(os.str());
  }
  return a(e) > 0 ? 1.0 : -1.0;
}

/// A list of joint names (field f of c).
inline std::vector<std::string> name_list(const json& c, const place& at, std::string_view f) {
  const json& l = c[std::string(f)];
  if (!l.is_array()) throw model_error(at.field(f) + "expected a list of joint names, got " + describe(l));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < l.size(); ++i) {
    if (!l[i].is_string())
      throw model_error(at.field(f) + "entry " + std::to_string(i) + ": expected a joint name, got " + describe(l[i]));
    out.push_back(l[i].get<std::string>());
  }
  return out;
}

/// A "wheeled_base" constraint object: its wheels, eta, actuated and weights.
template <class = void>  // compiled where used (config.hpp)
wheeled_base<double> read_wheeled_base(const json& c, const tree<double>& t, const place& at, const urdf_options& opt) {
  check_keys(c, {"type", "wheels", "eta", "actuated", "weights"}, {"wheels"}, at.prefix + ", ", "the constraint");
  const json& ws = c["wheels"];
  if (!ws.is_array() || ws.empty()) throw model_error(at.field("wheels") + "expected a non-empty list of wheels, got " + describe(ws));
  std::vector<wheel> wheels;
  for (std::size_t i = 0; i < ws.size(); ++i) {
    const place w{at.prefix + ", wheels[" + std::to_string(i) + "]"};
    const json& o = ws[i];
    if (!o.is_object() || !o.contains("kind") || !o["kind"].is_string())
      throw model_error(w.prefix + ": expected an object with a \"kind\" (fixed, steered, castor, swedish), got " + describe(o));
    const std::string kind = o["kind"].get<std::string>();
    wheel wh;
    if (kind == "fixed") {
      check_keys(o, {"kind", "spin", "radius"}, {"spin", "radius"}, w.prefix + ", ", "a fixed wheel");
      wh.kind = wheel_kind::fixed;
    } else if (kind == "steered") {
      check_keys(o, {"kind", "steer", "spin", "radius"}, {"steer", "spin", "radius"}, w.prefix + ", ", "a steered wheel");
      wh.kind = wheel_kind::steered;
      wh.steer = string_field(o["steer"], w, "steer");
    } else if (kind == "castor") {
      check_keys(o, {"kind", "swivel", "spin", "radius"}, {"swivel", "spin", "radius"}, w.prefix + ", ", "a castor");
      wh.kind = wheel_kind::castor;
      wh.steer = string_field(o["swivel"], w, "swivel");
    } else if (kind == "swedish") {
      check_keys(o, {"kind", "spin", "radius", "roller_angle"}, {"spin", "radius", "roller_angle"}, w.prefix + ", ",
                 "a swedish wheel");
      wh.kind = wheel_kind::swedish;
      const double g = number(o["roller_angle"], w, "roller_angle");
      if (!(std::abs(g) > 0 && std::abs(g) <= 90))
        throw model_error(w.field("roller_angle") + "the rollers' angle to the spin axis must be within ±90° and not 0, not " +
                          format_number(g) + "°");
      wh.roller_angle = g * std::numbers::pi / 180;
    } else {
      throw model_error(w.field("kind") + "unknown wheel kind '" + kind + "' (known: fixed, steered, castor, swedish)");
    }
    wh.spin = string_field(o["spin"], w, "spin");
    wh.radius = number(o["radius"], w, "radius");
    if (!(wh.radius > 0)) throw model_error(w.field("radius") + "the wheel radius must be positive, not " + format_number(wh.radius));
    wheels.push_back(std::move(wh));
  }
  wheeled_base_options o;
  if (c.contains("eta")) o.eta = name_list(c, at, "eta");
  if (c.contains("actuated")) o.actuated = name_list(c, at, "actuated");
  if (c.contains("weights")) {
    const json& w = c["weights"];
    if (!w.is_object()) throw model_error(at.field("weights") + "expected an object {joint name: weight}, got " + describe(w));
    for (auto it = w.begin(); it != w.end(); ++it) o.weights.emplace_back(it.key(), number(it.value(), at, "weights"));
  }
  o.warn = [&opt, &at](const std::string& msg) { opt.warning(at.prefix + ": " + msg); };
  return wheeled_base<double>(t, std::move(wheels), std::move(o));
}

template <class = void>  // compiled where used (config.hpp)
robot_constraint read_robot_constraint(const json& c, const tree<double>& t, const place& top,
                                       const urdf_options& opt) {
  const place at{top.prefix + ", constraint"};
  const std::string known = "(known: differential_drive, wheels, bicycle, wheeled_base)";
  if (!c.is_object() || !c.contains("type") || !c["type"].is_string())
    throw model_error(top.field("constraint") + "expected an object with a \"type\" " + known);
  const std::string type = c["type"].get<std::string>();
  const int n = t.dof();
  const auto needs_planar = [&] {
    if (!opt.planar_base)
      throw model_error(top.field("constraint") + "a '" + type + "' constraint needs a planar base (\"base\": {\"type\": \"planar\"})");
  };
  try {
    if (type == "differential_drive") {
      check_keys(c, {"type", "x", "y", "heading", "heading_sign", "forward_offset"}, {}, at.prefix + ", ", "the constraint");
      const bool named = c.contains("x") || c.contains("y") || c.contains("heading");
      if (!named) {
        needs_planar();
        if (c.contains("heading_sign") || c.contains("forward_offset"))
          throw model_error(at.prefix + ": heading_sign and forward_offset go with named x, y, heading joints");
        return differential_drive<double>(n, 0, 1, 2);
      }
      if (opt.planar_base)
        throw model_error(at.prefix + ": x, y, heading name the URDF's own base joints; with a planar base they are base_x, base_y, base_yaw (leave them out)");
      check_keys(c, {"type", "x", "y", "heading", "heading_sign", "forward_offset"}, {"x", "y", "heading"}, at.prefix + ", ",
                 "the constraint");
      const double sign = c.contains("heading_sign") ? number(c["heading_sign"], at, "heading_sign") : 1.0;
      const double offset = c.contains("forward_offset") ? number(c["forward_offset"], at, "forward_offset") : 0.0;
      return differential_drive<double>(n, named_joint(c, t, at, "x"), named_joint(c, t, at, "y"),
                                        named_joint(c, t, at, "heading"), offset, sign);
    }
    if (type == "wheels") {
      check_keys(c, {"type", "left", "right", "radius"}, {"left", "right", "radius"}, at.prefix + ", ", "the constraint");
      needs_planar();
      const double r = number(c["radius"], at, "radius");
      if (!(r > 0)) throw model_error(at.field("radius") + "the wheel radius must be positive, not " + format_number(r));
      const int l = named_joint(c, t, at, "left"), rt = named_joint(c, t, at, "right");
      if (l == rt) throw model_error(at.prefix + ": left and right name the same joint '" + t[l].joint_name + "'");
      const auto L = joint_on_root_link(t, l, at, "left", "a drive wheel");
      const auto R = joint_on_root_link(t, rt, at, "right", "a drive wheel");
      const double sl = axis_sign(L.axis, 1, at.field("left") + "joint '" + t[l].joint_name + "': ", "horizontal and lateral (±y)", opt);
      const double sr = axis_sign(R.axis, 1, at.field("right") + "joint '" + t[rt].joint_name + "': ", "horizontal and lateral (±y)", opt);
      if (std::abs(L.origin.x() - R.origin.x()) > 1e-6) {
        std::ostringstream os;
        os << at.prefix << ": the wheels are not on one axle: their centres are at x = " << L.origin.x() << " and "
           << R.origin.x() << " m in the root link's frame";
        throw model_error(os.str());
      }
      if (!(std::abs(L.origin.y() - R.origin.y()) > 1e-9))
        throw model_error(at.prefix + ": the two wheel centres have the same lateral position (zero track)");
      return rolling_wheels<double>(n, l, rt, r, L.origin.y(), R.origin.y(), 0.5 * (L.origin.x() + R.origin.x()), sl, sr);
    }
    if (type == "wheeled_base") {
      needs_planar();
      return read_wheeled_base(c, t, at, opt);
    }
    if (type == "bicycle") {
      check_keys(c, {"type", "steer", "wheelbase"}, {"steer", "wheelbase"}, at.prefix + ", ", "the constraint");
      needs_planar();
      const double L = number(c["wheelbase"], at, "wheelbase");
      if (!(L > 0)) throw model_error(at.field("wheelbase") + "must be positive, not " + format_number(L));
      const int s = named_joint(c, t, at, "steer");
      const auto J = joint_on_root_link(t, s, at, "steer", "the steering joint");
      const double sign = axis_sign(J.axis, 2, at.field("steer") + "joint '" + t[s].joint_name + "': ", "vertical (±z)", opt);
      if (std::abs(J.origin.x() - L) > 1e-3 || std::abs(J.origin.y()) > 1e-3) {
        std::ostringstream os;
        os << at.prefix << ": the steering joint '" << t[s].joint_name << "' is at (" << J.origin.x() << ", "
           << J.origin.y() << ") m in the root link's frame, not on the front axle at (" << L
           << ", 0); the model puts the front wheel at (wheelbase, 0)";
        opt.warning(os.str());
      }
      return bicycle<double>(n, s, L, sign);
    }
  } catch (const model_error& e) {
    const std::string what = e.what();
    if (what.rfind(at.prefix, 0) == 0 || what.rfind(top.prefix, 0) == 0) throw;
    throw model_error(at.prefix + ": " + what);
  }
  throw model_error(at.field("type") + "unknown constraint type '" + type + "' " + known);
}
}  // namespace detail

namespace detail {
/// The tree with the drives a robot file's "drives" gives by joint name (armature, friction;
/// or motor side, as in JSON models), over what the URDF's <dynamics> said.
template <class = void>  // compiled where used (config.hpp)
tree<double> with_drives(const tree<double>& t, const json& d, const place& top) {
  if (!d.is_object()) throw model_error(top.field("drives") + "expected an object {joint name: drive}, got " + describe(d));
  std::vector<body<double>> bodies = t.bodies();
  for (auto it = d.begin(); it != d.end(); ++it) {
    const place at{top.prefix + ", drives, joint '" + it.key() + "'"};
    int i = -1;
    for (int k = 0; k < t.dof(); ++k)
      if (t[k].joint_name == it.key()) i = k;
    if (i < 0) {
      std::string known;
      for (const auto& b : t) known += (known.empty() ? "" : ", ") + b.joint_name;
      throw model_error(at.prefix + ": no movable joint of that name (movable joints: " + known + ")");
    }
    if (!it.value().is_object()) throw model_error(at.prefix + ": expected an object, got " + describe(it.value()));
    check_keys(it.value(), {"armature", "friction", "motor"}, {}, at.prefix + ", ", "a drive");
    auto& b = bodies[std::size_t(i)];
    joint_friction f = b.friction_law();
    read_drive(it.value(), at, b.armature, f);
    b.set_friction_law(f);
  }
  try {
    return tree<double>(std::move(bodies), t.gravity(), t.name(), t.validation_policy(), t.root_name(), t.frames());
  } catch (const model_error& e) {
    throw model_error(top.field("drives") + e.what());
  }
}

/// The joints a constraint's rows involve: a nonzero column of A at either of two
/// configurations, or one that A, S or Ṡ depend on (`depends_on`).
template <class C>
std::vector<bool> constraint_joints(const C& c, int n) {
  std::vector<bool> used(std::size_t(n), false);
  for (int trial = 0; trial < 2; ++trial) {
    Eigen::VectorXd q(n);
    for (int j = 0; j < n; ++j) q(j) = 0.3 * std::sin(1.7 * j + 0.4 + 1.1 * trial);
    const Eigen::MatrixXd A = c.A(q);
    for (int j = 0; j < n; ++j)
      if (A.col(j).cwiseAbs().maxCoeff() > 0) used[std::size_t(j)] = true;
  }
  if constexpr (has_depends_on<C>)
    for (int j = 0; j < n; ++j)
      if (c.depends_on(j)) used[std::size_t(j)] = true;
  return used;
}

}  // namespace detail

template <class>
robot_model lock_robot(robot_model r, const std::vector<std::pair<std::string, double>>& locks,
                       const std::string& where) {
  if (locks.empty()) return r;
  lock_map m;
  try {
    m = lock_map_of(r.model, locks);
  } catch (const model_error& e) {
    throw model_error(where + e.what());
  }
  const auto joints = r.model.joint_names();
  if (r.constraint) {
    const std::vector<bool> used =
        std::visit([&](const auto& c) { return detail::constraint_joints(c, r.model.dof()); }, *r.constraint);
    const std::string type = r.constraint_source.is_object() && r.constraint_source.contains("type") &&
                                     r.constraint_source["type"].is_string()
                                 ? r.constraint_source["type"].get<std::string>()
                                 : std::holds_alternative<differential_drive<double>>(*r.constraint)
                                       ? std::string("differential_drive")
                                       : std::string("the robot's");
    for (const auto& [i, x] : m.locked)
      if (used[std::size_t(i)])
        throw model_error(where + "joint '" + joints[std::size_t(i)] + "' belongs to the constraint (" + type +
                          "): its rows involve it, so it cannot be locked");
  }
  r.model = lock_indices(r.model, m.locked);
  for (const auto& [i, x] : m.locked) r.locked.emplace_back(joints[std::size_t(i)], x);
  if (!r.constraint_source.is_null()) {
    urdf_options opt;
    opt.planar_base = r.planar_base;
    opt.warn = [](const std::string&) {};  // given when the full robot was read
    r.constraint = detail::read_robot_constraint(r.constraint_source, r.model, detail::place{"robot file '" + r.path + "', locked"}, opt);
  } else if (r.constraint) {
    // a JSON model's differential_drive (as_robot) names its joints by index: the kept
    // joints' indices in the smaller tree
    auto* dd = std::get_if<differential_drive<double>>(&*r.constraint);
    if (!dd) throw model_error(where + "the robot's constraint has no source to read again on the smaller tree");
    const auto index = [&](int j) { return int(std::find(m.kept.begin(), m.kept.end(), j) - m.kept.begin()); };
    r.constraint = differential_drive<double>(m.dof(), index(dd->x), index(dd->y), index(dd->heading),
                                              dd->forward_offset, dd->heading_sign);
  }
  return r;
}

template <class>
robot_model as_robot(const model<double>& m, const std::string& where) {
  robot_model r{.model = as_tree(m.chain), .constraint = std::nullopt, .name = m.chain.name(),
                .constraint_source = {}, .path = {}, .planar_base = false, .locked = {}};
  if (m.constraint) r.constraint = *m.constraint;
  return lock_robot(std::move(r), m.locked, where);
}

template <class>
robot_model parse_robot_file(const std::string& text, const std::string& path, urdf_options opt) {
  const std::string where = "robot file '" + path + "': ";
  const json j = parse_strict(text, where);
  if (!j.is_object()) throw model_error(where + "expected a JSON object, got " + detail::describe(j));
  detail::check_keys(j, {"name", "description", "urdf", "gravity", "base", "drives", "constraint", "locked"}, {"urdf"}, where,
                     "a robot file");
  const detail::place top{"robot file '" + path + "'"};
  if (!j["urdf"].is_string()) throw model_error(top.field("urdf") + "expected a path, got " + detail::describe(j["urdf"]));
  std::filesystem::path urdf_path = j["urdf"].get<std::string>();
  if (urdf_path.is_relative()) urdf_path = std::filesystem::path(path).parent_path() / urdf_path;
  if (j.contains("gravity")) opt.gravity = detail::vector3<double>(j["gravity"], top, "gravity");
  if (j.contains("base")) {
    const json& b = j["base"];
    if (!b.is_object() || !b.contains("type") || !b["type"].is_string())
      throw model_error(top.field("base") + "expected {\"type\": \"planar\"} or {\"type\": \"floating\"}");
    detail::check_keys(b, {"type"}, {"type"}, top.field("base"), "the base");
    if (b["type"] == "planar")
      opt.planar_base = true;
    else if (b["type"] == "floating")
      opt.floating_base = true;
    else
      throw model_error(top.field("base") + "unknown base type '" + b["type"].get<std::string>() +
                        "' (known: planar, floating)");
  }
  robot_model out{load_urdf(urdf_path.string(), opt), std::nullopt, ""};
  out.name = j.contains("name") && j["name"].is_string() ? j["name"].get<std::string>() : out.model.name();
  if (j.contains("drives")) out.model = detail::with_drives(out.model, j["drives"], top);
  if (j.contains("constraint") && out.model.floating())
    throw model_error(top.field("constraint") +
                      "constraints on a floating base are not supported yet (the robot floats freely: leave "
                      "\"constraint\" out)");
  if (j.contains("constraint")) out.constraint = detail::read_robot_constraint(j["constraint"], out.model, top, opt);
  if (j.contains("constraint")) out.constraint_source = j["constraint"];
  out.path = path;
  out.planar_base = opt.planar_base;
  if (j.contains("locked")) {
    const auto locks = detail::read_locked(j["locked"], top);
    out = lock_robot(std::move(out), locks, top.field("locked"));
  }
  return out;
}

template <class>
std::optional<robot_constraint> constraint_on(const robot_model& r, const tree<double>& t) {
  if (r.constraint_source.is_null()) return r.constraint;
  urdf_options opt;
  opt.planar_base = r.planar_base;
  opt.warn = [](const std::string&) {};
  return detail::read_robot_constraint(r.constraint_source, t, detail::place{"robot file '" + r.path + "'"}, opt);
}

template <class>
robot_model load_robot(const std::string& spec) {
  const auto presets = preset_names();
  std::string ext = std::filesystem::path(spec).extension().string();
  for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (ext == ".urdf") {
    tree<double> t = load_urdf(spec);
    std::string name = t.name();
    return robot_model{.model = std::move(t), .constraint = std::nullopt, .name = std::move(name),
                       .constraint_source = {}, .path = spec, .planar_base = false};
  }
  const bool preset = std::find(presets.begin(), presets.end(), spec) != presets.end();
  if (!preset) {
    std::ifstream in(spec);
    if (const auto j = json::parse(in, nullptr, false); j.is_object()) {
      if (j.contains("urdf")) return load_robot_file(spec);
      if (!j.contains("links")) {  // neither kind: say so, not the model parser's "unknown key"
        std::string keys;
        for (const auto& [key, value] : j.items()) keys += (keys.empty() ? "'" : ", '") + key + "'";
        throw model_error("robot '" + spec + "': a JSON object that is neither a robot file (it needs \"urdf\", "
                          "docs/model-format.md) nor a DH model file (it needs \"links\"); its keys: " +
                          (keys.empty() ? std::string("none") : keys));
      }
    }  // not JSON: the model loader names the error and its line
  }
  robot_model r = as_robot(load<double>(spec), "robot '" + spec + "', locked: ");
  r.path = spec;
  return r;
}
template <class>
robot_model load_robot_file(const std::string& path, urdf_options opt) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw model_error("robot file '" + path + "': cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_robot_file(ss.str(), path, std::move(opt));
}

#endif  // NHDYN_DEFINES(NHDYN_PART_IO)

}  // namespace nhdyn::io
