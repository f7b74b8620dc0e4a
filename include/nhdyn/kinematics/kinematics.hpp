#pragma once
/// \file kinematics/kinematics.hpp
/// Forward kinematics of every link frame, the geometric Jacobian of a point fixed on a
/// link, and J̇q̇ (that point's velocity-product acceleration), all in frame 0.
///
///     X_0i = A_1 ⋯ A_i,  A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)              (Spong, eq. 3.10)
///     J = [J_v; J_ω] (6×n), column j ≤ i: revolute (z_{j−1} × (p − o_{j−1}); z_{j−1}),
///                                      prismatic (z_{j−1}; 0); columns j > i are zero.
///     [v; ω] = J q̇,   [a; ω̇] = J q̈ + J̇q̇
#include <vector>

#include <range/v3/numeric/partial_sum.hpp>
#include <range/v3/view/iota.hpp>
#include <range/v3/view/transform.hpp>

#include "../model/dh_kernel.hpp"
#include "../detail/small_buffer.hpp"

namespace nhdyn {

/// Pose of frame i in frame 0: R_0i (orientation), p_0i (origin o_i).
template <class T>
struct pose {
  mat3<T> R = mat3<T>::Identity();
  vec3<T> p = vec3<T>::Zero();
};

/// Linear and angular velocity-product acceleration of a point: J̇q̇ = (a, ω̇) at q̈ = 0.
template <class T>
struct point_acceleration {
  vec3<T> linear = vec3<T>::Zero();
  vec3<T> angular = vec3<T>::Zero();
};

namespace detail {
template <class T, class S>
mat3<T> dh_rotation(const dh_link<S>& k, const T& ct, const T& st) {
  mat3<T> R;
  R << ct, -st * T(k.ca), st * T(k.sa),  //
      st, ct * T(k.ca), -ct * T(k.sa),   //
      T(0), T(k.sa), T(k.ca);
  return R;
}
}  // namespace detail

template <class S, int N = dynamic>
class kinematics {
 public:
  using scalar_type = S;
  explicit kinematics(const chain<S, N>& c) : links_(detail::make_dh_links(c)), n_(c.dof()) {}
  int dof() const { return n_; }

  /// Poses of frames 0…n in frame 0 (n+1 entries; entry 0 is the identity).
  template <class Q>
  auto forward(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<S, typename Q::Scalar>;
    std::vector<pose<T>> X(static_cast<std::size_t>(n_ + 1));
    forward_into(q, X.data());
    return X;
  }
  /// …into X (n + 1 poses; X[0] is left as it is, the identity of a new pose).
  template <class Q, class T>
  void forward_into(const Eigen::MatrixBase<Q>& q, pose<T>* X) const {
    detail::check_size(q, n_, "q");
    detail::check_finite(q, "q");
    // X_0i = X_0,i−1 · A_i: an inclusive scan of the link transforms (Spong eq. 3.10).
    const auto A_i = [&](int i) {
      const auto& k = links_[std::size_t(i)];
      const auto [ct, st, d] = detail::geometry(k, T(q(i)));
      return pose<T>{detail::dh_rotation(k, ct, st), vec3<T>(T(k.a) * ct, T(k.a) * st, d)};
    };
    const auto then = [](const pose<T>& X_0a, const pose<T>& X_ab) {
      return pose<T>{X_0a.R * X_ab.R, X_0a.p + X_0a.R * X_ab.p};
    };
    ranges::partial_sum(ranges::views::iota(0, n_) | ranges::views::transform(A_i), X + 1, then);
  }

  /// Pose of frame i (0…n) in frame 0.
  template <class Q>
  auto frame(const Eigen::MatrixBase<Q>& q, int i) const {
    check_link(i, true);
    return forward(q)[std::size_t(i)];
  }

  /// Position in frame 0 of the point p_i (given in frame i) of link i (1…n; 0 = base).
  template <class Q>
  auto point(const Eigen::MatrixBase<Q>& q, int i, const vec3<S>& p_i = vec3<S>::Zero()) const {
    using T = promote_t<S, typename Q::Scalar>;
    check_point(p_i);
    const auto X = frame(q, i);
    return vec3<T>(X.p + X.R * p_i.template cast<T>());
  }

  /// Geometric Jacobian (6×n, rows v then ω, frame 0) of point p_i of link i.
  template <class Q>
  auto jacobian(const Eigen::MatrixBase<Q>& q, int i, const vec3<S>& p_i = vec3<S>::Zero()) const {
    using T = promote_t<S, typename Q::Scalar>;
    check_link(i, true);
    check_point(p_i);
    const auto X = forward(q);
    const vec3<T> p = X[std::size_t(i)].p + X[std::size_t(i)].R * p_i.template cast<T>();
    Eigen::Matrix<T, 6, N> J = Eigen::Matrix<T, 6, N>::Zero(6, n_);
    for (int j = 0; j < i; ++j) {
      const auto& Xj = X[std::size_t(j)];  // frame j−1 of joint j (0-based j)
      const vec3<T> z = Xj.R.col(2);
      if (links_[std::size_t(j)].revolute) {
        J.col(j).template head<3>() = z.cross(p - Xj.p);
        J.col(j).template tail<3>() = z;
      } else {
        J.col(j).template head<3>() = z;
      }
    }
    return J;
  }

  /// out += Σ_x J(q, x.body, x.point)ᵀ [f_x; m_x] (n entries, of the model's and q's promoted
  /// scalar or a wider one): the joint forces of forces f_x at points fixed on links and of
  /// moments m_x (the principle of virtual work). Each x of `xs` has members `body` (link
  /// 0…n; 0, the base, moves nothing), `point` (link coordinates), `force` and `moment`, given
  /// in frame 0's axes, or in link x.body's where `in_body_axes(x)`. One forward pass for all:
  /// no allocation (the frames on the stack; beyond 340 links, a block the thread keeps).
  template <class Q, class Xs, class InBody, class Out>
  void add_point_forces(const Eigen::MatrixBase<Q>& q, const Xs& xs, InBody in_body_axes, Eigen::MatrixBase<Out>& out) const {
    using TK = promote_t<S, typename Q::Scalar>;
    using T = typename Out::Scalar;
    detail::check_size(out, n_, "out");
    detail::small_buffer<pose<TK>, N == dynamic ? dynamic : N + 1> X(n_ + 1);
    forward_into(q, X.data());
    X[0] = pose<TK>{};
    for (const auto& x : xs) {
      check_link(x.body, true);
      const int i = x.body;
      if (i == 0) continue;
      const auto& Xi = X[i];
      const vec3<T> p = (Xi.p + Xi.R * x.point.template cast<TK>()).template cast<T>();
      vec3<T> f = x.force.template cast<T>(), m = x.moment.template cast<T>();
      if (in_body_axes(x)) {
        const mat3<T> R = Xi.R.template cast<T>();
        f = R * f;
        m = R * m;
      }
      for (int j = 0; j < i; ++j) {  // frame j−1 of joint j (0-based j): z · ((p − o) × f + m), or z · f
        const vec3<T> z = X[j].R.col(2).template cast<T>();
        out(j) += links_[std::size_t(j)].revolute ? T(z.dot(vec3<T>((p - X[j].p.template cast<T>()).cross(f) + m)))
                                                  : T(z.dot(f));
      }
    }
  }

  /// J̇q̇ of point p_i of link i, in frame 0: its acceleration at q̈ = 0, no gravity.
  template <class Q, class QD>
  auto jdot_qdot(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, int i,
                 const vec3<S>& p_i = vec3<S>::Zero()) const {
    using T = promote_t<S, typename Q::Scalar>;
    check_link(i, true);
    detail::check_size(q, n_, "q");
    detail::check_size(qd, n_, "qd");
    detail::check_finite(q, "q");
    detail::check_finite(qd, "qd");
    check_point(p_i);
    vec3<T> w = vec3<T>::Zero(), dw = vec3<T>::Zero(), acc = vec3<T>::Zero();  // frame j
    mat3<T> R = mat3<T>::Identity();                                          // R_0j
    for (int j = 0; j < i; ++j) {
      const auto& k = links_[std::size_t(j)];
      const auto [ct, st, d] = detail::geometry(k, T(q(j)));
      const vec3<T> p = detail::offset<T>(k, d);
      const T qdj = T(qd(j));
      if (k.revolute) {
        dw = detail::rot_T(k, ct, st, vec3<T>(dw.x() + w.y() * qdj, dw.y() - w.x() * qdj, dw.z()));
        w = detail::rot_T(k, ct, st, vec3<T>(w.x(), w.y(), w.z() + qdj));
        acc = detail::rot_T(k, ct, st, acc) + dw.cross(p) + w.cross(w.cross(p));
      } else {
        const vec3<T> z = detail::axis<T>(k);
        w = detail::rot_T(k, ct, st, w);
        dw = detail::rot_T(k, ct, st, dw);
        acc = detail::rot_T(k, ct, st, acc) + dw.cross(p) + w.cross(w.cross(p)) + T(2) * qdj * w.cross(z);
      }
      R = R * detail::dh_rotation(k, ct, st);
    }
    const vec3<T> r = p_i.template cast<T>();
    point_acceleration<T> out;
    out.linear = R * vec3<T>(acc + dw.cross(r) + w.cross(w.cross(r)));
    out.angular = R * dw;
    return out;
  }

 private:
  static void check_point(const vec3<S>& p_i) {
    for (int r = 0; r < 3; ++r)
      if (!is_finite_scalar(p_i(r))) detail::throw_not_finite("p_i", r, value_of(p_i(r)));
  }
  void check_link(int i, bool allow_base) const {
    if (i < (allow_base ? 0 : 1) || i > n_)
      throw input_error("link index " + std::to_string(i) + " is outside 0…" + std::to_string(n_));
  }
  typename detail::dh_links<S, N>::type links_;
  int n_;
};

}  // namespace nhdyn
