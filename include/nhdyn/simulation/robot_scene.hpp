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
#include <algorithm>
#include <concepts>
#include <string>
#include <variant>

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
/// and the body frame's offset from the joint (p_JB; zero for URDFs, a for DH models).
inline tree<double> with_length_factors(const tree<double>& t, const std::vector<std::pair<std::string, double>>& factors,
                                        const std::string& where) {
  if (factors.empty()) return t;
  std::vector<body<double>> B(t.begin(), t.end());
  for (const auto& [name, f] : factors) {
    const auto it = std::find_if(B.begin(), B.end(), [&](const auto& b) { return b.joint_name == name; });
    if (it == B.end())
      throw input_error(where + "no movable joint named '" + name + "' for a length factor (joints: " +
                        detail::names_of(t, true) + ")");
    it->p_PJ *= f;
    it->p_JB *= f;
  }
  return tree<double>(std::move(B), t.gravity(), t.name(), t.validation_policy(), t.root_name(), t.frames());
}

/// The robot a scene names (not paper5, which `simulate` runs): a preset, a URDF, a robot file
/// or a JSON model, as a tree with its optional constraint.
inline io::robot_model load_scene_robot(const std::string& robot) {
  const auto presets = io::preset_names();
  std::string ext = std::filesystem::path(robot).extension().string();
  for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (ext == ".urdf") {
    io::robot_model r{io::load_urdf(robot), std::nullopt, ""};
    r.name = r.model.name();
    r.path = robot;
    return r;
  }
  const bool preset = std::find(presets.begin(), presets.end(), robot) != presets.end();
  if (!preset) {
    std::ifstream in(robot);
    if (const auto j = nlohmann::json::parse(in, nullptr, false); j.is_object() && j.contains("urdf")) return io::load_robot_file(robot);
  }
  const io::model<double> m = io::load<double>(robot);
  io::robot_model r{as_tree(m.chain), std::nullopt, m.chain.name()};
  if (m.constraint) r.constraint = *m.constraint;
  r.path = robot;
  return r;
}

/// One run of a scene on its robot (see the file comment). Throws for a scene that cannot be
/// set up (unknown frame or joint, wrong sizes, a controller that does not fit its
/// reference). A function object, as `simulate`: the closed loops (one per constraint type)
/// are compiled only where it is called.
struct simulate_scene_fn {
  template <std::same_as<run_spec> Spec>
  run_result operator()(const Spec& s) const {
    if (s.robot == "paper5") return simulate(s);
    return detail::timed([&] {  // the times include loading the robot
      const std::string where = "scene '" + s.name + "': ";
      const io::robot_model r = load_scene_robot(s.robot);
      const int n = r.model.dof(), m = n - r.k();
      detail::check_reference(s, n);
      const tree<double> plant = with_mass_factors(with_length_factors(r.model, s.plant_length, where + "plant: "),
                                                   s.plant_mass, where + "plant: ");
      const tree<double> nominal = with_mass_factors(with_length_factors(r.model, s.model_length, where + "model: "),
                                                     s.model_mass, where + "model: ");
      const auto f = r.model.find_frame(s.task_frame);  // throws naming the frame and the known ones
      const vec3<double> point = f.R * s.task_point + f.p;
      const int body = f.body + 1;
      if (body < 1)
        throw input_error(where + "field 'task.frame': '" + s.task_frame + "' is fixed to the world; name a moving body");
      const auto sized = [&](const Eigen::VectorXd& v, int size, const char* what) {
        if (v.size() == 0) return Eigen::VectorXd(Eigen::VectorXd::Zero(size));
        if (v.size() != size)
          throw input_error(where + "field 'initial." + what + "' has " + std::to_string(v.size()) + " entries, robot '" +
                            r.name + "' needs " + std::to_string(size));
        return v;
      };
      const Eigen::VectorXd q0 = sized(s.q_start, n, "q"), eta0 = sized(s.eta_start, m, "eta");
      Eigen::VectorXd mask = Eigen::VectorXd::Zero(n);
      const auto joints = r.model.joint_names();
      for (const auto& j : s.posture_joints) {
        const auto it = std::find(joints.begin(), joints.end(), j);
        if (it == joints.end())
          throw input_error(where + "field 'controller.posture_joints': no joint '" + j + "' (joints: " +
                            detail::names_of(r.model, true) + ")");
        mask(it - joints.begin()) = 1;
      }
      const tree_kinematics<double> model_kin(nominal);
      const scene_reference ref(s.reference, model_kin, body, point);
      const auto run = [&](const auto& c_plant, const auto& c_model) {
        using C = std::decay_t<decltype(c_plant)>;
        using Ctrl = any_controller<double, dynamic, C, tree<double>>;
        const Ctrl ctrl = s.controller == controller_type::task_space
                              ? Ctrl(rac_controller(nominal, c_model, s.gains, q0, mask, body, point))
                              : Ctrl(computed_torque_controller(nominal, c_model, s.ct));
        return simulate_robot(s.name, plant, c_plant, body, point, ctrl, ref, q0, eta0, options_of(s), r.eta_names());
      };
      if (!r.constraint) {
        if (s.plant_wheel_radius != 1 || s.model_wheel_radius != 1)
          throw input_error(where + "field 'wheel_radius_factor': robot '" + r.name + "' has no constraint (no wheels)");
        return run(holonomic<dynamic>{n}, holonomic<dynamic>{n});
      }
      // The constraint of each tree (its geometry follows the link lengths), with its wheel radius.
      const auto constraint_of = [&](const tree<double>& t, double radius_factor, const char* who) {
        io::robot_constraint c = *io::constraint_on(r, t);
        if (radius_factor != 1) {
          auto* w = std::get_if<rolling_wheels<double>>(&c);
          if (!w)
            throw input_error(where + who + ".wheel_radius_factor: robot '" + r.name +
                              "' has no wheel radius (its constraint is not of type 'wheels')");
          w->radius *= radius_factor;
        }
        return c;
      };
      const io::robot_constraint c_model = constraint_of(nominal, s.model_wheel_radius, "model");
      return std::visit(
          [&](const auto& c_plant) { return run(c_plant, std::get<std::decay_t<decltype(c_plant)>>(c_model)); },
          constraint_of(plant, s.plant_wheel_radius, "plant"));
    });
  }
};
inline constexpr simulate_scene_fn simulate_scene{};

}  // namespace nhdyn
