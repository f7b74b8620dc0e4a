// The trade between number types, measured (issue 4, item 5). Benchmarks:
//   scalar/<algorithm>/<model>/<scalar>   algorithm ∈ {rne, nh_id}, model ∈ {paper5, chain24}
//       counters: rel_err = max over 64 ordinary states of |τ − τ₅₀|/max|τ₅₀| (value part for
//       duals/autodiff, midpoint for intervals, whose counter width = max enclosure width);
//   scalar/nh_id/<model>/<scalar>_state: the double model on an S state (interval: bounds
//       over a box of states; the plain <scalar> row has the model in S too);
//   scalar/jacobian/paper5/{dual,dual_oneshot,dual_all_columns,autodiff,central}: the full
//       ∂τ/∂ζ (4×13) of paper5 (dual: inverse_dynamics_linearizer built once; oneshot:
//       linearize_inverse_dynamics per call; all_columns: jacobian() seeding all 13);
//   scalar/fd_linearize/paper5/{double_fd,ift,ift_oneshot,all_duals}: one double
//       nh_forward_dynamics call, and A, B of its linearisation by forward_dynamics_linearizer
//       built once (implicit function theorem on the linearizer's ∂τ/∂(q, η, η̇)), by
//       linearize_forward_dynamics (builds it per call), and by duals along all of (q, η, τ);
//   scalar/bounds/paper5/split:k: interval enclosure over a state box, counter width.
// chain24 is paper5's differential-drive base carrying a 21-joint random arm (bench/models.hpp).
// The 50-digit reference is cross-checked at start-up: rne₅₀ against the CRBA path
// M q̈ + h in 50 digits and against cpp_dec_float_50 (decimal arithmetic), both ≤ 1e-40.
#ifndef NHDYN_BENCH_FLOAT128
#define NHDYN_NO_FLOAT128 1  // quad = header-only cpp_bin_float_quad unless libquadmath is linked
#endif
#include <benchmark/benchmark.h>

#include <cstdio>
#include <nhdyn/analysis/bounds.hpp>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/scalar/autodiff.hpp>
#include <nhdyn/scalar/interval.hpp>
#include <nhdyn/scalar/multiprecision.hpp>
#include <random>

#include "models.hpp"

namespace {

using nhdyn::interval;
using nhdyn::mp50;
constexpr int n24 = 24;

template <class S, int R>
Eigen::Matrix<S, R, 1> to(const Eigen::Matrix<double, R, 1>& v) {
  return v.unaryExpr([](double x) { return S(x); });
}

/// 64 ordinary states of an n-joint chain with an m-dimensional η: q ∈ [−π, π], rates in [−1, 1].
template <int N, int M>
struct states {
  std::vector<Eigen::Matrix<double, N, 1>> q, qd, qdd;
  std::vector<Eigen::Matrix<double, M, 1>> eta, etad;
  states() {
    std::mt19937_64 g(2026);
    std::uniform_real_distribution<double> U(-1, 1);
    for (int k = 0; k < 64; ++k) {
      Eigen::Matrix<double, N, 1> a, b, c;
      Eigen::Matrix<double, M, 1> e, f;
      for (int i = 0; i < N; ++i) a(i) = 3.14159 * U(g), b(i) = U(g), c(i) = U(g);
      for (int i = 0; i < M; ++i) e(i) = U(g), f(i) = U(g);
      q.push_back(a), qd.push_back(b), qdd.push_back(c), eta.push_back(e), etad.push_back(f);
    }
  }
};

const nhdyn::chain<double, 5>& paper5() {
  static const auto c = nhdyn::presets::paper5_chain<double>();
  return c;
}
const nhdyn::chain<double, n24>& chain24() {
  static const auto c = nhdyn_bench::ddrive_arm(n24 - 3).fixed<n24>();
  return c;
}
template <int N>
const nhdyn::chain<double, N>& model() {
  if constexpr (N == 5) return paper5();
  else return chain24();
}
template <int N>
nhdyn::differential_drive<double, N> constraint() {
  return nhdyn::differential_drive<double, N>(N, 0, 1, 2, 0.0, -1.0);
}
template <int N>
const states<N, N - 1>& state_set() {
  static const states<N, N - 1> s;
  return s;
}

/// The 50-digit results for every state (rne and nh_id), computed once per model.
template <int N>
struct reference {
  std::vector<Eigen::Matrix<mp50, N, 1>> rne;
  std::vector<Eigen::Matrix<mp50, N - 1, 1>> nh;
  reference() {
    const auto c = model<N>().template cast<mp50>();
    const auto id = nhdyn::rne(c);
    const auto nid = nhdyn::inverse_dynamics(c, constraint<N>());
    const auto& s = state_set<N>();
    for (std::size_t k = 0; k < s.q.size(); ++k) {
      rne.push_back(id(to<mp50>(s.q[k]), to<mp50>(s.qd[k]), to<mp50>(s.qdd[k])));
      nh.push_back(nid(to<mp50>(s.q[k]), to<mp50>(s.eta[k]), to<mp50>(s.etad[k])));
    }
  }
};
template <int N>
const reference<N>& ref() {
  static const reference<N> r;
  return r;
}

template <class S>
double mid(const S& x) {
  return nhdyn::value_of(x);
}
template <class S>
double width(const S& x) {
  if constexpr (std::is_same_v<S, interval> || std::is_same_v<S, nhdyn::boost_interval>) return x.width();
  else return 0.0;
}

/// Relative error of a result against the 50-digit one (for high-precision types, computed
/// in 50 digits, not through double).
template <class V, class R>
std::pair<double, double> error_of(const V& v, const R& r) {
  using S = typename V::Scalar;
  mp50 scale = 0, err = 0;
  double w = 0;
  for (Eigen::Index i = 0; i < r.size(); ++i) scale = std::max(scale, mp50(abs(r(i))));
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    mp50 x;
    if constexpr (std::is_same_v<S, mp50> || std::is_same_v<S, nhdyn::dec50> || std::is_same_v<S, nhdyn::quad> ||
                  std::is_same_v<S, long double> || std::is_same_v<S, float> || std::is_same_v<S, double>)
      x = mp50(v(i));
    else
      x = mp50(mid(v(i)));
    err = std::max(err, mp50(abs(x - r(i))));
    w = std::max(w, width(v(i)));
  }
  return {static_cast<double>(err / scale), w / static_cast<double>(scale)};
}

template <class S, int N>
void bm_rne(benchmark::State& st) {
  const auto c = model<N>().template cast<S>();
  const auto id = nhdyn::rne(c);
  const auto& s = state_set<N>();
  std::vector<Eigen::Matrix<S, N, 1>> q, qd, qdd;
  for (std::size_t k = 0; k < s.q.size(); ++k) q.push_back(to<S>(s.q[k])), qd.push_back(to<S>(s.qd[k])), qdd.push_back(to<S>(s.qdd[k]));
  double err = 0, w = 0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    const auto [e, ww] = error_of(Eigen::Matrix<S, N, 1>(id(q[k], qd[k], qdd[k])), ref<N>().rne[k]);
    err = std::max(err, e), w = std::max(w, ww);
  }
  std::size_t k = 0;
  for (auto _ : st) {
    auto v = id(q[k], qd[k], qdd[k]);
    benchmark::DoNotOptimize(v);
    k = (k + 1) & 63;
  }
  st.counters["rel_err"] = err;
  if (w > 0) st.counters["rel_width"] = w;
}

/// ModelInS: the model's numbers in S too (e.g. an interval model: uncertain parameters);
/// otherwise a double model evaluated on an S state (e.g. bounds over a box of states).
template <class S, int N, bool ModelInS = true>
void bm_nh_id(benchmark::State& st) {
  const auto c = [] {
    if constexpr (ModelInS) return model<N>().template cast<S>();
    else return model<N>();
  }();
  const auto id = nhdyn::inverse_dynamics(c, constraint<N>());
  const auto& s = state_set<N>();
  std::vector<Eigen::Matrix<S, N, 1>> q;
  std::vector<Eigen::Matrix<S, N - 1, 1>> e, ed;
  for (std::size_t k = 0; k < s.q.size(); ++k) q.push_back(to<S>(s.q[k])), e.push_back(to<S>(s.eta[k])), ed.push_back(to<S>(s.etad[k]));
  double err = 0, w = 0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    const auto [x, ww] = error_of(Eigen::Matrix<S, N - 1, 1>(id(q[k], e[k], ed[k])), ref<N>().nh[k]);
    err = std::max(err, x), w = std::max(w, ww);
  }
  std::size_t k = 0;
  for (auto _ : st) {
    auto v = id(q[k], e[k], ed[k]);
    benchmark::DoNotOptimize(v);
    k = (k + 1) & 63;
  }
  st.counters["rel_err"] = err;
  if (w > 0) st.counters["rel_width"] = w;
}

using dual1 = nhdyn::dual<double, 1>;
using dual13 = nhdyn::dual<double, 13>;
using ad13 = Eigen::AutoDiffScalar<Eigen::Matrix<double, 13, 1>>;

template <class S>
void register_scalar(const char* name) {
  benchmark::RegisterBenchmark((std::string("scalar/rne/paper5/") + name).c_str(), bm_rne<S, 5>);
  benchmark::RegisterBenchmark((std::string("scalar/nh_id/paper5/") + name).c_str(), bm_nh_id<S, 5>);
  benchmark::RegisterBenchmark((std::string("scalar/rne/chain24/") + name).c_str(), bm_rne<S, n24>);
  benchmark::RegisterBenchmark((std::string("scalar/nh_id/chain24/") + name).c_str(), bm_nh_id<S, n24>);
}
/// An S state on the double model: <name>_state.
template <class S>
void register_state_scalar(const std::string& name) {
  benchmark::RegisterBenchmark(("scalar/nh_id/paper5/" + name + "_state").c_str(), bm_nh_id<S, 5, false>);
  benchmark::RegisterBenchmark(("scalar/nh_id/chain24/" + name + "_state").c_str(), bm_nh_id<S, n24, false>);
}

// ---- the full Jacobian ∂τ/∂ζ of paper5 (4 × 13)
using V5 = Eigen::Matrix<double, 5, 1>;
using V4 = Eigen::Matrix<double, 4, 1>;
using V13 = Eigen::Matrix<double, 13, 1>;

/// The linearizer built once, as the double inverse dynamics it is compared with is.
void bm_jacobian_dual(benchmark::State& st) {
  const nhdyn::inverse_dynamics_linearizer lin(paper5(), constraint<5>());
  const auto& s = state_set<5>();
  std::size_t k = 0;
  for (auto _ : st) {
    auto J = lin(s.q[k], s.eta[k], s.etad[k]);
    benchmark::DoNotOptimize(J);
    k = (k + 1) & 63;
  }
}
/// linearize_inverse_dynamics: builds the pipeline in every call.
void bm_jacobian_dual_oneshot(benchmark::State& st) {
  const auto c = constraint<5>();
  const auto& s = state_set<5>();
  std::size_t k = 0;
  for (auto _ : st) {
    auto J = nhdyn::linearize_inverse_dynamics(paper5(), c, s.q[k], s.eta[k], s.etad[k]);
    benchmark::DoNotOptimize(J);
    k = (k + 1) & 63;
  }
}
/// Every column seeded (dual<double, 13>): what the skipped base columns save.
void bm_jacobian_dual_all_columns(benchmark::State& st) {
  const auto id = nhdyn::inverse_dynamics(paper5(), constraint<5>());
  const auto f = [&](const auto& z) { return id(z.template head<5>(), z.template segment<4>(5), z.template tail<4>()); };
  const auto& s = state_set<5>();
  std::size_t k = 0;
  for (auto _ : st) {
    Eigen::Matrix<double, 13, 1> z;
    z << s.q[k], s.eta[k], s.etad[k];
    auto J = nhdyn::jacobian(f, z);
    benchmark::DoNotOptimize(J);
    k = (k + 1) & 63;
  }
}
void bm_jacobian_autodiff(benchmark::State& st) {
  const auto id = nhdyn::inverse_dynamics(paper5(), constraint<5>());
  const auto& s = state_set<5>();
  std::size_t k = 0;
  for (auto _ : st) {
    Eigen::Matrix<ad13, 5, 1> q;
    Eigen::Matrix<ad13, 4, 1> e, ed;
    for (int i = 0; i < 5; ++i) q(i) = ad13(s.q[k](i), 13, i);
    for (int i = 0; i < 4; ++i) e(i) = ad13(s.eta[k](i), 13, 5 + i), ed(i) = ad13(s.etad[k](i), 13, 9 + i);
    auto t = id(q, e, ed);
    Eigen::Matrix<double, 4, 13> J;
    for (int i = 0; i < 4; ++i) J.row(i) = t(i).derivatives().transpose();
    benchmark::DoNotOptimize(J);
    k = (k + 1) & 63;
  }
}
void bm_jacobian_central(benchmark::State& st) {
  const auto id = nhdyn::inverse_dynamics(paper5(), constraint<5>());
  const auto f = [&](const V13& z) { return V4(id(z.head<5>(), z.segment<4>(5), z.tail<4>())); };
  const auto& s = state_set<5>();
  std::size_t k = 0;
  for (auto _ : st) {
    V13 z;
    z << s.q[k], s.eta[k], s.etad[k];
    auto J = nhdyn::central_difference_jacobian(f, z, 6e-6);
    benchmark::DoNotOptimize(J);
    k = (k + 1) & 63;
  }
}

// ---- the forward dynamics' linearisation (A 9×9, B 9×4) of paper5
/// τ at each state (the forward dynamics' input), from the double inverse dynamics.
const std::vector<V4>& tau_set() {
  static const std::vector<V4> t = [] {
    const auto id = nhdyn::inverse_dynamics(paper5(), constraint<5>());
    const auto& s = state_set<5>();
    std::vector<V4> out;
    for (std::size_t k = 0; k < s.q.size(); ++k) out.push_back(id(s.q[k], s.eta[k], s.etad[k]));
    return out;
  }();
  return t;
}
/// One double nh_forward_dynamics call (what the linearisations are compared with).
void bm_fd_double(benchmark::State& st) {
  const auto fd = nhdyn::nh_forward_dynamics(paper5(), constraint<5>());
  const auto& s = state_set<5>();
  const auto& t = tau_set();
  std::size_t k = 0;
  for (auto _ : st) {
    auto ed = fd(s.q[k], s.eta[k], t[k]);
    benchmark::DoNotOptimize(ed);
    k = (k + 1) & 63;
  }
}
/// forward_dynamics_linearizer (built once, as the double forward dynamics is): the
/// inverse-dynamics Jacobian and the implicit function theorem.
void bm_fd_linearize(benchmark::State& st) {
  const nhdyn::forward_dynamics_linearizer lin(paper5(), constraint<5>());
  const auto& s = state_set<5>();
  const auto& t = tau_set();
  std::size_t k = 0;
  for (auto _ : st) {
    auto ss = lin(s.q[k], s.eta[k], t[k]);
    benchmark::DoNotOptimize(ss);
    k = (k + 1) & 63;
  }
}
/// linearize_forward_dynamics: the same, building the linearizer in every call.
void bm_fd_linearize_oneshot(benchmark::State& st) {
  const auto c = constraint<5>();
  const auto& s = state_set<5>();
  const auto& t = tau_set();
  std::size_t k = 0;
  for (auto _ : st) {
    auto ss = nhdyn::linearize_forward_dynamics(paper5(), c, s.q[k], s.eta[k], t[k]);
    benchmark::DoNotOptimize(ss);
    k = (k + 1) & 63;
  }
}
/// Every column of (q, η, τ) seeded through the forward dynamics (dual<double, 13>).
void bm_fd_linearize_all_duals(benchmark::State& st) {
  const auto c = constraint<5>();
  const auto fd = nhdyn::nh_forward_dynamics(paper5(), c);
  const auto f = [&](const auto& z) {
    using D = typename std::decay_t<decltype(z)>::Scalar;
    Eigen::Matrix<D, 9, 1> out;
    out << nhdyn::apply_S(c, z.template head<5>(), z.template segment<4>(5)),
        fd(z.template head<5>(), z.template segment<4>(5), z.template tail<4>());
    return out;
  };
  const auto& s = state_set<5>();
  const auto& t = tau_set();
  std::size_t k = 0;
  for (auto _ : st) {
    V13 z;
    z << s.q[k], s.eta[k], t[k];
    auto J = nhdyn::jacobian(f, z);
    benchmark::DoNotOptimize(J);
    k = (k + 1) & 63;
  }
}

// ---- interval width vs bisection depth vs time// ---- interval width vs bisection depth vs time
void bm_bounds(benchmark::State& st) {
  const int split = static_cast<int>(st.range(0));
  const auto c = constraint<5>();
  const V5 q0(0.2, -0.1, 0.3, 0.6, -0.8);
  const V4 e0(0.5, 0.2, 0.4, -0.3), ed0(0.3, -0.2, 0.5, 0.4);
  nhdyn::box<5> Q;
  nhdyn::box<4> H, HD;
  for (int i = 0; i < 5; ++i) Q(i) = nhdyn::outward_about(q0(i), 0.05);
  for (int i = 0; i < 4; ++i) H(i) = nhdyn::outward_about(e0(i), 0.05), HD(i) = nhdyn::outward_about(ed0(i), 0.1);
  double w = 0;
  for (auto _ : st) {
    auto T = nhdyn::torque_bounds(paper5(), c, Q, H, HD, split);
    w = 0;
    for (int i = 0; i < 4; ++i) w += T(i).width();
    benchmark::DoNotOptimize(T);
  }
  st.counters["width"] = w;
}

/// Start-up cross-check of the 50-digit reference (prints; aborts the run if it fails).
bool check_reference() {
  const auto c = paper5().cast<mp50>();
  const auto cd = paper5().cast<nhdyn::dec50>();
  const auto& s = state_set<5>();
  double worst_crba = 0, worst_dec = 0;
  for (std::size_t k = 0; k < s.q.size(); ++k) {
    const auto q = to<mp50>(s.q[k]), qd = to<mp50>(s.qd[k]), qdd = to<mp50>(s.qdd[k]);
    const Eigen::Matrix<mp50, 5, 1> v = nhdyn::rne(c)(q, qd, qdd);
    const Eigen::Matrix<mp50, 5, 1> w = nhdyn::mass_matrix(c)(q) * qdd + nhdyn::bias(c)(q, qd);
    const Eigen::Matrix<nhdyn::dec50, 5, 1> vd =
        nhdyn::rne(cd)(to<nhdyn::dec50>(s.q[k]), to<nhdyn::dec50>(s.qd[k]), to<nhdyn::dec50>(s.qdd[k]));
    for (int i = 0; i < 5; ++i) {
      worst_crba = std::max(worst_crba, static_cast<double>(abs(v(i) - w(i))));
      worst_dec = std::max(worst_dec, std::abs(static_cast<double>(v(i) - mp50(vd(i).str(60).c_str()))));
    }
  }
  std::fprintf(stderr, "50-digit reference: |rne - (M qdd + h)| <= %.1e, |bin50 - dec50| <= %.1e\n", worst_crba,
               worst_dec);
  return worst_crba < 1e-40 && worst_dec < 1e-40;
}

const bool registered = [] {
  register_scalar<float>("float");
  register_scalar<double>("double");
  register_scalar<long double>("long_double");
  register_scalar<mp50>("mp50");
  register_scalar<nhdyn::dec50>("dec50");
  register_scalar<nhdyn::quad>("quad");
  register_scalar<dual1>("dual1");
  register_scalar<dual13>("dual13");
  register_scalar<ad13>("autodiff13");
  register_scalar<interval>("interval");
  register_scalar<nhdyn::boost_interval>("boost_interval");
  register_state_scalar<interval>("interval");
  register_state_scalar<nhdyn::boost_interval>("boost_interval");
  register_state_scalar<dual13>("dual13");
  benchmark::RegisterBenchmark("scalar/jacobian/paper5/dual", bm_jacobian_dual);
  benchmark::RegisterBenchmark("scalar/jacobian/paper5/dual_oneshot", bm_jacobian_dual_oneshot);
  benchmark::RegisterBenchmark("scalar/jacobian/paper5/dual_all_columns", bm_jacobian_dual_all_columns);
  benchmark::RegisterBenchmark("scalar/jacobian/paper5/autodiff", bm_jacobian_autodiff);
  benchmark::RegisterBenchmark("scalar/jacobian/paper5/central", bm_jacobian_central);
  benchmark::RegisterBenchmark("scalar/fd_linearize/paper5/double_fd", bm_fd_double);
  benchmark::RegisterBenchmark("scalar/fd_linearize/paper5/ift", bm_fd_linearize);
  benchmark::RegisterBenchmark("scalar/fd_linearize/paper5/ift_oneshot", bm_fd_linearize_oneshot);
  benchmark::RegisterBenchmark("scalar/fd_linearize/paper5/all_duals", bm_fd_linearize_all_duals);
  for (int k : {0, 2, 4, 6, 8, 10})
    benchmark::RegisterBenchmark(("scalar/bounds/paper5/split:" + std::to_string(k)).c_str(), bm_bounds)->Arg(k);
  if (!check_reference()) std::fprintf(stderr, "WARNING: the 50-digit reference failed its cross-check\n");
  return true;
}();

}  // namespace
