// Kinematic trees (model/tree.hpp): the fast kernels (dynamics/tree.hpp, kinematics/tree.hpp)
// against the plain reference (dynamics/reference.hpp, Featherstone's spatial algebra), the DH
// chain kernels (a chain is a tree), and physics invariants that neither computes directly.
#include <catch2/catch.hpp>

#include <nhdyn/analysis/bounds.hpp>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/dynamics/reference.hpp>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/kinematics/tree.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/scalar/interval.hpp>
#include <limits>
#include <random>

#include "reference/lagrangian.hpp"
#include "reference/random_tree.hpp"

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

double rel(const MatrixXd& a, const MatrixXd& b) { return (a - b).norm() / std::max(1.0, b.norm()); }

/// paper5's planar base (its first three bodies of t = as_tree(paper5)) carrying a random
/// branching tree of `arm` bodies, under vertical gravity.
tree<double> base_with_branches(const tree<double>& t, std::mt19937_64& rng, int arm) {
  std::vector<body<double>> B = {t[0], t[1], t[2]};
  const tree<double> arms = nhdyn_ref::random_tree(rng, arm);
  for (int i = 0; i < arms.dof(); ++i) {
    body<double> b = arms[i];
    b.parent = b.parent < 0 ? 2 : b.parent + 3;
    B.push_back(b);
  }
  return tree<double>(B, Eigen::Vector3d(0, 0, -9.81), "base with branches");
}

VectorXd random_state(std::mt19937_64& rng, int n, double r = 1.5) {
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = nhdyn_ref::uniform(rng, -r, r);
  return v;
}

}  // namespace

TEST_CASE("a DH chain as a tree gives the chain kernels' rne, M and frames", "[tree]") {
  std::mt19937_64 rng(7);
  std::vector<chain<double>> chains{presets::paper5_chain().dynamic_size(), presets::puma560().dynamic_size()};
  for (int k = 0; k < 4; ++k) chains.push_back(nhdyn_ref::random_chain(rng, 3 + 2 * k));
  for (const auto& c : chains) {
    const tree<double> t = as_tree(c);
    const auto rc = rne(c);
    const auto rt = rne(t);
    const auto Mc = mass_matrix(c);
    const auto Mt = mass_matrix(t);
    const kinematics<double> kc(c);
    const tree_kinematics<double> kt(t);
    for (int s = 0; s < 5; ++s) {
      const VectorXd q = random_state(rng, c.dof()), qd = random_state(rng, c.dof()), qdd = random_state(rng, c.dof());
      CHECK(rel(rt(q, qd, qdd), rc(q, qd, qdd)) < 1e-13);
      CHECK(rel(Mt(q), Mc(q)) < 1e-13);
      const auto Xc = kc.forward(q);
      const auto Xt = kt.forward(q);
      for (int i = 1; i <= c.dof(); ++i) {
        CHECK(rel(Xt[std::size_t(i)].R, Xc[std::size_t(i)].R) < 1e-13);
        CHECK(rel(Xt[std::size_t(i)].p, Xc[std::size_t(i)].p) < 1e-13);
      }
      const Eigen::Vector3d p(0.1, -0.2, 0.3);
      CHECK(rel(kt.jacobian(q, c.dof(), p), kc.jacobian(q, c.dof(), p)) < 1e-13);
      const auto ac = kc.jdot_qdot(q, qd, c.dof(), p);
      const auto at = kt.jdot_qdot(q, qd, c.dof(), p);
      CHECK(rel(at.linear, ac.linear) < 1e-12);
      CHECK(rel(at.angular, ac.angular) < 1e-12);
    }
  }
}

TEST_CASE("tree kernels equal the reference on random trees (double)", "[tree]") {
  std::mt19937_64 rng(11);
  for (int n : {1, 2, 5, 12, 30, 60}) {
    const tree<double> t = nhdyn_ref::random_tree(rng, n);
    const auto id = rne(t);
    const auto M = mass_matrix(t);
    for (int s = 0; s < 3; ++s) {
      const VectorXd q = random_state(rng, n), qd = random_state(rng, n), qdd = random_state(rng, n);
      const VectorXd ref = reference::rne<double>(t, q, qd, qdd);
      INFO("n = " << n);
      CHECK(rel(id(q, qd, qdd), ref) < 1e-12);
      CHECK(rel(id.with({.gravity = false})(q, qd, qdd), reference::rne<double>(t, q, qd, qdd, false)) < 1e-12);
      CHECK(rel(id.with({.velocity = false})(q, qd, qdd), reference::rne<double>(t, q, VectorXd::Zero(n), qdd)) < 1e-12);
      const MatrixXd H = reference::crba<double>(t, q);
      CHECK(rel(M(q), H) < 1e-12);
      // bodies on different branches do not couple: exactly zero, in both
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          if (!t.supports(i, j) && !t.supports(j, i)) {
            CHECK(M(q)(i, j) == 0.0);
            CHECK(H(i, j) == 0.0);
          }
    }
  }
}

TEST_CASE("tree rne and CRBA into reused storage (evaluate) give the calls' numbers; large trees spill to the heap", "[tree]") {
  std::mt19937_64 rng(29);
  for (int n : {3, 16, 200}) {  // 200 bodies: the kernels' scratch beyond its stack part (170 in double)
    const tree<double> t = nhdyn_ref::random_tree(rng, n);
    const auto id = rne(t);
    const auto M = mass_matrix(t);
    VectorXd v(n);
    Eigen::MatrixXd H(2, 5);  // resized by the first call, reused by the next
    for (int s = 0; s < 2; ++s) {
      const VectorXd q = random_state(rng, n), qd = random_state(rng, n), qdd = random_state(rng, n);
      INFO("n = " << n);
      const VectorXd tau = id(q, qd, qdd);
      CHECK(rel(tau, reference::rne<double>(t, q, qd, qdd)) < 1e-12);
      CHECK(rel(M(q), reference::crba<double>(t, q)) < 1e-12);
      id.evaluate(q, qd, qdd, v);
      CHECK(v == tau);  // bit for bit
      VectorXd w = qdd;  // v over q̈'s own storage (what the pipeline does with a temporary ξ)
      id.evaluate(q, qd, w, w);
      CHECK(w == tau);
      double buf[200];  // into a map of the caller's storage
      Eigen::Map<VectorXd> mv(buf, n);
      id.evaluate(q, qd, qdd, mv);
      CHECK(mv == tau);
      M.evaluate(q, H);
      CHECK(H == M(q));
      // the pipeline form on a temporary ξ (v written over its q̈) = the call
      const auto f = id(joint_state<double, dynamic>{q, qd, qdd});
      CHECK(f.v == tau);
      CHECK(f.q == q);
    }
    VectorXd wrong(n + 1);
    CHECK_THROWS_WITH(id.evaluate(VectorXd::Zero(n), VectorXd::Zero(n), VectorXd::Zero(n), wrong),
                      Catch::Contains("v") && Catch::Contains(std::to_string(n)));
  }
}

TEST_CASE("tree CRBA into a mass_matrix_result: its zeros are kept, not written again, and M stays whole", "[tree]") {
  std::mt19937_64 rng(83);
  // two trees of 24 bodies with different branches, and one of 200 (past the kernel's stack scratch)
  const tree<double> a = nhdyn_ref::random_tree(rng, 24), b = nhdyn_ref::random_tree(rng, 24),
                     big = nhdyn_ref::random_tree(rng, 200);
  const auto Ma = mass_matrix(a), Mb = mass_matrix(b), Mbig = mass_matrix(big);
  // where a's M is nonzero and b's is zero by their branches: what b's first call must clear
  const VectorXd qa = random_state(rng, 24), qb = random_state(rng, 24);
  const MatrixXd Ha = Ma(qa), Hb = Mb(qb);
  int stale = 0;
  for (int i = 0; i < 24; ++i)
    for (int j = 0; j < 24; ++j) stale += Ha(i, j) != 0 && Hb(i, j) == 0;
  REQUIRE(stale > 0);
  mass_matrix_result<double> r;
  for (int s = 0; s < 3; ++s) {  // bit for bit the matrix a plain evaluate writes, call after call
    const VectorXd q = random_state(rng, 24);
    (s == 1 ? mass_matrix(a) : Ma).evaluate(q, r);  // (another function object of the same tree)
    CHECK(r.matrix() == Ma(q));
    CHECK(rel(r.matrix(), reference::crba<double>(a, q)) < 1e-12);
  }
  Mb.evaluate(qb, r);  // another tree of the same size into the same result: written whole
  CHECK(r.matrix() == Hb);
  Mbig.evaluate(random_state(rng, 200), r);  // and of another size
  const VectorXd qbig = random_state(rng, 200);
  Mbig.evaluate(qbig, r);
  CHECK(r.matrix() == Mbig(qbig));
  // a call that throws does so before it writes: the result keeps the last M
  Ma.evaluate(qa, r);
  VectorXd bad = qa;
  bad(3) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(Ma.evaluate(bad, r), Catch::Contains("q"));
  CHECK(r.matrix() == Ha);
  // a moved-from result is written whole by its next call, whatever storage the move left it
  mass_matrix_result<double> ra, rb;
  Ma.evaluate(qa, ra);
  Mb.evaluate(qb, rb);
  ra = std::move(rb);  // Eigen swaps the storage: rb may now hold a's M
  CHECK(ra.matrix() == Hb);
  Mb.evaluate(qb, rb);
  CHECK(rb.matrix() == Hb);
  mass_matrix_result<double> rc(std::move(ra));
  Ma.evaluate(qa, rc);  // b's zeros in rc: a's call writes M whole
  CHECK(rc.matrix() == Ha);
  // intervals run the kernel-frame kernel: the same with its zeros kept
  const tree<interval> ai = a.cast<interval>();
  const auto Mi = mass_matrix(ai);
  mass_matrix_result<interval> ri;
  for (int s = 0; s < 2; ++s) {
    const VectorXd q = random_state(rng, 24);
    Mi.evaluate(q.cast<interval>(), ri);
    const auto want = Mi(q.cast<interval>());
    for (int i = 0; i < 24; ++i)
      for (int j = 0; j < 24; ++j) {
        CHECK(ri.matrix()(i, j).lower() == want(i, j).lower());
        CHECK(ri.matrix()(i, j).upper() == want(i, j).upper());
      }
  }
}

TEST_CASE("tree CRBA: M does not depend on where a planar base stands, even 1e6 m away", "[tree][extremes]") {
  // a planar base (x, y slides, then a yaw) on a vertical slide, carrying a random branching
  // robot: M(q) depends on neither x nor y, so M at x = y = 1e6 m must be M at the origin. (The
  // vertical slide comes first so that x and y are not the root's joint, whose placement no
  // kernel needs.) The kernel's composites sit at their own bodies' origins and its lever arms
  // are sums of local steps, so nothing far enters (it gives the same M bit for bit here). The
  // same algorithm about one reference point, the root's origin, is off by 2e-11 to 6e-11 of
  // max |M| on such trees (measured).
  std::mt19937_64 rng(43);
  for (int rep = 0; rep < 3; ++rep) {
    const tree<double> arm = nhdyn_ref::random_tree(rng, 20);
    std::vector<body<double>> B(4);
    const Eigen::Vector3d axes[4] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                     Eigen::Vector3d::UnitZ()};
    for (int k = 0; k < 4; ++k) {
      B[std::size_t(k)].name = "base" + std::to_string(k);
      B[std::size_t(k)].joint_name = "base_joint" + std::to_string(k);
      B[std::size_t(k)].parent = k - 1;
      B[std::size_t(k)].joint = k < 3 ? joint_type::prismatic : joint_type::revolute;
      B[std::size_t(k)].axis = axes[k];
    }
    B[3].mass = 30;
    B[3].inertia = Eigen::Vector3d(1.2, 1.5, 2.0).asDiagonal();
    for (body<double> b : arm.bodies()) {
      b.parent = b.parent < 0 ? 3 : b.parent + 4;
      B.push_back(b);
    }
    const tree<double> t(B, Eigen::Vector3d(0, 0, -9.81), "planar base");
    const int n = t.dof();
    VectorXd q = random_state(rng, n);
    q(1) = q(2) = 0;
    const MatrixXd M0 = mass_matrix(t)(q);
    CHECK(rel(M0, reference::crba<double>(t, q)) < 1e-13);
    q(1) = q(2) = 1e6;
    const MatrixXd M1 = mass_matrix(t)(q);
    INFO("rep " << rep);
    CHECK((M1 - M0).cwiseAbs().maxCoeff() <= 1e-13 * M0.cwiseAbs().maxCoeff());
  }
}

TEST_CASE("tree kernels equal the reference for float, duals and intervals", "[tree]") {
  std::mt19937_64 rng(13);
  const tree<double> t = nhdyn_ref::random_tree(rng, 9);
  const int n = t.dof();
  const VectorXd q = random_state(rng, n), qd = random_state(rng, n), qdd = random_state(rng, n);
  const VectorXd ref = reference::rne<double>(t, q, qd, qdd);

  SECTION("float") {
    const tree<float> tf = t.cast<float>();
    const Eigen::VectorXf v = rne(tf)(q.cast<float>(), qd.cast<float>(), qdd.cast<float>());
    CHECK(rel(v.cast<double>(), ref) < 2e-4);
    CHECK(rel(mass_matrix(tf)(q.cast<float>()).cast<double>(), reference::crba<double>(t, q)) < 2e-4);
    // a float model at a double state: the kernel runs in double on the float model's constants
    // (cast, with its arrays of constants, to double)
    const Eigen::MatrixXd Mfd = mass_matrix(tf)(q);
    CHECK(rel(Mfd, reference::crba<double>(t, q)) < 2e-4);
  }
  SECTION("duals: the kernel's derivative is the reference's") {
    using D = dual<double, 2>;
    Eigen::Matrix<D, Eigen::Dynamic, 1> qD = q.cast<D>(), qdD = qd.cast<D>(), qddD = qdd.cast<D>();
    for (int i = 0; i < n; ++i) {
      qD(i).derivative(0) = qd(i);
      qdD(i).derivative(1) = 1.0;
    }
    const auto v = rne(t)(qD, qdD, qddD);
    const auto r = reference::rne<D>(t, qD, qdD, qddD);
    for (int i = 0; i < n; ++i) {
      CHECK(v(i).value() == Approx(r(i).value()).epsilon(1e-12).margin(1e-12));
      CHECK(v(i).derivative(0) == Approx(r(i).derivative(0)).epsilon(1e-11).margin(1e-11));
      CHECK(v(i).derivative(1) == Approx(r(i).derivative(1)).epsilon(1e-11).margin(1e-11));
    }
    const auto MD = mass_matrix(t)(qD);
    const auto HD = reference::crba<D>(t, qD);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) CHECK(MD(i, j).derivative(0) == Approx(HD(i, j).derivative(0)).margin(1e-11));
  }
  SECTION("intervals enclose the double result") {
    const tree<interval> ti = t.cast<interval>();
    const auto v = rne(ti)(q.cast<interval>(), qd.cast<interval>(), qdd.cast<interval>());
    for (int i = 0; i < n; ++i) {
      CHECK(v(i).lower() <= ref(i) + 1e-12 * std::abs(ref(i)));
      CHECK(v(i).upper() >= ref(i) - 1e-12 * std::abs(ref(i)));
      CHECK(v(i).upper() - v(i).lower() < 1e-9 * std::max(1.0, std::abs(ref(i))));
    }
  }
  SECTION("intervals: the CRBA encloses M at the point and at samples of a box of q") {
    const tree<interval> ti = t.cast<interval>();
    const MatrixXd H = reference::crba<double>(t, q);
    const double scale = 1 + H.cwiseAbs().maxCoeff();
    const auto Mp = mass_matrix(ti)(q.cast<interval>());
    Eigen::Matrix<interval, Eigen::Dynamic, 1> qb(n);
    for (int i = 0; i < n; ++i) qb(i) = interval(q(i) - 1e-3, q(i) + 1e-3);
    const auto Mb = mass_matrix(ti)(qb);
    double widest = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        CHECK(Mp(i, j).lower() <= H(i, j) + 1e-12 * scale);
        CHECK(Mp(i, j).upper() >= H(i, j) - 1e-12 * scale);
        CHECK(Mp(i, j).width() < 1e-9 * scale);
        widest = std::max(widest, Mb(i, j).width());
      }
    // the box's M over-encloses (about 7× the samples' range here) but stays of the box's order
    CHECK(widest < 0.02 * scale);
    std::uniform_real_distribution<double> u(-1e-3, 1e-3);
    for (int s = 0; s < 50; ++s) {
      VectorXd qs = q;
      for (int i = 0; i < n; ++i) qs(i) += u(rng);
      const MatrixXd Hs = reference::crba<double>(t, qs);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          CHECK(Mb(i, j).lower() <= Hs(i, j) + 1e-12 * scale);
          CHECK(Mb(i, j).upper() >= Hs(i, j) - 1e-12 * scale);
        }
    }
  }
}

TEST_CASE("tree dynamics: M q̈ + h = rne, forward dynamics inverts it, gravity and power balance", "[tree]") {
  std::mt19937_64 rng(17);
  for (int n : {3, 8, 20}) {
    const tree<double> t = nhdyn_ref::random_tree(rng, n);
    const auto id = rne(t);
    const auto M = mass_matrix(t);
    const auto h = bias(t);
    const auto fd = forward_dynamics(t);
    const tree_kinematics<double> kin(t);
    const VectorXd q = random_state(rng, n), qd = random_state(rng, n), qdd = random_state(rng, n);
    const VectorXd tau = id(q, qd, qdd);
    CHECK(rel(M(q) * qdd + h(q, qd), tau) < 1e-12);
    CHECK(rel(fd(q, qd, tau), qdd) < 1e-9);
    // g(q) = −Σ J_cᵀ m g, the Jacobians of the centres of mass from the kinematics
    VectorXd grav = VectorXd::Zero(n);
    for (int i = 0; i < n; ++i) {
      const MatrixXd J = kin.jacobian(q, i + 1, t[i].com);
      grav -= J.topRows<3>().transpose() * (t[i].mass * t.gravity());
    }
    CHECK(rel(id(q, VectorXd::Zero(n), VectorXd::Zero(n)), grav) < 1e-12);
    // power balance: dE/dt = q̇ᵀτ, E = ½ q̇ᵀ M q̇ − Σ m gᵀ c, differentiated along the motion
    // with a dual number (M from the composite-rigid-body algorithm, c from the kinematics)
    using D = dual<double, 1>;
    Eigen::Matrix<D, Eigen::Dynamic, 1> qD = q.cast<D>(), qdD = qd.cast<D>();
    for (int i = 0; i < n; ++i) {
      qD(i).derivative(0) = qd(i);
      qdD(i).derivative(0) = qdd(i);
    }
    D E = D(0.5) * qdD.dot(M(qD) * qdD);
    const auto X = kin.forward(qD);
    for (int i = 0; i < n; ++i) {
      const vec3<D> c = X[std::size_t(i + 1)].p + X[std::size_t(i + 1)].R * t[i].com.cast<D>();
      E = E - D(t[i].mass) * t.gravity().cast<D>().dot(c);
    }
    CHECK(E.derivative(0) == Approx(qd.dot(tau)).epsilon(1e-11));
  }
}

TEST_CASE("tree kinematics: J q̇ is the velocity of the point, J̇q̇ its acceleration at q̈ = 0", "[tree]") {
  std::mt19937_64 rng(19);
  const tree<double> t = nhdyn_ref::random_tree(rng, 10);
  const int n = t.dof();
  const tree_kinematics<double> kin(t);
  const VectorXd q = random_state(rng, n), qd = random_state(rng, n);
  using D = dual<double, 1>;
  Eigen::Matrix<D, Eigen::Dynamic, 1> qD = q.cast<D>();
  for (int i = 0; i < n; ++i) qD(i).derivative(0) = qd(i);
  const Eigen::Vector3d p(0.2, 0.1, -0.3);
  for (int b = 1; b <= n; ++b) {
    const auto x = kin.point(qD, b, p);
    const Eigen::Matrix<double, 6, Eigen::Dynamic> J = kin.jacobian(q, b, p);
    const Eigen::Matrix<D, 6, Eigen::Dynamic> JD = kin.jacobian(qD, b, p);
    const auto a = kin.jdot_qdot(q, qd, b, p);
    for (int r = 0; r < 3; ++r) {
      CHECK(x(r).derivative(0) == Approx((J.row(r) * qd)(0)).margin(1e-12));
      D jq(0);
      for (int j = 0; j < n; ++j) jq = jq + JD(r, j) * D(qd(j));
      CHECK(a.linear(r) == Approx(jq.derivative(0)).margin(1e-11));
    }
  }
  CHECK_THROWS_AS(kin.jacobian(q, n + 1), input_error);
  CHECK_THROWS_AS(kin.point(VectorXd::Zero(n - 1), 1), input_error);
}

TEST_CASE("tree validation names the body and the problem", "[tree][errors]") {
  std::mt19937_64 rng(23);
  const tree<double> good = nhdyn_ref::random_tree(rng, 4);
  const auto broken = [&](auto edit) {
    auto b = good.bodies();
    edit(b);
    return tree<double>(b, good.gravity(), "t");
  };
  CHECK_THROWS_WITH(broken([](auto& b) { b[2].mass = -1; }), Catch::Contains("body 'body2'") && Catch::Contains("mass is negative"));
  CHECK_THROWS_WITH(broken([](auto& b) { b[1].axis = Eigen::Vector3d(0, 0, 2); }), Catch::Contains("axis has length 2"));
  CHECK_THROWS_WITH(broken([](auto& b) { b[3].parent = 3; }), Catch::Contains("topological order"));
  CHECK_THROWS_WITH(broken([](auto& b) { b[0].p_PJ(1) = NAN; }), Catch::Contains("not finite"));
  CHECK_THROWS_WITH(broken([](auto& b) { b[0].inertia(2, 2) = -1; }), Catch::Contains("not positive semi-definite"));
  CHECK_THROWS_WITH(broken([](auto& b) { b[0].inertia = Eigen::Vector3d(0.001, 0.001, 0.01).asDiagonal(); }),
                    Catch::Contains("triangle inequality by 8.00e-03"));
  const auto id = rne(good);
  CHECK_THROWS_AS(id(VectorXd::Zero(3), VectorXd::Zero(4), VectorXd::Zero(4)), input_error);
  VectorXd q = VectorXd::Zero(4);
  q(2) = NAN;
  CHECK_THROWS_WITH(id(q, VectorXd::Zero(4), VectorXd::Zero(4)), Catch::Contains("q[2]"));
}

TEST_CASE("the nonholonomic stages run on trees: project ∘ rne ∘ lift, λ and the constrained forward dynamics", "[tree][nonholonomic]") {
  // paper5 as a tree, then a tree with the same base and a branching arm: the composition on
  // the tree equals the chain's (paper5) and inverts the constrained forward dynamics.
  std::mt19937_64 rng(43);
  const auto robot = presets::paper5();
  const chain<double> ch = robot.chain.dynamic_size();
  const differential_drive<double> dd(5, 0, 1, 2, 0.0, -1.0);
  const tree<double> t = as_tree(ch);
  for (int s = 0; s < 5; ++s) {
    const VectorXd q = random_state(rng, 5), eta = random_state(rng, 4), eta_dot = random_state(rng, 4);
    const VectorXd tau_t = inverse_dynamics(t, dd)(q, eta, eta_dot);
    const VectorXd tau_c = inverse_dynamics(ch, dd)(q, eta, eta_dot);
    CHECK(rel(tau_t, tau_c) < 1e-13);
    CHECK(rel(inverse_dynamics(t, robot.constraint)(q, eta, eta_dot), tau_c) < 1e-13);  // compile-time-sized constraint
    const auto f_t = inverse_dynamics_with_forces(t, dd)(q, eta, eta_dot);
    const auto f_c = inverse_dynamics_with_forces(ch, dd)(q, eta, eta_dot);
    CHECK(rel(f_t.lambda, f_c.lambda) < 1e-13);
    CHECK(rel(nh_forward_dynamics(t, dd)(q, eta, tau_t), eta_dot) < 1e-10);
  }
  // a base (x, y prismatic, heading revolute) carrying two branches
  const tree<double> mm = base_with_branches(t, rng, 6);
  const differential_drive<double> c(mm.dof(), 0, 1, 2);
  const auto id = inverse_dynamics(mm, c);
  const auto fd = nh_forward_dynamics(mm, c);
  for (int s = 0; s < 3; ++s) {
    const VectorXd q = random_state(rng, mm.dof()), eta = random_state(rng, c.m()), eta_dot = random_state(rng, c.m());
    const VectorXd tau = id(q, eta, eta_dot);
    // τ = Sᵀ(M S η̇ + rne(q, Sη, Ṡη)) from the mass matrix and the holonomic rne: a second route
    const MatrixXd S = c.S(q);
    const VectorXd qd = S * eta, qdd = S * eta_dot + c.Sdot(q, qd) * eta;
    CHECK(rel(tau, S.transpose() * (mass_matrix(mm)(q) * qdd + bias(mm)(q, qd))) < 1e-12);
    CHECK(rel(fd(q, eta, tau), eta_dot) < 1e-10);
  }
}

TEST_CASE("the linearizers run on trees: the chain's numbers on paper5, central differences on a branching robot", "[tree][linearize]") {
  std::mt19937_64 rng(47);
  const chain<double> ch = presets::paper5_chain().dynamic_size();
  const differential_drive<double> dd(5, 0, 1, 2, 0.0, -1.0);
  const tree<double> t = as_tree(ch);
  const VectorXd q = random_state(rng, 5), eta = random_state(rng, 4), eta_dot = random_state(rng, 4);
  const auto Jt = linearize_inverse_dynamics(t, dd, q, eta, eta_dot);
  const auto Jc = linearize_inverse_dynamics(ch, dd, q, eta, eta_dot);
  CHECK(rel(Jt.J, Jc.J) < 1e-12);
  const VectorXd tau = inverse_dynamics(t, dd)(q, eta, eta_dot);
  const auto At = linearize_forward_dynamics(t, dd, q, eta, tau);
  const auto Ac = linearize_forward_dynamics(ch, dd, q, eta, tau);
  CHECK(rel(At.A, Ac.A) < 1e-10);
  CHECK(rel(At.B, Ac.B) < 1e-10);
  // a branching tree under a differential drive: the dual Jacobian equals central differences
  const tree<double> mm = base_with_branches(t, rng, 5);
  const differential_drive<double> c(mm.dof(), 0, 1, 2);
  const int n = mm.dof(), m = c.m();
  VectorXd z(n + 2 * m);
  z << random_state(rng, n), random_state(rng, m), random_state(rng, m);
  const auto id = inverse_dynamics(mm, c);
  const auto f = [&](const auto& x) { return id(x.head(n), x.segment(n, m), x.tail(m)).eval(); };
  const MatrixXd Jfd = central_difference_jacobian(f, z, 1e-6);
  const inverse_dynamics_linearizer lin(mm, c);
  CHECK(rel(lin(z.head(n), z.segment(n, m), z.tail(m)).J, Jfd) < 1e-7);
}

TEST_CASE("interval bounds run on trees: they enclose the point values and equal the chain's on paper5", "[tree][bounds]") {
  std::mt19937_64 rng(53);
  const chain<double> ch = presets::paper5_chain().dynamic_size();
  const differential_drive<double> dd(5, 0, 1, 2, 0.0, -1.0);
  const tree<double> t = as_tree(ch);
  const VectorXd q = random_state(rng, 5), eta = random_state(rng, 4), eta_dot = random_state(rng, 4);
  const auto around = [](const VectorXd& x, double r) {
    box<dynamic> b(x.size());
    for (Eigen::Index i = 0; i < x.size(); ++i) b(i) = interval(x(i) - r, x(i) + r);
    return b;
  };
  const auto bt = torque_bounds(t, dd, around(q, 0.01), around(eta, 0.01), around(eta_dot, 0.01));
  const auto bc = torque_bounds(ch, dd, around(q, 0.01), around(eta, 0.01), around(eta_dot, 0.01));
  const VectorXd tau = inverse_dynamics(t, dd)(q, eta, eta_dot);
  for (int i = 0; i < 4; ++i) {
    CHECK(bt(i).lower() <= tau(i));
    CHECK(bt(i).upper() >= tau(i));
    // another kernel, another order of operations: another (valid) enclosure, of like width
    INFO("width tree " << bt(i).upper() - bt(i).lower() << ", chain " << bc(i).upper() - bc(i).lower());
    CHECK(bt(i).upper() - bt(i).lower() < 10 * (bc(i).upper() - bc(i).lower()));
  }
  // every τ at points of the box, computed by the chain kernel, lies in the tree's enclosure
  const auto id_chain = inverse_dynamics(ch, dd);
  for (int k = 0; k < 50; ++k) {
    const VectorXd tk = id_chain(q + 0.01 * random_state(rng, 5, 1.0), eta + 0.01 * random_state(rng, 4, 1.0),
                                 eta_dot + 0.01 * random_state(rng, 4, 1.0));
    for (int i = 0; i < 4; ++i) CHECK((bt(i).lower() <= tk(i) && tk(i) <= bt(i).upper()));
  }
  const tree<double> b = nhdyn_ref::random_tree(rng, 7);
  const VectorXd x = random_state(rng, 7), xd = random_state(rng, 7), xdd = random_state(rng, 7);
  const auto h = torque_bounds(b, around(x, 1e-3), around(xd, 1e-3), around(xdd, 1e-3));
  const VectorXd v = rne(b)(x, xd, xdd);
  for (int i = 0; i < 7; ++i) {
    CHECK(h(i).lower() <= v(i));
    CHECK(h(i).upper() >= v(i));
  }
}

TEST_CASE("tree rne and CRBA equal the independent Euler–Lagrange reference (long double) on random trees", "[tree][lagrange]") {
  // tests/reference/lagrangian.hpp: 4×4 transforms, link Jacobians by duals, Christoffel
  // symbols; no library algorithm
  using LD = long double;
  std::mt19937_64 rng(59);
  for (int n : {1, 2, 4, 7}) {
    const tree<double> t = nhdyn_ref::random_tree(rng, n);
    const auto ref = nhdyn_ref::from_tree<LD>(t);
    for (int s = 0; s < 2; ++s) {
      const VectorXd q = random_state(rng, n), qd = random_state(rng, n), qdd = random_state(rng, n);
      const nhdyn_ref::vec<LD> ql = q.cast<LD>(), qdl = qd.cast<LD>(), qddl = qdd.cast<LD>();
      const VectorXd tau_ref = nhdyn_ref::inverse_dynamics<LD>(ref, ql, qdl, qddl).cast<double>();
      INFO("n = " << n);
      CHECK(rel(rne(t)(q, qd, qdd), tau_ref) < 1e-12);
      CHECK(rel(mass_matrix(t)(q), nhdyn_ref::mass_matrix<LD>(ref, ql).cast<double>()) < 1e-12);
    }
  }
}
