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
#include <Eigen/Geometry>
#include "api.hpp"
struct pin_ctx { pinocchio::Model m; pinocchio::Data d; };
static pinocchio::SE3 se3(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) { return pinocchio::SE3(R, p); }
// nhdyn places body i as B_i = B_λ · X_PJ · joint(q_i) · X_JB; Pinocchio places joint i as
// J_i = J_λ · placement · joint(q_i). With J_i = nhdyn's moved joint frame turned by A_i,
// placement = A_λᵀ · X_JB(λ) · X_PJ(i) · A_i, and the body's inertia (in its body frame) is
// appended at A_iᵀ · X_JB(i). A joint about +x, +y or +z keeps A_i = 1 and gets Pinocchio's
// RX/RY/RZ (PX/PY/PZ), as Pinocchio's URDF parser gives it; any other axis u gets A_i with
// A_i z = u and Pinocchio's RZ (PZ), faster than the unaligned joint its parser would give.
// Every joint has one coordinate (a continuous joint too, as in nhdyn; Pinocchio's URDF parser
// would give it cos and sin).
void* pin_make(const nhdyn::tree<double>& t) {
  auto* c = new pin_ctx;
  auto& m = c->m;
  m.gravity.linear(t.gravity());
  const int n = t.dof();
  std::vector<Eigen::Matrix3d> A(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto& b = t[i];
    const Eigen::Vector3d u = b.axis;
    const bool aligned =
        u == Eigen::Vector3d::UnitX() || u == Eigen::Vector3d::UnitY() || u == Eigen::Vector3d::UnitZ();
    A[i] = aligned ? Eigen::Matrix3d::Identity()
                   : Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), u).toRotationMatrix();
    const pinocchio::JointIndex parent = b.parent < 0 ? 0 : pinocchio::JointIndex(b.parent + 1);
    const pinocchio::SE3 Xp = b.parent < 0 ? pinocchio::SE3::Identity()
                                           : pinocchio::SE3(A[b.parent].transpose(), Eigen::Vector3d::Zero()) *
                                                 se3(t[b.parent].R_JB, t[b.parent].p_JB);
    const pinocchio::SE3 place = Xp * se3(b.R_PJ, b.p_PJ) * pinocchio::SE3(A[i], Eigen::Vector3d::Zero());
    const Eigen::Vector3d a = aligned ? u : Eigen::Vector3d::UnitZ();
    pinocchio::JointIndex id;
    if (b.joint == nhdyn::joint_type::revolute) {
      if (a == Eigen::Vector3d::UnitX()) id = m.addJoint(parent, pinocchio::JointModelRX(), place, b.joint_name);
      else if (a == Eigen::Vector3d::UnitY()) id = m.addJoint(parent, pinocchio::JointModelRY(), place, b.joint_name);
      else id = m.addJoint(parent, pinocchio::JointModelRZ(), place, b.joint_name);
    } else {
      if (a == Eigen::Vector3d::UnitX()) id = m.addJoint(parent, pinocchio::JointModelPX(), place, b.joint_name);
      else if (a == Eigen::Vector3d::UnitY()) id = m.addJoint(parent, pinocchio::JointModelPY(), place, b.joint_name);
      else id = m.addJoint(parent, pinocchio::JointModelPZ(), place, b.joint_name);
    }
    m.appendBodyToJoint(id, pinocchio::Inertia(b.mass, b.com, pinocchio::Symmetric3(b.inertia)),
                        pinocchio::SE3(A[i].transpose(), Eigen::Vector3d::Zero()) * se3(b.R_JB, b.p_JB));
  }
  for (int i = 0; i < n; ++i) m.armature[i] = t[i].armature;
  c->d = pinocchio::Data(m);
  return c;
}
double pin_run(void* p, int algo, const states& s, long K) {
  auto& c = *static_cast<pin_ctx*>(p);
  return time_calls(K, [&](int i) {
    switch (algo) {
      case 0: pinocchio::rnea(c.m, c.d, s.q[i], s.qd[i], s.qdd[i]); break;
      case 1: pinocchio::crba(c.m, c.d, s.q[i], pinocchio::Convention::LOCAL); break;
      case 4: pinocchio::crba(c.m, c.d, s.q[i], pinocchio::Convention::WORLD); break;
      case 2: pinocchio::aba(c.m, c.d, s.q[i], s.qd[i], s.tau[i], pinocchio::Convention::LOCAL); break;
      case 5: pinocchio::aba(c.m, c.d, s.q[i], s.qd[i], s.tau[i], pinocchio::Convention::WORLD); break;
      case 3: pinocchio::computeRNEADerivatives(c.m, c.d, s.q[i], s.qd[i], s.qdd[i]); break;
    }
  });
}
void pin_outs(void* p, const states& s, outs& o) {
  auto& c = *static_cast<pin_ctx*>(p);
  const auto full = [](Eigen::MatrixXd M) {  // Pinocchio fills the upper triangle
    M.triangularView<Eigen::StrictlyLower>() = M.transpose();
    return M;
  };
  const auto same = [](const auto& a, const auto& b) { return (a - b).norm() <= 1e-9 * (1 + b.norm()); };
  o.tau = pinocchio::rnea(c.m, c.d, s.q[0], s.qd[0], s.qdd[0]);
  pinocchio::crba(c.m, c.d, s.q[0], pinocchio::Convention::WORLD);
  o.M = full(c.d.M);
  pinocchio::crba(c.m, c.d, s.q[0], pinocchio::Convention::LOCAL);
  if (!same(full(c.d.M), o.M)) o.M.setConstant(1e300);  // the conventions disagree
  o.qdd = pinocchio::aba(c.m, c.d, s.q[0], s.qd[0], s.tau[0], pinocchio::Convention::WORLD);
  const Eigen::VectorXd local = pinocchio::aba(c.m, c.d, s.q[0], s.qd[0], s.tau[0], pinocchio::Convention::LOCAL);
  if (!same(local, o.qdd)) o.qdd.setConstant(1e300);
  pinocchio::computeRNEADerivatives(c.m, c.d, s.q[0], s.qd[0], s.qdd[0]);
  o.dq = c.d.dtau_dq;
  o.dv = c.d.dtau_dv;
  o.tau_d = c.d.tau;
  o.M_d = full(c.d.M);  // ∂τ/∂q̈
}
void pin_free(void* p) { delete static_cast<pin_ctx*>(p); }
