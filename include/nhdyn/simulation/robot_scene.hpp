#pragma once
/// \file simulation/robot_scene.hpp
/// Runs a scene (run_spec) on the robot it names: paper5 by `simulate` (simulation.hpp, DH
/// kernels, fixed sizes); any other model — a preset, a JSON model, a URDF (fixed base, no
/// constraint) or a robot file (io/robot_file.hpp: a URDF with its wheeled base and
/// constraint) — as a tree by `simulate_robot`. Needs nhdyn::urdf (urdfdom), as URDFs do.
///
///     auto runs = nhdyn::scene::expand(nhdyn::scene::load("robot-circle"));
///     nhdyn::run_result r = nhdyn::simulate_scene(runs[0]);
///
/// What such a scene sets (docs/simulation.md, "Any robot"): the task frame (a body or frame
/// name and a point in it), the initial state (q with n entries, η with m; zeros by default),
/// the joints the posture term holds (by name), and the plant's and the model's factors: on a
/// body's mass (its rotational inertia scaled with it, so its centre of mass stays), on a
/// joint's placement (the joint's origin in its parent; for a DH model d and a of that link)
/// and on the constraint's wheel radius. A model without a constraint is holonomic (S = I).
/// The terms of each (run_spec::plant_terms, model_terms; dynamics/terms.hpp): the plant's
/// forward dynamics and the controller's inverse dynamics include those, and paper5 with
/// terms other than the default runs here as a tree rather than by `simulate`.
#include <algorithm>
#include <cctype>
#include <concepts>
#include <filesystem>
#include <fstream>
#include <string>
#include <variant>

#include "../config.hpp"
#include "../detail/compiled_abi.hpp"
#include "../constraints/holonomic.hpp"
#include "../io/robot_file.hpp"
#include "simulation.hpp"

namespace nhdyn {

namespace detail {
inline std::string names_of(const tree<double>& t, bool joints) {
  std::string known;
  for (const auto& b : t) known += (known.empty() ? "" : ", ") + (joints ? b.joint_name : b.name);
  return known;
}
}  // namespace detail

/// t with the masses (and rotational inertias) of the named bodies scaled.
inline tree<double> with_mass_factors(const tree<double>& t, const std::vector<std::pair<std::string, double>>& factors,
                                      const std::string& where) {
  if (factors.empty()) return t;
  std::vector<body<double>> B(t.begin(), t.end());
  for (const auto& [name, f] : factors) {
    bool found = false;
    for (auto& b : B)
      if (b.name == name) {
        b.mass *= f;
        b.inertia *= f;
        found = true;
      }
    if (!found) {
      for (const auto& fr : t.frames())
        if (fr.name == name && fr.body >= 0)
          throw input_error(where + "'" + name + "' is merged into body '" + t[fr.body].name +
                            "' by a fixed joint: give that body a mass factor (it carries both)");
      throw input_error(where + "no body named '" + name + "' for a mass factor (bodies: " + detail::names_of(t, false) + ")");
    }
  }
  return tree<double>(std::move(B), t.gravity(), t.name(), t.validation_policy(), t.root_name(), t.frames());
}

/// t with the placements of the named joints scaled: the joint's origin in its parent (p_PJ)
/// and the body frame's offset from the joint (p_JB; zero for URDFs, a for DH models). The
/// body's centre of mass and inertia stay where they are in its frame (paper5's own length
/// factors, which also move the box's mass, are another model). A joint whose placement is
/// zero (a planar base's joints) has no length to scale: an error.
inline tree<double> with_length_factors(const tree<double>& t, const std::vector<std::pair<std::string, double>>& factors,
                                        const std::string& where) {
  if (factors.empty()) return t;
  std::vector<body<double>> B(t.begin(), t.end());
  for (const auto& [joint, f] : factors) {
    const std::string& name = joint;  // (clang 14 cannot capture a structured binding)
    const auto it = std::find_if(B.begin(), B.end(), [&](const auto& b) { return b.joint_name == name; });
    if (it == B.end())
      throw input_error(where + "no movable joint named '" + name + "' for a length factor (joints: " +
                        detail::names_of(t, true) + ")");
    if (it->p_PJ.norm() == 0 && it->p_JB.norm() == 0)
      throw input_error(where + "joint '" + name + "' sits at its parent's origin: no placement length to scale");
    it->p_PJ *= f;
    it->p_JB *= f;
  }
  return tree<double>(std::move(B), t.gravity(), t.name(), t.validation_policy(), t.root_name(), t.frames());
}

namespace detail {
/// A scene's robot set up as trees (see the file comment): plant and nominal model, the
/// constraint of each (none: holonomic), the task body (1-based) and point, the initial
/// state, the posture mask and η's names. paper5 here is `as_tree` of its chains. Each tree
/// is as its terms want it (armature 0 when out, gravity zero when out: model_with_terms);
/// the velocity and friction terms are the computations' (simulate_robot, scene_controller).
struct scene_setup {
  std::string robot;
  tree<double> plant, nominal;
  std::optional<io::robot_constraint> c_plant, c_model;
  int body = 0;
  vec3<double> point = vec3<double>::Zero();
  Eigen::VectorXd q0, eta0, mask;
  std::vector<std::string> eta_names;
};

/// The set-up of scene s (throws for one that cannot be set up). In nhdyn::compiled: its body
/// instantiates every constraint type's construction (wheeled_base's SVD among them), 7.7 s of
/// g++'s time at -O1. A template (Spec is run_spec), so that header-only it is compiled only
/// in the files that run a scene, not in every file that includes this header.
template <std::same_as<run_spec> Spec>
scene_setup setup_scene(const Spec& s);
#if NHDYN_DEFINES(NHDYN_PART_SIMULATION)
template <std::same_as<run_spec> Spec>
scene_setup setup_scene(const Spec& s) {
  const std::string where = "scene '" + s.name + "': ";
  scene_setup out;
  // the trees as their terms want them (after everything else read them: the constraints, frames)
  const auto apply_terms = [&](scene_setup& o) {
    if (!(s.plant_terms == terms{})) o.plant = model_with_terms(o.plant, s.plant_terms);
    if (!(s.model_terms == terms{})) o.nominal = model_with_terms(o.nominal, s.model_terms);
    return std::move(o);
  };
  if (s.robot == "paper5") {
    detail::check_reference(s, 5);
    const differential_drive<double> c = *io::preset<double>("paper5").constraint;
    out.robot = "paper5";
    out.plant = as_tree(presets::paper5<double>(s.plant).chain);
    out.nominal = as_tree(presets::paper5<double>(s.model).chain);
    out.c_plant = out.c_model = c;
    out.body = 5;
    out.q0 = s.q0, out.eta0 = s.eta0, out.mask = s.posture_mask;
    out.eta_names = c.eta_names(out.plant.joint_names());
    return apply_terms(out);
  }
  const io::robot_model r = io::lock_robot(io::load_robot(s.robot), s.locked, where + "field 'locked': ");
  if (r.model.floating())
    throw input_error(where + "field 'robot': '" + r.name + "' has a floating base, which scenes do not take yet");
  const int n = r.model.dof(), m = n - r.k();
  out.robot = r.name;
  detail::check_reference(s, n);
  out.plant = with_mass_factors(with_length_factors(r.model, s.plant_length, where + "plant: "), s.plant_mass, where + "plant: ");
  out.nominal = with_mass_factors(with_length_factors(r.model, s.model_length, where + "model: "), s.model_mass, where + "model: ");
  const auto f = r.model.find_frame(s.task_frame);  // throws naming the frame and the known ones
  out.point = f.R * s.task_point + f.p;
  out.body = f.body + 1;
  if (out.body < 1) throw input_error(where + "field 'task.frame': '" + s.task_frame + "' is fixed to the world; name a moving body");
  const auto sized = [&](const Eigen::VectorXd& v, int size, const char* what) {
    if (v.size() == 0) return Eigen::VectorXd(Eigen::VectorXd::Zero(size));
    if (v.size() != size)
      throw input_error(where + "field 'initial." + what + "' has " + std::to_string(v.size()) + " entries, robot '" + r.name +
                        "' needs " + std::to_string(size));
    return v;
  };
  out.q0 = sized(s.q_start, n, "q"), out.eta0 = sized(s.eta_start, m, "eta");
  out.mask = Eigen::VectorXd::Zero(n);
  const auto joints = r.model.joint_names();
  for (const auto& j : s.posture_joints) {
    const auto it = std::find(joints.begin(), joints.end(), j);
    if (it == joints.end())
      throw input_error(where + "field 'controller.posture_joints': no joint '" + j + "' (joints: " + detail::names_of(r.model, true) + ")");
    out.mask(it - joints.begin()) = 1;
  }
  out.eta_names = r.eta_names();
  if (!r.constraint) {
    if (s.plant_wheel_radius != 1 || s.model_wheel_radius != 1)
      throw input_error(where + "field '" + (s.plant_wheel_radius != 1 ? "plant" : "model") +
                        ".wheel_radius_factor': robot '" + r.name + "' has no constraint (no wheels)");
    return apply_terms(out);
  }
  // The constraint of each tree (its geometry follows the link lengths), with its wheel radius.
  const auto constraint_of = [&](const tree<double>& t, double radius_factor, const std::string& who) {
    io::robot_constraint c = [&] {
      try {
        return *io::constraint_on(r, t);
      } catch (const std::exception& e) {  // e.g. one wheel moved off the common axle
        throw input_error(where + who + " (its length factors): " + e.what());
      }
    }();
    if (radius_factor != 1) {
      if (auto* w = std::get_if<rolling_wheels<double>>(&c))
        w->radius *= radius_factor;
      else if (auto* b = std::get_if<wheeled_base<double>>(&c))
        *b = b->with_radius_factor(radius_factor);  // every wheel's radius
      else
        throw input_error(where + "field '" + who + ".wheel_radius_factor': robot '" + r.name +
                          "' has no wheel radius (its constraint is not of type 'wheels' or 'wheeled_base')");
    }
    return c;
  };
  out.c_plant = constraint_of(out.plant, s.plant_wheel_radius, "plant");
  out.c_model = constraint_of(out.nominal, s.model_wheel_radius, "model");
  return apply_terms(out);
}
#endif
}  // namespace detail

/// One run of a scene on its robot as a tree (paper5 included) with the controller
/// `make(nominal, c, body, point, q0, posture_mask)` returns for the nominal tree and its
/// constraint c (`holonomic<dynamic>` for a model without one): a user's controller in a
/// scene's set-up. The plant runs with its terms (run_spec::plant_terms); `nominal` has the
/// model's armature and gravity terms applied (its velocity and friction terms are for
/// `make` to honour: scene_controller does). Throws for a scene that cannot be set up.
template <class Make>
run_result simulate_scene_with(const run_spec& s, const Make& make) {
  return detail::timed([&] {  // the times include loading the robot
    const detail::scene_setup S = detail::setup_scene(s);
    const tree_kinematics<double> model_kin(S.nominal);
    const scene_reference ref(s.reference, model_kin, S.body, S.point);
    const auto run = [&](const auto& c_plant, const auto& c_model) {
      const auto ctrl = make(S.nominal, c_model, S.body, S.point, S.q0, S.mask);
      return simulate_robot(s.name, S.plant, c_plant, S.body, S.point, ctrl, ref, S.q0, S.eta0, options_of(s), S.eta_names,
                            s.plant_terms);
    };
    if (!S.c_plant) return run(holonomic<dynamic>{S.plant.dof()}, holonomic<dynamic>{S.plant.dof()});
    return std::visit([&](const auto& c) { return run(c, std::get<std::decay_t<decltype(c)>>(*S.c_model)); }, *S.c_plant);
  });
}

/// The controller a scene names (controller.type) for the nominal tree and constraint c, with
/// the model's velocity term (rne_options) and, when in, its friction (the nominal tree's
/// joints' laws) from run_spec::model_terms.
struct scene_controller {
  const run_spec& s;
  template <class C>
  any_controller<double, dynamic, C, tree<double>> operator()(const tree<double>& nominal, const C& c, int body,
                                                             const vec3<double>& point, const Eigen::VectorXd& q0,
                                                             const Eigen::VectorXd& mask) const {
    using Ctrl = any_controller<double, dynamic, C, tree<double>>;
    const rne_options o = s.model_terms.rne();
    if (s.controller == controller_type::task_space)
      return Ctrl(rac_controller(nominal, c, s.gains, q0, mask, body, point, o, detail::friction_with_terms(nominal, s.model_terms)));
    return Ctrl(computed_torque_controller(nominal, c, s.ct, o, detail::friction_with_terms(nominal, s.model_terms)));
  }
};

/// One run of a scene on its robot (see the file comment): paper5 by `simulate` (DH kernels,
/// fixed sizes) when its terms are the default, any other robot (and paper5 with other terms,
/// as a tree) by simulate_scene_with and the scene's controller. Throws
/// for a scene that cannot be set up (unknown frame or joint, wrong sizes, a controller that
/// does not fit its reference). A function object, as `simulate`: the closed loops (one per
/// constraint type) are compiled only where it is called, or once in nhdyn::compiled
/// (config.hpp), which a program linking it calls instead.
struct simulate_scene_fn {
  template <std::same_as<run_spec> Spec>
  run_result operator()(const Spec& s) const;
};
template <std::same_as<run_spec> Spec>
run_result simulate_scene_fn::operator()(const Spec& s) const {  // not inline: extern template below
  if (s.robot == "paper5" && s.plant_terms == terms{} && s.model_terms == terms{}) return simulate(s);
  return simulate_scene_with(s, scene_controller{s});
}
#if !NHDYN_DEFINES(NHDYN_PART_SIMULATION)
extern template run_result simulate_scene_fn::operator()<run_spec>(const run_spec&) const;
#endif
inline constexpr simulate_scene_fn simulate_scene{};

}  // namespace nhdyn
