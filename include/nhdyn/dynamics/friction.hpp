#pragma once
/// \file dynamics/friction.hpp
/// Joint friction as its own stages, added to rne where a scene needs it (rne itself is
/// friction-free, and a scene without friction pays nothing):
///
///     τ = rne(q, q̇, q̈) + τ_f(q̇),   τ_f,i = B_i q̇_i + c_i(q̇_i)
///
///     auto id = nhdyn::rne(model) + nhdyn::friction(model);      // the model's own laws
///     auto id = nhdyn::rne(model) + nhdyn::viscous_friction(B);   // or any of them by hand
///
/// The Coulomb term c_i is `coulomb_pos` (≥ 0) while q̇_i > 0 and `coulomb_neg` (≤ 0) while
/// q̇_i < 0 (link::friction, body::friction_law; Corke's Tc⁺, Tc⁻ times |G|). At q̇_i = 0 it
/// is set-valued (anything between coulomb_neg and coulomb_pos: stiction); the two laws say
/// what a number there is:
///
/// - `coulomb_law::exact` (default): c = 0 at q̇ = 0, the sign law elsewhere — what Corke's
///   Robotics Toolbox computes. A dual number gets derivative 0 (the derivative at q̇ = 0 does
///   not exist; elsewhere it is 0). An interval q̇ that contains 0 gets the hull of every value
///   the law takes on it (e.g. [coulomb_neg, coulomb_pos]), so a bound over a box encloses
///   every branch.
/// - `coulomb_law::smooth(v_s)`: c = coulomb_pos · s(q̇) for q̇ ≥ 0 and −coulomb_neg · s(q̇)
///   below, s(x) = x / √(x² + v_s²): continuous, 0 at rest, within 1 − v_s²/(2q̇²) of the
///   exact law once |q̇| ≫ v_s; a dual gets the slope coulomb_pos / v_s at 0 (from the
///   right). Intervals are enclosed by the law's monotonicity (its values at the ends).
///
/// Each stage's call forms: `f(qd)` and `f(q, qd, qdd)` give τ_f (n entries, the common type
/// of the coefficients' and q̇'s scalar); sums `a + b` of stages with the (q, q̇, q̈) form add
/// their results and, on a pipeline's ξ = (q, q̇, q̈), add into rne's (q, v).
#include <Eigen/Core>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "../errors.hpp"
#include "../functional/compose.hpp"
#include "../functional/values.hpp"
#include "../model/tree.hpp"

namespace nhdyn {

/// How the Coulomb term treats q̇ at and near 0 (see the file comment).
struct coulomb_law {
  double velocity_scale = 0;  ///< 0: the exact sign law; > 0: smooth with this v_s [rad/s or m/s]
  static coulomb_law exact() { return {0}; }
  static coulomb_law smooth(double v_s) {
    if (!(v_s > 0) || !std::isfinite(v_s))
      throw input_error("coulomb_law::smooth: the velocity scale must be a finite number > 0, not " +
                        std::to_string(v_s));
    return {v_s};
  }
};

namespace detail {
template <class T>
concept interval_like = requires(const T& x) {
                          { x.lower() } -> std::convertible_to<double>;
                          { x.upper() } -> std::convertible_to<double>;
                        };

/// The smooth law's c(x) for x of value v (any scalar with sqrt; an interval x: an enclosure).
template <class T>
T smooth_coulomb(const T& x, double v, double pos, double neg, double v_s) {
  using std::sqrt;
  const T s = x / sqrt(x * x + T(v_s * v_s));
  return v >= 0 ? T(pos * s) : T(-neg * s);
}

/// c(x) of one joint under `law` (see the file comment).
template <class T>
T coulomb_term(const T& x, double pos, double neg, const coulomb_law& law) {
  if constexpr (interval_like<T>) {
    if (law.velocity_scale == 0) {  // the hull of the law's values on [lo, hi]
      const double lo = x.lower(), hi = x.upper();  // the law takes neg below 0, 0 at 0, pos above
      return T(lo < 0 ? neg : lo > 0 ? pos : 0.0, hi > 0 ? pos : hi < 0 ? neg : 0.0);
    }
    // smooth: monotone in x, so its values at the ends enclose it (each end evaluated in T,
    // whose arithmetic rounds outwards)
    const double lo = x.lower(), hi = x.upper(), v_s = law.velocity_scale;
    const T l = smooth_coulomb(T(lo), lo, pos, neg, v_s), h = smooth_coulomb(T(hi), hi, pos, neg, v_s);
    return T(std::min(l.lower(), h.lower()), std::max(l.upper(), h.upper()));
  } else {
    const double v = value_of(x);
    if (law.velocity_scale == 0) return v > 0 ? T(pos) : v < 0 ? T(neg) : T(0);
    return smooth_coulomb(x, v, pos, neg, law.velocity_scale);
  }
}
}  // namespace detail

/// Viscous and Coulomb friction per joint (see the file comment): τ_f,i = B_i q̇_i + c_i(q̇_i).
class friction_fn : public stage_tag {
 public:
  friction_fn(std::vector<joint_friction> laws, coulomb_law law = {}) : f_(std::move(laws)), law_(law) {
    for (std::size_t i = 0; i < f_.size(); ++i)
      if (auto why = detail::friction_problem(f_[i]))
        throw model_error("friction of joint " + std::to_string(i) + ": " + *why);
  }
  int dof() const { return static_cast<int>(f_.size()); }
  const std::vector<joint_friction>& laws() const { return f_; }
  coulomb_law law() const { return law_; }
  friction_fn with(coulomb_law law) const { return friction_fn(f_, law); }

  template <class QD>
  auto operator()(const Eigen::MatrixBase<QD>& qd) const {
    using T = promote_t<double, typename QD::Scalar>;
    detail::check_size(qd, dof(), "qd");
    detail::check_finite(qd, "qd");
    Eigen::Matrix<T, Eigen::Dynamic, 1> tau(dof());
    fill(qd, tau);
    return tau;
  }
  /// τ_f into out (resized to n; no allocation once it has that size), each entry computed as
  /// the call computes it and then converted to out's scalar.
  template <class QD, class Out>
  void evaluate(const Eigen::MatrixBase<QD>& qd, Eigen::PlainObjectBase<Out>& out) const {
    detail::check_size(qd, dof(), "qd");
    detail::check_finite(qd, "qd");
    out.resize(dof());
    fill(qd, out);
  }
  /// out += τ_f(q̇) (n entries), each entry computed as the call computes it, converted to out's
  /// scalar and added: `out += f(qd).cast<…>()`'s numbers without the new vector.
  template <class QD, class Out>
  void add_to(const Eigen::MatrixBase<QD>& qd, Eigen::MatrixBase<Out>& out) const {
    using T = promote_t<double, typename QD::Scalar>;
    using R = typename Out::Scalar;
    detail::check_size(qd, dof(), "qd");
    detail::check_finite(qd, "qd");
    detail::check_size(out, dof(), "out");
    for (int i = 0; i < dof(); ++i) {
      const auto& f = f_[std::size_t(i)];
      const T x = T(qd(i));
      out(i) += R(T(T(f.viscous) * x + detail::coulomb_term(x, f.coulomb_pos, f.coulomb_neg, law_)));
    }
  }
  template <class Q, class QD, class QDD>
  auto operator()(const Eigen::MatrixBase<Q>&, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>&) const {
    return (*this)(qd);
  }

 private:
  template <class QD, class Out>
  void fill(const Eigen::MatrixBase<QD>& qd, Out& tau) const {
    using T = promote_t<double, typename QD::Scalar>;
    using R = typename Out::Scalar;
    for (int i = 0; i < dof(); ++i) {
      const auto& f = f_[std::size_t(i)];
      const T x = T(qd(i));
      tau(i) = R(T(f.viscous) * x + detail::coulomb_term(x, f.coulomb_pos, f.coulomb_neg, law_));
    }
  }

  std::vector<joint_friction> f_;
  coulomb_law law_;
};

/// Viscous friction B_i q̇_i only.
inline friction_fn viscous_friction(const Eigen::VectorXd& B) {
  std::vector<joint_friction> f(static_cast<std::size_t>(B.size()));
  for (Eigen::Index i = 0; i < B.size(); ++i) f[std::size_t(i)].viscous = B(i);
  return friction_fn(std::move(f));
}
/// Coulomb friction only: coulomb_pos_i while q̇_i > 0, coulomb_neg_i while q̇_i < 0.
inline friction_fn coulomb_friction(const Eigen::VectorXd& pos, const Eigen::VectorXd& neg, coulomb_law law = {}) {
  if (pos.size() != neg.size())
    throw input_error("coulomb_friction: " + std::to_string(pos.size()) + " positive and " +
                      std::to_string(neg.size()) + " negative values");
  std::vector<joint_friction> f(static_cast<std::size_t>(pos.size()));
  for (Eigen::Index i = 0; i < pos.size(); ++i) f[std::size_t(i)] = {0, pos(i), neg(i)};
  return friction_fn(std::move(f), law);
}
/// The friction a chain's links carry (link::friction).
template <class S, int N>
friction_fn friction(const chain<S, N>& c, coulomb_law law = {}) {
  std::vector<joint_friction> f;
  for (int i = 0; i < c.dof(); ++i) f.push_back(c[i].friction);
  return friction_fn(std::move(f), law);
}
/// The friction a tree's joints carry (body::friction_law: URDF damping and friction).
template <class S>
friction_fn friction(const tree<S>& t, coulomb_law law = {}) {
  std::vector<joint_friction> f;
  for (const auto& b : t) f.push_back(b.friction_law());
  return friction_fn(std::move(f), law);
}

/// The sum of two stages that take (q, q̇, q̈): `(a + b)(q, qd, qdd) = a(…) + b(…)`; on ξ, a's
/// pipeline result (q, v) (rne's, with any memo) with b(q, q̇, q̈) added to v.
template <class A, class B>
struct sum_fn : stage_tag {
  A a;
  B b;
  template <class Q, class QD, class QDD>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<QDD>& qdd) const {
    const auto x = a(q, qd, qdd);
    const auto y = b(q, qd, qdd);
    using T = promote_t<typename decltype(x)::Scalar, typename decltype(y)::Scalar>;
    Eigen::Matrix<T, Eigen::Dynamic, 1> out = x.template cast<T>() + y.template cast<T>();
    return out;
  }
  /// With applied forces (dynamics/wrench.hpp): a(q, q̇, q̈, fx) + b(q, q̇, q̈).
  template <class Q, class QD, class QDD, applied_forces F>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                  const F& fx) const {
    const auto x = a(q, qd, qdd, fx);
    const auto y = b(q, qd, qdd);
    using T = promote_t<typename decltype(x)::Scalar, typename decltype(y)::Scalar>;
    Eigen::Matrix<T, Eigen::Dynamic, 1> out = x.template cast<T>() + y.template cast<T>();
    return out;
  }
  /// a(q, q̇, q̈) + b(q̇) into v (a's evaluate, then b's add_to: the ξ form's numbers, bit for
  /// bit, without its vectors), for a b that reads q̇ alone (friction), so v may be q̈'s storage.
  template <class Q, class QD, class QDD, class V>
    requires requires(const A& x, const B& y, const Q& q, const QD& qd, const QDD& qdd, Eigen::MatrixBase<V>& v) {
      x.evaluate(q, qd, qdd, v);
      y.add_to(qd, v);
    }
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                Eigen::MatrixBase<V>& v) const {
    a.evaluate(q, qd, qdd, v);
    b.add_to(qd, v);
  }
  int dof() const
    requires requires(const A& x) { x.dof(); }
  {
    return a.dof();
  }
  template <class Xi>
    requires requires(const Xi& x) {
      x.q;
      x.qd;
      x.qdd;
    }
  auto operator()(Xi&& xi) const {
    auto y = b(xi.q, xi.qd, xi.qdd);  // first: a may take ξ's storage
    auto out = a(std::forward<Xi>(xi));
    out.v += y.template cast<typename decltype(out.v)::Scalar>();
    return out;
  }
};
template <stage_like A, stage_like B>
auto operator+(A a, B b) {
  return sum_fn<A, B>{{}, std::move(a), std::move(b)};
}

}  // namespace nhdyn
