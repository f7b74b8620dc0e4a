/// \file bench/beside_pinocchio/nh.cpp
/// nhdyn's side: rne, CRBA, ABA and ∂τ/∂(q, q̇) into results the caller reuses (`evaluate`;
/// M into a mass_matrix_result, which keeps the tree's zeros as Pinocchio's Data::M does).
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/dynamics/rne_derivatives.hpp>
#include "api.hpp"
struct nh_ctx {
  decltype(nhdyn::rne(std::declval<nhdyn::tree<double>>())) id;
  decltype(nhdyn::mass_matrix(std::declval<nhdyn::tree<double>>())) M;
  decltype(nhdyn::aba(std::declval<nhdyn::tree<double>>())) fd;
  decltype(nhdyn::rne_derivatives(std::declval<nhdyn::tree<double>>())) d;
  Eigen::VectorXd v, a; nhdyn::mass_matrix_result<double> H; nhdyn::rne_derivatives_result<double> r;
};
void* nh_make(const nhdyn::tree<double>& t) {
  const int n = t.dof();
  auto* c = new nh_ctx{nhdyn::rne(t), nhdyn::mass_matrix(t), nhdyn::aba(t), nhdyn::rne_derivatives(t),
                       Eigen::VectorXd(n), Eigen::VectorXd(n), {}, {}};
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  c->r = c->d(z, z, z);
  return c;
}
double nh_run(void* p, int algo, const states& s, long K) {
  auto& c = *static_cast<nh_ctx*>(p);
  return time_calls(K, [&](int i) {
    switch (algo) {
      case 0: c.id.evaluate(s.q[i], s.qd[i], s.qdd[i], c.v); break;
      case 1: case 4: c.M.evaluate(s.q[i], c.H); break;
      case 2: case 5: c.fd.evaluate(s.q[i], s.qd[i], s.tau[i], c.a); break;
      case 3: c.d.evaluate(s.q[i], s.qd[i], s.qdd[i], c.r); break;
    }
  });
}
void nh_outs(void* p, const states& s, outs& o) {
  auto& c = *static_cast<nh_ctx*>(p);
  c.id.evaluate(s.q[0], s.qd[0], s.qdd[0], c.v); o.tau = c.v;
  c.M.evaluate(s.q[1], c.H);  // the first call writes M whole, the second (checked) keeps its zeros
  c.M.evaluate(s.q[0], c.H); o.M = c.H.matrix();
  c.fd.evaluate(s.q[0], s.qd[0], s.tau[0], c.a); o.qdd = c.a;
  c.d.evaluate(s.q[0], s.qd[0], s.qdd[0], c.r); o.dq = c.r.dq; o.dv = c.r.dqd;
  o.tau_d = c.r.tau; o.M_d = c.r.M;
}
void nh_free(void* p) { delete static_cast<nh_ctx*>(p); }
