#pragma once
/// \file simulation/integrators.hpp
/// Initial-value integrators for ẋ = f(t, x), x ∈ R^D (for a robot x = (q, η) and
/// f = (S(q) η, η̇) from nh_forward_dynamics), built on Boost.Odeint:
///
/// - `method::rk4`: classical fixed-step Runge–Kutta (order 4). The step is shortened so
///   that every event time (output row, controller sample) is a step point: no
///   interpolation is ever needed.
/// - `method::dopri5`: Dormand–Prince 5(4), error per step controlled against
///   atol + rtol·|x|, with its 4th-order continuous extension for output between steps
///   (odeint `runge_kutta_dopri5` + `dense_output_runge_kutta`).
/// - `method::rosenbrock4`: the linearly-implicit (stiff) Rosenbrock method of order 4 of
///   odeint's `rosenbrock4` (its coefficient set γ = 0.25, a₂₁ = 1.544, c₂ = 0.386 — the one
///   Numerical Recipes 3rd ed. uses in StepperRoss —, with its step controller and dense
///   output), run on Eigen storage (see detail::rosenbrock4_step for why). Its Jacobians
///   ∂f/∂x and ∂f/∂t are exact: f is evaluated once on nhdyn::dual<double, D + 1>
///   numbers, so f must be generic over its scalar; D must be known at compile time.
///
/// `integrate(f, x0, t0, t1, options, outputs, observe)` integrates from t0 to t1 and calls
/// observe(i, x(outputs[i])) for every output time in [t0, t1) (and t1 itself if it is the
/// last output). Failures never pass silently: step-size underflow, a non-finite state,
/// too many steps, and any exception thrown by f end the integration with a
/// `integration_failure` holding the time, the last good state and the reason.
///
///     auto f = [](auto t, const auto& x) { return decltype(x.eval())(x(1), -x(0)); };
///     std::vector<double> ts{0.0, 1.0};
///     auto r = nhdyn::integrate<2>(f, nhdyn::vecN<double, 2>(1, 0), 0.0, 1.0, {}, ts,
///                                  [](int, const auto& x) { /* x(t) */ });
#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <span>
#include <sstream>
#include <string>

// The parts of Boost.Odeint used here, not its umbrella header odeint.hpp (every stepper,
// integrate function and iterator: 5.8 s of g++ 12's time and 480 MB in every file that
// includes this one, against 2.3 s and 325 MB for these, -fsyntax-only; docs/performance.md).
// (In this order: dense_output_runge_kutta.hpp uses what the steppers' headers bring.)
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>
#include <boost/numeric/odeint/stepper/dense_output_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/generation.hpp>   // make_dense_output
#include <boost/numeric/odeint/stepper/rosenbrock4.hpp>  // default_rosenbrock_coefficients

#include "../errors.hpp"
#include "../model/chain.hpp"
#include "../scalar/dual.hpp"

namespace nhdyn {

enum class method { rk4, dopri5, rosenbrock4 };

inline const char* to_string(method m) {
  switch (m) {
    case method::rk4: return "rk4";
    case method::dopri5: return "dopri5";
    case method::rosenbrock4: return "rosenbrock4";
  }
  return "?";
}
inline method method_from_string(const std::string& s) {
  if (s == "rk4") return method::rk4;
  if (s == "dopri5") return method::dopri5;
  if (s == "rosenbrock4") return method::rosenbrock4;
  throw input_error("unknown integrator method '" + s + "' (rk4, dopri5, rosenbrock4)");
}

struct integrator_options {
  method kind = method::dopri5;
  double step = 1e-3;          ///< rk4: the (largest) step; adaptive: the first step tried
  double rtol = 1e-6, atol = 1e-8;
  long max_steps = 10'000'000;  ///< accepted steps over one integrate() call (simulate: over the run)
  double min_step = 1e-12;     ///< smallest admissible adaptive step, relative to max(1, |t|)
};

template <int D>
struct integration_failure {
  double t = 0;     ///< time of the last good state
  vecN<double, D> x;  ///< the last good state
  std::string reason;
};

template <int D>
struct integration_result {
  long steps = 0;  ///< accepted steps
  double t = 0;    ///< time reached
  vecN<double, D> x;  ///< state reached
  std::optional<integration_failure<D>> failure;
  bool success() const { return !failure; }
};

namespace detail {
template <int D>
using ode_state = std::conditional_t<D == dynamic, std::vector<double>, std::array<double, std::size_t(D < 0 ? 0 : D)>>;

template <int D, class X>
ode_state<D> to_ode(const X& x) {
  ode_state<D> s;
  if constexpr (D == dynamic) s.resize(std::size_t(x.size()));
  for (Eigen::Index i = 0; i < x.size(); ++i) s[std::size_t(i)] = x(i);
  return s;
}
template <int D, class X>
vecN<double, D> from_ode(const X& s) {
  vecN<double, D> x(Eigen::Index(s.size()));
  for (std::size_t i = 0; i < s.size(); ++i) x(Eigen::Index(i)) = s[i];
  return x;
}
/// Calls observe for every output time in [t0, t1) (and t1 if `last`), from `at(t)`.
struct output_cursor {
  std::span<const double> times;
  std::size_t next = 0;
  template <class At, class Observe>
  void emit_until(double t_hi, bool inclusive, At&& at, Observe&& observe) {
    while (next < times.size() && (times[next] < t_hi || (inclusive && times[next] <= t_hi))) {
      observe(int(next), at(times[next]));
      ++next;
    }
  }
};

inline std::string short_number(double x) {
  std::ostringstream os;
  os.precision(3);
  os << x;
  return os.str();
}

}  // namespace detail

namespace detail {
/// ∂f/∂x and ∂f/∂t at (t, x) from one evaluation of f on dual<double, D + 1>.
template <int D, class F>
void exact_jacobian(F& f, double t, const vecN<double, D>& x, Eigen::Matrix<double, D, D>& J,
                    vecN<double, D>& dfdt) {
  using Dual = dual<double, D + 1>;
  vecN<Dual, D> xd;
  for (int i = 0; i < D; ++i) xd(i) = Dual::variable(x(i), i);
  const Dual td = Dual::variable(t, D);
  const vecN<Dual, D> fd = f(td, xd);
  for (int i = 0; i < D; ++i) {
    for (int j = 0; j < D; ++j) J(i, j) = fd(i).derivative(j);
    dfdt(i) = fd(i).derivative(D);
  }
}

/// One step of odeint's rosenbrock4 (coefficients default_rosenbrock_coefficients: 4 stages,
/// order 4 with an order-3 error estimate and a continuous extension),
/// on Eigen storage: Boost 1.74's uBLAS, which odeint's own rosenbrock4 stores its state
/// in, does not compile as C++20 (it calls std::allocator::construct, removed in C++20).
/// The algorithm, coefficients and controller below are odeint's, line for line, with one
/// correction: Boost 1.74 has d₄ = +0.0362, where the method needs d₄ = −0.0362. With
/// +0.0362 a non-autonomous problem loses the method's order (tests/test_integrators.cpp: a step on ẋ = f(t, x) must equal
/// the step on the autonomised system (x, t)' = (f, 1), which holds only with −0.0362).
template <int D>
struct rosenbrock4_step {
  using vec = vecN<double, D>;
  boost::numeric::odeint::default_rosenbrock_coefficients<double> c{};
  double d4 = -std::abs(c.d4);  // see above
  vec g1, g2, g3, g4, g5, cont3, cont4;

  /// (x, t) → xout = x(t + h), xerr; f(t, x) and exact ∂f/∂x, ∂f/∂t at (t, x) by duals.
  template <class F>
  void step(F& f, const vec& x, double t, double h, vec& xout, vec& xerr) {
    Eigen::Matrix<double, D, D> J;
    vec dfdt;
    exact_jacobian<D>(f, t, x, J, dfdt);
    const vec dxdt = f(t, x);
    const Eigen::PartialPivLU<Eigen::Matrix<double, D, D>> lu(
        (Eigen::Matrix<double, D, D>::Identity() / (c.gamma * h) - J).eval());
    g1 = lu.solve(dxdt + h * c.d1 * dfdt);
    g2 = lu.solve(f(t + c.c2 * h, vec(x + c.a21 * g1)) + h * c.d2 * dfdt + c.c21 * g1 / h);
    g3 = lu.solve(f(t + c.c3 * h, vec(x + c.a31 * g1 + c.a32 * g2)) + h * c.d3 * dfdt +
                  (c.c31 * g1 + c.c32 * g2) / h);
    g4 = lu.solve(f(t + c.c4 * h, vec(x + c.a41 * g1 + c.a42 * g2 + c.a43 * g3)) + h * d4 * dfdt +
                  (c.c41 * g1 + c.c42 * g2 + c.c43 * g3) / h);
    const vec x5 = x + c.a51 * g1 + c.a52 * g2 + c.a53 * g3 + c.a54 * g4;
    g5 = lu.solve(f(t + h, x5) + (c.c51 * g1 + c.c52 * g2 + c.c53 * g3 + c.c54 * g4) / h);
    const vec xt = x5 + g5;
    xerr = lu.solve(f(t + h, xt) + (c.c61 * g1 + c.c62 * g2 + c.c63 * g3 + c.c64 * g4 + c.c65 * g5) / h);
    xout = xt + xerr;
  }
  void prepare_dense_output() {
    cont3 = c.d21 * g1 + c.d22 * g2 + c.d23 * g3 + c.d24 * g4 + c.d25 * g5;
    cont4 = c.d31 * g1 + c.d32 * g2 + c.d33 * g3 + c.d34 * g4 + c.d35 * g5;
  }
  vec calc_state(double t, const vec& x_old, double t_old, const vec& x_new, double t_new) const {
    const double s = (t - t_old) / (t_new - t_old), s1 = 1 - s;
    return x_old * s1 + s * (x_new + s1 * (cont3 + s * cont4));
  }
};

template <int D, class F, class Observe, class Check, class Fail>
integration_result<D> integrate_rosenbrock(F& f, const vecN<double, D>& x0, double t0, double t1,
                                           const integrator_options& o, output_cursor& out,
                                           Observe& observe, double* dt, integration_result<D>& res,
                                           Check& check, Fail& fail) {
  using vec = vecN<double, D>;
  rosenbrock4_step<D> st;
  double t = t0, h = dt && *dt > 0 ? *dt : o.step, h_old = 0, err_old = 0;
  bool first = true, last_rejected = false;
  vec x = x0, x_new, x_err;
  out.emit_until(t0, true, [&](double) { return x0; }, observe);
  long fails = 0;
  while (t < t1) {
    res.t = t;
    res.x = x;
    h = std::min(h, t1 - t);
    st.step(f, x, t, h, x_new, x_err);
    // odeint's rosenbrock4_controller: RMS error against atol + rtol·max(|x_old|, |x_new|).
    const double err = std::sqrt(
        (x_err.array() / (o.atol + o.rtol * x.cwiseAbs().cwiseMax(x_new.cwiseAbs()).array())).square().sum() / D);
    double fac = std::max(1.0 / 6, std::min(5.0, std::pow(err, 0.25) / 0.9));
    double h_new = h / fac;
    if (!(err <= 1.0)) {
      if (!x_new.allFinite() || !std::isfinite(err)) return fail(t, x, "the state became NaN or Inf");
      if (++fails > 500) return fail(t, x, "step size adjustment failed 500 times in a row");
      if (auto why = check(t, x, h_new)) return fail(t, x, *why);
      h = h_new;
      last_rejected = true;
      continue;
    }
    fails = 0;
    if (!first) {
      const double fac_pred =
          std::max(1.0 / 6, std::min(5.0, (h_old / h) * std::pow(err * err / err_old, 0.25) / 0.9));
      fac = std::max(fac, fac_pred);
      h_new = h / fac;
    }
    first = false;
    h_old = h;
    err_old = std::max(0.01, err);
    if (last_rejected) h_new = std::min(h_new, h);
    last_rejected = false;
    ++res.steps;
    if (auto why = check(t + h, x_new, h)) return fail(t, x, *why);
    st.prepare_dense_output();
    const double t_new = t + h >= t1 * (1 - 1e-15) && t1 - (t + h) < 1e-12 * std::max(1.0, std::abs(t1)) ? t1 : t + h;
    out.emit_until(t_new, t_new >= t1,
                   [&](double ti) { return st.calc_state(ti, x, t, x_new, t_new); }, observe);
    t = t_new;
    x = x_new;
    h = h_new;
  }
  if (dt) *dt = h;
  res.t = t1;
  res.x = x;
  return res;
}
}  // namespace detail

/// Integrates ẋ = f(t, x) from (t0, x0) to t1 (see the file comment). `dt` carries the
/// adaptive step between calls (in: first step to try, out: the last step size), so that a
/// piecewise integration (zero-order hold) does not restart its step-size search.
template <int D, class F, class Observe>
integration_result<D> integrate(F&& f, const vecN<double, D>& x0, double t0, double t1,
                                const integrator_options& o, std::span<const double> outputs,
                                Observe&& observe, double* dt = nullptr) {
  using state = detail::ode_state<D>;
  integration_result<D> res;
  res.t = t0;
  res.x = x0;
  detail::output_cursor out{outputs};
  const auto fail = [&](double t, const vecN<double, D>& x, std::string why) {
    res.failure = integration_failure<D>{t, x, std::move(why)};
    res.t = t;
    res.x = x;
    return res;
  };
  if (!x0.allFinite()) return fail(t0, x0, "the initial state is not finite");
  const auto rhs = [&f](const state& x, state& dxdt, double t) {
    const vecN<double, D> d = f(t, detail::from_ode<D>(x));
    for (std::size_t i = 0; i < x.size(); ++i) dxdt[i] = d(Eigen::Index(i));
  };
  const auto check = [&](double t, const vecN<double, D>& x, double h) -> std::optional<std::string> {
    if (!x.allFinite()) return "the state became NaN or Inf";
    if (res.steps > o.max_steps)
      return "too many steps (more than " + std::to_string(o.max_steps) + ")";
    if (h < o.min_step * std::max(1.0, std::abs(t)))
      return "step size underflow (h = " + detail::short_number(h) + " s)";
    return std::nullopt;
  };
  try {
    if (o.kind == method::rk4) {
      boost::numeric::odeint::runge_kutta4<state> rk;
      state x = detail::to_ode<D>(x0);
      double t = t0;
      // Steps land on every output time and on t1; outputs within tol of a step point are
      // taken there (no sliver steps from rounding of output and sample times).
      const double tol = 1e-9 * o.step;
      out.emit_until(t0 + tol, true, [&](double) { return x0; }, observe);
      while (t < t1) {
        const double t_event =
            out.next < outputs.size() && outputs[out.next] < t1 - tol ? outputs[out.next] : t1;
        const long n = std::max(1L, long(std::ceil((t_event - t) / o.step - 1e-6)));  // rounding slack
        const double h = (t_event - t) / double(n);
        for (long k = 0; k < n; ++k) {
          const vecN<double, D> before = detail::from_ode<D>(x);
          res.t = t;
          res.x = before;
          rk.do_step(rhs, x, t, h);
          t = k + 1 == n ? t_event : t + h;
          ++res.steps;
          if (auto why = check(t, detail::from_ode<D>(x), INFINITY)) return fail(t - h, before, *why);  // fixed h
        }
        out.emit_until(t + tol, true, [&](double) { return detail::from_ode<D>(x); }, observe);
      }
      res.t = t;
      res.x = detail::from_ode<D>(x);
    } else if (o.kind == method::dopri5) {
      using namespace boost::numeric::odeint;
      auto st = make_dense_output(o.atol, o.rtol, runge_kutta_dopri5<state>());
      st.initialize(detail::to_ode<D>(x0), t0, dt && *dt > 0 ? std::min(*dt, t1 - t0) : std::min(o.step, t1 - t0));
      out.emit_until(t0, true, [&](double) { return x0; }, observe);
      state tmp = detail::to_ode<D>(x0);
      const auto at = [&](double t) {
        st.calc_state(t, tmp);
        return detail::from_ode<D>(tmp);
      };
      while (st.current_time() < t1) {
        const double t_before = st.current_time();
        const vecN<double, D> before = detail::from_ode<D>(st.current_state());
        res.t = t_before;
        res.x = before;
        // Do not step far past t1: the interpolant is valid only inside the last step.
        if (st.current_time() + st.current_time_step() > t1)
          st.initialize(st.current_state(), st.current_time(), t1 - st.current_time());
        st.do_step(rhs);
        ++res.steps;
        const double h = st.current_time() - t_before;
        if (auto why = check(st.current_time(), detail::from_ode<D>(st.current_state()), h))
          return fail(t_before, before, *why);
        out.emit_until(std::min(st.current_time(), t1), st.current_time() >= t1, at, observe);
      }
      if (dt) *dt = st.current_time_step();
      res.t = t1;
      res.x = at(t1);
    } else {
      if constexpr (D == dynamic) {
        throw input_error("rosenbrock4 needs a compile-time state size");
      } else {
        return detail::integrate_rosenbrock<D>(f, x0, t0, t1, o, out, observe, dt, res, check, fail);
      }
    }
  } catch (const std::exception& e) {
    return fail(res.t, res.x, e.what());
  }
  return res;
}

}  // namespace nhdyn
