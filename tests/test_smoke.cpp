#include <catch2/catch.hpp>
#include <nhdyn/nhdyn.hpp>

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
