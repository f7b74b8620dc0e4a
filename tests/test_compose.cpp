// The composition law of functional/compose.hpp, and the nonholonomic inverse dynamics as
// the literal composition project ∘ rne ∘ lift, evaluated stage by stage.
//
// The law:  compose(f, g)(x) == f(g(x));   (g | f)(x) == f(g(x));
//           compose(f, compose(g, h)) == compose(compose(f, g), h) == compose(f, g, h)
//           and likewise for pipes: (h | g) | f == h | (g | f).
#include <catch2/catch.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>
#include <string>

namespace {
using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;
using V5 = Eigen::Matrix<double, 5, 1>;
using V4 = Eigen::Matrix<double, 4, 1>;

struct rng {
  std::mt19937 gen{11};
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  Vec vec(int n, double scale = 1.0) {
    Vec v(n);
    for (int i = 0; i < n; ++i) v(i) = scale * u(gen);
    return v;
  }
};

/// paper5.md's S and Ṡ, by hand.
Mat S_hand(const Vec& q) {
  Mat S = Mat::Zero(5, 4);
  S(0, 0) = std::cos(q(2));
  S(1, 0) = -std::sin(q(2));
  S(2, 1) = S(3, 2) = S(4, 3) = 1.0;
  return S;
}
Mat Sdot_hand(const Vec& q, const Vec& qd) {
  Mat Sd = Mat::Zero(5, 4);
  Sd(0, 0) = -std::sin(q(2)) * qd(2);
  Sd(1, 0) = -std::cos(q(2)) * qd(2);
  return Sd;
}
}  // namespace

TEST_CASE("compose: compose(f, g)(x) == f(g(x)) and (g | f)(x) == f(g(x))") {
  // Three maps that do not commute.
  const auto f = nhdyn::stage([](double x) { return 2.0 * x + 1.0; });
  const auto g = nhdyn::stage([](double x) { return x * x; });
  const auto h = nhdyn::stage([](double x) { return x - 3.0; });
  for (double x : {-2.5, -1.0, 0.0, 0.3, 1.7, 4.0}) {
    CHECK(nhdyn::compose(f, g)(x) == f(g(x)));
    CHECK((g | f)(x) == f(g(x)));
    CHECK(nhdyn::compose(f)(x) == f(x));
    CHECK(nhdyn::compose(f, g, h)(x) == f(g(h(x))));
    CHECK((h | g | f)(x) == f(g(h(x))));
    // Associativity.
    CHECK(nhdyn::compose(f, nhdyn::compose(g, h))(x) == nhdyn::compose(nhdyn::compose(f, g), h)(x));
    CHECK(((h | g) | f)(x) == (h | (g | f))(x));
    CHECK(nhdyn::compose(f, g, h)(x) == (h | g | f)(x));
  }
  CHECK(nhdyn::compose(f, g)(1.0) != nhdyn::compose(g, f)(1.0));  // the order is the one stated
}

TEST_CASE("compose: the innermost stage takes several arguments, and stages change types") {
  const auto product = nhdyn::stage([](double a, double b) { return a * b; });
  const auto to_string = nhdyn::stage([](double x) { return std::to_string(int(x)); });
  const auto length = nhdyn::stage([](const std::string& s) { return s.size(); });
  CHECK(nhdyn::compose(to_string, product)(6.0, 7.0) == "42");
  CHECK((product | to_string | length)(100.0, 10.0) == 4u);
  CHECK(nhdyn::compose(length, to_string, product)(100.0, 10.0) == 4u);
}

TEST_CASE("nonholonomic id == project o rne o lift, evaluated stage by stage") {
  const auto r = nhdyn::presets::paper5();
  const auto lift = nhdyn::lift(r.constraint);
  const auto rne = nhdyn::rne(r.chain);
  const auto project = nhdyn::project(r.constraint);
  const auto id = nhdyn::inverse_dynamics(r.chain, r.constraint);
  const auto piped = lift | rne | project;
  const auto composed = nhdyn::compose(project, rne, lift);
  rng R;
  for (int trial = 0; trial < 50; ++trial) {
    const V5 q = R.vec(5, 3.0);
    const V4 eta = R.vec(4, 2.0), eta_dot = R.vec(4, 3.0);
    // lift: ξ = (q, Sη, Sη̇ + Ṡη)  (eq. 19), against paper5.md's S by hand.
    const auto xi = lift(q, eta, eta_dot);
    const Vec qd_ref = S_hand(q) * Vec(eta);
    const Vec qdd_ref = S_hand(q) * Vec(eta_dot) + Sdot_hand(q, qd_ref) * Vec(eta);
    REQUIRE(xi.q == q);
    REQUIRE((Vec(xi.qd) - qd_ref).cwiseAbs().maxCoeff() < 1e-15);
    REQUIRE((Vec(xi.qdd) - qdd_ref).cwiseAbs().maxCoeff() < 1e-14);
    // rne: (q, v), v = rne(q, q̇, q̈), carrying q along.
    const auto gf = rne(xi);
    REQUIRE(gf.q == q);
    REQUIRE(gf.v == rne(xi.q, xi.qd, xi.qdd));
    // project: τ = Sᵀv (eq. 18; SᵀS = I).
    const V4 tau = project(gf);
    REQUIRE((Vec(tau) - S_hand(q).transpose() * Vec(gf.v)).cwiseAbs().maxCoeff() < 1e-13);
    // The composed forms give the same numbers, bit for bit.
    REQUIRE(id(q, eta, eta_dot) == tau);
    REQUIRE(piped(q, eta, eta_dot) == tau);
    REQUIRE(composed(q, eta, eta_dot) == tau);
    const nhdyn::reduced_state<double, 5, 4> zeta{q, eta, eta_dot};
    REQUIRE(id(zeta) == tau);
    // And with constraint forces: the same τ.
    const auto withf = (lift | rne | nhdyn::constraint_forces(r.constraint))(q, eta, eta_dot);
    REQUIRE(withf.tau == tau);
    REQUIRE(nhdyn::inverse_dynamics_with_forces(r.chain, r.constraint)(q, eta, eta_dot).lambda == withf.lambda);
  }
}

TEST_CASE("compose: user stages inserted in the nonholonomic pipeline") {
  const auto r = nhdyn::presets::paper5();
  const auto lift = nhdyn::lift(r.constraint);
  const auto rne = nhdyn::rne(r.chain);
  const auto project = nhdyn::project(r.constraint);
  const auto id = nhdyn::inverse_dynamics(r.chain, r.constraint);

  // An observer between lift and rne: passes ξ through, records it.
  int seen = 0;
  const auto observe = nhdyn::stage([&seen](const nhdyn::joint_state<double, 5>& xi) {
    ++seen;
    return xi;
  });
  // Viscous joint friction: replaces rne by rne + D q̇ (it needs q̇, so it takes ξ).
  const V5 D(0.0, 0.0, 0.8, 0.05, 0.02);
  const auto rne_with_friction = nhdyn::stage([&](const nhdyn::joint_state<double, 5>& xi) {
    auto f = rne(xi);
    f.v += D.cwiseProduct(xi.qd);
    return f;
  });
  // Gearboxes after the projection: motor torque = τ / N.
  const V4 gear(1.0, 1.0, 50.0, 30.0);
  const auto motors = nhdyn::stage([&](const V4& tau) { return V4(tau.cwiseQuotient(gear)); });
  // Velocities given in another unit before lift: η in (cm/s, deg/s, deg/s, deg/s).
  const auto units = nhdyn::stage([](const V5& q, const V4& eta, const V4& eta_dot) {
    const V4 k(0.01, M_PI / 180, M_PI / 180, M_PI / 180);
    return nhdyn::reduced_state<double, 5, 4>{q, eta.cwiseProduct(k), eta_dot.cwiseProduct(k)};
  });

  rng R;
  for (int trial = 0; trial < 20; ++trial) {
    const V5 q = R.vec(5, 3.0);
    const V4 eta = R.vec(4, 2.0), eta_dot = R.vec(4, 3.0);
    const V4 tau = id(q, eta, eta_dot);
    CHECK((lift | observe | rne | project)(q, eta, eta_dot) == tau);
    // Friction adds Sᵀ D S η (η-space damping), computed here independently.
    const Vec extra = S_hand(q).transpose() * D.asDiagonal() * S_hand(q) * Vec(eta);
    const V4 tau_f = (lift | rne_with_friction | project)(q, eta, eta_dot);
    CHECK((Vec(tau_f) - Vec(tau) - extra).cwiseAbs().maxCoeff() < 1e-13);
    CHECK((lift | rne | project | motors)(q, eta, eta_dot) == V4(tau.cwiseQuotient(gear)));
    const V4 k(0.01, M_PI / 180, M_PI / 180, M_PI / 180);
    CHECK((units | lift | rne | project)(q, eta, eta_dot) == id(q, V4(eta.cwiseProduct(k)), V4(eta_dot.cwiseProduct(k))));
  }
  CHECK(seen == 20);
}

TEST_CASE("compose: with no constraint the pipeline is the holonomic rne") {
  const auto ch = nhdyn::presets::paper5_chain<double>();
  const nhdyn::holonomic<5> free{};
  const auto id = nhdyn::inverse_dynamics(ch, free);
  const auto idf = nhdyn::inverse_dynamics_with_forces(ch, free);
  const auto rne = nhdyn::rne(ch);
  rng R;
  for (int trial = 0; trial < 20; ++trial) {
    const V5 q = R.vec(5, 3.0), qd = R.vec(5, 2.0), qdd = R.vec(5, 3.0);
    CHECK(id(q, qd, qdd) == rne(q, qd, qdd));
    const auto out = idf(q, qd, qdd);
    CHECK(out.tau == rne(q, qd, qdd));
    CHECK(out.lambda.size() == 0);
  }
}
