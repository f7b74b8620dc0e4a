/// \file fd.cpp
/// `nhdyn fd`: forward dynamics on JSON lines. Holonomic models: q̈ = M⁻¹(τ − bias)
/// (forward_dynamics). Models with a constraint: η̇ = M_η⁻¹(SᵀEτ − h_η) (nh_forward_dynamics).
/// --terms: rne_options, and the friction in the bias (fd.with(friction(model))).
#include <iostream>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/nhdyn.hpp>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
const std::string usage = std::string(R"(nhdyn fd --model MODEL [--strict] [--lock 'NAME=POS,...'] [--terms LIST] [--smooth-coulomb VS]
  Forward dynamics. Reads JSON lines on stdin, writes one JSON line per input line.
  Model without a constraint (n joints):
    {"q": [n], "qd": [n], "tau": [n]}        ->  {"qdd": [n]}         qdd = M(q)^-1 (tau - bias(q, qd))
  Model with a constraint (m actuator velocities):
    {"q": [n], "eta": [m], "tau": [p]}       ->  {"eta_dot": [m]}     eta_dot = M_eta^-1 (S^T E tau - h_eta)
  A URDF model is a tree without a constraint (the first form; q in `nhdyn model` order); a
  robot file with a constraint takes the second form (eta as `nhdyn model` names it).
  Either form takes an optional "f_ext" (external wrenches, as `nhdyn id --help` describes):
  the motion they cause with tau.
  A singular or near-singular (reduced) mass matrix is an error line.
)") + std::string(model_options_help) + std::string(terms_help);

/// Lines of a model with a constraint: (q, η, τ) -> η̇.
template <class Model, class C>
int constrained(const Model& model, const C& c, const std::string& name, const nhdyn::terms& t) {
  const auto fd = t.friction ? nhdyn::nh_forward_dynamics(model, c, t.rne()).with(nhdyn::friction(model, t.coulomb))
                             : nhdyn::nh_forward_dynamics(model, c, t.rne());
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("qd"))
      throw nhdyn::input_error("model '" + name + "' has a constraint: lines are {\"q\", \"eta\", \"tau\"} (eta has " +
                               std::to_string(c.m()) + " entries, tau " + std::to_string(nhdyn::actuator_count(c)) + ")");
    l.expect_keys(with_f_ext(l, {"q", "eta", "tau"}));
    const Eigen::VectorXd q = l.vector("q", c.dof()), eta = l.vector("eta", c.m()), tau = l.vector("tau", nhdyn::actuator_count(c));
    const Eigen::VectorXd eta_dot = l.has("f_ext") ? Eigen::VectorXd(fd(q, eta, tau, nhdyn::external_wrenches(model, wrenches_of(l, model))))
                                                   : Eigen::VectorXd(fd(q, eta, tau));
    return ordered_json{{"eta_dot", to_json(eta_dot)}};
  });
}
/// Lines of a holonomic model: (q, q̇, τ) -> q̈.
template <class Model>
int holonomic(const Model& model, const std::string& name, const nhdyn::terms& t) {
  const auto fd = t.friction ? nhdyn::forward_dynamics(model, t.rne()).with(nhdyn::friction(model, t.coulomb))
                             : nhdyn::forward_dynamics(model, t.rne());
  const int n = model.dof(), nq = nq_of(model);
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("eta"))
      throw nhdyn::input_error("model '" + name + "' has no constraint: lines are {\"q\", \"qd\", \"tau\"}");
    l.expect_keys(with_f_ext(l, {"q", "qd", "tau"}));
    const Eigen::VectorXd q = l.vector("q", nq), qd = l.vector("qd", n), tau = l.vector("tau", n);
    const Eigen::VectorXd qdd = l.has("f_ext") ? Eigen::VectorXd(fd(q, qd, tau, nhdyn::external_wrenches(model, wrenches_of(l, model))))
                                               : Eigen::VectorXd(fd(q, qd, tau));
    return ordered_json{{"qdd", to_json(qdd)}};
  });
}

int run(const std::vector<std::string>& args) {
  const auto any = start_any_model_command(args, usage, true);
  if (!any) return 0;  // --help
  return dispatch(
      *any, [&](const auto& model, const auto& c) { return constrained(model, c, any->name(), any->terms); },
      [&](const auto& model) { return holonomic(model, any->name(), any->terms); });
}
}  // namespace

command command_fd() { return {"fd", "forward dynamics: (q, qd, tau) -> qdd, or (q, eta, tau) -> eta_dot", usage, run}; }

}  // namespace nhdyn_tool
