/// \file id.cpp
/// `nhdyn id`: inverse dynamics on JSON lines. Holonomic models: τ = rne(q, q̇, q̈).
/// Models with a constraint: (τ, λ) = inverse_dynamics_with_forces(q, η, η̇), i.e. the
/// projection of rne ∘ lift (paper eqs. 18–19) and λ = (AAᵀ)⁻¹A(v − Eτ).
#include <iostream>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/nhdyn.hpp>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
constexpr std::string_view usage = R"(nhdyn id --model MODEL [--strict] [--lock 'NAME=POS,...']
  Inverse dynamics. Reads JSON lines on stdin, writes one JSON line per input line.
  Model without a constraint (n joints):
    {"q": [n], "qd": [n], "qdd": [n]}        ->  {"tau": [n]}         tau = rne(q, qd, qdd)
  Model with a constraint (m = n - k independent velocities, p actuators; paper5:
  eta = (v, omega, qd4, qd5), p = m):
    {"q": [n], "eta": [m], "eta_dot": [m]}   ->  {"tau": [p], "lambda": [k]}
  A URDF model is a tree without a constraint (the first form; q in `nhdyn model` order); a
  robot file with a constraint takes the second form (eta, tau and lambda as `nhdyn model`
  names them). With more actuators than eta has entries (a wheeled_base: four mecanum wheels
  driving three base velocities) tau is the one of least weighted norm that produces the motion.
  Either form takes an optional "f_ext": external wrenches on bodies, each
    {"body": NAME, "frame": "world" | "body", "point": [3], "force": [3], "moment": [3]}
  (the environment's force [N] and moment [N m] about the point on the body; point in the
  body's frame [m]; force and moment in the world's or the body's axes; DH models name their
  bodies link1 ... linkN). tau (and lambda) are then what balances them as well.
  Keys must be exactly those of the model's form; anything else is an error line.
  --strict: a URDF inertia that is not physically valid is an error instead of a warning.
  --lock 'NAME=POS,GLOB=POS,...': hold those joints (URDF joint names or shell globs: *, ?,
    [..]) at the positions [rad or m], their links merged into their parents; the model then
    has the other joints only (URDF files and robot files; a constraint's joints cannot be
    locked; `nhdyn model` lists what was locked).
)";

/// Lines of a model with a constraint: (q, η, η̇) -> (τ, λ).
template <class Model, class C>
int constrained(const Model& model, const C& c, const std::string& name) {
  const auto id = nhdyn::inverse_dynamics_with_forces(model, c);
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("qd") || l.has("qdd"))
      throw nhdyn::input_error("model '" + name + "' has a constraint: lines are {\"q\", \"eta\", \"eta_dot\"} (eta has " +
                               std::to_string(c.m()) + " entries)");
    l.expect_keys(with_f_ext(l, {"q", "eta", "eta_dot"}));
    const Eigen::VectorXd q = l.vector("q", c.dof()), eta = l.vector("eta", c.m()), eta_dot = l.vector("eta_dot", c.m());
    const auto out = [](const auto& f) {
      return ordered_json{{"tau", to_json(Eigen::VectorXd(f.tau))}, {"lambda", to_json(Eigen::VectorXd(f.lambda))}};
    };
    if (!l.has("f_ext")) return out(id(q, eta, eta_dot));
    const auto fx = nhdyn::external_wrenches(model, wrenches_of(l, model));
    return out((nhdyn::lift(c) | nhdyn::rne(model) | fx | nhdyn::constraint_forces(c))(
        nhdyn::reduced_state<double>{q, eta, eta_dot}));
  });
}
/// Lines of a holonomic model: (q, q̇, q̈) -> τ.
template <class Model>
int holonomic(const Model& model, const std::string& name) {
  const auto id = nhdyn::rne(model);
  const int n = model.dof();
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("eta") || l.has("eta_dot"))
      throw nhdyn::input_error("model '" + name + "' has no constraint: lines are {\"q\", \"qd\", \"qdd\"}");
    l.expect_keys(with_f_ext(l, {"q", "qd", "qdd"}));
    const Eigen::VectorXd q = l.vector("q", n), qd = l.vector("qd", n), qdd = l.vector("qdd", n);
    const Eigen::VectorXd tau = l.has("f_ext") ? Eigen::VectorXd(id(q, qd, qdd, nhdyn::external_wrenches(model, wrenches_of(l, model))))
                                               : Eigen::VectorXd(id(q, qd, qdd));
    return ordered_json{{"tau", to_json(tau)}};
  });
}

int run(const std::vector<std::string>& args) {
  const auto any = start_any_model_command(args, usage);
  if (!any) return 0;  // --help
  return dispatch(
      *any, [&](const auto& model, const auto& c) { return constrained(model, c, any->name()); },
      [&](const auto& model) { return holonomic(model, any->name()); });
}
}  // namespace

command command_id() { return {"id", "inverse dynamics: (q, qd, qdd) -> tau, or (q, eta, eta_dot) -> (tau, lambda)", usage, run}; }

}  // namespace nhdyn_tool
