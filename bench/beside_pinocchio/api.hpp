/// \file bench/beside_pinocchio/api.hpp
/// nhdyn beside Pinocchio, timed by hand (docs/performance.md, "Beside Pinocchio"): not part of
/// the build, its tests or CI. run.sh builds it against a Pinocchio source tree. Each library is
/// compiled in its own file (nh.cpp, pin.cpp), both with the same flags; main.cpp converts each
/// nhdyn tree to a Pinocchio model (pin.cpp), checks that both give the same τ, M, q̈ and
/// derivatives, and times the two in alternating blocks.
#pragma once
#include <Eigen/Core>
#include <chrono>
#include <vector>
#include <nhdyn/model/tree.hpp>
struct states { int n; std::vector<Eigen::VectorXd> q, qd, qdd, tau; };
// τ, M, q̈ (ABA) and the derivatives' own τ, ∂τ/∂q, ∂τ/∂q̇ and M, at the first state
struct outs { Eigen::VectorXd tau, qdd, tau_d; Eigen::MatrixXd M, dq, dv, M_d; };
// each: make a context; run one algorithm K times over the 64 states; fill outs for state 0
void* nh_make(const nhdyn::tree<double>& t);
double nh_run(void* c, int algo, const states& s, long K);
void nh_outs(void* c, const states& s, outs& o);
void nh_free(void* c);
void* pin_make(const nhdyn::tree<double>& t);
double pin_run(void* c, int algo, const states& s, long K);
void pin_outs(void* c, const states& s, outs& o);
void pin_free(void* c);
// algo: 0 rne, 1 crba, 2 aba, 3 rne derivatives; 4 crba and 5 aba (Pinocchio: 1 and 2 in the
// LOCAL convention, 4 and 5 in the WORLD one; nhdyn has one of each)

/// Seconds for K calls of call(i), i cycling through the 64 states; each library's file runs
/// its own loop (no call between the files inside it).
template <class F>
double time_calls(long K, const F& call) {
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < K; ++k) {
    call(int(k & 63));
    asm volatile("" ::: "memory");
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
