/// \file bench/kdl_reference.cpp
/// KDL side of the benchmark (see kdl_reference.hpp). Built with baseline flags only.
#include "kdl_reference.hpp"

#include <kdl/chain.hpp>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>
#include <kdl/segment.hpp>
#include <kdl/tree.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <memory>
#include <string>

namespace nhdyn_bench::kdl {

struct solver {
  KDL::Chain chain;
  std::unique_ptr<KDL::ChainIdSolver_RNE> id;
  std::unique_ptr<KDL::ChainFdSolver_RNE> fd;
  KDL::JntArray q, qd, qdd, tau, fd_tau, fd_qdd;
  KDL::Wrenches f_ext;
};

solver* make(const dh_row* rows, int n, const double g[3]) {
  auto* s = new solver;
  for (int i = 0; i < n; ++i) {
    const dh_row& r = rows[i];
    const double* I = r.inertia;
    // RotationalInertia(Ixx, Iyy, Izz, Ixy, Ixz, Iyz), about the centre of mass here
    // (RigidBodyInertia's third argument is "the rotational inertia in the cog").
    const KDL::RotationalInertia Ic(I[0], I[4], I[8], I[1], I[2], I[5]);
    const KDL::RigidBodyInertia rbi(r.mass, KDL::Vector(r.com[0], r.com[1], r.com[2]), Ic);
    const KDL::Joint j(r.prismatic ? KDL::Joint::TransZ : KDL::Joint::RotZ);
    s->chain.addSegment(KDL::Segment(j, KDL::Frame::DH(r.a, r.alpha, r.d, r.theta), rbi));
  }
  s->id = std::make_unique<KDL::ChainIdSolver_RNE>(s->chain, KDL::Vector(g[0], g[1], g[2]));
  s->fd = std::make_unique<KDL::ChainFdSolver_RNE>(s->chain, KDL::Vector(g[0], g[1], g[2]));
  s->q = s->qd = s->qdd = s->tau = s->fd_tau = s->fd_qdd = KDL::JntArray(static_cast<unsigned>(n));
  s->f_ext.assign(static_cast<std::size_t>(n), KDL::Wrench::Zero());
  return s;
}

void destroy(solver* s) { delete s; }

void set_state(solver* s, const double* q, const double* qd, const double* qdd) {
  for (unsigned i = 0; i < s->q.rows(); ++i) {
    s->q(i) = q[i];
    s->qd(i) = qd[i];
    s->qdd(i) = qdd[i];
  }
}

int run(solver* s) { return s->id->CartToJnt(s->q, s->qd, s->qdd, s->f_ext, s->tau); }

void torques(const solver* s, double* tau) {
  for (unsigned i = 0; i < s->tau.rows(); ++i) tau[i] = s->tau(i);
}

void set_fd_state(solver* s, const double* q, const double* qd, const double* tau) {
  for (unsigned i = 0; i < s->q.rows(); ++i) {
    s->q(i) = q[i];
    s->qd(i) = qd[i];
    s->fd_tau(i) = tau[i];
  }
}

int run_fd(solver* s) { return s->fd->CartToJnt(s->q, s->qd, s->fd_tau, s->f_ext, s->fd_qdd); }

void accelerations(const solver* s, double* qdd) {
  for (unsigned i = 0; i < s->fd_qdd.rows(); ++i) qdd[i] = s->fd_qdd(i);
}

struct tree_solver {
  KDL::Tree tree{"root"};
  std::unique_ptr<KDL::TreeIdSolver_RNE> id;
  KDL::JntArray q, qd, qdd, tau;
  KDL::WrenchMap f_ext;
};

tree_solver* make_tree(const tree_body* bodies, int n, const double g[3]) {
  auto* s = new tree_solver;
  for (int i = 0; i < n; ++i) {
    const tree_body& b = bodies[i];
    const KDL::Frame F(KDL::Rotation(b.R[0], b.R[1], b.R[2], b.R[3], b.R[4], b.R[5], b.R[6], b.R[7], b.R[8]),
                       KDL::Vector(b.p[0], b.p[1], b.p[2]));
    const std::string name = "b" + std::to_string(i);
    const KDL::Joint j(name, F.p, F.M * KDL::Vector(b.axis[0], b.axis[1], b.axis[2]),
                       b.prismatic ? KDL::Joint::TransAxis : KDL::Joint::RotAxis);
    const double* I = b.inertia;
    const KDL::RigidBodyInertia rbi(b.mass, KDL::Vector(b.com[0], b.com[1], b.com[2]),
                                    KDL::RotationalInertia(I[0], I[4], I[8], I[1], I[2], I[5]));
    s->tree.addSegment(KDL::Segment(name, j, F, rbi), b.parent < 0 ? "root" : "b" + std::to_string(b.parent));
  }
  s->id = std::make_unique<KDL::TreeIdSolver_RNE>(s->tree, KDL::Vector(g[0], g[1], g[2]));
  s->q = s->qd = s->qdd = s->tau = KDL::JntArray(static_cast<unsigned>(n));
  return s;
}

void destroy_tree(tree_solver* s) { delete s; }

void set_tree_state(tree_solver* s, const double* q, const double* qd, const double* qdd) {
  for (unsigned i = 0; i < s->q.rows(); ++i) {
    s->q(i) = q[i];
    s->qd(i) = qd[i];
    s->qdd(i) = qdd[i];
  }
}

int run_tree(tree_solver* s) { return s->id->CartToJnt(s->q, s->qd, s->qdd, s->f_ext, s->tau); }

void tree_torques(const tree_solver* s, double* tau) {
  for (unsigned i = 0; i < s->tau.rows(); ++i) tau[i] = s->tau(i);
}

}  // namespace nhdyn_bench::kdl
