#pragma once
/// \file functional/values.hpp
/// The small named values that flow between pipeline stages. Each carries q along so
/// that a later stage that needs the configuration (a projection) gets it without a
/// back-channel.
#include "../model/chain.hpp"

namespace nhdyn {

/// ξ = (q, q̇, q̈): the joint state of the stationary chain (n entries each).
template <class S, int N = dynamic>
struct joint_state {
  vecN<S, N> q, qd, qdd;
};

/// ζ = (q, η, η̇): configuration and actuator velocities/accelerations (m entries).
template <class S, int N = dynamic, int M = dynamic>
struct reduced_state {
  vecN<S, N> q;
  vecN<S, M> eta, eta_dot;
};

/// v, the joint-space generalised forces of the chain at configuration q.
template <class S, int N = dynamic>
struct generalized_forces {
  vecN<S, N> q;
  vecN<S, N> v;
};

/// A value together with what an earlier stage already evaluated at q, for a later stage
/// to reuse (differential_drive's lift passes its sin/cos of the heading on to the
/// projection). It derives from the value, so a stage written for the plain value accepts
/// it; a stage that builds a new plain value just drops the memo, and the later stage
/// evaluates the quantity itself. The numbers are the same either way.
template <class Value, class Memo>
struct with_memo : Value {
  Memo memo;
};

/// τ (actuator forces, m entries) and λ (constraint forces, k entries) at q.
template <class S, int M = dynamic, int K = dynamic>
struct constrained_forces {
  vecN<S, M> tau;
  vecN<S, K> lambda;
};

/// Forces applied to the joints from outside, known at q: `f.generalized_force(q)` (n
/// entries, the power they deliver is its dot product with q̇) — external wrenches
/// (dynamics/wrench.hpp). The dynamics take one as an optional last argument: rne and the
/// inverse dynamics subtract it (the actuators need that much less), the forward dynamics add
/// it to τ. A type opts in by declaring `using applied_forces_tag = void;`.
template <class F>
concept applied_forces = requires { typename std::remove_cvref_t<F>::applied_forces_tag; };

namespace detail {
/// v − Q_ext(q), N entries in the common scalar: what rne returns with applied forces.
template <int N, class V, class F, class Q>
auto minus_applied(const V& v, const F& fx, const Q& q) {
  const auto Qx = fx.generalized_force(q);
  using R = promote_t<typename V::Scalar, typename decltype(Qx)::Scalar>;
  vecN<R, N> out = v.template cast<R>() - Qx.template cast<R>();
  return out;
}
/// τ + Q_ext(q) in the common scalar: what the forward dynamics solve for with applied forces.
template <class Tau, class F, class Q>
auto plus_applied(const Tau& tau, const F& fx, const Q& q) {
  const auto Qx = fx.generalized_force(q);
  using R = promote_t<typename Tau::Scalar, typename decltype(Qx)::Scalar>;
  vecN<R, dynamic> out = tau.template cast<R>() + Qx.template cast<R>();
  return out;
}
}  // namespace detail

}  // namespace nhdyn
