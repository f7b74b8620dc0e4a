/// \file bound.cpp
/// `nhdyn bound`: guaranteed enclosures of the torques over boxes of states, by interval
/// arithmetic with outward rounding (analysis/bounds.hpp). Input bounds are widened by one
/// ulp (the decimal text may lie between doubles); output bounds are printed so that the
/// decimal text never narrows them (each bound moved one double outward, then written in the shortest form that reads
/// back to that double).
#include <iostream>
#include <nhdyn/analysis/bounds.hpp>
#include <nhdyn/nhdyn.hpp>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
const std::string usage = std::string(R"(nhdyn bound --model MODEL [--strict] [--lock 'NAME=POS,...'] [--terms LIST] [--smooth-coulomb VS]
  Guaranteed bounds on the torques over a box of states (interval arithmetic, outward rounding).
  Reads JSON lines on stdin, writes one JSON line per input line. Each box side is [lo, hi].
  Model with a constraint (n joints, m independent velocities, p actuators):
    {"q": [[lo, hi]] x n, "eta": [..] x m, "eta_dot": [..] x m [, "split": k]}  ->  {"tau": [[lo, hi]] x p}
  Model without a constraint:
    {"q": [..] x n, "qd": [..] x n, "qdd": [..] x n [, "split": k]}          ->  {"tau": [[lo, hi]] x n}
  A URDF model is a tree without a constraint (the second form); a robot file with a
  constraint takes the first form (q and eta as `nhdyn model` names them).
  split k (0..20, default 0): bisect the box k times, widest side first (2^k sub-boxes), and
  return the hull of their enclosures (tighter, 2^k times the work).
  Every true torque for every state in the box lies in the printed [lo, hi]: inputs are rounded
  outward, and printing rounds lo down and hi up. An unbounded enclosure is an error line naming
  the output (e.g. "tau[1]: the interval enclosure is unbounded ...").
)") + std::string(model_options_help) + std::string(terms_help);

nhdyn::box<nhdyn::dynamic> box_of(const line& l, std::string_view key, int n) {
  const Eigen::MatrixX2d m = l.intervals(key, n);
  nhdyn::box<nhdyn::dynamic> b(n);
  for (int i = 0; i < n; ++i) b(i) = nhdyn::outward(m(i, 0), m(i, 1));
  return b;
}

ordered_json reply(const nhdyn::vecN<nhdyn::interval, nhdyn::dynamic>& t) {
  ordered_json a = ordered_json::array();
  for (Eigen::Index i = 0; i < t.size(); ++i)
    a.push_back(ordered_json::array({nhdyn::detail::step_down(t(i).lower()), nhdyn::detail::step_up(t(i).upper())}));
  return {{"tau", a}};
}

int split_of(const line& l) { return l.has("split") ? l.integer("split", 20) : 0; }

void keys(const line& l, std::vector<std::string> k) {
  if (l.has("split")) k.push_back("split");
  l.expect_keys(k);
}

/// Lines of a model with a constraint: boxes of (q, η, η̇) -> τ.
template <class Model, class C>
int constrained(const Model& model, const C& c, const std::string& name, const nhdyn::terms& t) {
  const auto friction = friction_of(model, t);
  const int n = c.dof();
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("qd"))
      throw nhdyn::input_error("model '" + name + "' has a constraint: lines are {\"q\", \"eta\", \"eta_dot\"} (eta has " +
                               std::to_string(c.m()) + " entries)");
    keys(l, {"q", "eta", "eta_dot"});
    return reply(nhdyn::torque_bounds(model, c, box_of(l, "q", n), box_of(l, "eta", c.m()), box_of(l, "eta_dot", c.m()),
                                      split_of(l), t.rne(), friction));
  });
}
/// Lines of a holonomic model: boxes of (q, q̇, q̈) -> τ.
template <class Model>
int holonomic(const Model& model, const std::string& name, const nhdyn::terms& t) {
  const auto friction = friction_of(model, t);
  refuse_floating(model, "bound");
  const int n = model.dof();
  return run_lines(std::cin, std::cout, [&](const line& l) {
    if (l.has("eta"))
      throw nhdyn::input_error("model '" + name + "' has no constraint: lines are {\"q\", \"qd\", \"qdd\"}");
    keys(l, {"q", "qd", "qdd"});
    return reply(nhdyn::torque_bounds(model, box_of(l, "q", n), box_of(l, "qd", n), box_of(l, "qdd", n), split_of(l), t.rne(),
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

command command_bound() {
  return {"bound", "guaranteed torque bounds over a box of states: boxes -> tau [[lo, hi]]", usage, run};
}

}  // namespace nhdyn_tool
