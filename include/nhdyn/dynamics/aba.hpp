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
/// `reference_aba` is the algorithm as the book writes it (one screen, its names and equation
/// numbers); `aba(tree)` is the checked function object around it.
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "../errors.hpp"
#include "../functional/values.hpp"
#include "reference.hpp"
#include "rne.hpp"

namespace nhdyn {

namespace reference {
/// q̈ by the articulated-body algorithm (RBDA Table 7.1), gravity as the base acceleration
/// a_0 = −a_g. `check(i, D_i, U_i, S_i)` sees every articulated inertia along a joint axis,
/// D_i = S_iᵀ U_i with U_i = I^A_i S_i, before it is divided by.
template <class T, class S, class Check>
vecX<T> aba(const tree<S>& t, const vecX<T>& q, const vecX<T>& qd, const vecX<T>& tau, const Check& check) {
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
    check(i, D[i], U[i], Si[i]);
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
/// The same, unchecked.
template <class T, class S>
vecX<T> aba(const tree<S>& t, const vecX<T>& q, const vecX<T>& qd, const vecX<T>& tau) {
  return aba<T>(t, q, qd, tau, [](int, const T&, const spatial::vec6<T>&, const spatial::vec6<T>&) {});
}
}  // namespace reference

/// q̈ = aba(q, q̇, τ) on a tree, any scalar: inputs checked (sizes, finite), every articulated
/// inertia along its joint axis checked before the division (see the file comment), the
/// result checked for overflow.
template <class S>
class aba_fn : public stage_tag {
 public:
  explicit aba_fn(const tree<S>& t) : t_(t) {}
  int dof() const { return t_.dof(); }

  template <class Q, class QD, class TAU>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<TAU>& tau) const {
    using T = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>, typename TAU::Scalar>;
    const int n = t_.dof();
    detail::check_size(q, n, "q");
    detail::check_size(qd, n, "qd");
    detail::check_size(tau, n, "tau");
    detail::check_finite(q, "q");
    detail::check_finite(qd, "qd");
    detail::check_finite(tau, "tau");
    const auto check = [&](int i, const T& D, const spatial::vec6<T>& U, const spatial::vec6<T>& Si) {
      const auto norm = [](const spatial::vec6<T>& v) { return v.unaryExpr([](const T& x) { return value_of(x); }).template cast<double>().norm(); };
      const double d = value_of(D), s = norm(U) * norm(Si);  // D ≤ |U||S| (Cauchy–Schwarz)
      if (std::isfinite(d) && d > 64 * std::numeric_limits<double>::epsilon() * s) return;
      std::ostringstream os;
      os << "aba: model '" << t_.name() << "', joint '" << t_[i].joint_name
         << "': the articulated inertia along the joint axis is D = " << d;
      if (std::isfinite(d) && d < 0) {
        os << ", negative: the model's inertias are not physical (an articulated inertia is positive semi-definite)";
      } else {
        if (std::isfinite(d) && d > 0) os << ", numerically zero against its scale " << s << " (64 ε)";
        os << ": the forward dynamics is singular there (nothing with mass or inertia moves with this joint)";
      }
      throw numerical_error(os.str());
    };
    vecN<T, dynamic> out = reference::aba<T>(t_, vecN<T, dynamic>(q.template cast<T>()),
                                             vecN<T, dynamic>(qd.template cast<T>()),
                                             vecN<T, dynamic>(tau.template cast<T>()), check);
    detail::check_overflow(out, "aba");
    return out;
  }

  /// With applied forces (external wrenches, dynamics/wrench.hpp): q̈ for τ + Q_ext(q).
  template <class Q, class QD, class TAU, applied_forces F>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<TAU>& tau,
                  const F& fx) const {
    detail::check_size(tau, t_.dof(), "tau");
    return (*this)(q, qd, detail::plus_applied(tau, fx, q));
  }

 private:
  tree<S> t_;
};

/// The articulated-body forward dynamics of a tree (a chain: `aba(as_tree(chain))`).
template <class S>
aba_fn<S> aba(const tree<S>& t) {
  return aba_fn<S>(t);
}

}  // namespace nhdyn
