#pragma once
/// \file model/tree.hpp
/// A kinematic tree: bodies, each moved by one joint (revolute or prismatic, about or along
/// any unit axis) relative to its parent body, plus named frames fixed on bodies (what fixed
/// joints leave behind once merged). Plain constant data, validated once when built; the
/// bodies are in topological order (every parent before its children), which is the order of
/// the joint coordinates q.
///
/// Frames of body i (all right-handed, orthonormal):
///   - the parent frame P: body `parent`'s frame, or the base (world-fixed) frame for -1;
///   - the joint frame J: placed in P by (R_PJ, p_PJ) — URDF's `<origin xyz rpy>`. The joint
///     turns J about `axis` (a revolute joint: rotation by q about the axis through J's origin)
///     or slides it along `axis` (prismatic: translation q·axis), the axis given in J;
///   - the body frame B: placed in the moved joint frame by (R_JB, p_JB): the identity for
///     URDF (the body frame is the moved joint frame), Tx(a)·Rx(α) for a DH row.
/// So X_PB(q) = X_PJ · joint(q) · X_JB. Mass, centre of mass and inertia are in B.
///
/// A DH chain is one kind of tree (as_tree): body i's frame is DH frame i, X_PJ = Rz(θ)·Tz(d)
/// of its row's constant part, axis z, X_JB = Tx(a)·Rx(α).
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "../errors.hpp"
#include "../scalar/traits.hpp"
#include "chain.hpp"
#include "link.hpp"

namespace nhdyn {

/// Joint limits as a file gives them (URDF `<limit>`); kept, not enforced by the dynamics.
struct joint_limits {
  double lower = -INFINITY, upper = INFINITY;  ///< position [rad or m]
  double velocity = INFINITY;                  ///< |q̇| [rad/s or m/s]
  double effort = INFINITY;                    ///< |τ| [N·m or N]
};

/// A joint that copies another's motion in the file (URDF `<mimic>`): kept as information;
/// nhdyn treats a mimic joint as an independent coordinate, as Pinocchio does by default.
struct mimic_info {
  std::string joint;   ///< the joint it follows
  double multiplier = 1, offset = 0;
};

/// One body of a tree and the joint that moves it.
template <class S>
struct body {
  std::string name;        ///< the body's (link's) name
  std::string joint_name;  ///< its joint's name
  int parent = -1;         ///< index of the parent body; -1: the base (world-fixed root)
  joint_type joint = joint_type::revolute;
  bool continuous = false;  ///< a revolute joint without position limits (URDF `continuous`)
  mat3<S> R_PJ = mat3<S>::Identity();  ///< joint frame's axes in the parent frame
  vec3<S> p_PJ = vec3<S>::Zero();      ///< joint frame's origin in the parent frame [m]
  vec3<S> axis = vec3<S>::UnitZ();     ///< unit joint axis in the joint frame
  mat3<S> R_JB = mat3<S>::Identity();  ///< body frame's axes in the moved joint frame
  vec3<S> p_JB = vec3<S>::Zero();      ///< body frame's origin in the moved joint frame [m]
  S mass{0};                           ///< [kg]
  vec3<S> com = vec3<S>::Zero();       ///< centre of mass in the body frame [m]
  mat3<S> inertia = mat3<S>::Zero();   ///< about the centre of mass, body-frame axes [kg·m²]
  joint_limits limits{};
  double damping = 0;   ///< viscous friction: URDF `<dynamics damping>` [N·m·s/rad or N·s/m]
  double friction = 0;  ///< Coulomb friction: URDF `<dynamics friction>` [N·m or N]
  std::optional<mimic_info> mimic{};
  /// Joint-side rotor inertia of the drive, G²·J_m [kg·m² or kg]: adds armature·q̈_i to τ_i and
  /// to M's diagonal (URDF has no field for it; JSON models and robot files do).
  S armature{0};
  /// The Coulomb force at q̇ < 0 when it is not −friction (an asymmetric law, as Corke's Puma).
  std::optional<double> friction_negative{};
  /// One of the six velocity coordinates of a floating base (model/floating.hpp): the tree's
  /// first six bodies, evaluated at zero in the root link's frame, never a joint of its own.
  bool free_flyer = false;

  /// The friction law the friction stages use (dynamics/friction.hpp).
  joint_friction friction_law() const { return {damping, friction, friction_negative.value_or(-friction)}; }
  /// Sets damping, friction and friction_negative to the law f.
  void set_friction_law(const joint_friction& f) {
    damping = f.viscous;
    friction = f.coulomb_pos;
    friction_negative = f.coulomb_neg == -f.coulomb_pos ? std::nullopt : std::optional<double>(f.coulomb_neg);
  }

  template <class U>
  body<U> cast() const {
    return {name,   joint_name, parent, joint, continuous, R_PJ.template cast<U>(), p_PJ.template cast<U>(),
            axis.template cast<U>(), R_JB.template cast<U>(), p_JB.template cast<U>(), U(mass),
            com.template cast<U>(), inertia.template cast<U>(), limits, damping, friction, mimic, U(armature),
            friction_negative, free_flyer};
  }
};

/// A named frame fixed on a body (body -1: the base), at (R, p) in that body's frame.
template <class S>
struct frame {
  std::string name;
  int body = -1;
  mat3<S> R = mat3<S>::Identity();
  vec3<S> p = vec3<S>::Zero();

  template <class U>
  frame<U> cast() const {
    return {name, body, R.template cast<U>(), p.template cast<U>()};
  }
};

namespace detail {

/// Adds a rigid body (mass m, centre of mass c and inertia I about it, both in b's frame) to
/// body b, about their common centre of mass (parallel-axis theorem): how io/urdf.hpp merges a
/// fixed link and model/lock.hpp a locked body.
template <class S>
void merge_rigid_body(body<S>& b, const S& m, const vec3<S>& c, const mat3<S>& I) {
  const S total = b.mass + m;
  const vec3<S> cc = value_of(total) > 0 ? vec3<S>((b.mass * b.com + m * c) / total) : vec3<S>(vec3<S>::Zero());
  const auto shift = [](const S& mass, const vec3<S>& d) {
    return mat3<S>(mass * (d.dot(d) * mat3<S>::Identity() - d * d.transpose()));
  };
  b.inertia = mat3<S>(b.inertia + shift(b.mass, vec3<S>(b.com - cc)) + I + shift(m, vec3<S>(c - cc)));
  b.com = cc;
  b.mass = total;
}

/// What is wrong with a rigid body's (mass, inertia about the centre of mass), if anything
/// that the policy rejects, as a sentence fragment; nullopt when it is acceptable. Mass ≥ 0
/// and symmetry are always required; positive semi-definiteness and the triangle inequality
/// of the principal moments as the policy says.
inline std::optional<std::string> inertia_problem(double mass, const Eigen::Matrix3d& I, bool psd,
                                                  bool triangle) {
  std::ostringstream os;
  if (mass < 0) {
    os << "mass is negative (" << mass << " kg)";
    return os.str();
  }
  const double scale = std::max(I.cwiseAbs().maxCoeff(), 1e-300);
  const double tol = 1e-9 * scale;
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > tol) return "inertia is not symmetric";
  if (!psd && !triangle) return std::nullopt;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (I + I.transpose()), Eigen::EigenvaluesOnly);
  const Eigen::Vector3d e = es.eigenvalues();  // ascending
  os.precision(2);
  os << std::scientific;
  if (psd && e(0) < -tol) {
    os << "inertia is not positive semi-definite (smallest principal moment " << e(0) << " kg m^2)";
    return os.str();
  }
  if (triangle && e(0) + e(1) < e(2) - tol) {
    os << "principal moments violate the triangle inequality by " << (e(2) - e(0) - e(1)) << " kg m^2";
    return os.str();
  }
  return std::nullopt;
}

template <class S>
Eigen::Matrix3d value_matrix(const mat3<S>& M) {
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = value_of(M(r, c));
  return out;
}

/// Whether R is a rotation to within tol (RᵀR = 1, det R = +1), on its double value (for a
/// float model: to within float's rounding).
template <class S>
bool is_rotation(const mat3<S>& R, double tol = std::is_same_v<S, float> ? 1e-5 : 1e-9) {
  const Eigen::Matrix3d Rd = value_matrix(R);
  return (Rd.transpose() * Rd - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < tol &&
         std::abs(Rd.determinant() - 1) < tol;
}

}  // namespace detail

/// A kinematic tree of n = dof() bodies in the number type S (any nhdyn::scalar). n may be 0:
/// the base alone with its named frames (every joint locked, model/lock.hpp).
template <scalar S>
class tree {
 public:
  using scalar_type = S;
  static constexpr int size_at_compile_time = dynamic;

  tree() = default;

  /// Builds and validates a tree; throws model_error naming the body and the problem.
  /// `root` names the base (world-fixed) body, `frames` the extra named frames.
  tree(std::vector<body<S>> bodies, vec3<S> gravity, std::string name = "tree", validation v = {},
       std::string root = "base", std::vector<frame<S>> frames = {})
      : bodies_(std::move(bodies)), frames_(std::move(frames)), gravity_(std::move(gravity)),
        name_(std::move(name)), root_(std::move(root)), validation_(v) {
    for (int r = 0; r < 3; ++r)
      if (!is_finite_scalar(gravity_(r)))
        throw model_error("model '" + name_ + "', field 'gravity': is not finite (NaN or Inf)");
    for (std::size_t i = 0; i < bodies_.size(); ++i) validate(bodies_[i], static_cast<int>(i));
    for (const auto& f : frames_)
      if (f.body + 1 < 0 || f.body >= dof() || !detail::is_rotation(f.R) || !finite(f.p))
        throw model_error("model '" + name_ + "', frame '" + f.name +
                          "': body index out of range, a non-rotation, or a non-finite position");
    validate_floating();
    children_.assign(bodies_.size(), {});
    for (std::size_t i = 0; i < bodies_.size(); ++i)
      if (bodies_[i].parent >= 0) children_[static_cast<std::size_t>(bodies_[i].parent)].push_back(int(i));
  }

  /// The number of velocity coordinates (q̇, q̈ and τ have this many entries), the bodies'.
  int dof() const { return static_cast<int>(bodies_.size()); }
  /// Whether the root link floats (a free-flyer root, model/floating.hpp): its first six bodies
  /// are the floating base's velocity coordinates, and q has one entry more than q̇.
  bool floating() const { return floating_; }
  /// The number of configuration coordinates: dof() + 1 for a floating tree (the root's unit
  /// quaternion has four entries for three rotations), else dof().
  int nq() const { return dof() + (floating_ ? 1 : 0); }
  /// The number of velocity coordinates: dof().
  int nv() const { return dof(); }
  const body<S>& operator[](int i) const { return bodies_[static_cast<std::size_t>(i)]; }
  const std::vector<body<S>>& bodies() const { return bodies_; }
  const std::vector<frame<S>>& frames() const { return frames_; }
  const std::vector<int>& children(int i) const { return children_[static_cast<std::size_t>(i)]; }
  int parent(int i) const { return bodies_[static_cast<std::size_t>(i)].parent; }
  const vec3<S>& gravity() const { return gravity_; }
  const std::string& name() const { return name_; }
  const std::string& root_name() const { return root_; }
  const validation& validation_policy() const { return validation_; }
  auto begin() const { return bodies_.begin(); }
  auto end() const { return bodies_.end(); }

  /// Joint names in q order.
  std::vector<std::string> joint_names() const {
    std::vector<std::string> out;
    for (const auto& b : bodies_) out.push_back(b.joint_name);
    return out;
  }
  /// Index of the body named `n`: 0…n−1, −1 for the root; throws input_error if none.
  int body_index(const std::string& n) const {
    if (n == root_) return -1;
    for (int i = 0; i < dof(); ++i)
      if (bodies_[static_cast<std::size_t>(i)].name == n) return i;
    throw input_error("model '" + name_ + "': no body named '" + n + "'");
  }
  /// A named frame (a merged fixed link, or a body's own frame): its body and its placement.
  frame<S> find_frame(const std::string& n) const {
    for (const auto& f : frames_)
      if (f.name == n) return f;
    return frame<S>{n, body_index(n), mat3<S>::Identity(), vec3<S>::Zero()};
  }
  /// Whether body j is i or one of i's ancestors.
  bool supports(int j, int i) const {
    for (; i >= 0; i = parent(i))
      if (i == j) return true;
    return false;
  }

  template <class U>
  tree<U> cast() const {
    std::vector<body<U>> b;
    for (const auto& x : bodies_) b.push_back(x.template cast<U>());
    std::vector<frame<U>> f;
    for (const auto& x : frames_) f.push_back(x.template cast<U>());
    return tree<U>(std::move(b), gravity_.template cast<U>(), name_, validation_, root_, std::move(f));
  }
  tree dynamic_size() const { return *this; }
  tree with_gravity(vec3<S> g) const { return tree(bodies_, std::move(g), name_, validation_, root_, frames_); }

 private:
  /// A floating base is the first six bodies, flagged free_flyer, in the one form the
  /// algorithms read (model/floating.hpp): root_x, root_y, root_z slide along, root_rx,
  /// root_ry, root_rz turn about the x, y, z axes of one frame, with identity placements and no
  /// inertia but the last one's (the root link's); every other body hangs below the root link.
  void validate_floating() {
    int flagged = 0;
    for (const auto& b : bodies_) flagged += b.free_flyer ? 1 : 0;
    if (flagged == 0) return;
    const std::string where = "model '" + name_ + "', floating base: ";
    if (flagged != 6 || dof() < 6)
      throw model_error(where + std::to_string(flagged) + " bodies are flagged as its coordinates, not 6");
    for (int i = 0; i < 6; ++i) {
      const body<S>& b = bodies_[static_cast<std::size_t>(i)];
      const std::string at = where + "body " + std::to_string(i) + " ('" + b.name + "'): ";
      vec3<S> e = vec3<S>::Zero();
      e(i % 3) = S(1);
      const bool shape = b.free_flyer && b.parent == i - 1 &&
                         b.joint == (i < 3 ? joint_type::prismatic : joint_type::revolute) &&
                         detail::value_matrix(b.R_PJ).isIdentity(0) && detail::value_matrix(b.R_JB).isIdentity(0);
      bool exact = shape;
      for (int r = 0; r < 3 && exact; ++r)
        exact = value_of(b.axis(r)) == value_of(e(r)) && value_of(b.p_PJ(r)) == 0 && value_of(b.p_JB(r)) == 0;
      if (!exact)
        throw model_error(at + "not in the floating base's form (the first six bodies: root_x, root_y, root_z, "
                               "root_rx, root_ry, root_rz along and about x, y, z, identity placements)");
      if (i < 5 && (!is_exact_zero(b.mass) || detail::value_matrix(b.inertia).cwiseAbs().maxCoeff() != 0))
        throw model_error(at + "carries mass or inertia; only the sixth body (the root link) does");
      if (!is_exact_zero(b.armature) || b.damping != 0 || b.friction != 0 || b.friction_negative)
        throw model_error(at + "has armature or friction: a floating base has no drive");
    }
    for (int i = 6; i < dof(); ++i)
      if (bodies_[static_cast<std::size_t>(i)].parent < 5)
        throw model_error(where + "body '" + bodies_[static_cast<std::size_t>(i)].name + "' is attached to " +
                          (bodies_[static_cast<std::size_t>(i)].parent < 0 ? std::string("the world")
                                                                           : "a floating base coordinate") +
                          ", not below the root link '" + bodies_[5].name + "'");
    floating_ = true;
  }
  static bool finite(const auto& M) {
    for (Eigen::Index k = 0; k < M.size(); ++k)
      if (!is_finite_scalar(M.data()[k])) return false;
    return true;
  }
  void validate(const body<S>& b, int i) const {
    const std::string where = "model '" + name_ + "', body '" + b.name + "' (joint '" + b.joint_name + "'): ";
    if (b.parent < -1 || b.parent >= i)
      throw model_error(where + "parent index " + std::to_string(b.parent) +
                        " is not an earlier body (bodies must be in topological order)");
    if (!finite(b.R_PJ) || !finite(b.p_PJ) || !finite(b.axis) || !finite(b.R_JB) || !finite(b.p_JB) ||
        !is_finite_scalar(b.mass) || !finite(b.com) || !finite(b.inertia))
      throw model_error(where + "a placement, axis or inertial number is not finite (NaN or Inf)");
    if (!detail::is_rotation(b.R_PJ) || !detail::is_rotation(b.R_JB))
      throw model_error(where + "a placement's rotation is not a rotation matrix");
    const double len = std::sqrt(value_of(b.axis.dot(b.axis)));
    if (std::abs(len - 1) > 1e-6)
      throw model_error(where + "joint axis has length " + std::to_string(len) + ", not 1");
    if (auto why = detail::inertia_problem(value_of(b.mass), detail::value_matrix(b.inertia),
                                           validation_.positive_semidefinite, validation_.triangle_inequality))
      throw model_error(where + *why);
    if (!is_finite_scalar(b.armature) || value_of(b.armature) < 0)
      throw model_error(where + "armature " + std::to_string(value_of(b.armature)) + " is not a finite number >= 0");
    if (auto why = detail::friction_problem(b.friction_law())) throw model_error(where + "friction " + *why);
  }

  std::vector<body<S>> bodies_{};
  std::vector<frame<S>> frames_{};
  std::vector<std::vector<int>> children_{};
  vec3<S> gravity_ = vec3<S>::Zero();
  std::string name_ = "tree";
  std::string root_ = "base";
  validation validation_{};
  bool floating_ = false;
};

namespace detail {
template <class S>
mat3<S> rot_z(const S& t) {
  using std::cos;
  using std::sin;
  mat3<S> R = mat3<S>::Identity();
  const S c = cos(t), s = sin(t);
  R(0, 0) = c;
  R(0, 1) = -s;
  R(1, 0) = s;
  R(1, 1) = c;
  return R;
}
template <class S>
mat3<S> rot_x(const S& t) {
  using std::cos;
  using std::sin;
  mat3<S> R = mat3<S>::Identity();
  const S c = cos(t), s = sin(t);
  R(1, 1) = c;
  R(1, 2) = -s;
  R(2, 1) = s;
  R(2, 2) = c;
  return R;
}
}  // namespace detail

/// The DH chain c as a tree: body i is link i, its frame DH frame i (so com and inertia carry
/// over unchanged), its joint about / along z of the frame Rz(θ)·Tz(d) (the row's constant
/// part), then Tx(a)·Rx(α). Names: body `link1`…, joint `joint1`…; the base is `base`.
template <class S, int N>
tree<S> as_tree(const chain<S, N>& c) {
  std::vector<body<S>> out;
  for (int i = 0; i < c.dof(); ++i) {
    const link<S>& L = c[i];
    body<S> b;
    b.name = "link" + std::to_string(i + 1);
    b.joint_name = "joint" + std::to_string(i + 1);
    b.parent = i - 1;
    b.joint = L.joint;
    b.R_PJ = detail::rot_z(L.theta);
    b.p_PJ = vec3<S>(S(0), S(0), L.d);
    b.axis = vec3<S>::UnitZ();
    b.R_JB = detail::rot_x(L.alpha);
    b.p_JB = vec3<S>(L.a, S(0), S(0));
    b.mass = L.mass;
    b.com = L.com;
    b.inertia = L.inertia;
    b.continuous = L.joint == joint_type::revolute;
    b.armature = L.armature;
    b.set_friction_law(L.friction);
    out.push_back(std::move(b));
  }
  validation v = c.validation_policy();
  return tree<S>(std::move(out), c.gravity(), c.name(), v, "base");
}

/// A chain's body by the name as_tree gives it ("base", "link1" … "link<n>"), as
/// tree::find_frame does for a tree: its 0-based body (−1: the base) and an identity placement.
/// Throws input_error for any other name.
template <class S, int N>
frame<S> find_frame(const chain<S, N>& c, const std::string& name) {
  if (name == "base") return frame<S>{name, -1};
  for (int i = 1; i <= c.dof(); ++i)
    if (name == "link" + std::to_string(i)) return frame<S>{name, i - 1};
  throw input_error("model '" + c.name() + "' has no body '" + name + "' (bodies: base, link1 … link" +
                    std::to_string(c.dof()) + ")");
}
/// tree::find_frame as a free function, so that generic code names chains' and trees' bodies alike.
template <class S>
frame<S> find_frame(const tree<S>& t, const std::string& name) {
  return t.find_frame(name);
}

}  // namespace nhdyn
