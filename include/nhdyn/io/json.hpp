#pragma once
/// \file io/json.hpp
/// Robot model files (JSON) and the named presets: load, validate, save.
///
/// The format is documented in docs/model-format.md. In short:
///
///     {"name": "paper5", "description": "…",                      (description optional)
///      "gravity": [gx, gy, gz],
///      "links": [{"joint": "revolute" | "prismatic", "alpha", "a", "theta", "d", "mass",
///                 "com": [x, y, z], "inertia": [[Ixx,Ixy,Ixz],[Ixy,Iyy,Iyz],[Ixz,Iyz,Izz]],
///                 "armature", "friction": {"viscous", "coulomb"}         (optional, joint side)
///                 | "motor": {"inertia", "gear", "viscous", "coulomb"}}, …],  (or motor side)
///      "validation": {"triangle_inequality": true},                (optional)
///      "constraint": {"type": "differential_drive", "x": 0, "y": 1, "heading": 2,
///                     "forward_offset": 0, "heading_sign": -1},    (optional; 0-based joints)
///      "locked": {"joint5": 0.3, "joint[1-2]": 0}}                 (optional: joints held,
///                                                                    model::locked, as_robot)
///
/// Standard DH (Spong), com in link frame i, inertia about the centre of mass in frame i's
/// axes, radians and SI units. Every field of a link is required; unknown fields, duplicate
/// keys, wrong types or lengths and numbers that overflow are errors naming the file, the link
/// (1-based) and the field. Numbers are read as double and saved in their shortest
/// round-trip form (io/number.hpp), so save → load is exact. Needs nlohmann/json (Debian nlohmann-json3-dev).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "../constraints/constraint.hpp"
#include "../errors.hpp"
#include "../model/chain.hpp"
#include "../robots/presets.hpp"
#include "number.hpp"

namespace nhdyn::io {

using json = nlohmann::json;
using ordered_json = nlohmann::ordered_json;

/// A model as a file describes it: a run-time-sized chain, its constraint if any.
template <class S = double>
struct model {
  ::nhdyn::chain<S> chain;
  std::optional<differential_drive<S>> constraint;
  std::string description;
  /// The file's "locked" joints ({"joint2": 0.3, "joint[4-6]": 0}: as_tree's names, globs),
  /// in the file's order. `chain` is the full chain: a chain with joints held is no longer a
  /// DH chain but a tree, and `io::as_robot(m)` (robot_file.hpp) is that tree with the
  /// constraint on it, as the tool, scenes and Python load such a file.
  std::vector<std::pair<std::string, double>> locked{};
};

// ---------------------------------------------------------------------------------------
// Numbers and JSON text
// ---------------------------------------------------------------------------------------

namespace detail {
inline void dump_string(const std::string& s, std::string& out) {
  out += json(s).dump(-1, ' ', false, json::error_handler_t::replace);
}

template <class J>
bool is_flat(const J& j) {
  for (const auto& e : j)
    if (e.is_structured()) return false;
  return true;
}

template <class J>
void dump(const J& j, std::string& out, int indent, int level) {
  const auto newline = [&](int l) {
    if (indent >= 0) out += '\n' + std::string(static_cast<std::size_t>(indent * l), ' ');
  };
  switch (j.type()) {
    case nlohmann::json::value_t::object: {
      if (j.empty()) { out += "{}"; return; }
      out += '{';
      bool first = true;
      for (auto it = j.begin(); it != j.end(); ++it) {
        if (!first) out += indent >= 0 ? "," : ", ";
        first = false;
        newline(level + 1);
        dump_string(it.key(), out);
        out += ": ";
        dump(it.value(), out, indent, level + 1);
      }
      newline(level);
      out += '}';
      return;
    }
    case nlohmann::json::value_t::array: {
      // Arrays of numbers stay on one line (a vector, a matrix row).
      const bool inline_array = indent < 0 || is_flat(j);
      out += '[';
      bool first = true;
      for (const auto& e : j) {
        if (!first) out += inline_array ? ", " : ",";
        first = false;
        if (!inline_array) newline(level + 1);
        dump(e, out, inline_array ? -1 : indent, level + 1);
      }
      if (!inline_array && !j.empty()) newline(level);
      out += ']';
      return;
    }
    case nlohmann::json::value_t::number_float:
      out += format_number(j.template get<double>());
      return;
    case nlohmann::json::value_t::string:
      dump_string(j.template get<std::string>(), out);
      return;
    default:
      out += j.dump();
  }
}
}  // namespace detail

/// JSON text with every floating-point number printed by format_number (the shortest form
/// that reads back to the same double). indent < 0: one line ("{"a": [1, 2]}"); otherwise nested, arrays of scalars on
/// one line. Throws numerical_error if a number is NaN or Inf.
template <class J>
std::string dump(const J& j, int indent = -1) {
  std::string out;
  detail::dump(j, out, indent, 0);
  return out;
}

/// Parses JSON text strictly: syntax errors give their line and column, numbers that
/// overflow double and duplicate keys in an object are errors too (nlohmann would keep
/// the last of a duplicate silently). Throws E (an nhdyn::error) with `where` in front.
template <class E = model_error>
json parse_strict(std::string_view text, const std::string& where) {
  std::vector<std::vector<std::string>> keys;  // keys of the objects open at each depth
  std::string duplicate;
  const json::parser_callback_t cb = [&](int, json::parse_event_t ev, json& parsed) {
    if (ev == json::parse_event_t::object_start) keys.emplace_back();
    else if (ev == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    else if (ev == json::parse_event_t::key && !keys.empty()) {
      const auto k = parsed.get<std::string>();
      auto& seen = keys.back();
      if (duplicate.empty() && std::find(seen.begin(), seen.end(), k) != seen.end()) duplicate = k;
      seen.push_back(k);
    }
    return true;
  };
  json j;
  try {
    j = json::parse(text.begin(), text.end(), cb);
  } catch (const json::exception& e) {
    std::string msg = e.what();
    if (const auto p = msg.find("] "); msg.rfind("[json.exception.", 0) == 0 && p != std::string::npos)
      msg = msg.substr(p + 2);
    if (msg.rfind("number overflow", 0) == 0) msg += " (the number is too large for a double)";
    throw E(where + "invalid JSON: " + msg);
  }
  if (!duplicate.empty()) throw E(where + "duplicate key '" + duplicate + "'");
  return j;
}

// ---------------------------------------------------------------------------------------
// Reading fields with errors naming where
// ---------------------------------------------------------------------------------------

namespace detail {
/// "where" prefix: "file 'F', link 3, field 'mass': " and friends.
struct place {
  std::string prefix;  // e.g. "file 'x.json', link 3"
  std::string field(std::string_view f) const {
    return prefix + (prefix.empty() ? "" : ", ") + "field '" + std::string(f) + "': ";
  }
};

inline std::string describe(const json& j) {
  if (j.is_number()) return "number";
  if (j.is_boolean()) return "boolean";
  return j.type_name();
}

/// A "locked" object: {"NAME or GLOB": position, ...}.
inline std::vector<std::pair<std::string, double>> read_locked(const json& l, const place& top) {
  if (!l.is_object())
    throw model_error(top.field("locked") + "expected an object {\"joint name or glob\": position, ...}, got " + describe(l));
  std::vector<std::pair<std::string, double>> out;
  for (auto it = l.begin(); it != l.end(); ++it) {
    if (!it.value().is_number() || !std::isfinite(it.value().get<double>()))
      throw model_error(top.field("locked") + "'" + it.key() + "': expected a finite position [rad or m], got " +
                        (it.value().is_number() ? std::string("a non-finite number") : describe(it.value())));
    out.emplace_back(it.key(), it.value().get<double>());
  }
  return out;
}

/// Throws if obj has keys outside `allowed` or lacks one of `required`.
inline void check_keys(const json& obj, std::initializer_list<std::string_view> allowed,
                       std::initializer_list<std::string_view> required, const std::string& where,
                       std::string_view what) {
  std::string unknown;
  for (auto it = obj.begin(); it != obj.end(); ++it)
    if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end())
      unknown += (unknown.empty() ? "'" : ", '") + it.key() + "'";
  if (!unknown.empty()) {
    std::string known;
    for (auto k : allowed) known += (known.empty() ? "" : ", ") + std::string(k);
    throw model_error(where + "unknown field(s) " + unknown + " in " + std::string(what) +
                      " (known: " + known + ")");
  }
  for (auto k : required)
    if (!obj.contains(k))
      throw model_error(where + "field '" + std::string(k) + "': missing in " + std::string(what));
}

inline double number(const json& j, const place& at, std::string_view f, std::string_view part = "") {
  if (!j.is_number())
    throw model_error(at.field(f) + std::string(part) + "expected a number, got " + describe(j));
  const double x = j.get<double>();
  if (!std::isfinite(x)) throw model_error(at.field(f) + std::string(part) + "is not finite");
  return x;
}

inline std::string index_part(std::size_t i) { return "entry " + std::to_string(i) + ": "; }

template <class S>
vec3<S> vector3(const json& j, const place& at, std::string_view f) {
  if (!j.is_array() || j.size() != 3)
    throw model_error(at.field(f) + "expected an array of 3 numbers, got " +
                      (j.is_array() ? "an array of " + std::to_string(j.size()) : describe(j)));
  vec3<S> v;
  for (std::size_t i = 0; i < 3; ++i) v(static_cast<Eigen::Index>(i)) = S(number(j[i], at, f, index_part(i)));
  return v;
}

template <class S>
mat3<S> matrix3(const json& j, const place& at, std::string_view f) {
  const auto bad = [&](const std::string& got) {
    throw model_error(at.field(f) + "expected a 3×3 array of arrays [[Ixx,Ixy,Ixz],[Ixy,Iyy,Iyz],[Ixz,Iyz,Izz]], got " + got);
  };
  if (!j.is_array()) bad(describe(j));
  if (j.size() != 3) bad(std::to_string(j.size()) + " rows");
  mat3<S> M;
  for (std::size_t r = 0; r < 3; ++r) {
    if (!j[r].is_array()) bad("row " + std::to_string(r + 1) + " a " + describe(j[r]));
    if (j[r].size() != 3) bad("row " + std::to_string(r + 1) + " with " + std::to_string(j[r].size()) + " entries");
    for (std::size_t c = 0; c < 3; ++c)
      M(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) =
          S(number(j[r][c], at, f, "row " + std::to_string(r + 1) + ", column " + std::to_string(c + 1) + ": "));
  }
  return M;
}

inline std::string string_field(const json& j, const place& at, std::string_view f) {
  if (!j.is_string()) throw model_error(at.field(f) + "expected a string, got " + describe(j));
  return j.get<std::string>();
}

inline int joint_index(const json& j, const place& at, std::string_view f, int n) {
  if (!j.is_number_integer())
    throw model_error(at.field(f) + "expected an integer joint index (0-based), got " +
                      (j.is_number() ? "a non-integer number" : describe(j)));
  const auto i = j.get<long long>();
  if (i < 0 || i >= n)
    throw model_error(at.field(f) + "joint index " + std::to_string(i) + " outside 0…" +
                      std::to_string(n - 1) + " (indices are 0-based)");
  return static_cast<int>(i);
}

/// A Coulomb value: one number c (±c) or [c⁺, c⁻].
inline std::pair<double, double> coulomb_pair(const json& j, const place& at, std::string_view f) {
  if (j.is_array()) {
    if (j.size() != 2) throw model_error(at.field(f) + "expected a number or [positive, negative], got " + describe(j));
    return {number(j[0], at, f, "[0]: "), number(j[1], at, f, "[1]: ")};
  }
  const double c = number(j, at, f);
  return {c, -c};
}

/// A joint's drive, joint side ("armature", "friction": {"viscous", "coulomb"}) or motor side
/// ("motor": {"inertia", "gear", "viscous", "coulomb"}, reflected: G²J_m, G²B, |G|Tc).
template <class S>
void read_drive(const json& j, const place& at, S& armature, joint_friction& friction) {
  if (j.contains("motor") && (j.contains("armature") || j.contains("friction")))
    throw model_error(at.field("motor") + "give the drive either motor side (\"motor\") or joint side "
                                          "(\"armature\", \"friction\"), not both");
  if (j.contains("armature")) armature = S(number(j["armature"], at, "armature"));
  if (j.contains("friction")) {
    const place f{at.prefix + ", friction"};
    const json& o = j["friction"];
    if (!o.is_object()) throw model_error(at.field("friction") + "expected an object, got " + describe(o));
    check_keys(o, {"viscous", "coulomb"}, {}, f.prefix + ", ", "friction");
    if (o.contains("viscous")) friction.viscous = number(o["viscous"], f, "viscous");
    if (o.contains("coulomb")) std::tie(friction.coulomb_pos, friction.coulomb_neg) = coulomb_pair(o["coulomb"], f, "coulomb");
  }
  if (j.contains("motor")) {
    const place m{at.prefix + ", motor"};
    const json& o = j["motor"];
    if (!o.is_object()) throw model_error(at.field("motor") + "expected an object, got " + describe(o));
    check_keys(o, {"inertia", "gear", "viscous", "coulomb"}, {"gear"}, m.prefix + ", ", "motor");
    const double G = number(o["gear"], m, "gear"), aG = std::abs(G);
    if (G == 0) throw model_error(m.field("gear") + "a gear ratio of 0 connects no motor");
    if (o.contains("inertia")) armature = S(G * G * number(o["inertia"], m, "inertia"));
    if (o.contains("viscous")) friction.viscous = G * G * number(o["viscous"], m, "viscous");
    if (o.contains("coulomb")) {
      const auto [p, n] = coulomb_pair(o["coulomb"], m, "coulomb");
      friction.coulomb_pos = aG * p;
      friction.coulomb_neg = aG * n;
    }
  }
}

template <class S>
link<S> read_link(const json& j, const place& at) {
  if (!j.is_object()) throw model_error(at.prefix + ": expected an object, got " + describe(j));
  check_keys(j, {"joint", "alpha", "a", "theta", "d", "mass", "com", "inertia", "armature", "friction", "motor"},
             {"joint", "alpha", "a", "theta", "d", "mass", "com", "inertia"}, at.prefix + ", ", "the link");
  link<S> L;
  const auto joint = string_field(j["joint"], at, "joint");
  if (joint == "revolute") L.joint = joint_type::revolute;
  else if (joint == "prismatic") L.joint = joint_type::prismatic;
  else throw model_error(at.field("joint") + "unknown joint type '" + joint + "' (known: revolute, prismatic)");
  L.alpha = S(number(j["alpha"], at, "alpha"));
  L.a = S(number(j["a"], at, "a"));
  L.theta = S(number(j["theta"], at, "theta"));
  L.d = S(number(j["d"], at, "d"));
  L.mass = S(number(j["mass"], at, "mass"));
  L.com = vector3<S>(j["com"], at, "com");
  L.inertia = matrix3<S>(j["inertia"], at, "inertia");
  read_drive(j, at, L.armature, L.friction);
  return L;
}

template <class S>
differential_drive<S> read_constraint(const json& j, const place& at, int n) {
  const place c{at.prefix + (at.prefix.empty() ? "" : ", ") + "constraint"};
  if (!j.is_object()) throw model_error(at.field("constraint") + "expected an object, got " + describe(j));
  if (!j.contains("type")) throw model_error(c.field("type") + "missing (known types: differential_drive)");
  const auto type = string_field(j["type"], c, "type");
  if (type != "differential_drive")
    throw model_error(c.field("type") + "unknown constraint type '" + type + "' (known: differential_drive)");
  check_keys(j, {"type", "x", "y", "heading", "forward_offset", "heading_sign"}, {"x", "y", "heading"},
             c.prefix + ", ", "the constraint");
  const int x = joint_index(j["x"], c, "x", n), y = joint_index(j["y"], c, "y", n),
            h = joint_index(j["heading"], c, "heading", n);
  const double offset = j.contains("forward_offset") ? number(j["forward_offset"], c, "forward_offset") : 0.0;
  const double sign = j.contains("heading_sign") ? number(j["heading_sign"], c, "heading_sign") : 1.0;
  if (sign != 1.0 && sign != -1.0)
    throw model_error(c.field("heading_sign") + "must be 1 or -1, not " + format_number(sign));
  try {
    return differential_drive<S>(n, x, y, h, S(offset), S(sign));
  } catch (const model_error& e) {
    throw model_error(c.prefix + ": " + e.what());
  }
}
}  // namespace detail

/// A model from parsed JSON. `source` names where it came from in error messages
/// (e.g. "file 'robot.json'"); may be empty.
template <class S = double>
model<S> model_from_json(const json& j, const std::string& source = "") {
  const std::string pre = source.empty() ? "" : source + ", ";
  const detail::place top{source};
  if (!j.is_object()) throw model_error(pre + "expected a JSON object at the top level, got " + detail::describe(j));
  detail::check_keys(j, {"name", "description", "gravity", "links", "validation", "constraint", "locked"},
                     {"name", "gravity", "links"}, pre, "the model");
  const auto name = detail::string_field(j["name"], top, "name");
  std::string description;
  if (j.contains("description")) description = detail::string_field(j["description"], top, "description");
  const vec3<S> g = detail::vector3<S>(j["gravity"], top, "gravity");
  validation v{};
  if (j.contains("validation")) {
    const auto& jv = j["validation"];
    if (!jv.is_object()) throw model_error(top.field("validation") + "expected an object, got " + detail::describe(jv));
    detail::check_keys(jv, {"triangle_inequality"}, {}, pre + "validation, ", "validation");
    if (jv.contains("triangle_inequality")) {
      if (!jv["triangle_inequality"].is_boolean())
        throw model_error(pre + "validation, field 'triangle_inequality': expected true or false, got " +
                          detail::describe(jv["triangle_inequality"]));
      v.triangle_inequality = jv["triangle_inequality"].template get<bool>();
    }
  }
  const auto& jl = j["links"];
  if (!jl.is_array()) throw model_error(top.field("links") + "expected an array of links, got " + detail::describe(jl));
  if (jl.empty()) throw model_error(top.field("links") + "a chain needs at least one link");
  std::vector<link<S>> links;
  for (std::size_t i = 0; i < jl.size(); ++i)
    links.push_back(detail::read_link<S>(jl[i], {pre + "link " + std::to_string(i + 1)}));
  model<S> m{[&] {
               try {
                 return ::nhdyn::chain<S>(std::move(links), g, name, v);
               } catch (const model_error& e) {
                 throw model_error(pre + e.what());
               }
             }(),
             std::nullopt, description, {}};
  if (j.contains("constraint"))
    m.constraint = detail::read_constraint<S>(j["constraint"], top, m.chain.dof());
  if (j.contains("locked")) m.locked = detail::read_locked(j["locked"], top);
  return m;
}

/// A model from JSON text.
template <class S = double>
model<S> parse_model(std::string_view text, const std::string& source = "") {
  return model_from_json<S>(parse_strict<model_error>(text, source.empty() ? "" : source + ": "), source);
}

/// A model from a file; errors start with "file 'PATH'".
template <class S = double>
model<S> load_model(const std::filesystem::path& path) {
  const std::string source = "file '" + path.string() + "'";
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw model_error(source + ": is a directory, not a model file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw model_error(source + ": cannot be opened (" + (std::filesystem::exists(path, ec) ? "permission denied?" : "no such file") + ")");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw model_error(source + ": read error");
  return parse_model<S>(text.str(), source);
}

/// The names of the presets `preset` knows.
inline std::vector<std::string> preset_names() { return {"paper5", "puma560", "puma560_motors"}; }

/// A preset by name ("paper5" with its constraint, "puma560"); throws model_error otherwise.
template <class S = double>
model<S> preset(std::string_view name) {
  if (name == "paper5") {
    const auto r = presets::paper5<S>();
    const auto& c = r.constraint;
    return {r.chain.dynamic_size(),
            differential_drive<S>(c.n, c.x, c.y, c.heading, c.forward_offset, c.heading_sign),
            "The 5-DOF nonholonomic mobile manipulator of Salazar-Silva et al. (Tables I-II): a "
            "differential-drive platform (q1, q2 base position, q3 heading) carrying a planar 2-link "
            "arm (q4, q5); box inertias from the box formulas; eta = (v, omega, qd4, qd5)",
            {}};
  }
  if (name == "puma560")
    return {presets::puma560<S>().dynamic_size(), std::nullopt,
            "Unimation Puma 560, standard DH, rigid-body parameters of P. Corke's Robotics Toolbox "
            "mdl_puma560.m (parameters of 8/95: Corke & Armstrong-Helouvry, ICRA 1994); no motor inertia, gearing or friction; "
            "links 1 and 3 violate the triangle inequality as published",
            {}};
  if (name == "puma560_motors")
    return {presets::puma560_motors<S>().dynamic_size(), std::nullopt,
            "puma560 with its drives from the same file: armature G^2 Jm, viscous friction G^2 B and "
            "Coulomb friction |G| Tc per joint (joint side); rne adds the armature, friction is a stage",
            {}};
  std::string known;
  for (const auto& n : preset_names()) known += (known.empty() ? "" : ", ") + n;
  throw model_error("unknown preset '" + std::string(name) + "' (known: " + known + ")");
}

/// A preset name or a model file path: a preset if `spec` is one of preset_names(),
/// otherwise a file.
template <class S = double>
model<S> load(std::string_view spec) {
  std::string known;
  for (const auto& n : preset_names()) {
    if (spec == n) return preset<S>(spec);
    known += (known.empty() ? "" : ", ") + n;
  }
  const std::filesystem::path path{std::string(spec)};
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw model_error("model '" + std::string(spec) + "': no such file, and not a preset (presets: " + known + ")");
  return load_model<S>(path);
}

// ---------------------------------------------------------------------------------------
// Saving
// ---------------------------------------------------------------------------------------

/// The JSON of a chain and its optional constraint (numbers as double).
template <class S, int N>
ordered_json to_json(const chain<S, N>& ch, const differential_drive<S, N>* c = nullptr,
                     const std::string& description = "") {
  const auto d = [](const S& x) { return value_of(x); };
  ordered_json j;
  j["name"] = ch.name();
  if (!description.empty()) j["description"] = description;
  j["gravity"] = {d(ch.gravity()(0)), d(ch.gravity()(1)), d(ch.gravity()(2))};
  if (!ch.validation_policy().triangle_inequality) j["validation"] = {{"triangle_inequality", false}};
  if (c)
    j["constraint"] = {{"type", "differential_drive"}, {"x", c->x}, {"y", c->y}, {"heading", c->heading},
                       {"forward_offset", d(c->forward_offset)}, {"heading_sign", d(c->heading_sign)}};
  ordered_json links = ordered_json::array();
  for (const auto& L : ch) {
    ordered_json I = ordered_json::array();
    for (int r = 0; r < 3; ++r) I.push_back({d(L.inertia(r, 0)), d(L.inertia(r, 1)), d(L.inertia(r, 2))});
    ordered_json l = {{"joint", to_string(L.joint)}, {"alpha", d(L.alpha)}, {"a", d(L.a)},
                      {"theta", d(L.theta)}, {"d", d(L.d)}, {"mass", d(L.mass)},
                      {"com", {d(L.com(0)), d(L.com(1)), d(L.com(2))}}, {"inertia", I}};
    if (d(L.armature) != 0) l["armature"] = d(L.armature);
    if (L.friction != joint_friction{}) {
      const auto& f = L.friction;
      l["friction"] = {{"viscous", f.viscous}};
      if (f.coulomb_neg == -f.coulomb_pos)
        l["friction"]["coulomb"] = f.coulomb_pos;
      else
        l["friction"]["coulomb"] = {f.coulomb_pos, f.coulomb_neg};
    }
    links.push_back(l);
  }
  j["links"] = links;
  return j;
}

template <class S>
ordered_json to_json(const model<S>& m) {
  ordered_json j = to_json(m.chain, m.constraint ? &*m.constraint : nullptr, m.description);
  if (!m.locked.empty()) {
    ordered_json l = ordered_json::object();
    for (const auto& [name, x] : m.locked) l[name] = x;
    j["locked"] = l;
  }
  return j;
}

/// The model file's text (indented, numbers in their shortest round-trip form).
template <class S>
std::string to_string(const model<S>& m) {
  return dump(to_json(m), 2) + "\n";
}

/// Writes the model to a file; throws model_error if it cannot.
template <class S>
void save_model(const model<S>& m, const std::filesystem::path& path) {
  const auto text = to_string(m);
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw model_error("file '" + path.string() + "': cannot be written");
}

}  // namespace nhdyn::io
