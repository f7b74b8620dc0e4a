/// \file bench/beside_pinocchio/pin.cpp
/// Pinocchio's side: an nhdyn tree as a Pinocchio model, and its rnea, crba (both conventions),
/// aba and computeRNEADerivatives.
#include <nhdyn/model/tree.hpp>
#include "pinocchio/multibody/model.hpp"
#include "pinocchio/multibody/data.hpp"
#include "pinocchio/algorithm/rnea.hpp"
#include "pinocchio/algorithm/crba.hpp"
#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/rnea-derivatives.hpp"
#include <chrono>
#include "api.hpp"
struct pin_ctx { pinocchio::Model m; pinocchio::Data d; };
static pinocchio::SE3 se3(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) { return pinocchio::SE3(R, p); }
// nhdyn places body i as B_i = B_λ · X_PJ · joint(q_i) · X_JB; Pinocchio places joint i as
// J_i = J_λ · placement · joint(q_i). With J_i = nhdyn's moved joint frame, placement =
// X_JB(λ) · X_PJ(i), and the body's inertia (in its body frame) is appended at X_JB(i). Every
// joint has one coordinate (a continuous joint too, as in nhdyn; Pinocchio's URDF parser would
// give it cos and sin).
void* pin_make(const nhdyn::tree<double>& t) {
  auto* c = new pin_ctx;
  auto& m = c->m;
  m.gravity.linear(t.gravity());
  const int n = t.dof();
  for (int i = 0; i < n; ++i) {
    const auto& b = t[i];
    const pinocchio::JointIndex parent = b.parent < 0 ? 0 : pinocchio::JointIndex(b.parent + 1);
    const pinocchio::SE3 Xp = b.parent < 0 ? pinocchio::SE3::Identity() : se3(t[b.parent].R_JB, t[b.parent].p_JB);
    const pinocchio::SE3 place = Xp * se3(b.R_PJ, b.p_PJ);
    const Eigen::Vector3d u = b.axis;
    pinocchio::JointIndex id;
    // as Pinocchio's URDF parser: a joint about a coordinate axis gets its specialised model
    if (b.joint == nhdyn::joint_type::revolute) {
      if (u == Eigen::Vector3d::UnitX()) id = m.addJoint(parent, pinocchio::JointModelRX(), place, b.joint_name);
      else if (u == Eigen::Vector3d::UnitY()) id = m.addJoint(parent, pinocchio::JointModelRY(), place, b.joint_name);
      else if (u == Eigen::Vector3d::UnitZ()) id = m.addJoint(parent, pinocchio::JointModelRZ(), place, b.joint_name);
      else id = m.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(u), place, b.joint_name);
    } else {
      if (u == Eigen::Vector3d::UnitX()) id = m.addJoint(parent, pinocchio::JointModelPX(), place, b.joint_name);
      else if (u == Eigen::Vector3d::UnitY()) id = m.addJoint(parent, pinocchio::JointModelPY(), place, b.joint_name);
      else if (u == Eigen::Vector3d::UnitZ()) id = m.addJoint(parent, pinocchio::JointModelPZ(), place, b.joint_name);
      else id = m.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(u), place, b.joint_name);
    }
    m.appendBodyToJoint(id, pinocchio::Inertia(b.mass, b.com, pinocchio::Symmetric3(b.inertia)), se3(b.R_JB, b.p_JB));
  }
  for (int i = 0; i < n; ++i) m.armature[i] = t[i].armature;
  c->d = pinocchio::Data(m);
  return c;
}
double pin_run(void* p, int algo, const states& s, long K) {
  auto& c = *static_cast<pin_ctx*>(p);
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < K; ++k) {
    const int i = int(k & 63);
    switch (algo) {
      case 0: pinocchio::rnea(c.m, c.d, s.q[i], s.qd[i], s.qdd[i]); break;
      case 1: pinocchio::crba(c.m, c.d, s.q[i], pinocchio::Convention::LOCAL); break;
      case 4: pinocchio::crba(c.m, c.d, s.q[i], pinocchio::Convention::WORLD); break;
      case 2: pinocchio::aba(c.m, c.d, s.q[i], s.qd[i], s.tau[i]); break;
      case 3: pinocchio::computeRNEADerivatives(c.m, c.d, s.q[i], s.qd[i], s.qdd[i]); break;
    }
    asm volatile("" ::: "memory");
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
void pin_outs(void* p, const states& s, outs& o) {
  auto& c = *static_cast<pin_ctx*>(p);
  o.tau = pinocchio::rnea(c.m, c.d, s.q[0], s.qd[0], s.qdd[0]);
  pinocchio::crba(c.m, c.d, s.q[0], pinocchio::Convention::WORLD);
  o.M = c.d.M; o.M.triangularView<Eigen::StrictlyLower>() = o.M.transpose();
  pinocchio::crba(c.m, c.d, s.q[0], pinocchio::Convention::LOCAL);
  Eigen::MatrixXd ML = c.d.M; ML.triangularView<Eigen::StrictlyLower>() = ML.transpose();
  if ((ML - o.M).norm() > 1e-9 * (1 + o.M.norm())) o.M.setConstant(1e300);  // the conventions disagree
  o.qdd = pinocchio::aba(c.m, c.d, s.q[0], s.qd[0], s.tau[0]);
  pinocchio::computeRNEADerivatives(c.m, c.d, s.q[0], s.qd[0], s.qdd[0]);
  o.dq = c.d.dtau_dq; o.dv = c.d.dtau_dv;
}
void pin_free(void* p) { delete static_cast<pin_ctx*>(p); }
