/// \file linearize.cpp
/// `nhdyn linearize`: the exact linearisation ẋ ≈ A δx + B δu of the forward dynamics by
/// dual numbers (analysis/linearize.hpp). Models with a constraint: x = (q, η),
/// f = (S(q)η, η̇(q, η, τ)), u = τ. Holonomic models: x = (q, q̇), f = (q̇, q̈), u = τ.
#include <iostream>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/nhdyn.hpp>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
constexpr std::string_view usage = R"(nhdyn linearize --model MODEL
  Exact linearisation of the forward dynamics (derivatives by dual numbers, no step size).
  Reads JSON lines on stdin, writes one JSON line per input line; A and B are row-major.
  Model with a constraint (n joints, m actuator velocities; paper5: n = 5, m = 4):
    {"q": [n], "eta": [m], "tau": [m]}  ->  {"A": [[n+m] x (n+m)], "B": [[m] x (n+m)]}
        x = (q, eta), xdot = f(x, tau) = (S(q) eta, eta_dot),  A = df/dx, B = df/dtau
  Model without a constraint (n joints):
    {"q": [n], "qd": [n], "tau": [n]}   ->  {"A": [[2n] x 2n], "B": [[n] x 2n]}
        x = (q, qd), f = (qd, qdd)
  A singular (reduced) mass matrix is an error line.
)";

int run(const std::vector<std::string>& args) {
  const auto model = start_model_command(args, usage);
  if (!model) return 0;  // --help
  const auto& m = *model;
  const auto& ch = m.chain;
  const int n = ch.dof();
  const auto reply = [](const auto& ss) {
    return ordered_json{{"A", to_json(Eigen::MatrixXd(ss.A))}, {"B", to_json(Eigen::MatrixXd(ss.B))}};
  };
  if (!m.constraint)
    return run_lines(std::cin, std::cout, [&](const line& l) {
      if (l.has("eta"))
        throw nhdyn::input_error("model '" + ch.name() + "' has no constraint: lines are {\"q\", \"qd\", \"tau\"}");
      l.expect_keys({"q", "qd", "tau"});
      return reply(nhdyn::linearize_forward_dynamics(ch, l.vector("q", n), l.vector("qd", n), l.vector("tau", n)));
    });
  const auto& c = *m.constraint;
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("qd"))
      throw nhdyn::input_error("model '" + ch.name() + "' has a constraint: lines are {\"q\", \"eta\", \"tau\"} (eta and tau have " +
                               std::to_string(c.m()) + " entries)");
    l.expect_keys({"q", "eta", "tau"});
    return reply(nhdyn::linearize_forward_dynamics(ch, c, l.vector("q", n), l.vector("eta", c.m()), l.vector("tau", c.m())));
  });
}
}  // namespace

command command_linearize() {
  return {"linearize", "exact A, B of the forward dynamics by duals: (q, eta, tau) -> (A, B)", usage, run};
}

}  // namespace nhdyn_tool
