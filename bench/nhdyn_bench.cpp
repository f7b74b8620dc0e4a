/// \file bench/nhdyn_bench.cpp
/// nhdyn's benchmarks (Google Benchmark). Names pair up for scripts/perf_table.py:
///   rne/<model>/{nhdyn, nhdyn_fixed, kdl}       holonomic inverse dynamics vs Orocos KDL
///   nh_id/<model>/{rne, rne_fixed, lagrange}    nonholonomic inverse dynamics vs projected E–L
///   nh_pair/<model>/{fixed, run_time}           nh id and the holonomic rne at the lifted state,
///                                               timed in alternating blocks (counter `ratio`)
///   scene/<model>/<variant>                     "model only what a scene requires"
///   requires/<robot>/{full, locked}/<variant>   the same on a robot file: joints held, terms
///                                               (counter arm_rel_err: the accuracy it costs)
///   nh_inertia/<model>/{crba, rne_columns}      M_η = SᵀMS two ways
///   rne/<tree>/{nhdyn, reference, kdl}          rne on kinematic trees (the kernel, the plain
///   crba/<tree>/{nhdyn, reference}               spatial-algebra reference, KDL's tree solver);
///   {rne, crba, aba}/<tree>/evaluate            the kernels into a result the caller reuses;
///   crba_pair/<tree>                             rne and CRBA evaluate paired (ratio CRBA / rne);
///   crba/<tree>/kept, crba_pair_kept/<tree>      CRBA into a mass_matrix_result (the tree's zeros
///                                                kept from call to call), alone and paired with rne;
///   aba/<tree>/nhdyn                            ABA on the tree (a returned q̈)
///   fd/<model>/{aba, aba_reference, crba_ldlt, crba_ldlt_evaluate, kdl}  holonomic forward
///                                               dynamics: the articulated-body algorithm (kernel,
///                                               reference), CRBA + LDLᵀ (a call; into a reused
///                                               q̈ and scratch), KDL
///                                               mass matrix by the kernel and the reference
///   nh_id/<robot>/{rne, evaluate, lagrange}     a robot file's nonholonomic inverse dynamics (evaluate: into a reused τ)
///   nh_pair/<robot>/{run_time, evaluate}         (robot: mobile_manipulator_{ddrive, wheels,
///   nh_fd/<robot>/{nhdyn, evaluate}              bicycle, castors}, mecanum_arm, omni3_arm,
///                                                castor_drive_arm, powered_castors_arm; the
///                                                wheels robot as a wheeled_base too) vs
///                                                projected E–L on the tree, paired
///                                               with the holonomic rne, and its forward dynamics
///   el_pair/<robot>                             the method's call and projected E–L paired
///                                               (counter `ratio` = E–L / nh)
/// Every case checks its answer once, untimed, against an independent computation (KDL, the
/// Lagrangian, the run-time-sized variant) and aborts on disagreement; every unpaired case reports
/// `allocs_per_call`, the heap allocations of one call (counted by alloc_counter.cpp).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdint>

#include <cstdio>
#include <cstdlib>
#include <memory>

#include <nhdyn/analysis/batch.hpp>
#include <nhdyn/analysis/derivatives.hpp>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/dynamics/aba.hpp>
#include <nhdyn/dynamics/reference.hpp>
#include <nhdyn/dynamics/reference_derivatives.hpp>
#include <nhdyn/dynamics/rne_derivatives.hpp>
#include <nhdyn/dynamics/tree.hpp>
#ifdef NHDYN_BENCH_URDF
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/io/urdf.hpp>
#endif
#include <reference/random_tree.hpp>

#include "alloc_counter.hpp"
#include "lagrange.hpp"
#include "models.hpp"

namespace nhdyn_bench {
namespace {

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "nhdyn_bench: %s\n", what.c_str());
  std::exit(2);
}

/// |a − b|∞ ≤ tol·max(1, |b|∞), or abort naming the case.
template <class A, class B>
void agree(const A& a, const B& b, double tol, const std::string& what) {
  const Eigen::VectorXd x = a, y = b;
  if (x.size() != y.size()) fail(what + ": sizes differ");
  const double err = (x - y).lpNorm<Eigen::Infinity>();
  const double scale = std::max(1.0, y.lpNorm<Eigen::Infinity>());
  if (!(err <= tol * scale)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, ": disagreement %.3e > %.1e (scale %.3e)", err, tol, scale);
    fail(what + buf);
  }
}

/// Heap allocations per call of f, averaged over 64 calls (untimed).
template <class F>
double allocs_per_call(F&& f) {
  f();  // warm-up
  const auto before = allocations();
  for (int i = 0; i < 64; ++i) f();
  return double(allocations() - before) / 64.0;
}

/// Registers name → a loop over f(); f is also called by allocs_per_call.
template <class F>
void add(const std::string& name, F f) {
  auto fp = std::make_shared<F>(std::move(f));
  benchmark::RegisterBenchmark(name.c_str(), [fp](benchmark::State& st) {
    st.counters["allocs_per_call"] = allocs_per_call(*fp);
    for (auto _ : st) (*fp)();
  });
}

template <class V>
void opaque(V& v) {
  benchmark::DoNotOptimize(v);
}

/// Registers name → a paired measurement of two calls: blocks of 16 calls of a, then 16 of b
/// (the order swapped every iteration), each block timed by the steady clock, inside one
/// benchmark. On a machine whose speed drifts (a shared VM: per-case CV of 10–25 % between
/// separately run benchmarks), both sides of the ratio then see the same microseconds.
/// Counters: ratio = time(b) / time(a), a_ns and b_ns per call.
template <class A, class B>
void add_paired(const std::string& name, A a, B b) {
  auto fa = std::make_shared<A>(std::move(a));
  auto fb = std::make_shared<B>(std::move(b));
  benchmark::RegisterBenchmark(name.c_str(), [fa, fb](benchmark::State& st) {
    using clock = std::chrono::steady_clock;
    constexpr int block = 16;
    clock::duration ta{}, tb{};
    std::int64_t calls = 0;
    bool a_first = true;
    const auto run = [](auto& f, clock::duration& t) {
      const auto t0 = clock::now();
      for (int i = 0; i < block; ++i) f();
      t += clock::now() - t0;
    };
    for (auto _ : st) {
      if (a_first) {
        run(*fa, ta);
        run(*fb, tb);
      } else {
        run(*fb, tb);
        run(*fa, ta);
      }
      a_first = !a_first;
      calls += block;
    }
    const double sa = std::chrono::duration<double, std::nano>(ta).count();
    const double sb = std::chrono::duration<double, std::nano>(tb).count();
    st.counters["ratio"] = sb / sa;
    st.counters["a_ns"] = sa / double(calls);
    st.counters["b_ns"] = sb / double(calls);
  });
}

// ---------------------------------------------------------------- issue 2: rne vs KDL

template <int N>
void register_rne(const std::string& model, const chain<double>& cd, bool with_kdl = true) {
  const int n = cd.dof();
  const state s = random_state(n);
  const auto cf = cd.fixed<N>();
  auto idd = nhdyn::rne(cd);
  auto idf = nhdyn::rne(cf);
  const Eigen::VectorXd tau_d = idd(s.q, s.qd, s.qdd);
  const nhdyn::vecN<double, N> qf = s.q, qdf = s.qd, qddf = s.qdd;
  agree(idf(qf, qdf, qddf), tau_d, 1e-14, "rne/" + model + ": fixed vs run-time sized");
  add("rne/" + model + "/nhdyn", [idd, s]() mutable {
    opaque(s.q), opaque(s.qd), opaque(s.qdd);
    auto tau = idd(s.q, s.qd, s.qdd);
    benchmark::DoNotOptimize(tau);
  });
  add("rne/" + model + "/nhdyn_fixed", [idf, qf, qdf, qddf]() mutable {
    opaque(qf), opaque(qdf), opaque(qddf);
    auto tau = idf(qf, qdf, qddf);
    benchmark::DoNotOptimize(tau);
  });
  if (!with_kdl) return;
  const auto rows = kdl_rows(cd);
  std::shared_ptr<kdl::solver> k(kdl::make(rows.data(), n, cd.gravity().data()), kdl::destroy);
  kdl::set_state(k.get(), s.q.data(), s.qd.data(), s.qdd.data());
  if (kdl::run(k.get()) != 0) fail("rne/" + model + ": KDL's solver returned an error");
  Eigen::VectorXd tau_k(n);
  kdl::torques(k.get(), tau_k.data());
  agree(tau_d, tau_k, 1e-10, "rne/" + model + ": nhdyn vs KDL ChainIdSolver_RNE");
  add("rne/" + model + "/kdl", [k]() { benchmark::DoNotOptimize(kdl::run(k.get())); });
}

// ------------------------------------------------- issue 15: forward dynamics, ABA vs CRBA vs KDL

void register_fd(const std::string& model, const chain<double>& cd) {
  const int n = cd.dof();
  const state s = random_state(n, 23);
  const Eigen::VectorXd tau = s.qdd;  // any torques
  auto ab = nhdyn::aba(nhdyn::as_tree(cd));
  auto cr = nhdyn::forward_dynamics(cd, {}, {.method = nhdyn::fd_method::crba_ldlt});  // forced: the default picks by size
  const Eigen::VectorXd qdd = cr(s.q, s.qd, tau);
  agree(ab(s.q, s.qd, tau), qdd, 1e-9, "fd/" + model + ": aba vs CRBA + LDLT");
  const auto rows = kdl_rows(cd);
  std::shared_ptr<kdl::solver> k(kdl::make(rows.data(), n, cd.gravity().data()), kdl::destroy);
  kdl::set_fd_state(k.get(), s.q.data(), s.qd.data(), tau.data());
  if (kdl::run_fd(k.get()) != 0) fail("fd/" + model + ": KDL's ChainFdSolver_RNE returned an error");
  Eigen::VectorXd qdd_k(n);
  kdl::accelerations(k.get(), qdd_k.data());
  agree(qdd_k, qdd, 1e-8, "fd/" + model + ": KDL ChainFdSolver_RNE vs CRBA + LDLT");
  add("fd/" + model + "/aba", [ab, s, tau]() mutable {
    opaque(s.q), opaque(s.qd), opaque(tau);
    auto r = ab(s.q, s.qd, tau);
    benchmark::DoNotOptimize(r);
  });
  const auto tr = nhdyn::as_tree(cd);
  agree(nhdyn::reference::aba<double>(tr, s.q, s.qd, tau), qdd, 1e-9, "fd/" + model + ": reference aba vs CRBA + LDLT");
  add("fd/" + model + "/aba_reference", [tr, s, tau]() mutable {
    opaque(s.q), opaque(s.qd), opaque(tau);
    auto r = nhdyn::reference::aba<double>(tr, s.q, s.qd, tau);
    benchmark::DoNotOptimize(r);
  });
  add("fd/" + model + "/crba_ldlt", [cr, s, tau]() mutable {
    opaque(s.q), opaque(s.qd), opaque(tau);
    auto r = cr(s.q, s.qd, tau);
    benchmark::DoNotOptimize(r);
  });
  {  // the same into a reused q̈ and scratch (M, h, M's factor)
    nhdyn::forward_dynamics_scratch<double, nhdyn::dynamic> ws;
    Eigen::VectorXd out;
    cr.evaluate(s.q, s.qd, tau, ws, out);
    agree(out, qdd, 0, "fd/" + model + ": crba_ldlt evaluate vs the call");
    add("fd/" + model + "/crba_ldlt_evaluate", [cr, s, tau, ws, out]() mutable {
      opaque(s.q), opaque(s.qd), opaque(tau);
      cr.evaluate(s.q, s.qd, tau, ws, out);
      benchmark::DoNotOptimize(out.data());
    });
  }
  add("fd/" + model + "/kdl", [k]() { benchmark::DoNotOptimize(kdl::run_fd(k.get())); });
}

// ------------------------------------------------- issue 3: nonholonomic id vs Lagrange

struct nh_state {
  Eigen::VectorXd q, eta, eta_dot;
};
inline nh_state random_nh_state(int n) {
  const state s = random_state(n, 11);
  return {s.q, s.qd.head(n - 1), s.qdd.head(n - 1)};
}

template <int N>
void register_nh(const std::string& model, const chain<double>& cd) {
  const int n = cd.dof();
  const nh_state z = random_nh_state(n);
  const auto cf = cd.fixed<N>();
  const auto cond = ddrive_constraint<dynamic>(n);
  const auto conf = ddrive_constraint<N>(n);
  auto idd = nhdyn::inverse_dynamics(cd, cond);
  auto idf = nhdyn::inverse_dynamics(cf, conf);
  projected_lagrange<nhdyn::differential_drive<double, dynamic>> el(cd, cond);
  const Eigen::VectorXd tau_d = idd(z.q, z.eta, z.eta_dot);
  agree(tau_d, el(z.q, z.eta, z.eta_dot), 1e-10, "nh_id/" + model + ": rne vs projected Lagrange");
  constexpr int M = N - 1;
  const nhdyn::vecN<double, N> qf = z.q;
  const nhdyn::vecN<double, M> ef = z.eta, edf = z.eta_dot;
  agree(idf(qf, ef, edf), tau_d, 1e-14, "nh_id/" + model + ": fixed vs run-time sized");
  add("nh_id/" + model + "/rne", [idd, z]() mutable {
    opaque(z.q), opaque(z.eta), opaque(z.eta_dot);
    auto tau = idd(z.q, z.eta, z.eta_dot);
    benchmark::DoNotOptimize(tau);
  });
  add("nh_id/" + model + "/rne_fixed", [idf, qf, ef, edf]() mutable {
    opaque(qf), opaque(ef), opaque(edf);
    auto tau = idf(qf, ef, edf);
    benchmark::DoNotOptimize(tau);
  });
  // nh_pair/<model>/{fixed, run_time}: a = the holonomic rne of the same chain at the lifted
  // state ξ = lift(ζ), b = the nonholonomic inverse dynamics at ζ, paired (add_paired).
  {
    const auto lifted = nhdyn::lift(cond)(z.q, z.eta, z.eta_dot);
    const state xi{lifted.q, lifted.qd, lifted.qdd};
    const nhdyn::vecN<double, N> xq = xi.q, xqd = xi.qd, xqdd = xi.qdd;
    auto rd = nhdyn::rne(cd);
    auto rf = nhdyn::rne(cf);
    agree(nhdyn::apply_St(cond, z.q, rd(xi.q, xi.qd, xi.qdd)), tau_d, 1e-14, "nh_pair/" + model + ": Sᵀ rne(lift) vs nh");
    add_paired(
        "nh_pair/" + model + "/fixed",
        [rf, xq, xqd, xqdd]() mutable {
          opaque(xq), opaque(xqd), opaque(xqdd);
          auto v = rf(xq, xqd, xqdd);
          benchmark::DoNotOptimize(v);
        },
        [idf, qf, ef, edf]() mutable {
          opaque(qf), opaque(ef), opaque(edf);
          auto tau = idf(qf, ef, edf);
          benchmark::DoNotOptimize(tau);
        });
    add_paired(
        "nh_pair/" + model + "/run_time",
        [rd, xi]() mutable {
          opaque(xi.q), opaque(xi.qd), opaque(xi.qdd);
          auto v = rd(xi.q, xi.qd, xi.qdd);
          benchmark::DoNotOptimize(v);
        },
        [idd, z]() mutable {
          opaque(z.q), opaque(z.eta), opaque(z.eta_dot);
          auto tau = idd(z.q, z.eta, z.eta_dot);
          benchmark::DoNotOptimize(tau);
        });
  }
  // nh_fused/<model>/{fixed, run_time}: a = the plain composition project ∘ rne ∘ lift,
  // b = inverse_dynamics (which runs the call (q, η, η̇) on stack scratch with the lift inside
  // rne): ratio < 0.85 is what the fused path must buy to exist (15 %).
  {
    auto pf = nhdyn::compose(nhdyn::project(conf), nhdyn::rne(cf), nhdyn::lift(conf));
    auto pd = nhdyn::compose(nhdyn::project(cond), nhdyn::rne(cd), nhdyn::lift(cond));
    agree(pf(qf, ef, edf), idf(qf, ef, edf), 0.0, "nh_fused/" + model + ": composition vs fused, bit for bit");
    add_paired(
        "nh_fused/" + model + "/fixed",
        [pf, qf, ef, edf]() mutable {
          opaque(qf), opaque(ef), opaque(edf);
          auto tau = pf(qf, ef, edf);
          benchmark::DoNotOptimize(tau);
        },
        [idf, qf, ef, edf]() mutable {
          opaque(qf), opaque(ef), opaque(edf);
          auto tau = idf(qf, ef, edf);
          benchmark::DoNotOptimize(tau);
        });
    add_paired(
        "nh_fused/" + model + "/run_time",
        [pd, z]() mutable {
          opaque(z.q), opaque(z.eta), opaque(z.eta_dot);
          auto tau = pd(z.q, z.eta, z.eta_dot);
          benchmark::DoNotOptimize(tau);
        },
        [idd, z]() mutable {
          opaque(z.q), opaque(z.eta), opaque(z.eta_dot);
          auto tau = idd(z.q, z.eta, z.eta_dot);
          benchmark::DoNotOptimize(tau);
        });
  }
  add("nh_id/" + model + "/lagrange", [el, z]() mutable {
    opaque(z.q), opaque(z.eta), opaque(z.eta_dot);
    auto tau = el(z.q, z.eta, z.eta_dot);
    benchmark::DoNotOptimize(tau);
  });
  // M_η two ways (nh_forward_dynamics' reduced_inertia_method).
  auto fc = nhdyn::nh_forward_dynamics(cf, conf, {}, nhdyn::reduced_inertia_method::crba);
  auto fr = nhdyn::nh_forward_dynamics(cf, conf, {}, nhdyn::reduced_inertia_method::rne_columns);
  const Eigen::MatrixXd Mc = fc.reduced_inertia(qf), Mr = fr.reduced_inertia(qf);
  agree(Eigen::Map<const Eigen::VectorXd>(Mc.data(), Mc.size()),
        Eigen::Map<const Eigen::VectorXd>(Mr.data(), Mr.size()), 1e-12,
        "nh_inertia/" + model + ": crba vs rne_columns");
  add("nh_inertia/" + model + "/crba", [fc, qf]() mutable {
    opaque(qf);
    auto Me = fc.reduced_inertia(qf);
    benchmark::DoNotOptimize(Me);
  });
  add("nh_inertia/" + model + "/rne_columns", [fr, qf]() mutable {
    opaque(qf);
    auto Me = fr.reduced_inertia(qf);
    benchmark::DoNotOptimize(Me);
  });
}

// ------------------------------------------- "model only what a scene requires" (issue 3)

/// The chain with its massless links (zero mass, zero inertia) given 1 kg and a 0.1 m cube.
chain<double> without_massless_links(const chain<double>& c) {
  std::vector<link<double>> L(c.begin(), c.end());
  for (auto& l : L)
    if (l.mass == 0.0 && l.inertia.isZero(0.0)) {
      l.mass = 1.0;
      l.inertia = nhdyn::box_inertia<double>(1.0, 0.1, 0.1, 0.1);
    }
  return chain<double>(L, c.gravity(), c.name() + "_massive");
}
/// The chain with every other arm link (index ≥ 3, odd) massless.
chain<double> half_arm_massless(const chain<double>& c) {
  std::vector<link<double>> L(c.begin(), c.end());
  for (std::size_t i = 3; i < L.size(); i += 2) {
    L[i].mass = 0.0;
    L[i].com.setZero();
    L[i].inertia.setZero();
  }
  return chain<double>(L, c.gravity(), c.name() + "_half_massless");
}

template <int N>
void register_scene(const std::string& model, const chain<double>& cd) {
  const int n = cd.dof();
  const nh_state z = random_nh_state(n);
  const auto cf = cd.fixed<N>();
  const auto con = ddrive_constraint<N>(n);
  constexpr int M = N - 1;
  const nhdyn::vecN<double, N> q = z.q;
  const nhdyn::vecN<double, M> e = z.eta, ed = z.eta_dot;
  const auto id_case = [&](const std::string& variant, auto id) {
    add("scene/" + model + "/" + variant, [id, q, e, ed]() mutable {
      opaque(q), opaque(e), opaque(ed);
      auto tau = id(q, e, ed);
      benchmark::DoNotOptimize(tau);
    });
  };
  id_case("full", nhdyn::inverse_dynamics(cf, con));
  id_case("no_gravity", nhdyn::inverse_dynamics(cf, con, {false, true}));
  id_case("no_velocity", nhdyn::inverse_dynamics(cf, con, {true, false}));
  id_case("no_gravity_no_velocity", nhdyn::inverse_dynamics(cf, con, {false, false}));
  id_case("with_constraint_forces", nhdyn::inverse_dynamics_with_forces(cf, con));
  {
    auto id = nhdyn::inverse_dynamics(cd, ddrive_constraint<dynamic>(n));
    add("scene/" + model + "/run_time_sized", [id, z]() mutable {
      opaque(z.q), opaque(z.eta), opaque(z.eta_dot);
      auto tau = id(z.q, z.eta, z.eta_dot);
      benchmark::DoNotOptimize(tau);
    });
  }
  id_case("no_massless_links", nhdyn::inverse_dynamics(without_massless_links(cd).fixed<N>(), con));
  if (n > 8) id_case("half_arm_massless", nhdyn::inverse_dynamics(half_arm_massless(cd).fixed<N>(), con));
}

// ------------------------------------------------------ issue 13: trees vs KDL's tree solver

void register_tree(const std::string& model, const nhdyn::tree<double>& t) {
  const int n = t.dof();
  const state s = random_state(n);
  const auto id = nhdyn::rne(t);
  const auto M = nhdyn::mass_matrix(t);
  const Eigen::VectorXd tau = id(s.q, s.qd, s.qdd);
  agree(tau, nhdyn::reference::rne<double>(t, s.q, s.qd, s.qdd), 1e-12, "rne/" + model + ": kernel vs reference");
  const Eigen::MatrixXd H = nhdyn::reference::crba<double>(t, s.q);
  agree(Eigen::Map<const Eigen::VectorXd>(M(s.q).eval().data(), n * n), Eigen::Map<const Eigen::VectorXd>(H.data(), n * n),
        1e-12, "crba/" + model + ": kernel vs reference");
  add("rne/" + model + "/nhdyn", [id, s]() mutable {
    opaque(s.q), opaque(s.qd), opaque(s.qdd);
    auto v = id(s.q, s.qd, s.qdd);
    benchmark::DoNotOptimize(v);
  });
  add("rne/" + model + "/reference", [t, s]() mutable {
    opaque(s.q), opaque(s.qd), opaque(s.qdd);
    auto v = nhdyn::reference::rne<double>(t, s.q, s.qd, s.qdd);
    benchmark::DoNotOptimize(v);
  });
  add("crba/" + model + "/nhdyn", [M, s]() mutable {
    opaque(s.q);
    auto H = M(s.q);
    benchmark::DoNotOptimize(H);
  });
  {  // into results the caller reuses (evaluate): no allocation at all
    Eigen::VectorXd v(n);
    id.evaluate(s.q, s.qd, s.qdd, v);
    agree(v, tau, 0, "rne/" + model + ": evaluate vs the call");
    Eigen::MatrixXd Hm(n, n);
    M.evaluate(s.q, Hm);
    agree(Eigen::Map<const Eigen::VectorXd>(Hm.data(), n * n), Eigen::Map<const Eigen::VectorXd>(M(s.q).eval().data(), n * n), 0,
          "crba/" + model + ": evaluate vs the call");
    // each case's own copy of the function object, state and storage
    const auto rne_evaluate = [id, s, v]() mutable {
      opaque(s.q), opaque(s.qd), opaque(s.qdd);
      id.evaluate(s.q, s.qd, s.qdd, v);
      benchmark::DoNotOptimize(v.data());
    };
    const auto crba_evaluate = [M, s](auto out) {  // into a matrix, or a mass_matrix_result (kept)
      return [M, s, out]() mutable {
        opaque(s.q);
        M.evaluate(s.q, out);
        if constexpr (std::is_same_v<decltype(out), Eigen::MatrixXd>)
          benchmark::DoNotOptimize(out.data());
        else
          benchmark::DoNotOptimize(out.matrix().data());
      };
    };
    // the same into a mass_matrix_result, whose zeros the calls after its first keep
    nhdyn::mass_matrix_result<double> kept;
    M.evaluate(Eigen::VectorXd(-s.q), kept);  // the first call, at another state, writes M whole;
    M.evaluate(s.q, kept);                     // this one only the entries the branches make nonzero
    agree(Eigen::Map<const Eigen::VectorXd>(kept.matrix().data(), n * n), Eigen::Map<const Eigen::VectorXd>(Hm.data(), n * n), 0,
          "crba/" + model + ": kept vs evaluate");
    add("rne/" + model + "/evaluate", rne_evaluate);
    add("crba/" + model + "/evaluate", crba_evaluate(Hm));
    add("crba/" + model + "/kept", crba_evaluate(kept));
    // crba_pair/<tree>: one rne and one CRBA of the same tree and state, both into reused
    // storage, paired (ratio = CRBA / rne; issue 33's target ≤ 0.6); crba_pair_kept/<tree>: the
    // same with M into the mass_matrix_result
    add_paired("crba_pair/" + model, rne_evaluate, crba_evaluate(Hm));
    add_paired("crba_pair_kept/" + model, rne_evaluate, crba_evaluate(kept));
    // ABA (q̈ for τ = rne(q, q̇, q̈) gives q̈ back), as a call and into a reused q̈
    const auto fd = nhdyn::aba(t);
    agree(fd(s.q, s.qd, tau), s.qdd, 1e-8, "aba/" + model + ": aba inverts rne");
    Eigen::VectorXd a(n);
    fd.evaluate(s.q, s.qd, tau, a);
    agree(a, fd(s.q, s.qd, tau), 0, "aba/" + model + ": evaluate vs the call");
    add("aba/" + model + "/nhdyn", [fd, s, tau]() mutable {
      opaque(s.q), opaque(s.qd), opaque(tau);
      auto r = fd(s.q, s.qd, tau);
      benchmark::DoNotOptimize(r);
    });
    add("aba/" + model + "/evaluate", [fd, s, tau, a]() mutable {
      opaque(s.q), opaque(s.qd), opaque(tau);
      fd.evaluate(s.q, s.qd, tau, a);
      benchmark::DoNotOptimize(a.data());
    });
  }
  add("crba/" + model + "/reference", [t, s]() mutable {
    opaque(s.q);
    auto H = nhdyn::reference::crba<double>(t, s.q);
    benchmark::DoNotOptimize(H);
  });
  std::vector<kdl::tree_body> bodies(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto& b = t[i];
    if (!b.R_JB.isIdentity(0) || !b.p_JB.isZero(0)) fail("rne/" + model + ": body offsets are not passed to KDL");
    auto& k = bodies[std::size_t(i)];
    k.parent = b.parent;
    k.prismatic = b.joint == nhdyn::joint_type::prismatic;
    for (int r = 0; r < 3; ++r) {
      k.p[r] = b.p_PJ(r);
      k.axis[r] = b.axis(r);
      k.com[r] = b.com(r);
      for (int c = 0; c < 3; ++c) {
        k.R[3 * r + c] = b.R_PJ(r, c);
        k.inertia[3 * r + c] = b.inertia(r, c);
      }
    }
    k.mass = b.mass;
  }
  std::shared_ptr<kdl::tree_solver> k(kdl::make_tree(bodies.data(), n, t.gravity().data()), kdl::destroy_tree);
  kdl::set_tree_state(k.get(), s.q.data(), s.qd.data(), s.qdd.data());
  if (kdl::run_tree(k.get()) != 0) fail("rne/" + model + ": KDL's tree solver returned an error");
  Eigen::VectorXd tau_k(n);
  kdl::tree_torques(k.get(), tau_k.data());
  agree(tau, tau_k, 1e-10, "rne/" + model + ": nhdyn vs KDL TreeIdSolver_RNE");
  add("rne/" + model + "/kdl", [k]() { benchmark::DoNotOptimize(kdl::run_tree(k.get())); });
}

// ------------------------------------------- issue 18: analytic derivatives of rne on trees

/// deriv_rne/<model>/{rne, analytic, dual}: one double rne of the tree (the tree kernel), the
/// analytic ∂τ/∂(q, q̇) (and M) into a reused result, and the same Jacobian by dual numbers
/// through the tree kernel (8 directions per pass); deriv_rne_pair/<model>: rne and analytic
/// paired (ratio = analytic / rne).
void register_deriv(const std::string& model, const nhdyn::tree<double>& t) {
  const int n = t.dof();
  const state s = random_state(n);
  const auto id = nhdyn::rne(t);
  const auto d = nhdyn::rne_derivatives(t);
  const auto r = d(s.q, s.qd, s.qdd);
  const auto [rq, rqd] = nhdyn::reference::rne_derivatives(t, s.q, s.qd, s.qdd);
  const auto flat = [](const Eigen::MatrixXd& m) { return Eigen::Map<const Eigen::VectorXd>(m.data(), m.size()); };
  agree(flat(r.dq), flat(rq), 1e-11, "deriv_rne/" + model + ": dtau/dq analytic vs reference");
  agree(flat(r.dqd), flat(rqd), 1e-11, "deriv_rne/" + model + ": dtau/dqd analytic vs reference");
  const auto by_duals = [id, n](const Eigen::VectorXd& x, const Eigen::VectorXd& qdd) {
    return nhdyn::jacobian([&](const auto& z) { return id(z.head(n), z.tail(n), qdd.cast<typename std::decay_t<decltype(z)>::Scalar>().eval()); }, x);
  };
  Eigen::VectorXd x(2 * n);
  x << s.q, s.qd;
  const Eigen::MatrixXd J = by_duals(x, s.qdd);
  agree(flat(J.leftCols(n)), flat(r.dq), 1e-11, "deriv_rne/" + model + ": dtau/dq duals vs analytic");
  const auto rne_call = [id, s]() mutable {
    opaque(s.q), opaque(s.qd), opaque(s.qdd);
    auto v = id(s.q, s.qd, s.qdd);
    benchmark::DoNotOptimize(v);
  };
  auto out = std::make_shared<nhdyn::rne_derivatives_result<double>>(r);
  const auto analytic_call = [d, s, out]() mutable {
    opaque(s.q), opaque(s.qd), opaque(s.qdd);
    d.evaluate(s.q, s.qd, s.qdd, *out);
    benchmark::DoNotOptimize(out->dq.data());
  };
  add("deriv_rne/" + model + "/rne", rne_call);
  add("deriv_rne/" + model + "/analytic", analytic_call);
  add("deriv_rne/" + model + "/dual", [by_duals, x, s]() mutable {
    opaque(x);
    auto J = by_duals(x, s.qdd);
    benchmark::DoNotOptimize(J.data());
  });
  add_paired("deriv_rne_pair/" + model, rne_call, analytic_call);
}

/// deriv_fd/<model>/{fd, analytic, dual}: one holonomic forward dynamics call, its analytic
/// A, B (forward_dynamics_derivatives: q̈, ∂q̈/∂(q, q̇), M⁻¹; `evaluate` into a reused result,
/// as deriv_rne's analytic) and the same by duals
/// (linearize_forward_dynamics, 3n directions); deriv_fd_pair/<model>: fd and analytic paired.
void register_deriv_fd(const std::string& model, const nhdyn::tree<double>& t) {
  const int n = t.dof();
  const state s = random_state(n);
  const Eigen::VectorXd tau = nhdyn::rne(t)(s.q, s.qd, s.qdd);
  const auto fd = nhdyn::forward_dynamics(t);
  const auto d = nhdyn::forward_dynamics_derivatives(t);
  const auto a = d(s.q, s.qd, tau);
  const auto b = nhdyn::linearize_forward_dynamics(t, s.q, s.qd, tau);
  const auto A = a.state_space_model().A;
  agree(Eigen::Map<const Eigen::VectorXd>(A.data(), A.size()), Eigen::Map<const Eigen::VectorXd>(b.A.data(), b.A.size()),
        1e-9, "deriv_fd/" + model + ": analytic vs duals");
  const auto fd_call = [fd, s, tau]() mutable {
    opaque(s.q), opaque(s.qd), opaque(tau);
    auto r = fd(s.q, s.qd, tau);
    benchmark::DoNotOptimize(r);
  };
  const auto analytic_call = [d, s, tau, out = a]() mutable {  // into a reused result
    opaque(s.q), opaque(s.qd), opaque(tau);
    d.evaluate(s.q, s.qd, tau, out);
    benchmark::DoNotOptimize(out.dq.data());
  };
  add("deriv_fd/" + model + "/fd", fd_call);
  add("deriv_fd/" + model + "/analytic", analytic_call);
  add_paired("deriv_fd_pair/" + model, fd_call, analytic_call);
  add("deriv_fd/" + model + "/dual", [t, s, tau]() mutable {
    opaque(s.q), opaque(s.qd), opaque(tau);
    auto r = nhdyn::linearize_forward_dynamics(t, s.q, s.qd, tau);
    benchmark::DoNotOptimize(r.A.data());
  });
}

/// deriv_nh/<model>/{nh, analytic, dual}: one nonholonomic inverse dynamics call, its analytic
/// ∂τ/∂(q, η, η̇) (inverse_dynamics_derivatives, `evaluate` into a reused result) and the same by duals
/// (inverse_dynamics_linearizer, built once); deriv_nh_pair/<model>: nh and analytic paired;
/// deriv_nh_fd/<model>/{fd, analytic, dual}: the constrained forward dynamics and its A, B;
/// deriv_nh_fd_pair/<model>: fd and analytic paired.
template <class C>
void register_deriv_nh(const std::string& model, const nhdyn::tree<double>& t, const C& c) {
  const int n = c.dof(), m = c.m();
  const state s = random_state(n);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const Eigen::VectorXd q = s.q, eta = Eigen::VectorXd::NullaryExpr(m, [&] { return U(rng); }),
                        eta_dot = Eigen::VectorXd::NullaryExpr(m, [&] { return U(rng); });
  const auto id = nhdyn::inverse_dynamics(t, c);
  const auto d = nhdyn::inverse_dynamics_derivatives(t, c);
  const nhdyn::inverse_dynamics_linearizer lin(t, c);
  const auto J = d(q, eta, eta_dot).J();
  const auto Jd = lin(q, eta, eta_dot).J;
  agree(Eigen::Map<const Eigen::VectorXd>(J.data(), J.size()), Eigen::Map<const Eigen::VectorXd>(Jd.data(), Jd.size()),
        1e-11, "deriv_nh/" + model + ": analytic vs duals");
  const auto nh_call = [id, q, eta, eta_dot]() mutable {
    opaque(q), opaque(eta), opaque(eta_dot);
    auto r = id(q, eta, eta_dot);
    benchmark::DoNotOptimize(r);
  };
  const auto analytic_call = [d, q, eta, eta_dot, out = d(q, eta, eta_dot)]() mutable {  // into a reused result
    opaque(q), opaque(eta), opaque(eta_dot);
    d.evaluate(q, eta, eta_dot, out);
    benchmark::DoNotOptimize(out.dq.data());
  };
  add("deriv_nh/" + model + "/nh", nh_call);
  add("deriv_nh/" + model + "/analytic", analytic_call);
  add("deriv_nh/" + model + "/dual", [lin, q, eta, eta_dot]() mutable {
    opaque(q), opaque(eta), opaque(eta_dot);
    auto r = lin(q, eta, eta_dot);
    benchmark::DoNotOptimize(r.J.data());
  });
  add_paired("deriv_nh_pair/" + model, nh_call, analytic_call);
  const Eigen::VectorXd tau = id(q, eta, eta_dot);
  const auto fd = nhdyn::nh_forward_dynamics(t, c);
  const auto fdd = nhdyn::forward_dynamics_derivatives(t, c);
  const nhdyn::forward_dynamics_linearizer fdl(t, c);
  const auto A = fdd(q, eta, tau).ss.A;
  const auto Ad = fdl(q, eta, tau).A;
  agree(Eigen::Map<const Eigen::VectorXd>(A.data(), A.size()), Eigen::Map<const Eigen::VectorXd>(Ad.data(), Ad.size()),
        1e-9, "deriv_nh_fd/" + model + ": analytic vs duals");
  const auto nh_fd_call = [fd, q, eta, tau]() mutable {
    opaque(q), opaque(eta), opaque(tau);
    auto r = fd(q, eta, tau);
    benchmark::DoNotOptimize(r);
  };
  const auto nh_fd_analytic_call = [fdd, q, eta, tau, out = fdd(q, eta, tau)]() mutable {  // reused result
    opaque(q), opaque(eta), opaque(tau);
    fdd.evaluate(q, eta, tau, out);
    benchmark::DoNotOptimize(out.ss.A.data());
  };
  add("deriv_nh_fd/" + model + "/fd", nh_fd_call);
  add("deriv_nh_fd/" + model + "/analytic", nh_fd_analytic_call);
  add_paired("deriv_nh_fd_pair/" + model, nh_fd_call, nh_fd_analytic_call);
  add("deriv_nh_fd/" + model + "/dual", [fdl, q, eta, tau]() mutable {
    opaque(q), opaque(eta), opaque(tau);
    auto r = fdl(q, eta, tau);
    benchmark::DoNotOptimize(r.A.data());
  });
}

/// batch_rne/<model>/{one, batch}: one double rne of the tree (run-time sized), and
/// rne_batch over 256 states in one call (time per call: divide by 256 for a state);
/// batch_fd/<model>/{one, batch}: the same for aba and forward_dynamics_batch.
constexpr int batch_states = 256;
void register_batch(const std::string& model, const nhdyn::tree<double>& t) {
  const int n = t.dof();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const Eigen::MatrixXd Q = Eigen::MatrixXd::NullaryExpr(n, batch_states, [&] { return 3 * U(rng); }),
                        QD = Eigen::MatrixXd::NullaryExpr(n, batch_states, [&] { return U(rng); }),
                        QDD = Eigen::MatrixXd::NullaryExpr(n, batch_states, [&] { return U(rng); });
  const auto id = nhdyn::rne(t);
  const auto b = nhdyn::rne_batch(t);
  const Eigen::MatrixXd T = b(Q, QD, QDD);
  for (int k = 0; k < batch_states; ++k)
    agree(T.col(k), id(Q.col(k), QD.col(k), QDD.col(k)), 1e-12, "batch_rne/" + model + ": a column vs rne");
  const Eigen::VectorXd q = Q.col(0), qd = QD.col(0), qdd = QDD.col(0);
  add("batch_rne/" + model + "/one", [id, q, qd, qdd]() mutable {
    opaque(q), opaque(qd), opaque(qdd);
    auto v = id(q, qd, qdd);
    benchmark::DoNotOptimize(v);
  });
  add("batch_rne/" + model + "/batch", [b, Q, QD, QDD]() mutable {
    opaque(Q), opaque(QD), opaque(QDD);
    auto v = b(Q, QD, QDD);
    benchmark::DoNotOptimize(v.data());
  });
  const auto fd = nhdyn::aba(t);
  const auto fb = nhdyn::forward_dynamics_batch(t);
  const Eigen::MatrixXd A = fb(Q, QD, T);
  for (int k = 0; k < batch_states; ++k)
    agree(A.col(k), fd(Q.col(k), QD.col(k), T.col(k)), 1e-9, "batch_fd/" + model + ": a column vs aba");
  const Eigen::VectorXd tau = T.col(0);
  add("batch_fd/" + model + "/one", [fd, q, qd, tau]() mutable {
    opaque(q), opaque(qd), opaque(tau);
    auto v = fd(q, qd, tau);
    benchmark::DoNotOptimize(v);
  });
  add("batch_fd/" + model + "/batch", [fb, Q, QD, T]() mutable {
    opaque(Q), opaque(QD), opaque(T);
    auto v = fb(Q, QD, T);
    benchmark::DoNotOptimize(v.data());
  });
}

}  // namespace
#ifdef NHDYN_BENCH_URDF
/// A robot file's constrained robot (a tree and one of its constraint types): the paper's
/// method against the projected Euler–Lagrange formulation on the tree, paired with the
/// holonomic rne at the lifted state, and the constrained forward dynamics.
template <class C>
void register_wheeled(const std::string& model, const nhdyn::tree<double>& t, const C& c) {
  const int n = c.dof(), m = c.m(), p = nhdyn::actuator_count(c);
  const state s = random_state(n);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const Eigen::VectorXd q = s.q, eta = Eigen::VectorXd::NullaryExpr(m, [&] { return U(rng); }),
                        eta_dot = Eigen::VectorXd::NullaryExpr(m, [&] { return U(rng); }),
                        tau_in = Eigen::VectorXd::NullaryExpr(p, [&] { return U(rng); });
  auto id = nhdyn::inverse_dynamics(t, c);
  projected_lagrange<C, tree_lagrange_terms> el(t, c);
  const Eigen::VectorXd tau = id(q, eta, eta_dot);
  agree(tau, el(q, eta, eta_dot), 1e-10, "nh_id/" + model + ": rne vs projected Lagrange");
  // the method's call and E–L's, timed alone (nh_id) and paired (nh_pair, el_pair)
  const auto nh_call = [id, q, eta, eta_dot]() mutable {
    opaque(q), opaque(eta), opaque(eta_dot);
    auto r = id(q, eta, eta_dot);
    benchmark::DoNotOptimize(r);
  };
  const auto el_call = [el, q, eta, eta_dot]() mutable {
    opaque(q), opaque(eta), opaque(eta_dot);
    auto r = el(q, eta, eta_dot);
    benchmark::DoNotOptimize(r);
  };
  add("nh_id/" + model + "/rne", nh_call);
  add("nh_id/" + model + "/lagrange", el_call);
  // the method into a τ the caller reuses (inverse_dynamics on a tree: every built-in constraint)
  constexpr bool has_evaluate = requires(Eigen::VectorXd& out) { id.evaluate(q, eta, eta_dot, out); };
  if constexpr (has_evaluate) {
    Eigen::VectorXd out = Eigen::VectorXd::Zero(p);
    id.evaluate(q, eta, eta_dot, out);
    agree(out, tau, 0.0, "nh_id/" + model + ": evaluate into a reused tau vs the call");
    add("nh_id/" + model + "/evaluate", [id, q, eta, eta_dot, out]() mutable {
      opaque(q), opaque(eta), opaque(eta_dot);
      id.evaluate(q, eta, eta_dot, out);
      benchmark::DoNotOptimize(out.data());
    });
  }
  const auto xi = nhdyn::lift(c)(q, eta, eta_dot);
  const Eigen::VectorXd xq = xi.q, xqd = xi.qd, xqdd = xi.qdd;
  auto rn = nhdyn::rne(t);
  agree(nhdyn::detail::solve_StE(c, q, nhdyn::apply_St(c, q, rn(xq, xqd, xqdd))), tau, 1e-13,
        "nh_pair/" + model + ": (SᵀE)⁺Sᵀ rne(lift) vs nh");
  add_paired(
      "nh_pair/" + model + "/run_time",
      [rn, xq, xqd, xqdd]() mutable {
        opaque(xq), opaque(xqd), opaque(xqdd);
        auto v = rn(xq, xqd, xqdd);
        benchmark::DoNotOptimize(v);
      },
      nh_call);
  // E–L / nh itself, paired: both sides see the same machine state, as nh / holonomic does
  add_paired("el_pair/" + model, nh_call, el_call);
  if constexpr (has_evaluate) {
    // the same pair with both sides into storage the caller reuses (no allocator in either)
    add_paired(
        "nh_pair/" + model + "/evaluate",
        [rn, xq, xqd, xqdd, v = Eigen::VectorXd(xq.size())]() mutable {
          opaque(xq), opaque(xqd), opaque(xqdd);
          rn.evaluate(xq, xqd, xqdd, v);
          benchmark::DoNotOptimize(v.data());
        },
        [id, q, eta, eta_dot, out = Eigen::VectorXd(tau.size())]() mutable {
          opaque(q), opaque(eta), opaque(eta_dot);
          id.evaluate(q, eta, eta_dot, out);
          benchmark::DoNotOptimize(out.data());
        });
  }
  auto fd = nhdyn::nh_forward_dynamics(t, c);
  agree(fd(q, eta, tau), eta_dot, 1e-9, "nh_fd/" + model + ": forward dynamics inverts inverse dynamics");
  add("nh_fd/" + model + "/nhdyn", [fd, q, eta, tau_in]() mutable {
    opaque(q), opaque(eta), opaque(tau_in);
    auto r = fd(q, eta, tau_in);
    benchmark::DoNotOptimize(r);
  });
  // the same into a result the caller reuses (η̇, M, S, M_η and its factor)
  nhdyn::nh_forward_dynamics_result<double> fout;
  fd.evaluate(q, eta, tau_in, fout);
  agree(fout.eta_dot, fd(q, eta, tau_in), 0.0, "nh_fd/" + model + ": evaluate into a reused result vs the call");
  add("nh_fd/" + model + "/evaluate", [fd, q, eta, tau_in, fout]() mutable {
    opaque(q), opaque(eta), opaque(tau_in);
    fd.evaluate(q, eta, tau_in, fout);
    benchmark::DoNotOptimize(fout.eta_dot.data());
  });
}

/// "Model only what the scene requires" on one robot file (the TIAGo-style robot): the cost of
/// the nonholonomic inverse and forward dynamics of the full model and of it with joints held
/// (nhdyn::lock through the robot file's machinery), and of each choice of terms; the counter
/// `arm_rel_err` says what a choice costs in accuracy: |τ − τ_ref|∞ / |τ_ref|∞ over the kept
/// actuators, τ_ref the full model's with every term (friction included) at a state where the
/// held joints move too: each joint entry of η uniform within its URDF velocity limit (1 where
/// it has none), η̇ the same in per-second units, q uniform in [−1, 1].
void register_requires(const std::string& name, const nhdyn::io::robot_model& full,
                       const std::vector<std::pair<std::string, double>>& held) {
  const auto& cf = std::get<nhdyn::wheeled_base<double>>(*full.constraint);
  const auto r = nhdyn::io::lock_robot(full, held, "bench: ");
  const auto& cr = std::get<nhdyn::wheeled_base<double>>(*r.constraint);
  const auto jf = full.model.joint_names(), jr = r.model.joint_names();
  const auto ef = cf.eta_names(jf), er = cr.eta_names(jr), tf = full.tau_names(), tr = r.tau_names();
  const auto index = [](const std::vector<std::string>& from, const std::vector<std::string>& names) {
    std::vector<Eigen::Index> out;
    for (const auto& n : names) out.push_back(std::find(from.begin(), from.end(), n) - from.begin());
    return out;
  };
  const auto iq = index(jf, jr), ie = index(ef, er), it = index(tf, tr);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(cf.m());
  for (int i = 0; i < cf.m(); ++i) {
    const auto j = std::find(jf.begin(), jf.end(), ef[std::size_t(i)]);
    if (j != jf.end() && std::isfinite(full.model[int(j - jf.begin())].limits.velocity))
      scale(i) = full.model[int(j - jf.begin())].limits.velocity;
  }
  const Eigen::VectorXd q = Eigen::VectorXd::NullaryExpr(cf.dof(), [&] { return U(rng); });
  const Eigen::VectorXd eta = Eigen::VectorXd::NullaryExpr(cf.m(), [&] { return U(rng); }).cwiseProduct(scale),
                        eta_dot = Eigen::VectorXd::NullaryExpr(cf.m(), [&] { return U(rng); }).cwiseProduct(scale);
  Eigen::VectorXd qr = q(iq), etar = eta(ie), eta_dotr = eta_dot(ie);
  const Eigen::VectorXd tau_ref = nhdyn::inverse_dynamics(full.model, cf, {}, nhdyn::friction(full.model))(q, eta, eta_dot);
  const Eigen::VectorXd ref_kept = tau_ref(it);
  const auto rel_err = [&](const Eigen::VectorXd& tau) {
    return (tau - ref_kept).lpNorm<Eigen::Infinity>() / ref_kept.lpNorm<Eigen::Infinity>();
  };
  const auto case_ = [&](const std::string& variant, auto id, const Eigen::VectorXd& qq, const Eigen::VectorXd& ee,
                         const Eigen::VectorXd& ed, double err) {
    auto fp = std::make_shared<decltype(id)>(std::move(id));
    const std::string full_name = "requires/" + name + "/" + variant;
    benchmark::RegisterBenchmark(full_name.c_str(), [fp, qq, ee, ed, err](benchmark::State& st) mutable {
      const auto call = [&] {
        opaque(qq), opaque(ee), opaque(ed);
        auto tau = (*fp)(qq, ee, ed);
        benchmark::DoNotOptimize(tau);
      };
      st.counters["allocs_per_call"] = allocs_per_call(call);
      st.counters["arm_rel_err"] = err;
      st.counters["dof"] = double(qq.size());
      for (auto _ : st) call();
    });
  };
  const auto kept = [&](const Eigen::VectorXd& tau_full) { return Eigen::VectorXd(tau_full(it)); };
  // the full model with every term (the reference), and with the default terms (no friction)
  case_("full/all", nhdyn::inverse_dynamics(full.model, cf, {}, nhdyn::friction(full.model)), q, eta, eta_dot, 0.0);
  case_("full/default", nhdyn::inverse_dynamics(full.model, cf), q, eta, eta_dot,
        rel_err(kept(nhdyn::inverse_dynamics(full.model, cf)(q, eta, eta_dot))));
  // held joints: the kept joints' torques, the held ones treated as still; then each term
  // left out of that model in turn
  const auto held_id = [&](nhdyn::rne_options o) { return nhdyn::inverse_dynamics(r.model, cr, o, nhdyn::friction(r.model)); };
  const auto lr = [&](nhdyn::rne_options o) { return nhdyn::inverse_dynamics(r.model, cr, o); };
  case_("locked/all", held_id({}), qr, etar, eta_dotr, rel_err(held_id({})(qr, etar, eta_dotr)));
  case_("locked/default", lr({}), qr, etar, eta_dotr, rel_err(lr({})(qr, etar, eta_dotr)));
  case_("locked/all_but_velocity", held_id({true, false}), qr, etar, eta_dotr, rel_err(held_id({true, false})(qr, etar, eta_dotr)));
  case_("locked/all_but_gravity", held_id({false, true}), qr, etar, eta_dotr, rel_err(held_id({false, true})(qr, etar, eta_dotr)));
  // exactness of the held model where the held joints do hold still: its torques are the
  // full model's kept rows
  Eigen::VectorXd qs = q, es = eta, eds = eta_dot;
  for (const auto& [joint, x] : r.locked) {
    qs(std::find(jf.begin(), jf.end(), joint) - jf.begin()) = x;
    const auto e = std::find(ef.begin(), ef.end(), joint) - ef.begin();
    es(e) = eds(e) = 0;
  }
  agree(lr({})(Eigen::VectorXd(qs(iq)), Eigen::VectorXd(es(ie)), Eigen::VectorXd(eds(ie))),
        kept(nhdyn::inverse_dynamics(full.model, cf)(qs, es, eds)), 1e-10, "requires/" + name + ": held model = full model's rows");
  // forward dynamics, full and held
  const auto fdf = nhdyn::nh_forward_dynamics(full.model, cf);
  const auto fdr = nhdyn::nh_forward_dynamics(r.model, cr);
  const Eigen::VectorXd tauf = nhdyn::inverse_dynamics(full.model, cf)(q, eta, eta_dot),
                        taur = lr({})(qr, etar, eta_dotr);
  agree(fdr(qr, etar, taur), eta_dotr, 1e-8, "requires/" + name + ": held fd inverts id");
  add("requires/" + name + "/full/fd", [fdf, q, eta, tauf]() mutable {
    opaque(q), opaque(eta), opaque(tauf);
    auto r = fdf(q, eta, tauf);
    benchmark::DoNotOptimize(r);
  });
  add("requires/" + name + "/locked/fd", [fdr, qr, etar, taur]() mutable {
    opaque(qr), opaque(etar), opaque(taur);
    auto r = fdr(qr, etar, taur);
    benchmark::DoNotOptimize(r);
  });
  benchmark::AddCustomContext("requires_" + name + "_dof", std::to_string(cf.dof()) + " full, " + std::to_string(cr.dof()) + " held");
}
#endif

}  // namespace nhdyn_bench

int main(int argc, char** argv) {
  using namespace nhdyn_bench;
  const auto p5 = nhdyn::presets::paper5_chain<double>().dynamic_size();
  register_rne<5>("paper5", p5);
  register_rne<6>("puma560", nhdyn::presets::puma560<double>().dynamic_size());
  register_rne<6>("rev6", random_chain(6));
  register_rne<12>("rev12", random_chain(12));
  register_rne<24>("rev24", random_chain(24));
  register_rne<48>("rev48", random_chain(48));
  register_rne<96>("rev96", random_chain(96));

  register_fd("paper5", p5);
  register_fd("puma560", nhdyn::presets::puma560<double>().dynamic_size());
  for (int n : {6, 12, 24, 48, 96}) register_fd("rev" + std::to_string(n), random_chain(n));

  register_nh<5>("paper5", p5);
  register_rne<5>("ddrive_arm2", ddrive_arm(2), false);
  register_nh<5>("ddrive_arm2", ddrive_arm(2));
  register_rne<7>("ddrive_arm4", ddrive_arm(4), false);
  register_nh<7>("ddrive_arm4", ddrive_arm(4));
  register_rne<11>("ddrive_arm8", ddrive_arm(8), false);
  register_nh<11>("ddrive_arm8", ddrive_arm(8));
  register_rne<19>("ddrive_arm16", ddrive_arm(16), false);
  register_nh<19>("ddrive_arm16", ddrive_arm(16));
  register_rne<27>("ddrive_arm24", ddrive_arm(24), false);
  register_nh<27>("ddrive_arm24", ddrive_arm(24));
  register_rne<51>("ddrive_arm48", ddrive_arm(48), false);
  register_nh<51>("ddrive_arm48", ddrive_arm(48));

  register_scene<5>("paper5", p5);
  register_scene<27>("ddrive_arm24", ddrive_arm(24));

#ifdef NHDYN_BENCH_URDF
  register_tree("mobile_manipulator", nhdyn::io::load_urdf(NHDYN_SOURCE_DIR "/examples/urdf/mobile_manipulator.urdf"));
  // the project's TIAGo-style (56 joints, a five-finger hand) and PR2-style (four driven castors
  // and an arm) files, as trees
  register_tree("tiago_style", nhdyn::io::load_urdf(NHDYN_SOURCE_DIR "/examples/urdf/tiago_style.urdf"));
  register_tree("powered_castors_arm", nhdyn::io::load_urdf(NHDYN_SOURCE_DIR "/examples/urdf/powered_castors_arm.urdf"));
  for (const auto& [name, file] : {std::pair{"mobile_manipulator_ddrive", "mobile_manipulator.json"},
                                   std::pair{"mobile_manipulator_wheels", "mobile_manipulator_wheels.json"},
                                   std::pair{"mobile_manipulator_bicycle", "mobile_manipulator_bicycle.json"},
                                   std::pair{"mobile_manipulator_castors", "mobile_manipulator_castors.json"},
                                   std::pair{"mecanum_arm", "mecanum_arm.json"}, std::pair{"omni3_arm", "omni3_arm.json"},
                                   std::pair{"castor_drive_arm", "castor_drive_arm.json"},
                                   std::pair{"powered_castors_arm", "powered_castors_arm.json"}}) {
    const auto r = nhdyn::io::load_robot_file(std::string(NHDYN_SOURCE_DIR "/examples/robots/") + file);
    const std::string robot = name;  // a lambda may not capture a structured binding under clang 14
    std::visit([&](const auto& c) {
      register_wheeled(robot, r.model, c);
      register_deriv_nh(robot, r.model, c);
    }, *r.constraint);
    if (std::string(name) == "mobile_manipulator_wheels") {  // the same two wheels as a wheeled_base: `wheels` is its fast instance
      const nhdyn::wheeled_base<double> wb(r.model, {{nhdyn::wheel_kind::fixed, "wheel_left_joint", "", 0.1},
                                                     {nhdyn::wheel_kind::fixed, "wheel_right_joint", "", 0.1}});
      register_wheeled("mobile_manipulator_wheels_as_wheeled_base", r.model, wb);
    }
  }
  register_requires("tiago_style", nhdyn::io::load_robot_file(NHDYN_SOURCE_DIR "/examples/robots/tiago_style.json"),
                    {{"hand_*", 0.1}, {"head_*", 0.2}});
#endif
  std::mt19937_64 tree_rng(41);
  std::vector<std::pair<std::string, nhdyn::tree<double>>> trees;
  // branching trees, URDF-like (no body offsets); 96 bodies: past the kernels' stack scratch
  for (int n : {12, 24, 48, 96})
    trees.emplace_back("tree" + std::to_string(n), nhdyn_ref::random_tree(tree_rng, n, 0.4, false));
  for (const auto& [name, t] : trees) register_tree(name, t);

  register_deriv("paper5", nhdyn::as_tree(p5));
  register_deriv("puma560", nhdyn::as_tree(nhdyn::presets::puma560<double>()));
#ifdef NHDYN_BENCH_URDF
  register_deriv("mobile_manipulator", nhdyn::io::load_urdf(NHDYN_SOURCE_DIR "/examples/urdf/mobile_manipulator.urdf"));
#endif
  for (const auto& [name, t] : trees) register_deriv(name, t);
  register_deriv_nh("paper5", nhdyn::as_tree(p5), ddrive_constraint<dynamic>(5));
  register_deriv_fd("paper5", nhdyn::as_tree(p5));
  register_deriv_fd("puma560", nhdyn::as_tree(nhdyn::presets::puma560<double>()));
  for (const auto& [name, t] : trees) register_deriv_fd(name, t);
  register_batch("paper5", nhdyn::as_tree(p5));
  register_batch("puma560", nhdyn::as_tree(nhdyn::presets::puma560<double>()));
#ifdef NHDYN_BENCH_URDF
  register_batch("mobile_manipulator", nhdyn::io::load_urdf(NHDYN_SOURCE_DIR "/examples/urdf/mobile_manipulator.urdf"));
#endif
  for (const auto& [name, t] : trees)
    if (t.dof() <= 48) register_batch(name, t);
  benchmark::AddCustomContext("simd_width", std::to_string(nhdyn::simd_width));

  benchmark::AddCustomContext("nhdyn_compiler", NHDYN_BENCH_CXX);
  benchmark::AddCustomContext("nhdyn_flags", NHDYN_BENCH_FLAGS);
  benchmark::AddCustomContext("kdl_flags", "-O3 (baseline x86-64, no -march)");
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
