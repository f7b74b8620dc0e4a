#pragma once
/// \file dynamics/terms.hpp
/// Which terms of the equations of motion a computation includes, by name — the same names
/// at every interface (C++, the tool's `--terms`, Python's `terms=`, a scene's plant and model "terms"):
///
///     τ = M(q) q̈ + I_a q̈ + C(q, q̇) q̇ + g(q) + τ_f(q̇)
///              ──────── ─────────── ────   ──────
///              armature  velocity   gravity friction
///
/// - `gravity`:  g(q)                 (rne_options::gravity)
/// - `velocity`: C(q, q̇) q̇            (rne_options::velocity)
/// - `armature`: the joints' reflected rotor inertia I_a = G²J_m: I_a q̈ in τ and I_a on M's
///   diagonal (body::armature, link::armature; off: `without_armature(model)`)
/// - `friction`: the joints' viscous and Coulomb friction τ_f(q̇) (the model's laws,
///   dynamics/friction.hpp), by `coulomb` exact or smooth — added to rne's τ
///   (`rne(model) + friction(model)`), and to the bias of the forward dynamics
///   (`forward_dynamics(model).with(friction(model))`).
///
/// The default, `terms{}`, is gravity, velocity and armature: what KDL's and Pinocchio's
/// inverse dynamics compute (Pinocchio's `model.armature`); friction only when asked.
/// The mass-matrix term M(q) q̈ is always in: without it there is no dynamics to speak of.
///
///     const auto t = nhdyn::terms::parse("gravity,velocity,armature,friction");
///     const auto model = nhdyn::with_terms(tree, t);              // armature dropped if off
///     auto id = nhdyn::rne(model, t.rne()) + nhdyn::friction(model, t.coulomb);
#include <sstream>
#include <string>
#include <string_view>

#include "../errors.hpp"
#include "../model/chain.hpp"
#include "../model/tree.hpp"
#include "friction.hpp"
#include "rne.hpp"

namespace nhdyn {

/// The terms a computation includes (see the file comment).
struct terms {
  bool gravity = true;
  bool velocity = true;
  bool armature = true;
  bool friction = false;
  coulomb_law coulomb = {};  ///< how the friction's Coulomb part treats q̇ at and near 0

  /// The names, in this order: gravity, velocity, armature, friction.
  static constexpr std::string_view names[4] = {"gravity", "velocity", "armature", "friction"};

  /// rne's part of the choice.
  rne_options rne() const { return {gravity, velocity}; }

  /// From a comma-separated list of names (any order, each at most once; spaces around a
  /// name ignored): the terms named are in, the others out. "none" (alone) is the empty
  /// set, "all" (alone) every term. An unknown or repeated name, or an empty entry, is an
  /// input_error naming it and listing the names.
  static terms parse(std::string_view list) {
    const auto trim = [](std::string_view s) {
      while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
      while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
      return s;
    };
    const std::string known = "gravity, velocity, armature, friction (or all, or none)";
    const std::string_view whole = trim(list);
    if (whole == "all") return {true, true, true, true};
    if (whole == "none") return {false, false, false, false};
    terms t{false, false, false, false};
    bool* flag[4] = {&t.gravity, &t.velocity, &t.armature, &t.friction};
    bool seen[4] = {false, false, false, false};
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = whole.find(',', start);
      const std::string_view name = trim(whole.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
      if (name.empty())
        throw input_error("terms '" + std::string(list) + "': an empty entry; the terms are " + known);
      int k = 0;
      while (k < 4 && names[k] != name) ++k;
      if (k == 4)
        throw input_error("terms '" + std::string(list) + "': no term named '" + std::string(name) + "'; the terms are " + known);
      if (seen[k]) throw input_error("terms '" + std::string(list) + "': '" + std::string(name) + "' is named twice");
      seen[k] = true;
      *flag[k] = true;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    return t;
  }

  /// The names of the terms that are in, comma-separated ("none" for none).
  std::string list() const {
    std::ostringstream os;
    const bool on[4] = {gravity, velocity, armature, friction};
    bool first = true;
    for (int k = 0; k < 4; ++k)
      if (on[k]) {
        os << (first ? "" : ",") << names[k];
        first = false;
      }
    return first ? "none" : os.str();
  }
  bool operator==(const terms& o) const {
    return gravity == o.gravity && velocity == o.velocity && armature == o.armature && friction == o.friction &&
           coulomb.velocity_scale == o.coulomb.velocity_scale;
  }
};

/// The chain with every joint's armature 0.
template <class S, int N>
chain<S, N> without_armature(const chain<S, N>& c) {
  auto links = c.links();
  for (auto& l : links) l.armature = S(0);
  return chain<S, N>(std::move(links), c.gravity(), c.name(), c.validation_policy());
}
/// The tree with every joint's armature 0 (frames, root and names kept).
template <class S>
tree<S> without_armature(const tree<S>& t) {
  auto bodies = t.bodies();
  for (auto& b : bodies) b.armature = S(0);
  return tree<S>(std::move(bodies), t.gravity(), t.name(), t.validation_policy(), t.root_name(), t.frames());
}
/// The model as the terms want it: itself, or without_armature when armature is out.
template <class Model>
Model with_terms(const Model& m, const terms& t) {
  return t.armature ? m : without_armature(m);
}

}  // namespace nhdyn
