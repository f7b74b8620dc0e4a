// Model and input validation (issue 2, item 3): every non-physical or malformed model is a
// model_error naming the model, the link and the field; every state of the wrong size or
// not finite is an input_error naming it; a link with zero mass but rotational inertia is
// legal and handled right (checked against the independent Lagrangian).
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <nhdyn/nhdyn.hpp>
#include <random>
#include <string>
#include <vector>

#include "reference/lagrangian.hpp"
#include "reference/random_chain.hpp"

namespace {

using Catch::Contains;
using L = nhdyn::link<double>;

/// A valid three-link chain (revolute, prismatic, revolute) to break one field at a time.
std::vector<L> good_links() {
  std::vector<L> out(3);
  for (int i = 0; i < 3; ++i) {
    auto& k = out[std::size_t(i)];
    k.joint = i == 1 ? nhdyn::joint_type::prismatic : nhdyn::joint_type::revolute;
    k.alpha = 0.3 * (i + 1);
    k.a = 0.2;
    k.theta = 0.1;
    k.d = 0.05;
    k.mass = 1.0 + i;
    k.com = Eigen::Vector3d(0.1, 0.0, -0.05);
    k.inertia = nhdyn::box_inertia<double>(k.mass, 0.3, 0.1, 0.1);
  }
  return out;
}

nhdyn::chain<double> make(std::vector<L> links, nhdyn::validation v = {}) {
  return nhdyn::chain<double>(std::move(links), Eigen::Vector3d(0, 0, -9.81), "testbot", v);
}

constexpr double k_nan = std::numeric_limits<double>::quiet_NaN();
constexpr double k_inf = std::numeric_limits<double>::infinity();

}  // namespace

TEST_CASE("validation: a valid chain is accepted, also fixed-size and cast to other scalars") {
  CHECK_NOTHROW(make(good_links()));
  CHECK_NOTHROW(make(good_links()).fixed<3>());
  CHECK_NOTHROW(make(good_links()).cast<float>());
  CHECK_NOTHROW(make(good_links()).cast<long double>());
}

TEST_CASE("validation: negative mass is a model_error naming model, link and field") {
  auto links = good_links();
  links[1].mass = -0.5;
  CHECK_THROWS_AS(make(links), nhdyn::model_error);
  CHECK_THROWS_WITH(make(links), Contains("model 'testbot'") && Contains("link 2") && Contains("field 'mass'") &&
                                     Contains("negative"));
  // Every nhdyn error is a std::runtime_error.
  CHECK_THROWS_AS(make(links), std::runtime_error);
}

TEST_CASE("validation: an asymmetric inertia is a model_error") {
  auto links = good_links();
  links[2].inertia(0, 1) += 0.01;
  CHECK_THROWS_AS(make(links), nhdyn::model_error);
  CHECK_THROWS_WITH(make(links), Contains("link 3") && Contains("field 'inertia'") && Contains("not symmetric"));
}

TEST_CASE("validation: an inertia that is not positive semi-definite is a model_error") {
  auto links = good_links();
  links[0].inertia = Eigen::Vector3d(0.1, 0.1, -0.05).asDiagonal();
  CHECK_THROWS_AS(make(links), nhdyn::model_error);
  CHECK_THROWS_WITH(make(links), Contains("link 1") && Contains("field 'inertia'") &&
                                     Contains("not positive semi-definite"));
  // Indefinite with positive diagonal (off-diagonal too large), in a rotated frame.
  links = good_links();
  links[1].inertia << 0.1, 0.2, 0, 0.2, 0.1, 0, 0, 0, 0.15;
  CHECK_THROWS_WITH(make(links), Contains("link 2") && Contains("not positive semi-definite"));
  CHECK_THROWS_WITH(make(links, nhdyn::validation{false}), Contains("not positive semi-definite"));
}

TEST_CASE("validation: principal moments that violate the triangle inequality are a model_error unless allowed") {
  auto links = good_links();
  links[2].inertia = Eigen::Vector3d(0.01, 0.02, 0.5).asDiagonal();
  CHECK_THROWS_AS(make(links), nhdyn::model_error);
  CHECK_THROWS_WITH(make(links), Contains("link 3") && Contains("field 'inertia'") && Contains("triangle inequality"));
  CHECK_NOTHROW(make(links, nhdyn::validation{false}));
  // A rotated body: the inequality is about principal moments, not the diagonal.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  links[2].inertia = R * Eigen::Vector3d(0.01, 0.02, 0.5).asDiagonal() * R.transpose();
  CHECK_THROWS_WITH(make(links), Contains("triangle inequality"));
  // The boundary (a thin rod or a flat plate, I₁ + I₂ = I₃) is physical.
  links[2].inertia = Eigen::Vector3d(0.2, 0.3, 0.5).asDiagonal();
  CHECK_NOTHROW(make(links));
  // Corke's Puma 560 as published violates it (links 1 and 3): the preset says so.
  const auto puma = nhdyn::presets::puma560<double>();
  std::vector<L> pl(puma.links().begin(), puma.links().end());
  CHECK_THROWS_WITH(nhdyn::chain<double>(pl, puma.gravity(), "puma"), Contains("link 1") && Contains("triangle"));
  CHECK_FALSE(puma.validation_policy().triangle_inequality);
}

TEST_CASE("validation: NaN or Inf in any field is a model_error naming that field") {
  struct field {
    const char* name;
    double& (*at)(L&);
  };
  const std::vector<field> fields = {
      {"alpha", [](L& k) -> double& { return k.alpha; }},
      {"a", [](L& k) -> double& { return k.a; }},
      {"theta", [](L& k) -> double& { return k.theta; }},
      {"d", [](L& k) -> double& { return k.d; }},
      {"mass", [](L& k) -> double& { return k.mass; }},
      {"com", [](L& k) -> double& { return k.com(0); }},
      {"com", [](L& k) -> double& { return k.com(1); }},
      {"com", [](L& k) -> double& { return k.com(2); }},
  };
  for (const double bad : {k_nan, k_inf, -k_inf})
    for (int link = 0; link < 3; ++link) {
      for (const auto& f : fields) {
        auto links = good_links();
        f.at(links[std::size_t(link)]) = bad;
        INFO("field " << f.name << " = " << bad << " on link " << link + 1);
        CHECK_THROWS_AS(make(links), nhdyn::model_error);
        CHECK_THROWS_WITH(make(links), Contains("link " + std::to_string(link + 1)) &&
                                           Contains(std::string("field '") + f.name + "'") && Contains("not finite"));
      }
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          auto links = good_links();
          links[std::size_t(link)].inertia(r, c) = bad;
          INFO("inertia(" << r << ", " << c << ") = " << bad << " on link " << link + 1);
          CHECK_THROWS_WITH(make(links), Contains("link " + std::to_string(link + 1)) &&
                                             Contains("field 'inertia'") && Contains("not finite"));
        }
    }
  for (int r = 0; r < 3; ++r) {
    Eigen::Vector3d g(0, 0, -9.81);
    g(r) = k_nan;
    CHECK_THROWS_WITH(nhdyn::chain<double>(good_links(), g, "testbot"), Contains("field 'gravity'") && Contains("not finite"));
  }
}

TEST_CASE("validation: an empty chain and a wrong compile-time size are model_errors") {
  CHECK_THROWS_WITH(nhdyn::chain<double>({}, Eigen::Vector3d(0, 0, -9.81), "empty"),
                    Contains("model 'empty'") && Contains("at least one link"));
  CHECK_THROWS_AS(make(good_links()).fixed<4>(), nhdyn::model_error);
  CHECK_THROWS_WITH(make(good_links()).fixed<4>(), Contains("has 3 links"));
}

TEST_CASE("validation: q, qd, qdd, tau of the wrong size are input_errors naming the argument") {
  const auto c = make(good_links());
  const Eigen::VectorXd ok = Eigen::VectorXd::Constant(3, 0.2), short2 = Eigen::VectorXd::Zero(2),
                        long4 = Eigen::VectorXd::Zero(4);
  const auto id = nhdyn::rne(c);
  CHECK_NOTHROW(id(ok, ok, ok));
  CHECK_THROWS_AS(id(short2, ok, ok), nhdyn::input_error);
  CHECK_THROWS_WITH(id(short2, ok, ok), Contains("q has 2 entries") && Contains("needs 3"));
  CHECK_THROWS_WITH(id(ok, long4, ok), Contains("qd has 4 entries"));
  CHECK_THROWS_WITH(id(ok, ok, short2), Contains("qdd has 2 entries"));
  CHECK_THROWS_WITH(nhdyn::mass_matrix(c)(long4), Contains("q has 4 entries"));
  CHECK_THROWS_WITH(nhdyn::bias(c)(ok, short2), Contains("qd has 2 entries"));
  CHECK_THROWS_WITH(nhdyn::forward_dynamics(c)(ok, ok, long4), Contains("tau has 4 entries"));
  CHECK_THROWS_WITH(nhdyn::forward_dynamics(c)(short2, ok, ok), Contains("q has 2 entries"));
  // A compile-time-sized model called with run-time-sized vectors of the wrong size.
  const auto cf = c.fixed<3>();
  CHECK_NOTHROW(nhdyn::rne(cf)(ok, ok, ok));
  CHECK_THROWS_WITH(nhdyn::rne(cf)(long4, ok, ok), Contains("q has 4 entries"));
  CHECK_THROWS_WITH(nhdyn::rne(cf)(ok, short2, ok), Contains("qd has 2 entries"));
  CHECK_THROWS_WITH(nhdyn::rne(cf)(ok, ok, long4), Contains("qdd has 4 entries"));
  CHECK_THROWS_WITH(nhdyn::mass_matrix(cf)(short2), Contains("q has 2 entries"));
  CHECK_THROWS_WITH(nhdyn::forward_dynamics(cf)(ok, ok, short2), Contains("tau has 2 entries"));
}

TEST_CASE("validation: a non-finite state is an input_error naming the entry") {
  const auto c = make(good_links());
  const Eigen::VectorXd ok = Eigen::VectorXd::Constant(3, 0.2);
  Eigen::VectorXd bad = ok;
  bad(1) = k_nan;
  const auto id = nhdyn::rne(c);
  CHECK_THROWS_AS(id(bad, ok, ok), nhdyn::input_error);
  CHECK_THROWS_WITH(id(bad, ok, ok), Contains("q[1]") && Contains("not finite"));
  CHECK_THROWS_WITH(id(ok, bad, ok), Contains("qd[1]"));
  CHECK_THROWS_WITH(id(ok, ok, bad), Contains("qdd[1]"));
  bad(1) = k_inf;
  CHECK_THROWS_WITH(id(ok, ok, bad), Contains("qdd[1]"));
  CHECK_THROWS_WITH(nhdyn::forward_dynamics(c)(ok, ok, bad), Contains("tau[1]"));
}

TEST_CASE("validation: a link with zero mass but rotational inertia is legal and matches the Lagrangian") {
  for (int k = 0; k < 3; ++k) {
    auto links = good_links();
    links[std::size_t(k)].mass = 0;  // keeps its inertia and com
    const auto c = make(links);
    const auto ref = nhdyn_ref::from_chain<long double>(c);
    std::mt19937_64 rng(21 + k);
    for (int s = 0; s < 5; ++s) {
      const Eigen::VectorXd q = nhdyn_ref::random_vector(rng, 3, -3, 3), qd = nhdyn_ref::random_vector(rng, 3, -2, 2),
                            qdd = nhdyn_ref::random_vector(rng, 3, -3, 3);
      const nhdyn_ref::vec<long double> tau = nhdyn_ref::inverse_dynamics<long double>(
          ref, q.cast<long double>(), qd.cast<long double>(), qdd.cast<long double>());
      const Eigen::VectorXd v = nhdyn::rne(c)(q, qd, qdd);
      INFO("massless link " << k + 1 << ", q = " << q.transpose());
      CHECK(double((v.cast<long double>() - tau).cwiseAbs().maxCoeff() / tau.cwiseAbs().maxCoeff()) < 1e-12);
      // Its inertia matters: dropping it changes the torques.
      auto stripped = links;
      stripped[std::size_t(k)].inertia.setZero();
      CHECK((nhdyn::rne(make(stripped))(q, qd, qdd) - v).cwiseAbs().maxCoeff() > 1e-6);
    }
  }
}

TEST_CASE("presets: paper5's perturbation factors change the box they describe, as paper5.md defines") {
  // Expected values written from paper5.md's rules, not from the preset's code: a length
  // factor scales the DH parameter and the box edge along the same axis (platform height for
  // d₃, link length for a₄, a₅), the centre of mass and the box inertia follow; a mass factor
  // scales the link's mass and its inertia (same box, denser).
  const auto box = [](double m, double ex, double ey, double ez) {
    return Eigen::Vector3d(m * (ey * ey + ez * ez) / 12, m * (ex * ex + ez * ez) / 12, m * (ex * ex + ey * ey) / 12);
  };
  const auto diag = [](const nhdyn::mat3<double>& I) { return Eigen::Vector3d(I(0, 0), I(1, 1), I(2, 2)); };
  const auto near = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return (a - b).cwiseAbs().maxCoeff() <= 1e-15 * std::max(1.0, b.cwiseAbs().maxCoeff());
  };
  for (const double f : {0.9, 1.1}) {
    INFO("factor " << f);
    nhdyn::presets::paper5_parameters<double> p;
    p.d3_factor = f;
    p.a4_factor = f;
    p.a5_factor = f;
    p.mass_factor[2] = f;
    const auto c = nhdyn::presets::paper5_chain<double>(p);
    const double d3 = 0.237 * f, a4 = 0.150 * f, a5 = 0.168 * f, m3 = 9.0 * f;
    CHECK(c[2].d == Approx(d3).epsilon(1e-15));
    CHECK(c[2].mass == Approx(m3).epsilon(1e-15));
    CHECK(near(c[2].com, Eigen::Vector3d(0, -d3 / 2, 0)));
    CHECK(near(diag(c[2].inertia), box(m3, 0.445, d3, 0.393)));
    CHECK(c[3].a == Approx(a4).epsilon(1e-15));
    CHECK(near(c[3].com, Eigen::Vector3d(-a4 / 2, 0, 0)));
    CHECK(near(diag(c[3].inertia), box(0.1, a4, 0.05, 0.05)));
    CHECK(c[4].a == Approx(a5).epsilon(1e-15));
    CHECK(near(c[4].com, Eigen::Vector3d(-a5 / 2, 0, 0)));
    CHECK(near(diag(c[4].inertia), box(0.1, a5, 0.05, 0.05)));
    // The table's rounded figures at the nominal values (paper5.md, Table II).
    if (f == 0.9) continue;
    const auto n = nhdyn::presets::paper5_chain<double>();
    CHECK(near(diag(n[2].inertia), Eigen::Vector3d(0.1579635, 0.2643555, 0.1906455)));
    CHECK((diag(n[4].inertia) - Eigen::Vector3d(4.1666667e-5, 2.5603333e-4, 2.5603333e-4)).cwiseAbs().maxCoeff() < 1e-11);  // 8 digits
  }
  // Mass factors on the arm links scale mass and inertia together.
  nhdyn::presets::paper5_parameters<double> p;
  p.mass_factor[3] = 1.1;
  const auto c = nhdyn::presets::paper5_chain<double>(p);
  CHECK(c[3].mass == Approx(0.11).epsilon(1e-15));
  CHECK(near(diag(c[3].inertia), box(0.11, 0.150, 0.05, 0.05)));
}
