/// \file linearize.cpp
/// `nhdyn linearize`: the exact linearisation ẋ ≈ A δx + B δu of the forward dynamics by
/// dual numbers (analysis/linearize.hpp). Models with a constraint: x = (q, η),
/// f = (S(q)η, η̇(q, η, τ)), u = τ. Holonomic models: x = (q, q̇), f = (q̇, q̈), u = τ.
/// --terms: rne_options, and the friction in the forward dynamics.
#include <iostream>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/nhdyn.hpp>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
const std::string usage = std::string(R"(nhdyn linearize --model MODEL [--strict] [--lock 'NAME=POS,...'] [--terms LIST] [--smooth-coulomb VS]
  Exact linearisation of the forward dynamics (derivatives by dual numbers, no step size).
  Reads JSON lines on stdin, writes one JSON line per input line; A and B are row-major.
  Model with a constraint (n joints, m independent velocities, p actuators; paper5: n = 5,
  m = p = 4):
    {"q": [n], "eta": [m], "tau": [p]}  ->  {"A": [[n+m] x (n+m)], "B": [[p] x (n+m)]}
        x = (q, eta), xdot = f(x, tau) = (S(q) eta, eta_dot),  A = df/dx, B = df/dtau
  Model without a constraint (n joints):
    {"q": [n], "qd": [n], "tau": [n]}   ->  {"A": [[2n] x 2n], "B": [[n] x 2n]}
        x = (q, qd), f = (qd, qdd)
  A URDF model is a tree without a constraint (the second form; q in `nhdyn model` order); a
  robot file with a constraint takes the first form (eta as `nhdyn model` names it).
  A singular (reduced) mass matrix is an error line.
)") + std::string(model_options_help) + std::string(terms_help);

ordered_json reply(const auto& ss) {
  return ordered_json{{"A", to_json(Eigen::MatrixXd(ss.A))}, {"B", to_json(Eigen::MatrixXd(ss.B))}};
}

/// Lines of a model with a constraint: (q, η, τ) -> (A, B).
template <class Model, class C>
int constrained(const Model& model, const C& c, const std::string& name, const nhdyn::terms& t) {
  const auto lin = nhdyn::forward_dynamics_linearizer(model, c, t.rne(), friction_of(model, t));
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("qd"))
      throw nhdyn::input_error("model '" + name + "' has a constraint: lines are {\"q\", \"eta\", \"tau\"} (eta has " +
                               std::to_string(c.m()) + " entries, tau " + std::to_string(nhdyn::actuator_count(c)) + ")");
    l.expect_keys({"q", "eta", "tau"});
    return reply(lin(l.vector("q", c.dof()), l.vector("eta", c.m()), l.vector("tau", nhdyn::actuator_count(c))));
  });
}
/// Lines of a holonomic model: (q, q̇, τ) -> (A, B).
template <class Model>
int holonomic(const Model& model, const std::string& name, const nhdyn::terms& t) {
  const auto friction = friction_of(model, t);
  refuse_floating(model, "linearize");
  const int n = model.dof();
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("eta"))
      throw nhdyn::input_error("model '" + name + "' has no constraint: lines are {\"q\", \"qd\", \"tau\"}");
    l.expect_keys({"q", "qd", "tau"});
    return reply(nhdyn::linearize_forward_dynamics(model, l.vector("q", n), l.vector("qd", n), l.vector("tau", n), t.rne(),
                                                   friction));
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

command command_linearize() {
  return {"linearize", "exact A, B of the forward dynamics by duals: (q, eta, tau) -> (A, B)", usage, run};
}

}  // namespace nhdyn_tool
