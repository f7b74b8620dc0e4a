/// \file view.cpp
/// `nhdyn view`: one self-contained HTML page of a robot and its runs — the page of viewer/
/// (three.js and urdf-loader, bundled into share/nhdyn/viewer/template.html by the build) with
/// the robot's URDF, its meshes and the runs' CSVs as data (viewer/README.md: the schema).
#ifdef NHDYN_TOOL_URDF
#include <tinyxml2.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <Eigen/Geometry>
#include <nhdyn/io/json.hpp>
#include <nhdyn/model/tree.hpp>
#include <set>
#include <sstream>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
constexpr std::string_view usage = R"(nhdyn view --model MODEL [--lock L] [--q Q1,Q2,...] [--out PAGE.html] [--package-path DIR]...
nhdyn view RUN_DIR [--model MODEL [--lock L]] [--out PAGE.html] [--package-path DIR]... [--max-runs N]
  Writes one self-contained HTML page (no server, nothing fetched when it is opened: the
  JavaScript, the URDF, its meshes and the runs are inside it) and prints its path. The page
  shows the robot from its URDF, the floor, the base's trace, the task path and its reference,
  a time slider with play/pause and speed, q and eta at the cursor, plots of the tracking
  error and tau with a cursor, a study's runs listed or overlaid; orbit, pan, zoom, follow
  the base (docs/tool.md).
  MODEL: a URDF file, a robot file, paper5 (its shipped robot file), or a DH model (a preset
  or a JSON model), drawn as rods between its frames and a drum at each joint.
  --model MODEL alone: one pose, q from --q (comma-separated, `nhdyn model` order; default
    zeros). Default page: MODEL's name .html in the current folder.
  --lock 'NAME=POS,...': the joints held, as the other subcommands take it (q then has the
    other joints).
  RUN_DIR: an `nhdyn simulate` output folder: every <run>.csv in it (summary.json's order),
    the robot (and its scene's locked joints) from summary.json, or --model and --lock.
    Default page: RUN_DIR/view.html.
  --package-path DIR: where package://PKG/... meshes are (DIR/PKG/... or, when DIR is named
    PKG, DIR/...); repeatable. Relative mesh paths are read from the URDF's folder. A mesh
    that does not resolve is drawn as a stand-in box, with a notice on the page and here.
  --max-runs N: at most N runs of a study on the page (default 40).
)";

/// The robot of a page: its URDF (a file, or the text of one) and what the page needs beside it.
struct page_robot {
  std::string name;
  std::filesystem::path urdf;
  std::string urdf_text;  ///< when not empty, the URDF (a DH model's rods, stick_urdf), not the file
  std::vector<std::string> joints;  ///< q's names, nhdyn's order
  bool planar = false;              ///< q starts with base_x, base_y, base_yaw
  std::vector<std::string> base_joints;
  std::vector<std::pair<std::string, double>> locked;
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
};

std::string num(double x) { return nhdyn::io::format_number(x); }
std::string xyz(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

/// URDF's roll, pitch, yaw of R = Rz(yaw)·Ry(pitch)·Rx(roll).
Eigen::Vector3d rpy(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  if (std::abs(std::cos(pitch)) > 1e-9) return {std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0))};
  return {0.0, pitch, std::atan2(-R(0, 1), R(1, 1))};  // gimbal lock: roll folded into yaw
}

/// A URDF <visual> cylinder of radius r from a to b (its axis, z, turned onto b − a).
std::string rod(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, const char* material) {
  const Eigen::Vector3d d = b - a;
  const double length = d.norm();
  if (!(length > 1e-9)) return "";
  const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), d / length).toRotationMatrix();
  return "    <visual><origin xyz=\"" + xyz((a + b) / 2) + "\" rpy=\"" + xyz(rpy(R)) + "\"/><geometry><cylinder radius=\"" +
         num(r) + "\" length=\"" + num(length) + "\"/></geometry><material name=\"" + material + "\"/></visual>\n";
}

/// A URDF of the tree t drawn as its frames joined: a rod from each body's frame to each of
/// its children's joint frames and from the joint frame to the body frame, a drum along each
/// joint's axis (as the Robotics Toolbox draws a DH robot). Body NAME becomes two links,
/// NAME_joint_frame (the moved joint frame) and NAME (the body frame, behind a fixed joint
/// X_JB), so that each body's pose on the page is nhdyn's body frame. Sizes follow the
/// robot's longest rod.
std::string stick_urdf(const nhdyn::tree<double>& t) {
  const auto& B = t.bodies();
  double longest = 0;
  for (const auto& b : B) longest = std::max({longest, b.p_PJ.norm(), b.p_JB.norm()});
  const double s = std::max(longest, 0.05), r = 0.06 * s;
  std::vector<std::string> children(B.size() + 1);  // the rods of each body (0: the root) to its children
  for (const auto& b : B) children[std::size_t(b.parent + 1)] += rod(Eigen::Vector3d::Zero(), b.p_PJ, r, "rod");
  std::string name = t.name();  // a JSON model's free text: nothing that would end the attribute
  for (auto& ch : name)
    if (ch == '"' || ch == '<' || ch == '>' || ch == '&' || ch == '\'') ch = '_';
  std::string u = "<?xml version=\"1.0\"?>\n<robot name=\"" + name + "\">\n" +
                  "  <material name=\"rod\"><color rgba=\"0.62 0.66 0.72 1\"/></material>\n" +
                  "  <material name=\"joint\"><color rgba=\"0.93 0.55 0.15 1\"/></material>\n";
  u += "  <link name=\"" + t.root_name() + "\">\n" + children[0] + "  </link>\n";
  for (std::size_t i = 0; i < B.size(); ++i) {
    const auto& b = B[i];
    const std::string parent = b.parent < 0 ? t.root_name() : B[std::size_t(b.parent)].name, jf = b.name + "_joint_frame";
    const bool revolute = b.joint == nhdyn::joint_type::revolute;
    u += "  <joint name=\"" + b.joint_name + "\" type=\"" + (revolute ? "continuous" : "prismatic") + "\">\n    <parent link=\"" +
         parent + "\"/><child link=\"" + jf + "\"/>\n    <origin xyz=\"" + xyz(b.p_PJ) + "\" rpy=\"" + xyz(rpy(b.R_PJ)) +
         "\"/><axis xyz=\"" + xyz(b.axis) + "\"/>\n" +
         (revolute ? "" : "    <limit lower=\"-1e9\" upper=\"1e9\" effort=\"1e9\" velocity=\"1e9\"/>\n") + "  </joint>\n";
    const Eigen::Vector3d half = b.axis * (revolute ? 0.15 : 0.3) * s;
    u += "  <link name=\"" + jf + "\">\n" + rod(-half, half, (revolute ? 2.0 : 1.4) * r, "joint") +
         rod(Eigen::Vector3d::Zero(), b.p_JB, r, "rod") + "  </link>\n";
    u += "  <joint name=\"" + b.name + "_fixed\" type=\"fixed\">\n    <parent link=\"" + jf + "\"/><child link=\"" + b.name +
         "\"/>\n    <origin xyz=\"" + xyz(b.p_JB) + "\" rpy=\"" + xyz(rpy(b.R_JB)) + "\"/>\n  </joint>\n";
    u += "  <link name=\"" + b.name + "\">\n" + children[i + 1] + "  </link>\n";
  }
  return u + "</robot>\n";
}

page_robot robot_of(const std::string& spec, const std::vector<std::pair<std::string, double>>& locks = {}) {
  page_robot r;
  if (spec == "paper5") return robot_of((data_dir() / "robots" / "paper5.json").string(), locks);  // the preset's robot file
  const any_model a = load_any_model(spec, false, locks);
  if (!is_urdf(spec) && !is_robot_file(spec)) {  // a DH model: its full chain's frames joined (the page holds locked joints)
    const auto m = load_model(spec);
    const auto t = nhdyn::as_tree(m.chain);
    r.name = a.name(), r.locked = a.locked, r.urdf_text = stick_urdf(t);
    r.joints = a.tree ? a.tree->joint_names() : t.joint_names();
    if (t.gravity().norm() > 0) r.up = -t.gravity().normalized();
    if (m.constraint) {  // the base's trace from its x, y and heading joints
      const auto names = t.joint_names();
      r.base_joints = {names[std::size_t(m.constraint->x)], names[std::size_t(m.constraint->y)],
                       names[std::size_t(m.constraint->heading)]};
    }
    return r;
  }
  refuse_floating(*a.tree, "view");
  r.name = a.name(), r.joints = a.tree->joint_names(), r.locked = a.locked;
  if (a.tree->gravity().norm() > 0) r.up = -a.tree->gravity().normalized();
  if (is_urdf(spec)) {
    r.urdf = spec;
    return r;
  }
  std::ifstream in(spec);
  const json j = json::parse(in);  // a robot file (load_any_model read it already)
  r.urdf = std::filesystem::path(spec).parent_path() / j.at("urdf").get<std::string>();
  r.planar = j.contains("base") && j["base"].is_object() && j["base"].value("type", "") == "planar";
  if (r.planar) r.base_joints = {"base_x", "base_y", "base_yaw"};
  if (const auto c = j.value("constraint", json::object()); !r.planar && c.is_object() && c.contains("x") && c.contains("y") &&
                                                           c.contains("heading"))
    r.base_joints = {c["x"].get<std::string>(), c["y"].get<std::string>(), c["heading"].get<std::string>()};  // its own base joints
  return r;
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) throw nhdyn::input_error("nhdyn view: cannot read '" + p.string() + "'");
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string base64(const std::string& in) {
  static constexpr char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
    out += {digits[v >> 18], digits[v >> 12 & 63], digits[v >> 6 & 63], digits[v & 63]};
  }
  if (i + 1 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16;
    out += {digits[v >> 18], digits[v >> 12 & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
    out += {digits[v >> 18], digits[v >> 12 & 63], digits[v >> 6 & 63], '='};
  }
  return out;
}

/// The file a URDF mesh name resolves to, or none (see --package-path in the usage).
std::optional<std::filesystem::path> resolve_mesh(const std::string& name, const std::filesystem::path& urdf_dir,
                                                  const std::vector<std::string>& package_paths) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto file = [&](const fs::path& p) { return fs::is_regular_file(p, ec); };
  const std::string pkg_prefix = "package://", file_prefix = "file://";
  if (name.rfind(pkg_prefix, 0) == 0) {
    const std::string rest = name.substr(pkg_prefix.size());
    const auto slash = rest.find('/');
    const std::string pkg = rest.substr(0, slash), rel = slash == std::string::npos ? "" : rest.substr(slash + 1);
    for (const auto& d : package_paths) {
      if (file(fs::path(d) / pkg / rel)) return fs::path(d) / pkg / rel;
      if (fs::path(d).lexically_normal().filename() == pkg && file(fs::path(d) / rel)) return fs::path(d) / rel;
    }
    return std::nullopt;
  }
  fs::path p = name.rfind(file_prefix, 0) == 0 ? fs::path(name.substr(file_prefix.size())) : fs::path(name);
  if (p.is_relative()) p = urdf_dir / p;
  if (file(p)) return p;
  return std::nullopt;
}

/// The meshes the URDF's visuals name, embedded (name → base64), and those that do not resolve.
std::pair<ordered_json, std::vector<std::string>> embed_meshes(const std::string& urdf_text, const std::filesystem::path& urdf,
                                                               const std::vector<std::string>& package_paths) {
#ifndef NHDYN_TOOL_URDF
  (void)urdf_text, (void)package_paths;
  throw nhdyn::model_error("nhdyn view: '" + urdf.string() + "': this nhdyn was built without URDF support (urdfdom, tinyxml2)");
#else
  tinyxml2::XMLDocument doc;
  if (doc.Parse(urdf_text.c_str()) != tinyxml2::XML_SUCCESS)
    throw nhdyn::model_error("nhdyn view: '" + urdf.string() + "' is not XML (line " + std::to_string(doc.ErrorLineNum()) +
                             "): " + doc.ErrorStr());
  ordered_json meshes = ordered_json::object();
  std::vector<std::string> missing;
  std::set<std::string> seen;
  const auto* robot = doc.FirstChildElement("robot");
  for (auto* link = robot ? robot->FirstChildElement("link") : nullptr; link; link = link->NextSiblingElement("link"))
    for (auto* visual = link->FirstChildElement("visual"); visual; visual = visual->NextSiblingElement("visual")) {
      const auto* geometry = visual->FirstChildElement("geometry");
      const auto* mesh = geometry ? geometry->FirstChildElement("mesh") : nullptr;
      const char* name = mesh ? mesh->Attribute("filename") : nullptr;
      if (!name || !seen.insert(name).second) continue;
      if (const auto p = resolve_mesh(name, urdf.parent_path(), package_paths))
        meshes[name] = base64(read_file(*p));
      else
        missing.push_back(name);
    }
  return {meshes, missing};
#endif
}

/// x rounded to `decimals` decimal places (plots need no more; the page stays small).
double rounded(double x, int decimals) {
  if (!std::isfinite(x)) return x;
  const double s = std::pow(10.0, decimals);
  const double r = std::round(x * s) / s;
  return r == 0 ? 0.0 : r;
}

/// One CSV of `nhdyn simulate`: its columns by name.
struct csv_table {
  std::vector<std::string> header;
  std::vector<std::vector<double>> cols;
  int index(const std::string& name) const {
    for (std::size_t j = 0; j < header.size(); ++j)
      if (header[j] == name) return int(j);
    return -1;
  }
};

csv_table read_csv(const std::filesystem::path& p) {
  std::ifstream f(p);
  if (!f) throw nhdyn::input_error("nhdyn view: cannot read '" + p.string() + "'");
  csv_table t;
  std::string line;
  if (!std::getline(f, line)) throw nhdyn::input_error("nhdyn view: '" + p.string() + "' is empty");
  std::stringstream hs(line);
  for (std::string h; std::getline(hs, h, ',');) t.header.push_back(h);
  t.cols.assign(t.header.size(), {});
  int row = 1;
  while (std::getline(f, line)) {
    ++row;
    if (line.empty()) continue;
    std::stringstream ls(line);
    std::size_t j = 0;
    for (std::string cell; std::getline(ls, cell, ','); ++j) {
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (j >= t.header.size() || end == cell.c_str())
        throw nhdyn::input_error("nhdyn view: '" + p.string() + "', line " + std::to_string(row) + ": not a row of numbers of the header's columns");
      t.cols[j].push_back(v);
    }
    if (j != t.header.size())
      throw nhdyn::input_error("nhdyn view: '" + p.string() + "', line " + std::to_string(row) + ": " + std::to_string(j) +
                               " values, the header has " + std::to_string(t.header.size()));
  }
  return t;
}

/// The columns called prefix_<name> (or prefix<k>), in order, and their names.
std::vector<std::pair<std::string, int>> columns_of(const csv_table& t, const std::string& prefix) {
  std::vector<std::pair<std::string, int>> out;
  for (std::size_t j = 0; j < t.header.size(); ++j) {
    const auto& h = t.header[j];
    if (h.rfind(prefix + "_", 0) == 0)
      out.emplace_back(h.substr(prefix.size() + 1), int(j));
    else if (h.size() > prefix.size() && h.rfind(prefix, 0) == 0 &&
             h.find_first_not_of("0123456789", prefix.size()) == std::string::npos)
      out.emplace_back(h, int(j));
  }
  return out;
}

/// Rows of the given columns, each column rounded to 6 significant digits of its largest value.
ordered_json rows_of(const csv_table& t, const std::vector<std::pair<std::string, int>>& cols) {
  std::vector<int> decimals;
  for (const auto& [name, j] : cols) {
    double big = 0;
    for (double v : t.cols[std::size_t(j)])
      if (std::isfinite(v)) big = std::max(big, std::abs(v));
    decimals.push_back(big > 0 ? 5 - int(std::floor(std::log10(big))) : 6);
  }
  ordered_json rows = ordered_json::array();
  const std::size_t n = t.cols.empty() ? 0 : t.cols[0].size();
  for (std::size_t i = 0; i < n; ++i) {
    ordered_json row = ordered_json::array();
    for (std::size_t k = 0; k < cols.size(); ++k) row.push_back(rounded(t.cols[std::size_t(cols[k].second)][i], decimals[k]));
    rows.push_back(row);
  }
  return rows;
}

ordered_json names_of(const std::vector<std::pair<std::string, int>>& cols) {
  ordered_json a = ordered_json::array();
  for (const auto& c : cols) a.push_back(c.first);
  return a;
}

/// One run of RUN_DIR as the page's data; q's columns are checked against the robot's joints.
ordered_json run_of(const std::filesystem::path& csv, const std::string& name, const page_robot& robot) {
  const csv_table t = read_csv(csv);
  const int ti = t.index("t");
  const auto q = columns_of(t, "q");
  if (ti < 0 || q.empty())
    throw nhdyn::input_error("nhdyn view: '" + csv.string() + "' has no t and q columns: not a run of nhdyn simulate");
  if (q.size() != robot.joints.size())
    throw nhdyn::input_error("nhdyn view: '" + csv.string() + "' has " + std::to_string(q.size()) + " q columns, robot '" +
                             robot.name + "' has " + std::to_string(robot.joints.size()) + " joints (give its --model)");
  for (std::size_t k = 0; k < q.size(); ++k)  // q_<joint> names must be the robot's (paper5's q1..q5 by position)
    if (q[k].first != robot.joints[k] && q[k].first != "q" + std::to_string(k + 1))
      throw nhdyn::input_error("nhdyn view: '" + csv.string() + "': column q_" + q[k].first + " where robot '" + robot.name +
                               "' has joint '" + robot.joints[k] + "' (give its --model)");
  ordered_json r;
  r["name"] = name;
  r["t"] = t.cols[std::size_t(ti)];
  ordered_json qs = ordered_json::array();
  for (std::size_t i = 0; i < t.cols[0].size(); ++i) {
    ordered_json row = ordered_json::array();
    for (const auto& c : q) row.push_back(t.cols[std::size_t(c.second)][i]);  // as written: the same doubles
    qs.push_back(row);
  }
  r["q"] = qs;
  ordered_json columns = ordered_json::object();
  if (const int e = t.index("err"); e >= 0) {
    ordered_json err = ordered_json::array();
    for (const auto& row : rows_of(t, {{"err", e}})) err.push_back(row[0]);
    columns["error"] = err;
  }
  if (const auto tau = columns_of(t, "tau"); !tau.empty()) {
    columns["tau"] = rows_of(t, tau);
    columns["tau_names"] = names_of(tau);
  }
  if (const auto eta = columns_of(t, "eta"); !eta.empty()) {
    columns["eta"] = rows_of(t, eta);
    columns["eta_names"] = names_of(eta);
  }
  r["columns"] = columns;
  ordered_json task = ordered_json::object();
  for (const auto& [key, names] : {std::pair<std::string, std::array<const char*, 3>>{"path", {"r_x", "r_y", "r_z"}},
                                   {"reference", {"rd_x", "rd_y", "rd_z"}}}) {
    const int a = t.index(names[0]), b = t.index(names[1]), c = t.index(names[2]);
    if (a < 0 || b < 0 || c < 0) continue;
    ordered_json pts = ordered_json::array();
    for (std::size_t i = 0; i < t.cols[0].size(); ++i)
      pts.push_back({rounded(t.cols[std::size_t(a)][i], 7), rounded(t.cols[std::size_t(b)][i], 7),
                     rounded(t.cols[std::size_t(c)][i], 7)});
    task[key] = pts;
  }
  r["task"] = task;
  return r;
}

/// The page: the template with its data line.
std::string page_of(const ordered_json& data) {
  const auto tpl_path = data_dir() / "viewer" / "template.html";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(tpl_path, ec))
    throw nhdyn::model_error("nhdyn view: the page's template " + tpl_path.string() +
                             " is not there: the build makes it with node from viewer/ (scripts/install-deps.sh "
                             "installs node and the pinned npm packages; viewer/README.md)");
  const std::string tpl = read_file(tpl_path);
  std::string text = data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string safe;  // inside <script>: no '<' at all (no </script>, no <!--); U+2028/9 escaped
  safe.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '<') {
      safe += "\\u003c";
    } else if (text.compare(i, 3, "\xE2\x80\xA8") == 0 || text.compare(i, 3, "\xE2\x80\xA9") == 0) {
      safe += text[i + 2] == '\xA8' ? "\\u2028" : "\\u2029";
      i += 2;
    } else {
      safe += text[i];
    }
  }
  const std::string placeholder = "/*NHDYN_DATA*/";
  const auto at = tpl.find(placeholder);
  if (at == std::string::npos || tpl.find(placeholder, at + 1) != std::string::npos)
    throw nhdyn::model_error("nhdyn view: " + tpl_path.string() + " does not hold one data line " + placeholder);
  return tpl.substr(0, at) + "window.NHDYN_DATA = " + safe + ";" + tpl.substr(at + placeholder.size());
}

ordered_json robot_json(const page_robot& r, const std::vector<std::string>& package_paths, std::vector<std::string>& missing) {
  const std::string urdf_text = r.urdf_text.empty() ? read_file(r.urdf) : r.urdf_text;
  auto [meshes, miss] = embed_meshes(urdf_text, r.urdf, package_paths);
  missing = miss;
  ordered_json j;
  j["name"] = r.name;
  j["urdf"] = urdf_text;
  j["meshes"] = meshes;
  j["joint_names"] = r.joints;
  ordered_json base;
  base["planar"] = r.planar;
  base["joints"] = r.base_joints.empty() ? ordered_json(nullptr) : ordered_json(r.base_joints);
  j["base"] = base;
  ordered_json locked = ordered_json::object();
  for (const auto& [name, x] : r.locked) locked[name] = x;
  j["locked"] = locked;
  return j;
}

/// Writes the page of `robot` and `runs` to `page` (the data of viewer/README.md); names
/// the meshes that did not resolve on stderr.
std::filesystem::path write_page(const page_robot& robot, const std::string& title, ordered_json runs,
                                 const std::filesystem::path& page, const std::vector<std::string>& package_paths) {
  std::vector<std::string> missing;
  ordered_json data;
  data["version"] = 1;
  data["title"] = title;
  data["up"] = {robot.up.x(), robot.up.y(), robot.up.z()};
  data["robot"] = robot_json(robot, package_paths, missing);
  data["runs"] = std::move(runs);
  for (const auto& m : missing) std::cerr << "nhdyn view: mesh not found, the page draws a stand-in: " << m << '\n';
  std::ofstream(page, std::ios::binary) << page_of(data);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(page, ec)) throw nhdyn::input_error("nhdyn view: cannot write '" + page.string() + "'");
  return page;
}

}  // namespace

std::filesystem::path write_view_page(const std::filesystem::path& run_dir, const std::string& model,
                                      const std::filesystem::path& out, const std::vector<std::string>& package_paths,
                                      int max_runs, const std::vector<std::pair<std::string, double>>& locks) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // the runs, in summary.json's order, then any other CSV
  std::vector<std::string> names;
  std::map<std::string, json> summary;
  std::string robot_spec = model;
  std::vector<std::pair<std::string, double>> held = locks;
  if (fs::is_regular_file(run_dir / "summary.json", ec)) {
    std::ifstream in(run_dir / "summary.json");
    const json s = json::parse(in, nullptr, false);
    if (s.is_object() && s.contains("runs") && s["runs"].is_array())
      for (const auto& r : s["runs"]) {
        if (!r.is_object() || !r.contains("name")) continue;
        names.push_back(r["name"].get<std::string>());
        summary[names.back()] = r;
        if (robot_spec.empty() && r.contains("robot")) {
          robot_spec = r["robot"].get<std::string>();
          if (r.contains("locked") && r["locked"].is_object())  // the scene's held joints
            for (auto it = r["locked"].begin(); it != r["locked"].end(); ++it) held.emplace_back(it.key(), it.value().get<double>());
        }
      }
  }
  std::vector<std::string> csvs;
  for (const auto& e : fs::directory_iterator(run_dir, ec)) {
    const std::string f = e.path().filename().string();
    if (e.is_regular_file() && f.size() > 4 && f.ends_with(".csv") && !f.ends_with("-bands.csv")) csvs.push_back(f.substr(0, f.size() - 4));
  }
  if (ec) throw nhdyn::input_error("nhdyn view: cannot read the folder '" + run_dir.string() + "': " + ec.message());
  std::sort(csvs.begin(), csvs.end());
  std::vector<std::string> order;
  for (const auto& n : names)
    if (std::find(csvs.begin(), csvs.end(), n) != csvs.end()) order.push_back(n);
  for (const auto& n : csvs)
    if (std::find(order.begin(), order.end(), n) == order.end()) order.push_back(n);
  if (order.empty()) throw nhdyn::input_error("nhdyn view: no <run>.csv in '" + run_dir.string() + "'");
  if (robot_spec.empty())
    throw nhdyn::input_error("nhdyn view: '" + run_dir.string() + "/summary.json' does not name the runs' robot: give --model");
  if (int(order.size()) > max_runs) {
    std::cerr << "nhdyn view: " << order.size() << " runs, the page holds the first " << max_runs << " (--max-runs)\n";
    order.resize(std::size_t(max_runs));
  }
  const page_robot robot = robot_of(robot_spec, held);
  ordered_json runs = ordered_json::array();
  for (const auto& n : order) {
    ordered_json r = run_of(run_dir / (n + ".csv"), n, robot);
    if (summary.count(n) && summary[n].contains("success")) r["success"] = summary[n]["success"];
    runs.push_back(r);
  }
  // the page adds the shown run's name to the title
  const std::string title =
      order.size() == 1 ? robot.name : robot.name + " — " + fs::absolute(run_dir).lexically_normal().filename().string();
  return write_page(robot, title, std::move(runs), out.empty() ? run_dir / "view.html" : out, package_paths);
}

namespace {
std::filesystem::path pose_page(const std::string& model, const std::vector<std::pair<std::string, double>>& locks,
                                const std::string& q_text, const std::filesystem::path& out,
                                const std::vector<std::string>& package_paths) {
  const page_robot robot = robot_of(model, locks);
  const std::size_t n = robot.joints.size();
  std::vector<double> q(n, 0.0);
  if (!q_text.empty()) {
    std::vector<double> v;
    std::stringstream s(q_text);
    for (std::string x; std::getline(s, x, ',');) {
      char* end = nullptr;
      const double d = std::strtod(x.c_str(), &end);
      if (x.empty() || *end != '\0' || !std::isfinite(d)) throw usage_error("--q: '" + x + "' is not a finite number");
      v.push_back(d);
    }
    if (v.size() != n)
      throw usage_error("--q has " + std::to_string(v.size()) + " values, robot '" + robot.name + "' has " + std::to_string(n) +
                        " joints (`nhdyn model` lists them)");
    q = v;
  }
  const ordered_json runs = ordered_json::array({ordered_json{
      {"name", "pose"}, {"t", {0.0}}, {"q", {q}}, {"columns", ordered_json::object()}, {"task", ordered_json::object()}}});
  return write_page(robot, robot.name, runs, out.empty() ? std::filesystem::path(robot.name + ".html") : out, package_paths);
}

int run(const std::vector<std::string>& args) {
  CLI::App app;
  std::string run_dir, model, q, out, lock;
  std::vector<std::string> package_paths;
  int max_runs = 40;
  app.add_option("RUN_DIR", run_dir);
  app.add_option("--model", model);
  app.add_option("--q", q);
  app.add_option("--lock", lock);
  app.add_option("--out", out);
  app.add_option("--package-path", package_paths);
  add_integer_option(app, "--max-runs", max_runs, 1, 100000);
  if (!parse_command_line(app, args, usage)) return 0;
  if (run_dir.empty() && model.empty()) throw usage_error("give RUN_DIR (an nhdyn simulate folder) or --model MODEL");
  if (!run_dir.empty() && !q.empty()) throw usage_error("--q is for a pose (--model alone), not for RUN_DIR's runs");
  if (!lock.empty() && model.empty()) throw usage_error("--lock goes with --model (a run folder's summary.json names its own)");
  const auto locks = lock.empty() ? std::vector<std::pair<std::string, double>>{} : parse_locks(lock);
  const auto page = run_dir.empty() ? pose_page(model, locks, q, out, package_paths)
                                    : write_view_page(run_dir, model, out, package_paths, max_runs, locks);
  std::cout << page.string() << '\n';
  return 0;
}
}  // namespace

command command_view() {
  return {"view", "a self-contained HTML page of a robot or of simulate's runs (three.js): -> PAGE.html", usage, run};
}

}  // namespace nhdyn_tool
