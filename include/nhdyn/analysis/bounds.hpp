#pragma once
/// \file analysis/bounds.hpp
/// Guaranteed enclosures of torques (and η̇) over boxes of states and model parameters, by
/// evaluating nhdyn's algorithms in interval arithmetic (scalar/interval.hpp).
///
/// Every returned interval contains the exact value of the computation for every point of
/// the box (rounding included), for the model as given in double. Interval arithmetic
/// over-estimates (the dependency effect): `split = k` bisects the box k times, widest side
/// first (2^k sub-boxes), and returns the hull of the sub-enclosures, which is never wider
/// and, for smooth functions, shrinks about linearly with the sub-box width.
///
/// - `enclose(f, box, k)`: any f from a vector of intervals to a vector of intervals.
/// - `torque_bounds(chain, c, Q, H, HD, k)`: τ over q ∈ Q, η ∈ H, η̇ ∈ HD (nonholonomic).
///   Each bound takes, after k, rne_options and the joints' friction (friction(model),
///   dynamics/terms.hpp: the terms it includes; none by default).
/// - `torque_bounds(chain, Q, QD, QDD, k)`: v = rne over a holonomic box.
/// - `eta_dot_bounds(chain, c, Q, H, TAU, k)`: η̇ of the constrained forward dynamics.
/// - `paper5_torque_bounds(P, Q, H, HD, k)`: τ over paper5's parameter box P as well.
/// - `format_lower`/`format_upper`: decimal text that never narrows a bound.
///
/// An enclosure that is unbounded (an infinite or empty bound: a division by an interval
/// containing 0, e.g. a reduced-inertia pivot over too wide a box) throws numerical_error
/// naming the output entry, e.g. "eta_dot[2]: the interval enclosure is unbounded over this
/// box (…)"; a malformed box (lo > hi, NaN) throws input_error naming the entry.
#include <cstdio>
#include <optional>
#include <string>

#include "../constraints/forward_dynamics.hpp"
#include "../constraints/stages.hpp"
#include "../dynamics/friction.hpp"
#include "../dynamics/rne.hpp"
#include "../robots/presets.hpp"
#include "../scalar/interval.hpp"

namespace nhdyn {

template <int N>
using box = vecN<interval, N>;

/// Index of the widest side of box X (the first one if several tie).
template <class B>
int widest_side(const B& X) {
  int j = 0;
  for (int i = 1; i < static_cast<int>(X.size()); ++i)
    if (X(i).width() > X(j).width()) j = i;
  return j;
}

/// Throws input_error if a side of X is empty, reversed or not finite.
template <class B>
void check_box(const B& X, const char* what) {
  for (Eigen::Index i = 0; i < X.size(); ++i)
    if (!is_finite_scalar(X(i))) {
      throw input_error(std::string(what) + "[" + std::to_string(i) +
                        "] is not a finite interval [lo, hi] with lo <= hi");
    }
}

/// Throws numerical_error naming the first unbounded entry of an enclosure.
template <class R>
void check_bounded(const R& r, const char* what) {
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (!is_finite_scalar(r(i)))
      throw numerical_error(std::string(what) + "[" + std::to_string(i) +
                            "]: the interval enclosure is unbounded over this box (a division by an "
                            "interval containing 0); bisect the box (split) or make it smaller");
}

/// f over box X with `split` levels of bisection, widest side first: the hull of the 2^split
/// sub-box enclosures.
template <class F, class B>
auto enclose(const F& f, const B& X, int split = 0) {
  using R = std::remove_cvref_t<decltype(f(X))>;
  if (split < 0) throw input_error("split must be >= 0, not " + std::to_string(split));
  if (split > 30) throw input_error("split " + std::to_string(split) + " is too deep (2^split boxes)");
  if (split == 0) return R(f(X));
  const int j = widest_side(X);
  const double mid = 0.5 * X(j).lower() + 0.5 * X(j).upper();
  B lo = X, hi = X;
  lo(j) = interval(X(j).lower(), mid);  // both halves contain mid: together they cover X
  hi(j) = interval(mid, X(j).upper());
  const R a = enclose(f, lo, split - 1), b = enclose(f, hi, split - 1);
  R h(a.size());
  for (Eigen::Index i = 0; i < a.size(); ++i) h(i) = hull(a(i), b(i));
  return h;
}

namespace detail {
template <class T, int Z, class... P>
vecN<T, Z> stack(const P&... p) {
  vecN<T, Z> z((p.size() + ...));
  Eigen::Index k = 0;
  ((z.segment(k, p.size()) = p.template cast<T>(), k += p.size()), ...);
  return z;
}
/// Runs an interval evaluation; a numerical_error from inside (an overflowing result) and an
/// unbounded result are both reported as an unbounded enclosure of `what`.
template <class F>
auto bounded(const F& f, const char* what) {
  try {
    auto r = f();
    check_bounded(r, what);
    return r;
  } catch (const numerical_error& e) {
    const std::string msg = e.what();
    if (msg.rfind(what, 0) == 0) throw;
    throw numerical_error(std::string(what) + ": the interval enclosure is unbounded over this box (" +
                          msg + "); bisect the box (split) or make it smaller");
  }
}
}  // namespace detail

/// Enclosure of the nonholonomic τ = project∘rne∘lift over q ∈ Q, η ∈ H, η̇ ∈ HD.
/// The model — a chain<S, N>, or a tree<S> with run-time-sized boxes — may be double (a fixed
/// model) or interval (a model with uncertain parameters).
template <int N, class Model, class C, int M>
  requires(std::is_same_v<Model, chain<typename Model::scalar_type, N>> ||
           std::is_same_v<Model, tree<typename Model::scalar_type>>)
vecN<interval, M> torque_bounds(const Model& ch, const C& c, const box<N>& Q, const box<M>& H,
                                const box<M>& HD, int split = 0, rne_options o = {},
                                const std::optional<friction_fn>& friction = std::nullopt) {
  const int n = c.dof(), m = c.m();
  detail::check_size(Q, n, "q");
  detail::check_size(H, m, "eta");
  detail::check_size(HD, m, "eta_dot");
  check_box(Q, "q");
  check_box(H, "eta");
  check_box(HD, "eta_dot");
  constexpr int Z = (N == dynamic || M == dynamic) ? dynamic : N + 2 * M;
  const auto bound = [&](const auto& id) {
    const auto f = [&](const box<Z>& z) { return vecN<interval, M>(id(z.head(n), z.segment(n, m), z.tail(m))); };
    return detail::bounded([&] { return enclose(f, detail::stack<interval, Z>(Q, H, HD), split); }, "tau");
  };
  return friction ? bound(inverse_dynamics(ch, c, o, *friction)) : bound(inverse_dynamics(ch, c, o));
}

/// Enclosure of the holonomic v = rne(q, q̇, q̈) over q ∈ Q, q̇ ∈ QD, q̈ ∈ QDD (a chain, or a
/// tree with run-time-sized boxes).
template <int N, class Model>
  requires(std::is_same_v<Model, chain<typename Model::scalar_type, N>> ||
           std::is_same_v<Model, tree<typename Model::scalar_type>>)
vecN<interval, N> torque_bounds(const Model& ch, const box<N>& Q, const box<N>& QD, const box<N>& QDD,
                                int split = 0, rne_options o = {},
                                const std::optional<friction_fn>& friction = std::nullopt) {
  const int n = ch.dof();
  detail::check_size(Q, n, "q");
  detail::check_size(QD, n, "qd");
  detail::check_size(QDD, n, "qdd");
  check_box(Q, "q");
  check_box(QD, "qd");
  check_box(QDD, "qdd");
  constexpr int Z = N == dynamic ? dynamic : 3 * N;
  const auto bound = [&](const auto& id) {
    const auto f = [&](const box<Z>& z) { return vecN<interval, N>(id(z.head(n), z.segment(n, n), z.tail(n))); };
    return detail::bounded([&] { return enclose(f, detail::stack<interval, Z>(Q, QD, QDD), split); }, "tau");
  };
  return friction ? bound(rne(ch, o) + *friction) : bound(rne(ch, o));
}

/// Enclosure of η̇ = M_η⁻¹(SᵀEτ − h_η) over q ∈ Q, η ∈ H, τ ∈ TAU (p actuators; a chain, or a
/// tree with run-time-sized boxes).
template <int N, class Model, class C, int M, int P>
  requires(std::is_same_v<Model, chain<typename Model::scalar_type, N>> ||
           std::is_same_v<Model, tree<typename Model::scalar_type>>)
vecN<interval, M> eta_dot_bounds(const Model& ch, const C& c, const box<N>& Q, const box<M>& H,
                                 const box<P>& TAU, int split = 0, rne_options o = {},
                                 const std::optional<friction_fn>& friction = std::nullopt) {
  const int n = c.dof(), m = c.m(), p = actuator_count(c);
  detail::check_size(Q, n, "q");
  detail::check_size(H, m, "eta");
  detail::check_size(TAU, p, "tau");
  check_box(Q, "q");
  check_box(H, "eta");
  check_box(TAU, "tau");
  constexpr int Z = (N == dynamic || M == dynamic || P == dynamic) ? dynamic : N + M + P;
  const auto fd = friction ? nh_forward_dynamics(ch, c, o).with(*friction) : nh_forward_dynamics(ch, c, o);
  const auto f = [&](const box<Z>& z) {
    return vecN<interval, M>(fd(z.head(n), z.segment(n, m), z.tail(p)));
  };
  return detail::bounded([&] { return enclose(f, detail::stack<interval, Z>(Q, H, TAU), split); },
                         "eta_dot");
}

/// Enclosure of paper5's τ over its parameter box P (factors, e.g. outward(0.9, 1.1)) and
/// the state box; bisection runs over parameters and states together (21 sides).
inline vecN<interval, 4> paper5_torque_bounds(const presets::paper5_parameters<interval>& P, const box<5>& Q,
                                              const box<4>& H, const box<4>& HD, int split = 0) {
  box<8> pb;
  pb << P.mass_factor[0], P.mass_factor[1], P.mass_factor[2], P.mass_factor[3], P.mass_factor[4], P.d3_factor,
      P.a4_factor, P.a5_factor;
  check_box(pb, "parameter factors");
  check_box(Q, "q");
  check_box(H, "eta");
  check_box(HD, "eta_dot");
  const auto f = [](const box<21>& z) {
    presets::paper5_parameters<interval> p{{z(0), z(1), z(2), z(3), z(4)}, z(5), z(6), z(7)};
    const auto r = presets::paper5<interval>(p);
    return vecN<interval, 4>(inverse_dynamics(r.chain, r.constraint)(z.segment<5>(8), z.segment<4>(13), z.tail<4>()));
  };
  return detail::bounded([&] { return enclose(f, detail::stack<interval, 21>(pb, Q, H, HD), split); }, "tau");
}

/// A lower bound as decimal text that is ≤ lo as a real number: %.17g of the next double
/// below lo. (A 17-digit decimal is within half a unit of its 17th digit, < 2⁻⁵³·|x|, of the
/// double it prints, so it stays between that double and lo.) Infinities print as ∓1e999.
inline std::string format_lower(double lo) {
  if (std::isinf(lo)) return lo < 0 ? "-1e999" : "1e999";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", detail::step_down(lo));
  return buf;
}
/// An upper bound as decimal text that is ≥ hi as a real number.
inline std::string format_upper(double hi) {
  if (std::isinf(hi)) return hi < 0 ? "-1e999" : "1e999";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", detail::step_up(hi));
  return buf;
}

}  // namespace nhdyn
