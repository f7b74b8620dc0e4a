// Kinematics against independent references (issue 2, item 5):
//  - forward kinematics of every frame against the product of 4×4 DH matrices
//    (tests/reference/lagrangian.hpp, long double);
//  - the geometric Jacobian of points on links against central finite differences (4th
//    order, long double) of the reference's point positions and orientations, and against
//    the reference's exact (dual-number) Jacobian;
//  - J̇q̇ against finite differences of J(q + t q̇) q̇ along the motion and against the
//    reference's exact second derivative of the point's position and of the orientation.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <nhdyn/nhdyn.hpp>
#include <random>
#include <string>

#include "reference/lagrangian.hpp"
#include "reference/random_chain.hpp"

namespace {

using LD = long double;
using nhdyn_ref::random_vector;

struct worst {
  std::string what;
  double e = 0;
  explicit worst(std::string w) : what(std::move(w)) {}
  double operator()(double x) {
    e = std::max(e, x);
    return x;
  }
  ~worst() { std::printf("  max error, %-64s %.3g\n", what.c_str(), e); }
};

template <class A, class B>
double max_abs_diff(const A& x, const B& y) {
  return double((x.template cast<LD>() - y.template cast<LD>()).cwiseAbs().maxCoeff());
}

/// The chains of this file: paper5, puma560 and random mixed chains.
std::vector<nhdyn::chain<double>> chains(std::mt19937_64& rng) {
  std::vector<nhdyn::chain<double>> out{nhdyn::presets::paper5_chain<double>().dynamic_size(),
                                        nhdyn::presets::puma560<double>().dynamic_size()};
  for (int n = 1; n <= 7; ++n) out.push_back(nhdyn_ref::random_chain(rng, n, {.prismatic_probability = 0.4}));
  return out;
}

/// The reference model with link i's centre of mass moved to point p (so that the
/// reference's centre-of-mass velocities are that point's).
nhdyn_ref::model<LD> with_point(nhdyn_ref::model<LD> m, int i, const Eigen::Vector3d& p) {
  m.bodies[std::size_t(i - 1)].com = p.cast<LD>();
  return m;
}

nhdyn_ref::vec3<LD> vee(const nhdyn_ref::mat3<LD>& W) {
  return {0.5L * (W(2, 1) - W(1, 2)), 0.5L * (W(0, 2) - W(2, 0)), 0.5L * (W(1, 0) - W(0, 1))};
}

/// 4th-order central difference of f at 0 with step h: (−f(2h) + 8f(h) − 8f(−h) + f(−2h)) / 12h.
template <class F>
auto derivative(F f, LD h) {
  using R = decltype(f(h));
  return R((f(-2 * h) - f(2 * h) + LD(8) * (f(h) - f(-h))) / (12 * h));
}

}  // namespace

TEST_CASE("kinematics: forward kinematics equals the product of 4×4 DH matrices") {
  std::mt19937_64 rng(11);
  worst w("frames: |R − R_ref|, |p − p_ref| / (1 + |p_ref|)");
  for (const auto& c : chains(rng)) {
    const auto ref = nhdyn_ref::from_chain<LD>(c);
    const nhdyn::kinematics k(c);
    for (int s = 0; s < 10; ++s) {
      const Eigen::VectorXd q = random_vector(rng, c.dof(), -3.1, 3.1);
      const auto X = k.forward(q);
      const auto Xr = nhdyn_ref::poses<LD>(ref, nhdyn_ref::vec<LD>(q.cast<LD>()));
      REQUIRE(X.size() == Xr.size());
      INFO("chain " << c.name() << ", q = " << q.transpose());
      for (std::size_t i = 0; i < X.size(); ++i) {
        const nhdyn_ref::mat3<LD> R = Xr[i].block<3, 3>(0, 0);
        const nhdyn_ref::vec3<LD> p = Xr[i].block<3, 1>(0, 3);
        CHECK(w(max_abs_diff(X[i].R, R)) < 1e-14);
        CHECK(w(max_abs_diff(X[i].p, p) / (1 + double(p.norm()))) < 1e-14);
        const auto F = k.frame(q, int(i));
        CHECK(max_abs_diff(F.p, X[i].p) == 0);
        // A point fixed on link i.
        if (i > 0) {
          const Eigen::Vector3d pi = random_vector(rng, 3, -0.5, 0.5);
          const auto P = nhdyn_ref::point<LD>(ref, nhdyn_ref::vec<LD>(q.cast<LD>()), int(i), nhdyn_ref::vec3<LD>(pi.cast<LD>()));
          CHECK(w(max_abs_diff(k.point(q, int(i), pi), P) / (1 + double(P.norm()))) < 1e-14);
        }
      }
    }
  }
  // The paper's start pose (paper5.md): tip at (0.35, 1, 0) — a published value.
  const auto p5 = nhdyn::presets::paper5_chain<double>();
  const nhdyn::kinematics k5(p5);
  const auto X5 = nhdyn_ref::poses<LD>(nhdyn_ref::from_chain<LD>(p5), nhdyn_ref::vec<LD>::Zero(5));
  CHECK(max_abs_diff(k5.forward(Eigen::Matrix<double, 5, 1>::Zero())[5].p, nhdyn_ref::vec3<LD>(X5[5].block<3, 1>(0, 3))) <
        1e-15);
}

TEST_CASE("kinematics: the Jacobian of a point equals finite differences of its position and orientation") {
  std::mt19937_64 rng(12);
  worst w_fd("Jacobian vs 4th-order central differences (long double), / |J|"),
      w_exact("Jacobian vs the reference's exact dual-number Jacobian, / |J|");
  for (const auto& c : chains(rng)) {
    const auto ref = nhdyn_ref::from_chain<LD>(c);
    const nhdyn::kinematics k(c);
    const int n = c.dof();
    for (int s = 0; s < 4; ++s) {
      const Eigen::VectorXd q = random_vector(rng, n, -3.1, 3.1);
      const nhdyn_ref::vec<LD> ql = q.cast<LD>();
      for (int i = 1; i <= n; ++i) {
        const Eigen::Vector3d pi = random_vector(rng, 3, -0.5, 0.5);
        const Eigen::MatrixXd J = k.jacobian(q, i, pi);
        REQUIRE(J.rows() == 6);
        REQUIRE(J.cols() == n);
        // Finite differences of the reference's position and orientation of the point.
        nhdyn_ref::mat<LD> Jfd(6, n);
        for (int j = 0; j < n; ++j) {
          const auto at = [&](LD t) {
            nhdyn_ref::vec<LD> qt = ql;
            qt(j) += t;
            return nhdyn_ref::poses<LD>(ref, qt)[std::size_t(i)];
          };
          const nhdyn_ref::mat3<LD> R = at(0).block<3, 3>(0, 0);
          Jfd.col(j).head<3>() = derivative(
              [&](LD t) {
                const nhdyn_ref::mat4<LD> X = at(t);
                return nhdyn_ref::vec3<LD>(X.block<3, 1>(0, 3) + X.block<3, 3>(0, 0) * pi.cast<LD>());
              },
              1e-4L);
          const nhdyn_ref::mat3<LD> dR =
              derivative([&](LD t) { return nhdyn_ref::mat3<LD>(at(t).block<3, 3>(0, 0)); }, 1e-4L);
          Jfd.col(j).tail<3>() = vee(nhdyn_ref::mat3<LD>(dR * R.transpose()));
        }
        const double scale = std::max(1.0, J.cwiseAbs().maxCoeff());
        INFO("chain " << c.name() << ", link " << i << ", q = " << q.transpose() << "\nJ =\n"
                      << J << "\nfinite differences =\n"
                      << Jfd.cast<double>());
        CHECK(w_fd(max_abs_diff(J, Jfd) / scale) < 1e-12);
        // The reference's exact Jacobian (dual numbers) of the same point.
        const auto Jr = nhdyn_ref::jacobians<LD>(with_point(ref, i, pi), ql)[std::size_t(i - 1)];
        CHECK(w_exact(max_abs_diff(J.topRows(3), Jr.Jv) / scale) < 1e-14);
        CHECK(w_exact(max_abs_diff(J.bottomRows(3), Jr.Jw) / scale) < 1e-14);
      }
      // Link 0 is the base: it does not move.
      CHECK(k.jacobian(q, 0).cwiseAbs().maxCoeff() == 0);
    }
  }
}

TEST_CASE("kinematics: J̇q̇ equals the derivative of J(q + t q̇) q̇ along the motion") {
  std::mt19937_64 rng(13);
  worst w_fd("J̇q̇ vs central differences of J(q+t·qd)·qd (long double), / scale"),
      w_exact("J̇q̇ vs the reference's exact acceleration (nested duals), / scale");
  for (const auto& c : chains(rng)) {
    const auto ref = nhdyn_ref::from_chain<LD>(c);
    const nhdyn::kinematics k(c);
    const auto cl = c.cast<LD>();
    const nhdyn::kinematics kl(cl);
    const int n = c.dof();
    for (int s = 0; s < 4; ++s) {
      const Eigen::VectorXd q = random_vector(rng, n, -3.1, 3.1), qd = random_vector(rng, n, -2, 2);
      const nhdyn_ref::vec<LD> ql = q.cast<LD>(), qdl = qd.cast<LD>();
      for (int i = 1; i <= n; ++i) {
        const Eigen::Vector3d pi = random_vector(rng, 3, -0.5, 0.5);
        const auto a = k.jdot_qdot(q, qd, i, pi);
        Eigen::Matrix<double, 6, 1> jdqd;
        jdqd << a.linear, a.angular;
        // d/dt [J(q + t q̇) q̇] at t = 0, with the library's own J in long double.
        const nhdyn_ref::vec<LD> fd = derivative(
            [&](LD t) {
              return nhdyn_ref::vec<LD>(kl.jacobian(nhdyn_ref::vec<LD>(ql + t * qdl), i, pi.cast<LD>()) * qdl);
            },
            1e-4L);
        // Exact: the reference's point acceleration and angular acceleration along
        // (q + t q̇, q̇), by dual numbers over its own 4×4 kinematics.
        using D = nhdyn::dual<LD, 1>;
        nhdyn_ref::vec<D> qe(n), qde(n);
        for (int j = 0; j < n; ++j) {
          qe(j) = D(ql(j), {qdl(j)});
          qde(j) = D(qdl(j));
        }
        const auto tw = nhdyn_ref::twists<D>(with_point(ref, i, pi), qe, qde)[std::size_t(i - 1)];
        nhdyn_ref::vec<LD> exact(6);
        for (int r = 0; r < 3; ++r) {
          exact(r) = tw.v(r).derivative(0);
          exact(3 + r) = tw.w(r).derivative(0);
        }
        const double scale = std::max(1.0, double(exact.cwiseAbs().maxCoeff()));
        INFO("chain " << c.name() << ", link " << i << ", q = " << q.transpose() << ", qd = " << qd.transpose()
                      << "\nJdot qd = " << jdqd.transpose() << "\nexact   = " << exact.cast<double>().transpose());
        CHECK(w_fd(max_abs_diff(jdqd, fd) / scale) < 1e-11);
        CHECK(w_exact(max_abs_diff(jdqd, exact) / scale) < 1e-13);
      }
    }
  }
}

TEST_CASE("kinematics: a link index outside 0…n or a q of the wrong size is an input_error") {
  const auto c = nhdyn::presets::puma560<double>().dynamic_size();
  const nhdyn::kinematics k(c);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(6), q5 = Eigen::VectorXd::Zero(5);
  CHECK_THROWS_AS(k.jacobian(q, 7), nhdyn::input_error);
  CHECK_THROWS_WITH(k.jacobian(q, -1), Catch::Contains("link index -1"));
  CHECK_THROWS_AS(k.frame(q, 7), nhdyn::input_error);
  CHECK_THROWS_AS(k.jdot_qdot(q, q, 7), nhdyn::input_error);
  CHECK_THROWS_WITH(k.forward(q5), Catch::Contains("q has 5 entries") && Catch::Contains("needs 6"));
  CHECK_THROWS_WITH(k.jdot_qdot(q, q5, 6), Catch::Contains("qd has 5 entries"));
  // Fixed-size model, run-time-sized vector of the wrong size.
  const nhdyn::kinematics kf(nhdyn::presets::puma560<double>());
  CHECK_THROWS_WITH(kf.jacobian(q5, 6), Catch::Contains("q has 5 entries"));
}
