#include <catch2/catch.hpp>
#include <nhdyn/dynamics/rne_derivatives.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>
#include <reference/random_tree.hpp>

TEST_CASE("smoke: paper5 and puma560 inverse dynamics agree with M qdd + bias") {
  auto r = nhdyn::presets::paper5();
  Eigen::Matrix<double, 5, 1> q(0.1, -0.2, 0.7, 0.4, -0.9), qd(0.3, -0.1, 0.5, 1.2, -0.7), qdd(0.2, 0.4, -0.3, 1.0, 0.5);
  auto id = nhdyn::rne(r.chain);
  auto M = nhdyn::mass_matrix(r.chain)(q);
  auto h = nhdyn::bias(r.chain)(q, qd);
  Eigen::Matrix<double, 5, 1> v = id(q, qd, qdd);
  CHECK((M * qdd + h - v).norm() < 1e-12 * v.norm());
  auto p = nhdyn::presets::puma560();
  Eigen::Matrix<double, 6, 1> q6 = Eigen::Matrix<double, 6, 1>::Random(), qd6 = Eigen::Matrix<double, 6, 1>::Random(), qdd6 = Eigen::Matrix<double, 6, 1>::Random();
  auto M6 = nhdyn::mass_matrix(p)(q6);
  auto v6 = nhdyn::rne(p)(q6, qd6, qdd6);
  CHECK((M6 * qdd6 + nhdyn::bias(p)(q6, qd6) - v6).norm() < 1e-12 * v6.norm());
  auto pd = p.dynamic_size();
  Eigen::VectorXd v6d = nhdyn::rne(pd)(Eigen::VectorXd(q6), Eigen::VectorXd(qd6), Eigen::VectorXd(qdd6));
  CHECK((v6d - v6).norm() < 1e-14 * v6.norm());
  auto fd = nhdyn::forward_dynamics(p)(q6, qd6, v6);
  CHECK((fd - qdd6).norm() < 1e-10);
  // nonholonomic
  auto idn = nhdyn::inverse_dynamics(r.chain, r.constraint);
  Eigen::Matrix<double, 4, 1> eta(0.3, 0.5, 1.2, -0.7), etad(0.2, -0.3, 1.0, 0.5);
  Eigen::Matrix<double, 4, 1> tau = idn(q, eta, etad);
  auto fdn = nhdyn::nh_forward_dynamics(r.chain, r.constraint);
  CHECK((fdn(q, eta, tau) - etad).norm() < 1e-10);
  auto withf = nhdyn::inverse_dynamics_with_forces(r.chain, r.constraint)(q, eta, etad);
  CHECK((withf.tau - tau).norm() < 1e-14);
  auto S = r.constraint.S(q);
  auto A = r.constraint.A(q);
  CHECK((A * S).norm() < 1e-15);
  nhdyn::kinematics kin(r.chain);
  auto J = kin.jacobian(q, 5);
  CHECK(J.rows() == 6);
}

// The kernels read their vectors through maps (detail::kernel_vector, kernel_input: one
// kernel per scalar, size and contiguity, whatever Eigen types a caller passes). Each vector type reaches them by
// its own path: a plain vector, a segment of a longer one, a row of a matrix (a stride), an
// Eigen::Ref, an expression (evaluated into scratch first). Every path gives the same numbers,
// bit for bit, as the plain vectors do.
TEST_CASE("smoke: the kernels give the same numbers whatever vector types they are given") {
  using Eigen::MatrixXd;
  using Eigen::VectorXd;
  const auto p = nhdyn::presets::puma560();
  const auto pd = p.dynamic_size();
  const auto t = nhdyn::as_tree(pd);
  const int n = 6;
  const VectorXd q = VectorXd::LinSpaced(n, -0.7, 0.9), qd = VectorXd::LinSpaced(n, 0.4, -1.1),
                 qdd = VectorXd::LinSpaced(n, 1.3, -0.2);
  // The same vectors as rows 1, 2 and 3 of a matrix (inner stride 4), as segments of a
  // longer vector, and as expressions (q + 0 · q: a sum, with no storage of its own).
  MatrixXd rows = MatrixXd::Zero(4, n);
  rows.row(1) = q.transpose();
  rows.row(2) = qd.transpose();
  rows.row(3) = qdd.transpose();
  VectorXd longer = VectorXd::Zero(3 * n + 2);
  longer << 7.0, q, qd, qdd, -7.0;
  const auto seg = [&](int k) { return longer.segment(1 + k * n, n); };
  const Eigen::Ref<const VectorXd> rq(q), rqd(qd), rqdd(qdd);

  const auto same = [](const auto& a, const auto& b) { return (a.array() == b.array()).all(); };
  const VectorXd quarter = VectorXd::Constant(n, 0.25);  // stored, against Constant(n, 0.25)

  // chains: rne (fixed and run-time size), the mass matrix
  const Eigen::Matrix<double, 6, 1> v_fixed = nhdyn::rne(p)(Eigen::Matrix<double, 6, 1>(q), Eigen::Matrix<double, 6, 1>(qd),
                                                            Eigen::Matrix<double, 6, 1>(qdd));
  CHECK(same(nhdyn::rne(p)(seg(0), seg(1), seg(2)), v_fixed));
  CHECK(same(nhdyn::rne(p)(rows.row(1).transpose(), rows.row(2).transpose(), rows.row(3).transpose()), v_fixed));
  const Eigen::Matrix<double, 6, 1> q6(q), qd6(qd), qdd6(qdd);
  CHECK(same(nhdyn::rne(p)(q6 + 0.0 * q6, qd6 + 0.0 * qd6, qdd6 + 0.0 * qdd6), v_fixed));  // fixed-size scratch
  CHECK(same(nhdyn::mass_matrix(p)(q6 + 0.0 * q6), nhdyn::mass_matrix(p)(q6)));
  const auto id = nhdyn::rne(pd);
  const VectorXd v = id(q, qd, qdd);
  CHECK(same(v, v_fixed));
  CHECK(same(id(seg(0), seg(1), seg(2)), v));
  CHECK(same(id(rows.row(1).transpose(), rows.row(2).transpose(), rows.row(3).transpose()), v));
  CHECK(same(id(rq, rqd, rqdd), v));
  CHECK(same(id(q + 0.0 * q, qd + 0.0 * qd, qdd + 0.0 * qdd), v));
  CHECK(same(id(q, qd, VectorXd::Constant(n, 0.25)), id(q, qd, quarter)));
  MatrixXd out_rows = MatrixXd::Zero(3, n);
  auto out_row = out_rows.row(1).transpose();
  id.evaluate(q, qd, qdd, out_row);  // a strided output
  CHECK(same(out_rows.row(1).transpose(), v));
  CHECK(out_rows.row(0).isZero(0.0));
  CHECK(out_rows.row(2).isZero(0.0));
  const MatrixXd M = nhdyn::mass_matrix(pd)(q);
  CHECK(same(nhdyn::mass_matrix(pd)(rows.row(1).transpose()), M));
  CHECK(same(nhdyn::mass_matrix(pd)(seg(0)), M));
  CHECK(same(nhdyn::mass_matrix(pd)(q + 0.0 * q), M));

  // trees: rne, CRBA, ABA, ∂τ/∂(q, q̇)
  const auto idt = nhdyn::rne(t);
  const VectorXd vt = idt(q, qd, qdd);
  CHECK(same(idt(rows.row(1).transpose(), rows.row(2).transpose(), rows.row(3).transpose()), vt));
  CHECK(same(idt(seg(0), seg(1), seg(2)), vt));
  CHECK(same(idt(q + 0.0 * q, rqd, qdd + 0.0 * qdd), vt));
  CHECK(same(idt(q, qd, VectorXd::Constant(n, 0.25)), idt(q, qd, quarter)));
  MatrixXd tree_out = MatrixXd::Zero(3, n);
  auto tree_row = tree_out.row(2).transpose();
  idt.evaluate(q, qd, qdd, tree_row);  // a strided output
  CHECK(same(tree_out.row(2).transpose(), vt));
  const MatrixXd Mt = nhdyn::mass_matrix(t)(q);
  CHECK(same(nhdyn::mass_matrix(t)(rows.row(1).transpose()), Mt));
  CHECK(same(nhdyn::mass_matrix(t)(q + 0.0 * q), Mt));
  const auto fd = nhdyn::aba(t);
  const VectorXd a = fd(q, qd, vt);
  CHECK(same(fd(rows.row(1).transpose(), seg(1), vt + 0.0 * vt), a));
  CHECK(same(fd(rq, rqd, Eigen::Ref<const VectorXd>(vt)), a));
  auto aba_row = tree_out.row(0).transpose();
  fd.evaluate(q, qd, vt, aba_row);  // a strided output
  CHECK(same(tree_out.row(0).transpose(), a));
  CHECK(same(tree_out.row(2).transpose(), vt));  // the row beside it untouched
  const auto dt = nhdyn::rne_derivatives(t);
  const auto d = dt(q, qd, qdd);
  const auto ds = dt(rows.row(1).transpose(), seg(1), qdd + 0.0 * qdd);
  CHECK(same(ds.tau, d.tau));
  CHECK(same(ds.dq, d.dq));
  CHECK(same(ds.dqd, d.dqd));

  // An expression longer than the stack scratch (64 entries) is copied to the thread's block.
  std::mt19937_64 rng(70);
  const auto big = nhdyn::rne(nhdyn_ref::random_tree(rng, 70));
  const VectorXd qb = VectorXd::LinSpaced(70, -1.0, 1.0), qdb = VectorXd::LinSpaced(70, 0.5, -0.5);
  CHECK(same(big(qb + 0.0 * qb, qdb + 0.0 * qdb, VectorXd::Constant(70, 0.25)),
             big(qb, qdb, VectorXd(VectorXd::Constant(70, 0.25)))));
}
