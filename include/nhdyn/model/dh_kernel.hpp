#pragma once
/// \file model/dh_kernel.hpp
/// Link-frame building blocks shared by kinematics and dynamics: per-link constants
/// precomputed once per model, and the elementary rotations of a standard DH row.
///
/// Notation (docs/notation.md): R_i = Rz(θ_i)·Rx(α_i) maps frame-i coordinates to frame
/// i−1; p_i = the vector o_{i−1} → o_i in frame i = (a_i, d_i sin α_i, d_i cos α_i);
/// z_i = z_{i−1} in frame i = (0, sin α_i, cos α_i).
#include <cmath>
#include <limits>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "chain.hpp"
#include "../scalar/sincos.hpp"
#include "../detail/small_buffer.hpp"

namespace nhdyn::detail {

/// What a kernel reads and writes a vector argument through: a vector with direct access (a
/// matrix, a map, a block, a Ref) as a map of its scalar at the model's size N, so that the
/// kernel is compiled once per scalar, size and contiguity (a strided vector, such as a row
/// of a matrix, is a second map type), not once per argument type (a kernel was
/// instantiated for every combination of its callers' Eigen types: 152 copies of rne's in one
/// test file, where 44 differ in what they compute; docs/performance.md, "Compile times").
/// Any other expression (a constant, a product) is passed as it is. Reading through a map
/// gives the same numbers: only where the coefficients come from changes.
template <class D>
inline constexpr bool maps_as_vector = (int(D::Flags) & Eigen::DirectAccessBit) != 0 && D::IsVectorAtCompileTime;
template <int N, class X>
decltype(auto) kernel_vector(X& x) {
  using D = std::remove_cvref_t<decltype(x.derived())>;  // X may be an Eigen::MatrixBase<D>
  if constexpr (maps_as_vector<D>) {
    constexpr bool writable = !std::is_const_v<X> && (int(D::Flags) & Eigen::LvalueBit) != 0;
    using V = Eigen::Matrix<typename D::Scalar, N, 1>;
    using M = std::conditional_t<writable, V, const V>;
    auto& d = x.derived();
    if constexpr (D::InnerStrideAtCompileTime == 1)
      return Eigen::Map<M>(d.data(), d.size());
    else
      return Eigen::Map<M, 0, Eigen::InnerStride<>>(d.data(), d.size(), Eigen::InnerStride<>(d.innerStride()));
  } else {
    return (x);
  }
}

/// An input vector as a kernel reads it: kernel_vector's map where the vector has storage, and
/// otherwise (an expression: VectorXd::Zero(n), a product) a map of scratch that holds its
/// values, so that an expression too reaches the kernel as a map, not as a type of its own.
/// The scratch is on the stack up to 64 entries and beyond in the block its thread keeps
/// (detail/small_buffer.hpp). Lives as long as the vector it is made from (a temporary is
/// refused).
template <int N, class X>
class kernel_input {
  using D = std::remove_cvref_t<decltype(std::declval<const X&>().derived())>;
  using S = typename D::Scalar;
  static constexpr bool direct = maps_as_vector<D>;
  struct none {
    explicit none(int) {}
  };

 public:
  explicit kernel_input(const X& x) : x_(x), buf_(static_cast<int>(x.size())) {
    if constexpr (!direct) Eigen::Map<Eigen::Matrix<S, N, 1>>(buf_.data(), x.size()).noalias() = x;
  }
  kernel_input(const X&&) = delete;
  decltype(auto) get() const {
    if constexpr (direct)
      return kernel_vector<N>(x_);
    else
      return Eigen::Map<const Eigen::Matrix<S, N, 1>>(buf_.data(), x_.size());
  }

 private:
  const X& x_;
  std::conditional_t<direct, none, small_buffer<S, N, 64>> buf_;
};

/// The constants of one link, as the recursions use them.
template <class S>
struct dh_link {
  bool revolute = true;
  bool has_inertia = true;  ///< false: zero mass and zero inertia, the link is skipped
  S ca{1}, sa{0};     ///< cos α_i, sin α_i
  S a{0}, d0{0}, th0{0};
  S ct0{1}, st0{0};   ///< cos θ⁰, sin θ⁰: a prismatic joint's constant rotation
  S m{0};
  vec3<S> h = vec3<S>::Zero();   ///< first moment m_i·c_i, frame i
  mat3<S> Io = mat3<S>::Zero();  ///< rotational inertia about o_i, frame i (parallel axis)
  // The same constants as plain scalars, for the unrolled kernels (no Eigen temporaries):
  S p0[3] = {S(0), S(0), S(0)};                ///< p_i at d = d0: (a, d0 sin α, d0 cos α)
  S hs[3] = {S(0), S(0), S(0)};                ///< h
  S Is[6] = {S(0), S(0), S(0), S(0), S(0), S(0)};  ///< I_o: xx, yy, zz, xy, xz, yz
  S Ia{0};                    ///< the joint's armature (joint-side rotor inertia)
  bool has_armature = false;  ///< Ia ≠ 0
};

template <class S>
dh_link<S> make_dh_link(const link<S>& L) {
  using std::cos;
  using std::sin;
  dh_link<S> k;
  k.revolute = L.joint == joint_type::revolute;
  k.ca = cos(L.alpha);
  k.sa = sin(L.alpha);
  // Exact zeros where α is a multiple of π/2 in double: keeps the planar cases planar. For
  // every real number type (float … long double, multiprecision), so that a model evaluates
  // the same in all of them; not for duals (∂/∂α must survive) nor intervals (enclosure).
  if constexpr (std::is_floating_point_v<S> ||
                (std::numeric_limits<S>::is_specialized && !std::numeric_limits<S>::is_integer)) {
    // Snap both: a zero cosine makes the sine ±1 exactly (else cos² + sin² ≠ 1 by ~1e-33,
    // which a 50-digit evaluation sees as a 1e-32 disagreement between rne and CRBA).
    if (std::abs(value_of(k.ca)) < 1e-15) k.ca = S(0), k.sa = S(value_of(k.sa) < 0 ? -1 : 1);
    if (std::abs(value_of(k.sa)) < 1e-15) k.sa = S(0), k.ca = S(value_of(k.ca) < 0 ? -1 : 1);
  }
  k.a = L.a;
  k.d0 = L.d;
  k.th0 = L.theta;
  {
    using std::cos;
    using std::sin;
    k.ct0 = cos(L.theta);
    k.st0 = sin(L.theta);
  }
  k.m = L.mass;
  k.h = L.mass * L.com;
  const S cc = L.com.squaredNorm();
  k.Io = L.inertia + L.mass * (cc * mat3<S>::Identity() - L.com * L.com.transpose());  // I_o = I_c + m(|c|²1 − ccᵀ)
  k.p0[0] = k.a;
  k.p0[1] = k.d0 * k.sa;
  k.p0[2] = k.d0 * k.ca;
  for (int r = 0; r < 3; ++r) k.hs[r] = k.h(r);
  k.Is[0] = k.Io(0, 0);
  k.Is[1] = k.Io(1, 1);
  k.Is[2] = k.Io(2, 2);
  k.Is[3] = k.Io(0, 1);
  k.Is[4] = k.Io(0, 2);
  k.Is[5] = k.Io(1, 2);
  bool zero = is_exact_zero(L.mass);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) zero = zero && is_exact_zero(L.inertia(r, c));
  k.has_inertia = !zero;
  k.Ia = L.armature;
  k.has_armature = !is_exact_zero(L.armature);
  return k;
}

template <class S, int N>
struct dh_links {
  using type = std::array<dh_link<S>, static_cast<std::size_t>(N)>;
};
template <class S>
struct dh_links<S, dynamic> {
  using type = std::vector<dh_link<S>>;
};

template <class S, int N>
typename dh_links<S, N>::type make_dh_links(const chain<S, N>& c) {
  typename dh_links<S, N>::type out{};
  if constexpr (N == dynamic) out.resize(static_cast<std::size_t>(c.dof()));
  for (int i = 0; i < c.dof(); ++i) out[static_cast<std::size_t>(i)] = make_dh_link(c[i]);
  return out;
}

/// θ = θ⁰ + q is rounded before sin/cos: at |q| = 1e6 a double loses up to 6e-11 rad of
/// θ⁰ (a float 0.03 rad), an error of the algorithm, not of the input. For floating-point T
/// the rounding error e = (θ⁰ + q) − θ is exact (Knuth's TwoSum), and (c, s) of θ are turned
/// by e: cos/sin of the exact sum. Nothing is done when e = 0 (θ⁰ = 0, or small angles).
template <class T>
void correct_angle_sum(const T& a, const T& b, const T& sum, T& c, T& s) {
  if constexpr (std::is_floating_point_v<T>) {
    const T bb = sum - a;
    const T e = (a - (sum - bb)) + (b - bb);
    if (e != T(0)) {
      const T ce = std::cos(e), se = std::sin(e);
      const T c1 = c * ce - s * se;
      s = s * ce + c * se;
      c = c1;
    }
  }
}

/// cos θ_i, sin θ_i and d_i of link i at joint value qi.
template <class T, class S>
struct joint_geometry {
  T ct, st, d;
};
template <class T, class S>
joint_geometry<T, S> geometry(const dh_link<S>& k, const T& qi) {
  using std::cos;
  using std::sin;
  if (k.revolute) {
    const T th = T(k.th0) + qi;
    T c = cos(th), s = sin(th);
    correct_angle_sum(T(k.th0), qi, th, c, s);
    return {c, s, T(k.d0)};
  }
  const T th = T(k.th0);
  return {cos(th), sin(th), T(k.d0) + qi};
}

/// A forward-mode dual number over double (scalar/dual.hpp, or any type shaped like it).
template <class T>
concept double_dual = requires(const T& x) {
  requires std::is_same_v<typename T::value_type, double>;
  { x.value() } -> std::convertible_to<double>;
  x.derivatives();
  chain_rule(x, 0.0, 0.0);
};
/// (sin x, cos x) of one angle: sincos_kernel for a double within its range; for a dual
/// one sin/cos of its value; for a type with `sincos_pair` (nhdyn::interval) that; otherwise
/// the scalar's own sin and cos.
template <class T>
inline sin_cos<T> sincos_of(const T& x) {
  if constexpr (std::is_same_v<T, double>) {
    if (std::abs(x) <= 1e5) return sincos_kernel(x);
  } else if constexpr (requires { sincos_pair(x); }) {  // e.g. nhdyn::interval: both at once
    auto p = sincos_pair(x);
    return {std::move(p.first), std::move(p.second)};
  } else if constexpr (double_dual<T>) {
    // One sin/cos of the value; the derivative parts by the chain rule.
    const auto p = sincos_of(x.value());
    return {chain_rule(x, p.s, p.c), chain_rule(x, p.c, -p.s)};
  }
  using std::cos;
  using std::sin;
  return {sin(x), cos(x)};
}

/// correct_angle_sum for every revolute joint with θ⁰ ≠ 0 (see there).
template <class T, class Links, class Q>
void correct_angle_sums(const Links& L, const Q& q, int n, T* c, T* s) {
  if constexpr (std::is_floating_point_v<T>) {
    for (int i = 0; i < n; ++i) {
      const auto& k = L[static_cast<std::size_t>(i)];
      if (k.revolute && k.th0 != 0) correct_angle_sum(T(k.th0), T(q(i)), T(T(k.th0) + T(q(i))), c[i], s[i]);
    }
  }
}

/// An angle given as the sum a + b, whose sin/cos are those of the exact sum (as a joint's
/// θ⁰ + q; correct_angle_sum): e.g. a mobile base's heading ψ = ±q_h + offset.
template <class T>
struct angle_sum {
  T a, b;
};
/// An angle as a joint's: ψ = sign·q_joint + offset (sign ±1).
template <class S>
struct joint_angle_form {
  int joint;
  S sign, offset;
};
/// sin/cos of a + b as the joint angles get them: sincos_of of the rounded sum, then turned
/// by its rounding error. joint_angles' batch gives the same numbers for its extra angle.
template <class T>
sin_cos<T> sincos_of_sum(const angle_sum<T>& x) {
  const T sum = x.a + x.b;
  auto p = sincos_of(sum);
  correct_angle_sum(x.a, x.b, sum, p.c, p.s);
  return p;
}

/// cos θ_i and sin θ_i of links 0…n−1 at q (θ_i = θ_i⁰ + q_i for a revolute joint, θ_i⁰
/// for a prismatic one), all at once: for double by sincos_reduced, otherwise by the
/// scalar's own cos and sin. With `extra`, also cos/sin of that angle, into c[n] and s[n]
/// (c and s then hold n + 1): a stage around the kernel (the nonholonomic lift's heading)
/// gets its sin/cos from the same batch, the same numbers as sincos_of_sum gives.
template <class T, int N, class Links, class Q>
void joint_angles(const Links& L, const Q& q, int n, T* c, T* s, const angle_sum<T>* extra = nullptr) {
  using std::cos;
  using std::sin;
  const auto theta = [&](int i) {
    const auto& k = L[static_cast<std::size_t>(i)];
    return k.revolute ? T(T(k.th0) + T(q(i))) : T(k.th0);
  };
  if constexpr (std::is_same_v<T, double>) {
    const int total = n + (extra ? 1 : 0);
    small_buffer<double, N == dynamic ? dynamic : N + 1> th(total);
    bool small = true;
    for (int i = 0; i < n; ++i) {
      th[i] = theta(i);
      small = small & (std::abs(th[i]) <= 1e5);  // false for NaN
    }
    if (extra) {
      th[n] = extra->a + extra->b;
      small = small & (std::abs(th[n]) <= 1e5);
    } else if constexpr (N != dynamic) {
      th[n] = 0.0;  // the spare slot of a fixed-size buffer (unread; GCC cannot tell)
    }
    if (small) {
      sincos_reduced(th.data(), s, c, total);
      correct_angle_sums(L, q, n, c, s);
      if (extra) correct_angle_sum(extra->a, extra->b, th[n], c[n], s[n]);
      return;
    }
  }
  for (int i = 0; i < n; ++i) {
    const auto& k = L[static_cast<std::size_t>(i)];
    if (k.revolute) {
      const auto p = sincos_of(T(q(i) + k.th0));
      c[i] = p.c;
      s[i] = p.s;
    } else {  // a constant angle: sin/cos in the model's scalar
      const auto p = sincos_of(k.th0);
      c[i] = T(p.c);
      s[i] = T(p.s);
    }
  }
  correct_angle_sums(L, q, n, c, s);
  if (extra) {
    const auto p = sincos_of_sum(*extra);
    c[n] = p.c;
    s[n] = p.s;
  }
}

/// v in frame i−1 → frame i: R_iᵀ v = Rx(α)ᵀ Rz(θ)ᵀ v.
template <class T, class S>
vec3<T> rot_T(const dh_link<S>& k, const T& ct, const T& st, const vec3<T>& v) {
  const T ux = ct * v.x() + st * v.y();
  const T uy = ct * v.y() - st * v.x();
  return {ux, T(k.ca) * uy + T(k.sa) * v.z(), T(k.ca) * v.z() - T(k.sa) * uy};
}
/// v in frame i → frame i−1: R_i v = Rz(θ) Rx(α) v.
template <class T, class S>
vec3<T> rot(const dh_link<S>& k, const T& ct, const T& st, const vec3<T>& v) {
  const T uy = T(k.ca) * v.y() - T(k.sa) * v.z();
  const T uz = T(k.sa) * v.y() + T(k.ca) * v.z();
  return {ct * v.x() - st * uy, st * v.x() + ct * uy, uz};
}
/// p_i: o_{i−1} → o_i in frame i.
template <class T, class S>
vec3<T> offset(const dh_link<S>& k, const T& d) {
  return {T(k.a), d * T(k.sa), d * T(k.ca)};
}
/// A 3-vector as three plain scalars: the kernels' working type. Eigen's fixed 3-vectors
/// make the compiler pack 2+1 lanes and go through the stack (store-forwarding stalls);
/// three scalars stay in registers.
template <class T>
struct v3 {
  T x, y, z;
};
template <class T>
[[gnu::always_inline]] inline v3<T> operator+(const v3<T>& a, const v3<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
inline v3<T> operator*(const std::type_identity_t<T>& s, const v3<T>& a) {  // T from v3 only: s may be an expression (AutoDiffScalar)
  return {s * a.x, s * a.y, s * a.z};
}
template <class T>
[[gnu::always_inline]] inline v3<T> cross(const v3<T>& a, const v3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// Mixed forms: a model constant (scalar C, e.g. double) with a state-dependent vector
// (scalar T, e.g. a dual or an interval). The constant is not promoted to T, so a dual
// pays K + 1 operations for the product, not 2K + 1 (scalar/dual.hpp), and an interval
// two products, not four. For T = C they are the plain forms.
/// s v for a constant s.
template <class C, class T>
[[gnu::always_inline]] inline v3<T> scale(const C& s, const v3<T>& a) {
  return {T(s * a.x), T(s * a.y), T(s * a.z)};
}
/// a × c for a constant c.
template <class T, class C>
[[gnu::always_inline]] inline v3<T> cross_c(const v3<T>& a, const v3<C>& c) {
  return {T(a.y * c.z - a.z * c.y), T(a.z * c.x - a.x * c.z), T(a.x * c.y - a.y * c.x)};
}
/// c × a for a constant c.
template <class C, class T>
[[gnu::always_inline]] inline v3<T> c_cross(const v3<C>& c, const v3<T>& a) {
  return {T(c.y * a.z - c.z * a.y), T(c.z * a.x - c.x * a.z), T(c.x * a.y - c.y * a.x)};
}
/// Rᵀ v (frame i−1 → frame i) with R = Rz(θ) Rx(α); cos α, sin α constants (and cos θ,
/// sin θ too for a prismatic joint: A = C).
template <class C, class A, class T>
[[gnu::always_inline]] inline v3<T> rot_T(const C& ca, const C& sa, const A& ct, const A& st, const v3<T>& v) {
  const T uy = ct * v.y - st * v.x;
  return {T(ct * v.x + st * v.y), T(ca * uy + sa * v.z), T(ca * v.z - sa * uy)};
}
/// R v (frame i → frame i−1).
template <class C, class A, class T>
[[gnu::always_inline]] inline v3<T> rot(const C& ca, const C& sa, const A& ct, const A& st, const v3<T>& v) {
  const T uy = ca * v.y - sa * v.z;
  return {T(ct * v.x - st * uy), T(st * v.x + ct * uy), T(sa * v.y + ca * v.z)};
}
/// A constant vector in the computation's scalar.
template <class T, class C>
inline v3<T> z_as(const v3<C>& c) {
  return {T(c.x), T(c.y), T(c.z)};
}
/// I v for a constant symmetric I given as (xx, yy, zz, xy, xz, yz).
template <class T, class S>
[[gnu::always_inline]] inline v3<T> sym_times(const S* I, const v3<T>& v) {
  return {T(I[0] * v.x + I[3] * v.y + I[4] * v.z), T(I[3] * v.x + I[1] * v.y + I[5] * v.z),
          T(I[4] * v.x + I[5] * v.y + I[2] * v.z)};
}

/// z_{i−1} in frame i.
template <class T, class S>
vec3<T> axis(const dh_link<S>& k) {
  return {T(0), T(k.sa), T(k.ca)};
}

}  // namespace nhdyn::detail
