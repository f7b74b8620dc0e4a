#pragma once
/// \file constraints/differential_drive.hpp
/// `differential_drive`: a planar base that cannot slip sideways, on any x, y, heading triple
/// of joints of a chain or tree.
#include <sstream>
#include <string>
#include <vector>

#include "../model/dh_kernel.hpp"
#include "concept.hpp"

namespace nhdyn {

/// A differential-drive (unicycle) base: the base point moves only along its forward axis.
/// Joints x and y translate the base point along two orthogonal ground axes; joint
/// `heading` turns it. With ψ = heading_sign·q_h + forward_offset the forward axis is
/// (cos ψ, sin ψ) in (x, y), and
///
///     A = −sin ψ at x, cos ψ at y;     η = (v, q̇_j for every other joint j, in order),
///
/// v (the forward speed) standing in the place of the first of x, y. paper5:
/// x = 0 (q₁), y = 1 (q₂), heading = 2, heading_sign = −1, forward_offset = 0.
template <class Sc = double, int N = dynamic>
struct differential_drive {
  static constexpr int n_at_compile_time = N;
  static constexpr int k_at_compile_time = N == dynamic ? dynamic : 1;
  static constexpr int m_at_compile_time = N == dynamic ? dynamic : N - 1;
  static constexpr bool orthonormal_S = true;  // SᵀS = I
  using scalar_type = Sc;

  int n = N == dynamic ? 0 : N;
  int x = 0, y = 1, heading = 2;
  Sc forward_offset{0};
  Sc heading_sign{1};

  differential_drive() = default;
  differential_drive(int n_joints, int x_joint, int y_joint, int heading_joint, Sc offset = Sc(0),
                     Sc sign = Sc(1))
      : n(n_joints), x(x_joint), y(y_joint), heading(heading_joint), forward_offset(offset),
        heading_sign(sign) {
    validate();
  }

  void validate() const {
    std::ostringstream os;  // every flaw, each ending "; "
    if (N != dynamic && n != N) os << "differential_drive: n = " << n << " but the chain has " << N << "; ";
    for (int j : {x, y, heading})
      if (j < 0 || j >= n) os << "differential_drive: joint index " << j << " outside 0…" << n - 1 << "; ";
    if (x == y || x == heading || y == heading)
      os << "differential_drive: x, y and heading joints must differ (" << x << ", " << y << ", "
         << heading << "); ";
    const double s = value_of(heading_sign);
    if (s != 1.0 && s != -1.0) os << "differential_drive: heading_sign must be +1 or −1, not " << s << "; ";
    if (!is_finite_scalar(forward_offset)) os << "differential_drive: forward_offset is not finite; ";
    if (!os.str().empty()) throw model_error(os.str().substr(0, os.str().size() - 2));
  }

  int dof() const { return n; }
  int k() const { return 1; }
  int m() const { return n - 1; }
  int v_slot() const { return std::min(x, y); }
  /// A, S, Ṡ depend on the heading joint only.
  bool depends_on(int j) const { return j == heading; }

  /// cos ψ, sin ψ of the heading ψ = heading_sign·q_h + forward_offset, as the exact sum: for
  /// a floating-point T the rounding error of the sum is recovered (TwoSum) and (cos, sin) are
  /// turned by it, as for a joint's θ⁰ + q (model/dh_kernel.hpp); with offset 0 nothing is done.
  template <class T>
  detail::sin_cos<T> sincos_psi(const T& qh) const {
    return detail::sincos_of_sum(heading_angle(qh));
  }
  /// ψ as the sum (heading_sign·q_h, forward_offset) whose sin/cos sincos_psi takes.
  template <class T>
  detail::angle_sum<T> heading_angle(const T& qh) const {
    return {T(heading_sign * qh), T(forward_offset)};  // heading_sign = ±1: exact
  }

  /// Names of η's entries from the joints' names (q order): "v" in the place of the first of
  /// x, y; "omega" for the heading joint's rate when it is the yaw rate (heading_sign +1),
  /// else the joint's name; the other joints' names.
  std::vector<std::string> eta_names(const std::vector<std::string>& joints) const {
    std::vector<std::string> out;
    for (int j = 0; j < n; ++j) {
      if (j == std::max(x, y)) continue;
      const bool omega = j == heading && value_of(heading_sign) == 1.0;
      out.push_back(j == std::min(x, y) ? "v" : omega ? "omega" : joints.at(std::size_t(j)));
    }
    return out;
  }

  template <class Q>
  auto A(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    using std::cos;
    using std::sin;
    const auto p = sincos_psi(T(q(heading)));
    matrix<T, k_at_compile_time, N> a = matrix<T, k_at_compile_time, N>::Zero(1, n);
    a(0, x) = -p.s;
    a(0, y) = p.c;
    return a;
  }
  /// S(q): the column of v is (cos ψ, sin ψ) in the x and y rows; every other joint has its
  /// own unit column (the same layout as S_times, with one sin/cos of ψ).
  template <class Q>
  auto S(const Eigen::MatrixBase<Q>& q) const {
    return detail::S_by_S_into(*this, q);
  }
  /// S(q) into s (n × m), which holds zeros or S at another q: only the entries that can be
  /// nonzero are written (no allocation, no zeroing; `has_S_into`).
  template <class Q, class Sm>
  void S_into(const Eigen::MatrixBase<Q>& q, Eigen::MatrixBase<Sm>& s) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    const auto p = sincos_psi(T(q(heading)));
    const int lo = std::min(x, y), hi = std::max(x, y);
    int c = 0;
    for (int j = 0; j < n; ++j) {
      if (j == lo) {
        s(x, c) = p.c;
        s(y, c) = p.s;
        ++c;
      } else if (j != hi) {
        s(j, c++) = T(1);
      }
    }
  }
  template <class Q, class QD>
  auto Sdot(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename QD::Scalar>;
    return detail::columns_of<T, N, m_at_compile_time>(n, n - 1, [&](const auto& e) { return Sdot_times(q, qd, e); });
  }
  /// q̇ = S(q) η without forming S.
  template <class Q, class E>
  auto S_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename E::Scalar>;
    using std::cos;
    using std::sin;
    vecN<T, N> qd(n);
    const int lo = std::min(x, y), hi = std::max(x, y);
    int c = 0;
    for (int j = 0; j < n; ++j) {
      if (j == lo) {
        const auto p = sincos_psi(T(q(heading)));
        const T v = T(eta(c++));
        qd(x) = p.c * v;
        qd(y) = p.s * v;
      } else if (j != hi) {
        qd(j) = T(eta(c++));
      }
    }
    return qd;
  }
  /// A v without forming A (k = 1: −sin ψ v_x + cos ψ v_y). A's one row has unit length
  /// (AAᵀ = 1), so for E = S the constraint force is λ = A v (stages.hpp).
  template <class Q, class V>
  auto A_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) const {
    vecN<promote_t<promote_t<Sc, typename Q::Scalar>, typename V::Scalar>, k_at_compile_time> out;
    A_times_into(q, v, out);
    return out;
  }
  /// A v into out (resized to 1).
  template <class Q, class V, class Out>
  void A_times_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, Eigen::PlainObjectBase<Out>& out) const {
    using T = typename Out::Scalar;
    const auto p = sincos_psi(T(q(heading)));
    out.resize(1);
    out(0) = p.c * T(v(y)) - p.s * T(v(x));
  }
  /// Sᵀ v without forming S.
  template <class Q, class V>
  auto St_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename V::Scalar>;
    using std::cos;
    using std::sin;
    vecN<T, m_at_compile_time> out(n - 1);
    const int lo = std::min(x, y), hi = std::max(x, y);
    int c = 0;
    for (int j = 0; j < n; ++j) {
      if (j == lo) {
        const auto p = sincos_psi(T(q(heading)));
        out(c++) = p.c * T(v(x)) + p.s * T(v(y));
      } else if (j != hi) {
        out(c++) = T(v(j));
      }
    }
    return out;
  }
  /// Sᵀ v written over v's own storage (v's first m entries, then v shrinks to m): the
  /// projection of a temporary v allocates nothing. Sᵀv's entry c reads v's entries ≥ c only.
  template <class Q, class T>
  auto St_times_in_place(const Eigen::MatrixBase<Q>& q, vecN<T, N>&& v) const {
    return St_times_in_place(q, std::move(v), sincos_psi(T(q(heading))));
  }
  /// The same with sin/cos of ψ already known (the memo of lift_into).
  template <class Q, class T>
  vecN<T, m_at_compile_time> St_times_in_place(const Eigen::MatrixBase<Q>&, vecN<T, N>&& v,
                                               const detail::sin_cos<T>& p) const {
    if constexpr (N == dynamic) {
      St_times_into(v, p, v);
      v.conservativeResize(n - 1);
      return std::move(v);
    } else {
      // Fixed size: written straight into the (elided) result; compacting v and copying its
      // head would read back just-written scalars as a vector (a store-forwarding stall).
      return St_times(v, p);
    }
  }
  /// Sᵀv into a new vector of m entries, with sin/cos of ψ known (v: any Eigen vector of n).
  template <class V, class T>
  vecN<T, m_at_compile_time> St_times(const Eigen::MatrixBase<V>& v, const detail::sin_cos<T>& p) const {
    vecN<T, m_at_compile_time> out;
    out.resize(n - 1);
    St_times_into(v, p, out);
    return out;
  }
  /// Sᵀv into the first m entries of out, which may be v itself: entry c is written after
  /// every entry ≥ c it needs has been read (c ≤ j, and v(x), v(y) are read at j = min(x, y)).
  template <class V, class T, class Out>
  void St_times_into(const Eigen::MatrixBase<V>& v, const detail::sin_cos<T>& p, Eigen::MatrixBase<Out>& out) const {
    const int lo = std::min(x, y), hi = std::max(x, y);
    int c = 0;
    for (int j = 0; j < n; ++j) {
      if (j == lo)
        out(c++) = p.c * v(x) + p.s * v(y);
      else if (j != hi)
        out(c++) = v(j);
    }
  }
  /// Sᵀ M S for a symmetric n×n M (the reduced inertia M_η from the joint-space M), in O(n²)
  /// with one sin/cos of ψ: M's rows and columns with the y joint's folded into the x joint's
  /// as the v row/column (cos ψ·M_x + sin ψ·M_y), every other joint's copied.
  template <class Q, class MM>
  auto St_M_S(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<MM>& M) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename MM::Scalar>;
    const auto p = sincos_psi(T(q(heading)));
    const int lo = std::min(x, y), hi = std::max(x, y);
    // M's row (or column, M = Mᵀ) of joint j, seen from the v direction: cos ψ M_xj + sin ψ M_yj.
    const auto v_row = [&](int j) { return T(p.c * M(x, j) + p.s * M(y, j)); };
    matrix<T, m_at_compile_time, m_at_compile_time> out(n - 1, n - 1);
    for (int i = 0, ci = 0; i < n; ++i) {
      if (i == hi) continue;
      for (int j = 0, cj = 0; j <= i; ++j) {
        if (j == hi) continue;
        T e;
        if (i == lo && j == lo)
          e = T(p.c * v_row(x) + p.s * v_row(y));
        else if (i == lo)
          e = v_row(j);
        else if (j == lo)
          e = v_row(i);
        else
          e = T(M(i, j));
        out(ci, cj) = e;
        out(cj, ci) = e;
        ++cj;
      }
      ++ci;
    }
    return out;
  }
  /// (q̇, q̈) = (S η, S η̇ + Ṡ η) in one pass and one sin/cos of ψ, written into qd and qdd
  /// (n entries each): the lift's work (constraints/stages.hpp uses it when a constraint has
  /// it). Returns sin/cos of ψ, which rides along with ξ as a memo for the projection
  /// (St_times_in_place). qd and qdd: any writable Eigen vectors of n entries of one scalar.
  template <class Q, class E, class ED, class QDo, class QDDo, class T = typename QDo::Scalar>
    requires std::is_same_v<T, typename QDDo::Scalar>
  detail::sin_cos<T> lift_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta,
                               const Eigen::MatrixBase<ED>& eta_dot, Eigen::MatrixBase<QDo>& qd,
                               Eigen::MatrixBase<QDDo>& qdd) const {
    return lift_into(eta, eta_dot, qd, qdd, sincos_psi(T(q(heading))));
  }
  /// The angle whose sin/cos lift_into needs (ψ), for a caller that has it computed with
  /// others (inverse_dynamics: with rne's joint angles), and lift_into with that sin/cos.
  /// lift_angle_form: ψ = sign·q_j + offset for joint j (when the chain's θ_j = θ⁰_j + q_j
  /// has θ⁰_j·sign = offset, ψ = sign·θ_j and its sin/cos are the joint's own).
  template <class T, class Q>
  detail::angle_sum<T> lift_angle(const Eigen::MatrixBase<Q>& q) const {
    return heading_angle(T(q(heading)));
  }
  detail::joint_angle_form<Sc> lift_angle_form() const { return {heading, heading_sign, forward_offset}; }
  template <class E, class ED, class QDo, class QDDo, class T = typename QDo::Scalar>
    requires std::is_same_v<T, typename QDDo::Scalar>
  detail::sin_cos<T> lift_into(const Eigen::MatrixBase<E>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                               Eigen::MatrixBase<QDo>& qd, Eigen::MatrixBase<QDDo>& qdd,
                               const detail::sin_cos<T>& p) const {
    const int lo = std::min(x, y), hi = std::max(x, y);
    for (int j = 0, c = 0; j < n; ++j)
      if (j != lo && j != hi) {
        qd(j) = T(eta(c));
        qdd(j) = T(eta_dot(c));
        ++c;
      } else if (j == lo) {
        ++c;
      }
    const T v = T(eta(v_slot())), vd = T(eta_dot(v_slot()));
    const T wv = T(heading_sign * qd(heading)) * v;  // ψ̇ v
    qd(x) = p.c * v;
    qd(y) = p.s * v;
    qdd(x) = p.c * vd - p.s * wv;
    qdd(y) = p.s * vd + p.c * wv;
    return p;
  }
  /// Ṡ(q, q̇) η without forming Ṡ: only the v column moves, with ψ̇ = heading_sign·q̇_h.
  template <class Q, class QD, class E>
  auto Sdot_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<E>& eta) const {
    using T = promote_t<promote_t<promote_t<Sc, typename Q::Scalar>, typename QD::Scalar>, typename E::Scalar>;
    using std::cos;
    using std::sin;
    vecN<T, N> out = vecN<T, N>::Zero(n);
    const auto p = sincos_psi(T(q(heading)));
    const T pd = T(heading_sign) * T(qd(heading));
    const T v = T(eta(v_slot()));
    out(x) = -p.s * pd * v;
    out(y) = p.c * pd * v;
    return out;
  }

  template <class U>
  differential_drive<U, N> cast() const {
    differential_drive<U, N> d;
    d.n = n;
    d.x = x;
    d.y = y;
    d.heading = heading;
    d.forward_offset = U(forward_offset);
    d.heading_sign = U(heading_sign);
    return d;
  }
};

}  // namespace nhdyn
