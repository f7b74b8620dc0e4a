/// The reference derivatives of rne on trees (dynamics/reference_derivatives.hpp, issue 18's
/// oracle) against forward-mode dual numbers through the fast tree kernel (a second
/// implementation of rne, differentiated by the scalar type) and 30-digit central differences
/// of the reference rne, on random trees (branches, revolute and prismatic joints, armature),
/// paper5 as a tree and puma560.
#include <catch2/catch.hpp>

#include <nhdyn/dynamics/reference_derivatives.hpp>
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
/// (∂τ/∂q, ∂τ/∂q̇) of the fast tree rne (nhdyn::rne(tree)), one dual direction at a time.
std::pair<MatrixXd, MatrixXd> by_duals(const tree<double>& t, const VectorXd& q, const VectorXd& qd, const VectorXd& qdd) {
  using D = dual<double, 1>;
  const int n = t.dof();
  const auto id = rne(t);
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
