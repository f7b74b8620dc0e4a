// The worked paper5 example of docs/theory.md §8, as a program: one state ζ = (q, η, η̇) of
// the paper's robot, pushed through the three stages of Theorem 1 one at a time,
//
//     lift (eq. 19):    ζ ↦ ξ = (q, Sη, Sη̇ + Ṡη)
//     rne (eq. 15):     ξ ↦ v = M(q)q̈ + C(q, q̇)q̇ + g(q)
//     project (eq. 18): v ↦ τ = (SᵀS)⁻¹Sᵀv   (= Sᵀv for paper5, SᵀS = I)
//
// then the constraint force λ = (AAᵀ)⁻¹A(v − Sτ) and the constrained forward dynamics
// (M_η = SᵀMS, h_η = Sᵀ rne(q, Sη, Ṡη)) that gives η̇ back from τ. Every printed number is
// quoted in docs/theory.md; rerun this program to regenerate them.
#include <cstdio>
#include <nhdyn/nhdyn.hpp>
#include <numbers>
#include <string>

namespace {

template <class V>
void print_vector(const char* name, const V& v, const char* unit = "") {
  std::printf("  %-9s = [", name);
  for (Eigen::Index i = 0; i < v.size(); ++i) std::printf("%s%13.9f", i ? " " : "", double(v(i)) + 0.0);  // + 0.0: prints −0 as 0
  std::printf(" ]%s%s\n", *unit ? "  " : "", unit);
}

template <class M>
void print_matrix(const char* name, const M& m) {
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    std::printf("  %-9s %s", r == 0 ? name : "", r == 0 ? "= [" : "   ");
    for (Eigen::Index c = 0; c < m.cols(); ++c) std::printf("%s%13.9f", c ? " " : "", double(m(r, c)) + 0.0);
    std::printf("%s\n", r + 1 == m.rows() ? " ]" : "");
  }
}

}  // namespace

int main() {
  using std::numbers::pi;
  using vec5 = Eigen::Matrix<double, 5, 1>;
  using vec4 = Eigen::Vector4d;

  const auto robot = nhdyn::presets::paper5();  // chain<double,5> + differential_drive<double,5>
  const auto& c = robot.constraint;

  // The state: base at (q₁, q₂), heading q₃ = π/6, arm at (π/4, −π/3); driving forward at
  // 0.5 m/s while turning, the arm moving.
  const vec5 q(0.3, -0.2, pi / 6, pi / 4, -pi / 3);  // [m, m, rad, rad, rad]
  const vec4 eta(0.5, 0.2, 1.0, -0.5);             // η  = (v [m/s], ω [rad/s], q̇₄, q̇₅ [rad/s])
  const vec4 eta_dot(0.4, -0.1, 2.0, 1.0);         // η̇  = (v̇ [m/s²], ω̇, q̈₄, q̈₅ [rad/s²])

  std::printf("paper5 worked example (docs/theory.md §8), produced by examples/paper5_worked.cpp\n\n");
  std::printf("state zeta = (q, eta, eta_dot)\n");
  print_vector("q", q, "(m, m, rad, rad, rad)");
  print_vector("eta", eta, "(v m/s, omega rad/s, qd4, qd5 rad/s)");
  print_vector("eta_dot", eta_dot);

  std::printf("\nconstraint matrices at q (eq. 1-2)\n");
  print_matrix("A(q)", c.A(q));
  print_matrix("S(q)", c.S(q));
  std::printf("  |A S|     = %.3g    |S^T S - I| = %.3g\n", (c.A(q) * c.S(q)).norm(),
              (c.S(q).transpose() * c.S(q) - Eigen::Matrix4d::Identity()).norm());

  // Stage 1: lift (eq. 19).
  const auto xi = nhdyn::lift(c)(q, eta, eta_dot);
  std::printf("\nstage 1, lift (eq. 19): xi = W(q) zeta = (q, S eta, S eta_dot + Sdot eta)\n");
  print_vector("qd", xi.qd, "= S eta");
  print_vector("Sdot eta", nhdyn::apply_Sdot(c, q, xi.qd, eta));
  print_vector("qdd", xi.qdd, "= S eta_dot + Sdot eta");
  std::printf("  A qd      = %.3g   (the constraint holds)\n", (c.A(q) * xi.qd)(0));

  // Stage 2: the holonomic rne, untouched.
  const auto f = nhdyn::rne(robot.chain)(xi);
  std::printf("\nstage 2, rne: v = rne(q, qd, qdd), the chain's generalized forces\n");
  print_vector("v", f.v, "(N, N, N m, N m, N m)");

  // Stage 3: project (eq. 18).
  const vec4 tau = nhdyn::project(c)(f);
  std::printf("\nstage 3, project (eq. 18): tau = (S^T S)^-1 S^T v = S^T v\n");
  print_vector("tau", tau, "(N forward, N m yaw, N m shoulder, N m elbow)");

  // The same three stages as one function object, both ways of writing it.
  const vec4 tau_pipe = (nhdyn::lift(c) | nhdyn::rne(robot.chain) | nhdyn::project(c))(q, eta, eta_dot);
  const vec4 tau_id = nhdyn::inverse_dynamics(robot.chain, c)(q, eta, eta_dot);
  std::printf("  |pipe - stages| = %.3g   |inverse_dynamics - stages| = %.3g\n", (tau_pipe - tau).norm(),
              (tau_id - tau).norm());

  // Constraint force.
  const auto tl = nhdyn::constraint_forces(c)(f);
  std::printf("\nconstraint force: lambda = (A A^T)^-1 A (v - S tau)\n");
  print_vector("lambda", tl.lambda, "(N, lateral, on the base point)");
  const vec5 residual = c.S(q) * tau + c.A(q).transpose() * tl.lambda - f.v;
  std::printf("  |S tau + A^T lambda - v| = %.3g   (eq. 1)\n", residual.norm());
  std::printf("  qd^T A^T lambda          = %.3g   (the constraint force does no work)\n",
              xi.qd.dot(c.A(q).transpose() * tl.lambda));

  // Constrained forward dynamics.
  const auto fd = nhdyn::nh_forward_dynamics(robot.chain, c);
  std::printf("\nconstrained forward dynamics: M_eta eta_dot = S^T S tau - h_eta\n");
  print_matrix("M_eta", fd.reduced_inertia(q));
  print_vector("h_eta", fd.reduced_bias(q, eta), "= S^T rne(q, S eta, Sdot eta)");
  print_vector("S^T g(q)", nhdyn::apply_St(c, q, nhdyn::rne(robot.chain)(q, vec5::Zero(), vec5::Zero())),
               "= S^T rne(q, 0, 0), its gravity part");
  print_vector("eta_dot", fd(q, eta, tau), "(recovered from tau)");
  return 0;
}
