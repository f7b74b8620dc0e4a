// Guaranteed bounds on paper5's actuator torques τ = (F_v, τ_ω, τ₄, τ₅):
//  1. over a box of states about a moving pose, with bisection (widths per depth, and time);
//  2. over the paper's parameter variations: every link mass ±10 %, and the factorial
//     ranges of d₃, m₃, a₄, a₅ (each ±10 %), at a fixed state.
// Every bound is a rigorous enclosure (interval arithmetic with outward rounding,
// scalar/interval.hpp), printed so that printing never narrows it.
#include <chrono>
#include <cstdio>
#include <nhdyn/analysis/bounds.hpp>
#include <nhdyn/nhdyn.hpp>

namespace {
using nhdyn::interval;
using V5 = Eigen::Matrix<double, 5, 1>;
using V4 = Eigen::Matrix<double, 4, 1>;

template <int N>
nhdyn::box<N> around(const Eigen::Matrix<double, N, 1>& c, double r) {
  nhdyn::box<N> b;
  for (int i = 0; i < N; ++i) b(i) = nhdyn::outward_about(c(i), r);
  return b;
}

void print(const char* label, const nhdyn::vecN<interval, 4>& T, const V4& nominal, double ms) {
  static const char* names[4] = {"F_v [N]", "tau_w [Nm]", "tau_4 [Nm]", "tau_5 [Nm]"};
  std::printf("%s  (%.3f ms)\n", label, ms);
  for (int i = 0; i < 4; ++i)
    std::printf("    %-11s nominal %+10.5f  in [%s, %s]  width %.3e\n", names[i], nominal(i),
                nhdyn::format_lower(T(i).lower()).c_str(), nhdyn::format_upper(T(i).upper()).c_str(), T(i).width());
}

template <class F>
auto timed(const F& f, double& ms) {
  const auto t0 = std::chrono::steady_clock::now();
  auto r = f();
  ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return r;
}
}  // namespace

int main() {
  const auto rb = nhdyn::presets::paper5();
  const V5 q0(0.2, -0.1, 0.3, 0.6, -0.8);
  const V4 eta0(0.5, 0.2, 0.4, -0.3), etad0(0.3, -0.2, 0.5, 0.4);
  const V4 nominal = nhdyn::inverse_dynamics(rb.chain, rb.constraint)(q0, eta0, etad0);
  std::printf("paper5 torque bounds at q = (0.2, -0.1, 0.3, 0.6, -0.8), eta = (0.5, 0.2, 0.4, -0.3), "
              "eta_dot = (0.3, -0.2, 0.5, 0.4)\n\n");

  std::printf("1. State box: q +- 0.05, eta +- 0.05, eta_dot +- 0.1\n");
  const auto Q = around<5>(q0, 0.05);
  const auto H = around<4>(eta0, 0.05), HD = around<4>(etad0, 0.1);
  for (int k : {0, 4, 8, 12}) {
    double ms = 0;
    const auto T = timed([&] { return nhdyn::torque_bounds(rb.chain, rb.constraint, Q, H, HD, k); }, ms);
    char label[64];
    std::snprintf(label, sizeof label, "  split %d (%d boxes)", k, 1 << k);
    print(label, T, nominal, ms);
  }

  std::printf("\n2. Parameters at the nominal state (point box)\n");
  const auto Qp = around<5>(q0, 0);
  const auto Hp = around<4>(eta0, 0), HDp = around<4>(etad0, 0);
  nhdyn::presets::paper5_parameters<interval> all;
  for (auto& f : all.mass_factor) f = nhdyn::outward(0.9, 1.1);
  nhdyn::presets::paper5_parameters<interval> fact;
  fact.mass_factor[2] = nhdyn::outward(0.9, 1.1);
  fact.d3_factor = fact.a4_factor = fact.a5_factor = nhdyn::outward(0.9, 1.1);
  for (int k : {0, 6}) {
    double ms = 0;
    auto T = timed([&] { return nhdyn::paper5_torque_bounds(all, Qp, Hp, HDp, k); }, ms);
    char label[80];
    std::snprintf(label, sizeof label, "  every mass +-10 %%, split %d", k);
    print(label, T, nominal, ms);
    T = timed([&] { return nhdyn::paper5_torque_bounds(fact, Qp, Hp, HDp, k); }, ms);
    std::snprintf(label, sizeof label, "  factorial ranges d3, m3, a4, a5 +-10 %%, split %d", k);
    print(label, T, nominal, ms);
  }
  // Sanity: the 16 corners of the factorial design lie inside the enclosure.
  const auto T = nhdyn::paper5_torque_bounds(fact, Qp, Hp, HDp, 6);
  int inside = 0;
  for (int corner = 0; corner < 16; ++corner) {
    const auto f = [&](int b) { return (corner >> b & 1) ? 1.1 : 0.9; };
    nhdyn::presets::paper5_parameters<double> p;
    p.d3_factor = f(0);
    p.mass_factor[2] = f(1);
    p.a4_factor = f(2);
    p.a5_factor = f(3);
    const auto r = nhdyn::presets::paper5<double>(p);
    const V4 t = nhdyn::inverse_dynamics(r.chain, r.constraint)(q0, eta0, etad0);
    bool in = true;
    for (int i = 0; i < 4; ++i) in = in && contains(T(i), t(i));
    inside += in;
  }
  std::printf("\n  the 16 factorial corners inside the split-6 enclosure: %d of 16\n", inside);
  return inside == 16 ? 0 : 1;
}
