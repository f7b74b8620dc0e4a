#pragma once
/// \file io/urdf.hpp
/// URDF import: `io::load_urdf(path)` and `io::parse_urdf(text)` give a `tree<double>`.
/// Needs urdfdom and tinyxml2 (CMake target `nhdyn::urdf`, component `urdf`).
///
/// - Joint order (q): the movable joints (revolute, continuous, prismatic) in depth-first
///   pre-order from the root link, siblings in the order their `<joint>` elements appear in
///   the file (taken from the document: urdfdom sorts siblings by name).
/// - Fixed joints are merged: a link attached by a fixed joint joins its parent body (masses,
///   centres of mass and inertias combined) and stays a named frame of it.
/// - Mimic joints are independent coordinates (the `<mimic>` is kept in `body::mimic`).
/// - Read: links, joints (type, origin xyz rpy, axis, limit, dynamics, mimic), `<inertial>`
///   (origin xyz rpy, mass, inertia). Ignored: visual, collision, material, transmission,
///   gazebo, sensors, safety_controller, calibration.
/// - Errors (model_error, naming the file and the link or joint): malformed XML, several
///   roots, a cycle, a missing parent or child link, NaN or Inf, a negative mass, a zero or
///   non-unit axis, `planar` joints, and `floating` joints but the one that may join the root
///   link (often called "world") to the robot's first link: that robot floats
///   (model/floating.hpp; its link's six coordinates root_x … root_rz come first, its other
///   links on the world are frames of the world). An inertia that is not physically valid
///   (not positive semi-definite, or principal moments breaking the triangle inequality) is
///   used as written with one warning per link, or refused with `urdf_options::strict`.
/// - Gravity: (0, 0, −9.81) unless the options say otherwise.
#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "../config.hpp"
#include "../detail/compiled_abi.hpp"
#include "../errors.hpp"
#include "../model/floating.hpp"
#include "../model/tree.hpp"

#if NHDYN_DEFINES(NHDYN_PART_IO)  // the parsers' headers: only where the loaders are defined
#include <tinyxml2.h>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>
#endif

namespace nhdyn::io {

struct urdf_options {
  /// Refuse non-physical inertias instead of warning.
  bool strict = false;
  vec3<double> gravity{0, 0, -9.81};
  /// Where warnings go; default: one line each on stderr, prefixed "nhdyn: warning: ".
  std::function<void(const std::string&)> warn{};
  /// Sends one warning where `warn` says.
  void warning(const std::string& msg) const {
    if (warn)
      warn(msg);
    else
      std::cerr << "nhdyn: warning: " << msg << "\n";
  }
  /// A planar base in front of the URDF's joints: q = (base_x, base_y, base_yaw, the URDF's
  /// joints), the root link's pose on the floor (x, y along the world axes, yaw about world
  /// z). The root link then moves: its own <inertial> and those of links fixed to it count.
  bool planar_base = false;
  /// A floating base in front of the URDF's joints (model/floating.hpp): the root link moves
  /// freely, q = (x, y, z, qx, qy, qz, qw, the URDF's joints), v = (v_B, ω_B, the joints'
  /// rates). A URDF whose root link is joined to the world by a `floating` joint floats too,
  /// without this option.
  bool floating_base = false;
};

/// A URDF document (its text) as a tree. `where` names it in messages (a file name).
template <class = void>
tree<double> parse_urdf(const std::string& text, const std::string& where = "URDF", urdf_options opt = {});
/// The URDF file at `path` as a tree; messages name the file.
template <class = void>
tree<double> load_urdf(const std::string& path, urdf_options opt = {});

#if NHDYN_DEFINES(NHDYN_PART_IO)
namespace detail {

/// Collects what urdfdom says through console_bridge while it parses (instead of printing it).
class console_capture : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR)
      lines.push_back(text);
    else if (level == console_bridge::CONSOLE_BRIDGE_LOG_WARN)
      warnings.push_back(text);
  }
  std::vector<std::string> lines;     ///< errors
  std::vector<std::string> warnings;  ///< urdfdom's warnings
};

inline std::mutex& urdfdom_mutex() {
  static std::mutex m;
  return m;
}

inline Eigen::Matrix3d rotation(const urdf::Rotation& r) {
  return Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized().toRotationMatrix();
}
inline Eigen::Vector3d vector(const urdf::Vector3& v) { return {v.x, v.y, v.z}; }

/// One joint element of the document: its name, line, parent and child link, and raw axis.
struct joint_element {
  std::string name, parent, child;
  int line = 0;
  std::string axis;  // the xyz attribute as written ("" if absent)
};

struct urdf_document {
  std::vector<joint_element> joints;  // document order
  std::map<std::string, int> link_line;
};

inline urdf_document read_document(const std::string& text, const std::string& where) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    throw model_error(where + "malformed XML (line " + std::to_string(doc.ErrorLineNum()) + "): " +
                      (doc.ErrorStr() ? doc.ErrorStr() : "parse error"));
  const auto* robot = doc.FirstChildElement("robot");
  if (!robot) throw model_error(where + "no <robot> element");
  urdf_document out;
  for (const auto* e = robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link"))
    if (const char* n = e->Attribute("name")) out.link_line[n] = e->GetLineNum();
  for (const auto* e = robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
    joint_element j;
    j.name = e->Attribute("name") ? e->Attribute("name") : "";
    j.line = e->GetLineNum();
    if (const auto* p = e->FirstChildElement("parent"); p && p->Attribute("link")) j.parent = p->Attribute("link");
    if (const auto* c = e->FirstChildElement("child"); c && c->Attribute("link")) j.child = c->Attribute("link");
    if (const auto* a = e->FirstChildElement("axis"); a && a->Attribute("xyz")) j.axis = a->Attribute("xyz");
    out.joints.push_back(std::move(j));
  }
  return out;
}

inline bool finite3(const Eigen::Vector3d& v) { return v.allFinite(); }

/// The joints of a cycle in the document, as "'j1' (line 4), 'j2' (line 9)", if its joints
/// form one (urdfdom says only "no root link"); empty otherwise. A link with two parent
/// joints is left to urdfdom, which names it.
inline std::string joint_cycle(const urdf_document& doc) {
  std::map<std::string, const joint_element*> parent_joint;  // child link → its joint
  for (const auto& j : doc.joints) {
    if (j.child.empty() || j.parent.empty()) continue;
    if (parent_joint.count(j.child)) return {};
    parent_joint[j.child] = &j;
  }
  for (const auto& [start, unused] : parent_joint) {
    std::vector<const joint_element*> path;
    std::map<std::string, std::size_t> seen;  // link → its place on the path
    for (std::string link = start;;) {
      const auto it = parent_joint.find(link);
      if (it == parent_joint.end()) break;  // reached a root
      if (const auto s = seen.find(link); s != seen.end()) {
        std::string out;
        for (std::size_t k = s->second; k < path.size(); ++k)
          out += (out.empty() ? "'" : ", '") + path[k]->name + "' (line " + std::to_string(path[k]->line) + ")";
        return out;
      }
      seen[link] = path.size();
      path.push_back(it->second);
      link = it->second->parent;
    }
  }
  return {};
}

}  // namespace detail

template <class>
tree<double> parse_urdf(const std::string& text, const std::string& where, urdf_options opt) {
  const std::string at = where + ": ";
  const detail::urdf_document doc = detail::read_document(text, at);
  if (const std::string cycle = detail::joint_cycle(doc); !cycle.empty())
    throw model_error(at + "the joints form a cycle (" + cycle +
                      "): every link on it has a parent, so there is no root link; a URDF is a tree");
  urdf::ModelInterfaceSharedPtr model;
  std::vector<std::string> urdfdom_warnings;
  {
    std::lock_guard<std::mutex> lock(detail::urdfdom_mutex());
    detail::console_capture capture;
    console_bridge::useOutputHandler(&capture);
    try {
      model = urdf::parseURDF(text);
    } catch (const std::exception& e) {
      capture.lines.push_back(e.what());
    }
    console_bridge::restorePreviousOutputHandler();
    // urdfdom logs some errors and goes on (a malformed <inertial> is dropped, mass 0): any
    // error it reports is an error here, model or not.
    if (!model || !capture.lines.empty()) {
      std::string why;
      for (const auto& l : capture.lines) why += (why.empty() ? "" : "; ") + l;
      throw model_error(at + "not a valid URDF: " + (why.empty() ? "urdfdom refused it" : why));
    }
    urdfdom_warnings = std::move(capture.warnings);
  }
  const auto warn = [&](const std::string& msg) { opt.warning(where + ": " + msg); };
  for (const auto& w : urdfdom_warnings) warn("urdfdom: " + w);
  const auto line_of_link = [&](const std::string& n) {
    const auto it = doc.link_line.find(n);
    return it == doc.link_line.end() ? std::string() : " (line " + std::to_string(it->second) + ")";
  };
  const auto root = model->getRoot();
  if (!root) throw model_error(at + "no root link");

  std::vector<body<double>> bodies;
  std::vector<frame<double>> frames;
  // each link's body (−1: the root's) and its placement in that body's frame
  struct placed {
    int body;
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
  };
  std::map<std::string, placed> where_is;
  where_is[root->name] = {-1, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()};
  if (opt.planar_base) {
    // base_x, base_y slide along the world x and y axes, base_yaw turns about world z and
    // carries the root link (massless bodies in front: the root link's inertia is its own).
    const char* names[3] = {"base_x", "base_y", "base_yaw"};
    for (int i = 0; i < 3; ++i) {
      body<double> b;
      b.name = i == 2 ? root->name : names[i] + std::string("_link");
      b.joint_name = names[i];
      b.parent = i - 1;
      b.joint = i == 2 ? joint_type::revolute : joint_type::prismatic;
      b.continuous = i == 2;
      b.axis = i == 0 ? Eigen::Vector3d::UnitX() : i == 1 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
      bodies.push_back(std::move(b));
    }
    where_is[root->name] = {2, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()};
  }
  // A floating base: six bodies in front (model/floating.hpp), the last the floating link,
  // which is the root link (the option) or the child of the root's floating joint (the file).
  const detail::joint_element* root_floating = nullptr;
  for (const auto& j : doc.joints)
    if (j.parent == root->name && model->getJoint(j.name) && model->getJoint(j.name)->type == urdf::Joint::FLOATING) {
      if (root_floating)
        throw model_error(at + "joints '" + root_floating->name + "' and '" + j.name +
                          "' both float on the root link '" + root->name + "': a robot has one floating base");
      root_floating = &j;
    }
  if (root_floating && (opt.floating_base || opt.planar_base))
    throw model_error(at + "joint '" + root_floating->name + "' (line " + std::to_string(root_floating->line) +
                      ") is a floating joint, and the robot file gives the base too (\"base\"): give it once");
  const bool floating = opt.floating_base || root_floating;
  if (opt.floating_base && opt.planar_base) throw model_error(at + "a base cannot be both planar and floating");
  if (floating) {
    const std::string link = root_floating ? root_floating->child : root->name;
    bodies = free_flyer_bodies<double>(link);
    where_is[link] = {5, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()};
  }

  // A link's own inertial, checked, in the frame of the body it joins.
  const auto add_inertial = [&](const urdf::Link& L, const placed& pl) {
    // (pl.body): in a template, clang 14 reads `pl.body <` as the class template body<…>
    if (!L.inertial || (pl.body) < 0) return;
    const auto& in = *L.inertial;
    const std::string here = "link '" + L.name + "'" + line_of_link(L.name) + ": ";
    Eigen::Matrix3d Ic;
    Ic << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    const Eigen::Vector3d c_link = detail::vector(in.origin.position);
    if (!std::isfinite(in.mass) || !Ic.allFinite() || !c_link.allFinite())
      throw model_error(at + here + "an <inertial> number is not finite (NaN or Inf)");
    if (in.mass < 0) throw model_error(at + here + "mass is negative (" + std::to_string(in.mass) + " kg)");
    if (auto why = nhdyn::detail::inertia_problem(in.mass, Ic, true, true)) {
      if (opt.strict) throw model_error(at + here + *why);
      warn(here + *why + "; used as given");
    }
    const Eigen::Matrix3d R_li = detail::rotation(in.origin.rotation);
    const Eigen::Matrix3d I_b = pl.R * R_li * Ic * R_li.transpose() * pl.R.transpose();
    const Eigen::Vector3d c_b = pl.p + pl.R * c_link;
    nhdyn::detail::merge_rigid_body(bodies[static_cast<std::size_t>(pl.body)], in.mass, c_b, I_b);
  };

  // Depth-first pre-order from the root, siblings in document order.
  std::vector<std::string> stack{root->name};
  std::map<std::string, int> visits;
  while (!stack.empty()) {
    const std::string link_name = stack.back();
    stack.pop_back();
    if (++visits[link_name] > 1) throw model_error(at + "link '" + link_name + "' is reached twice (a cycle)");
    std::vector<const detail::joint_element*> kids;
    for (const auto& j : doc.joints)
      if (j.parent == link_name) kids.push_back(&j);
    for (auto it = kids.rbegin(); it != kids.rend(); ++it) stack.push_back((*it)->child);
    // process the joints whose child is link_name (at most one: urdfdom checked)
    if (link_name == root->name) continue;
    const detail::joint_element* je = nullptr;
    for (const auto& j : doc.joints)
      if (j.child == link_name) je = &j;
    const auto J = model->getJoint(je->name);
    const auto L = model->getLink(link_name);
    const std::string here = "joint '" + je->name + "' (line " + std::to_string(je->line) + "): ";
    const placed parent = where_is.at(je->parent);
    const Eigen::Matrix3d R_o = detail::rotation(J->parent_to_joint_origin_transform.rotation);
    const Eigen::Vector3d p_o = detail::vector(J->parent_to_joint_origin_transform.position);
    if (!R_o.allFinite() || !p_o.allFinite()) throw model_error(at + here + "origin is not finite (NaN or Inf)");
    const Eigen::Matrix3d R_PJ = parent.R * R_o;
    const Eigen::Vector3d p_PJ = parent.p + parent.R * p_o;
    switch (J->type) {
      case urdf::Joint::FIXED:
        where_is[link_name] = {parent.body, R_PJ, p_PJ};
        frames.push_back({link_name, parent.body, R_PJ, p_PJ});
        add_inertial(*L, where_is[link_name]);
        continue;
      case urdf::Joint::FLOATING:
        if (je == root_floating) {
          if ((R_o - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-12 || p_o.cwiseAbs().maxCoeff() > 1e-12)
            throw model_error(at + here + "a floating joint's <origin> must be the identity: q places the link '" +
                              link_name + "' in the world directly");
          add_inertial(*L, where_is[link_name]);
          continue;
        }
        throw model_error(at + here + "type 'floating' is supported only on the root link (the robot's floating "
                          "base, docs/model-format.md), not inside the tree under '" + je->parent + "'");
      case urdf::Joint::PLANAR:
        throw model_error(at + here + "type 'planar' is not supported: a mobile base is described in a robot file beside the URDF "
                          "(\"base\": {\"type\": \"planar\"}, docs/model-format.md), not by a joint in it");
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS:
      case urdf::Joint::PRISMATIC:
        break;
      default:
        throw model_error(at + here + "unknown joint type");
    }
    Eigen::Vector3d axis(1, 0, 0);  // URDF's default axis
    if (!je->axis.empty()) {
      std::istringstream is(je->axis);
      is.imbue(std::locale::classic());
      std::string tok;
      std::vector<double> xs;
      while (is >> tok) {
        try {
          std::size_t used = 0;
          xs.push_back(std::stod(tok, &used));
          if (used != tok.size()) throw std::invalid_argument(tok);
        } catch (const std::exception&) {
          throw model_error(at + here + "axis '" + je->axis + "' is not three numbers");
        }
      }
      if (xs.size() != 3) throw model_error(at + here + "axis '" + je->axis + "' is not three numbers");
      axis = {xs[0], xs[1], xs[2]};
    }
    const double len = axis.norm();
    if (!std::isfinite(len)) throw model_error(at + here + "axis is not finite (NaN or Inf)");
    if (len == 0) throw model_error(at + here + "axis is zero");
    if (std::abs(len - 1) > 1e-6) {
      std::ostringstream os;
      os << at << here << "axis has length " << len << ", not 1";
      throw model_error(os.str());
    }
    if (floating && (parent.body) < 0)
      throw model_error(at + here + "a movable joint on the world link '" + je->parent +
                        "' of a floating robot: every moving link must hang below the floating link '" + bodies[5].name + "'");
    body<double> b;
    b.name = link_name;
    b.joint_name = je->name;
    b.parent = parent.body;
    b.joint = J->type == urdf::Joint::PRISMATIC ? joint_type::prismatic : joint_type::revolute;
    b.continuous = J->type == urdf::Joint::CONTINUOUS;
    b.R_PJ = R_PJ;
    b.p_PJ = p_PJ;
    b.axis = axis / len;
    if (J->limits) {
      if (!b.continuous) {
        b.limits.lower = J->limits->lower;
        b.limits.upper = J->limits->upper;
      }
      if (J->limits->velocity > 0) b.limits.velocity = J->limits->velocity;
      if (J->limits->effort > 0) b.limits.effort = J->limits->effort;
    }
    if (J->dynamics) {
      b.damping = J->dynamics->damping;
      b.friction = J->dynamics->friction;
      if (!std::isfinite(b.damping) || !std::isfinite(b.friction))
        throw model_error(at + here + "<dynamics> is not finite (NaN or Inf)");
    }
    if (J->mimic) b.mimic = mimic_info{J->mimic->joint_name, J->mimic->multiplier, J->mimic->offset};
    bodies.push_back(std::move(b));
    where_is[link_name] = {static_cast<int>(bodies.size()) - 1, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()};
    add_inertial(*L, where_is[link_name]);
  }
  if (opt.planar_base || opt.floating_base) add_inertial(*root, where_is[root->name]);
  if (visits.size() != model->links_.size())
    for (const auto& [name, l] : model->links_)
      if (!visits.count(name)) throw model_error(at + "link '" + name + "'" + line_of_link(name) + " is not connected to the root '" + root->name + "'");
  // no movable joint: a model of 0 joints (a bare base, a sensor head), its links frames of the
  // root, as KDL loads such files
  validation v;
  v.triangle_inequality = false;  // checked per link above (warning or error)
  v.positive_semidefinite = false;
  return tree<double>(std::move(bodies), opt.gravity, model->getName(), v,
                      opt.planar_base || opt.floating_base ? "world" : root->name, std::move(frames));
}

template <class>
tree<double> load_urdf(const std::string& path, urdf_options opt) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw model_error(path + ": cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_urdf(ss.str(), path, std::move(opt));
}

#endif  // NHDYN_DEFINES(NHDYN_PART_IO)

}  // namespace nhdyn::io
