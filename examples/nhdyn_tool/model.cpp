/// \file model.cpp
/// `nhdyn model`: one JSON object describing a model, so that a program can line its vectors
/// up with it: name, dof, joint names in q order, the names of η's entries, k, gravity.
#include <iostream>
#include <nhdyn/nhdyn.hpp>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
const std::string usage = std::string(R"(nhdyn model --model MODEL [--strict] [--lock 'NAME=POS,...']
  Prints one JSON object describing MODEL:
    {"name": ..., "dof": n, "nq": nq, "nv": n, "joints": [n names], "eta": [m names],
     "tau": [p names], "k": k, "gravity": [gx, gy, gz]}
  nq is q's length, nv (= dof) that of qd, qdd and tau. They differ for a floating base (a
  robot file's "base": {"type": "floating"}, or a URDF whose root link floats): q is then
  (x, y, z, qx, qy, qz, qw, joints) -- the root link's position and unit quaternion -- and
  qd = (v, omega, joint rates) its velocity in its own frame; "base": "floating" and
  "q": [nq names] are added, and joints begins with root_x, root_y, root_z, root_rx,
  root_ry, root_rz (the entries of qd and tau: tau's first six are the root's force and
  moment in its frame).
  eta names the entries of eta, the independent velocities of a model with a constraint
  ("v" forward speed, "omega" yaw rate, or joint names: the wheel or steering joints of a
  wheels or bicycle constraint, a wheeled_base's choice, the other joints); tau names the
  actuators, tau's entries (eta's names, except for a wheeled_base: its actuated joints).
  Without a constraint eta and tau are the joint names and k is 0. A wheeled_base adds
    "lambda": [k names: <spin joint>.lateral, .rolling or .roller, the rows kept],
    "mobility": {"degree_of_mobility": dm, "degree_of_steerability": ds[, "note": ...]}
  (Campion's degrees: the base's motions at fixed steering, the independent steering
  directions; the note says when the base cannot move or moves only along a line). A model
  with locked joints (--lock, a robot file's "locked") adds "locked": {joint: position}.
  DH models name their joints joint1...jointn; a URDF's joints keep their names, movable
  joints only, in the documented order (docs/trees-and-urdf.md); a robot file's planar base
  adds base_x, base_y, base_yaw in front.
)") + std::string(model_options_help);

/// q's entry names: the joints', a floating base's seven (x, y, z and the quaternion) first.
std::vector<std::string> q_names(const std::vector<std::string>& joints) {
  std::vector<std::string> q{"root_x", "root_y", "root_z", "root_qx", "root_qy", "root_qz", "root_qw"};
  q.insert(q.end(), joints.begin() + 6, joints.end());
  return q;
}

ordered_json describe(const std::string& name, const std::vector<std::string>& joints, const std::vector<std::string>& eta,
                      const std::vector<std::string>& tau, int k, const Eigen::Vector3d& g, bool floating = false) {
  ordered_json j;
  j["name"] = name;
  j["dof"] = joints.size();
  j["nq"] = joints.size() + (floating ? 1 : 0);
  j["nv"] = joints.size();
  if (floating) {
    j["base"] = "floating";
    j["q"] = q_names(joints);
  }
  j["joints"] = joints;
  j["eta"] = eta;
  j["tau"] = tau;
  j["k"] = k;
  j["gravity"] = to_json(Eigen::VectorXd(g));
  return j;
}

int run(const std::vector<std::string>& args) {
  const auto model = start_any_model_command(args, usage);
  if (!model) return 0;  // --help
  ordered_json out;
  if (model->tree) {
    const auto& t = *model->tree;
    const auto joints = t.joint_names();
    if (model->tree_constraint) {  // a robot file's constraint names η's and τ's entries
      std::visit(
          [&](const auto& c) {
            const auto eta = c.eta_names(joints);
            out = describe(model->name(), joints, eta, nhdyn::tau_names_of(c, joints, eta), c.k(), t.gravity());
            if constexpr (requires { c.mobility(); }) {
              out["lambda"] = c.lambda_names();
              ordered_json mob;
              mob["degree_of_mobility"] = c.mobility();
              mob["degree_of_steerability"] = c.steerability();
              if (!c.mobility_note().empty()) mob["note"] = c.mobility_note();
              out["mobility"] = mob;
            }
          },
          *model->tree_constraint);
    } else {
      out = describe(model->name(), joints, joints, joints, 0, t.gravity(), t.floating());
    }
    if (!model->locked.empty()) {  // what was held, in the full model's q order
      ordered_json held = ordered_json::object();
      for (const auto& [name, x] : model->locked) held[name] = x;
      out["locked"] = held;
    }
  } else {
    const auto& m = *model->dh;
    const auto joints = nhdyn::as_tree(m.chain).joint_names();
    std::vector<std::string> eta = joints;
    int k = 0;
    if (m.constraint) {
      const auto& c = *m.constraint;
      eta = c.eta_names(joints);
      k = c.k();
    }
    out = describe(m.chain.name(), joints, eta, eta, k, m.chain.gravity());
  }
  std::cout << nhdyn::io::dump(out) << '\n';
  return 0;
}
}  // namespace

command command_model() { return {"model", "describe a model: name, dof, joint, eta and tau names, k, gravity", usage, run}; }

}  // namespace nhdyn_tool
