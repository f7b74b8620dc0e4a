#pragma once
/// \file model/floating.hpp
/// A floating base (a free-flyer root): a tree whose root link moves freely in space, as a
/// humanoid's pelvis, a quadruped's trunk, a wheeled-legged robot's body. Pinocchio's layout
/// and conventions (JointModelFreeFlyer), so that numbers compare entry for entry:
///
///     q = (x, y, z, qx, qy, qz, qw, q_joints)    nq = nv + 1: the root frame B's origin in the
///                                                world W and its unit quaternion (Hamilton)
///     v = (v_B, ω_B, q̇_joints)                   nv: B's spatial velocity in B's own axes, the
///                                                velocity of B's origin, then the angular one
///     a = (v̇_B, ω̇_B, q̈_joints)                  the derivative of v's entries
///     τ = (f_B, n_B, τ_joints)                    the wrench the root would need: force, then
///                                                moment about B's origin, in B's axes
///
/// World-frame velocities: ṗ_WB = R_WB v_B, ω_W = R_WB ω_B (world_velocity, body_velocity).
/// Configurations are added and subtracted on the manifold as Pinocchio does (SE(3), the
/// exponential in B's frame): integrate(q, v) = q ⊕ v with X_WB' = X_WB exp(v) (v already
/// multiplied by the step), difference(q0, q1) = log(X_WB0⁻¹ X_WB1), joints by + and −.
///
/// How every algorithm runs on it. In the tree the floating base is six bodies in front of the
/// root link, flagged `free_flyer`: root_x, root_y, root_z slide along B's axes, root_rx,
/// root_ry, root_rz turn about them, the last carries the root link. The algorithms evaluate
/// them *at zero*, in B's frame at this instant: there the six joints' frames coincide with B,
/// their motion subspaces are the six unit twists, and the robot is a fixed-base tree whose
/// base frame is B with
///
///     q_K = (0₆, q_joints)        the six coordinates at zero
///     q̇_K = v                     (at zero the six joints' rates are v_B and ω_B exactly)
///     q̈_K = a − (b(v), 0)          b: the six joints' velocity-product acceleration at zero,
///                                  b(v) = (v_B × ω_B, (ω_y ω_z, −ω_x ω_z, ω_x ω_y))
///     g_K = R_WBᵀ g                gravity in B's axes: the one place the root's pose enters
///
/// so that rne, CRBA, ABA, the derivatives and the kinematics of any fixed-base tree compute
/// the floating robot's, in any scalar, and the six joints' τ is the root's wrench (the six
/// frames coincide, so each transmits the root's whole wrench). Nothing here is an
/// approximation: at zero the map is exact, and the root's pose never passes through the six
/// joints' angles (no Euler-angle singularity). tests/test_floating.cpp checks every algorithm
/// against a plain 6-DoF joint (S = 1₆) and against a world-fixed chain of six joints.
#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "../errors.hpp"
#include "../scalar/traits.hpp"
#include "chain.hpp"
#include "tree.hpp"

namespace nhdyn {

/// The names of the floating base's six velocity coordinates (v's and τ's first entries).
inline const std::vector<std::string>& free_flyer_joint_names() {
  static const std::vector<std::string> names{"root_x", "root_y", "root_z", "root_rx", "root_ry", "root_rz"};
  return names;
}

/// The six bodies of a floating base (model/tree.hpp's form): massless but the last, which is
/// the root link `root_link` (give it the root link's inertia); append the robot's bodies after
/// them, each with a parent of 5 or more.
template <class S = double>
std::vector<body<S>> free_flyer_bodies(const std::string& root_link) {
  std::vector<body<S>> out(6);
  const auto& names = free_flyer_joint_names();
  for (int i = 0; i < 6; ++i) {
    auto& b = out[static_cast<std::size_t>(i)];
    b.name = i == 5 ? root_link : names[static_cast<std::size_t>(i)] + "_link";
    b.joint_name = names[static_cast<std::size_t>(i)];
    b.parent = i - 1;
    b.joint = i < 3 ? joint_type::prismatic : joint_type::revolute;
    b.continuous = i >= 3;
    b.axis = vec3<S>::Zero();
    b.axis(i % 3) = S(1);
    b.free_flyer = true;
  }
  return out;
}

/// The tree t with a floating root: t's base becomes a free body (its name, `root_link`'s
/// mass m, centre of mass c and inertia Ic about c, in the base frame), t's bodies attached to
/// the base hang from it, and the frames on the base move with it. Gravity and names carry over.
template <class S>
tree<S> make_floating(const tree<S>& t, const S& m, const vec3<S>& c, const mat3<S>& Ic) {
  if (t.floating()) throw model_error("model '" + t.name() + "': make_floating: the tree floats already");
  std::vector<body<S>> bodies = free_flyer_bodies<S>(t.root_name());
  bodies[5].mass = m;
  bodies[5].com = c;
  bodies[5].inertia = Ic;
  for (const auto& b : t.bodies()) {
    body<S> x = b;
    x.parent = b.parent < 0 ? 5 : b.parent + 6;
    bodies.push_back(std::move(x));
  }
  std::vector<frame<S>> frames;
  for (auto f : t.frames()) {
    f.body = (f.body) < 0 ? 5 : (f.body) + 6;  // (f.body): clang 14 reads `f.body <` as body<…>
    frames.push_back(std::move(f));
  }
  return tree<S>(std::move(bodies), t.gravity(), t.name(), t.validation_policy(), "world", std::move(frames));
}

namespace detail {

/// R(x, y, z, w) of a unit quaternion (Hamilton's convention, Eigen's and Pinocchio's).
template <class T>
mat3<T> quaternion_matrix(const T& x, const T& y, const T& z, const T& w) {
  mat3<T> R;
  const T two(2);
  R << T(1) - two * (y * y + z * z), two * (x * y - z * w), two * (x * z + y * w),  //
      two * (x * y + z * w), T(1) - two * (x * x + z * z), two * (y * z - x * w),    //
      two * (x * z - y * w), two * (y * z + x * w), T(1) - two * (x * x + y * y);
  return R;
}

/// R_WB of a floating tree's configuration q (its entries 3…6).
template <class T, class Q>
mat3<T> root_rotation(const Q& q) {
  return quaternion_matrix<T>(T(q(3)), T(q(4)), T(q(5)), T(q(6)));
}

/// How far a quaternion's norm may be from 1 [relative]: a quaternion normalised in double and
/// written with 9 or more digits passes; one typed by hand to 4 digits does not.
inline constexpr double quaternion_tolerance = 1e-6;

[[noreturn, gnu::cold, gnu::noinline]] inline void throw_quaternion(double norm, const char* what) {
  std::ostringstream os;
  os.precision(17);
  os << what << "[3..6]: the root's quaternion (qx, qy, qz, qw) has norm " << norm
     << ", not 1 (to within " << quaternion_tolerance << "); normalise it";
  throw input_error(os.str());
}

/// Checks a floating tree's configuration: nq entries, finite, a unit quaternion.
template <class Q>
void check_floating_configuration(const Q& q, int nq, const char* what) {
  check_size(q, nq, what);
  check_finite(q, what);
  double s = 0;
  for (int i = 3; i < 7; ++i) s += value_of(q(i)) * value_of(q(i));
  if (!(std::abs(std::sqrt(s) - 1) <= quaternion_tolerance)) throw_quaternion(std::sqrt(s), what);
}

/// q_K = (0₆, q_joints): q's trunk-frame form (the file comment), into qk (nv entries).
template <class Q, class QK>
void trunk_configuration(const Q& q, QK& qk) {
  using T = typename QK::Scalar;
  for (int i = 0; i < 6; ++i) qk(i) = T(0);
  for (Eigen::Index i = 6; i < qk.size(); ++i) qk(i) = T(q(i + 1));
}

/// a(0…5) −= b(v): the six joints' velocity-product acceleration at zero (the file comment).
template <class V, class A>
void subtract_root_bias(const V& v, A& a) {
  using T = typename A::Scalar;
  const T vx = T(v(0)), vy = T(v(1)), vz = T(v(2)), wx = T(v(3)), wy = T(v(4)), wz = T(v(5));
  a(0) -= vy * wz - vz * wy;  // v × ω
  a(1) -= vz * wx - vx * wz;
  a(2) -= vx * wy - vy * wx;
  a(3) -= wy * wz;
  a(4) += wx * wz;
  a(5) -= wx * wy;
}

/// ∂b/∂v_root (6 × 6, rows and columns in v's order): what rne_derivatives adds to ∂τ/∂v.
template <class T, class V>
Eigen::Matrix<T, 6, 6> root_bias_jacobian(const V& v) {
  const T vx = T(v(0)), vy = T(v(1)), vz = T(v(2)), wx = T(v(3)), wy = T(v(4)), wz = T(v(5));
  Eigen::Matrix<T, 6, 6> J = Eigen::Matrix<T, 6, 6>::Zero();
  // ∂(v × ω)/∂v = −[ω]×, ∂(v × ω)/∂ω = [v]×
  J(0, 1) = wz, J(0, 2) = -wy, J(1, 0) = -wz, J(1, 2) = wx, J(2, 0) = wy, J(2, 1) = -wx;
  J(0, 4) = -vz, J(0, 5) = vy, J(1, 3) = vz, J(1, 5) = -vx, J(2, 3) = -vy, J(2, 4) = vx;
  J(3, 4) = wz, J(3, 5) = wy, J(4, 3) = -wz, J(4, 5) = -wx, J(5, 3) = wy, J(5, 4) = wx;
  return J;
}

/// Series-safe coefficients of SO(3)'s and SE(3)'s exponential in θ² (any scalar: no branch on
/// a derivative; Taylor polynomials below θ² = 1e-3, exact to rounding there).
template <class T>
struct exp_coefficients {
  T a, b, c;  ///< sin θ / θ, (1 − cos θ) / θ², (θ − sin θ) / θ³
};
template <class T>
exp_coefficients<T> exp_coeffs(const T& t2) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  if (value_of(t2) < 1e-3) {
    return {T(1) - t2 / T(6) * (T(1) - t2 / T(20) * (T(1) - t2 / T(42))),
            T(0.5) - t2 / T(24) * (T(1) - t2 / T(30) * (T(1) - t2 / T(56))),
            T(1) / T(6) - t2 / T(120) * (T(1) - t2 / T(42) * (T(1) - t2 / T(72)))};
  }
  const T t = sqrt(t2), s = sin(t), c = cos(t);
  return {s / t, (T(1) - c) / t2, (t - s) / (t2 * t)};
}

}  // namespace detail

/// The neutral configuration: zeros, the root at the world origin with the identity quaternion.
template <class S>
Eigen::VectorXd neutral_configuration(const tree<S>& t) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(t.nq());
  if (t.floating()) q(6) = 1;
  return q;
}

/// q ⊕ v: the configuration reached from q by the velocity v held for unit time (v·dt for a
/// step dt). A floating root moves by SE(3)'s exponential in its own frame (Pinocchio's
/// integrate): X_WB' = X_WB exp(v_B, ω_B), the quaternion renormalised; the joints by q + v.
/// q: nq entries, v: nv; any scalar.
template <class S, class Q, class V>
auto integrate(const tree<S>& t, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) {
  using T = promote_t<promote_t<S, typename Q::Scalar>, typename V::Scalar>;
  using std::sqrt;
  Eigen::Matrix<T, Eigen::Dynamic, 1> out(t.nq());
  detail::check_size(v, t.nv(), "v");
  if (!t.floating()) {
    detail::check_size(q, t.nq(), "q");
    out = q.template cast<T>() + v.template cast<T>();
    return out;
  }
  detail::check_floating_configuration(q, t.nq(), "q");
  const vec3<T> u = v.template head<3>().template cast<T>(), w = v.template segment<3>(3).template cast<T>();
  const T t2 = w.squaredNorm();
  const auto k = detail::exp_coeffs(t2);
  // p' = p + R V u, V = 1 + b [ω]× + c [ω]×²
  const vec3<T> wu = w.cross(u);
  const vec3<T> Vu = u + k.b * wu + k.c * w.cross(wu);
  const mat3<T> R = detail::root_rotation<T>(q);
  out.template head<3>() = q.template head<3>().template cast<T>() + R * Vu;
  // quaternion product q ⊗ exp(ω/2): exp(ω/2) = (sin(θ/2)/θ · ω, cos(θ/2)), with
  // sin(θ/2)/θ = a(θ/2)/2 and cos(θ/2) = 1 − (θ/2)² b(θ/2)
  const auto h = detail::exp_coeffs(T(t2 / T(4)));
  const vec3<T> e = (h.a / T(2)) * w;
  const T ew = T(1) - (t2 / T(4)) * h.b;
  const vec3<T> qv(T(q(3)), T(q(4)), T(q(5)));
  const T qw = T(q(6));
  vec3<T> rv = qw * e + ew * qv + qv.cross(e);
  T rw = qw * ew - qv.dot(e);
  const T norm = sqrt(rv.squaredNorm() + rw * rw);
  rv /= norm;
  rw /= norm;
  out.template segment<3>(3) = rv;
  out(6) = rw;
  out.tail(t.nq() - 7) = q.tail(t.nq() - 7).template cast<T>() + v.tail(t.nv() - 6).template cast<T>();
  return out;
}

/// q1 ⊖ q0: the velocity v (nv entries) with integrate(q0, v) = q1. A floating root's part is
/// SE(3)'s logarithm of X_WB0⁻¹ X_WB1 (the shorter of the two rotations, |ω| ≤ π).
template <class S, class Q0, class Q1>
auto difference(const tree<S>& t, const Eigen::MatrixBase<Q0>& q0, const Eigen::MatrixBase<Q1>& q1) {
  using T = promote_t<promote_t<S, typename Q0::Scalar>, typename Q1::Scalar>;
  using std::atan2;
  using std::sqrt;
  Eigen::Matrix<T, Eigen::Dynamic, 1> v(t.nv());
  if (!t.floating()) {
    detail::check_size(q0, t.nq(), "q0");
    detail::check_size(q1, t.nq(), "q1");
    v = q1.template cast<T>() - q0.template cast<T>();
    return v;
  }
  detail::check_floating_configuration(q0, t.nq(), "q0");
  detail::check_floating_configuration(q1, t.nq(), "q1");
  // relative rotation r = q0⁻¹ ⊗ q1, its angle θ = 2 atan2(|r_v|, r_w), the shorter way (r_w ≥ 0)
  const vec3<T> av(T(q0(3)), T(q0(4)), T(q0(5))), bv(T(q1(3)), T(q1(4)), T(q1(5)));
  const T aw = T(q0(6)), bw = T(q1(6));
  vec3<T> rv = aw * bv - bw * av - av.cross(bv);
  T rw = aw * bw + av.dot(bv);
  if (value_of(rw) < 0) {
    rv = -rv;
    rw = -rw;
  }
  const T s2 = rv.squaredNorm();
  // ω = θ / sin(θ/2) · r_v, with sin(θ/2) = |r_v|: the series 2/r_w (1 − s²/(3 r_w²)) near 0
  T scale;
  if (value_of(s2) < 1e-12)
    scale = T(2) / rw * (T(1) - s2 / (T(3) * rw * rw));
  else {
    const T s = sqrt(s2);
    scale = T(2) * atan2(s, rw) / s;
  }
  const vec3<T> w = scale * rv;
  const mat3<T> R0 = detail::root_rotation<T>(q0);
  const vec3<T> dp = R0.transpose() * vec3<T>(q1.template head<3>().template cast<T>() - q0.template head<3>().template cast<T>());
  // u = V⁻¹ dp, V⁻¹ = 1 − ½ [ω]× + d [ω]×², d = (1 − a / (2 b)) / θ²
  const T t2 = w.squaredNorm();
  T d;
  if (value_of(t2) < 1e-3)
    d = T(1) / T(12) + t2 / T(720) + t2 * t2 / T(30240);
  else {
    const auto k = detail::exp_coeffs(t2);
    d = (T(1) - k.a / (T(2) * k.b)) / t2;
  }
  const vec3<T> wp = w.cross(dp);
  v.template head<3>() = dp - T(0.5) * wp + d * w.cross(wp);
  v.template segment<3>(3) = w;
  v.tail(t.nv() - 6) = q1.tail(t.nq() - 7).template cast<T>() - q0.tail(t.nq() - 7).template cast<T>();
  return v;
}

/// A random configuration: each joint uniform within its limits (within ±π, or ±1 m for a
/// prismatic joint, where the limits are not finite); a floating root at a position uniform in
/// [−1, 1]³ m with a quaternion uniform on the sphere. Reproducible for a seeded rng.
template <class S, class Rng>
Eigen::VectorXd random_configuration(const tree<S>& t, Rng& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> gauss(0, 1);
  Eigen::VectorXd q(t.nq());
  const int first = t.floating() ? 6 : 0, offset = t.floating() ? 1 : 0;
  for (int i = first; i < t.dof(); ++i) {
    const auto& L = t[i].limits;
    const double span = t[i].joint == joint_type::revolute ? std::numbers::pi : 1.0;
    const double lo = std::isfinite(L.lower) ? L.lower : -span, hi = std::isfinite(L.upper) ? L.upper : span;
    q(i + offset) = lo + 0.5 * (u(rng) + 1) * (hi - lo);
  }
  if (t.floating()) {
    for (int i = 0; i < 3; ++i) q(i) = u(rng);
    Eigen::Vector4d h;
    do {
      for (int i = 0; i < 4; ++i) h(i) = gauss(rng);
    } while (h.norm() < 1e-6);
    q.segment<4>(3) = h.normalized();
  }
  return q;
}

/// The root's velocity in world axes from v: (ṗ_WB, ω_W) = (R_WB v_B, R_WB ω_B); the joints'
/// rates unchanged. A fixed-base tree: v itself.
template <class S, class Q, class V>
auto world_velocity(const tree<S>& t, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v) {
  using T = promote_t<promote_t<S, typename Q::Scalar>, typename V::Scalar>;
  Eigen::Matrix<T, Eigen::Dynamic, 1> out = v.template cast<T>();
  detail::check_size(v, t.nv(), "v");
  if (!t.floating()) return out;
  detail::check_floating_configuration(q, t.nq(), "q");
  const mat3<T> R = detail::root_rotation<T>(q);
  out.template head<3>() = R * v.template head<3>().template cast<T>();
  out.template segment<3>(3) = R * v.template segment<3>(3).template cast<T>();
  return out;
}
/// The inverse of world_velocity: v from the root's world-axes velocities (ṗ_WB, ω_W).
template <class S, class Q, class V>
auto body_velocity(const tree<S>& t, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& vw) {
  using T = promote_t<promote_t<S, typename Q::Scalar>, typename V::Scalar>;
  Eigen::Matrix<T, Eigen::Dynamic, 1> out = vw.template cast<T>();
  detail::check_size(vw, t.nv(), "v");
  if (!t.floating()) return out;
  detail::check_floating_configuration(q, t.nq(), "q");
  const mat3<T> R = detail::root_rotation<T>(q);
  out.template head<3>() = R.transpose() * vw.template head<3>().template cast<T>();
  out.template segment<3>(3) = R.transpose() * vw.template segment<3>(3).template cast<T>();
  return out;
}

}  // namespace nhdyn
