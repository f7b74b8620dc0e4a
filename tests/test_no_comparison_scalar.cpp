// "Never branch on a generic scalar's comparison", proved by the compiler: `strict` is a
// number type whose comparison operators are deleted, so if any algorithm compared two of
// its generic scalars (an `if (x < y)`, a std::max, an Eigen maxCoeff, an `== 0` test
// outside scalar_traits) this file would not compile. It then runs every algorithm on it
// and checks the results against the double ones (same arithmetic: rounding-level
// agreement; the double path reduces its angles with its own sin/cos kernel).
#include <catch2/catch.hpp>
#include <cmath>
#include <nhdyn/nhdyn.hpp>

namespace strict_ns {

/// A real number that cannot be compared.
struct strict {
  double x = 0;
  strict() = default;
  strict(double v) : x(v) {}  // NOLINT: implicit, like a real

  friend strict operator+(strict a, strict b) { return a.x + b.x; }
  friend strict operator-(strict a, strict b) { return a.x - b.x; }
  friend strict operator*(strict a, strict b) { return a.x * b.x; }
  friend strict operator/(strict a, strict b) { return a.x / b.x; }
  friend strict operator-(strict a) { return -a.x; }
  friend strict operator+(strict a) { return a; }
  strict& operator+=(strict b) { return x += b.x, *this; }
  strict& operator-=(strict b) { return x -= b.x, *this; }
  strict& operator*=(strict b) { return x *= b.x, *this; }
  strict& operator/=(strict b) { return x /= b.x, *this; }

  friend bool operator<(strict, strict) = delete;
  friend bool operator>(strict, strict) = delete;
  friend bool operator<=(strict, strict) = delete;
  friend bool operator>=(strict, strict) = delete;
  friend bool operator==(strict, strict) = delete;
  friend bool operator!=(strict, strict) = delete;

  friend strict sin(strict a) { return std::sin(a.x); }
  friend strict cos(strict a) { return std::cos(a.x); }
  friend strict sqrt(strict a) { return std::sqrt(a.x); }
  friend strict atan2(strict a, strict b) { return std::atan2(a.x, b.x); }
  friend strict abs(strict a) { return std::abs(a.x); }
};

}  // namespace strict_ns

using strict_ns::strict;

template <>
struct nhdyn::scalar_traits<strict> {
  static double value(const strict& a) { return a.x; }
  static bool is_exact_zero(const strict& a) { return a.x == 0; }
  static bool is_finite(const strict& a) { return std::isfinite(a.x); }
};

namespace Eigen {
template <>
struct NumTraits<strict> : NumTraits<double> {
  using Real = strict;
  using NonInteger = strict;
  using Nested = strict;
  using Literal = strict;
  static inline Real epsilon() { return NumTraits<double>::epsilon(); }
  static inline Real dummy_precision() { return NumTraits<double>::dummy_precision(); }
  static inline Real highest() { return NumTraits<double>::highest(); }
  static inline Real lowest() { return NumTraits<double>::lowest(); }
};
}  // namespace Eigen

namespace {

template <int R, int C>
Eigen::Matrix<strict, R, C> to_strict(const Eigen::Matrix<double, R, C>& m) {
  return m.unaryExpr([](double v) { return strict(v); });
}
template <class M>
Eigen::MatrixXd to_double(const M& m) {
  return m.unaryExpr([](const strict& v) { return v.x; }).template cast<double>();
}
/// max |a − b| / max(1, max |b|).
template <class A>
double rel(const A& a, const Eigen::MatrixXd& b) {
  return (to_double(a) - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace

TEST_CASE("strict scalar: a number type without comparisons is an nhdyn scalar") {
  STATIC_REQUIRE(nhdyn::scalar<strict>);
  STATIC_REQUIRE(!nhdyn::scalar<int>);  // the algorithms divide
}

TEST_CASE("strict scalar: every holonomic algorithm runs without comparing scalars and agrees with double") {
  const auto c = nhdyn::presets::puma560<double>();
  const auto cs = c.cast<strict>();
  using V6 = Eigen::Matrix<double, 6, 1>;
  const V6 q(0.3, -0.8, 1.1, 0.2, -0.5, 0.9), qd(0.5, -0.3, 0.8, -1.0, 0.4, 0.7), qdd(-0.4, 0.9, 0.3, 0.6, -0.2, 1.1);
  const auto qS = to_strict(q), qdS = to_strict(qd), qddS = to_strict(qdd);
  const double tol = 1e-13;

  const V6 v = nhdyn::rne(c)(q, qd, qdd);
  CHECK(rel(nhdyn::rne(cs)(qS, qdS, qddS), v) < tol);
  CHECK(rel(nhdyn::rne(cs, {.gravity = false, .velocity = false})(qS, qdS, qddS),
            nhdyn::rne(c, {.gravity = false, .velocity = false})(q, qd, qdd)) < tol);
  CHECK(rel(nhdyn::mass_matrix(cs)(qS), nhdyn::mass_matrix(c)(q)) < tol);
  CHECK(rel(nhdyn::bias(cs)(qS, qdS), nhdyn::bias(c)(q, qd)) < tol);
  CHECK(rel(nhdyn::forward_dynamics(cs)(qS, qdS, to_strict(v)), qdd) < 1e-11);

  nhdyn::kinematics<strict, 6> ks(cs);
  nhdyn::kinematics<double, 6> kd(c);
  CHECK(rel(ks.jacobian(qS, 6), kd.jacobian(q, 6)) < tol);
  CHECK(rel(ks.jdot_qdot(qS, qdS, 6).linear, kd.jdot_qdot(q, qd, 6).linear) < tol);
  CHECK(rel(ks.jdot_qdot(qS, qdS, 6).angular, kd.jdot_qdot(q, qd, 6).angular) < tol);
  CHECK(rel(ks.point(qS, 6, Eigen::Matrix<strict, 3, 1>::Zero()), kd.point(q, 6, Eigen::Vector3d::Zero())) < tol);
}

TEST_CASE("strict scalar: the nonholonomic stages and forward dynamics run without comparing scalars") {
  const auto r = nhdyn::presets::paper5<double>();
  const auto rs = nhdyn::presets::paper5<strict>();
  using V5 = Eigen::Matrix<double, 5, 1>;
  using V4 = Eigen::Matrix<double, 4, 1>;
  const V5 q(0.1, -0.2, 0.7, 0.4, -0.9);
  const V4 eta(0.3, 0.5, 1.2, -0.7), eta_dot(0.2, -0.3, 1.0, 0.5);
  const auto qS = to_strict(q);
  const auto etaS = to_strict(eta), eta_dotS = to_strict(eta_dot);
  const double tol = 1e-13;

  const V4 tau = nhdyn::inverse_dynamics(r.chain, r.constraint)(q, eta, eta_dot);
  CHECK(rel(nhdyn::inverse_dynamics(rs.chain, rs.constraint)(qS, etaS, eta_dotS), tau) < tol);
  const auto f = nhdyn::inverse_dynamics_with_forces(rs.chain, rs.constraint)(qS, etaS, eta_dotS);
  const auto fd = nhdyn::inverse_dynamics_with_forces(r.chain, r.constraint)(q, eta, eta_dot);
  CHECK(rel(f.lambda, fd.lambda) < tol);
  const auto nh_fd = nhdyn::nh_forward_dynamics(rs.chain, rs.constraint);
  CHECK(rel(nh_fd(qS, etaS, to_strict(tau)), eta_dot) < 1e-11);
  CHECK(rel(nhdyn::nh_forward_dynamics(rs.chain, rs.constraint, {}, nhdyn::reduced_inertia_method::rne_columns)(
                qS, etaS, to_strict(tau)),
            eta_dot) < 1e-11);
}
