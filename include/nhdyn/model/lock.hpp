#pragma once
/// \file model/lock.hpp
/// Locked joints: `lock(t, {{"hand_*", 0.0}, {"head_1_joint", 0.3}})` is the tree t with the
/// joints named (or matched by a shell-style glob) held at the given positions, their bodies
/// merged into their parents — Pinocchio's buildReducedModel. The smaller tree computes, for
/// the joints it keeps, exactly what the full tree does with the locked joints at their
/// positions and zero rate and acceleration: rne's rows of the kept joints, the kept block of
/// M, and the forward dynamics of the kept joints while the locked ones are held.
///
/// - Patterns: each entry names a joint or is a glob over the whole joint name — `*` any run
///   of characters, `?` one character, `[abc]` / `[a-z]` one of a set, `[!abc]` / `[^abc]`
///   one not in it, `\c` the character c itself. An entry that matches no joint, a joint that
///   two entries match, a position that is not finite: model_error naming them. Locking every
///   joint is allowed and gives a tree of 0 joints.
/// - A locked body i (frames as model/tree.hpp: X_PB(q) = X_PJ · joint(q) · X_JB) is fixed in
///   its parent at X_PB(q_i) and merged, with every locked body between them, into its nearest
///   kept ancestor A (or into the base, A = −1). Its mass, centre of mass and inertia join A's,
///   combined about their common centre of mass in A's body frame, as io/urdf.hpp merges a
///   fixed link; on the base, which is world-fixed, they have no effect and are dropped. Its
///   children hang from A, their X_PJ preceded by the locked body's placement in A. Its body
///   frame, and every frame that was fixed on it, stay named frames of A (of the base: body
///   −1). Its joint's armature, friction, limits and mimic go with it.
/// - Kept bodies keep everything else (limits, friction, armature, mimic — a mimic of a
///   locked joint stays, as information, like every mimic), in their order: the reduced q is
///   the full q's kept entries in order. Name, gravity, validation policy and root name stay.
/// - `lock_map_of(t, locked)` says which joints are kept and which held where, and converts
///   joint vectors between the two trees (`reduce`, `expand_q`, `expand`);
///   `reduced_indices` and `lock_positions` are its two lists; `lock_indices(t, {{i, q_i}})`
///   locks by index.
#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "../errors.hpp"
#include "tree.hpp"
#include "tree_kernel.hpp"

namespace nhdyn {

namespace detail {

/// Whether the character c is one of the bracket expression that starts at pattern[open]
/// ('['); `next` is set to the index after its closing ']'. False with next = npos when the
/// expression is not closed (the '[' is then an ordinary character).
inline bool glob_class(std::string_view pattern, std::size_t open, char c, std::size_t& next) {
  std::size_t j = open + 1;
  bool negate = false;
  if (j < pattern.size() && (pattern[j] == '!' || pattern[j] == '^')) {
    negate = true;
    ++j;
  }
  bool hit = false;
  bool first = true;
  for (; j < pattern.size(); first = false) {
    char lo = pattern[j];
    if (lo == ']' && !first) {
      next = j + 1;
      return hit != negate;
    }
    if (lo == '\\' && j + 1 < pattern.size()) lo = pattern[++j];
    char hi = lo;
    if (j + 2 < pattern.size() && pattern[j + 1] == '-' && pattern[j + 2] != ']') {
      j += 2;
      hi = pattern[j];
      if (hi == '\\' && j + 1 < pattern.size()) hi = pattern[++j];
    }
    if (lo <= c && c <= hi) hit = true;
    ++j;
  }
  next = std::string_view::npos;
  return false;
}

/// Whether pattern[p…] matches one character c at its start; `next` is where the pattern
/// goes on. `*` is handled by the caller.
inline bool glob_one(std::string_view pattern, std::size_t p, char c, std::size_t& next) {
  const char x = pattern[p];
  if (x == '?') {
    next = p + 1;
    return true;
  }
  if (x == '[') {
    const bool hit = glob_class(pattern, p, c, next);
    if (next != std::string_view::npos) return hit;
    // an unclosed '[' is a literal
  }
  if (x == '\\' && p + 1 < pattern.size()) {
    next = p + 2;
    return pattern[p + 1] == c;
  }
  next = p + 1;
  return x == c;
}

/// Shell-style glob matching of a whole name (see the file comment): the iterative matcher
/// that backtracks to the last `*` only, linear in practice and never exponential.
inline bool glob_match(std::string_view pattern, std::string_view name) {
  constexpr auto none = std::string_view::npos;
  std::size_t p = 0, i = 0, star_p = none, star_i = 0;
  while (i < name.size()) {
    if (p < pattern.size()) {
      if (pattern[p] == '*') {
        star_p = ++p;
        star_i = i;
        continue;
      }
      std::size_t next = 0;
      if (glob_one(pattern, p, name[i], next)) {
        p = next;
        ++i;
        continue;
      }
    }
    if (star_p == none) return false;
    p = star_p;  // let the last '*' take one more character
    i = ++star_i;
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

/// The placement (R, p) of body b's frame in its parent's frame with its joint at q:
/// X_PB(q) = X_PJ · joint(q) · X_JB, the joint's motion written as the tree kernels write it
/// (model/tree_kernel.hpp: A·Rz(q)·Aᵀ about the axis, A = align_z(axis); a slide q·axis).
template <class S>
void locked_placement(const body<S>& b, double q, mat3<S>& R, vec3<S>& p) {
  mat3<S> Rj = mat3<S>::Identity();
  vec3<S> pj = vec3<S>::Zero();
  if (b.joint == joint_type::revolute) {
    const mat3<S> A = align_z(b.axis);
    Rj = A * rot_z(S(q)) * A.transpose();
  } else {
    pj = b.axis * S(q);
  }
  R = b.R_PJ * Rj * b.R_JB;
  p = b.p_PJ + b.R_PJ * vec3<S>(pj + Rj * b.p_JB);
}

inline std::string lock_where(const std::string& model) { return "model '" + model + "', lock: "; }

inline std::string lock_number(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

}  // namespace detail

/// Which joints a lock list holds (see the file comment): the kept joints' indices in the full
/// tree and the locked ones' with their positions, both ascending, and the conversions of
/// joint vectors between the full tree and the reduced one.
struct lock_map {
  int full_dof = 0;                            ///< the full tree's joints
  std::vector<int> kept;                       ///< full-tree indices of the kept joints (the reduced q order)
  std::vector<std::pair<int, double>> locked;  ///< (full-tree index, position) of the locked joints
  /// A floating tree's (model/floating.hpp): its q has one entry more than its joint vectors,
  /// the root's quaternion, which reduce and expand_q carry over.
  bool floating = false;

  /// The reduced tree's joints.
  int dof() const { return static_cast<int>(kept.size()); }

  /// The kept entries of a full-tree joint vector (q̇, q̈, τ; or q), in order. A floating
  /// tree's q (full_dof + 1 entries) keeps its seven root entries.
  template <class V>
  Eigen::Matrix<typename V::Scalar, Eigen::Dynamic, 1> reduce(const Eigen::MatrixBase<V>& full) const {
    const int extra = floating && full.size() == full_dof + 1 ? 1 : 0;
    detail::check_size(full, full_dof + extra, "full-tree joint vector");
    Eigen::Matrix<typename V::Scalar, Eigen::Dynamic, 1> out(dof() + extra);
    for (int k = 0; k < dof(); ++k) {
      const int i = kept[static_cast<std::size_t>(k)];
      out(k + (extra && k >= 6 ? 1 : 0)) = full(i + (extra && i >= 6 ? 1 : 0));
    }
    if (extra) out(6) = full(6);
    return out;
  }
  /// The full-tree positions of reduced-tree positions q: the locked joints at their positions.
  /// A floating tree's q has dof() + 1 entries, and so has the result.
  template <class V>
  Eigen::Matrix<typename V::Scalar, Eigen::Dynamic, 1> expand_q(const Eigen::MatrixBase<V>& q) const {
    using T = typename V::Scalar;
    if (floating) {
      detail::check_size(q, dof() + 1, "reduced-tree configuration");
      Eigen::Matrix<T, Eigen::Dynamic, 1> qv(dof());  // q without qw, as a joint vector
      qv << q.head(6), q.tail(dof() - 6);
      const Eigen::Matrix<T, Eigen::Dynamic, 1> e = expand(qv);
      Eigen::Matrix<T, Eigen::Dynamic, 1> out(full_dof + 1);
      out << e.head(6), q(6), e.tail(full_dof - 6);
      for (const auto& [i, x] : locked) out(i + 1) = T(x);
      return out;
    }
    Eigen::Matrix<T, Eigen::Dynamic, 1> out = expand(q);
    for (const auto& [i, x] : locked) out(i) = T(x);
    return out;
  }
  /// The full-tree vector of a reduced-tree rate, acceleration (or any joint vector whose
  /// locked entries are zero): the locked joints' entries zero.
  template <class V>
  Eigen::Matrix<typename V::Scalar, Eigen::Dynamic, 1> expand(const Eigen::MatrixBase<V>& v) const {
    using T = typename V::Scalar;
    detail::check_size(v, dof(), "reduced-tree joint vector");
    Eigen::Matrix<T, Eigen::Dynamic, 1> out(full_dof);
    for (int i = 0; i < full_dof; ++i) out(i) = T(0);
    for (int k = 0; k < dof(); ++k) out(kept[static_cast<std::size_t>(k)]) = v(k);
    return out;
  }
};

/// Resolves a lock list (joint names or globs, each with a position) on tree t; throws
/// model_error for an entry that matches no joint, a joint matched by two entries, or a
/// position that is not finite.
template <class S>
lock_map lock_map_of(const tree<S>& t, const std::vector<std::pair<std::string, double>>& locked) {
  const int n = t.dof();
  const std::string at = detail::lock_where(t.name());
  std::vector<int> by(static_cast<std::size_t>(n), -1);  // the entry that locks joint i
  for (std::size_t e = 0; e < locked.size(); ++e) {
    const auto& [pattern, position] = locked[e];
    if (!std::isfinite(position))
      throw model_error(at + "the position of '" + pattern + "' is not finite (" + detail::lock_number(position) + ")");
    bool any = false;
    for (int i = 0; i < n; ++i) {
      if (t[i].free_flyer) {  // a floating base's coordinates are not joints: a glob passes them by
        if (pattern == t[i].joint_name)
          throw model_error(at + "'" + pattern + "' is a coordinate of the floating base, which cannot be locked");
        continue;
      }
      if (!detail::glob_match(pattern, t[i].joint_name)) continue;
      any = true;
      int& owner = by[static_cast<std::size_t>(i)];
      if (owner >= 0)
        throw model_error(at + "joint '" + t[i].joint_name + "' is matched by both '" +
                          locked[static_cast<std::size_t>(owner)].first + "' and '" + pattern +
                          "' (each joint is locked by one entry)");
      owner = static_cast<int>(e);
    }
    if (!any) {
      std::string known;
      for (int i = 0; i < n; ++i)
        if (!t[i].free_flyer) known += (known.empty() ? "" : ", ") + t[i].joint_name;
      throw model_error(at + "'" + pattern + "' matches no movable joint (movable joints: " +
                        (known.empty() ? std::string("none") : known) + ")");
    }
  }
  lock_map m;
  m.full_dof = n;
  m.floating = t.floating();
  for (int i = 0; i < n; ++i) {
    const int e = by[static_cast<std::size_t>(i)];
    if (e < 0)
      m.kept.push_back(i);
    else
      m.locked.emplace_back(i, locked[static_cast<std::size_t>(e)].second);
  }
  return m;
}

/// The kept joints' indices in the full tree, in the reduced tree's q order.
template <class S>
std::vector<int> reduced_indices(const tree<S>& t, const std::vector<std::pair<std::string, double>>& locked) {
  return lock_map_of(t, locked).kept;
}

/// The locked joints' indices in the full tree with their positions, ascending.
template <class S>
std::vector<std::pair<int, double>> lock_positions(const tree<S>& t,
                                                   const std::vector<std::pair<std::string, double>>& locked) {
  return lock_map_of(t, locked).locked;
}

/// The tree t with the joints of the given full-tree indices held at the given positions
/// (see the file comment); throws model_error for an index out of range, given twice, or a
/// position that is not finite.
template <class S>
tree<S> lock_indices(const tree<S>& t, const std::vector<std::pair<int, double>>& locked) {
  const int n = t.dof();
  const std::string at = detail::lock_where(t.name());
  std::vector<std::optional<double>> held(static_cast<std::size_t>(n));
  for (const auto& [i, x] : locked) {
    if (i < 0 || i >= n)
      throw model_error(at + "joint index " + std::to_string(i) + " is outside 0…" + std::to_string(n - 1));
    if (!std::isfinite(x))
      throw model_error(at + "the position of joint '" + t[i].joint_name + "' is not finite (" +
                        detail::lock_number(x) + ")");
    if (held[static_cast<std::size_t>(i)])
      throw model_error(at + "joint '" + t[i].joint_name + "' is locked twice");
    if (t[i].free_flyer)
      throw model_error(at + "'" + t[i].joint_name + "' is a coordinate of the floating base, which cannot be locked");
    held[static_cast<std::size_t>(i)] = x;
  }

  // Where each full-tree body's frame is: on which reduced-tree body (−1: the base), and at
  // which placement in that body's frame (`moved` false: the identity, a kept body itself).
  struct placed {
    int body = -1;
    bool moved = false;
    mat3<S> R = mat3<S>::Identity();
    vec3<S> p = vec3<S>::Zero();
  };
  const placed base{};
  std::vector<placed> where(static_cast<std::size_t>(n));
  std::vector<body<S>> bodies;
  std::vector<frame<S>> merged;  // the locked bodies' own frames, in body order
  for (int i = 0; i < n; ++i) {
    const body<S>& b = t[i];
    const placed& up = b.parent < 0 ? base : where[static_cast<std::size_t>(b.parent)];
    placed& here = where[static_cast<std::size_t>(i)];
    if (!held[static_cast<std::size_t>(i)]) {  // kept: hangs from the surviving ancestor
      body<S> k = b;
      k.parent = up.body;
      if (up.moved) {
        k.R_PJ = up.R * b.R_PJ;
        k.p_PJ = up.p + up.R * b.p_PJ;
      }
      bodies.push_back(std::move(k));
      here.body = static_cast<int>(bodies.size()) - 1;
      continue;
    }
    // locked: its frame fixed in its parent's, then in the surviving ancestor's
    mat3<S> R;
    vec3<S> p;
    detail::locked_placement(b, *held[static_cast<std::size_t>(i)], R, p);
    here.body = up.body;
    here.moved = true;
    if (up.moved) {
      here.R = up.R * R;
      here.p = up.p + up.R * p;
    } else {
      here.R = R;
      here.p = p;
    }
    merged.push_back(frame<S>{b.name, here.body, here.R, here.p});
    if (here.body >= 0)  // on the base (world-fixed) its inertia has no effect
      detail::merge_rigid_body(bodies[static_cast<std::size_t>(here.body)], b.mass,
                               vec3<S>(here.R * b.com + here.p), mat3<S>(here.R * b.inertia * here.R.transpose()));
  }

  std::vector<frame<S>> frames;
  frames.reserve(t.frames().size() + merged.size());
  for (const frame<S>& f : t.frames()) {
    if (0 > f.body) {  // not `f.body < 0`: `body <` would open the template body<S>
      frames.push_back(f);
      continue;
    }
    const placed& on = where[static_cast<std::size_t>(f.body)];
    if (on.moved)
      frames.push_back(frame<S>{f.name, on.body, mat3<S>(on.R * f.R), vec3<S>(on.p + on.R * f.p)});
    else
      frames.push_back(frame<S>{f.name, on.body, f.R, f.p});
  }
  for (auto& f : merged) frames.push_back(std::move(f));
  // needs tree<S> to accept 0 bodies (every joint locked)
  return tree<S>(std::move(bodies), t.gravity(), t.name(), t.validation_policy(), t.root_name(), std::move(frames));
}

/// The tree t with the joints that `locked` names or globs held at the given positions (see
/// the file comment): `nhdyn::lock(t, {{"hand_*", 0.0}, {"head_1_joint", 0.3}})`.
template <class S>
tree<S> lock(const tree<S>& t, const std::vector<std::pair<std::string, double>>& locked) {
  return lock_indices(t, lock_map_of(t, locked).locked);
}

}  // namespace nhdyn
