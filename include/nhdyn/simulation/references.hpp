#pragma once
/// \file simulation/references.hpp
/// What a closed loop tracks: a reference r_d(t) with ṙ_d, r̈_d for a task point, and for
/// joint-space references also q_d(t), q̇_d, q̈_d. Every reference is generic over the time's
/// scalar (duals give exact Jacobians of the closed loop).
///
///     circle:       r_d = c + w t + R (u cos(ωt + φ) + v sin(ωt + φ))          (paper5.md: w = 0)
///     line:         r_d = a + s(τ)(b − a),  τ = (t − t₀)/(t₁ − t₀) clamped to [0, 1],
///                   s = 10τ³ − 15τ⁴ + 6τ⁵ (rest to rest: ṡ = s̈ = 0 at both ends)
///     spline:       r_d through waypoints p_k at times t_k: the cubic spline with zero
///                   velocity at t₀ and t_K (C², r̈_d piecewise linear); held before/after
///     joint spline: q_d through joint waypoints q_k at t_k, the same spline per joint; its
///                   task image r_d = r(q_d), ṙ_d = J q̇_d, r̈_d = J q̈_d + J̇ q̇_d on the
///                   controller's model, so a task-space controller can follow it too
///
/// `reference_spec` is a scene's reference as data; `scene_reference(spec, kinematics, body,
/// point)` is the callable the closed loop evaluates.
#include <algorithm>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Dense>

#include "../errors.hpp"
#include "../model/chain.hpp"

namespace nhdyn {

/// r_d(t) and its first two derivatives; for a joint-space reference also q_d(t), q̇_d, q̈_d
/// (empty for task-space references).
template <class T>
struct task_reference {
  vec3<T> r, rd, rdd;
  vecN<T, dynamic> q, qd, qdd;
};

/// r_d(t) = c + w t + R (u cos(ω t + φ) + v sin(ω t + φ)): a circle whose centre moves at the
/// constant velocity w (0 by default). paper5's circle is c = (0.35, 0, 0), R = 1, u = y₀,
/// v = z₀, ω = 2π/20, φ = 0.
struct circle_reference {
  Eigen::Vector3d center{0.35, 0, 0}, u{0, 1, 0}, v{0, 0, 1};
  double radius = 1, omega = 2 * 3.14159265358979323846 / 20, phase = 0;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< w [m/s]: the centre's drift

  template <class T>
  task_reference<T> operator()(const T& t) const {
    using std::cos;
    using std::sin;
    const T th = T(omega) * t + T(phase), c = cos(th), s = sin(th);
    const vec3<T> U = u.cast<T>(), V = v.cast<T>();
    task_reference<T> ref;
    ref.r = center.cast<T>() + T(radius) * (c * U + s * V);
    ref.rd = T(radius * omega) * (c * V - s * U);
    if (!velocity.isZero()) {  // paper5's circle keeps its arithmetic unchanged
      ref.r += velocity.cast<T>() * t;
      ref.rd += velocity.cast<T>();
    }
    ref.rdd = T(-radius * omega * omega) * (c * U + s * V);
    return ref;
  }
};

/// A straight line from `from` to `to`, rest to rest over [start, end] by the quintic
/// s(τ) = 10τ³ − 15τ⁴ + 6τ⁵; r_d = from before start, = to after end.
struct line_reference {
  Eigen::Vector3d from = Eigen::Vector3d::Zero(), to = Eigen::Vector3d::Zero();
  double start = 0, end = 1;  ///< [s], end > start

  template <class T>
  task_reference<T> operator()(const T& t) const {
    const double span = end - start;
    task_reference<T> ref;
    const vec3<T> a = from.cast<T>(), d = (to - from).cast<T>();
    const double tv = value_of(t);
    if (!(tv > start) || !(tv < end)) {  // at rest at either end (NaN: the start)
      ref.r = tv >= end ? vec3<T>(to.cast<T>()) : a;
      ref.rd.setZero();
      ref.rdd.setZero();
      return ref;
    }
    const T tau = (t - T(start)) / T(span), t2 = tau * tau, t3 = t2 * tau;
    const T s = t3 * (T(10) - T(15) * tau + T(6) * t2);
    const T sd = T(30) * t2 * (T(1) - T(2) * tau + t2) / T(span);
    const T sdd = T(60) * tau * (T(1) - T(3) * tau + T(2) * t2) / T(span * span);
    ref.r = a + s * d;
    ref.rd = sd * d;
    ref.rdd = sdd * d;
    return ref;
  }
};

/// The cubic spline through (t_k, y_k), k = 0…K (y_k ∈ R^d, one row each), with zero
/// velocity at t₀ and t_K ("clamped"): C² inside, y(t) = y₀ before t₀ and y_K after t_K
/// (continuous in y and y' there; y'' steps from 0 to M₀ at t₀ and from M_K to 0 at t_K).
/// With h_k = t_{k+1} − t_k and M_k = y''(t_k) (Burden & Faires, Alg. 3.5):
///
///     h_{k−1} M_{k−1} + 2(h_{k−1} + h_k) M_k + h_k M_{k+1} = 6(Δ_k − Δ_{k−1}),  Δ_k = (y_{k+1} − y_k)/h_k
///     2h₀ M₀ + h₀ M₁ = 6Δ₀,   h_{K−1} M_{K−1} + 2h_{K−1} M_K = −6Δ_{K−1}
class cubic_spline {
 public:
  cubic_spline() = default;
  /// times: strictly increasing, at least 2; values: one row per time. `what` names the
  /// reference in errors.
  cubic_spline(std::vector<double> times, Eigen::MatrixXd values, const std::string& what = "spline")
      : t_(std::move(times)), y_(std::move(values)) {
    const int K = int(t_.size()) - 1;
    if (K < 1) throw input_error(what + ": needs at least 2 waypoints");
    if (y_.rows() != K + 1) throw input_error(what + ": " + std::to_string(t_.size()) + " times for " + std::to_string(y_.rows()) + " waypoints");
    for (int k = 0; k <= K; ++k) {
      if (!std::isfinite(t_[std::size_t(k)])) throw input_error(what + ": time " + std::to_string(k) + " is not finite");
      if (k > 0 && !(t_[std::size_t(k)] > t_[std::size_t(k - 1)]))
        throw input_error(what + ": times must increase strictly (time " + std::to_string(k) + ")");
    }
    if (!y_.allFinite()) throw input_error(what + ": a waypoint is not finite");
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(K + 1, K + 1), b(K + 1, y_.cols());
    const auto h = [&](int k) { return t_[std::size_t(k + 1)] - t_[std::size_t(k)]; };
    const auto delta = [&](int k) { return Eigen::RowVectorXd((y_.row(k + 1) - y_.row(k)) / h(k)); };
    A(0, 0) = 2 * h(0), A(0, 1) = h(0), b.row(0) = 6 * delta(0);
    for (int k = 1; k < K; ++k) {
      A(k, k - 1) = h(k - 1), A(k, k) = 2 * (h(k - 1) + h(k)), A(k, k + 1) = h(k);
      b.row(k) = 6 * (delta(k) - delta(k - 1));
    }
    A(K, K - 1) = h(K - 1), A(K, K) = 2 * h(K - 1), b.row(K) = -6 * delta(K - 1);
    M_ = A.partialPivLu().solve(b);  // diagonally dominant: well conditioned
  }

  int dimension() const { return int(y_.cols()); }
  double start() const { return t_.front(); }
  double end() const { return t_.back(); }

  /// y, y', y'' at t.
  template <class T>
  void operator()(const T& t, vecN<T, dynamic>& y, vecN<T, dynamic>& yd, vecN<T, dynamic>& ydd) const {
    const int d = dimension(), K = int(t_.size()) - 1;
    const double tv = value_of(t);
    yd = vecN<T, dynamic>::Zero(d);
    ydd = vecN<T, dynamic>::Zero(d);
    if (!(tv > t_.front()) || !(tv < t_.back())) {
      y = (tv >= t_.back() ? y_.row(K) : y_.row(0)).transpose().template cast<T>();
      return;
    }
    const int k = int(std::upper_bound(t_.begin(), t_.end(), tv) - t_.begin()) - 1;
    const double h = t_[std::size_t(k + 1)] - t_[std::size_t(k)];
    const T a = (T(t_[std::size_t(k + 1)]) - t) / T(h), b = (t - T(t_[std::size_t(k)])) / T(h);
    y.resize(d);
    for (int j = 0; j < d; ++j) {
      const double y0 = y_(k, j), y1 = y_(k + 1, j), m0 = M_(k, j), m1 = M_(k + 1, j);
      y(j) = a * T(y0) + b * T(y1) + ((a * a * a - a) * T(m0) + (b * b * b - b) * T(m1)) * T(h * h / 6);
      yd(j) = T((y1 - y0) / h) - (T(3) * a * a - T(1)) * T(h * m0 / 6) + (T(3) * b * b - T(1)) * T(h * m1 / 6);
      ydd(j) = a * T(m0) + b * T(m1);
    }
  }

 private:
  std::vector<double> t_;
  Eigen::MatrixXd y_, M_;  // waypoints and second derivatives, one row per time
};

/// r_d through task-space waypoints (one row of `points` per time): cubic_spline, d = 3.
struct spline_reference {
  cubic_spline spline;
  spline_reference() = default;
  spline_reference(std::vector<double> times, Eigen::MatrixXd points)
      : spline(std::move(times), std::move(points), "spline reference") {
    if (spline.dimension() != 3) throw input_error("spline reference: waypoints are points (3 numbers each)");
  }
  template <class T>
  task_reference<T> operator()(const T& t) const {
    vecN<T, dynamic> y, yd, ydd;
    spline(t, y, yd, ydd);
    task_reference<T> ref;
    ref.r = y, ref.rd = yd, ref.rdd = ydd;
    return ref;
  }
};

/// q_d through joint-space waypoints (one row of `q` per time, n columns): cubic_spline per
/// joint. Its task image needs the model's kinematics: scene_reference supplies it.
struct joint_spline_reference {
  cubic_spline spline;
  joint_spline_reference() = default;
  joint_spline_reference(std::vector<double> times, Eigen::MatrixXd q)
      : spline(std::move(times), std::move(q), "joint spline reference") {}
  int dof() const { return spline.dimension(); }
};

/// A scene's reference, as data.
using reference_spec = std::variant<circle_reference, line_reference, spline_reference, joint_spline_reference>;

/// Whether the reference gives q_d (a joint-space controller needs one).
inline bool is_joint_space(const reference_spec& r) { return std::holds_alternative<joint_spline_reference>(r); }

/// The reference a closed loop evaluates: `spec`'s r_d(t) (and q_d(t)); for a joint spline the
/// task image of q_d is the point `point` on body `body` of the kinematics `kin` (the
/// controller's model). Both are kept by reference: they must outlive this object.
template <class Kin>
class scene_reference {
 public:
  scene_reference(const reference_spec& spec, const Kin& kin, int body, const vec3<double>& point)
      : spec_(&spec), kin_(&kin), body_(body), point_(point) {
    if (const auto* l = std::get_if<line_reference>(&spec); l && !(l->end > l->start))
      throw input_error("line reference: end must be later than start");
  }
  scene_reference(reference_spec&&, const Kin&, int, const vec3<double>&) = delete;  // would dangle
  scene_reference(const reference_spec&, const Kin&&, int, const vec3<double>&) = delete;

  template <class T>
  task_reference<T> operator()(const T& t) const {
    if (const auto* j = std::get_if<joint_spline_reference>(spec_)) {
      task_reference<T> ref;
      j->spline(t, ref.q, ref.qd, ref.qdd);
      return with_task_image(std::move(ref));
    }
    return std::visit(
        [&](const auto& r) -> task_reference<T> {
          if constexpr (std::is_same_v<std::decay_t<decltype(r)>, joint_spline_reference>) return {};
          else return r(t);
        },
        *spec_);
  }

 private:
  template <class T>
  task_reference<T> with_task_image(task_reference<T> ref) const {
    const auto J = kin_->jacobian(ref.q, body_, point_);
    ref.r = kin_->point(ref.q, body_, point_);
    ref.rd = J.template topRows<3>() * ref.qd;
    ref.rdd = J.template topRows<3>() * ref.qdd + kin_->jdot_qdot(ref.q, ref.qd, body_, point_).linear;
    return ref;
  }
  const reference_spec* spec_;
  const Kin* kin_;
  int body_;
  vec3<double> point_;
};

}  // namespace nhdyn
