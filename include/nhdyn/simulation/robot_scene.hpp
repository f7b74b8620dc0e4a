#pragma once
/// \file simulation/robot_scene.hpp
/// Runs a scene (run_spec) on the robot it names: paper5 by `simulate` (simulation.hpp), a
/// robot file (io/robot_file.hpp: a URDF with its wheeled base and constraint) by
/// `simulate_robot`. Needs nhdyn::urdf (urdfdom), as robot files do.
///
///     auto runs = nhdyn::scene::expand(nhdyn::scene::load("robot-circle"));
///     nhdyn::run_result r = nhdyn::simulate_scene(runs[0]);
///
/// What a robot-file scene sets (docs/simulation.md, "Any robot"): the task frame (a body or
/// frame name and a point in it), the initial state (q with n entries, η with m; zeros by
/// default), the joints the posture term holds (by name), and the plant's and the model's
/// mass factors by body name (each scales the body's mass and rotational inertia, so its
/// centre of mass stays where it is).
#include <algorithm>
#include <concepts>
#include <string>
#include <variant>

#include "../io/robot_file.hpp"
#include "simulation.hpp"

namespace nhdyn {

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
      std::string known;
      for (const auto& b : B) known += (known.empty() ? "" : ", ") + b.name;
      throw input_error(where + "no body named '" + name + "' for a mass factor (bodies: " + known + ")");
    }
  }
  return tree<double>(std::move(B), t.gravity(), t.name());
}

/// One run of a scene on its robot (see the file comment). Throws for a scene that cannot be
/// set up (unknown frame or joint, wrong sizes, a robot file without a constraint). A function
/// object, as `simulate`: the closed loops (one per constraint type) are compiled only where
/// it is called.
struct simulate_scene_fn {
  template <std::same_as<run_spec> Spec>
  run_result operator()(const Spec& s) const {
    if (s.robot == "paper5") return simulate(s);
    return detail::timed([&] {  // the times include loading the robot
      const std::string where = "scene '" + s.name + "': ";
      const io::robot_model r = io::load_robot_file(s.robot);
      if (!r.constraint)
        throw input_error(where + "robot file '" + s.robot +
                          "' has no constraint: the task-space controller drives a wheeled robot (give the file a \"constraint\")");
      const tree<double> plant = with_mass_factors(r.model, s.plant_mass, where + "plant: ");
      const tree<double> nominal = with_mass_factors(r.model, s.model_mass, where + "model: ");
      const int n = r.model.dof(), m = n - r.k();
      const auto f = r.model.find_frame(s.task_frame);  // throws naming the frame and the known ones
      const vec3<double> point = f.R * s.task_point + f.p;
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
        if (it == joints.end()) {
          std::string known;
          for (const auto& k : joints) known += (known.empty() ? "" : ", ") + k;
          throw input_error(where + "field 'controller.posture_joints': no joint '" + j + "' (joints: " + known + ")");
        }
        mask(it - joints.begin()) = 1;
      }
      return std::visit(
          [&](const auto& c) {
            return simulate_robot(s.name, plant, nominal, c, f.body + 1, point, s.reference, s.gains, q0, eta0, mask,
                                  options_of(s), r.eta_names());
          },
          *r.constraint);
    });
  }
};
inline constexpr simulate_scene_fn simulate_scene{};

}  // namespace nhdyn
