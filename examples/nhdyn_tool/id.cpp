/// \file id.cpp
/// `nhdyn id`: inverse dynamics on JSON lines. Holonomic models: τ = rne(q, q̇, q̈).
/// Models with a constraint: (τ, λ) = inverse_dynamics_with_forces(q, η, η̇), i.e. the
/// projection of rne ∘ lift (paper eqs. 18–19) and λ = (AAᵀ)⁻¹A(v − Eτ). --terms chooses
/// what rne includes, and puts rne + friction in its place (dynamics/terms.hpp).
#include <iostream>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/nhdyn.hpp>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
const std::string usage = std::string(R"(nhdyn id --model MODEL [--strict] [--lock 'NAME=POS,...'] [--terms LIST] [--smooth-coulomb VS]
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
)") + std::string(model_options_help) + std::string(terms_help);

/// Lines of a model with a constraint: (q, η, η̇) -> (τ, λ); `dyn` is rne or rne + friction.
template <class Model, class C, class Dyn>
int constrained(const Model& model, const C& c, const std::string& name, const nhdyn::terms& t, const Dyn& dyn) {
  // constraint_forces ∘ rne ∘ lift, or with friction in rne's place
  const auto id = [&] {
    if constexpr (std::is_same_v<Dyn, decltype(nhdyn::rne(model))>)
      return nhdyn::inverse_dynamics_with_forces(model, c, t.rne());
    else
      return nhdyn::inverse_dynamics_with_forces(model, c, t.rne(), dyn.b);
  }();
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
    return out((nhdyn::lift(c) | dyn | fx | nhdyn::constraint_forces(c))(nhdyn::reduced_state<double>{q, eta, eta_dot}));
  });
}
/// Lines of a holonomic model: (q, q̇, q̈) -> τ; `id` is rne or rne + friction.
template <class Model, class Id>
int holonomic(const Model& model, const std::string& name, const Id& id) {
  const int n = model.dof(), nq = nq_of(model);
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("eta") || l.has("eta_dot"))
      throw nhdyn::input_error("model '" + name + "' has no constraint: lines are {\"q\", \"qd\", \"qdd\"}");
    l.expect_keys(with_f_ext(l, {"q", "qd", "qdd"}));
    const Eigen::VectorXd q = l.vector("q", nq), qd = l.vector("qd", n), qdd = l.vector("qdd", n);
    const Eigen::VectorXd tau = l.has("f_ext") ? Eigen::VectorXd(id(q, qd, qdd, nhdyn::external_wrenches(model, wrenches_of(l, model))))
                                               : Eigen::VectorXd(id(q, qd, qdd));
    return ordered_json{{"tau", to_json(tau)}};
  });
}

int run(const std::vector<std::string>& args) {
  const auto any = start_any_model_command(args, usage, true);
  if (!any) return 0;  // --help
  const auto& t = any->terms;
  return dispatch(
      *any,
      [&](const auto& model, const auto& c) {
        return with_dynamics(model, t, [&](const auto& dyn) { return constrained(model, c, any->name(), t, dyn); });
      },
      [&](const auto& model) {
        return with_dynamics(model, t, [&](const auto& dyn) { return holonomic(model, any->name(), dyn); });
      });
}
}  // namespace

command command_id() { return {"id", "inverse dynamics: (q, qd, qdd) -> tau, or (q, eta, eta_dot) -> (tau, lambda)", usage, run}; }

}  // namespace nhdyn_tool
