#pragma once
/// \file dynamics/aba.hpp
/// Forward dynamics q̈ = FD(q, q̇, τ) of a tree by Featherstone's articulated-body algorithm
/// (Rigid Body Dynamics Algorithms, 2008, Table 7.1; "RBDA"), generic over the scalar, O(n).
///
/// Why beside CRBA + LDLᵀ (dynamics/tree.hpp `forward_dynamics`): ABA never forms the
/// joint-space mass matrix M(q), whose condition number grows with the spread of the masses
/// (a 1e-9 kg tool on a 1e6 kg base gives cond M ≈ 1e15 and more, past what a Cholesky
/// factorisation of M in double can answer), while the articulated inertias it inverts are
/// 1×1 per joint and well scaled body by body: q̈ stays accurate where it is determined. It
/// refuses only a truly singular problem: an articulated inertia D_i = S_iᵀ I^A_i S_i that is
/// not positive, or positive but below 64 ε of its own scale |I^A_i S_i|·|S_i| (RBDA
/// eq. 7.37's division has nothing to divide), and says which joint.
///
/// `reference::aba` is the algorithm as the book writes it (one screen, its names and equation
/// numbers: the spec and the oracle); `detail::tree_aba_kernel` is its optimisation, tested
/// equal to it, and `aba(tree)` the checked function object around the kernel. What the
/// kernel changes: spatial quantities are expressed in world axes about each body's own
/// kernel-frame origin (model/tree_kernel.hpp: on the joint axis). A child's articulated
/// inertia then reaches its parent by a shift of origin along the link (eq. 7.40 without its
/// rotation: three 3×3 cross-product blocks instead of two 6×6 products with X_i), the
/// rigid-body inertia is rotated once per body in pass 1, S_i is the world joint axis in one
/// half of a 6-vector, (7.38)/(7.39) share one rank-one update, and one scratch buffer per call
/// lives on the stack for up to 51 bodies (32 KiB; beyond, in a heap block the thread keeps for
/// its next call, detail/small_buffer.hpp). Origins stay on the bodies (not at the world
/// origin, as Pinocchio's ABA): inertias about a far origin grow as m·|p|² and lose digits —
/// on tests/test_aba.cpp's random trees of up to 40 bodies, q̈ about the world origin was
/// 5e-10 from CRBA + LDLᵀ, about the bodies' origins 4.8e-13 (the 6×6 reference: 1.2e-12).
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "../detail/attributes.hpp"
#include "../detail/small_buffer.hpp"
#include "../errors.hpp"
#include "../functional/values.hpp"
#include "../model/floating.hpp"
#include "../model/tree_kernel.hpp"
#include "../spatial/spatial.hpp"
#include "reference.hpp"
#include "rne.hpp"

namespace nhdyn {

namespace reference {
/// q̈ by the articulated-body algorithm (RBDA Table 7.1), gravity as the base acceleration
/// a_0 = −a_g. Unchecked: the oracle of the kernel below.
template <class T, class S>
vecX<T> aba(const tree<S>& t, const vecX<T>& q, const vecX<T>& qd, const vecX<T>& tau) {
  using namespace spatial;
  const int n = t.dof();
  std::vector<mat6<T>> X(n), IA(n);  // ^iX_λ(i); articulated inertias I^A_i
  std::vector<vec6<T>> Si(n), v(n), c(n), pA(n), U(n), a(n);
  std::vector<T> D(n), u(n);
  for (int i = 0; i < n; ++i) {  // pass 1: velocities, bias accelerations and forces
    const auto [R, p] = placement(t[i], q(i));
    X[i] = motion_transform(R, p);
    Si[i] = motion_subspace<T>(t[i]);
    const int l = t.parent(i);
    const vec6<T> vJ = Si[i] * qd(i);
    v[i] = (l < 0 ? vec6<T>(vec6<T>::Zero()) : vec6<T>(X[i] * v[l])) + vJ;  // (7.34)
    c[i] = crm(v[i]) * vJ;                                                   // c_J = 0 (Ṡ = 0)
    IA[i] = inertia<T>(T(t[i].mass), t[i].com.template cast<T>(), t[i].inertia.template cast<T>());
    pA[i] = crf(v[i]) * IA[i] * v[i];                                        // (7.35), no f^x
  }
  for (int i = n - 1; i >= 0; --i) {  // pass 2: articulated inertias, leaves to root
    U[i] = IA[i] * Si[i];
    D[i] = Si[i].dot(U[i]) + T(t[i].armature);  // (7.37), with the joint's armature
    u[i] = tau(i) - Si[i].dot(pA[i]);
    const int l = t.parent(i);
    if (l >= 0) {
      const mat6<T> Ia = IA[i] - U[i] * U[i].transpose() / D[i];            // (7.38)
      const vec6<T> pa = pA[i] + Ia * c[i] + U[i] * (u[i] / D[i]);          // (7.39)
      IA[l] += X[i].transpose() * Ia * X[i];                                // (7.40)
      pA[l] += X[i].transpose() * pa;                                       // (7.41)
    }
  }
  vec6<T> a0 = vec6<T>::Zero();
  a0.template tail<3>() = -t.gravity().template cast<T>();
  vecX<T> qdd(n);
  for (int i = 0; i < n; ++i) {  // pass 3: accelerations, root to leaves
    const int l = t.parent(i);
    const vec6<T> ap = X[i] * (l < 0 ? a0 : a[l]) + c[i];                  // (7.42)
    qdd(i) = (u[i] - U[i].dot(ap)) / D[i];                                  // (7.43)
    a[i] = ap + Si[i] * qdd(i);                                             // (7.44)
  }
  return qdd;
}
}  // namespace reference

namespace detail {

/// One body's scratch in the ABA kernel: spatial quantities in world axes about K_i's origin.
template <class T>
struct aba_scratch {
  spatial::mat6<T> IA;  ///< articulated inertia I^A_i
  spatial::vec6<T> v, c, pA, U, a;
  mat3<T> R;            ///< K_i's axes in the world
  vec3<T> d;            ///< K_i's origin from K_λ's, world axes
  T D, u;
};

/// I += the articulated inertia J (world axes, about a point d from I's point) moved to I's
/// point: with P = d×, A += A_J − B_J P − (B_J P)ᵀ − P C_J P, B += B_J − (C_J P)ᵀ, C += C_J.
template <class T>
NHDYN_ALWAYS_INLINE void add_shifted_inertia(spatial::mat6<T>& I, const spatial::mat6<T>& J, const vec3<T>& d) {
  mat3<T> BP, CP;  // row j of M P is (M.row(j)ᵀ × d)ᵀ
  for (int j = 0; j < 3; ++j) {
    BP.row(j) = vec3<T>(J.template block<1, 3>(j, 3).transpose()).cross(d).transpose();
    CP.row(j) = vec3<T>(J.template block<1, 3>(3 + j, 3).transpose()).cross(d).transpose();
  }
  mat3<T> PCP;
  for (int j = 0; j < 3; ++j) PCP.col(j) = d.cross(vec3<T>(CP.col(j)));
  I.template topLeftCorner<3, 3>() += J.template topLeftCorner<3, 3>() - BP - BP.transpose() - PCP;
  const mat3<T> B = J.template topRightCorner<3, 3>() - CP.transpose();
  I.template topRightCorner<3, 3>() += B;
  I.template bottomLeftCorner<3, 3>() += B.transpose();
  I.template bottomRightCorner<3, 3>() += J.template bottomRightCorner<3, 3>();
}

/// ABA on the kernel constants (see the file comment), q̈ into qdd. `check(i, D_i, U_i, S_i)`
/// sees every D_i before it is divided by.
template <class T, class LS, class Q, class QD, class TAU, class QDD, class Check>
void tree_aba_kernel_impl(const std::vector<tree_link<LS>>& L, const vec3<T>& g, const Q& q, const QD& qd,
                          const TAU& tau, QDD& qdd, const Check& check) {
  using spatial::vec6;
  const int n = static_cast<int>(L.size());
  small_buffer<aba_scratch<T>, dynamic> s(n);
  const auto motion_subspace = [&](int i) {  // S_i: the joint axis z of K_i, in world axes
    vec6<T> S = vec6<T>::Zero();
    S.template segment<3>(L[i].revolute ? 0 : 3) = s[i].R.col(2);
    return S;
  };
  for (int i = 0; i < n; ++i) {  // pass 1: placements, v_i, c_i, rigid-body inertias, bias forces
    const tree_link<LS>& k = L[i];
    aba_scratch<T>& b = s[i];
    mat3<T> R;
    vec3<T> p;
    kernel_placement(k, T(q(i)), R, p);  // K_i in K_λ
    vec3<T> w = vec3<T>::Zero(), vo = vec3<T>::Zero();
    if (k.parent < 0) {
      b.R = R;
      b.d = p;
    } else {  // (7.34): v_λ moved to K_i's origin, + v_J
      const aba_scratch<T>& l = s[k.parent];
      b.R.noalias() = l.R * R;
      b.d.noalias() = l.R * p;
      w = l.v.template head<3>();
      vo = l.v.template tail<3>() + w.cross(b.d);
    }
    const vec3<T> z = b.R.col(2);
    const T qdi = T(qd(i));
    // (fixed-size blocks, not comma initialisers: those assign through run-time-sized blocks,
    // which clang 14 leaves as out-of-line loops even in a flattened kernel)
    if (k.revolute) {  // v_J = (z q̇, 0): c = v × v_J = (ω × z q̇, v_O × z q̇)
      b.c.template head<3>() = w.cross(z) * qdi;
      b.c.template tail<3>() = vo.cross(z) * qdi;
      w += z * qdi;
    } else {  // v_J = (0, z q̇): c = (0, ω × z q̇)
      b.c.template head<3>().setZero();
      b.c.template tail<3>() = w.cross(z) * qdi;
      vo += z * qdi;
    }
    b.v.template head<3>() = w;
    b.v.template tail<3>() = vo;
    // the rigid-body inertia in world axes about K_i's origin: R I_o Rᵀ, h = R h_K, m
    const vec3<T> h = b.R * k.h;
    mat3<T> IoRt, Io;
    IoRt.noalias() = k.Io * b.R.transpose();
    Io.noalias() = b.R * IoRt;
    const mat3<T> H = spatial::skew(h);
    b.IA.template topLeftCorner<3, 3>() = Io;
    b.IA.template topRightCorner<3, 3>() = H;
    b.IA.template bottomLeftCorner<3, 3>() = -H;
    b.IA.template bottomRightCorner<3, 3>() = k.m * mat3<T>::Identity();
    // (7.35): p = v ×* I v, with I v = (I_o ω + h × v_O, m v_O − h × ω)
    const vec3<T> fn = Io * w + h.cross(vo), ff = k.m * vo - h.cross(w);
    b.pA.template head<3>() = w.cross(fn) + vo.cross(ff);
    b.pA.template tail<3>() = w.cross(ff);
  }
  for (int i = n - 1; i >= 0; --i) {  // pass 2: articulated inertias and bias forces, leaves to root
    const tree_link<LS>& k = L[i];
    aba_scratch<T>& b = s[i];
    const vec3<T> z = b.R.col(2);
    const int o = k.revolute ? 0 : 3;  // S = z in the angular or the linear half
    b.U.noalias() = b.IA.template middleCols<3>(o) * z;  // U = I^A S
    b.D = z.dot(b.U.template segment<3>(o));             // (7.37)
    if (k.has_armature) b.D += k.Ia;
    b.u = T(tau(i)) - z.dot(b.pA.template segment<3>(o));
    check(i, b.D, b.U, motion_subspace(i));
    if (k.parent < 0) continue;
    // (7.38), (7.39): I^a = I^A − U Uᵀ/D;  p^a = p^A + I^a c + U u/D = p^A + I^A c + U (u − Uᵀc)/D
    const vec6<T> W = b.U / b.D;
    vec6<T> pa = b.pA + W * (b.u - b.U.dot(b.c));
    pa.noalias() += b.IA * b.c;
    b.IA.noalias() -= W * b.U.transpose();
    // (7.40), (7.41): the axes are the world's, so X_i only moves the point by d_i
    aba_scratch<T>& l = s[k.parent];
    add_shifted_inertia(l.IA, b.IA, b.d);
    l.pA.template head<3>() += pa.template head<3>() + b.d.cross(vec3<T>(pa.template tail<3>()));
    l.pA.template tail<3>() += pa.template tail<3>();
  }
  for (int i = 0; i < n; ++i) {  // pass 3: accelerations, root to leaves
    const tree_link<LS>& k = L[i];
    aba_scratch<T>& b = s[i];
    if (k.parent < 0) {  // a_0 = −a_g
      b.a.template head<3>().setZero();
      b.a.template tail<3>() = -g;
    } else {  // (7.42): a_λ moved to K_i's origin
      const aba_scratch<T>& l = s[k.parent];
      b.a.template head<3>() = l.a.template head<3>();
      b.a.template tail<3>() = l.a.template tail<3>() + vec3<T>(l.a.template head<3>()).cross(b.d);
    }
    b.a += b.c;
    const vec3<T> z = b.R.col(2);
    const int o = k.revolute ? 0 : 3;
    const T qddi = (b.u - b.U.dot(b.a)) / b.D;  // (7.43)
    qdd(i) = qddi;
    b.a.template segment<3>(o) += z * qddi;  // (7.44)
  }
}

/// The kernel with every call inside it inlined for the scalars of `flatten_kernels` (floating
/// point, SIMD packs; detail/attributes.hpp), as it is for the others.
template <class T, class LS, class Q, class QD, class TAU, class QDD, class Check>
NHDYN_FLATTEN void tree_aba_kernel_flat(const std::vector<tree_link<LS>>& L, const vec3<T>& g, const Q& q,
                                        const QD& qd, const TAU& tau, QDD& qdd, const Check& check) {
  tree_aba_kernel_impl<T>(L, g, q, qd, tau, qdd, check);
}
/// Links in T, or in double for T a SIMD pack (constants broadcast where used).
template <class T, class LS, class Q, class QD, class TAU, class QDD, class Check>
void tree_aba_kernel_on(const std::vector<tree_link<LS>>& L, const vec3<T>& g, const Q& q, const QD& qd,
                        const TAU& tau, QDD& qdd, const Check& check) {
  if constexpr (flatten_kernels<T>)
    tree_aba_kernel_flat<T>(L, g, q, qd, tau, qdd, check);
  else
    tree_aba_kernel_impl<T>(L, g, q, qd, tau, qdd, check);
}
/// The kernel on maps of the vectors (kernel_vector): one kernel per scalar and check,
/// whatever Eigen types the caller passes.
template <class T, class LS, class Q, class QD, class TAU, class QDD, class Check>
void tree_aba_kernel(const std::vector<tree_link<LS>>& L, const vec3<T>& g, const Q& q, const QD& qd, const TAU& tau,
                     QDD& qdd, const Check& check) {
  const kernel_input<dynamic, Q> qi(q);
  const kernel_input<dynamic, QD> qdi(qd);
  const kernel_input<dynamic, TAU> taui(tau);
  decltype(auto) out = kernel_vector<dynamic>(qdd);
  tree_aba_kernel_on<T>(L, g, qi.get(), qdi.get(), taui.get(), out, check);
}

}  // namespace detail

/// q̈ = aba(q, q̇, τ) on a tree, any scalar: inputs checked (sizes, finite), every articulated
/// inertia along its joint axis checked before the division (see the file comment), the
/// result checked for overflow.
template <class S>
class aba_fn : public stage_tag {
 public:
  explicit aba_fn(const tree<S>& t)
      : links_(detail::make_tree_links(t)), g_(t.gravity()), name_(t.name()), floating_(t.floating()) {
    joints_.reserve(static_cast<std::size_t>(t.dof()));
    for (int i = 0; i < t.dof(); ++i) joints_.push_back(t[i].joint_name);
  }
  int dof() const { return static_cast<int>(links_.size()); }
  /// q's entries: dof() + 1 for a floating tree (model/floating.hpp), else dof().
  int nq() const { return dof() + (floating_ ? 1 : 0); }

  template <class Q, class QD, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<TAU>& tau) const {
    using T = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>, typename TAU::Scalar>;
    vecN<T, dynamic> out(dof());
    evaluate(q, qd, tau, out);
    return out;
  }

  /// q̈ = aba(q, q̇, τ) into qdd (n entries, of the model's and the inputs' promoted scalar; a
  /// vector or a map the caller reuses: no allocation). qdd may be τ's (or q's, q̇'s) own
  /// storage: the kernel has read them all before its last pass writes q̈.
  template <class Q, class QD, class TAU, class QDD>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                Eigen::MatrixBase<QDD>& qdd) const {
    using T = typename QDD::Scalar;
    static_assert(std::is_same_v<T, promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>,
                                              typename TAU::Scalar>>,
                  "qdd's scalar is the model's and the inputs' promoted scalar");
    const int n = dof();
    detail::check_size(qdd, n, "qdd");
    if (floating_)
      detail::check_floating_configuration(q, n + 1, "q");
    else
      detail::check_size(q, n, "q");
    detail::check_size(qd, n, "qd");
    detail::check_size(tau, n, "tau");
    detail::check_finite(q, "q");
    detail::check_finite(qd, "qd");
    detail::check_finite(tau, "tau");
    const auto check = [&](int i, const T& D, const spatial::vec6<T>& U, const spatial::vec6<T>& Si) {
      // D = Sᵀ U ≤ |U| |S| (Cauchy–Schwarz)
      const double d = value_of(D);
      double u2 = 0, s2 = 0;
      for (int j = 0; j < 6; ++j) u2 += sq(value_of(U(j))), s2 += sq(value_of(Si(j)));
      constexpr double tol = 64 * std::numeric_limits<double>::epsilon();
      if (std::isfinite(d) && d > 0 && d * d > tol * tol * u2 * s2) return;
      refuse(i, d, std::sqrt(u2 * s2));
    };
    if (floating_) {
      evaluate_floating(q, qd, tau, qdd, check);
    } else if constexpr (std::is_same_v<T, S>) {
      detail::tree_aba_kernel<T>(links_, g_, q, qd, tau, qdd, check);
    } else {
      detail::tree_aba_kernel<T>(detail::cast_links<T>(links_), vec3<T>(g_.template cast<T>()), q, qd, tau, qdd,
                                 check);
    }
    detail::check_overflow(qdd.derived(), "aba");
  }

  /// With applied forces (external wrenches, dynamics/wrench.hpp): q̈ for τ + Q_ext(q).
  template <class Q, class QD, class TAU, applied_forces F>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                  const F& fx) const {
    using T = promote_t<promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>, typename TAU::Scalar>,
                        detail::applied_scalar_t<F, Q>>;
    vecN<T, dynamic> out(dof());  // q̈ the one allocation: τ + Q_ext in evaluate's stack scratch
    evaluate(q, qd, tau, fx, out);
    return out;
  }
  /// …into qdd (of the model's, the inputs' and Q_ext's promoted scalar): the call's numbers
  /// bit for bit; τ + Q_ext in stack scratch, so no allocation where the applied forces write
  /// into storage (external_wrenches does).
  template <class Q, class QD, class TAU, applied_forces F, class QDD>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                const F& fx, Eigen::MatrixBase<QDD>& qdd) const {
    using R = promote_t<typename TAU::Scalar, detail::applied_scalar_t<F, Q>>;
    detail::check_size(tau, dof(), "tau");
    detail::small_buffer<R, dynamic> buf(dof());
    Eigen::Map<vecN<R, dynamic>> t(buf.data(), dof());
    t = tau.template cast<R>();
    detail::add_applied<+1>(fx, q, t);
    evaluate(q, qd, t, qdd);
  }

 private:
  /// A floating tree: the fixed-base tree in the root's frame (model/floating.hpp) gives
  /// q̈_K; a = q̈_K + (b(v), 0). b is taken before the kernel writes q̈ (which may be q̇'s storage).
  template <class Q, class QD, class TAU, class QDD, class Check>
  void evaluate_floating(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                         const Eigen::MatrixBase<TAU>& tau, Eigen::MatrixBase<QDD>& qdd, const Check& check) const {
    using T = typename QDD::Scalar;
    const int n = dof();
    detail::small_buffer<T, dynamic> qk_s(n);
    Eigen::Map<vecN<T, dynamic>> qk(qk_s.data(), n);
    detail::trunk_configuration(q, qk);
    spatial::vec6<T> minus_b = spatial::vec6<T>::Zero();
    detail::subtract_root_bias(qd, minus_b);
    const vec3<T> g = detail::root_rotation<T>(q).transpose() * g_.template cast<T>();
    if constexpr (std::is_same_v<T, S>)
      detail::tree_aba_kernel<T>(links_, g, qk, qd, tau, qdd, check);
    else
      detail::tree_aba_kernel<T>(detail::cast_links<T>(links_), g, qk, qd, tau, qdd, check);
    qdd.template head<6>() -= minus_b;
  }
  static double sq(double x) { return x * x; }
  [[noreturn]] void refuse(int i, double d, double scale) const {
    std::ostringstream os;
    os << "aba: model '" << name_ << "', joint '" << joints_[static_cast<std::size_t>(i)]
       << "': the articulated inertia along the joint axis is D = " << d;
    if (std::isfinite(d) && d < 0) {
      os << ", negative: the model's inertias are not physical (an articulated inertia is positive semi-definite)";
    } else {
      if (std::isfinite(d) && d > 0) os << ", numerically zero against its scale " << scale << " (64 ε)";
      os << ": the forward dynamics is singular there (nothing with mass or inertia moves with this joint)";
    }
    throw numerical_error(os.str());
  }

  std::vector<detail::tree_link<S>> links_;
  vec3<S> g_;
  std::string name_;
  std::vector<std::string> joints_;
  bool floating_ = false;
};

/// The articulated-body forward dynamics of a tree (a chain: `aba(as_tree(chain))`).
template <class S>
aba_fn<S> aba(const tree<S>& t) {
  return aba_fn<S>(t);
}

}  // namespace nhdyn
