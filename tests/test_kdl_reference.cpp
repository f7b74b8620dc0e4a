// nhdyn against Orocos KDL (issue 2, item 7 iii): inverse dynamics (ChainIdSolver_RNE),
// joint-space inertia, Coriolis and gravity terms (ChainDynParam), forward kinematics
// (ChainFkSolverPos_recursive) and the tip Jacobian (ChainJntToJacSolver), on random mixed
// revolute/prismatic chains with massless links, on puma560 and on paper5.
//
// A Spong DH row i (A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i), joint i about / along z_{i−1}) is
// the KDL segment Segment(Joint(RotZ or TransZ), Frame::DH(a_i, α_i, d_i, θ_i), I): KDL's
// segment pose is joint.pose(q) · f_tip = Rz(q) · Rz(θ) Tz(d) Tx(a) Rx(α) = A_i(θ + q) for
// RotZ, and Tz(q) · Rz(θ) Tz(d) Tx(a) Rx(α) = A_i(d + q) for TransZ (Tz and Rz commute).
// The segment's inertia is expressed in its tip frame (= frame i) with
// RigidBodyInertia(m, com, rotational inertia about the com) — the nhdyn link's data as is.
#include <catch2/catch.hpp>

#ifdef NHDYN_HAVE_KDL

#include <algorithm>
#include <cstdio>
#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>
#include <string>

#include "reference/random_chain.hpp"

namespace {

using nhdyn_ref::random_vector;

struct worst {
  std::string what;
  double e = 0;
  explicit worst(std::string w) : what(std::move(w)) {}
  double operator()(double x) {
    e = std::max(e, x);
    return x;
  }
  ~worst() { std::printf("  max relative error, %-52s %.3g\n", what.c_str(), e); }
};

/// ‖x − ref‖∞ / max(‖ref‖∞, floor); the floor keeps terms that vanish by symmetry from
/// dividing rounding by rounding.
template <class A, class B>
double rel(const A& x, const B& ref, double floor = 0) {
  return (x - ref).cwiseAbs().maxCoeff() / std::max({ref.cwiseAbs().maxCoeff(), floor, 1e-300});
}

/// The KDL chain of an nhdyn chain (see the file comment).
template <int N>
KDL::Chain to_kdl(const nhdyn::chain<double, N>& c) {
  KDL::Chain k;
  for (const auto& L : c) {
    const KDL::Joint j(L.joint == nhdyn::joint_type::revolute ? KDL::Joint::RotZ : KDL::Joint::TransZ);
    const KDL::RotationalInertia I(L.inertia(0, 0), L.inertia(1, 1), L.inertia(2, 2), L.inertia(0, 1),
                                   L.inertia(0, 2), L.inertia(1, 2));
    k.addSegment(KDL::Segment(j, KDL::Frame::DH(L.a, L.alpha, L.d, L.theta),
                              KDL::RigidBodyInertia(L.mass, KDL::Vector(L.com(0), L.com(1), L.com(2)), I)));
  }
  return k;
}

KDL::Vector kdl_vector(const Eigen::Vector3d& v) { return KDL::Vector(v(0), v(1), v(2)); }

KDL::JntArray jnt(const Eigen::VectorXd& v) {
  KDL::JntArray a(static_cast<unsigned>(v.size()));
  a.data = v;
  return a;
}

/// rne (fixed- or run-time sized) against ChainIdSolver_RNE, and M, C q̇, g against
/// ChainDynParam, at random states.
template <int N>
void compare(const nhdyn::chain<double, N>& c, std::mt19937_64& rng, int states, worst& w_id, worst& w_M,
             worst& w_cg) {
  const int n = c.dof();
  KDL::Chain kc = to_kdl(c);
  REQUIRE(int(kc.getNrOfJoints()) == n);
  KDL::ChainIdSolver_RNE id_kdl(kc, kdl_vector(c.gravity()));
  KDL::ChainDynParam dyn_kdl(kc, kdl_vector(c.gravity()));
  const auto id = nhdyn::rne(c);
  const auto M = nhdyn::mass_matrix(c);
  const auto no_g = id.with({.gravity = false, .velocity = true});
  const auto only_g = id.with({.gravity = true, .velocity = false});
  for (int s = 0; s < states; ++s) {
    const Eigen::VectorXd q = random_vector(rng, n, -3.1, 3.1), qd = random_vector(rng, n, -2, 2),
                          qdd = random_vector(rng, n, -3, 3), z = Eigen::VectorXd::Zero(n);
    const nhdyn::vecN<double, N> qN = q, qdN = qd, qddN = qdd, zN = z;
    KDL::JntArray tau(static_cast<unsigned>(n)), cor(static_cast<unsigned>(n)), grav(static_cast<unsigned>(n));
    KDL::Wrenches f_ext(kc.getNrOfSegments(), KDL::Wrench::Zero());
    REQUIRE(id_kdl.CartToJnt(jnt(q), jnt(qd), jnt(qdd), f_ext, tau) >= 0);
    KDL::JntSpaceInertiaMatrix H(static_cast<unsigned>(n));
    REQUIRE(dyn_kdl.JntToMass(jnt(q), H) >= 0);
    REQUIRE(dyn_kdl.JntToCoriolis(jnt(q), jnt(qd), cor) >= 0);
    REQUIRE(dyn_kdl.JntToGravity(jnt(q), grav) >= 0);
    INFO("chain " << c.name() << " (" << n << " dof), q = " << q.transpose() << ", qd = " << qd.transpose()
                  << ", qdd = " << qdd.transpose());
    const Eigen::VectorXd v = id(qN, qdN, qddN);
    CHECK(w_id(rel(v, tau.data)) < 1e-12);
    const Eigen::MatrixXd Mq = M(qN);
    CHECK(w_M(rel(Mq, H.data)) < 1e-12);
    // C q̇ and g, with a floor of 1e-3 of the torque scale for terms that vanish by symmetry.
    const double floor = 1e-3 * tau.data.cwiseAbs().maxCoeff();
    const Eigen::VectorXd c_nh = Eigen::VectorXd(no_g(qN, qdN, zN)), g_nh = Eigen::VectorXd(only_g(qN, zN, zN));
    CHECK(w_cg(rel(c_nh, cor.data, floor)) < 1e-12);
    CHECK(w_cg(rel(g_nh, grav.data, floor)) < 1e-12);
  }
}

}  // namespace

TEST_CASE("kdl: rne equals KDL's ChainIdSolver_RNE on random mixed chains with massless links") {
  std::mt19937_64 rng(31);
  worst w_id("rne vs KDL ChainIdSolver_RNE, random chains"), w_M("M vs KDL ChainDynParam, random chains"),
      w_cg("C qd, g vs KDL ChainDynParam, random chains");
  for (int n = 1; n <= 10; ++n)
    for (int r = 0; r < 4; ++r) {
      nhdyn_ref::random_chain_options o;
      o.prismatic_probability = r == 3 ? 0.0 : 0.35;
      if (r == 1) o.massless_with_inertia = n / 2;
      if (r == 2 && n >= 2) {
        o.fully_massless = n - 1;
        o.massless_with_inertia = 0;
      }
      const auto c = nhdyn_ref::random_chain(rng, n, o);
      compare(c, rng, 4, w_id, w_M, w_cg);
      if (n == 6) compare(c.fixed<6>(), rng, 4, w_id, w_M, w_cg);
    }
}

TEST_CASE("kdl: rne equals KDL's ChainIdSolver_RNE on long revolute chains (the benchmark sizes)") {
  std::mt19937_64 rng(34);
  worst w_id("rne vs KDL ChainIdSolver_RNE, 6…96 revolute links"), w_M("M vs KDL ChainDynParam, 6…96 links"),
      w_cg("C qd, g vs KDL ChainDynParam, 6…96 links");
  for (const int n : {6, 12, 24, 48, 96}) {
    const auto c = nhdyn_ref::random_chain(rng, n, {.prismatic_probability = 0.0});
    compare(c, rng, 2, w_id, w_M, w_cg);
    if (n == 12) compare(c.fixed<12>(), rng, 2, w_id, w_M, w_cg);
  }
}

TEST_CASE("kdl: rne equals KDL's ChainIdSolver_RNE on puma560 and paper5, fixed and run-time sized") {
  std::mt19937_64 rng(32);
  worst w_id("rne vs KDL ChainIdSolver_RNE, puma560 + paper5"), w_M("M vs KDL ChainDynParam, presets"),
      w_cg("C qd, g vs KDL ChainDynParam, presets");
  compare(nhdyn::presets::puma560<double>(), rng, 20, w_id, w_M, w_cg);
  compare(nhdyn::presets::puma560<double>().dynamic_size(), rng, 20, w_id, w_M, w_cg);
  compare(nhdyn::presets::paper5_chain<double>(), rng, 20, w_id, w_M, w_cg);
  compare(nhdyn::presets::paper5_chain<double>().dynamic_size(), rng, 20, w_id, w_M, w_cg);
  // Corke's published gravity load of the Puma at q = 0 (gravload(qz)), through KDL too.
  const auto puma = nhdyn::presets::puma560<double>();
  KDL::Chain kc = to_kdl(puma);
  KDL::ChainDynParam dyn(kc, kdl_vector(puma.gravity()));
  KDL::JntArray g(6);
  REQUIRE(dyn.JntToGravity(jnt(Eigen::VectorXd::Zero(6)), g) >= 0);
  CHECK(g(1) == Approx(37.4837).margin(1e-4));
  CHECK(g(2) == Approx(0.2489).margin(1e-4));
}

TEST_CASE("kdl: rne with external wrenches equals ChainIdSolver_RNE with f_ext") {
  // KDL's f_ext[i]: the wrench on segment i from the environment, in segment i's (tip) frame =
  // DH frame i, about its origin — nhdyn's wrench on link i in wrench_frame::body at point 0.
  // A second set at random points (the moment moved to the origin for KDL: m + p × f).
  std::mt19937_64 rng(77);
  worst w("rne with wrenches vs KDL f_ext, random chains");
  for (int n = 1; n <= 9; ++n) {
    const auto c = nhdyn_ref::random_chain(rng, n, {.prismatic_probability = 0.3});
    KDL::Chain kc = to_kdl(c);
    KDL::ChainIdSolver_RNE id_kdl(kc, kdl_vector(c.gravity()));
    for (int s = 0; s < 4; ++s) {
      const Eigen::VectorXd q = random_vector(rng, n, -3.1, 3.1), qd = random_vector(rng, n, -2, 2),
                            qdd = random_vector(rng, n, -3, 3);
      KDL::Wrenches f_ext(kc.getNrOfSegments(), KDL::Wrench::Zero());
      std::vector<nhdyn::wrench<double>> W;
      for (int i = 0; i < n; ++i) {
        nhdyn::wrench<double> x;
        x.body = i + 1;
        x.frame = nhdyn::wrench_frame::body;
        x.force = random_vector(rng, 3, -10, 10);
        x.moment = random_vector(rng, 3, -3, 3);
        if (s % 2) x.point = random_vector(rng, 3, -0.5, 0.5);
        const Eigen::Vector3d m0 = x.moment + x.point.cross(x.force);
        f_ext[std::size_t(i)] = KDL::Wrench(kdl_vector(x.force), kdl_vector(m0));
        W.push_back(x);
      }
      KDL::JntArray tau(static_cast<unsigned>(n));
      REQUIRE(id_kdl.CartToJnt(jnt(q), jnt(qd), jnt(qdd), f_ext, tau) >= 0);
      const Eigen::VectorXd v = nhdyn::rne(c)(q, qd, qdd, nhdyn::external_wrenches(c, W));
      CHECK(w(rel(v, tau.data)) < 1e-12);
    }
  }
}

TEST_CASE("kdl: forward kinematics and the tip Jacobian equal KDL's") {
  std::mt19937_64 rng(33);
  worst w("frames and tip Jacobian vs KDL (absolute / scale)");
  std::vector<nhdyn::chain<double>> cs{nhdyn::presets::puma560<double>().dynamic_size(),
                                       nhdyn::presets::paper5_chain<double>().dynamic_size()};
  for (int n = 1; n <= 8; ++n) cs.push_back(nhdyn_ref::random_chain(rng, n, {.prismatic_probability = 0.4}));
  for (const auto& c : cs) {
    const int n = c.dof();
    KDL::Chain kc = to_kdl(c);
    KDL::ChainFkSolverPos_recursive fk(kc);
    KDL::ChainJntToJacSolver jac(kc);
    const nhdyn::kinematics k(c);
    for (int s = 0; s < 5; ++s) {
      const Eigen::VectorXd q = random_vector(rng, n, -3.1, 3.1);
      INFO("chain " << c.name() << ", q = " << q.transpose());
      const auto X = k.forward(q);
      for (int i = 1; i <= n; ++i) {
        KDL::Frame F;
        REQUIRE(fk.JntToCart(jnt(q), F, i) >= 0);
        for (int r = 0; r < 3; ++r) {
          CHECK(w(std::abs(X[std::size_t(i)].p(r) - F.p(r)) / (1 + X[std::size_t(i)].p.norm())) < 1e-14);
          for (int cc = 0; cc < 3; ++cc) CHECK(w(std::abs(X[std::size_t(i)].R(r, cc) - F.M(r, cc))) < 1e-14);
        }
      }
      KDL::Jacobian J(static_cast<unsigned>(n));
      REQUIRE(jac.JntToJac(jnt(q), J) >= 0);  // reference point: the tip frame's origin, base axes
      const Eigen::MatrixXd Jn = k.jacobian(q, n);
      CHECK(w(rel(Jn, Eigen::MatrixXd(J.data))) < 1e-13);
    }
  }
}

#else

TEST_CASE("kdl: Orocos KDL not found, the KDL comparison is skipped") {
  WARN("Orocos KDL (Debian liborocos-kdl-dev) was not found at configure time: the comparison of rne with "
       "KDL's ChainIdSolver_RNE did not run. Install it and re-run cmake.");
}

#endif
