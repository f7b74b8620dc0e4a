#pragma once
/// \file constraints/rolling_wheels.hpp
/// `rolling_wheels`: a planar base on two drive wheels whose angles are coordinates of the
/// model; no lateral slip at the wheel axle, and each wheel rolls without slipping (k = 3).
#include <sstream>
#include <string>
#include <vector>

#include "../model/dh_kernel.hpp"
#include "concept.hpp"

namespace nhdyn {

/// Two drive wheels on a planar base (docs/theory.md, "Constraints from the geometry").
///
/// q holds the base pose (x, y, ψ) — joints `x`, `y` translate the base frame's origin along
/// the world x and y axes, joint `heading` turns it about world z by ψ = q_heading — and the
/// wheel angles φ_L = q_left, φ_R = q_right. In the base frame the wheel centres are at
/// (axle_x, left_y) and (axle_x, right_y) (a common axle, left_y ≠ right_y), the spin axes
/// along ±y (spin signs s_L, s_R: +1 when the joint axis is +y). With the base frame's
/// forward speed u = cos ψ ẋ + sin ψ ẏ and yaw rate ω = ψ̇:
///
///     lateral no-slip at the axle:  −sin ψ ẋ + cos ψ ẏ + axle_x ω = 0
///     left wheel rolls:             u − left_y ω − r s_L φ̇_L = 0
///     right wheel rolls:            u − right_y ω − r s_R φ̇_R = 0          (the rows of A)
///
/// η = (φ̇_L, φ̇_R, q̇_j of every other joint j in q order): the wheel rates fix the base's
/// motion, ω = r (s_R φ̇_R − s_L φ̇_L) / (left_y − right_y), u = r s_L φ̇_L + left_y ω, lateral
/// speed −axle_x ω. The actuators are the wheel torques and the other joints' own: E selects
/// the rows of the joints whose rates η holds, so SᵀE = I and τ = Sᵀ v.
template <class Sc = double, int N = dynamic>
struct rolling_wheels {
  static constexpr int n_at_compile_time = N;
  static constexpr int k_at_compile_time = N == dynamic ? dynamic : 3;
  static constexpr int m_at_compile_time = N == dynamic ? dynamic : N - 3;
  static constexpr bool orthonormal_S = false;
  static constexpr bool StE_identity = true;  // E selects η's own joints: SᵀE = I
  using scalar_type = Sc;

  int n = N == dynamic ? 0 : N;
  int x = 0, y = 1, heading = 2;
  int left = 3, right = 4;
  Sc radius{0};                        ///< r [m]
  Sc left_y{0}, right_y{0};            ///< wheel centres' lateral positions in the base frame [m]
  Sc axle_x{0};                        ///< the axle's forward position in the base frame [m]
  Sc left_sign{1}, right_sign{1};      ///< spin signs (±1)

  rolling_wheels() = default;
  rolling_wheels(int n_joints, int left_joint, int right_joint, Sc r, Sc left_lateral, Sc right_lateral,
                 Sc axle_forward = Sc(0), Sc s_left = Sc(1), Sc s_right = Sc(1), int x_joint = 0, int y_joint = 1,
                 int heading_joint = 2)
      : n(n_joints), x(x_joint), y(y_joint), heading(heading_joint), left(left_joint), right(right_joint),
        radius(r), left_y(left_lateral), right_y(right_lateral), axle_x(axle_forward), left_sign(s_left),
        right_sign(s_right) {
    validate();
  }

  void validate() const {
    std::ostringstream os;
    if (N != dynamic && n != N) os << "rolling_wheels: n = " << n << " but the model has " << N << "; ";
    for (int j : {x, y, heading, left, right})
      if (j < 0 || j >= n) os << "rolling_wheels: joint index " << j << " outside 0…" << n - 1 << "; ";
    const int js[5] = {x, y, heading, left, right};
    for (int i = 0; i < 5; ++i)
      for (int k = i + 1; k < 5; ++k)
        if (js[i] == js[k]) os << "rolling_wheels: x, y, heading, left and right joints must differ (joint " << js[i] << " twice); ";
    const double r = value_of(radius);
    if (!(std::isfinite(r) && r > 0)) os << "rolling_wheels: the wheel radius must be positive and finite, not " << r << "; ";
    for (const Sc* s : {&left_sign, &right_sign})
      if (value_of(*s) != 1.0 && value_of(*s) != -1.0) os << "rolling_wheels: a spin sign must be +1 or −1, not " << value_of(*s) << "; ";
    if (!is_finite_scalar(left_y) || !is_finite_scalar(right_y) || !is_finite_scalar(axle_x))
      os << "rolling_wheels: a wheel position is not finite; ";
    else if (!(std::abs(value_of(left_y) - value_of(right_y)) > 0))
      os << "rolling_wheels: both wheels at lateral position " << value_of(left_y) << " m: the track is zero; ";
    if (!os.str().empty()) throw model_error(os.str().substr(0, os.str().size() - 2));
  }

  int dof() const { return n; }
  int k() const { return 3; }
  int m() const { return n - 3; }
  /// A, S, Ṡ depend on the heading joint only.
  bool depends_on(int j) const { return j == heading; }

  /// The base's body-frame motion per unit wheel rate: ω = w_L φ̇_L + w_R φ̇_R,
  /// u = u_L φ̇_L + u_R φ̇_R (forward), lateral speed l_L φ̇_L + l_R φ̇_R.
  struct wheel_map {
    Sc wL, wR, uL, uR, lL, lR;
  };
  wheel_map map() const {
    const Sc track = left_y - right_y;
    wheel_map k;
    k.wL = -radius * left_sign / track;
    k.wR = radius * right_sign / track;
    k.uL = radius * left_sign + left_y * k.wL;
    k.uR = left_y * k.wR;
    k.lL = -axle_x * k.wL;
    k.lR = -axle_x * k.wR;
    return k;
  }
  /// Whether joint j is one of the base's (x, y, heading) or a wheel: not an "other" joint.
  bool is_base_or_wheel(int j) const { return j == x || j == y || j == heading || j == left || j == right; }

  /// Names of η's entries from the joints' names (q order): the wheel joints', the others'.
  std::vector<std::string> eta_names(const std::vector<std::string>& joints) const {
    std::vector<std::string> out{joints.at(std::size_t(left)), joints.at(std::size_t(right))};
    for (int j = 0; j < n; ++j)
      if (!is_base_or_wheel(j)) out.push_back(joints.at(std::size_t(j)));
    return out;
  }

  template <class Q>
  auto A(const Eigen::MatrixBase<Q>& q) const {
    return detail::A_by_A_into(*this, q);
  }
  /// A(q) into a (resized to 3 × n: no allocation once it has that size).
  template <class Q, class Am>
  void A_into(const Eigen::MatrixBase<Q>& q, Eigen::PlainObjectBase<Am>& a) const {
    using T = typename Am::Scalar;
    const auto p = detail::sincos_of(T(q(heading)));
    a.setZero(3, n);
    a(0, x) = -p.s;
    a(0, y) = p.c;
    a(0, heading) = T(axle_x);
    for (int i = 1; i <= 2; ++i) {
      a(i, x) = p.c;
      a(i, y) = p.s;
    }
    a(1, heading) = T(-left_y);
    a(2, heading) = T(-right_y);
    a(1, left) = T(-radius * left_sign);
    a(2, right) = T(-radius * right_sign);
  }
  /// S(q), filled directly (one sin/cos of ψ; the layout of S_times).
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
    const wheel_map k = map();
    s(x, 0) = p.c * T(k.uL) - p.s * T(k.lL);
    s(y, 0) = p.s * T(k.uL) + p.c * T(k.lL);
    s(heading, 0) = T(k.wL);
    s(left, 0) = T(1);
    s(x, 1) = p.c * T(k.uR) - p.s * T(k.lR);
    s(y, 1) = p.s * T(k.uR) + p.c * T(k.lR);
    s(heading, 1) = T(k.wR);
    s(right, 1) = T(1);
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_wheel(j)) s(j, c++) = T(1);
  }
  template <class Q, class QD>
  auto Sdot(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename QD::Scalar>;
    return detail::columns_of<T, N, m_at_compile_time>(n, n - 3, [&](const auto& e) { return Sdot_times(q, qd, e); });
  }
  /// The input map: unit columns at the wheel joints and at every other joint (η's order).
  template <class Q>
  auto E(const Eigen::MatrixBase<Q>&) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    matrix<T, N, m_at_compile_time> e = matrix<T, N, m_at_compile_time>::Zero(n, n - 3);
    e(left, 0) = T(1);
    e(right, 1) = T(1);
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_wheel(j)) e(j, c++) = T(1);
    return e;
  }
  /// E τ into out (n entries) without forming E: τ at the wheel joints and the other joints.
  template <class Q, class Tau, class Out>
  void E_times_into(const Eigen::MatrixBase<Q>&, const Eigen::MatrixBase<Tau>& tau, Eigen::MatrixBase<Out>& out) const {
    using T = typename Out::Scalar;
    detail::check_size(tau, n - 3, "tau");
    detail::check_size(out, n, "E tau");
    out.setZero();
    out(left) = T(tau(0));
    out(right) = T(tau(1));
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_wheel(j)) out(j) = T(tau(c++));
  }
  /// q̇ = S(q) η without forming S.
  template <class Q, class Et>
  auto S_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Et>& eta) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename Et::Scalar>;
    const auto p = detail::sincos_of(T(q(heading)));
    const wheel_map k = map();
    const T fl = T(eta(0)), fr = T(eta(1));
    const T u = T(k.uL) * fl + T(k.uR) * fr, l = T(k.lL) * fl + T(k.lR) * fr;
    vecN<T, N> qd(n);
    qd(x) = p.c * u - p.s * l;
    qd(y) = p.s * u + p.c * l;
    qd(heading) = T(k.wL) * fl + T(k.wR) * fr;
    qd(left) = fl;
    qd(right) = fr;
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_wheel(j)) qd(j) = T(eta(c++));
    return qd;
  }
  /// Sᵀ v without forming S.
  template <class Q, class V>
  auto St_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) const {
    vecN<promote_t<promote_t<Sc, typename Q::Scalar>, typename V::Scalar>, m_at_compile_time> out(n - 3);
    St_times_into(q, v, out);
    return out;
  }
  /// The same into out (m entries, of the promoted scalar; a vector or a map): no allocation.
  template <class Q, class V, class Out>
  void St_times_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, Eigen::MatrixBase<Out>& out) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename V::Scalar>;
    static_assert(std::is_same_v<typename Out::Scalar, T>, "out's scalar is the promoted scalar of q and v");
    const auto p = detail::sincos_of(T(q(heading)));
    const wheel_map k = map();
    // v seen in the base frame: forward and lateral components of (v_x, v_y).
    const T fu = p.c * T(v(x)) + p.s * T(v(y)), fl = -p.s * T(v(x)) + p.c * T(v(y)), fw = T(v(heading));
    out(0) = T(k.uL) * fu + T(k.lL) * fl + T(k.wL) * fw + T(v(left));
    out(1) = T(k.uR) * fu + T(k.lR) * fl + T(k.wR) * fw + T(v(right));
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_wheel(j)) out(c++) = T(v(j));
  }
  /// Ṡ(q, q̇) η: only the x and y rows move (they turn with ψ, ψ̇ = q̇_heading).
  template <class Q, class QD, class Et>
  auto Sdot_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<Et>& eta) const {
    using T = promote_t<promote_t<promote_t<Sc, typename Q::Scalar>, typename QD::Scalar>, typename Et::Scalar>;
    const auto p = detail::sincos_of(T(q(heading)));
    const wheel_map k = map();
    const T fl = T(eta(0)), fr = T(eta(1)), w = T(qd(heading));
    const T u = T(k.uL) * fl + T(k.uR) * fr, l = T(k.lL) * fl + T(k.lR) * fr;
    vecN<T, N> out = vecN<T, N>::Zero(n);
    out(x) = -w * (p.s * u + p.c * l);
    out(y) = w * (p.c * u - p.s * l);
    return out;
  }

  /// (q̇, q̈) = (S η, S η̇ + Ṡ η) in one pass and one sin/cos of ψ, into qd and qdd (n
  /// entries each): the lift's work (constraints/stages.hpp uses it when a constraint has it).
  template <class Q, class Et, class ED, class QDo, class QDDo, class T = typename QDo::Scalar>
    requires std::is_same_v<T, typename QDDo::Scalar>
  detail::sin_cos<T> lift_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Et>& eta,
                               const Eigen::MatrixBase<ED>& eta_dot, Eigen::MatrixBase<QDo>& qd,
                               Eigen::MatrixBase<QDDo>& qdd) const {
    const auto p = detail::sincos_of(T(q(heading)));
    const wheel_map k = map();
    const T e0 = T(eta(0)), e1 = T(eta(1)), d0 = T(eta_dot(0)), d1 = T(eta_dot(1));
    const T u = T(k.uL) * e0 + T(k.uR) * e1, l = T(k.lL) * e0 + T(k.lR) * e1;
    const T ud = T(k.uL) * d0 + T(k.uR) * d1, ld = T(k.lL) * d0 + T(k.lR) * d1;
    const T w = T(k.wL) * e0 + T(k.wR) * e1;
    qd(x) = p.c * u - p.s * l;
    qd(y) = p.s * u + p.c * l;
    qd(heading) = w;
    qd(left) = e0;
    qd(right) = e1;
    qdd(x) = p.c * ud - p.s * ld - w * (p.s * u + p.c * l);
    qdd(y) = p.s * ud + p.c * ld + w * (p.c * u - p.s * l);
    qdd(heading) = T(k.wL) * d0 + T(k.wR) * d1;
    qdd(left) = d0;
    qdd(right) = d1;
    for (int j = 0, c = 2; j < n; ++j)
      if (!is_base_or_wheel(j)) {
        qd(j) = T(eta(c));
        qdd(j) = T(eta_dot(c));
        ++c;
      }
    return p;
  }

  template <class U>
  rolling_wheels<U, N> cast() const {
    rolling_wheels<U, N> d;
    d.n = n;
    d.x = x;
    d.y = y;
    d.heading = heading;
    d.left = left;
    d.right = right;
    d.radius = U(radius);
    d.left_y = U(left_y);
    d.right_y = U(right_y);
    d.axle_x = U(axle_x);
    d.left_sign = U(left_sign);
    d.right_sign = U(right_sign);
    return d;
  }
};

}  // namespace nhdyn
