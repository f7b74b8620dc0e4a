/// Many states per call (analysis/batch.hpp) on the SIMD-pack scalar (scalar/simd.hpp): every
/// column equals the one-state double call (rne, inverse_dynamics, aba) on paper5, puma560 and
/// random trees, for batch sizes below, at and past the pack width (padded tails), with the
/// rne options; bad columns and singular models are named.
#include <catch2/catch.hpp>

#include <nhdyn/analysis/batch.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>

#include "reference/random_tree.hpp"

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
MatrixXd random_mat(std::mt19937_64& rng, int r, int c, double s) {
  return MatrixXd::NullaryExpr(r, c, [&] { return nhdyn_ref::uniform(rng, -s, s); });
}
/// Largest difference of a column from its reference, relative to max(1, |reference|).
template <class F>
double worst_column(const MatrixXd& batch, F one) {
  double w = 0;
  for (Eigen::Index k = 0; k < batch.cols(); ++k) {
    const VectorXd r = one(k);
    w = std::max(w, (batch.col(k) - r).lpNorm<Eigen::Infinity>() / std::max(1.0, r.lpNorm<Eigen::Infinity>()));
  }
  return w;
}
}  // namespace

TEST_CASE("simd_pack: lane-wise arithmetic and libm-accurate sin, cos, sqrt") {
  using P = simd_pack<simd_width>;
  P a, b;
  for (int l = 0; l < simd_width; ++l) a[l] = 0.3 * l - 1.1, b[l] = 1.7 + l;
  const P c = (a * b - a) / b + P(2.0);
  const P s = sin(a), co = cos(a), r = sqrt(b);
  for (int l = 0; l < simd_width; ++l) {
    CHECK(c[l] == (a[l] * b[l] - a[l]) / b[l] + 2.0);
    CHECK(std::abs(s[l] - std::sin(a[l])) <= 2e-16);
    CHECK(std::abs(co[l] - std::cos(a[l])) <= 2e-16);
    CHECK(std::abs(r[l] - std::sqrt(b[l])) <= 4e-16 * r[l]);
  }
  CHECK(is_exact_zero(P(0.0)));
  P z(0.0);
  z[simd_width - 1] = 1e-300;
  CHECK_FALSE(is_exact_zero(z));
  z[0] = std::numeric_limits<double>::infinity();
  CHECK_FALSE(is_finite_scalar(z));
}

TEST_CASE("rne_batch: every column equals rne, for batches below, at and past the pack width") {
  std::mt19937_64 rng(25);
  std::vector<tree<double>> models{as_tree(presets::paper5<double>().chain), as_tree(presets::puma560<double>())};
  for (int n : {1, 7, 20}) models.push_back(nhdyn_ref::random_tree(rng, n, 0.4, n % 2 == 1));
  for (const auto& t : models) {
    const int n = t.dof();
    for (const int K : {1, simd_width - 1, simd_width, 2 * simd_width + 3}) {
      if (K < 1) continue;
      const MatrixXd Q = random_mat(rng, n, K, 2), QD = random_mat(rng, n, K, 2), QDD = random_mat(rng, n, K, 2);
      for (const rne_options o : {rne_options{}, rne_options{false, true}, rne_options{true, false}}) {
        const auto id = rne(t, o);
        const MatrixXd T = rne_batch(t, o)(Q, QD, QDD);
        INFO(t.name() << ", K = " << K << ", gravity " << o.gravity << ", velocity " << o.velocity);
        CHECK(worst_column(T, [&](Eigen::Index k) { return VectorXd(id(Q.col(k), QD.col(k), QDD.col(k))); }) < 1e-13);
      }
    }
  }
  // a chain: its tree
  const auto p5 = presets::paper5<double>().chain;
  const MatrixXd Q = random_mat(rng, 5, 11, 2);
  const MatrixXd T = rne_batch(p5)(Q, Q, Q);
  CHECK(worst_column(T, [&](Eigen::Index k) { return VectorXd(rne(p5)(Q.col(k), Q.col(k), Q.col(k))); }) < 1e-13);
}

TEST_CASE("inverse_dynamics_batch and forward_dynamics_batch: every column equals the one-state call") {
  std::mt19937_64 rng(26);
  const auto p5 = as_tree(presets::paper5<double>().chain);
  const differential_drive<double, dynamic> dd(5, 0, 1, 2, 0.0, -1.0);
  const int K = 3 * simd_width + 1;
  const MatrixXd Q = random_mat(rng, 5, K, 1.5), E = random_mat(rng, 4, K, 1), ED = random_mat(rng, 4, K, 1);
  const MatrixXd T = inverse_dynamics_batch(p5, dd)(Q, E, ED);
  const auto id = inverse_dynamics(p5, dd);
  CHECK(worst_column(T, [&](Eigen::Index k) {
          return VectorXd(id(VectorXd(Q.col(k)), VectorXd(E.col(k)), VectorXd(ED.col(k))));
        }) < 1e-13);
  const MatrixXd Th = inverse_dynamics_batch(p5, holonomic<dynamic>{5})(Q, Q, Q);
  CHECK(worst_column(Th, [&](Eigen::Index k) { return VectorXd(rne(p5)(Q.col(k), Q.col(k), Q.col(k))); }) < 1e-13);
  for (const int n : {3, 12, 30}) {
    std::vector<body<double>> B;
    for (const auto& b : nhdyn_ref::random_tree(rng, n, 0.4, true)) B.push_back(b);
    for (auto& b : B) b.armature = nhdyn_ref::uniform(rng, 0.0, 0.2);
    const tree<double> t(std::move(B), vec3<double>(0, 0, -9.81), "random tree");
    const MatrixXd q = random_mat(rng, n, K, 2), qd = random_mat(rng, n, K, 2), tau = random_mat(rng, n, K, 10);
    const MatrixXd A = forward_dynamics_batch(t)(q, qd, tau);
    const auto fd = aba(t);
    INFO("n = " << n);
    CHECK(worst_column(A, [&](Eigen::Index k) { return VectorXd(fd(q.col(k), qd.col(k), tau.col(k))); }) < 1e-11);
  }
}

TEST_CASE("batches: wrong sizes, a non-finite column and a singular model are refused by name") {
  const auto t = as_tree(presets::puma560<double>());
  const auto b = rne_batch(t);
  const MatrixXd Z = MatrixXd::Zero(6, 5);
  CHECK_THROWS_WITH(b(Z, MatrixXd::Zero(6, 4).eval(), Z), Catch::Contains("QD") && Catch::Contains("6 × 5"));
  CHECK_THROWS_WITH(b(MatrixXd::Zero(5, 5).eval(), Z, Z), Catch::Contains("Q is 5 × 5"));
  MatrixXd bad = Z;
  bad(2, 3) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(b(Z, Z, bad), Catch::Contains("QDD") && Catch::Contains("column) 3"));
  CHECK_THROWS_WITH(forward_dynamics_batch(t)(Z, bad, Z), Catch::Contains("column) 3"));
  const differential_drive<double, dynamic> dd(5, 0, 1, 2, 0.0, -1.0);
  CHECK_THROWS_WITH(inverse_dynamics_batch(t, dd), Catch::Contains("5 joints"));
  // the constraint's own error in one state names that state: E = q₃·S makes SᵀE singular at q₃ = 0
  const auto scaled = make_constraint(
      5, 1, [dd](const auto& q) { return dd.A(q); }, [dd](const auto& q) { return dd.S(q); }, nullptr,
      [dd](const auto& q) {
        using T = typename std::decay_t<decltype(q)>::Scalar;
        return Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>(dd.S(q) * q(3));
      });
  const auto p5 = as_tree(presets::paper5<double>().chain);
  MatrixXd Q5 = MatrixXd::Constant(5, 4, 0.5);
  Q5(3, 2) = 0;
  CHECK_THROWS_WITH(inverse_dynamics_batch(p5, scaled)(Q5, MatrixXd::Zero(4, 4).eval(), MatrixXd::Zero(4, 4).eval()),
                    Catch::Contains("state (column) 2") && Catch::Contains("SᵀE"));
  // a massless leaf: nothing with inertia moves with its joint
  std::vector<body<double>> B(t.begin(), t.end());
  B.back().mass = 0;
  B.back().inertia.setZero();
  const tree<double> massless(std::move(B), t.gravity(), "massless leaf", t.validation_policy());
  CHECK_THROWS_WITH(forward_dynamics_batch(massless)(Z, Z, Z), Catch::Contains("state (column) 0") &&
                                                                   Catch::Contains(massless[5].joint_name));
}
