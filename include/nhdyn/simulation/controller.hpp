#pragma once
/// \file simulation/controller.hpp
/// Controllers of the closed loop: the joint-space computed-torque controller (below, with
/// its equations), `any_controller` (either behind one call), and the paper's robust
/// task-space controller (paper.md §3, Salazar-Silva et al. §V) for a
/// point r ∈ R³ on any body of any model (a DH chain or a kinematic tree) with any
/// constraint; paper5.md uses it with r the origin of paper5's last link:
///
///     r̃ = r_d − r,  dr̃/dt = ṙ_d − B η,  e = (r̃, dr̃/dt) ∈ R⁶,  H = [0; −I₃]
///     δ   = −ρ(e) Hᵀ P e / max(‖Hᵀ P e‖, ε)   (0 where Hᵀ P e = 0)        (eq. 23–28)
///     ρ(e) = (γ₂‖e‖² + γ₁‖e‖ + γ₀) / (1 − α)
///     a_r = r̈_d + K₁ dr̃/dt + K₀ r̃ + δ                                          (eq. 23)
///     a   = B⁺(a_r − Ḃη) + (I − B⁺B) z,   B⁺ = Bᵀ(BBᵀ + λ²I)⁻¹                 (eq. 30, damped)
///     z   = −k_N η − k_P Sᵀ W (q − q_posture)    (W selects the posture joints)
///     τ   = (SᵀS)⁻¹ Sᵀ rne_nominal(q, Sη, Sa + Ṡη)                              (eq. 21)
///
/// with B = J_v(q) S(q) (3×m, eq. 29; J_v the point's translational Jacobian), Ḃη = J̇q̇ + J_v Ṡ η at q̇ = Sη, and P the solution of
/// the Lyapunov equation A_cᵀP + PA_c = −I₆, A_c = [0 I; −K₀ −K₁]. ε = 0 is the paper's
/// discontinuous unit vector; ε > 0 the boundary-layer variant. For paper5's posture term
/// (0, 0, q₄ − q₄(0), q₅ − q₅(0)) W = diag(0, 0, 0, 1, 1): Sᵀ maps it to η's slots.
///
/// Everything the controller knows is its (nominal) model; the plant is another object.
/// The call is generic over the state's scalar, so duals give the closed loop's exact
/// Jacobian (rosenbrock4, linearisation).
///
///     nhdyn::rac_controller ctrl(nominal.chain, nominal.constraint, gains, q0, mask);
///     Eigen::Vector4d tau = ctrl(q, eta, r_measured, circle(t));
///     // any tree and constraint, the point p on body i (1-based, as tree_kinematics):
///     nhdyn::rac_controller arm(tree, c, gains, q0, mask, i, p);
#include <optional>
#include <variant>

#include <Eigen/Dense>

#include "../config.hpp"
#include "../detail/compiled_abi.hpp"
#include "../constraints/stages.hpp"
#include "../detail/ldlt.hpp"
#include "../dynamics/friction.hpp"
#include "../dynamics/tree.hpp"
#include "../kinematics/kinematics.hpp"
#include "../kinematics/tree.hpp"
#include "references.hpp"

namespace nhdyn {

/// The robust term's constants (Table III) and the boundary layer ε (0: none).
struct robust_gains {
  double alpha = 0, gamma0 = 0, gamma1 = 0.1, gamma2 = 0.2, epsilon = 0;
};

struct rac_gains {
  Eigen::Matrix3d K0 = 400 * Eigen::Matrix3d::Identity();
  Eigen::Matrix3d K1 = 40 * Eigen::Matrix3d::Identity();
  double lambda = 0.02;  ///< damping of B⁺ [m/s² per rad/s², i.e. units of B]
  double kN = 4, kP = 4;  ///< null-space damping [1/s] and posture stiffness [1/s²]
  robust_gains robust{};
  bool use_robust = true;
};

/// P with A_cᵀP + PA_c = −I₆, A_c = [0 I; −K₀ −K₁], by the vectorised (Kronecker) linear
/// system (I ⊗ A_cᵀ + A_cᵀ ⊗ I) vec P = −vec I. Throws numerical_error if A_c is not
/// Hurwitz (P not positive definite).
template <class = void>
Eigen::Matrix<double, 6, 6> lyapunov_P(const Eigen::Matrix3d& K0, const Eigen::Matrix3d& K1);
#if NHDYN_DEFINES(NHDYN_PART_SIMULATION)
template <class>
Eigen::Matrix<double, 6, 6> lyapunov_P(const Eigen::Matrix3d& K0, const Eigen::Matrix3d& K1) {
  using M6 = Eigen::Matrix<double, 6, 6>;
  M6 Ac = M6::Zero();
  Ac.topRightCorner<3, 3>().setIdentity();
  Ac.bottomLeftCorner<3, 3>() = -K0;
  Ac.bottomRightCorner<3, 3>() = -K1;
  Eigen::Matrix<double, 36, 36> L = Eigen::Matrix<double, 36, 36>::Zero();
  const M6 I = M6::Identity(), At = Ac.transpose();
  for (int j = 0; j < 6; ++j) L.block<6, 6>(6 * j, 6 * j) += At;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) L.block<6, 6>(6 * i, 6 * j) += At(i, j) * I;
  const M6 minusI = -I;
  const Eigen::Matrix<double, 36, 1> p =
      L.fullPivLu().solve(Eigen::Map<const Eigen::Matrix<double, 36, 1>>(minusI.data()));
  M6 P = Eigen::Map<const M6>(p.data());
  P = (0.5 * (P + P.transpose())).eval();
  // positive definite ⇔ its Cholesky factor exists (LLT: far less to compile than an eigensolver)
  if (!P.allFinite() || Eigen::LLT<M6>(P).info() != Eigen::Success)
    throw numerical_error("controller gains: A_c = [0 I; −K₀ −K₁] is not Hurwitz (no positive-definite P)");
  return P;
}
#endif  // NHDYN_DEFINES(NHDYN_PART_SIMULATION)

namespace detail {
template <class S, int N>
kinematics<S, N> kinematics_of(const chain<S, N>& c) {
  return kinematics<S, N>(c);
}
template <class S>
tree_kinematics<S> kinematics_of(const tree<S>& t) {
  return tree_kinematics<S>(t);
}
/// The controllers' inverse dynamics with the joints' friction: project ∘ (rne + τ_f) ∘ lift.
template <class Model, class C>
using friction_inverse_dynamics_t = decltype(inverse_dynamics(std::declval<const Model&>(), std::declval<const C&>(),
                                                              rne_options{}, std::declval<friction_fn>()));
}  // namespace detail

/// Model: chain<S, N> (the default) or tree<S> (N = dynamic).
template <class S, int N, class C, class Model = chain<S, N>>
class rac_controller {
 public:
  static constexpr int M = C::m_at_compile_time;

  /// nominal: the controller's model; posture_mask: 1 for joints the posture term holds at
  /// q_posture (paper5: joints 4 and 5), 0 elsewhere; task_body: the link or body carrying r
  /// (1…n as the kinematics number them; default the last), task_point: r on it, in its frame.
  /// o: the terms of eq. 21's rne (gravity, velocity; dynamics/terms.hpp); friction: the
  /// joints' friction the controller compensates (eq. 21 with rne + τ_f), none by default.
  rac_controller(const Model& nominal, C c, rac_gains g, vecN<double, N> q_posture, vecN<double, N> posture_mask,
                 int task_body = -1, const vec3<S>& task_point = vec3<S>::Zero(), rne_options o = {},
                 std::optional<friction_fn> friction = std::nullopt)
      : c_(c), kin_(detail::kinematics_of(nominal)), id_(inverse_dynamics(nominal, c, o)), g_(std::move(g)),
        P_(lyapunov_P(g_.K0, g_.K1)), q_posture_(std::move(q_posture)), mask_(std::move(posture_mask)),
        link_(task_body < 0 ? nominal.dof() : task_body), point_(task_point) {
    if (!(g_.lambda >= 0) || !(g_.kN >= 0) || !(g_.kP >= 0) || !(g_.robust.epsilon >= 0) ||
        !(g_.robust.alpha >= 0 && g_.robust.alpha < 1))
      throw input_error("controller gains: need λ, k_N, k_P, ε ≥ 0 and 0 ≤ α < 1");
    const int n = nominal.dof();
    if (q_posture_.size() != n || mask_.size() != n)
      throw input_error("controller: the posture and its mask need " + std::to_string(n) + " entries (one per joint)");
    if (c_.dof() != n)
      throw input_error("controller: the constraint is for " + std::to_string(c_.dof()) + " coordinates, the model has " +
                        std::to_string(n));
    if (link_ < 1 || link_ > n) throw input_error("controller: task body " + std::to_string(link_) + " is not in 1…" + std::to_string(n));
    if (!point_.allFinite()) throw input_error("controller: the task point is not finite");
    if (friction) {
      if (friction->dof() != n)
        throw input_error("controller: the friction is of " + std::to_string(friction->dof()) + " joints, the model has " +
                          std::to_string(n));
      idf_.emplace(inverse_dynamics(nominal, c_, o, std::move(*friction)));
    }
  }
  const Eigen::Matrix<double, 6, 6>& P() const { return P_; }
  const rac_gains& gains() const { return g_; }

  /// The robust term δ(e) (the outer loop, eq. 23–28).
  template <class T>
  vec3<T> delta(const Eigen::Matrix<T, 6, 1>& e) const {
    using std::sqrt;
    const auto& rb = g_.robust;
    const vec3<T> w = -(P_.template cast<T>() * e).template tail<3>();  // Hᵀ P e, H = [0; −I]
    const T e2 = e.squaredNorm(), w2 = w.squaredNorm();
    if (!g_.use_robust || value_of(w2) == 0) return vec3<T>::Zero();
    const T ne = value_of(e2) == 0 ? T(0) : T(sqrt(e2));
    const T rho = (T(rb.gamma2) * e2 + T(rb.gamma1) * ne + T(rb.gamma0)) / T(1 - rb.alpha);
    const T nw = sqrt(w2);
    const T den = value_of(nw) >= rb.epsilon ? nw : T(rb.epsilon);
    return vec3<T>(-rho * w / den);
  }

  /// τ (m entries) for the state (q, η), the measured task point r and the reference.
  template <class T>
  vecN<T, M> operator()(const vecN<T, N>& q, const vecN<T, M>& eta, const vec3<T>& r,
                        const task_reference<T>& ref) const {
    const vecN<T, N> qd = apply_S(c_, q, eta);
    const Eigen::Matrix<T, 3, N> Jv = kin_.jacobian(q, link_, point_).template topRows<3>();
    const auto Sq = c_.S(q);
    const Eigen::Matrix<T, 3, M> B = Jv * Sq;                                       // eq. 29
    const vec3<T> Bdot_eta = kin_.jdot_qdot(q, qd, link_, point_).linear + Jv * apply_Sdot(c_, q, qd, eta);
    Eigen::Matrix<T, 6, 1> e;
    e << ref.r - r, ref.rd - B * eta;
    const vec3<T> a_r = ref.rdd + g_.K1.template cast<T>() * e.template tail<3>() +
                        g_.K0.template cast<T>() * e.template head<3>() + delta(e);  // eq. 23
    Eigen::Matrix3d l2 = g_.lambda * g_.lambda * Eigen::Matrix3d::Identity();
    const Eigen::Matrix<T, 3, 3> G = B * B.transpose() + l2.cast<T>();
    const auto f = ldlt_factor<T, 3>(G, "B Bᵀ + λ²I");
    const Eigen::Matrix<T, M, 3> Bp = B.transpose() * f.solve(Eigen::Matrix<T, 3, 3>::Identity());
    const vecN<T, N> dq = (mask_.template cast<T>().array() * (q - q_posture_.template cast<T>()).array()).matrix();
    const vecN<T, M> z = -T(g_.kN) * eta - T(g_.kP) * apply_St(c_, q, dq);
    const vecN<T, M> a = Bp * (a_r - Bdot_eta) + z - Bp * (B * z);                 // eq. 30
    if (idf_) return vecN<T, M>((*idf_)(q, eta, a));                                // eq. 21 with friction
    return id_(q, eta, a);                                                          // eq. 21
  }

  /// The task point r(q) on the controller's model.
  template <class T>
  vec3<T> task_point(const vecN<T, N>& q) const {
    return kin_.point(q, link_, point_);
  }

  /// The singular values of B(q) = J_v(q) S(q) (eq. 29), largest first, in double: how far
  /// the task is from a singular configuration (σ₃ → 0 there: some task velocity cannot be
  /// produced). With λ > 0 the damped B⁺ keeps its gain σ/(σ² + λ²) ≤ 1/(2λ) there; with
  /// λ = 0 the controller throws numerical_error at a singular B instead of dividing by 0.
  Eigen::Vector3d task_singular_values(const vecN<double, N>& q) const {
    const Eigen::Matrix<double, 3, M> B = kin_.jacobian(q, link_, point_).template topRows<3>() * c_.S(q);
    return Eigen::JacobiSVD<Eigen::Matrix<double, 3, M>>(B).singularValues().template head<3>();
  }

 private:
  C c_;
  decltype(detail::kinematics_of(std::declval<const Model&>())) kin_;
  decltype(inverse_dynamics(std::declval<const Model&>(), std::declval<const C&>())) id_;
  std::optional<detail::friction_inverse_dynamics_t<Model, C>> idf_;  ///< with friction (then used instead of id_)
  rac_gains g_;
  Eigen::Matrix<double, 6, 6> P_;
  vecN<double, N> q_posture_, mask_;
  int link_;
  vec3<S> point_;
};

template <class S, int N, class C, class... A>
rac_controller(const chain<S, N>&, C, A...) -> rac_controller<S, N, C>;
template <class S, class C, class... A>
rac_controller(const tree<S>&, C, A...) -> rac_controller<S, dynamic, C, tree<S>>;

/// Gains of the joint-space computed-torque controller (defaults: ω_n = 10 rad/s, ζ = 1).
struct ct_gains {
  double kp = 100;  ///< k_P [1/s²]
  double kd = 20;   ///< k_D [1/s]
};

/// The joint-space computed-torque controller (Siciliano et al., Robotics, §8.5.2) for any
/// model and constraint, on its nominal model and a joint-space reference (q_d, q̇_d, q̈_d):
///
///     q̇ = S η,   a_q = q̈_d + k_D (q̇_d − q̇) + k_P (q_d − q)
///     η̇* = (SᵀS)⁻¹ Sᵀ (a_q − Ṡ η)        (the admissible η̇ nearest to a_q, least squares)
///     τ  = (SᵀE)⁻¹ Sᵀ rne_nominal(q, Sη, Sη̇* + Ṡη)   (eq. 21; E = S without an input map)
///
/// Without a constraint (S = I) this is τ = M(q) a_q + h(q, q̇), and on the nominal plant the
/// error obeys ë + k_D ė + k_P e = 0. With a constraint only the part of the error that the
/// admissible motions can correct is corrected: a nonholonomic base's sideways error is not
/// (no smooth static feedback stabilises it, Brockett 1983) — drive a wheeled base with the
/// task-space controller, or give it a feasible joint-space path and a small initial error.
template <class S, int N, class C, class Model = chain<S, N>>
class computed_torque_controller {
 public:
  static constexpr int M = C::m_at_compile_time;

  /// o: the terms of the nominal rne (gravity, velocity; dynamics/terms.hpp); friction: the
  /// joints' friction the controller compensates (rne + τ_f), none by default.
  computed_torque_controller(const Model& nominal, C c, ct_gains g, rne_options o = {},
                             std::optional<friction_fn> friction = std::nullopt)
      : c_(c), id_(inverse_dynamics(nominal, c, o)), g_(g), n_(nominal.dof()) {
    if (!(g_.kp >= 0) || !(g_.kd >= 0) || !std::isfinite(g_.kp) || !std::isfinite(g_.kd))
      throw input_error("computed-torque controller: need finite k_P, k_D ≥ 0");
    if (c_.dof() != n_)
      throw input_error("computed-torque controller: the constraint is for " + std::to_string(c_.dof()) +
                        " coordinates, the model has " + std::to_string(n_));
    if (friction) {
      if (friction->dof() != n_)
        throw input_error("computed-torque controller: the friction is of " + std::to_string(friction->dof()) +
                          " joints, the model has " + std::to_string(n_));
      idf_.emplace(inverse_dynamics(nominal, c_, o, std::move(*friction)));
    }
  }
  const ct_gains& gains() const { return g_; }

  /// τ (m entries) for the state (q, η) and a joint-space reference (ref.q, ref.qd, ref.qdd);
  /// the measured task point is not used.
  template <class T>
  vecN<T, M> operator()(const vecN<T, N>& q, const vecN<T, M>& eta, const vec3<T>&, const task_reference<T>& ref) const {
    if (ref.q.size() != n_ || ref.qd.size() != n_ || ref.qdd.size() != n_)
      throw input_error("computed-torque controller: needs a joint-space reference with " + std::to_string(n_) +
                        " joints (q_d, q̇_d, q̈_d), got " + std::to_string(ref.q.size()));
    const vecN<T, N> qd = apply_S(c_, q, eta);
    const vecN<T, N> a = vecN<T, N>(ref.qdd) + T(g_.kd) * (vecN<T, N>(ref.qd) - qd) + T(g_.kp) * (vecN<T, N>(ref.q) - q);
    const vecN<T, M> rhs = apply_St(c_, q, vecN<T, N>(a - apply_Sdot(c_, q, qd, eta)));
    const auto id = [&](const vecN<T, M>& eta_dot) -> vecN<T, M> {
      if (idf_) return vecN<T, M>((*idf_)(q, eta, eta_dot));
      return id_(q, eta, eta_dot);
    };
    if constexpr (C::orthonormal_S) {
      return id(rhs);
    } else {
      const auto Sq = c_.S(q);
      const Eigen::Matrix<T, M, M> G = Sq.transpose() * Sq;
      return id(vecN<T, M>(ldlt_factor<T, M>(G, "SᵀS").solve(rhs)));
    }
  }

 private:
  C c_;
  decltype(inverse_dynamics(std::declval<const Model&>(), std::declval<const C&>())) id_;
  std::optional<detail::friction_inverse_dynamics_t<Model, C>> idf_;  ///< with friction (then used instead of id_)
  ct_gains g_;
  int n_;
};

template <class S, int N, class C, class... A>
computed_torque_controller(const chain<S, N>&, C, ct_gains, A...) -> computed_torque_controller<S, N, C>;
template <class S, class C, class... A>
computed_torque_controller(const tree<S>&, C, ct_gains, A...) -> computed_torque_controller<S, dynamic, C, tree<S>>;

/// Either controller behind one call (a scene picks one at run time; the closed loop is
/// compiled once for both).
template <class S, int N, class C, class Model = chain<S, N>>
class any_controller {
 public:
  static constexpr int M = C::m_at_compile_time;
  using rac = rac_controller<S, N, C, Model>;
  using computed_torque = computed_torque_controller<S, N, C, Model>;

  any_controller(rac c) : v_(std::move(c)) {}
  any_controller(computed_torque c) : v_(std::move(c)) {}

  template <class T>
  vecN<T, M> operator()(const vecN<T, N>& q, const vecN<T, M>& eta, const vec3<T>& r, const task_reference<T>& ref) const {
    return std::visit([&](const auto& c) { return vecN<T, M>(c(q, eta, r, ref)); }, v_);
  }

 private:
  std::variant<rac, computed_torque> v_;
};

}  // namespace nhdyn
