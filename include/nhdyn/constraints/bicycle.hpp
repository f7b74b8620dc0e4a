#pragma once
/// \file constraints/bicycle.hpp
/// `bicycle`: a car-like (Ackermann, single-track) planar base: a rear axle at the base
/// frame's origin and a steered front wheel, neither slipping sideways (k = 2).
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "../errors.hpp"
#include "../model/dh_kernel.hpp"
#include "concept.hpp"

namespace nhdyn {

/// The bicycle (single-track) model of a car-like base (docs/theory.md, "Constraints from the
/// geometry").
///
/// q holds the base pose (x, y, ψ) — joints `x`, `y` translate the base frame's origin (the
/// rear axle's centre) along the world x and y axes, joint `heading` turns it about world z
/// by ψ = q_heading — and the steering angle δ = steer_sign·q_steer of the front wheel,
/// `wheelbase` L ahead on the base frame's x axis. Neither axle slips sideways:
///
///     rear:   −sin ψ ẋ + cos ψ ẏ = 0
///     front:  −sin δ (cos ψ ẋ + sin ψ ẏ) + L cos δ ψ̇ = 0          (the rows of A)
///
/// η = (v, q̇_steer, q̇_j of every other joint j in q order), v the forward speed of the rear
/// axle: ẋ = v cos ψ, ẏ = v sin ψ, ψ̇ = v tan δ / L. The actuators: a traction force along the
/// base's forward axis at the rear axle (τ_v, in N), the steering torque and the other joints'
/// own; SᵀE = I, so τ = Sᵀ v. S is unbounded at δ = ±90° (the rear axle cannot move): S
/// refuses |cos δ| < 1e-9.
template <class Sc = double, int N = dynamic>
struct bicycle {
  static constexpr int n_at_compile_time = N;
  static constexpr int k_at_compile_time = N == dynamic ? dynamic : 2;
  static constexpr int m_at_compile_time = N == dynamic ? dynamic : N - 2;
  static constexpr bool orthonormal_S = false;
  static constexpr bool StE_identity = true;  // E = S with the v column's ψ entry dropped: SᵀE = I
  using scalar_type = Sc;

  int n = N == dynamic ? 0 : N;
  int x = 0, y = 1, heading = 2;
  int steer = 3;
  Sc wheelbase{0};     ///< L [m]
  Sc steer_sign{1};    ///< δ = steer_sign·q_steer (±1)

  bicycle() = default;
  bicycle(int n_joints, int steer_joint, Sc L, Sc sign = Sc(1), int x_joint = 0, int y_joint = 1, int heading_joint = 2)
      : n(n_joints), x(x_joint), y(y_joint), heading(heading_joint), steer(steer_joint), wheelbase(L),
        steer_sign(sign) {
    validate();
  }

  void validate() const {
    std::ostringstream os;
    if (N != dynamic && n != N) os << "bicycle: n = " << n << " but the model has " << N << "; ";
    for (int j : {x, y, heading, steer})
      if (j < 0 || j >= n) os << "bicycle: joint index " << j << " outside 0…" << n - 1 << "; ";
    const int js[4] = {x, y, heading, steer};
    for (int i = 0; i < 4; ++i)
      for (int k = i + 1; k < 4; ++k)
        if (js[i] == js[k]) os << "bicycle: x, y, heading and steer joints must differ (joint " << js[i] << " twice); ";
    const double L = value_of(wheelbase);
    if (!(std::isfinite(L) && L > 0)) os << "bicycle: the wheelbase must be positive and finite, not " << L << "; ";
    if (value_of(steer_sign) != 1.0 && value_of(steer_sign) != -1.0)
      os << "bicycle: steer_sign must be +1 or −1, not " << value_of(steer_sign) << "; ";
    if (!os.str().empty()) throw model_error(os.str().substr(0, os.str().size() - 2));
  }

  int dof() const { return n; }
  int k() const { return 2; }
  int m() const { return n - 2; }
  /// A, S, Ṡ depend on the heading and steering joints only.
  bool depends_on(int j) const { return j == heading || j == steer; }
  bool is_base_or_steer(int j) const { return j == x || j == y || j == heading || j == steer; }

  /// sin/cos of δ, refusing δ within 1e-9 (in cos δ) of ±90°, where S is unbounded.
  template <class T>
  detail::sin_cos<T> steering(const T& qs) const {
    const auto d = detail::sincos_of(T(steer_sign * qs));
    if (!(std::abs(value_of(d.c)) >= 1e-9)) {
      std::ostringstream os;
      os << "bicycle: the steering angle " << value_of(qs) << " rad (joint " << steer
         << ") is at ±90°: the rear axle cannot move and ψ̇ = v tan δ / L is unbounded";
      throw numerical_error(os.str());
    }
    return d;
  }

  /// Names of η's entries from the joints' names (q order): "v", the steering joint's, the others'.
  std::vector<std::string> eta_names(const std::vector<std::string>& joints) const {
    std::vector<std::string> out{"v", joints.at(std::size_t(steer))};
    for (int j = 0; j < n; ++j)
      if (!is_base_or_steer(j)) out.push_back(joints.at(std::size_t(j)));
    return out;
  }

  template <class Q>
  auto A(const Eigen::MatrixBase<Q>& q) const {
    return detail::A_by_A_into(*this, q);
  }
  /// A(q) into a (resized to 2 × n: no allocation once it has that size).
  template <class Q, class Am>
  void A_into(const Eigen::MatrixBase<Q>& q, Eigen::PlainObjectBase<Am>& a) const {
    using T = typename Am::Scalar;
    const auto p = detail::sincos_of(T(q(heading)));
    const auto d = detail::sincos_of(T(steer_sign * T(q(steer))));
    a.setZero(2, n);
    a(0, x) = -p.s;
    a(0, y) = p.c;
    a(1, x) = -d.s * p.c;
    a(1, y) = -d.s * p.s;
    a(1, heading) = T(wheelbase) * d.c;
  }
  /// S(q), filled directly (one sin/cos of ψ and of δ; the layout of S_times).
  template <class Q>
  auto S(const Eigen::MatrixBase<Q>& q) const {
    return detail::S_by_S_into(*this, q);
  }
  /// S(q) into s (n × m), which holds zeros or S at another q: only the entries that can be
  /// nonzero are written (no allocation, no zeroing; `has_S_into`).
  template <class Q, class Sm>
  void S_into(const Eigen::MatrixBase<Q>& q, Eigen::MatrixBase<Sm>& s) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    const auto p = detail::sincos_of(T(q(heading)));
    const auto d = steering(T(q(steer)));
    s(x, 0) = p.c;
    s(y, 0) = p.s;
    s(heading, 0) = d.s / (T(wheelbase) * d.c);
    s(steer, 1) = T(1);
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_steer(j)) s(j, c++) = T(1);
  }
  template <class Q, class QD>
  auto Sdot(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename QD::Scalar>;
    return detail::columns_of<T, N, m_at_compile_time>(n, n - 2, [&](const auto& e) { return Sdot_times(q, qd, e); });
  }
  /// The input map: the traction force along (cos ψ, sin ψ) in the x, y rows, unit columns
  /// at the steering joint and every other joint (η's order).
  template <class Q>
  auto E(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    const auto p = detail::sincos_of(T(q(heading)));
    matrix<T, N, m_at_compile_time> e = matrix<T, N, m_at_compile_time>::Zero(n, n - 2);
    e(x, 0) = p.c;
    e(y, 0) = p.s;
    e(steer, 1) = T(1);
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_steer(j)) e(j, c++) = T(1);
    return e;
  }
  /// E τ into out (n entries) without forming E: the traction along (cos ψ, sin ψ), τ at the
  /// steering joint and the other joints.
  template <class Q, class Tau, class Out>
  void E_times_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Tau>& tau, Eigen::MatrixBase<Out>& out) const {
    using T = typename Out::Scalar;
    detail::check_size(tau, n - 2, "tau");
    detail::check_size(out, n, "E tau");
    const auto p = detail::sincos_of(T(q(heading)));
    out.setZero();
    out(x) = p.c * T(tau(0));
    out(y) = p.s * T(tau(0));
    out(steer) = T(tau(1));
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_steer(j)) out(j) = T(tau(c++));
  }
  /// q̇ = S(q) η without forming S.
  template <class Q, class Et>
  auto S_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Et>& eta) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename Et::Scalar>;
    const auto p = detail::sincos_of(T(q(heading)));
    const auto d = steering(T(q(steer)));
    const T v = T(eta(0));
    vecN<T, N> qd(n);
    qd(x) = p.c * v;
    qd(y) = p.s * v;
    qd(heading) = v * d.s / (T(wheelbase) * d.c);
    qd(steer) = T(eta(1));
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_steer(j)) qd(j) = T(eta(c++));
    return qd;
  }
  /// Sᵀ v without forming S.
  template <class Q, class V>
  auto St_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) const {
    vecN<promote_t<promote_t<Sc, typename Q::Scalar>, typename V::Scalar>, m_at_compile_time> out(n - 2);
    St_times_into(q, v, out);
    return out;
  }
  /// The same into out (m entries, of the promoted scalar; a vector or a map): no allocation.
  template <class Q, class V, class Out>
  void St_times_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, Eigen::MatrixBase<Out>& out) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename V::Scalar>;
    static_assert(std::is_same_v<typename Out::Scalar, T>, "out's scalar is the promoted scalar of q and v");
    const auto p = detail::sincos_of(T(q(heading)));
    const auto d = steering(T(q(steer)));
    out(0) = p.c * T(v(x)) + p.s * T(v(y)) + T(v(heading)) * d.s / (T(wheelbase) * d.c);
    out(1) = T(v(steer));
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_steer(j)) out(c++) = T(v(j));
  }
  /// Ṡ(q, q̇) η: only the v column moves: d/dt (cos ψ, sin ψ, tan δ / L) =
  /// (−sin ψ ψ̇, cos ψ ψ̇, δ̇ / (L cos² δ)), δ̇ = steer_sign·q̇_steer.
  template <class Q, class QD, class Et>
  auto Sdot_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<Et>& eta) const {
    using T = promote_t<promote_t<promote_t<Sc, typename Q::Scalar>, typename QD::Scalar>, typename Et::Scalar>;
    const auto p = detail::sincos_of(T(q(heading)));
    const auto d = steering(T(q(steer)));
    const T v = T(eta(0)), w = T(qd(heading)), dd = T(steer_sign * T(qd(steer)));
    vecN<T, N> out = vecN<T, N>::Zero(n);
    out(x) = -p.s * w * v;
    out(y) = p.c * w * v;
    out(heading) = v * dd / (T(wheelbase) * d.c * d.c);
    return out;
  }

  /// (q̇, q̈) = (S η, S η̇ + Ṡ η) in one pass with one sin/cos each of ψ and δ, into qd and
  /// qdd (n entries each): the lift's work (constraints/stages.hpp uses it when present).
  template <class Q, class Et, class ED, class QDo, class QDDo, class T = typename QDo::Scalar>
    requires std::is_same_v<T, typename QDDo::Scalar>
  detail::sin_cos<T> lift_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Et>& eta,
                               const Eigen::MatrixBase<ED>& eta_dot, Eigen::MatrixBase<QDo>& qd,
                               Eigen::MatrixBase<QDDo>& qdd) const {
    const auto p = detail::sincos_of(T(q(heading)));
    const auto d = steering(T(q(steer)));
    const T v = T(eta(0)), vd = T(eta_dot(0)), L = T(wheelbase);
    const T t = d.s / (L * d.c);  // tan δ / L
    const T w = v * t;              // ψ̇
    const T dd = T(steer_sign * T(eta(1)));
    qd(x) = p.c * v;
    qd(y) = p.s * v;
    qd(heading) = w;
    qd(steer) = T(eta(1));
    qdd(x) = p.c * vd - p.s * w * v;
    qdd(y) = p.s * vd + p.c * w * v;
    qdd(heading) = vd * t + v * dd / (L * d.c * d.c);
    qdd(steer) = T(eta_dot(1));
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_steer(j)) {
        qd(j) = T(eta(c));
        qdd(j) = T(eta_dot(c));
        ++c;
      }
    return p;
  }

  template <class U>
  bicycle<U, N> cast() const {
    bicycle<U, N> b;
    b.n = n;
    b.x = x;
    b.y = y;
    b.heading = heading;
    b.steer = steer;
    b.wheelbase = U(wheelbase);
    b.steer_sign = U(steer_sign);
    return b;
  }
};

}  // namespace nhdyn
