#pragma once
/// \file io/robot_file.hpp
/// Robot files: a JSON object that names a URDF and says how the robot moves on the floor
/// (docs/model-format.md, "Robot files"). Needs nhdyn::json and nhdyn::urdf.
///
///     {"name": "...", "urdf": "robot.urdf",              (the path relative to this file)
///      "gravity": [0, 0, -9.81],                          (optional, this default)
///      "base": {"type": "planar"},                        (optional; absent: fixed base)
///      "constraint": {"type": "differential_drive"}}      (optional, needs a planar base)
///
/// A planar base puts q = (base_x, base_y, base_yaw, the URDF's joints): the root link's pose
/// on the floor. `differential_drive`: the root link's origin cannot slip along the root
/// link's y axis; η = (v, ω, the URDF's joint rates), v the forward speed along the root
/// link's x axis, ω = ψ̇; k = 1 (`differential_drive(n, 0, 1, 2)`).
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include "../constraints/differential_drive.hpp"
#include "json.hpp"
#include "urdf.hpp"

namespace nhdyn::io {

/// A robot loaded from a robot file: its tree and, when the file gives one, its constraint.
struct robot_model {
  tree<double> model;
  std::optional<differential_drive<double>> constraint;
  std::string name;
};

/// The robot file's text; `path` locates the URDF (relative paths from its folder) and names
/// the file in messages.
inline robot_model parse_robot_file(const std::string& text, const std::string& path, urdf_options opt = {}) {
  const std::string where = "robot file '" + path + "': ";
  const json j = parse_strict(text, where);
  if (!j.is_object()) throw model_error(where + "expected a JSON object, got " + detail::describe(j));
  detail::check_keys(j, {"name", "description", "urdf", "gravity", "base", "constraint"}, {"urdf"}, where,
                     "a robot file");
  const detail::place top{"robot file '" + path + "'"};
  if (!j["urdf"].is_string()) throw model_error(top.field("urdf") + "expected a path, got " + detail::describe(j["urdf"]));
  std::filesystem::path urdf_path = j["urdf"].get<std::string>();
  if (urdf_path.is_relative()) urdf_path = std::filesystem::path(path).parent_path() / urdf_path;
  if (j.contains("gravity")) opt.gravity = detail::vector3<double>(j["gravity"], top, "gravity");
  if (j.contains("base")) {
    const json& b = j["base"];
    if (!b.is_object() || !b.contains("type") || !b["type"].is_string())
      throw model_error(top.field("base") + "expected {\"type\": \"planar\"}");
    detail::check_keys(b, {"type"}, {"type"}, top.field("base"), "the base");
    if (b["type"] != "planar")
      throw model_error(top.field("base") + "unknown base type '" + b["type"].get<std::string>() + "' (known: planar)");
    opt.planar_base = true;
  }
  robot_model out{load_urdf(urdf_path.string(), opt), std::nullopt, ""};
  out.name = j.contains("name") && j["name"].is_string() ? j["name"].get<std::string>() : out.model.name();
  if (j.contains("constraint")) {
    const json& c = j["constraint"];
    if (!c.is_object() || !c.contains("type") || !c["type"].is_string())
      throw model_error(top.field("constraint") + "expected {\"type\": \"differential_drive\"}");
    detail::check_keys(c, {"type"}, {"type"}, top.field("constraint"), "the constraint");
    const std::string type = c["type"].get<std::string>();
    if (type != "differential_drive")
      throw model_error(top.field("constraint") + "unknown constraint type '" + type + "' (known: differential_drive)");
    if (!opt.planar_base)
      throw model_error(top.field("constraint") + "a differential drive needs a planar base (\"base\": {\"type\": \"planar\"})");
    out.constraint = differential_drive<double>(out.model.dof(), 0, 1, 2);
  }
  return out;
}

/// The robot file at `path`.
inline robot_model load_robot_file(const std::string& path, urdf_options opt = {}) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw model_error("robot file '" + path + "': cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_robot_file(ss.str(), path, std::move(opt));
}

}  // namespace nhdyn::io
