/// The derivatives of rne on trees: the reference (dynamics/reference_derivatives.hpp, the
/// oracle) against forward-mode dual numbers through the fast tree kernel (a second
/// implementation of rne, differentiated by the scalar type) and 50-digit central differences
/// of the reference rne; the analytic recursion (dynamics/rne_derivatives.hpp) against the
/// reference, CRBA, the duals (with external wrenches) and, evaluated in 50 digits, the
/// 50-digit central differences — on random trees (branches, revolute and prismatic joints,
/// armature, massless bodies, point masses), paper5 as a tree and puma560.
#include <catch2/catch.hpp>

#include <algorithm>

#include <nhdyn/dynamics/reference_derivatives.hpp>
#include <nhdyn/dynamics/rne_derivatives.hpp>
#include <nhdyn/dynamics/tree_factor.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/scalar/multiprecision.hpp>
#include <random>

#include "reference/random_tree.hpp"

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
VectorXd random_vec(std::mt19937_64& rng, int n, double r) {
  return VectorXd::NullaryExpr(n, [&] { return nhdyn_ref::uniform(rng, -r, r); });
}
double rel(const MatrixXd& a, const MatrixXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / std::max(1.0, b.lpNorm<Eigen::Infinity>());
}
/// (∂τ/∂q, ∂τ/∂q̇) of id(q, q̇, q̈) — the fast tree rne, with or without wrenches — one dual
/// direction at a time.
template <class F>
std::pair<MatrixXd, MatrixXd> duals_of(const F& id, const VectorXd& q, const VectorXd& qd, const VectorXd& qdd) {
  using D = dual<double, 1>;
  const int n = static_cast<int>(q.size());
  MatrixXd dq(n, n), dqd(n, n);
  for (int j = 0; j < n; ++j) {
    Eigen::Matrix<D, Eigen::Dynamic, 1> Q = q.cast<D>(), QD = qd.cast<D>(), QDD = qdd.cast<D>();
    Q(j) = D::variable(q(j), 0);
    const auto a = id(Q, QD, QDD);
    QD(j) = D::variable(qd(j), 0);
    const auto b = id(q.cast<D>().eval(), QD, QDD);
    for (int i = 0; i < n; ++i) dq(i, j) = a(i).derivative(0), dqd(i, j) = b(i).derivative(0);
  }
  return {dq, dqd};
}
std::pair<MatrixXd, MatrixXd> by_duals(const tree<double>& t, const VectorXd& q, const VectorXd& qd, const VectorXd& qdd) {
  const auto id = rne(t);
  return duals_of([&](const auto& x, const auto& xd, const auto& xdd) { return id(x, xd, xdd); }, q, qd, qdd);
}
}  // namespace

TEST_CASE("rne derivatives (reference): equal the dual-number Jacobians of the fast kernel on random trees") {
  std::mt19937_64 rng(18);
  double worst = 0;
  for (int n : {1, 2, 3, 5, 8, 12, 16}) {
    for (int trial = 0; trial < 3; ++trial) {
      auto t = nhdyn_ref::random_tree(rng, n, 0.4, trial % 2 == 0);
      if (trial == 2) {  // with armature: no q or q̇ dependence, so the same derivatives
        std::vector<body<double>> B(t.begin(), t.end());
        for (auto& b : B) b.armature = nhdyn_ref::uniform(rng, 0.0, 0.5);
        t = tree<double>(std::move(B), t.gravity(), t.name());
      }
      const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), qdd = random_vec(rng, n, 2);
      const auto [dq, dqd] = reference::rne_derivatives(t, q, qd, qdd);
      const auto [eq, eqd] = by_duals(t, q, qd, qdd);
      worst = std::max({worst, rel(dq, eq), rel(dqd, eqd)});
      CHECK(rel(dq, eq) < 1e-12);
      CHECK(rel(dqd, eqd) < 1e-12);
      // without gravity the q̇ derivative at q̇ = 0 vanishes (τ is quadratic in q̇)
      const auto [g0, r0] = reference::rne_derivatives(t, q, VectorXd::Zero(n).eval(), qdd, false);
      CHECK(r0.lpNorm<Eigen::Infinity>() == 0);
    }
  }
  INFO("worst relative difference " << worst);
  CHECK(worst < 1e-12);
}

TEST_CASE("rne derivatives (reference): 30-digit central differences of the reference rne, paper5 and puma560") {
  using M = boost::multiprecision::cpp_bin_float_50;
  std::mt19937_64 rng(7);
  for (const tree<double>& t : {as_tree(presets::paper5<double>().chain), as_tree(presets::puma560<double>())}) {
    const int n = t.dof();
    const VectorXd q = random_vec(rng, n, 1.5), qd = random_vec(rng, n, 1.5), qdd = random_vec(rng, n, 1.5);
    const auto [dq, dqd] = reference::rne_derivatives(t, q, qd, qdd);
    const M h("1e-20");
    MatrixXd fq(n, n), fqd(n, n);
    const Eigen::Matrix<M, Eigen::Dynamic, 1> Q = q.cast<M>(), QD = qd.cast<M>(), QDD = qdd.cast<M>();
    for (int j = 0; j < n; ++j) {
      auto Qp = Q, Qm = Q, Dp = QD, Dm = QD;
      Qp(j) += h, Qm(j) -= h, Dp(j) += h, Dm(j) -= h;
      const auto a = ((reference::rne(t, Qp, QD, QDD) - reference::rne(t, Qm, QD, QDD)) / (2 * h)).eval();
      const auto b = ((reference::rne(t, Q, Dp, QDD) - reference::rne(t, Q, Dm, QDD)) / (2 * h)).eval();
      for (int i = 0; i < n; ++i) fq(i, j) = double(a(i)), fqd(i, j) = double(b(i));
    }
    INFO(t.name());
    CHECK(rel(dq, fq) < 1e-13);
    CHECK(rel(dqd, fqd) < 1e-13);
  }
}

namespace {
/// (∂τ/∂q, ∂τ/∂q̇) of rne(t)(q, qd, qdd, w) by duals (the wrenches' kinematics differentiated too).
template <class W>
std::pair<MatrixXd, MatrixXd> by_duals_with(const tree<double>& t, const W& w, const VectorXd& q, const VectorXd& qd,
                                            const VectorXd& qdd) {
  const auto id = rne(t);
  return duals_of([&](const auto& x, const auto& xd, const auto& xdd) { return id(x, xd, xdd, w); }, q, qd, qdd);
}
/// The tree in 50 digits with its rotations and axes made exactly orthonormal there (a double
/// rotation is orthogonal only to 1e-16, which two algorithms may read differently).
template <class M>
tree<M> rigid_in(const tree<double>& t) {
  const auto orthonormal = [](mat3<M> R) {
    using std::sqrt;
    vec3<M> x = R.col(0), y = R.col(1);
    x /= sqrt(x.dot(x));
    y -= x * x.dot(y);
    y /= sqrt(y.dot(y));
    R << x, y, x.cross(y);
    return R;
  };
  std::vector<body<M>> B;
  for (const auto& b : t) {
    body<M> c = b.template cast<M>();
    c.R_PJ = orthonormal(c.R_PJ);
    c.R_JB = orthonormal(c.R_JB);
    using std::sqrt;
    c.axis /= sqrt(c.axis.dot(c.axis));
    B.push_back(c);
  }
  return tree<M>(std::move(B), t.gravity().template cast<M>(), t.name(), t.validation_policy());
}
tree<double> with_armature(const tree<double>& t, std::mt19937_64& rng) {
  std::vector<body<double>> B(t.begin(), t.end());
  for (auto& b : B) b.armature = nhdyn_ref::uniform(rng, 0.0, 0.5);
  return tree<double>(std::move(B), t.gravity(), t.name());
}
}  // namespace

TEST_CASE("rne derivatives (analytic): equal the reference, CRBA and rne on random trees of 1-48 bodies") {
  std::mt19937_64 rng(1818);
  double worst = 0;
  for (int n : {1, 2, 3, 5, 8, 12, 16, 24, 48}) {
    for (int trial = 0; trial < 3; ++trial) {
      auto t = nhdyn_ref::random_tree(rng, n, trial == 1 ? 0.0 : 0.4, trial % 2 == 0);
      if (trial == 2) t = with_armature(t, rng);
      const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), qdd = random_vec(rng, n, 2);
      const auto d = rne_derivatives(t)(q, qd, qdd);
      const auto [rq, rqd] = reference::rne_derivatives(t, q, qd, qdd);
      INFO("n = " << n << ", trial " << trial);
      CHECK(rel(d.dq, rq) < 1e-12);
      CHECK(rel(d.dqd, rqd) < 1e-12);
      CHECK(rel(d.M, mass_matrix(t)(q)) < 1e-12);
      CHECK(rel(d.tau, rne(t)(q, qd, qdd)) < 1e-12);
      worst = std::max({worst, rel(d.dq, rq), rel(d.dqd, rqd)});
      // gravity and velocity terms off: the reference without gravity, at q̇ = 0
      const auto z = rne_derivatives(t, {.gravity = false, .velocity = false})(q, qd, qdd);
      const auto [zq, zqd] = reference::rne_derivatives(t, q, VectorXd::Zero(n).eval(), qdd, false);
      CHECK(rel(z.dq, zq) < 1e-12);
      CHECK(z.dqd.lpNorm<Eigen::Infinity>() == 0);
    }
  }
  INFO("worst relative difference " << worst);
  CHECK(worst < 1e-12);
  const auto p5 = presets::paper5<double>();
  const VectorXd q = random_vec(rng, 5, 1), qd = random_vec(rng, 5, 1), qdd = random_vec(rng, 5, 1);
  const auto c = rne_derivatives(p5.chain)(q, qd, qdd);
  const auto [rq, rqd] = reference::rne_derivatives(as_tree(p5.chain), q, qd, qdd);
  CHECK(rel(c.dq, rq) < 1e-13);
  CHECK(rel(c.dqd, rqd) < 1e-13);
  CHECK(rel(c.tau, rne(p5.chain)(q, qd, qdd)) < 1e-13);
}

TEST_CASE("tree_ltl: M = LᵀL with the tree's sparsity, solves equal a dense Cholesky's, not-PD refused") {
  std::mt19937_64 rng(613);
  std::vector<tree<double>> trees{as_tree(presets::puma560<double>())};
  for (int n : {1, 2, 5, 16, 48}) trees.push_back(nhdyn_ref::random_tree(rng, n, 0.4, n % 2 == 0));
  trees.push_back(nhdyn_ref::random_tree(rng, 12, 0.0, false));  // a chain
  for (const auto& t : trees) {
    const int n = t.dof();
    INFO("n = " << n);
    const VectorXd q = random_vec(rng, n, 2);
    const MatrixXd M = mass_matrix(t)(q);  // CRBA
    std::vector<int> parent;
    for (int i = 0; i < n; ++i) parent.push_back(t.parent(i));
    const tree_sparsity s(parent);
    const tree_ltl<double> f(M, s);
    REQUIRE(f.ok());
    // L as a dense matrix, only its (i, i) and (i, ancestor of i) entries: LᵀL must be all of M
    // (M's other entries are zero: the sparsity is the tree's)
    MatrixXd L = MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
      L(i, i) = f.L(i, i);
      for (int j = t.parent(i); j >= 0; j = t.parent(j)) L(i, j) = f.L(i, j);
    }
    CHECK(rel(L.transpose() * L, M) < 1e-14);
    // the descendant lists are the ancestor lists inverted, increasing
    for (int j = 0; j < n; ++j) {
      std::vector<int> expect;
      for (int i = 0; i < n; ++i)
        if (std::find(s.begin(i), s.end(i), j) != s.end(i)) expect.push_back(i);
      CHECK(std::vector<int>(s.desc_begin(j), s.desc_end(j)) == expect);
    }
    // solves: against Eigen's dense Cholesky, for column counts that use every block width
    // of the solve (48, 8, 4 and single columns) and a view into a wider matrix
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> X;
    for (int k : {1, 7, 13, 3 * n, 100}) {
      const MatrixXd B = MatrixXd::NullaryExpr(n, k, [&] { return nhdyn_ref::uniform(rng, -3, 3); });
      X = B;
      f.solve_in_place(X);
      CHECK(rel(X, M.llt().solve(B)) < 1e-12);
    }
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> wide =
        MatrixXd::NullaryExpr(n, 60, [&] { return nhdyn_ref::uniform(rng, -3, 3); });
    const MatrixXd before = wide;
    auto middle = wide.middleCols(5, 50);
    f.solve_in_place(middle);
    CHECK(rel(wide.middleCols(5, 50), M.llt().solve(before.middleCols(5, 50))) < 1e-12);
    CHECK(wide.leftCols(5) == before.leftCols(5));  // the columns outside the view untouched
    CHECK(wide.rightCols(5) == before.rightCols(5));
    // not positive definite (a leaf's diagonal, then the root's): refused
    MatrixXd bad = M;
    bad(n - 1, n - 1) = -1;
    CHECK_FALSE(tree_ltl<double>(bad, s).ok());
    bad = M;
    bad(0, 0) = std::numeric_limits<double>::quiet_NaN();
    CHECK_FALSE(tree_ltl<double>(bad, s).ok());
    // misuse is refused: a solve without a factorisation, a wrong size, a bad parent list
    tree_ltl<double> none;
    CHECK_THROWS_AS(none.solve_in_place(X), std::logic_error);
    CHECK_THROWS_AS(tree_ltl<double>(MatrixXd::Identity(n + 1, n + 1), s), std::invalid_argument);
  }
  CHECK_THROWS_WITH(tree_sparsity(std::vector<int>{-1, 1}), Catch::Contains("parent[1] = 1"));
  CHECK_THROWS_AS(tree_sparsity(std::vector<int>{-2}), std::invalid_argument);
}

TEST_CASE("rne derivatives (analytic): with external wrenches, equal the duals of rne(q, qd, qdd, w)") {
  std::mt19937_64 rng(99);
  for (int n : {1, 4, 9, 20}) {
    for (int trial = 0; trial < 2; ++trial) {
      const auto t = with_armature(nhdyn_ref::random_tree(rng, n, 0.4, trial == 0), rng);
      std::vector<wrench<double>> ws;
      for (int k = 0; k < 4; ++k) {
        wrench<double> w;
        w.body = std::uniform_int_distribution<int>(0, n)(rng);
        w.force = random_vec(rng, 3, 20);
        w.moment = random_vec(rng, 3, 5);
        w.point = random_vec(rng, 3, 0.5);
        w.frame = k % 2 ? wrench_frame::body : wrench_frame::world;
        ws.push_back(w);
      }
      const auto w = external_wrenches(t, ws);
      const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), qdd = random_vec(rng, n, 2);
      const auto d = rne_derivatives(t)(q, qd, qdd, w);
      const auto [eq, eqd] = by_duals_with(t, w, q, qd, qdd);
      INFO("n = " << n << ", trial " << trial);
      CHECK(rel(d.dq, eq) < 1e-12);
      CHECK(rel(d.dqd, eqd) < 1e-12);
      CHECK(rel(d.tau, rne(t)(q, qd, qdd, w)) < 1e-12);
      // the wrenches change ∂τ/∂q (else this test could not tell them apart)
      if (n >= 4) CHECK(rel(rne_derivatives(t)(q, qd, qdd).dq, eq) > 1e-6);
    }
  }
}

TEST_CASE("rne derivatives (analytic): in 50 digits, equal 50-digit central differences to 1e-30") {
  using M = boost::multiprecision::cpp_bin_float_50;
  std::mt19937_64 rng(50);
  std::vector<tree<double>> models{as_tree(presets::paper5<double>().chain), as_tree(presets::puma560<double>()),
                                   with_armature(nhdyn_ref::random_tree(rng, 12, 0.4, true), rng)};
  for (const auto& t : models) {
    const int n = t.dof();
    const VectorXd q = random_vec(rng, n, 1.5), qd = random_vec(rng, n, 1.5), qdd = random_vec(rng, n, 1.5);
    const Eigen::Matrix<M, Eigen::Dynamic, 1> Q = q.cast<M>(), QD = qd.cast<M>(), QDD = qdd.cast<M>();
    const tree<M> tm = rigid_in<M>(t);
    const auto d = rne_derivatives(tm)(Q, QD, QDD);
    const M h("1e-17");  // truncation O(h²) ≈ 1e-34, rounding 1e-50/h ≈ 1e-33
    double worst = 0;
    for (int j = 0; j < n; ++j) {
      auto Qp = Q, Qm = Q, Dp = QD, Dm = QD;
      Qp(j) += h, Qm(j) -= h, Dp(j) += h, Dm(j) -= h;
      const auto a = ((reference::rne(tm, Qp, QD, QDD) - reference::rne(tm, Qm, QD, QDD)) / (2 * h)).eval();
      const auto b = ((reference::rne(tm, Q, Dp, QDD) - reference::rne(tm, Q, Dm, QDD)) / (2 * h)).eval();
      for (int i = 0; i < n; ++i) {
        using std::abs;
        worst = std::max({worst, double(abs(d.dq(i, j) - a(i))), double(abs(d.dqd(i, j) - b(i)))});
      }
    }
    const double scale = std::max({1.0, double(d.dq.cwiseAbs().maxCoeff()), double(d.dqd.cwiseAbs().maxCoeff())});
    INFO(t.name() << ": largest difference " << worst << ", relative " << worst / scale);
    CHECK(worst / scale < 1e-30);
  }
}

TEST_CASE("rne derivatives (analytic): wrong sizes and non-finite inputs are refused by name") {
  const auto t = as_tree(presets::puma560<double>());
  const auto d = rne_derivatives(t);
  const VectorXd z = VectorXd::Zero(6);
  CHECK_THROWS_WITH(d(VectorXd::Zero(5).eval(), z, z), Catch::Contains("q"));
  CHECK_THROWS_WITH(d(z, z, VectorXd::Zero(7).eval()), Catch::Contains("qdd"));
  VectorXd bad = z;
  bad(3) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(d(z, bad, z), input_error);
  const auto w = external_wrenches(as_tree(presets::paper5<double>().chain), {});
  CHECK_THROWS_WITH(d(z, z, z, w), Catch::Contains("external wrenches"));
  rne_derivatives_result<double> out;
  d.evaluate(z, z, z, out);
  CHECK(out.dq.rows() == 6);
  CHECK_THROWS_AS(d.evaluate(z, z, bad, out), input_error);
}

namespace {
/// n bodies in a straight line along x (1 m apart), every axis z; each body's mass m at 0.25 m.
tree<double> straight_arm(int n, double m, double inertia) {
  std::vector<body<double>> B(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    auto& b = B[static_cast<std::size_t>(i)];
    b.name = "b" + std::to_string(i);
    b.joint_name = "j" + std::to_string(i);
    b.parent = i - 1;
    b.axis = vec3<double>(0, 0, 1);
    b.p_PJ = vec3<double>(i ? 1.0 : 0.0, 0, 0);
    b.mass = m;
    b.com = vec3<double>(0.25, 0, 0);
    b.inertia = Eigen::Matrix3d::Identity() * inertia;
  }
  return tree<double>(B, vec3<double>(0, 0, -9.81), "straight arm");
}
}  // namespace

TEST_CASE("rne derivatives (analytic): an overflowing derivative is refused although tau is finite; huge finite ones are not") {
  // The kernel sums every entry of dq, dqd and M as it writes them and the matrices are read
  // again only when that sum is not finite. Each case below has τ finite, so only the
  // derivative check can refuse it.
  const VectorXd z = VectorXd::Zero(3);
  const auto t = straight_arm(3, 1, 0.01);
  const auto d = rne_derivatives(t);
  wrench<double> w;
  w.body = 3;  // the last body, at x = 2 m
  w.force = vec3<double>(1e308, 0, 0);  // along the arm: no torque on any joint
  w.point.setZero();
  w.moment.setZero();
  SECTION("a world-axes force: its variation overflows, on one body the diagonal alone") {
    w.frame = wrench_frame::world;
    const auto W = external_wrenches(t, {w});
    CHECK(rne(t)(z, z, z, W).allFinite());
    CHECK_THROWS_WITH(d(z, z, z, W), Catch::Contains("rne_derivatives (a derivative)") && Catch::Contains("overflow"));
    const auto one = straight_arm(1, 1, 0.01);
    const VectorXd z1 = VectorXd::Zero(1);
    w.body = 1;
    w.point = vec3<double>(2, 0, 0);  // 2 m out along the arm: p × f overflows
    const auto W1 = external_wrenches(one, {w});
    CHECK(rne(one)(z1, z1, z1, W1).allFinite());
    CHECK_THROWS_WITH(rne_derivatives(one)(z1, z1, z1, W1), Catch::Contains("rne_derivatives (a derivative)"));
  }
  SECTION("a body-axes force: only off-diagonal entries overflow") {
    w.frame = wrench_frame::body;
    const auto W = external_wrenches(t, {w});
    CHECK(rne(t)(z, z, z, W).allFinite());
    // the kernel alone: the diagonal stays finite, ∂τ_j/∂q_2 (j = 0, 1: S_j · (S_2 ×* F)) does not
    const auto L = detail::make_tree_links(t);
    const std::vector<wrench<double>> ws{w};
    const detail::wrench_forces<double, double> fx{&ws, &L};
    rne_derivatives_result<double> out;
    CHECK_FALSE(detail::rne_derivatives_dispatch<double>(L, t.gravity(), true, z, z, z, fx, out));
    CHECK(out.dq.diagonal().allFinite());
    CHECK_FALSE(std::isfinite(out.dq(1, 2)));
    CHECK_THROWS_WITH(d(z, z, z, W), Catch::Contains("rne_derivatives (a derivative)"));
  }
  SECTION("entries near the largest double whose sum overflows: accepted, and equal CRBA's M") {
    const auto heavy = straight_arm(5, 3e306, 3e304);
    const VectorXd z5 = VectorXd::Zero(5);
    const auto r = rne_derivatives(heavy, rne_options{.gravity = false})(z5, z5, z5);
    CHECK(r.M.allFinite());
    const auto L = detail::make_tree_links(heavy);
    rne_derivatives_result<double> out;  // the kernel's own sum overflowed: the full check ran
    CHECK_FALSE(detail::rne_derivatives_dispatch<double>(L, heavy.gravity(), false, z5, z5, z5,
                                                         detail::wrench_forces<double, double>{}, out));
    CHECK(out.M == r.M);
    const MatrixXd C = mass_matrix(heavy)(z5);
    CHECK(((r.M - C).cwiseAbs().array() <= 1e-12 * C.cwiseAbs().maxCoeff()).all());
  }
  SECTION("ordinary states take the one-pass check") {
    const auto p = as_tree(presets::puma560<double>());
    const auto L = detail::make_tree_links(p);
    const VectorXd q = VectorXd::LinSpaced(6, -1, 1);
    rne_derivatives_result<double> out;
    CHECK(detail::rne_derivatives_dispatch<double>(L, p.gravity(), true, q, q, q, detail::wrench_forces<double, double>{}, out));
  }
}
