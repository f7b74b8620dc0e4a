#pragma once
/// \file functional/values.hpp
/// The small named values that flow between pipeline stages. Each carries q along so
/// that a later stage that needs the configuration (a projection) gets it without a
/// back-channel.
#include "../detail/small_buffer.hpp"
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
/// Q_ext(q)'s scalar for applied forces F at a q of Q's scalar.
template <class F, class Q>
using applied_scalar_t = typename decltype(std::declval<const F&>().generalized_force(std::declval<const Q&>()))::Scalar;
/// Q_ext(q) into out (n entries of its own scalar): into the storage where F writes into
/// storage (`generalized_force_into`: external wrenches do), else from F's new vector.
template <class F, class Q, class Out>
void generalized_force_into(const F& fx, const Q& q, Out& out) {
  if constexpr (requires { fx.generalized_force_into(q, out); })
    fx.generalized_force_into(q, out);
  else
    out = fx.generalized_force(q).template cast<typename Out::Scalar>();
}
/// v −= Q_ext(q) (sign −1) or v += Q_ext(q) (sign +1), entry by entry, in v's scalar (which
/// must hold Q_ext's), Q_ext in stack scratch (beyond 4096 entries, a block the thread keeps):
/// no allocation where F writes into storage. The call forms (minus_applied, plus_applied) and
/// the `evaluate` forms all add Q_ext through it, so they agree bit for bit.
template <int Sign, class F, class Q, class V>
void add_applied(const F& fx, const Q& q, Eigen::MatrixBase<V>& v) {
  using R = applied_scalar_t<F, Q>;
  using T = typename V::Scalar;
  static_assert(std::is_same_v<promote_t<T, R>, T>, "the result's scalar holds Q_ext's");
  const int n = static_cast<int>(v.size());
  small_buffer<R, dynamic> buf(n);
  Eigen::Map<vecN<R, dynamic>> Qx(buf.data(), n);
  generalized_force_into(fx, q, Qx);
  for (int j = 0; j < n; ++j) {
    if constexpr (Sign < 0)
      v(j) = v(j) - T(Qx(j));
    else
      v(j) = v(j) + T(Qx(j));
  }
}
/// v − Q_ext(q), N entries in the common scalar: what rne returns with applied forces.
/// A new v of that type is moved in, not copied: a call that forms v allocates it only.
template <int N, class V, class F, class Q>
auto minus_applied(V&& v, const F& fx, const Q& q) {
  using W = std::remove_cvref_t<V>;
  using R = promote_t<typename W::Scalar, applied_scalar_t<F, Q>>;
  vecN<R, N> out;
  if constexpr (std::is_same_v<W, vecN<R, N>> && !std::is_lvalue_reference_v<V>)
    out = std::move(v);
  else
    out = v.template cast<R>();
  add_applied<-1>(fx, q, out);
  return out;
}
/// τ + Q_ext(q) in the common scalar: what the forward dynamics solve for with applied forces.
template <class Tau, class F, class Q>
auto plus_applied(const Tau& tau, const F& fx, const Q& q) {
  using R = promote_t<typename Tau::Scalar, applied_scalar_t<F, Q>>;
  vecN<R, dynamic> out = tau.template cast<R>();
  add_applied<+1>(fx, q, out);
  return out;
}
}  // namespace detail

}  // namespace nhdyn
