// Integrators (simulation/integrators.hpp) against problems with known solutions: observed
// orders of convergence, dense output between steps, a stiff problem, exact Jacobians,
// and failures reported with time, state and reason.
#include <catch2/catch.hpp>
#include <cmath>
#include <nhdyn/simulation/integrators.hpp>

using nhdyn::integrate;
using nhdyn::method;
using nhdyn::vecN;

namespace {
// Harmonic oscillator x'' = −x: x(t) = (cos t, −sin t) from (1, 0).
const auto oscillator = [](const auto& t, const auto& x) {
  using T = std::decay_t<decltype(t)>;
  return vecN<T, 2>(x(1), -x(0));
};
// A non-autonomous, nonlinear problem with the solution y(t) = 1 / (1 + t²)·... : y' = −2 t y²,
// y(0) = 1 → y = 1 / (1 + t²).
const auto riccati = [](const auto& t, const auto& x) {
  using T = std::decay_t<decltype(t)>;
  return vecN<T, 1>(-T(2) * t * x(0) * x(0));
};

struct run {
  double err;
  long steps;
};

template <int D, class F, class Exact>
run error_at_end(F f, vecN<double, D> x0, double t1, nhdyn::integrator_options o, Exact exact) {
  std::vector<double> out{t1};
  vecN<double, D> x_end = x0;
  const auto r = integrate<D>(f, x0, 0.0, t1, o, out, [&](int, const vecN<double, D>& x) { x_end = x; });
  REQUIRE(r.success());
  return {(x_end - exact(t1)).norm(), r.steps};
}

const auto osc_exact = [](double t) { return vecN<double, 2>(std::cos(t), -std::sin(t)); };
const auto ric_exact = [](double t) { return vecN<double, 1>(1 / (1 + t * t)); };
}  // namespace

TEST_CASE("integrators: rk4 converges at order 4 on the harmonic oscillator and a Riccati equation") {
  for (int problem = 0; problem < 2; ++problem) {
    double prev = 0;
    for (double h : {0.1, 0.05, 0.025}) {
      nhdyn::integrator_options o{method::rk4, h};
      const double e = problem == 0 ? error_at_end<2>(oscillator, vecN<double, 2>(1, 0), 5.0, o, osc_exact).err
                                    : error_at_end<1>(riccati, vecN<double, 1>(1), 3.0, o, ric_exact).err;
      if (prev > 0) CHECK(std::log2(prev / e) == Approx(4).margin(0.25));
      prev = e;
    }
  }
}

// For an adaptive method of order p, the error at the end falls like N^−p with the number
// of steps N as the tolerance tightens (same error-per-unit-step control).
template <class F, int D, class Exact>
double observed_order(method m, F f, vecN<double, D> x0, double t1, Exact exact, std::vector<double> tols) {
  std::vector<run> r;
  for (double tol : tols) r.push_back(error_at_end<D>(f, x0, t1, {m, 1e-3, tol, tol}, exact));
  const double slope = std::log(r.front().err / r.back().err) / std::log(double(r.back().steps) / r.front().steps);
  return slope;
}

// Fixed steps of h through [0, t1] with one stepper; the global error's order from h and h/2.
template <class Step>
double fixed_step_order(Step step, double t1) {
  double prev = 0, order = 0;
  for (int n : {60, 120, 240}) {
    const double h = t1 / n;
    vecN<double, 1> x(1);
    for (int k = 0; k < n; ++k) x = step(k * h, x, h);
    const double e = std::abs(x(0) - ric_exact(t1)(0));
    if (prev > 0) order = std::log2(prev / e);
    prev = e;
  }
  return order;
}

TEST_CASE("integrators: dopri5 and rosenbrock4 steppers converge at orders 5 and 4 with fixed steps") {
  const double dopri = fixed_step_order(
      [](double t, const vecN<double, 1>& x, double h) {
        std::array<double, 1> s{x(0)};
        boost::numeric::odeint::runge_kutta_dopri5<std::array<double, 1>>().do_step(
            [](const std::array<double, 1>& y, std::array<double, 1>& dy, double tt) { dy[0] = -2 * tt * y[0] * y[0]; },
            s, t, h);
        return vecN<double, 1>(s[0]);
      },
      3.0);
  CHECK(dopri == Approx(5).margin(0.3));
  const double ros = fixed_step_order(
      [](double t, const vecN<double, 1>& x, double h) {
        nhdyn::detail::rosenbrock4_step<1> st;
        vecN<double, 1> out, err;
        auto f = riccati;
        st.step(f, x, t, h, out, err);
        return out;
      },
      3.0);
  CHECK(ros == Approx(4).margin(0.3));
}

TEST_CASE("integrators: a rosenbrock4 step on ẋ = f(t, x) equals the step on the autonomised (x, t)' = (f, 1)") {
  // Holds only with d₄ = −0.0362 (Boost 1.74's odeint has +0.0362; see integrators.hpp).
  const auto autonomised = [](const auto& t, const auto& y) {
    using T = std::decay_t<decltype(t)>;
    return vecN<T, 2>(-T(2) * y(1) * y(0) * y(0), T(1));
  };
  nhdyn::detail::rosenbrock4_step<1> a;
  nhdyn::detail::rosenbrock4_step<2> b;
  vecN<double, 1> xa, ea;
  vecN<double, 2> xb, eb;
  auto f = riccati;
  auto g = autonomised;
  a.step(f, vecN<double, 1>(0.8), 0.5, 0.3, xa, ea);
  b.step(g, vecN<double, 2>(0.8, 0.5), 0.0, 0.3, xb, eb);
  CHECK(xa(0) == Approx(xb(0)).epsilon(1e-13));
  CHECK(ea(0) == Approx(eb(0)).epsilon(1e-11));
}

TEST_CASE("integrators: adaptive error falls like steps^-p as the tolerance tightens (dopri5 p = 5, rosenbrock4 p = 4)") {
  // A looser check than fixed steps: the controller adds its own wobble.
  CHECK(observed_order(method::dopri5, oscillator, vecN<double, 2>(1, 0), 10.0, osc_exact, {1e-5, 1e-11}) ==
        Approx(5.5).margin(1.0));
  CHECK(observed_order(method::dopri5, riccati, vecN<double, 1>(1), 5.0, ric_exact, {1e-5, 1e-11}) ==
        Approx(5.5).margin(1.0));
  CHECK(observed_order(method::rosenbrock4, oscillator, vecN<double, 2>(1, 0), 10.0, osc_exact, {1e-5, 1e-10}) ==
        Approx(4).margin(0.7));
  CHECK(observed_order(method::rosenbrock4, riccati, vecN<double, 1>(1), 5.0, ric_exact, {1e-5, 1e-10}) ==
        Approx(4).margin(0.7));
}

TEST_CASE("integrators: dense output between steps is as accurate as the steps") {
  std::vector<double> out;
  for (int i = 0; i <= 1000; ++i) out.push_back(0.01 * i);
  for (method m : {method::dopri5, method::rosenbrock4}) {
    double worst = 0;
    int seen = 0;
    const auto r = integrate<2>(oscillator, vecN<double, 2>(1, 0), 0.0, 10.0, {m, 1e-3, 1e-10, 1e-10}, out,
                                [&](int i, const vecN<double, 2>& x) {
                                  worst = std::max(worst, (x - osc_exact(out[std::size_t(i)])).norm());
                                  CHECK(i == seen++);
                                });
    REQUIRE(r.success());
    CHECK(seen == 1001);
    CHECK(r.steps < 1000);  // outputs come from interpolation, not from steps at every output
    CHECK(worst < (m == method::dopri5 ? 1e-8 : 1e-7));
  }
}

TEST_CASE("integrators: on a stiff problem rosenbrock4 needs far fewer steps than dopri5") {
  // y' = −1e4 (y − cos t) − sin t, y(0) = 1: y = cos t, stiffness ratio 1e4.
  const auto stiff = [](const auto& t, const auto& x) {
    using T = std::decay_t<decltype(t)>;
    using std::cos;
    using std::sin;
    return vecN<T, 1>(T(-1e4) * (x(0) - cos(t)) - sin(t));
  };
  const auto exact = [](double t) { return vecN<double, 1>(std::cos(t)); };
  const auto ros = error_at_end<1>(stiff, vecN<double, 1>(1), 5.0, {method::rosenbrock4, 1e-3, 1e-7, 1e-9}, exact);
  const auto dp = error_at_end<1>(stiff, vecN<double, 1>(1), 5.0, {method::dopri5, 1e-3, 1e-7, 1e-9}, exact);
  CHECK(ros.err < 1e-6);
  CHECK(dp.err < 1e-6);
  CHECK(ros.steps * 20 < dp.steps);
}

TEST_CASE("integrators: the dual Jacobian equals central differences") {
  const auto f = [](const auto& t, const auto& x) {
    using T = std::decay_t<decltype(t)>;
    using std::sin;
    using std::cos;
    return vecN<T, 3>(sin(x(0)) * x(1) + t * x(2), x(2) * x(2) - cos(t * x(0)), x(0) * x(1) * x(2));
  };
  const vecN<double, 3> x(0.3, -1.2, 0.7);
  const double t = 0.4, h = 1e-6;
  Eigen::Matrix3d J;
  vecN<double, 3> ft;
  nhdyn::detail::exact_jacobian<3>(f, t, x, J, ft);
  for (int j = 0; j < 3; ++j) {
    vecN<double, 3> dx = vecN<double, 3>::Zero();
    dx(j) = h;
    CHECK((J.col(j) - (f(t, vecN<double, 3>(x + dx)) - f(t, vecN<double, 3>(x - dx))) / (2 * h)).norm() < 1e-8);
  }
  CHECK((ft - (f(t + h, x) - f(t - h, x)) / (2 * h)).norm() < 1e-8);
}

TEST_CASE("integrators: failures are reported with time, state and reason") {
  std::vector<double> none;
  const auto ignore = [](int, const auto&) {};
  SECTION("a blow-up (y' = y², y(0) = 1, singular at t = 1) ends near t = 1") {
    const auto blow = [](const auto& t, const auto& x) {
      using T = std::decay_t<decltype(t)>;
      return vecN<T, 1>(x(0) * x(0));
    };
    for (method m : {method::dopri5, method::rosenbrock4, method::rk4}) {
      const auto r = integrate<1>(blow, vecN<double, 1>(1), 0.0, 2.0, {m, 1e-2, 1e-8, 1e-8}, none, ignore);
      REQUIRE_FALSE(r.success());
      CHECK(r.failure->t > 0.8);
      CHECK(r.failure->t < 1.05);  // numerical solutions may step just past the pole
      CHECK(std::isfinite(r.failure->x(0)));  // the last good state
      CHECK(!r.failure->reason.empty());
    }
  }
  SECTION("a right-hand side that returns NaN") {
    const auto nan_after = [](const auto& t, const auto& x) {
      using T = std::decay_t<decltype(t)>;
      return vecN<T, 1>(nhdyn::value_of(t) > 0.5 ? T(NAN) : -x(0));
    };
    for (method m : {method::dopri5, method::rk4, method::rosenbrock4}) {
      const auto r = integrate<1>(nan_after, vecN<double, 1>(1), 0.0, 1.0, {m, 1e-2}, none, ignore);
      REQUIRE_FALSE(r.success());
      CHECK_THAT(r.failure->reason, Catch::Contains("NaN"));
      CHECK(r.failure->t <= 0.5 + 1e-12);
      CHECK(r.failure->t > 0.4);
    }
  }
  SECTION("a right-hand side that throws: its message is the reason") {
    const auto throws = [](const auto& t, const auto& x) -> vecN<std::decay_t<decltype(t)>, 1> {
      if (nhdyn::value_of(t) > 0.25) throw nhdyn::numerical_error("the reduced inertia is singular");
      return -x;
    };
    const auto r = integrate<1>(throws, vecN<double, 1>(1), 0.0, 1.0, {method::dopri5, 1e-2}, none, ignore);
    REQUIRE_FALSE(r.success());
    CHECK_THAT(r.failure->reason, Catch::Contains("singular"));
    CHECK(r.failure->t <= 0.25);
  }
  SECTION("step size underflow: an explicit method on a stiff problem with a floor on the step") {
    // y' = −10⁶ (y − cos t), y(0) = 1 (no transient: y ≈ cos t): dopri5 is stable only for
    // h ≲ 3e-6, below the floor of 1e-4.
    const auto stiff = [](const auto& t, const auto& x) {
      using T = std::decay_t<decltype(t)>;
      using std::cos;
      return vecN<T, 1>(T(-1e6) * (x(0) - cos(t)));
    };
    nhdyn::integrator_options o{method::dopri5, 1e-3, 1e-8, 1e-8};
    o.min_step = 1e-4;
    const auto r = integrate<1>(stiff, vecN<double, 1>(1), 0.0, 1.0, o, none, ignore);
    REQUIRE_FALSE(r.success());
    CHECK_THAT(r.failure->reason, Catch::Contains("step size underflow"));
    CHECK(r.failure->t < 1.0);
    CHECK(r.failure->x.allFinite());
    // The stiff method takes the same problem in stride with the same floor.
    o.kind = method::rosenbrock4;
    CHECK(integrate<1>(stiff, vecN<double, 1>(1), 0.0, 1.0, o, none, ignore).success());
  }
  SECTION("too many steps") {
    nhdyn::integrator_options o{method::dopri5, 1e-3, 1e-12, 1e-12};
    o.max_steps = 50;
    const auto r = integrate<2>(oscillator, vecN<double, 2>(1, 0), 0.0, 100.0, o, none, ignore);
    REQUIRE_FALSE(r.success());
    CHECK_THAT(r.failure->reason, Catch::Contains("too many steps"));
    CHECK(r.failure->t > 0);
    CHECK(r.failure->x.allFinite());
  }
}
