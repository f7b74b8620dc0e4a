#pragma once
/// \file bench/kdl_reference.hpp
/// Orocos KDL's ChainIdSolver_RNE, ChainFdSolver_RNE and TreeIdSolver_RNE behind a plain-C++ boundary: only doubles, ints and an
/// opaque handle cross it. kdl_reference.cpp is compiled with baseline x86-64 flags (as
/// Debian's KDL is), the rest of the benchmark with -march=native, so no Eigen object may
/// be shared between the two (their alignment ABI differs).

namespace nhdyn_bench::kdl {

/// One standard-DH row (Spong) with its rigid-body parameters: com in frame i, inertia
/// about the centre of mass in frame i's axes (row-major 3×3).
struct dh_row {
  bool prismatic;
  double alpha, a, theta, d, mass;
  double com[3];
  double inertia[9];
};

struct solver;  // opaque

/// Builds a KDL chain (joint about/along z of the segment start, then Frame::DH(a, α, d, θ),
/// RigidBodyInertia(m, com, I_c)) and its ChainIdSolver_RNE with the given gravity.
solver* make(const dh_row* rows, int n, const double gravity[3]);
void destroy(solver* s);
/// Stores the state in the solver's own JntArrays (not timed).
void set_state(solver* s, const double* q, const double* qd, const double* qdd);
/// One CartToJnt call on the stored state (the timed part); returns KDL's error code.
int run(solver* s);
/// Copies the last result out.
void torques(const solver* s, double* tau);
/// KDL's ChainFdSolver_RNE (M by n RNE calls, then a Cholesky solve) on the same chain:
/// stores (q, q̇, τ); one CartToJnt call (timed); copies q̈ out.
void set_fd_state(solver* s, const double* q, const double* qd, const double* tau);
int run_fd(solver* s);
void accelerations(const solver* s, double* qdd);

/// One body of a kinematic tree (nhdyn's tree<double> with identity body offsets, as URDF
/// gives): its parent (−1: the root), the joint frame in the parent's (R row-major, p), the
/// unit axis in the joint frame, and the rigid-body parameters in the body (= joint) frame.
struct tree_body {
  int parent;
  bool prismatic;
  double R[9], p[3], axis[3];
  double mass;
  double com[3];
  double inertia[9];
};

struct tree_solver;  // opaque

/// Builds a KDL::Tree (one segment per body, added in the given order, so KDL's q index of
/// body i is i) and its TreeIdSolver_RNE.
tree_solver* make_tree(const tree_body* bodies, int n, const double gravity[3]);
void destroy_tree(tree_solver* s);
void set_tree_state(tree_solver* s, const double* q, const double* qd, const double* qdd);
int run_tree(tree_solver* s);
void tree_torques(const tree_solver* s, double* tau);

}  // namespace nhdyn_bench::kdl
