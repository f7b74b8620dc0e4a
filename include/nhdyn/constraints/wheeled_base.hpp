#pragma once
/// \file constraints/wheeled_base.hpp
/// `wheeled_base`: any set of wheels on a planar base — fixed, steered, castor and Swedish
/// (mecanum, omni) wheels, any number, driven or passive — as one Pfaffian constraint read off
/// the tree's kinematics (docs/theory.md §11). One physical statement: the rim point of a
/// wheel in contact with the floor does not slip.
///
/// A wheel's spin joint gives its centre c (the joint's origin) and spin axis a; its contact
/// point is P = c − r e_z (the floor is z = 0 of the world). In the floor plane,
/// f = a × e_z / |a × e_z| is the direction in which a positive spin rolls the wheel forward and
/// ℓ = e_z × f its lateral direction. With G(q) q̇ the velocity of the wheel's material point at
/// P — column j of G is z_j × (P − o_j) for a revolute joint on the wheel's path from the world,
/// z_j for a prismatic one (z_j, o_j the joint's axis and origin), zero for every other joint —
/// the rows of A are
///
///     standard wheel (fixed, steered, castor):  ℓᵀ G q̇ = 0 (lateral),  fᵀ G q̇ = 0 (rolling)
///     Swedish wheel, rollers at γ:              uᵀ G q̇ = 0,   u = cos γ ℓ + sin γ f
///
/// so λ, the multiplier of a row, is the floor's force on the wheel along that row's unit
/// vector [N]. Rows that depend on rows before them at every configuration (two coaxial
/// wheels forbid the same sideways motion) are kept once (rank-revealing, below).
///
/// η = q̇_I for a set I of m = n − k coordinates (the `eta` option, or the rule below); the k
/// others, D, all on wheels' paths (W: the base's joints and the wheels' own), follow from
/// A_D q̇_D = −A_I q̇_I. Every joint off the wheels' paths (an arm) is in η with a unit column of
/// S. A_D is solved by block elimination: a wheel's own dependent joints (a castor's swivel and
/// spin, a Swedish wheel's spin, …) appear only in its own rows, with coefficients that do not
/// change with q, so a constant pivot block per wheel eliminates them, and a small dense system
/// (K, at each q; on one body with unsteered base rows K = K₀ T(ψ), factored once, and with no
/// steered wheel at all A = A₀ T(ψ): docs/theory.md §11) remains for the base's dependent
/// joints. The lift computes
/// q̈_D = −A_D⁻¹ (A_I η̇ + Ȧ q̇) with Ȧq̇ from the velocity and bias acceleration of the wheels'
/// paths (analytic, in the floor plane; `Sdot` is S's derivative by dual numbers, tested
/// equal). The input map E selects the actuated joints (p of them, τ's order): with p > m, τ
/// is the solution of SᵀE τ = Sᵀ v of least Σ w_j τ_j².
///
/// The reference (`reference_A`, from tree_kinematics' Jacobian of the contact point) is the
/// kernel's oracle; docs/model-format.md gives the robot-file form.
#include <Eigen/Core>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <numbers>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../detail/ldlt.hpp"
#include "../detail/small_buffer.hpp"
#include "../kinematics/tree.hpp"
#include "../model/tree_kernel.hpp"
#include "../scalar/dual.hpp"
#include "concept.hpp"

namespace nhdyn {

/// The wheel kinds of the standard classification (Campion, Bastin and d'Andréa-Novel 1996):
/// fixed, steered (orientable about a vertical axis, the steering joint driven), castor
/// (off-centred orientable: a passive swivel with a trail), Swedish (rollers on the rim at
/// `roller_angle` to the spin axis: mecanum ±45°, omni 90°).
enum class wheel_kind { fixed, steered, castor, swedish };

inline const char* to_string(wheel_kind k) {
  switch (k) {
    case wheel_kind::fixed: return "fixed";
    case wheel_kind::steered: return "steered";
    case wheel_kind::castor: return "castor";
    case wheel_kind::swedish: return "swedish";
  }
  return "?";
}

/// One wheel, its joints named as in the tree.
struct wheel {
  wheel_kind kind = wheel_kind::fixed;
  std::string spin;          ///< the spin joint: its origin is the wheel centre, its axis the spin axis
  std::string steer{};       ///< steered: the steering joint; castor: the swivel joint (vertical axes)
  double radius = 0;         ///< r [m]
  double roller_angle = 0;   ///< swedish: γ [rad], signed, 0 < |γ| ≤ π/2 (see docs/theory.md)
};

/// How η and τ are chosen; empty lists take the defaults.
struct wheeled_base_options {
  /// The joints whose rates η holds, in η's order (empty: the rule of `wheeled_base`).
  std::vector<std::string> eta{};
  /// The actuated joints, in τ's order (empty: every joint in q order except the base's —
  /// joints on a wheel's path that belong to no wheel — and the castors' swivel and spin).
  std::vector<std::string> actuated{};
  /// w_j > 0 of Σ w_j τ_j² for actuated joints (others: 1); used when p > m.
  std::vector<std::pair<std::string, double>> weights{};
  /// Where warnings go (a wheel that does not touch the floor z = 0, an axis a little off);
  /// default: one line on stderr, prefixed "nhdyn: warning: ".
  std::function<void(const std::string&)> warn{};
};

/// Which component of a wheel's contact velocity a row of A forbids.
enum class wheel_row { lateral, rolling, roller };

namespace detail {

/// A small dense LU factorisation with partial pivoting, in place on a column-major k×k buffer
/// (pivots chosen on the entries' double values, so that it runs on duals and intervals): L's
/// strict lower triangle, U's upper triangle with 1/u_jj on the diagonal (so that a solve
/// multiplies). Returns the smallest |u_jj| relative to the largest |a_ij|: 0 for a singular
/// matrix.
template <class T>
double lu_in_place(T* a, int k, int* perm) {
  double scale = 0;
  for (int i = 0; i < k * k; ++i) scale = std::max(scale, std::abs(value_of(a[i])));
  double min_pivot = k == 0 ? 1.0 : INFINITY;
  for (int j = 0; j < k; ++j) {
    int p = j;
    double best = std::abs(value_of(a[j + j * k]));
    for (int i = j + 1; i < k; ++i)
      if (const double v = std::abs(value_of(a[i + j * k])); v > best) best = v, p = i;
    perm[j] = p;
    if (p != j)
      for (int c = 0; c < k; ++c) std::swap(a[j + c * k], a[p + c * k]);
    min_pivot = std::min(min_pivot, scale > 0 ? best / scale : 0.0);
    if (best == 0) continue;  // singular: reported by the caller through min_pivot
    const T inv = T(1) / a[j + j * k];
    for (int i = j + 1; i < k; ++i) a[i + j * k] *= inv;
    for (int c = j + 1; c < k; ++c) {
      const T u = a[j + c * k];
      if (is_exact_zero(u)) continue;
      for (int i = j + 1; i < k; ++i) a[i + c * k] -= a[i + j * k] * u;
    }
    a[j + j * k] = inv;
  }
  return min_pivot;
}
/// Solves (LU) x = P b in place (b: k entries, stride 1) after lu_in_place.
template <class T, class X>
void lu_solve(const T* lu, const int* perm, int k, X* b) {
  for (int j = 0; j < k; ++j)
    if (perm[j] != j) std::swap(b[j], b[perm[j]]);
  for (int j = 0; j < k; ++j)
    for (int i = j + 1; i < k; ++i) b[i] -= lu[i + j * k] * b[j];
  for (int j = k - 1; j >= 0; --j) {
    b[j] *= lu[j + j * k];
    for (int i = 0; i < j; ++i) b[i] -= lu[i + j * k] * b[j];
  }
}

/// LDLᵀ factorisation of a symmetric positive-definite k×k column-major matrix, in place: L's
/// strict lower triangle, and 1/d_j on the diagonal (so that a solve multiplies; pivots judged
/// on values). Returns the smallest d_j / a_jj (in (0, 1]); 0 when a pivot is not positive.
template <class T>
double ldlt_in_place(T* a, int k) {
  double smallest = 1;
  small_buffer<T, dynamic, 64> dd(k);  // the pivots d_t
  for (int j = 0; j < k; ++j) {
    T d = a[j + j * k];
    for (int t = 0; t < j; ++t) d -= a[j + t * k] * a[j + t * k] * dd[t];
    const double dv = value_of(d), ajj = value_of(a[j + j * k]);
    if (!(dv > 0) || !(ajj > 0)) return 0;
    smallest = std::min(smallest, dv / ajj);
    dd[j] = d;
    const T inv = T(1) / d;
    for (int i = j + 1; i < k; ++i) {  // L(i, j) = (a_ij − Σ_t L_it L_jt d_t) / d_j
      T x = a[i + j * k];
      for (int t = 0; t < j; ++t) x -= a[i + t * k] * a[j + t * k] * dd[t];
      a[i + j * k] = x * inv;
    }
    a[j + j * k] = inv;
  }
  return smallest;
}
/// Solves (L D Lᵀ) x = b in place after ldlt_in_place.
template <class T, class X>
void ldlt_solve(const T* l, int k, X* b) {
  for (int j = 0; j < k; ++j)
    for (int t = 0; t < j; ++t) b[j] -= l[j + t * k] * b[t];
  for (int j = 0; j < k; ++j) b[j] *= l[j + j * k];
  for (int j = k - 1; j >= 0; --j)
    for (int t = j + 1; t < k; ++t) b[j] -= l[t + j * k] * b[t];
}

/// A joint's kernel frame on a wheel's path (the world first): K's placement in its parent's
/// at q = 0, the joint turning about or sliding along K's z.
template <class S>
struct wheel_path_node {
  int joint = -1;   ///< q index
  int parent = -1;  ///< node index, −1: the world
  bool revolute = true;
  bool spin = false;  ///< a wheel's spin joint (a leaf: its own rotation moves nothing A sees)
  mat3<S> R = mat3<S>::Identity();
  vec3<S> p = vec3<S>::Zero();
};

/// The kernel's scratch: a few dozen entries, inline (up to 256; beyond, the heap) — not the
/// 32 KiB default of small_buffer, whose many buffers would spread one call over many pages.
template <class T, int N>
using wheel_buffer = small_buffer<T, N, 256>;

/// One equation of the block elimination of A_D (constraints/wheeled_base.hpp): a linear
/// combination Σ_t coef_t · (row P_t of A x = b) of at most two rows of one wheel, with
/// `row` its own row (an N row left for the base) or its unknown's position in D (an own
/// dependent joint solved from the wheel's pivot rows).
template <class S>
struct elim_eq {
  int row = 0, d = 0;
  int P[2] = {0, 0};
  S coef[2] = {S(0), S(0)};

  template <class U>
  elim_eq<U> cast() const {
    return {row, d, {P[0], P[1]}, {U(coef[0]), U(coef[1])}};
  }
  /// A base equation's left side on v (A's rows): v[row] − Σ coef_t v[P_t].
  template <class T>
  T reduced(const T* v) const {
    T y = v[row];
    for (int t = 0; t < d; ++t) y -= T(coef[t]) * v[P[t]];
    return y;
  }
  /// An own joint's equation on v: Σ coef_t v[P_t].
  template <class T>
  T combined(const T* v) const {
    T y = T(coef[0]) * v[P[0]];
    if (d > 1) y += T(coef[1]) * v[P[1]];
    return y;
  }
};

/// A vector of the floor plane as two plain scalars (the kernel's 2-D arithmetic: Eigen's
/// 16-byte 2-vectors, built from two scalar stores and read back as one load, stalled on
/// store forwarding in every column of A).
template <class T>
struct vec2 {
  T x_, y_;  // no initialisers: trivially constructed (the kernel's scratch arrays of frames are not zeroed)
  vec2() = default;
  vec2(T x, T y) : x_(std::move(x)), y_(std::move(y)) {}
  static vec2 Zero() { return {T(0), T(0)}; }
  const T& x() const { return x_; }
  const T& y() const { return y_; }
  T dot(const vec2& o) const { return x_ * o.x_ + y_ * o.y_; }
  template <class U>
  vec2<U> cast() const { return {U(x_), U(y_)}; }
  friend vec2 operator+(const vec2& a, const vec2& b) { return {a.x_ + b.x_, a.y_ + b.y_}; }
  friend vec2 operator-(const vec2& a, const vec2& b) { return {a.x_ - b.x_, a.y_ - b.y_}; }
  friend vec2 operator*(const T& k, const vec2& a) { return {k * a.x_, k * a.y_}; }
  friend vec2 operator*(const vec2& a, const T& k) { return {a.x_ * k, a.y_ * k}; }
  vec2& operator+=(const vec2& b) { x_ += b.x_, y_ += b.y_; return *this; }
};

/// A wheel-path joint in the floor plane (the kernel's constants, read at q = 0): its parent
/// node, whether it is revolute (about ±e_z: `sign`) or prismatic, or a wheel's spin joint; its
/// origin's offset from its parent's, in its parent's heading frame (D); a prismatic joint's
/// horizontal axis, or a spin joint's axis's horizontal part (axis), in the same frame.
template <class S>
struct plane_node {
  int joint = -1, parent = -1;
  bool revolute = true, spin = false;
  S sign{1};
  vec2<S> D = vec2<S>::Zero(), axis = vec2<S>::Zero();
  S inv_len{1};  ///< 1/|axis| (a spin axis's horizontal part is a unit vector only when the axis is exactly horizontal)

  template <class U>
  plane_node<U> cast() const {
    return {joint, parent, revolute, spin, U(sign), D.template cast<U>(), axis.template cast<U>(), U(inv_len)};
  }
};

/// The world poses (axes, origin) of a wheel-path's kernel frames at q, in 3-D: the
/// constructor's checks (axes vertical or horizontal) and the plane nodes' constants.
inline std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> path_poses(const std::vector<wheel_path_node<double>>& nodes,
                                                                           const Eigen::VectorXd& q) {
  std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> X(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const auto& nd = nodes[i];
    Eigen::Matrix3d R = nd.R;
    Eigen::Vector3d p = nd.p;
    if (nd.revolute && !nd.spin) {
      const double c = std::cos(q(nd.joint)), s = std::sin(q(nd.joint));
      R.col(0) = c * nd.R.col(0) + s * nd.R.col(1);
      R.col(1) = c * nd.R.col(1) - s * nd.R.col(0);
    } else if (!nd.revolute) {
      p += nd.R.col(2) * q(nd.joint);
    }
    X[i] = nd.parent < 0 ? std::pair{R, p} : std::pair{Eigen::Matrix3d(X[std::size_t(nd.parent)].first * R),
                                                       Eigen::Vector3d(X[std::size_t(nd.parent)].second + X[std::size_t(nd.parent)].first * p)};
  }
  return X;
}

/// A kept row of A: its wheel and kind.
struct wheel_row_info {
  int wheel = 0;
  wheel_row kind = wheel_row::lateral;
};
}  // namespace detail

/// Any set of wheels on a planar base (see the file comment). Run-time sized; constant after
/// construction; A, S, Ṡ, E on any scalar.
///
/// η's default (no `eta` option): the dependent set D is chosen greedily among the wheels'
/// paths' joints, each taken when its column of A (at a configuration with every steering
/// and swivel angle generic) is independent of those taken before, in this order — castor
/// swivel and spin joints and Swedish spin joints (the floor dictates them); the base's
/// joints (base_x, base_y, base_yaw); fixed and steered wheels' spin joints, in the wheels'
/// order; steering joints — until k are taken. η is every other joint, in q order. So a
/// mecanum, omni or castor-only base has η = (base_x, base_y, base_yaw, …), a differential
/// drive (with or without castors) η = (its drive wheels' spin rates, …).
template <class Sc = double>
class wheeled_base {
 public:
  static constexpr int n_at_compile_time = dynamic;
  static constexpr int k_at_compile_time = dynamic;
  static constexpr int m_at_compile_time = dynamic;
  static constexpr int p_at_compile_time = dynamic;
  static constexpr bool orthonormal_S = false;
  using scalar_type = Sc;

  /// Dependent rows: a row is dropped when, at two generic configurations, it lies within
  /// this (relative to its norm) of the span of the rows kept before it.
  static constexpr double row_tolerance = 1e-9;
  /// A_D is refused as singular at a configuration when the base's block left by the
  /// elimination (K) has an LU pivot below this times its largest entry; so is SᵀE's block of
  /// the wheel-path actuators (and B W⁻¹ Bᵀ, its Gram matrix, at this squared). Where K or A
  /// only turns with ψ (prepare_body_base_block, prepare_body_rigid), the test is made once,
  /// at construction: its outcome does not change with q.
  static constexpr double singular_tolerance = 1e-10;

  wheeled_base() = default;

  /// The wheels of tree t (joints named as in t); throws model_error naming the wheel, the
  /// joint and the problem.
  wheeled_base(const tree<Sc>& t, std::vector<wheel> wheels, wheeled_base_options o = {})
      : n_(t.dof()), wheels_(std::move(wheels)), names_(t.joint_names()), model_(t.name()) {
    build(t, o);
  }

  int dof() const { return n_; }
  int k() const { return static_cast<int>(rows_.size()); }
  int m() const { return n_ - k(); }
  int p() const { return static_cast<int>(act_.size()); }

  const std::vector<wheel>& wheels() const { return wheels_; }
  /// η's joints (q indices, η's order), the actuated joints (τ's order), their weights.
  const std::vector<int>& eta_joints() const { return eta_; }
  const std::vector<int>& actuated_joints() const { return act_; }
  const std::vector<double>& weights() const { return weights_; }
  /// The kept rows of A: their wheel (index into wheels()) and kind.
  const std::vector<detail::wheel_row_info>& rows() const { return rows_; }
  /// Campion's degrees of mobility δm and steerability δs (docs/theory.md): the dimension of
  /// the base motions the fixed and steered wheels allow at fixed steering angles, and the
  /// number of independently steerable directions.
  int mobility() const { return mobility_; }
  int steerability() const { return steerability_; }
  /// Whether every wheel stands on one body that slides and turns in the plane, directly (fixed,
  /// Swedish) or through its steering or swivel joint (steered, castor): the lift then forms A
  /// and Ȧq̇ in closed form in the body's heading and the steering angles (docs/theory.md §11;
  /// docs/performance.md note 26 measures it). Every shipped base does.
  bool wheels_on_one_body() const { return body_yaw_ >= 0; }
  /// A sentence on a base that cannot move or moves only along a line; empty otherwise.
  std::string mobility_note() const {
    if (base_joints_ == 0) return "";
    if (mobility_ == 0 && steerability_ == 0)
      return "the base cannot move: its fixed wheels' axles do not meet in one point (degree of mobility 0)";
    if (mobility_ == 1 && steerability_ == 0)
      return "the base has a single motion (degree of mobility 1, no steering): along a line when its fixed wheels' axles "
             "are parallel — fixed wheels on two or more parallel axles, as a skid-steer base, slip by design: model such "
             "a base as a differential drive (docs/model-format.md) — or about the one point where the axles meet";
    return "";
  }

  /// A, S, Ṡ, E depend on the revolute joints of the wheels' paths other than the spin joints
  /// (the base's heading, steering and swivel angles).
  bool depends_on(int j) const { return j >= 0 && j < n_ && depends_[std::size_t(j)]; }

  /// Names: η's entries, τ's (the actuated joints), λ's (`<spin joint>.lateral`,
  /// `.rolling`, `.roller`).
  std::vector<std::string> eta_names(const std::vector<std::string>& joints) const { return pick(joints, eta_); }
  std::vector<std::string> tau_names(const std::vector<std::string>& joints) const { return pick(joints, act_); }
  std::vector<std::string> lambda_names() const {
    std::vector<std::string> out;
    for (const auto& r : rows_)
      out.push_back(wheels_[std::size_t(r.wheel)].spin + "." +
                    (r.kind == wheel_row::lateral ? "lateral" : r.kind == wheel_row::rolling ? "rolling" : "roller"));
    return out;
  }

  /// A(q), k × n.
  template <class Q>
  auto A(const Eigen::MatrixBase<Q>& q) const {
    return detail::A_by_A_into(*this, q);
  }
  /// A(q) into a (resized to k × n: no allocation once it has that size).
  template <class Q, class Am>
  void A_into(const Eigen::MatrixBase<Q>& q, Eigen::PlainObjectBase<Am>& a) const {
    using T = typename Am::Scalar;
    check_q(q);
    detail::wheel_buffer<T, dynamic> aw(k() * nw());
    rows_at(q, aw.data());
    a.setZero(k(), n_);
    for (int c = 0; c < nw(); ++c)
      for (int r = 0; r < k(); ++r) a(r, W_[std::size_t(c)]) = aw[r + c * k()];
  }

  /// S(q), n × m: unit rows at η's joints, −A_D⁻¹ A_I at D's.
  template <class Q>
  auto S(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    matrix<T, dynamic, dynamic> out = matrix<T, dynamic, dynamic>::Zero(n_, m());
    S_into(q, out);
    return out;
  }
  /// S(q) into s (n × m), which holds zeros or S at another q: only the unit entries and the D
  /// rows' η ∩ W entries are written (`has_S_into`).
  template <class Q, class Sm>
  void S_into(const Eigen::MatrixBase<Q>& q, Eigen::MatrixBase<Sm>& s) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    check_q(q);
    const factored<T> f(*this, q, true);
    for (int c = 0; c < m(); ++c) s(eta_[std::size_t(c)], c) = T(1);
    for (int i = 0; i < mw(); ++i)
      for (int d = 0; d < k(); ++d) s(W_[std::size_t(D_[std::size_t(d)])], Icol_[std::size_t(i)]) = f.sd[d + i * k()];
  }
  /// Ṡ(q, q̇) = Σ_j ∂S/∂q_j q̇_j: the derivative part of S at the dual q + ε q̇.
  template <class Q, class QD>
  auto Sdot(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename QD::Scalar>;
    check_q(q);
    detail::check_size(qd, n_, "qd");
    using D1 = dual<T, 1>;
    vecN<D1, dynamic> x(n_);
    for (int j = 0; j < n_; ++j) x(j) = D1(T(q(j)), {depends_on(j) ? T(qd(j)) : T(0)});
    const auto s = S(x);
    return matrix<T, dynamic, dynamic>(s.unaryExpr([](const D1& d) { return d.derivative(0); }));
  }
  /// E, n × p: a unit column at each actuated joint (τ's order).
  template <class Q>
  auto E(const Eigen::MatrixBase<Q>&) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    matrix<T, dynamic, dynamic> e = matrix<T, dynamic, dynamic>::Zero(n_, p());
    for (int a = 0; a < p(); ++a) e(act_[std::size_t(a)], a) = T(1);
    return e;
  }

  /// E τ into out (n entries) without forming E: τ at the actuated joints, zeros elsewhere.
  template <class Q, class Tau, class Out>
  void E_times_into(const Eigen::MatrixBase<Q>&, const Eigen::MatrixBase<Tau>& tau, Eigen::MatrixBase<Out>& out) const {
    using T = typename Out::Scalar;
    detail::check_size(tau, p(), "tau");
    detail::check_size(out, n_, "E tau");
    out.setZero();
    for (int a = 0; a < p(); ++a) out(act_[std::size_t(a)]) = T(tau(a));
  }

  /// q̇ = S(q) η without forming S.
  template <class Q, class Et>
  auto S_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Et>& eta) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename Et::Scalar>;
    check_q(q);
    vecN<T, dynamic> qd(n_);
    const factored<T> f(*this, q, true);
    velocities(f.sd.data(), eta, qd);
    return qd;
  }
  /// Sᵀ v without forming S: v at η's joints, plus S_Dᵀ v_D.
  template <class Q, class V>
  auto St_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename V::Scalar>;
    vecN<T, dynamic> out(m());
    St_times_into(q, v, out);
    return out;
  }
  /// The same into out (m entries, of the promoted scalar of the model, q and v): no
  /// allocation (`has_St_times_into`).
  template <class Q, class V, class Out>
  void St_times_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, Eigen::MatrixBase<Out>& out) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename V::Scalar>;
    static_assert(std::is_same_v<typename Out::Scalar, T>, "out's scalar is the model's, q's and v's promoted scalar");
    check_q(q);
    detail::check_size(out, m(), "S^T v");
    const factored<T> f(*this, q, true);
    project_force(f.sd.data(), v, out);
  }

  /// What the lift leaves for the projection (carried through rne with (q, v)): S's dependent
  /// rows S_D (k × |η ∩ W|, column-major) at the lift's q, so that the projection does not form
  /// A again. Up to 24 entries inline; beyond, in a block borrowed from the thread's
  /// detail::scratch_blocks (given back when the memo goes), so that a lift on a base of any
  /// size allocates nothing once its thread has met that size.
  template <class T>
  struct memo {
    static constexpr int inline_capacity = 24;
    memo() = default;
    memo(const memo& o) { assign(o.data(), o.size); }
    memo(memo&& o) noexcept : size(o.size) {
      if (size <= inline_capacity)
        std::copy(o.small.begin(), o.small.begin() + size, small.begin());
      else
        large = std::move(o.large), o.size = 0;
    }
    memo& operator=(const memo& o) {
      if (this != &o) assign(o.data(), o.size);
      return *this;
    }
    memo& operator=(memo&& o) noexcept {
      if (this == &o) return *this;
      release();
      if (o.size <= inline_capacity) {
        std::copy(o.small.begin(), o.small.begin() + o.size, small.begin());
        size = o.size;
      } else {
        large = std::move(o.large);
        size = std::exchange(o.size, 0);
      }
      return *this;
    }
    ~memo() { release(); }
    const T* data() const { return size <= inline_capacity ? small.data() : large.data(); }
    /// Room for n entries, which the caller writes (their values until then unspecified).
    T* reset(int n) {
      release();
      if (n <= inline_capacity) {
        size = n;
        return small.data();
      }
      large = detail::scratch_blocks<T>::take(static_cast<std::size_t>(n));
      std::uninitialized_default_construct_n(large.data(), n);
      size = n;
      return large.data();
    }
    void assign(const T* from, int n) {
      release();
      if (n <= inline_capacity) {
        std::copy(from, from + n, small.begin());
      } else {
        large = detail::scratch_blocks<T>::take(static_cast<std::size_t>(n));
        std::uninitialized_copy(from, from + n, large.data());  // if a copy throws, size stays 0 and the block is freed
      }
      size = n;
    }

   private:
    void release() noexcept {
      if (size > inline_capacity && large.data()) {
        std::destroy_n(large.data(), size);
        detail::scratch_blocks<T>::give_back(std::move(large));
      }
      size = 0;
    }
    std::array<T, inline_capacity> small;               ///< S_D when k·|η ∩ W| ≤ 24 (only `size` entries copied)
    typename detail::scratch_blocks<T>::block large{};  ///< else here: `size` constructed entries
    int size = 0;
  };

  /// (q̇, q̈) = (S η, S η̇ + Ṡ η) in one pass: q̇_D = S_D η, q̈_D = S_D η̇ − A_D⁻¹ Ȧ q̇, Ȧq̇ from the
  /// wheels' paths' velocities and bias accelerations (constraints/stages.hpp's lift uses it).
  /// Returns S_D for the projection (`project_with`).
  template <class Q, class Et, class ED, class QDo, class QDDo, class T = typename QDo::Scalar>
    requires std::is_same_v<T, typename QDDo::Scalar>
  memo<T> lift_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Et>& eta, const Eigen::MatrixBase<ED>& eta_dot,
                    Eigen::MatrixBase<QDo>& qd, Eigen::MatrixBase<QDDo>& qdd) const {
    check_q(q);
    detail::check_size(eta_dot, m(), "eta_dot");
    // −A_D⁻¹ Ȧ q̇ (in D's order) into x, S_D into the memo
    const int kk = k();
    detail::wheel_buffer<T, dynamic> b(kk), x(kk);
    memo<T> out;
    bool rigid = false;
    if constexpr (body_kernel_for<T>) {  // (the body kernel runs in the model's own scalar only)
      rigid = body_rigid_kernel<T>();
      if (rigid) {  // no wheel steered: S_D and A_D⁻¹ are turns of constants
        const vec2<T> cs = turn_of<T>(body_yaw_, q);
        T* const sd = out.reset(kk * mw());
        body_rigid_sd(cs, sd);
        velocities(sd, eta, qd);
        body_Adot_qdot(cs, body_u0_.data(), qd, b.data());
        body_rigid_solve(cs, b.data(), x.data());
      }
    }
    if (!rigid) {
      const factored<T> f(*this, q, true);
      out.assign(f.sd.data(), kk * mw());
      velocities(f.sd.data(), eta, qd);
      if (f.body)
        body_Adot_qdot(f.yaw, f.ub.data(), qd, b.data());
      else
        Adot_qdot(f.X.data(), qd, b.data());
      f.solve(b.data(), x.data());
    }
    // q̈: η̇ at η's joints, S_D η̇ − A_D⁻¹ Ȧ q̇ at D's
    const T* const sd = out.data();
    const int mm = m(), mwi = mw();
    for (int c = 0; c < mm; ++c) qdd(eta_[std::size_t(c)]) = T(eta_dot(c));
    for (int d = 0; d < kk; ++d) {
      T a = -x[d];
      for (int i = 0; i < mwi; ++i) a += sd[d + i * kk] * T(eta_dot(Icol_[std::size_t(i)]));
      qdd(Dq_[std::size_t(d)]) = a;
      if (!is_finite_scalar(a)) [[unlikely]]
        throw_not_solved(d, "accelerations");
    }
    return out;
  }
  /// τ from (q, v) with the lift's S_D at that q: the projection (SᵀE)⁺_W Sᵀ v without forming A
  /// again (constraints/stages.hpp's project takes it on project ∘ rne ∘ lift).
  template <class Q, class V, class T>
  auto project_with(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, const memo<T>& mm) const {
    vecN<promote_t<T, typename V::Scalar>, dynamic> tau(p());
    project_into(q, v, mm, tau);
    return tau;
  }
  /// The same into tau (p entries, of the promoted scalar; a vector or a map): no allocation.
  template <class Q, class V, class T, class Tau>
  void project_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, const memo<T>& mm,
                    Eigen::MatrixBase<Tau>& tau) const {
    using R = promote_t<T, typename V::Scalar>;
    static_assert(std::is_same_v<typename Tau::Scalar, R>, "tau's scalar is the lift's and v's promoted scalar");
    detail::check_size(tau, p(), "tau");
    if (act_is_eta_) {  // SᵀE = I: τ = Sᵀ v
      project_force(mm.data(), v, tau);
      return;
    }
    detail::wheel_buffer<R, dynamic> rb(m());
    Eigen::Map<vecN<R, dynamic>> r(rb.data(), m());
    project_force(mm.data(), v, r);
    actuation_into(q, mm.data(), r, tau);
  }

  /// τ = the solution of (SᵀE) τ = r of least Σ w_j τ_j² (p ≥ m), for r = Sᵀ v of m rows (a
  /// vector or a matrix of columns): the projection's last step (constraints/stages.hpp,
  /// detail::solve_StE). Throws numerical_error naming the η direction no actuator produces.
  template <class Q, class R>
  auto solve_actuation(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<R>& r) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename R::Scalar>;
    Eigen::Matrix<T, dynamic, R::ColsAtCompileTime> tau;
    solve_actuation_into(q, r, tau);
    return tau;
  }
  /// The same into tau (p × r's columns, of the promoted scalar; resized if it is a matrix of
  /// another size): no allocation once tau has that size. tau must not alias r.
  template <class Q, class R, class Out>
  void solve_actuation_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<R>& r,
                            Eigen::PlainObjectBase<Out>& tau) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename R::Scalar>;
    static_assert(std::is_same_v<typename Out::Scalar, T>, "tau's scalar is q's, r's and the model's promoted scalar");
    check_q(q);
    if (r.rows() != m()) detail::throw_size(r.rows(), m(), "Sᵀv");
    tau.resize(p(), r.cols());
    if (act_is_eta_) {  // SᵀE = I
      tau = r.template cast<T>();
      return;
    }
    const factored<T> f(*this, q, true);
    actuation_into(q, f.sd.data(), r, tau);
  }

  /// The constants in another scalar (a long-double reference, duals of the geometry).
  template <class U>
  wheeled_base<U> cast() const {
    wheeled_base<U> o;
    o.copy_structure(*this);
    for (const auto& nd : plane_) o.plane_.push_back(nd.template cast<U>());
    for (const Sc& r : radius_) o.radius_.push_back(U(r));
    for (const Sc& c : cos_gamma_) o.cos_gamma_.push_back(U(c));
    for (const Sc& s : sin_gamma_) o.sin_gamma_.push_back(U(s));
    o.prepare_body_kernel();
    return o;
  }
  /// A copy with every wheel's radius multiplied by f > 0 (a plant whose wheels differ from
  /// the nominal model's). A spin joint's column of A is −r a × e_z, so a wheel's pivot block
  /// of its own joints scales by f on its spin column: the inverse's spin row by 1/f (the
  /// eliminated rows' multipliers A[N, own] Pinv do not change).
  wheeled_base with_radius_factor(double f) const {
    if (!(std::isfinite(f) && f > 0)) throw model_error("wheeled_base: a radius factor must be positive and finite");
    wheeled_base o = *this;
    for (auto& r : o.radius_) r *= Sc(f);
    for (auto& w : o.wheels_) w.radius *= f;
    for (auto& e : o.own_eqs_)
      if (plane_[std::size_t(D_[std::size_t(e.row)])].spin)
        for (int t = 0; t < e.d; ++t) e.coef[t] /= Sc(f);
    o.prepare_body_kernel();
    return o;
  }

  /// The reference rows: A(q) from tree_kinematics' Jacobian of each contact point (the fast
  /// kernel's oracle; O(n) per wheel, allocating).
  static Eigen::MatrixXd reference_A(const tree<double>& t, const wheeled_base<double>& c, const Eigen::VectorXd& q) {
    const tree_kinematics<double> kin(t);
    Eigen::MatrixXd a(c.k(), t.dof());
    const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
    for (int i = 0; i < c.k(); ++i) {
      const auto& row = c.rows_[std::size_t(i)];
      const int spin = c.spin_joint_[std::size_t(row.wheel)];
      const auto Xc = kin.frame(q, spin + 1);  // the wheel's body frame: the spin joint's origin is fixed in it
      const auto& b = t[spin];
      const Eigen::Vector3d c_W = Xc.p + Xc.R * (b.R_JB.transpose() * -b.p_JB);  // the joint frame's origin
      const Eigen::Vector3d a_W = Xc.R * (b.R_JB.transpose() * b.axis);
      const double r = c.wheels_[std::size_t(row.wheel)].radius;
      const Eigen::Vector3d P_W = c_W - r * ez;
      const Eigen::Vector3d f = a_W.cross(ez).normalized(), l = ez.cross(f);
      const double g = c.wheels_[std::size_t(row.wheel)].roller_angle;
      const Eigen::Vector3d u = row.kind == wheel_row::lateral ? l
                                : row.kind == wheel_row::rolling ? f
                                                                 : Eigen::Vector3d(std::cos(g) * l + std::sin(g) * f);
      const Eigen::MatrixXd J = kin.jacobian(q, spin + 1, Xc.R.transpose() * (P_W - Xc.p));
      a.row(i) = u.transpose() * J.topRows(3);
    }
    return a;
  }

 private:
  template <class U>
  friend class wheeled_base;

  int nw() const { return static_cast<int>(W_.size()); }
  int mw() const { return static_cast<int>(I_.size()); }
  int pw() const { return static_cast<int>(actw_.size()); }

  template <class Q>
  void check_q(const Q& q) const {
    detail::check_size(q, n_, "q");
    detail::check_finite(q, "q");
  }
  static std::vector<std::string> pick(const std::vector<std::string>& names, const std::vector<int>& idx) {
    std::vector<std::string> out;
    for (int j : idx) out.push_back(names.at(std::size_t(j)));
    return out;
  }

  template <class U>
  void copy_structure(const wheeled_base<U>& o) {
    n_ = o.n_, wheels_ = o.wheels_, names_ = o.names_, model_ = o.model_;
    rows_ = o.rows_, row_node_ = o.row_node_, paths_ = o.paths_, read_paths_ = o.read_paths_, spin_joint_ = o.spin_joint_;
    W_ = o.W_, D_ = o.D_, I_ = o.I_, Icol_ = o.Icol_, Dq_ = o.Dq_, dcol_ = o.dcol_, icol_ = o.icol_;
    eta_ = o.eta_, act_ = o.act_, weights_ = o.weights_, inv_weight_w_ = o.inv_weight_w_, act_eta_ = o.act_eta_, actw_ = o.actw_;
    depends_ = o.depends_, act_is_eta_ = o.act_is_eta_, mobility_ = o.mobility_, steerability_ = o.steerability_;
    Db_ = o.Db_, Db_pos_ = o.Db_pos_, kb_ = o.kb_;
    base_eqs_.clear(), own_eqs_.clear();
    for (const auto& e : o.base_eqs_) base_eqs_.push_back(e.template cast<Sc>());
    for (const auto& e : o.own_eqs_) own_eqs_.push_back(e.template cast<Sc>());
    base_joints_ = o.base_joints_, built_ = o.built_;
  }

  template <class T>
  using vec2 = detail::vec2<T>;

  // ---- the kernel: the wheels' paths in the plane, the rows of A, Ȧq̇
  //
  // Every path joint but the spin joints turns about a vertical axis or slides along a
  // horizontal one (the constructor checks it), so a node's orientation is Rz(Θ) R(0) with Θ
  // the sum of the signed revolute rates above it, and everything A and Ȧq̇ need lies in the
  // floor plane: a node's heading (cos Θ, sin Θ), its origin's (x, y), and its velocity and
  // bias acceleration there. (The 3-D forms are the constructor's checks and reference_A.)

  /// A node's frame in the plane at q: the heading (c, s) = (cos Θ, sin Θ) and origin o; a
  /// spin node's o is the wheel centre and a its spin axis's horizontal part; a prismatic
  /// node's a is its sliding axis (in the plane, at its parent's heading).
  template <class T>
  struct frame2 {
    T c, s;
    vec2<T> o, a;
    vec2<T> turn(const vec2<Sc>& v) const { return vec2<T>(c * T(v.x()) - s * T(v.y()), s * T(v.x()) + c * T(v.y())); }
  };
  template <class T>
  static vec2<T> perp(const vec2<T>& v) { return vec2<T>(-v.y(), v.x()); }  // e_z × v

  /// The nodes' planar frames at q (Θ composed from each revolute joint's own sin/cos).
  template <class T, class Q>
  void frames(const Q& q, frame2<T>* X) const {
    const std::size_t nodes = plane_.size();
    for (std::size_t i = 0; i < nodes; ++i) {
      const auto& nd = plane_[i];
      frame2<T> P{T(1), T(0), vec2<T>::Zero(), vec2<T>::Zero()};
      if (nd.parent >= 0) P = X[nd.parent];
      auto& x = X[i];
      if (nd.spin) {
        x.c = P.c, x.s = P.s;
        x.o = P.o + P.turn(nd.D);
        x.a = P.turn(nd.axis);
      } else if (nd.revolute) {
        const T qi = T(nd.sign) * T(q(nd.joint));
        const auto sc = detail::sincos_of(qi);  // the tree kernels' sin/cos (model/dh_kernel.hpp)
        const T &cq = sc.c, &sq = sc.s;
        x.c = P.c * cq - P.s * sq, x.s = P.s * cq + P.c * sq;
        x.o = P.o + P.turn(nd.D);
      } else {
        x.c = P.c, x.s = P.s;
        x.a = P.turn(nd.axis);
        x.o = P.o + P.turn(nd.D) + x.a * T(q(nd.joint));
      }
    }
  }

  /// The rows of A on the wheels' paths' columns (k × |W|, column-major into aw) at q, and the
  /// nodes' planar frames X (filled here). Column j of wheel w's G at the contact point P:
  /// s_j e_z × (P − o_j) (revolute, s_j = ±1 its axis's sign), its sliding axis (prismatic),
  /// −r a × e_z (the spin joint); a row is uᵀ G with u = ℓ, f or cos γ ℓ + sin γ f.
  /// With `all` false only the columns that change with q and are read are written (η's and
  /// the base's dependent joints'; a wheel's own dependent joints' are the elimination's
  /// constants), the others left zero.
  template <class T, class Q>
  void rows_at(const Q& q, T* aw, frame2<T>* X = nullptr, bool all = true) const {
    detail::wheel_buffer<frame2<T>, dynamic> own(X ? 0 : static_cast<int>(plane_.size()));
    if (!X) X = own.data();
    frames(q, X);
    const int kk = k();
    for (int i = 0, e = kk * nw(); i < e; ++i) aw[i] = T(0);
    for (int r = 0; r < kk;) {  // one wheel's rows at a time (they are consecutive)
      const int w = rows_[std::size_t(r)].wheel, sn = row_node_[std::size_t(r)];
      const frame2<T>& S = X[sn];
      const floor_frame<T> F(S.a, T(plane_[std::size_t(sn)].inv_len));
      const vec2<T> P = S.o;  // the contact point's (x, y): the centre's
      const auto& path_v = all ? paths_[std::size_t(w)] : read_paths_[std::size_t(w)];
      const int* const path = path_v.data();
      const int len = static_cast<int>(path_v.size());
      const T rad = T(radius_[std::size_t(w)]);
      vec2<T> g[8];  // G's columns on the path (a longer path takes them one at a time)
      const bool keep = len <= 8;
      if (keep)
        for (int t = 0; t < len; ++t) g[t] = column_of_G(X, path[t], P, rad);
      const T cg = T(cos_gamma_[std::size_t(w)]), sg = T(sin_gamma_[std::size_t(w)]);
      for (; r < kk && rows_[std::size_t(r)].wheel == w; ++r) {
        const vec2<T> u = F.row(rows_[std::size_t(r)].kind, cg, sg);
        T* const row = aw + r;
        for (int t = 0; t < len; ++t) row[path[t] * kk] = u.dot(keep ? g[t] : column_of_G(X, path[t], P, rad));
      }
    }
  }
  template <class T>
  vec2<T> column_of_G(const frame2<T>* X, int j, const vec2<T>& P, const T& radius) const {
    const auto& nd = plane_[std::size_t(j)];
    if (nd.spin) return vec2<T>(-radius * X[j].a.y(), radius * X[j].a.x());  // −r a × e_z
    if (nd.revolute) return T(nd.sign) * perp(vec2<T>(P - X[j].o));
    return X[j].a;  // the sliding axis
  }
  /// A wheel's floor-plane directions from its spin axis's horizontal part a and ih = 1/|a|:
  /// f = a × e_z/|a| (a positive spin rolls it along f), ℓ = e_z × f = a/|a|; a row's unit
  /// vector (ℓ, f or cos γ ℓ + sin γ f).
  template <class T>
  struct floor_frame {
    vec2<T> f, l;
    floor_frame(const vec2<T>& a, const T& ih) : f(a.y() * ih, -a.x() * ih), l(a.x() * ih, a.y() * ih) {}
    vec2<T> row(wheel_row kind, const T& cg, const T& sg) const {
      if (kind == wheel_row::lateral) return l;
      if (kind == wheel_row::rolling) return f;
      return cg * l + sg * f;
    }
  };

  /// Ȧ q̇ (k entries into b) for q̇ (n entries) at the planar frames X. In the plane every node
  /// turns at Ω (the sum of its revolute rates), its origin moves at v and accelerates at
  /// a = a_p − Ω_p² d (+ 2 Ω_p e_z × t q̇ for a prismatic joint along t) at q̈ = 0 (d the offset
  /// from its parent's origin). A wheel turns at ω_w = Ω e_z + φ̇ a, with the bias acceleration
  /// α_w = Ω φ̇ e_z × a, Ω its spin joint's parent's; a row's value is u̇ᵀ v_rim + uᵀ a_rim with
  /// v_rim = v_c + r φ̇ e_z × a, a_rim = a_c − r Ω φ̇ a, u̇ = Ω e_z × u.
  template <class T, class QD>
  void Adot_qdot(const frame2<T>* X, const QD& qd, T* b) const {
    struct motion {
      T w;
      vec2<T> v, ac;
    };
    detail::wheel_buffer<motion, dynamic> M(static_cast<int>(plane_.size()));
    for (std::size_t i = 0; i < plane_.size(); ++i) {
      const auto& nd = plane_[i];
      const T qdi = T(qd(nd.joint));
      motion m{T(0), vec2<T>::Zero(), vec2<T>::Zero()};
      vec2<T> o_p = vec2<T>::Zero();
      if (nd.parent >= 0) {
        const motion& P = M[nd.parent];
        o_p = X[nd.parent].o;
        const vec2<T> d = X[i].o - o_p;
        m.w = P.w;
        m.v = P.v + P.w * perp(d);
        m.ac = P.ac - P.w * P.w * d;
      }
      if (nd.spin) {
        m.w = qdi;  // the spin rate (M[i].w holds φ̇ for a spin node)
      } else if (nd.revolute) {
        m.w += T(nd.sign) * qdi;
      } else {
        const vec2<T> t = X[i].a * qdi;  // the sliding axis (frames)
        m.v += t;
        if (nd.parent >= 0) m.ac += T(2) * M[nd.parent].w * perp(t);
      }
      M[i] = m;
    }
    for (int r = 0; r < k();) {  // one wheel's rows at a time
      const int w = rows_[std::size_t(r)].wheel, sn = row_node_[std::size_t(r)];
      const int ps = plane_[std::size_t(sn)].parent;
      const T rad = T(radius_[std::size_t(w)]), Om = ps >= 0 ? M[ps].w : T(0), phi = M[sn].w;
      const vec2<T>& a = X[sn].a;
      const floor_frame<T> F(a, T(plane_[std::size_t(sn)].inv_len));
      const vec2<T> v_rim = M[sn].v + rad * phi * perp(a);
      const vec2<T> a_rim = M[sn].ac - rad * Om * phi * a;
      const T cg = T(cos_gamma_[std::size_t(w)]), sg = T(sin_gamma_[std::size_t(w)]);
      for (; r < k() && rows_[std::size_t(r)].wheel == w; ++r) {
        const vec2<T> u = F.row(rows_[std::size_t(r)].kind, cg, sg);
        b[r] = Om * perp(u).dot(v_rim) + u.dot(a_rim);
      }
    }
  }

  /// Wheels on one planar body: the nodes are prismatic joints with fixed axes a_j, one revolute
  /// joint ψ below them (the body's heading, sign s_ψ), and per wheel its spin joint, hanging
  /// from ψ directly (fixed, Swedish) or through one steering or swivel joint β (steered,
  /// castor). A row's floor direction is then u = R(ψ + β) u₀ and its contact point's offset
  /// from ψ's origin R(ψ)(d_β + R(β) d_w), so its entries are constants except
  ///   (R(ψ + β) u₀)·a_j on a prismatic column, s_ψ (R(β) u₀)·(e_z × d_β) + const on ψ's,
  /// and Ȧq̇ = (ψ̇ + β̇) (e_z × u)·Σ a_j q̇_j + s_ψ q̇_ψ β̇ (R(β) u₀)·d_β (β, d_β zero for a wheel
  /// without a steering joint). rows_at and Adot_qdot in closed form (`body_rows`,
  /// `body_Adot_qdot`; docs/theory.md §11), in the model's own scalar only: any other — duals,
  /// intervals, a higher precision — takes the general kernel, which forms every constant in
  /// its own arithmetic (test_wheel_kinds holds the two to each other).
  template <class T>
  static constexpr bool body_kernel_for = std::is_same_v<T, Sc> && !enclosure_scalar<Sc>;
  template <class T>
  bool body_kernel() const {
    if constexpr (body_kernel_for<T>)
      return body_yaw_ >= 0;
    else
      return false;
  }
  /// (cos, sin) of a revolute node's signed angle at q.
  template <class T, class Q>
  vec2<T> turn_of(int node, const Q& q) const {
    const auto& nd = plane_[std::size_t(node)];
    const auto sc = detail::sincos_of(T(nd.sign) * T(q(nd.joint)));
    return vec2<T>(sc.c, sc.s);
  }
  /// v turned by the angle whose (cos, sin) is cs.
  template <class T, class V>
  static vec2<T> rotate(const vec2<T>& cs, const V& v) {
    return vec2<T>(cs.x() * v.x() - cs.y() * v.y(), cs.y() * v.x() + cs.x() * v.y());
  }
  /// A's read columns (k × |W|, column-major into aw; the others zero) on one body; cs gets
  /// (cos ψ, sin ψ) and ub (k entries) each row's R(β) u₀, for body_Adot_qdot.
  template <class T, class Q>
  void body_rows(const Q& q, T* aw, vec2<T>& cs, vec2<T>* ub_rows) const {
    cs = turn_of<T>(body_yaw_, q);
    const T s_yaw = T(plane_[std::size_t(body_yaw_)].sign);
    const int kk = k();
    for (int i = 0, e = kk * nw(); i < e; ++i) aw[i] = T(0);
    vec2<T> beta(T(1), T(0));
    for (int r = 0, last = -1; r < kk; ++r) {
      const int st = body_steer_[std::size_t(r)];
      if (st >= 0 && st != last) beta = turn_of<T>(st, q), last = st;  // a wheel's rows are consecutive
      const vec2<Sc>& u0 = body_u0_[std::size_t(r)];
      const vec2<T> ub = st >= 0 ? rotate(beta, u0) : vec2<T>(T(u0.x()), T(u0.y()));
      const vec2<T> u = rotate(cs, ub);
      ub_rows[r] = ub;
      for (const int j : read_paths_[std::size_t(rows_[std::size_t(r)].wheel)]) {
        const auto& nd = plane_[std::size_t(j)];
        T& a = aw[r + j * kk];
        if (!nd.revolute)
          a = u.x() * nd.axis.x() + u.y() * nd.axis.y();
        else if (j == body_yaw_ && st >= 0)
          a = s_yaw * (ub.y() * body_ds_[std::size_t(r)].x() - ub.x() * body_ds_[std::size_t(r)].y()) + T(body_c_[std::size_t(r)]);  // s_ψ ub·(e_z × d_β) + const
        else
          a = T(body_a0_[std::size_t(r + j * kk)]);
      }
    }
  }
  /// Ȧq̇ (k entries into b) on one body, at (cos ψ, sin ψ) = cs and body_rows' R(β) u₀ per row.
  template <class T, class QD>
  void body_Adot_qdot(const vec2<T>& cs, const vec2<T>* ub_rows, const QD& qd, T* b) const {
    const auto& yaw = plane_[std::size_t(body_yaw_)];
    const T qd_yaw = T(qd(yaw.joint)), psi_dot = T(yaw.sign) * qd_yaw;
    T vx(0), vy(0);  // Σ a_j q̇_j
    for (const int j : body_prism_) {
      const auto& nd = plane_[std::size_t(j)];
      const T qdj = T(qd(nd.joint));
      vx += nd.axis.x() * qdj, vy += nd.axis.y() * qdj;
    }
    for (int r = 0; r < k(); ++r) {
      const int st = body_steer_[std::size_t(r)];
      const vec2<T>& ub = ub_rows[r];
      const vec2<T> u = rotate(cs, ub);
      if (st < 0) {
        b[r] = psi_dot * (u.x() * vy - u.y() * vx);  // ψ̇ (e_z × u)·v
        continue;
      }
      const auto& sn = plane_[std::size_t(st)];
      const T beta_dot = T(sn.sign) * T(qd(sn.joint));
      const vec2<Sc>& ds = body_ds_[std::size_t(r)];
      b[r] = (psi_dot + beta_dot) * (u.x() * vy - u.y() * vx) +
             T(yaw.sign) * qd_yaw * beta_dot * (ub.x() * ds.x() + ub.y() * ds.y());
    }
  }
  /// Finds whether the wheels stand on one planar body (body_rows) and keeps, per row, u₀, the
  /// steering node, d_β and the constant part of ψ's column, and A at q = 0.
  void prepare_body_kernel() {
    body_yaw_ = -1, body_prism_.clear(), body_u0_.clear(), body_a0_.clear(), body_steer_.clear(), body_ds_.clear(),
    body_c_.clear(), body_kinv_.clear(), body_kpos_ = {-1, -1}, body_rigid_ = false;
    if constexpr (!enclosure_scalar<Sc>) {
      const int nodes = static_cast<int>(plane_.size());
      const auto revolute = [&](int i) { return plane_[std::size_t(i)].revolute && !plane_[std::size_t(i)].spin; };
      // ψ: the one revolute node with no revolute node above it
      int yaw = -1;
      for (int i = 0; i < nodes; ++i) {
        if (!revolute(i)) continue;
        bool top = true;
        for (int p = plane_[std::size_t(i)].parent; p >= 0; p = plane_[std::size_t(p)].parent) top = top && !revolute(p);
        if (!top) continue;
        if (yaw >= 0) return;  // two bodies turning independently
        yaw = i;
      }
      if (yaw < 0 || k() == 0) return;
      std::vector<bool> above(std::size_t(nodes), false);
      for (int p = plane_[std::size_t(yaw)].parent; p >= 0; p = plane_[std::size_t(p)].parent) above[std::size_t(p)] = true;
      std::vector<int> prism;
      for (int i = 0; i < nodes; ++i) {
        const auto& nd = plane_[std::size_t(i)];
        const int par = nd.parent;
        if (i == yaw) continue;
        if (above[std::size_t(i)])
          prism.push_back(i);  // prismatic: the only revolute node above ψ would be a second top one
        else if (nd.spin && (par == yaw || (par >= 0 && revolute(par) && plane_[std::size_t(par)].parent == yaw)))
          continue;  // a wheel on the body, or below its steering joint
        else if (revolute(i) && par == yaw)
          continue;  // a steering or swivel joint (its children checked as spins above)
        else
          return;
      }
      const int kk = k();
      std::vector<frame2<Sc>> X(std::size_t(nodes), frame2<Sc>{Sc(1), Sc(0), vec2<Sc>::Zero(), vec2<Sc>::Zero()});
      std::vector<Sc> a0(std::size_t(kk * nw()), Sc(0));
      rows_at(vecN<Sc, dynamic>(vecN<Sc, dynamic>::Zero(n_)), a0.data(), X.data(), true);
      const Sc s_yaw = plane_[std::size_t(yaw)].sign;
      for (int r = 0; r < kk; ++r) {
        const int sn = row_node_[std::size_t(r)], w = rows_[std::size_t(r)].wheel, par = plane_[std::size_t(sn)].parent;
        const floor_frame<Sc> F(X[std::size_t(sn)].a, plane_[std::size_t(sn)].inv_len);
        const vec2<Sc> u0 = F.row(rows_[std::size_t(r)].kind, cos_gamma_[std::size_t(w)], sin_gamma_[std::size_t(w)]);
        body_u0_.push_back(u0);
        if (par == yaw) {
          body_steer_.push_back(-1), body_ds_.push_back(vec2<Sc>::Zero()), body_c_.push_back(Sc(0));
        } else {  // ψ's column at q = 0 is s_ψ u₀·(e_z × d_β) + the constant part
          const vec2<Sc> ds = X[std::size_t(par)].o - X[std::size_t(yaw)].o;
          body_steer_.push_back(par), body_ds_.push_back(ds);
          body_c_.push_back(a0[std::size_t(r + yaw * kk)] - s_yaw * u0.dot(perp(ds)));
        }
      }
      body_a0_ = std::move(a0), body_prism_ = std::move(prism), body_yaw_ = yaw;
      prepare_body_base_block();
      prepare_body_rigid();
    }
  }
  /// When the base's rows (base_eqs_) come from wheels without a steering joint, each is
  /// ũᵀR(ψ)ᵀa_j on a prismatic column and constant on every other (body_rows), so the base's
  /// Schur block is K(ψ) = K₀ T(ψ): T is the identity but on the base's two prismatic columns,
  /// where it is Paᵀ R(ψ)ᵀ Pa (Pa = [a₁ a₂], their orthonormal floor axes). K₀ is factored
  /// here, once: x_b = T⁻¹ K₀⁻¹ b' at each q (body_base_solve) instead of an LU of K. T is
  /// orthogonal, so K's conditioning does not change with ψ: a K₀ well inside the singularity
  /// test (100× its tolerance) leaves every K(ψ) determined; a K₀ nearer keeps the per-q LU.
  void prepare_body_base_block() {
    body_kinv_.clear(), body_kpos_ = {-1, -1};
    const int kb = kb_, kk = k();
    if (kb == 0) return;
    for (const auto& e : base_eqs_) {
      if (body_steer_[std::size_t(e.row)] >= 0) return;
      for (int t = 0; t < e.d; ++t)
        if (body_steer_[std::size_t(e.P[t])] >= 0) return;
    }
    int found = 0;
    for (int j = 0; j < kb; ++j)
      for (std::size_t i = 0; i < body_prism_.size(); ++i)
        if (Db_[std::size_t(j)] == body_prism_[i]) {
          if (body_prism_.size() != 2) return;
          body_kpos_[i] = j, ++found;
        }
    if (found == 1) return;
    if (found == 2 && !body_pair_orthonormal()) return body_kpos_ = {-1, -1}, void();
    std::vector<Sc> K(static_cast<std::size_t>(kb * kb)), inv(static_cast<std::size_t>(kb * kb), Sc(0));
    std::vector<int> perm(static_cast<std::size_t>(kb));
    for (int j = 0; j < kb; ++j)  // K at q = 0, as factored forms it at q
      for (int r = 0; r < kb; ++r)
        K[std::size_t(r + j * kb)] = base_eqs_[std::size_t(r)].reduced(body_a0_.data() + Db_[std::size_t(j)] * kk);
    if (detail::lu_in_place(K.data(), kb, perm.data()) < 100 * singular_tolerance) return body_kpos_ = {-1, -1}, void();
    for (int j = 0; j < kb; ++j) {
      inv[std::size_t(j + j * kb)] = Sc(1);
      detail::lu_solve(K.data(), perm.data(), kb, inv.data() + j * kb);
    }
    body_kinv_ = std::move(inv);
  }
  /// x_b = K(ψ)⁻¹ b' in place (kb entries) by K₀⁻¹ and T(ψ)⁻¹ (prepare_body_base_block), at
  /// (cos ψ, sin ψ) = cs.
  template <int KB, class T>
  void body_base_solve(const vec2<T>& cs, T* x) const {
    const int kb = KB == dynamic ? kb_ : KB;
    detail::wheel_buffer<T, KB> y(kb);
    for (int r = 0; r < kb; ++r) {
      T a(0);
      for (int i = 0; i < kb; ++i) a += T(body_kinv_[std::size_t(r + i * kb)]) * x[i];
      y[r] = a;
    }
    if (const int p = body_kpos_[0]; p >= 0) body_pair_turn(cs, y[p], y[body_kpos_[1]]);
    for (int r = 0; r < kb; ++r) x[r] = y[r];
  }
  /// Whether the base's two prismatic joints slide along orthonormal floor axes (T orthogonal).
  bool body_pair_orthonormal() const {
    const vec2<Sc>&a1 = plane_[std::size_t(body_prism_[0])].axis, &a2 = plane_[std::size_t(body_prism_[1])].axis;
    using std::abs;
    return abs(a1.dot(a1) - 1) < Sc(1e-12) && abs(a2.dot(a2) - 1) < Sc(1e-12) && abs(a1.dot(a2)) < Sc(1e-12);
  }
  /// [v₁; v₂] ← Paᵀ R(ψ) Pa [v₁; v₂] on the base's two prismatic joints (Pa = [a₁ a₂], their
  /// orthonormal floor axes), at (cos ψ, sin ψ) = cs; R(−ψ) when cs is conjugated.
  template <class T>
  void body_pair_turn(const vec2<T>& cs, T& v1, T& v2) const {
    const auto& a1 = plane_[std::size_t(body_prism_[0])].axis;
    const auto& a2 = plane_[std::size_t(body_prism_[1])].axis;
    const vec2<T> v = rotate(cs, vec2<T>(v1 * T(a1.x()) + v2 * T(a2.x()), v1 * T(a1.y()) + v2 * T(a2.y())));
    v1 = T(a1.x()) * v.x() + T(a1.y()) * v.y();
    v2 = T(a2.x()) * v.x() + T(a2.y()) * v.y();
  }
  /// When no wheel has a steering joint (fixed and Swedish wheels), every row is ũᵀR(ψ)ᵀa_j on
  /// a prismatic column and constant on every other: A(q) = A₀ T(ψ), T as in
  /// prepare_body_base_block but on all of W. With both prismatic joints in D or both in η, and
  /// neither actuated, the lift and the projection need only constants at ψ = 0 and turns by ψ:
  ///   S_D = T_D⁻¹ S_D0 T_I,   A_D⁻¹ b = T_D⁻¹ A_D0⁻¹ b,   τ_W = P₀ T_I r_W,
  /// the last because SᵀE's block is B = T_Iᵀ B₀ (the actuated rows of T⁻¹ are unit rows), so
  /// B⁻¹ = B₀⁻¹ T_I and W⁻¹Bᵀ(BW⁻¹Bᵀ)⁻¹ = W⁻¹B₀ᵀ(B₀W⁻¹B₀ᵀ)⁻¹ T_I (T_I orthogonal). S_D0, A_D0⁻¹
  /// and P₀ come from the general kernel at q = 0 (which checks that η determines the motion
  /// and that the actuators produce it: T is invertible, so both then hold at every q).
  void prepare_body_rigid() {
    body_rigid_ = false, body_sd0_.clear(), body_adinv_.clear(), body_act0_.clear();
    body_dpair_ = {-1, -1}, body_ipair_ = {-1, -1};
    if (!built_) return;  // a copy the constructor makes before its structure is complete
    for (const int st : body_steer_)
      if (st >= 0) return;
    if (!body_prism_.empty()) {
      if (body_prism_.size() != 2 || !body_pair_orthonormal()) return;
      for (int i = 0; i < 2; ++i) {
        const int node = body_prism_[std::size_t(i)];
        body_dpair_[std::size_t(i)] = dcol_[std::size_t(node)], body_ipair_[std::size_t(i)] = icol_[std::size_t(node)];
      }
      if ((body_dpair_[0] >= 0) != (body_dpair_[1] >= 0)) return;  // one in D, one in η
      for (const auto& aw : actw_)
        if (aw.second == body_prism_[0] || aw.second == body_prism_[1]) return;
    }
    const int kk = k(), mwi = mw(), pwi = pw(), mm = m();
    const vecN<Sc, dynamic> q0 = vecN<Sc, dynamic>::Zero(n_);
    try {
      const factored<Sc> f(*this, q0, true);
      std::vector<Sc> adinv(static_cast<std::size_t>(kk * kk)), e(static_cast<std::size_t>(kk));
      for (int r = 0; r < kk; ++r) {
        std::fill(e.begin(), e.end(), Sc(0));
        e[std::size_t(r)] = Sc(1);
        f.solve(e.data(), adinv.data() + r * kk);
      }
      std::vector<Sc> act(static_cast<std::size_t>(pwi * mwi));
      if (mwi > 0) {  // (none: the wheels allow no motion, their actuators need no torque)
        Eigen::Matrix<Sc, Eigen::Dynamic, Eigen::Dynamic> R = Eigen::Matrix<Sc, Eigen::Dynamic, Eigen::Dynamic>::Zero(mm, mwi),
                                                         tau(p(), mwi);
        for (int i = 0; i < mwi; ++i) R(Icol_[std::size_t(i)], i) = Sc(1);
        actuation_into(q0, f.sd.data(), R, tau);
        for (int i = 0; i < mwi; ++i)
          for (int a = 0; a < pwi; ++a) act[std::size_t(a + i * pwi)] = tau(actw_[std::size_t(a)].first, i);
      }
      body_sd0_.assign(f.sd.data(), f.sd.data() + kk * mwi), body_adinv_ = std::move(adinv), body_act0_ = std::move(act);
    } catch (const std::exception&) {
      return;  // the general kernel reports it at the configuration
    }
    body_rigid_ = true;
  }
  /// Whether the lift and the projection in T take prepare_body_rigid's constants.
  template <class T>
  bool body_rigid_kernel() const {
    return body_kernel<T>() && body_rigid_;
  }
  /// x = A_D⁻¹ b = T_D⁻¹ A_D0⁻¹ b at (cos ψ, sin ψ) = cs (prepare_body_rigid; b: k entries in
  /// A's row order, x: k in D's order).
  template <class T>
  void body_rigid_solve(const vec2<T>& cs, const T* b, T* x) const {
    const int k = this->k();
    const Sc* const adinv = body_adinv_.data();
    for (int d = 0; d < k; ++d) x[d] = T(0);
    for (int r = 0; r < k; ++r)
      for (int d = 0; d < k; ++d) x[d] += T(adinv[d + r * k]) * b[r];
    if (const int d1 = body_dpair_[0]; d1 >= 0) body_pair_turn(cs, x[d1], x[body_dpair_[1]]);
  }
  /// S_D = T_D⁻¹ S_D0 T_I at (cos ψ, sin ψ) = cs (prepare_body_rigid), into sd (k × |η ∩ W|).
  template <class T>
  void body_rigid_sd(const vec2<T>& cs, T* sd) const {
    const int kk = k(), mwi = mw();
    const Sc* const sd0 = body_sd0_.data();
    for (int i = 0; i < kk * mwi; ++i) sd[i] = T(sd0[i]);
    if (const int i1 = body_ipair_[0]; i1 >= 0)  // a row s times T_I: (T_Iᵀ sᵀ)ᵀ, T_Iᵀ = Paᵀ R(ψ) Pa
      for (int d = 0; d < kk; ++d) body_pair_turn(cs, sd[d + i1 * kk], sd[d + body_ipair_[1] * kk]);
    if (const int d1 = body_dpair_[0]; d1 >= 0)
      for (int i = 0; i < mwi; ++i) body_pair_turn(cs, sd[d1 + i * kk], sd[body_dpair_[1] + i * kk]);
  }

  /// A at q on the wheels' paths' columns and the block elimination of A_D (refused, naming the
  /// configuration and the wheels, where η does not determine the motion): each wheel's own
  /// dependent joints appear in its own rows only, with coefficients that do not change with q
  /// (the rows and the own joints' columns turn together), so a constant pivot block per wheel
  /// (`wheel_elim`) eliminates them; the rows left form K x_b = b' for the base's dependent
  /// joints (k_b × k_b, LU with partial pivoting, at each q, unless fixed_k or rigid); and S_D = −A_D⁻¹ A_I. On the stack.
  template <class T>
  struct factored {
    const wheeled_base& c;
    bool body;                                 ///< the rows in closed form (body_rows): X unused, yaw = (cos ψ, sin ψ)
    bool rigid;                                ///< no wheel steered (prepare_body_rigid): only yaw, ub and sd used
    bool fixed_k;                              ///< K = K₀ T(ψ) (body_base_solve): K and perm unused
    vec2<T> yaw = vec2<T>::Zero();
    detail::wheel_buffer<vec2<T>, dynamic> ub;  ///< body_rows' R(β) u₀ per row (k; empty if not body)
    detail::wheel_buffer<frame2<T>, dynamic> X;
    detail::wheel_buffer<T, dynamic> aw;  ///< A on W's columns, k × |W|
    detail::wheel_buffer<T, dynamic> K;   ///< the base's Schur block, its LU (k_b × k_b)
    detail::wheel_buffer<int, dynamic> perm;
    detail::wheel_buffer<T, dynamic> H;   ///< per wheel Pinv A[P, D_b], stacked (k − k_b) × k_b
    detail::wheel_buffer<T, dynamic> sd;  ///< S_D = −A_D⁻¹ A_I, k × |η ∩ W|, D's order
    /// For an enclosure scalar (intervals): K preconditioned by the inverse of its midpoint
    /// (Hansen), so that interval elimination does not blow up; its right-hand sides then C b.
    Eigen::MatrixXd C{};

    template <class Q>
    factored(const wheeled_base& w, const Q& q, bool with_sd)
        : c(w), body(w.template body_kernel<T>()), rigid(body && w.body_rigid_),
          fixed_k(body && !rigid && !w.body_kinv_.empty()), ub(body ? w.k() : 0),
          X(body ? 0 : static_cast<int>(w.plane_.size())), aw(rigid ? 0 : w.k() * w.nw()),
          K(rigid || fixed_k ? 0 : w.kb_ * w.kb_), perm(rigid || fixed_k ? 0 : w.kb_), H(rigid ? 0 : (w.k() - w.kb_) * w.kb_),
          sd(with_sd ? w.k() * w.mw() : 0) {
      const int k = c.k(), kb = c.kb_;
      if (rigid) {
        yaw = c.template turn_of<T>(c.body_yaw_, q);
        for (int r = 0; r < k; ++r) ub[r] = vec2<T>(T(c.body_u0_[std::size_t(r)].x()), T(c.body_u0_[std::size_t(r)].y()));
        if (with_sd) c.body_rigid_sd(yaw, sd.data());
        return;
      }
      if (body)
        c.body_rows(q, aw.data(), yaw, ub.data());
      else
        c.rows_at(q, aw.data(), X.data(), false);
      const auto A = [&](int r, int col) -> const T& { return aw[r + col * k]; };
      // K: each wheel's rows left after its pivot rows eliminate its own dependent joints;
      // H = Pinv A[P, D_b] of each own dependent joint
      for (int j = 0; j < kb; ++j) {
        const T* col = aw.data() + c.Db_[std::size_t(j)] * k;
        if (!fixed_k)
          for (int r = 0; r < kb; ++r) K[r + j * kb] = c.base_eqs_[std::size_t(r)].reduced(col);
        for (int o = 0; o < k - kb; ++o) H[o + j * (k - kb)] = c.own_eqs_[std::size_t(o)].combined(col);
      }
      if constexpr (enclosure_scalar<T>) precondition();
      if (kb > 0 && !fixed_k && detail::lu_in_place(K.data(), kb, perm.data()) < singular_tolerance)
        c.throw_undetermined(q, aw.data());
      if (with_sd) {
        if (kb == 0) {  // every dependent joint a wheel's own: S_D(o, i) = −Σ Pinv A(P, I_i)
          for (int i = 0; i < c.mw(); ++i) {
            const T* col = aw.data() + c.I_[std::size_t(i)] * k;
            for (const auto& e : c.own_eqs_) sd[e.row + i * k] = -e.combined(col);
          }
        } else {
          detail::wheel_buffer<T, dynamic> b(k);
          for (int i = 0; i < c.mw(); ++i) {
            for (int r = 0; r < k; ++r) b[r] = -A(r, c.I_[std::size_t(i)]);
            solve(b.data(), sd.data() + i * k);
          }
        }
        if (!detail::finite_range(Eigen::Map<const vecN<T, dynamic>>(sd.data(), k * c.mw()), 0, k * c.mw())) [[unlikely]]
          for (int j = 0; j < k * c.mw(); ++j)
            if (!is_finite_scalar(sd[j])) c.throw_not_solved(j % k, "velocities");
      }
    }
    /// x = A_D⁻¹ b (b: k entries in A's row order; x: k entries in D's order). A planar base's
    /// three dependent velocities (x, y, ψ) at a compile-time size, any other count at run time.
    void solve(const T* b, T* x) const {
      if (rigid) return c.body_rigid_solve(yaw, b, x);
      if (c.kb_ == 3)
        solve_n<3>(b, x);
      else
        solve_n<dynamic>(b, x);
    }

   private:
    template <int KB>
    void solve_n(const T* b, T* x) const {
      const int k = c.k(), kb = KB == dynamic ? c.kb_ : KB;
      detail::wheel_buffer<T, KB> bb(kb);
      for (int r = 0; r < kb; ++r) bb[r] = c.base_eqs_[std::size_t(r)].reduced(b);
      if (fixed_k)
        c.template body_base_solve<KB>(yaw, bb.data());
      else if (kb > 0) {
        if (C.size()) {
          detail::wheel_buffer<T, dynamic> t(kb);
          for (int r = 0; r < kb; ++r) {
            T y(0);
            for (int i = 0; i < kb; ++i) y += T(C(r, i)) * bb[i];
            t[r] = y;
          }
          for (int r = 0; r < kb; ++r) bb[r] = t[r];
        }
        detail::lu_solve(K.data(), perm.data(), kb, bb.data());
      }
      for (int j = 0; j < kb; ++j) x[c.Db_pos_[std::size_t(j)]] = bb[j];
      for (int o = 0; o < k - kb; ++o) {
        const auto& e = c.own_eqs_[std::size_t(o)];
        T y = e.combined(b);
        for (int j = 0; j < kb; ++j) y -= H[o + j * (k - kb)] * bb[j];
        x[e.row] = y;
      }
    }
    void precondition() {
      const int kb = c.kb_;
      if (kb == 0) return;
      Eigen::MatrixXd mid(kb, kb);
      for (int j = 0; j < kb; ++j)
        for (int r = 0; r < kb; ++r) mid(r, j) = value_of(K[r + j * kb]);
      const Eigen::FullPivLU<Eigen::MatrixXd> plu(mid);
      if (!mid.allFinite() || !plu.isInvertible()) return;
      C = plu.inverse();
      detail::wheel_buffer<T, dynamic> t(kb * kb);
      for (int j = 0; j < kb; ++j)
        for (int r = 0; r < kb; ++r) {
          T y(0);
          for (int i = 0; i < kb; ++i) y += T(C(r, i)) * K[i + j * kb];
          t[r + j * kb] = y;
        }
      for (int i = 0; i < kb * kb; ++i) K[i] = t[i];
    }
  };

  /// q̇ = S η into qd: η at its joints, q̇_D = S_D η.
  template <class T, class Et, class QDo>
  void velocities(const T* sd, const Et& eta, QDo& qd) const {
    detail::check_size(eta, m(), "eta");
    const int kk = k(), mm = m(), mwi = mw();
    using R = typename QDo::Scalar;
    for (int c = 0; c < mm; ++c) qd(eta_[std::size_t(c)]) = R(eta(c));
    for (int d = 0; d < kk; ++d) {
      R a(0);
      for (int i = 0; i < mwi; ++i) a += R(sd[d + i * kk]) * R(eta(Icol_[std::size_t(i)]));
      qd(Dq_[std::size_t(d)]) = a;
    }
  }
  /// Sᵀ v into out (m entries): v at η's joints, plus S_Dᵀ v_D.
  template <class T, class V, class Out>
  void project_force(const T* sd, const V& v, Out& out) const {
    detail::check_size(v, n_, "v");
    using R = typename Out::Scalar;
    const int kk = k(), mm = m(), mwi = mw();
    for (int c = 0; c < mm; ++c) out(c) = R(v(eta_[std::size_t(c)]));
    for (int i = 0; i < mwi; ++i) {
      R s(0);
      for (int d = 0; d < kk; ++d) s += R(sd[d + i * kk]) * R(v(Dq_[std::size_t(d)]));
      out(Icol_[std::size_t(i)]) += s;
    }
  }
  /// τ (p rows) from r = Sᵀv (m rows, any number of columns) into tau (p × r's columns; no
  /// allocation): actuators off the wheels' paths take their η entry's force; the wheel-path
  /// actuators solve B τ_w = r_w, B = SᵀE's block (|η ∩ W| × p_w), exactly when square, else
  /// with least Σ w τ²: τ_w = W⁻¹Bᵀ(BW⁻¹Bᵀ)⁻¹ r_w.
  template <class Q, class T, class R, class Out>
  void actuation_into(const Q& q, const T* sd, const R& r, Out& tau) const {
    using U = promote_t<T, typename R::Scalar>;
    const Eigen::Index cols = r.cols();
    for (const auto& [a, c] : act_eta_)
      for (Eigen::Index j = 0; j < cols; ++j) tau(a, j) = U(r(c, j));
    if constexpr (std::is_same_v<typename Q::Scalar, T>)  // (a q of another scalar: the general path)
      if (body_rigid_kernel<T>()) return body_rigid_actuation_into<U>(turn_of<T>(body_yaw_, q), r, tau);
    switch (mw()) {
      case 0:  // the wheels allow no motion: their actuators need no torque
        for (const auto& aw : actw_) tau.row(aw.first).setZero();
        return;
      case 3:  // a planar base's (ẋ, ẏ, ψ̇): the loops below at a size the compiler knows
        return wheel_actuation_into<3>(q, sd, r, tau);
      default:
        return wheel_actuation_into<dynamic>(q, sd, r, tau);
    }
  }
  /// actuation_into's wheel-path block with no steered wheel: τ_W = P₀ T_I r_W
  /// (prepare_body_rigid), at (cos ψ, sin ψ) = cs.
  template <class U, class T, class R, class Out>
  void body_rigid_actuation_into(const vec2<T>& cs, const R& r, Out& tau) const {
    const int mwi = mw(), pwi = pw();
    const vec2<U> back(U(cs.x()), U(-cs.y()));  // R(−ψ)
    const Sc* const act0 = body_act0_.data();
    detail::wheel_buffer<U, dynamic> x(mwi);
    for (Eigen::Index j = 0; j < r.cols(); ++j) {
      for (int i = 0; i < mwi; ++i) x[i] = U(r(Icol_[std::size_t(i)], j));
      if (const int i1 = body_ipair_[0]; i1 >= 0) body_pair_turn(back, x[i1], x[body_ipair_[1]]);
      for (int a = 0; a < pwi; ++a) {
        U t(0);
        for (int i = 0; i < mwi; ++i) t += U(act0[a + i * pwi]) * x[i];
        tau(actw_[std::size_t(a)].first, j) = t;
      }
    }
  }
  /// actuation_into's wheel-path block, |η ∩ W| = MW (or dynamic).
  template <int MW, class Q, class T, class R, class Out>
  void wheel_actuation_into(const Q& q, const T* sd, const R& r, Out& tau) const {
    using U = promote_t<T, typename R::Scalar>;
    const int kk = k(), mw_ = MW == dynamic ? mw() : MW, pw_ = pw();
    const Eigen::Index cols = r.cols();
    // B(i, a) = S(actuator a's joint, η's wheel-path entry i): a column of S_D, or a unit column
    const bool square = pw_ == mw_;
    detail::wheel_buffer<U, dynamic> buf(mw_ * pw_ + mw_ * mw_ + mw_);  // B, G, x
    U* __restrict const B = buf.data();
    U* __restrict const G = B + mw_ * pw_;
    U* __restrict const x = G + mw_ * mw_;
    detail::wheel_buffer<int, dynamic> perm(mw_);
    for (int a = 0; a < pw_; ++a) {
      const int w = actw_[std::size_t(a)].second, d = dcol_[std::size_t(w)];
      U* __restrict const b = B + a * mw_;
      if (d >= 0) {
        for (int i = 0; i < mw_; ++i) b[i] = U(sd[d + i * kk]);
      } else {
        for (int i = 0; i < mw_; ++i) b[i] = U(0);
        b[icol_[std::size_t(w)]] = U(1);
      }
    }
    if (square) {
      for (int i = 0; i < mw_ * mw_; ++i) G[i] = B[i];
    } else {  // G = B W⁻¹ Bᵀ, each entry's sum in a register
      const double* const iw = inv_weight_w_.data();
      for (int j = 0; j < mw_; ++j)
        for (int i = j; i < mw_; ++i) {
          U g(0);
          for (int a = 0; a < pw_; ++a) g += (B[i + a * mw_] * U(iw[a])) * B[j + a * mw_];
          G[i + j * mw_] = g;
          G[j + i * mw_] = g;
        }
    }
    // B itself by LU (square), B W⁻¹ Bᵀ (symmetric positive definite) by LDLᵀ: refused below
    // a relative pivot of 1e-10 (B) or 1e-20 (BW⁻¹Bᵀ, whose condition number is B's squared)
    if (square ? detail::lu_in_place(G, mw_, perm.data()) < singular_tolerance
               : detail::ldlt_in_place(G, mw_) < singular_tolerance * singular_tolerance)
      throw_uncontrollable(q, B);
    for (Eigen::Index c = 0; c < cols; ++c) {
      for (int i = 0; i < mw_; ++i) x[i] = U(r(Icol_[std::size_t(i)], c));
      if (square) {
        detail::lu_solve(G, perm.data(), mw_, x);
        for (int a = 0; a < pw_; ++a) tau(actw_[std::size_t(a)].first, c) = x[a];
      } else {  // τ_w = W⁻¹ Bᵀ x
        detail::ldlt_solve(G, mw_, x);
        for (int a = 0; a < pw_; ++a) {
          U t(0);
          for (int i = 0; i < mw_; ++i) t += B[i + a * mw_] * x[i];
          tau(actw_[std::size_t(a)].first, c) = t * U(inv_weight_w_[std::size_t(a)]);
        }
      }
    }
  }
  /// A solved dependent rate not finite: an enclosure too wide for A_D (an interval box:
  /// refused by name, not passed on as a NaN) or an overflow.
  [[noreturn]] void throw_not_solved(int d, const char* what) const {
    throw numerical_error("wheeled_base: the dependent joints' " + std::string(what) + " are not finite (" +
                          names_[std::size_t(W_[std::size_t(D_[std::size_t(d)])])] +
                          "): an interval box too wide for the wheels' constraint matrix, or an overflow");
  }

  // ---- errors

  template <class Q>
  std::string configuration(const Q& q) const {
    std::ostringstream os;
    bool first = true;
    for (int j = 0; j < n_; ++j)
      if (depends_on(j)) os << (first ? "" : ", ") << names_[std::size_t(j)] << " = " << value_of(q(j)), first = false;
    return os.str();
  }
  /// A_D singular at q: the wheels whose rows carry its null direction.
  template <class Q, class T>
  [[noreturn]] void throw_undetermined(const Q& q, const T*) const {
    const int kk = k();
    std::vector<T> aw(std::size_t(kk * nw()));
    rows_at(q, aw.data());  // every column (the kernel wrote only those it reads)
    Eigen::MatrixXd AD(kk, kk);
    for (int d = 0; d < kk; ++d)
      for (int r = 0; r < kk; ++r) AD(r, d) = value_of(aw[r + D_[std::size_t(d)] * kk]);
    std::ostringstream os;
    os << "wheeled_base: model '" << model_ << "' at " << configuration(q)
       << ": the velocities in eta are not independent there, or do not determine the others (the wheels' constraints on ";
    for (int d = 0; d < kk; ++d) os << (d ? ", " : "") << names_[std::size_t(W_[std::size_t(D_[std::size_t(d)])])];
    os << ", are singular there); wheels involved: ";
    if (!AD.allFinite()) {
      os << "(not finite)";
      throw numerical_error(os.str());
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(AD, Eigen::ComputeFullU);
    const Eigen::VectorXd y = svd.matrixU().col(kk - 1);
    std::vector<int> seen;
    for (int r = 0; r < kk; ++r)
      if (std::abs(y(r)) > 0.1) {
        const int w = rows_[std::size_t(r)].wheel;
        if (std::find(seen.begin(), seen.end(), w) == seen.end()) seen.push_back(w);
      }
    for (std::size_t i = 0; i < seen.size(); ++i)
      os << (i ? ", " : "") << wheels_[std::size_t(seen[i])].spin << " (" << to_string(wheels_[std::size_t(seen[i])].kind) << ")";
    throw numerical_error(os.str());
  }
  /// SᵀE has rank < m on η's wheel-path block B (column-major |η ∩ W| × p_w): the direction of η
  /// no actuator produces.
  template <class Q, class U>
  [[noreturn]] void throw_uncontrollable(const Q& q, const U* b) const {
    Eigen::MatrixXd Bd(mw(), pw());
    for (int a = 0; a < pw(); ++a)
      for (int i = 0; i < mw(); ++i) Bd(i, a) = value_of(b[i + a * mw()]);
    std::ostringstream os;
    os << "wheeled_base: model '" << model_ << "' at " << configuration(q)
       << ": the actuated joints cannot produce every motion eta allows; no actuator drives the direction (";
    if (Bd.allFinite()) {
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(Bd, Eigen::ComputeFullU);
      const Eigen::VectorXd y = svd.matrixU().col(Bd.rows() - 1);
      bool first = true;
      for (int i = 0; i < mw(); ++i)
        if (std::abs(y(i)) > 1e-6)
          os << (first ? "" : ", ") << names_[std::size_t(eta_[std::size_t(Icol_[std::size_t(i)])])] << ": " << y(i), first = false;
    }
    os << ") of eta";
    throw numerical_error(os.str());
  }

  // ---- construction (the tree's geometry in double; decisions on values)

  void warn(const wheeled_base_options& o, const std::string& msg) const {
    if (o.warn)
      o.warn(msg);
    else
      std::cerr << "nhdyn: warning: " << msg << "\n";
  }
  int joint_index(const std::string& name, const std::string& where) const {
    for (int i = 0; i < n_; ++i)
      if (names_[std::size_t(i)] == name) return i;
    std::string known;
    for (const auto& j : names_) known += (known.empty() ? "" : ", ") + j;
    throw model_error(where + "no movable joint named '" + name + "' (movable joints: " + known + ")");
  }

  void build(const tree<Sc>& t, const wheeled_base_options& o);
  template <class U>
  static Eigen::VectorXd generic_q(const wheeled_base<U>& c, int which);

  int n_ = 0;
  std::vector<wheel> wheels_{};
  std::vector<std::string> names_{};
  std::string model_{};
  std::vector<detail::plane_node<Sc>> plane_{};       ///< the wheels' paths' joints, q order (node i is W column i)
  std::vector<Sc> radius_{}, cos_gamma_{}, sin_gamma_{};  ///< per wheel
  std::vector<int> spin_joint_{};                     ///< per wheel
  std::vector<std::vector<int>> paths_{};             ///< per wheel: its path's nodes
  std::vector<std::vector<int>> read_paths_{};        ///< per wheel: its path's nodes in η or the base's D
  std::vector<detail::wheel_row_info> rows_{};        ///< the kept rows
  std::vector<int> row_node_{};                       ///< per row: its wheel's spin node
  std::vector<int> W_{};                              ///< the wheels' paths' joints (q order)
  std::vector<int> D_{}, I_{};                        ///< W columns: dependent; in η
  std::vector<int> Icol_{};                           ///< per I_ entry: its η column
  std::vector<int> Dq_{};                             ///< per D_ entry: its joint (q index), W_[D_[d]]
  std::vector<int> dcol_{}, icol_{};                  ///< per W column: its D position / I_ position, or −1
  std::vector<int> eta_{}, act_{};                    ///< q indices
  std::vector<double> weights_{};                     ///< per actuated joint
  std::vector<double> inv_weight_w_{};                ///< 1/w of each actuator on the wheels' paths (actw_'s order)
  std::vector<std::pair<int, int>> act_eta_{};        ///< (τ entry, η column) of the actuators off the wheels' paths
  std::vector<std::pair<int, int>> actw_{};           ///< (τ entry, W column) of the actuators on the wheels' paths
  std::vector<bool> depends_{};
  /// The block elimination of A_D: each base row n (a wheel's row left after its own joints are
  /// eliminated) is row n − Σ G row P, each own dependent joint Σ Pinv row P − H x_b.
  std::vector<detail::elim_eq<Sc>> base_eqs_{}, own_eqs_{};
  std::vector<int> Db_{}, Db_pos_{};              ///< the base's dependent joints: W column, position in D
  int kb_ = 0;                                    ///< |Db_|
  /// Wheels on one planar body (prepare_body_kernel): ψ's node (−1: the general kernel), the
  /// prismatic nodes above it; per row u at q = 0, its steering node (or −1), d_β and the
  /// constant part of ψ's column; A at q = 0 (k × |W|, column-major).
  int body_yaw_ = -1;
  std::vector<int> body_prism_{}, body_steer_{};
  std::vector<detail::vec2<Sc>> body_u0_{}, body_ds_{};
  std::vector<Sc> body_c_{}, body_a0_{};
  /// The base's Schur block on one body, when it is K₀ T(ψ) (prepare_body_base_block): K₀⁻¹
  /// (kb × kb, column-major; empty: the per-q LU), the positions in D_b of the two prismatic
  /// columns (or −1).
  std::vector<Sc> body_kinv_{};
  std::array<int, 2> body_kpos_{-1, -1};
  /// No wheel steered (prepare_body_rigid): S_D0 (k × |η ∩ W|), A_D0⁻¹ (k × k, D's order by A's
  /// rows), P₀ (p_W × |η ∩ W|), all column-major; the prismatic pair's positions in D and in η ∩ W.
  bool body_rigid_ = false;
  std::vector<Sc> body_sd0_{}, body_adinv_{}, body_act0_{};
  std::array<int, 2> body_dpair_{-1, -1}, body_ipair_{-1, -1};
  bool act_is_eta_ = false;  ///< the actuators are η's joints in η's order: SᵀE = I
  bool built_ = false;       ///< the constructor has finished (its own copies, made before, are not)
  int mobility_ = 0, steerability_ = 0, base_joints_ = 0;
};

template <class Sc>
template <class U>
Eigen::VectorXd wheeled_base<Sc>::generic_q(const wheeled_base<U>& c, int which) {
  // every angle the rows depend on at a value with no special relation to the others
  Eigen::VectorXd q = Eigen::VectorXd::Zero(c.n_);
  int i = 0;
  for (int j = 0; j < c.n_; ++j)
    if (c.depends_[std::size_t(j)]) q(j) = (which == 0 ? 0.3711 : -1.2093) + (which == 0 ? 0.8377 : 1.4431) * ++i;
  return q;
}

template <class Sc>
void wheeled_base<Sc>::build(const tree<Sc>& t, const wheeled_base_options& o) {
  const std::string top = "wheeled_base: ";
  if (wheels_.empty()) throw model_error(top + "no wheels");
  const int nwh = static_cast<int>(wheels_.size());
  // Each wheel's joints, checked by kind.
  std::vector<int> steer_joint(std::size_t(nwh), -1);
  std::vector<int> owner(std::size_t(n_), -1);  // which wheel a joint belongs to
  for (int w = 0; w < nwh; ++w) {
    const wheel& wh = wheels_[std::size_t(w)];
    const std::string at = top + "wheel " + std::to_string(w) + " (" + to_string(wh.kind) + ", spin '" + wh.spin + "'): ";
    const int s = joint_index(wh.spin, at + "spin: ");
    if (t[s].joint != joint_type::revolute) throw model_error(at + "the spin joint '" + wh.spin + "' is prismatic");
    if (!(std::isfinite(wh.radius) && wh.radius > 0))
      throw model_error(at + "the radius must be positive and finite, not " + std::to_string(wh.radius));
    const bool needs_steer = wh.kind == wheel_kind::steered || wh.kind == wheel_kind::castor;
    const char* steer_word = wh.kind == wheel_kind::castor ? "swivel" : "steer";
    if (needs_steer && wh.steer.empty()) throw model_error(at + "a " + to_string(wh.kind) + " wheel needs its " + steer_word + " joint");
    if (!needs_steer && !wh.steer.empty())
      throw model_error(at + "a " + to_string(wh.kind) + " wheel has no steer or swivel joint ('" + wh.steer + "' given)");
    if (wh.kind == wheel_kind::swedish) {
      const double g = wh.roller_angle;
      if (!(std::isfinite(g) && std::abs(g) > 1e-9 && std::abs(g) <= std::numbers::pi / 2 + 1e-12))
        throw model_error(at + "roller_angle must be within ±90° and not 0 (rollers along the spin axis do not roll), not " +
                          std::to_string(g * 180 / std::numbers::pi) + "°");
    } else if (wh.roller_angle != 0) {
      throw model_error(at + "roller_angle is for swedish wheels");
    }
    if (owner[std::size_t(s)] >= 0) throw model_error(at + "joint '" + wh.spin + "' belongs to another wheel too");
    owner[std::size_t(s)] = w;
    if (needs_steer) {
      const int b = joint_index(wh.steer, at + steer_word + ": ");
      if (t[b].joint != joint_type::revolute) throw model_error(at + "the " + steer_word + " joint '" + wh.steer + "' is prismatic");
      if (owner[std::size_t(b)] >= 0) throw model_error(at + "joint '" + wh.steer + "' belongs to another wheel too");
      if (!t.supports(b, s))
        throw model_error(at + "the " + steer_word + " joint '" + wh.steer + "' does not carry the spin joint '" + wh.spin + "'");
      owner[std::size_t(b)] = w;
      steer_joint[std::size_t(w)] = b;
    }
  }
  // The wheels' paths: every joint from the world to each spin joint.
  std::vector<bool> onpath(std::size_t(n_), false);
  for (int w = 0; w < nwh; ++w)
    for (int j = joint_index(wheels_[std::size_t(w)].spin, ""); j >= 0; j = t.parent(j)) onpath[std::size_t(j)] = true;
  for (int j = 0; j < n_; ++j)
    if (onpath[std::size_t(j)]) W_.push_back(j);
  std::vector<int> node_of(std::size_t(n_), -1);
  for (int i = 0; i < nw(); ++i) node_of[std::size_t(W_[std::size_t(i)])] = i;
  const auto links = detail::make_tree_links(t);
  std::vector<detail::wheel_path_node<double>> nodes3;  // the 3-D kernel frames, for the checks and the plane nodes
  for (int i = 0; i < nw(); ++i) {
    const int j = W_[std::size_t(i)];
    const auto& L = links[std::size_t(j)];
    detail::wheel_path_node<double> nd;
    nd.joint = j;
    nd.parent = L.parent < 0 ? -1 : node_of[std::size_t(L.parent)];
    nd.revolute = L.revolute;
    nd.spin = owner[std::size_t(j)] >= 0 && joint_index(wheels_[std::size_t(owner[std::size_t(j)])].spin, "") == j;
    nd.R = detail::value_matrix(L.R);
    for (int r = 0; r < 3; ++r) nd.p(r) = value_of(L.p(r));
    nodes3.push_back(nd);
  }
  // A spin joint carries nothing A sees; a wheel's path holds the base's joints and its own.
  base_joints_ = 0;
  for (int i = 0; i < nw(); ++i) {
    const int j = W_[std::size_t(i)];
    if (owner[std::size_t(j)] < 0) ++base_joints_;
    if (nodes3[std::size_t(i)].spin)
      for (int c : t.children(j))
        if (onpath[std::size_t(c)])
          throw model_error(top + "joint '" + names_[std::size_t(c)] + "' lies after the spin joint '" + names_[std::size_t(j)] +
                            "' on another wheel's path: a wheel cannot carry a wheel");
  }
  depends_.assign(std::size_t(n_), false);
  for (int i = 0; i < nw(); ++i)
    depends_[std::size_t(W_[std::size_t(i)])] = nodes3[std::size_t(i)].revolute && !nodes3[std::size_t(i)].spin;
  for (int w = 0; w < nwh; ++w) {
    const int s = joint_index(wheels_[std::size_t(w)].spin, "");
    spin_joint_.push_back(s);
    std::vector<int> path;
    for (int j = s; j >= 0; j = t.parent(j)) {
      if (owner[std::size_t(j)] >= 0 && owner[std::size_t(j)] != w)
        throw model_error(top + "wheel " + std::to_string(w) + " (spin '" + wheels_[std::size_t(w)].spin + "'): joint '" +
                          names_[std::size_t(j)] + "' of another wheel lies on its path");
      path.push_back(node_of[std::size_t(j)]);
    }
    std::reverse(path.begin(), path.end());
    paths_.push_back(path);
    radius_.push_back(Sc(wheels_[std::size_t(w)].radius));
    cos_gamma_.push_back(Sc(std::cos(wheels_[std::size_t(w)].roller_angle)));
    sin_gamma_.push_back(Sc(std::sin(wheels_[std::size_t(w)].roller_angle)));
  }
  // All rows, then the geometry's checks at two generic configurations and q = 0.
  for (int w = 0; w < nwh; ++w) {
    if (wheels_[std::size_t(w)].kind == wheel_kind::swedish) {
      rows_.push_back({w, wheel_row::roller});
    } else {
      rows_.push_back({w, wheel_row::lateral});
      rows_.push_back({w, wheel_row::rolling});
    }
  }
  const auto node_rows = [&] {
    row_node_.clear();
    for (const auto& r : rows_) row_node_.push_back(node_of[std::size_t(spin_joint_[std::size_t(r.wheel)])]);
  };
  node_rows();
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(n_), qg[2] = {generic_q(*this, 0), generic_q(*this, 1)};
  struct pose3 {
    Eigen::Matrix3d R;
    Eigen::Vector3d o;
  };
  const auto value_poses = [&](const Eigen::VectorXd& q) {
    std::vector<pose3> X;
    for (const auto& [R, o] : detail::path_poses(nodes3, q)) X.push_back({R, o});
    return X;
  };
  for (const Eigen::VectorXd* q : {&q0, &qg[0], &qg[1]}) {
    const auto X = value_poses(*q);
    for (int w = 0; w < nwh; ++w) {
      const wheel& wh = wheels_[std::size_t(w)];
      const std::string at = top + "wheel " + std::to_string(w) + " (" + to_string(wh.kind) + ", spin '" + wh.spin + "'): ";
      const auto& xs = X[std::size_t(node_of[std::size_t(spin_joint_[std::size_t(w)])])];
      const Eigen::Vector3d a = xs.R.col(2);
      if (std::abs(a.z()) > 1e-3) {
        std::ostringstream os;
        os << at << "the spin joint's axis is (" << a.x() << ", " << a.y() << ", " << a.z() << ") in the world, not horizontal";
        throw model_error(os.str());
      }
      if (steer_joint[std::size_t(w)] >= 0) {
        const Eigen::Vector3d b = X[std::size_t(node_of[std::size_t(steer_joint[std::size_t(w)])])].R.col(2);
        if (std::abs(std::abs(b.z()) - 1) > 1e-6) {
          std::ostringstream os;
          os << at << "the " << (wh.kind == wheel_kind::castor ? "swivel" : "steer") << " joint '" << wh.steer
             << "' has axis (" << b.x() << ", " << b.y() << ", " << b.z() << ") in the world, not vertical";
          throw model_error(os.str());
        }
      }
      for (const int j : paths_[std::size_t(w)]) {
        const int jj = W_[std::size_t(j)];
        if (owner[std::size_t(jj)] == w) continue;
        const Eigen::Vector3d z = X[std::size_t(j)].R.col(2);
        const bool ok = nodes3[std::size_t(j)].revolute ? std::abs(std::abs(z.z()) - 1) < 1e-6 : std::abs(z.z()) < 1e-6;
        if (!ok)
          throw model_error(at + "joint '" + names_[std::size_t(jj)] + "' on the wheel's path moves it off the floor plane "
                                 "(a wheeled base's joints are planar: translations along the floor, turns about vertical axes)");
      }
      if (q == &q0) {
        if (std::abs(a.z()) > 1e-9) {
          std::ostringstream os;
          os << at << "the spin axis is " << a.z() << " off horizontal; taken as it is";
          warn(o, os.str());
        }
        const double h = xs.o.z();
        if (std::abs(h - wh.radius) > 1e-3 * std::max(1.0, wh.radius)) {
          std::ostringstream os;
          os << at << "the wheel centre is " << h << " m above the floor z = 0 and the radius is " << wh.radius
             << " m: the wheel does not touch the floor (the constraint keeps the point r below the centre from slipping)";
          warn(o, os.str());
        }
        if (wh.kind == wheel_kind::castor) {
          // the castor's own block [ℓ·(e_z × d), 0; f·(e_z × d), −r] has determinant −r (d·f): the
          // trail d (swivel axis to contact point) must reach along the rolling direction f
          const Eigen::Vector3d d = xs.o - X[std::size_t(node_of[std::size_t(steer_joint[std::size_t(w)])])].o;
          const Eigen::Vector3d f = a.cross(Eigen::Vector3d::UnitZ()).normalized();
          if (std::abs(d.dot(f)) < 1e-6) {
            std::ostringstream os;
            os << at << "the wheel centre is " << std::abs(d.dot(f)) << " m from the swivel axis of '" << wh.steer
               << "' along the rolling direction (no trail): a castor needs its wheel behind the swivel axis; a wheel "
                  "turned about its own centre is 'steered'";
            throw model_error(os.str());
          }
        }
      }
    }
  }
  // The plane nodes: each path joint's constants at q = 0, where every heading is 0 (offsets
  // and axes in the world are then in the parent's heading frame); axes within the checks'
  // tolerance of vertical or horizontal are taken as exactly so.
  {
    const auto X0 = value_poses(q0);
    for (int i = 0; i < nw(); ++i) {
      const auto& nd = nodes3[std::size_t(i)];
      detail::plane_node<Sc> pn;
      pn.joint = nd.joint, pn.parent = nd.parent, pn.revolute = nd.revolute, pn.spin = nd.spin;
      const Eigen::Vector3d z = X0[std::size_t(i)].R.col(2);
      const Eigen::Vector3d d = X0[std::size_t(i)].o - (nd.parent < 0 ? Eigen::Vector3d::Zero() : X0[std::size_t(nd.parent)].o);
      pn.D = detail::vec2<Sc>(Sc(d.x()), Sc(d.y()));
      if (nd.spin) {
        pn.axis = detail::vec2<Sc>(Sc(z.x()), Sc(z.y()));
        pn.inv_len = Sc(1 / std::hypot(z.x(), z.y()));
      } else if (nd.revolute) {
        pn.sign = Sc(z.z() > 0 ? 1 : -1);
      } else {
        const double h = std::hypot(z.x(), z.y());
        pn.axis = detail::vec2<Sc>(Sc(z.x() / h), Sc(z.y() / h));
      }
      plane_.push_back(pn);
    }
  }
  // Dependent rows: modified Gram–Schmidt in row order at the first generic configuration,
  // checked at the second.
  const auto rows_value = [&](const Eigen::VectorXd& q) {
    Eigen::MatrixXd a(k(), nw());
    cast<double>().rows_at(q, a.data());
    return a;
  };
  const Eigen::MatrixXd all_rows = rows_value(qg[0]);  // every row, before any is dropped
  const std::vector<detail::wheel_row_info> all_info = rows_;
  {
    std::vector<bool> keep_row(rows_.size(), false);
    const Eigen::MatrixXd a1 = rows_value(qg[1]);
    for (int g = 0; g < 2; ++g) {
      const Eigen::MatrixXd& a = g == 0 ? all_rows : a1;
      std::vector<Eigen::VectorXd> basis;
      for (int r = 0; r < k(); ++r) {
        Eigen::VectorXd v = a.row(r).transpose();
        const double norm = v.norm();
        for (const auto& b : basis) v -= b.dot(v) * b;
        const bool independent = v.norm() > row_tolerance * std::max(norm, 1e-300);
        if (g == 0) keep_row[std::size_t(r)] = independent;
        if (independent != keep_row[std::size_t(r)]) {
          const auto& ri = rows_[std::size_t(r)];
          throw model_error(top + "the " + (ri.kind == wheel_row::lateral ? "lateral" : ri.kind == wheel_row::rolling ? "rolling" : "roller") +
                            " constraint of wheel '" + wheels_[std::size_t(ri.wheel)].spin +
                            "' depends on the other wheels' at some configurations only: the wheels' layout is degenerate");
        }
        if (independent) basis.push_back(v / v.norm());
      }
    }
    std::vector<detail::wheel_row_info> kept;
    for (std::size_t r = 0; r < rows_.size(); ++r)
      if (keep_row[r]) kept.push_back(rows_[r]);
    rows_ = kept;
    node_rows();
  }
  const int kk = k();
  if (kk == 0) throw model_error(top + "the wheels constrain nothing");
  // Campion's degrees: δm = (the base's joints) − rank of the fixed and steered wheels' lateral
  // rows on the base's columns; δs = the rank of the steered wheels' lateral rows there.
  {
    std::vector<int> base_cols;
    for (int i = 0; i < nw(); ++i)
      if (owner[std::size_t(W_[std::size_t(i)])] < 0) base_cols.push_back(i);
    const auto rank_of = [&](bool steered_only) {
      std::vector<int> rs;
      for (std::size_t r = 0; r < all_info.size(); ++r) {
        const auto kind = wheels_[std::size_t(all_info[r].wheel)].kind;
        if (all_info[r].kind == wheel_row::lateral && (kind == wheel_kind::steered || (!steered_only && kind == wheel_kind::fixed)))
          rs.push_back(static_cast<int>(r));
      }
      if (rs.empty() || base_cols.empty()) return 0;
      Eigen::MatrixXd M(Eigen::Index(rs.size()), Eigen::Index(base_cols.size()));
      for (std::size_t r = 0; r < rs.size(); ++r)
        for (std::size_t c = 0; c < base_cols.size(); ++c) M(Eigen::Index(r), Eigen::Index(c)) = all_rows(rs[r], base_cols[c]);
      const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(M).singularValues();
      int rank = 0;
      for (Eigen::Index i = 0; i < s.size(); ++i) rank += s(i) > row_tolerance * std::max(1.0, s(0));
      return rank;
    };
    mobility_ = static_cast<int>(base_cols.size()) - rank_of(false);
    steerability_ = rank_of(true);
  }
  // η: the option's joints, or the rule's; D the wheel-path joints not in η.
  std::vector<bool> in_eta(std::size_t(n_), false);
  if (!o.eta.empty()) {
    for (const auto& name : o.eta) {
      const int j = joint_index(name, top + "eta: ");
      if (in_eta[std::size_t(j)]) throw model_error(top + "eta: joint '" + name + "' twice");
      in_eta[std::size_t(j)] = true;
      eta_.push_back(j);
    }
    if (static_cast<int>(eta_.size()) != n_ - kk) {
      std::ostringstream os;
      os << top << "eta has " << eta_.size() << " entries; the wheels leave m = n − k = " << n_ << " − " << kk << " = "
         << n_ - kk << " independent velocities";
      throw model_error(os.str());
    }
    for (int j = 0; j < n_; ++j)
      if (!onpath[std::size_t(j)] && !in_eta[std::size_t(j)])
        throw model_error(top + "eta: joint '" + names_[std::size_t(j)] +
                          "' is not in eta, and no wheel determines its rate (it is on no wheel's path)");
  } else {
    const Eigen::MatrixXd a = rows_value(qg[0]);
    std::vector<int> order;  // W columns in the rule's priority
    const auto add = [&](auto pred) {
      for (int i = 0; i < nw(); ++i)
        if (pred(W_[std::size_t(i)]) && std::find(order.begin(), order.end(), i) == order.end()) order.push_back(i);
    };
    const auto kind_of = [&](int j) { return owner[std::size_t(j)] < 0 ? -1 : int(wheels_[std::size_t(owner[std::size_t(j)])].kind); };
    const auto is_spin = [&](int j) { return owner[std::size_t(j)] >= 0 && spin_joint_[std::size_t(owner[std::size_t(j)])] == j; };
    add([&](int j) { return kind_of(j) == int(wheel_kind::castor) || (kind_of(j) == int(wheel_kind::swedish) && is_spin(j)); });
    add([&](int j) { return owner[std::size_t(j)] < 0; });
    for (int w = 0; w < nwh; ++w) {  // spin joints in the wheels' order
      const auto kind = wheels_[std::size_t(w)].kind;
      if (kind == wheel_kind::fixed || kind == wheel_kind::steered) add([&](int j) { return j == spin_joint_[std::size_t(w)]; });
    }
    add([](int) { return true; });
    std::vector<Eigen::VectorXd> basis;
    std::vector<bool> dep(std::size_t(nw()), false);
    for (const int i : order) {
      if (static_cast<int>(basis.size()) == kk) break;
      Eigen::VectorXd v = a.col(i);
      const double norm = v.norm();
      for (const auto& b : basis) v -= b.dot(v) * b;
      if (v.norm() > row_tolerance * std::max(norm, 1e-300) && norm > 0) {
        basis.push_back(v / v.norm());
        dep[std::size_t(i)] = true;
      }
    }
    for (int i = 0; i < nw(); ++i)
      if (!dep[std::size_t(i)]) in_eta[std::size_t(W_[std::size_t(i)])] = true;
    for (int j = 0; j < n_; ++j)
      if (!onpath[std::size_t(j)]) in_eta[std::size_t(j)] = true;
    for (int j = 0; j < n_; ++j)
      if (in_eta[std::size_t(j)]) eta_.push_back(j);
  }
  std::vector<int> eta_col(std::size_t(n_), -1);
  for (std::size_t c = 0; c < eta_.size(); ++c) eta_col[std::size_t(eta_[c])] = static_cast<int>(c);
  dcol_.assign(std::size_t(nw()), -1);
  icol_.assign(std::size_t(nw()), -1);
  for (int i = 0; i < nw(); ++i) {
    const int j = W_[std::size_t(i)];
    if (in_eta[std::size_t(j)]) {
      icol_[std::size_t(i)] = static_cast<int>(I_.size());
      I_.push_back(i);
      Icol_.push_back(eta_col[std::size_t(j)]);
    } else {
      dcol_[std::size_t(i)] = static_cast<int>(D_.size());
      D_.push_back(i);
      Dq_.push_back(j);
    }
  }
  // η must determine the motion at generic configurations (else it never does).
  for (const auto& q : qg) {
    const Eigen::MatrixXd a = rows_value(q);
    Eigen::MatrixXd AD(kk, kk);
    for (int d = 0; d < kk; ++d) AD.col(d) = a.col(D_[std::size_t(d)]);
    std::vector<int> perm(static_cast<std::size_t>(kk));
    if (detail::lu_in_place(AD.data(), kk, perm.data()) < singular_tolerance) {
      std::string dep;
      for (int d : D_) dep += (dep.empty() ? "" : ", ") + names_[std::size_t(W_[std::size_t(d)])];
      throw model_error(top + "the velocities in eta are not independent, or do not determine the others (" + dep +
                        "), at generic configurations (so almost nowhere): choose eta among the joints the wheels leave free");
    }
  }
  // The elimination: each wheel's own dependent joints appear only in its rows, with constant
  // coefficients (its rows and its own joints' columns turn together; checked at the two
  // generic configurations), eliminated by a pivot block of its rows; its other rows, and the
  // wheels' without own dependent joints, constrain the base's dependent joints (K).
  {
    const Eigen::MatrixXd a0 = rows_value(qg[0]), a1 = rows_value(qg[1]);
    for (int d = 0; d < kk; ++d)
      if (owner[std::size_t(W_[std::size_t(D_[std::size_t(d)])])] < 0) Db_.push_back(D_[std::size_t(d)]), Db_pos_.push_back(d);
    kb_ = static_cast<int>(Db_.size());
    for (const auto& path : paths_) {  // the columns the kernel reads: η's and the base's dependent joints'
      std::vector<int> read;
      for (const int j : path)
        if (icol_[std::size_t(j)] >= 0 || owner[std::size_t(W_[std::size_t(j)])] < 0) read.push_back(j);
      read_paths_.push_back(read);
    }
    int base_row = 0;
    for (int w = 0; w < nwh; ++w) {
      struct {
        std::vector<int> P, N, own;
      } e;
      std::vector<int> rw;
      for (int r = 0; r < kk; ++r)
        if (rows_[std::size_t(r)].wheel == w) rw.push_back(r);
      for (int d = 0; d < kk; ++d)
        if (owner[std::size_t(W_[std::size_t(D_[std::size_t(d)])])] == w) e.own.push_back(d);
      const int nd = static_cast<int>(e.own.size()), nr = static_cast<int>(rw.size());
      Eigen::MatrixXd Cw(nr, nd);
      for (int r = 0; r < nr; ++r)
        for (int j = 0; j < nd; ++j) {
          const int col = D_[std::size_t(e.own[std::size_t(j)])];
          Cw(r, j) = a0(rw[std::size_t(r)], col);
          if (std::abs(a1(rw[std::size_t(r)], col) - Cw(r, j)) > 1e-12 * (1 + std::abs(Cw(r, j))))
            throw model_error(top + "wheel " + std::to_string(w) + " (spin '" + wheels_[std::size_t(w)].spin +
                              "'): its own joints' coefficients change with the configuration: a joint between its steering or "
                              "swivel joint and its spin joint, or an axis that is not vertical");
        }
      // the pivot rows: the d of its rows whose block has the largest |det| (d ≤ 2)
      std::vector<int> best;
      double best_det = 0;
      const auto consider = [&](std::vector<int> P) {
        Eigen::MatrixXd B(nd, nd);
        for (int i = 0; i < nd; ++i) B.row(i) = Cw.row(P[std::size_t(i)]);
        const double det = nd == 0 ? 1.0 : std::abs(B.determinant());
        if (det > best_det) best_det = det, best = P;
      };
      if (nd > nr) best_det = 0;
      else if (nd == 0) consider({});
      else if (nd == 1) for (int r = 0; r < nr; ++r) consider({r});
      else if (nd == 2) for (int r = 0; r < nr; ++r) for (int r2 = r + 1; r2 < nr; ++r2) consider({r, r2});
      if (!(best_det > 1e-12)) {
        std::string joints;
        for (int d : e.own) joints += (joints.empty() ? "" : ", ") + names_[std::size_t(W_[std::size_t(D_[std::size_t(d)])])];
        throw model_error(top + "wheel " + std::to_string(w) + " (spin '" + wheels_[std::size_t(w)].spin + "'): its rows do not determine " +
                          joints + ": choose eta so that they are");
      }
      Eigen::MatrixXd CP(nd, nd), CN(nr - nd, nd);
      std::vector<bool> is_p(std::size_t(nr), false);
      for (int i = 0; i < nd; ++i) is_p[std::size_t(best[std::size_t(i)])] = true;
      for (int i = 0; i < nd; ++i) CP.row(i) = Cw.row(best[std::size_t(i)]), e.P.push_back(rw[std::size_t(best[std::size_t(i)])]);
      for (int r = 0, nn = 0; r < nr; ++r)
        if (!is_p[std::size_t(r)]) {
          if (nd > 0) CN.row(nn) = Cw.row(r);  // a row of a 0-column matrix has no storage to point at
          ++nn, e.N.push_back(rw[std::size_t(r)]);
        }
      const Eigen::MatrixXd Pinv = nd ? Eigen::MatrixXd(CP.inverse()) : Eigen::MatrixXd(0, 0), G = CN * Pinv;
      for (std::size_t nn = 0; nn < e.N.size(); ++nn) {  // base row: row N − Σ G row P
        detail::elim_eq<Sc> eq;
        eq.row = e.N[nn], eq.d = nd;
        for (int t = 0; t < nd; ++t) eq.P[t] = e.P[std::size_t(t)], eq.coef[t] = Sc(G(Eigen::Index(nn), t));
        base_eqs_.push_back(eq);
      }
      for (int pp = 0; pp < nd; ++pp) {  // own dependent joint: Σ Pinv row P (− H x_b)
        detail::elim_eq<Sc> eq;
        eq.row = e.own[std::size_t(pp)], eq.d = nd;
        for (int t = 0; t < nd; ++t) eq.P[t] = e.P[std::size_t(t)], eq.coef[t] = Sc(Pinv(pp, t));
        own_eqs_.push_back(eq);
      }
      base_row += static_cast<int>(e.N.size());
    }
    if (base_row != kb_)
      throw model_error(top + "the velocities in eta are not independent, or do not determine the others: the wheels leave " +
                        std::to_string(base_row) + " conditions on the base's " + std::to_string(kb_) + " dependent velocities");
  }
  // Actuators: the option's joints, or every joint but the base's and the castors'.
  std::vector<bool> is_act(std::size_t(n_), false);
  if (!o.actuated.empty()) {
    for (const auto& name : o.actuated) {
      const int j = joint_index(name, top + "actuated: ");
      if (is_act[std::size_t(j)]) throw model_error(top + "actuated: joint '" + name + "' twice");
      is_act[std::size_t(j)] = true;
      act_.push_back(j);
    }
  } else {
    for (int j = 0; j < n_; ++j) {
      const bool base = onpath[std::size_t(j)] && owner[std::size_t(j)] < 0;
      const bool castor = owner[std::size_t(j)] >= 0 && wheels_[std::size_t(owner[std::size_t(j)])].kind == wheel_kind::castor;
      if (!base && !castor) act_.push_back(j), is_act[std::size_t(j)] = true;
    }
  }
  weights_.assign(act_.size(), 1.0);
  for (const auto& [name, w] : o.weights) {
    const int j = joint_index(name, top + "weights: ");
    const auto it = std::find(act_.begin(), act_.end(), j);
    if (it == act_.end()) throw model_error(top + "weights: joint '" + name + "' is not actuated");
    if (!(std::isfinite(w) && w > 0)) throw model_error(top + "weights: the weight of '" + name + "' must be positive and finite");
    weights_[std::size_t(it - act_.begin())] = w;
  }
  // τ's structure: an actuator whose S row is a unit (a joint in η off the wheels' paths) takes
  // its η entry's force; the others (wheel-path joints) share η's wheel-path block.
  for (std::size_t a = 0; a < act_.size(); ++a) {
    const int j = act_[a];
    if (!onpath[std::size_t(j)]) {
      act_eta_.push_back({static_cast<int>(a), eta_col[std::size_t(j)]});
    } else {
      actw_.push_back({static_cast<int>(a), node_of[std::size_t(j)]});
    }
  }
  act_is_eta_ = act_ == eta_;
  for (const auto& [a, w] : actw_) inv_weight_w_.push_back(1 / weights_[std::size_t(a)]);
  // Every η entry off the wheels' paths needs its own actuator.
  for (const int j : eta_)
    if (!onpath[std::size_t(j)] && !is_act[std::size_t(j)])
      throw model_error(top + "joint '" + names_[std::size_t(j)] +
                        "' is in eta but not actuated, and no other actuator moves it: its motion cannot be produced");
  if (mw() > pw())
    throw model_error(top + "the wheels leave " + std::to_string(mw()) + " velocities of the base and wheels free (" +
                      [&] {
                        std::string s;
                        for (int i : I_) s += (s.empty() ? "" : ", ") + names_[std::size_t(W_[std::size_t(i)])];
                        return s;
                      }() +
                      ") but only " + std::to_string(pw()) + " actuated joints act on them: the actuators cannot produce every motion");
  // …and the wheel-path actuators must drive η's wheel-path block at generic configurations.
  if (mw() > 0) {
    for (const auto& q : qg) {
      try {
        (void)cast<double>().solve_actuation(q, Eigen::MatrixXd(Eigen::MatrixXd::Zero(m(), 1)));
      } catch (const numerical_error& e) {
        throw model_error(e.what());
      }
    }
  }
  built_ = true;
  prepare_body_kernel();
}

}  // namespace nhdyn
