#pragma once
/// \file tests/reference/random_tree.hpp
/// Random but physical kinematic trees (seeded, reproducible): each body's parent drawn among
/// the earlier ones (so branches), random joint placements (rotation and offset), random unit
/// axes, revolute and prismatic joints, a random body-frame offset after the joint (as DH rows
/// have), physical inertias, a massless body and a point mass; and the same as URDF text, with
/// fixed joints and extra links, for the loader and for KDL.
#include <Eigen/Geometry>
#include <cstdio>
#include <nhdyn/model/tree.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "random_chain.hpp"

namespace nhdyn_ref {

inline Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  return Eigen::Quaterniond(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1))
      .normalized()
      .toRotationMatrix();
}
inline Eigen::Vector3d random_vector(std::mt19937_64& rng, double r) {
  return {uniform(rng, -r, r), uniform(rng, -r, r), uniform(rng, -r, r)};
}
inline Eigen::Vector3d random_axis(std::mt19937_64& rng) {
  // a coordinate axis (±) half of the time, as real robots have; otherwise any direction
  if (uniform(rng, 0, 1) < 0.5) {
    Eigen::Vector3d a = Eigen::Vector3d::Zero();
    a(std::uniform_int_distribution<int>(0, 2)(rng)) = uniform(rng, 0, 1) < 0.5 ? -1 : 1;
    return a;
  }
  return random_vector(rng, 1).normalized();
}

/// A random tree of n bodies. `branching`: probability that a body's parent is not the
/// previous body; `body_offset`: whether X_JB is random (else the identity, as URDF).
inline nhdyn::tree<double> random_tree(std::mt19937_64& rng, int n, double branching = 0.4, bool body_offset = true) {
  std::vector<nhdyn::body<double>> B(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    auto& b = B[std::size_t(i)];
    b.name = "body" + std::to_string(i);
    b.joint_name = "joint" + std::to_string(i);
    b.parent = i == 0 || uniform(rng, 0, 1) >= branching ? i - 1 : std::uniform_int_distribution<int>(-1, i - 1)(rng);
    b.joint = uniform(rng, 0, 1) < 0.3 ? nhdyn::joint_type::prismatic : nhdyn::joint_type::revolute;
    b.R_PJ = random_rotation(rng);
    b.p_PJ = random_vector(rng, 0.5);
    b.axis = random_axis(rng);
    if (body_offset) {
      b.R_JB = random_rotation(rng);
      b.p_JB = random_vector(rng, 0.3);
    }
    b.mass = uniform(rng, 0.2, 5.0);
    b.com = random_vector(rng, 0.3);
    b.inertia = random_inertia(rng, b.mass);
  }
  if (n > 2) {
    B[1].mass = 0;  // massless, with rotational inertia; it turns (a massless body sliding
    B[1].joint = nhdyn::joint_type::revolute;  // at a leaf would make M singular)
    B[std::size_t(n - 1)].inertia.setZero();  // a point mass
  }
  const Eigen::Vector3d g = random_vector(rng, 1).normalized() * 9.81;
  return nhdyn::tree<double>(std::move(B), g, "random tree");
}

/// "x y z" with 17 significant digits.
inline std::string xyz(const Eigen::Vector3d& v) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g", v.x(), v.y(), v.z());
  return buf;
}
/// URDF's rpy (fixed axes X, then Y, then Z: R = Rz(y) Ry(p) Rx(r)) of a rotation.
inline Eigen::Vector3d rpy(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d e = R.eulerAngles(2, 1, 0);  // R = Rz(e0) Ry(e1) Rx(e2)
  return {e(2), e(1), e(0)};
}
inline std::string origin(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) {
  return "<origin xyz=\"" + xyz(p) + "\" rpy=\"" + xyz(rpy(R)) + "\"/>";
}
inline std::string inertial(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& R, const Eigen::Matrix3d& I) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "<inertial>%s<mass value=\"%.17g\"/><inertia ixx=\"%.17g\" ixy=\"%.17g\" ixz=\"%.17g\" "
                "iyy=\"%.17g\" iyz=\"%.17g\" izz=\"%.17g\"/></inertial>",
                origin(R, c).c_str(), m, I(0, 0), I(0, 1), I(0, 2), I(1, 1), I(1, 2), I(2, 2));
  return buf;
}

/// A random URDF of n movable joints: a root link, a tree of links with random origins (rpy),
/// axes and inertials (each with its own rotated inertial frame), and after some links a
/// fixed joint to an extra link with mass (merged by the loaders). Joints are written in a
/// shuffled document order whose names do not sort in that order.
inline std::string random_urdf(std::mt19937_64& rng, int n, double branching = 0.4) {
  std::ostringstream links, joints;
  links << "<link name=\"root\"/>\n";
  std::vector<std::string> names{"root"};
  int fixed = 0;
  for (int i = 0; i < n; ++i) {
    const int parent = i == 0 || uniform(rng, 0, 1) >= branching
                           ? static_cast<int>(names.size()) - 1
                           : std::uniform_int_distribution<int>(0, static_cast<int>(names.size()) - 1)(rng);
    const std::string name = "l" + std::to_string(i);
    const double m = i == 1 ? 0.0 : uniform(rng, 0.2, 5.0);
    links << "<link name=\"" << name << "\">"
          << (i == 2 ? std::string() : inertial(m, random_vector(rng, 0.3), random_rotation(rng), random_inertia(rng, m + 0.1)))
          << "<visual><geometry><mesh filename=\"package://robot/meshes/" << name << ".stl\"/></geometry></visual></link>\n";
    // (link 1, massless, turns so that its rotational inertia moves; link 2, without an
    // <inertial>, always carries a fixed link with mass: M stays positive definite)
    const bool prismatic = i != 1 && uniform(rng, 0, 1) < 0.3;
    const std::string type = prismatic ? "prismatic" : uniform(rng, 0, 1) < 0.5 ? "continuous" : "revolute";
    joints << "<joint name=\"" << char('z' - (i % 26)) << i << "\" type=\"" << type << "\"><parent link=\""
           << names[std::size_t(parent)] << "\"/><child link=\"" << name << "\"/>"
           << origin(random_rotation(rng), random_vector(rng, 0.5)) << "<axis xyz=\"" << xyz(random_axis(rng)) << "\"/>"
           << (type == "continuous" ? "" : "<limit lower=\"-2\" upper=\"2\" effort=\"100\" velocity=\"3\"/>")
           << "</joint>\n";
    names.push_back(name);
    if (i == 2 || uniform(rng, 0, 1) < 0.3) {  // a fixed child with mass: merged into this body
      const std::string f = "f" + std::to_string(fixed++);
      const double mf = uniform(rng, 0.1, 1.0);
      links << "<link name=\"" << f << "\">" << inertial(mf, random_vector(rng, 0.2), random_rotation(rng), random_inertia(rng, mf))
            << "</link>\n";
      joints << "<joint name=\"fixed_" << f << "\" type=\"fixed\"><parent link=\"" << name << "\"/><child link=\"" << f
             << "\"/>" << origin(random_rotation(rng), random_vector(rng, 0.3)) << "</joint>\n";
    }
  }
  return "<?xml version=\"1.0\"?>\n<robot name=\"random\">\n" + links.str() + joints.str() + "</robot>\n";
}

}  // namespace nhdyn_ref
