#pragma once
/// \file simulation/free_motion.hpp
/// The unactuated (τ = 0), undamped motion of a constrained robot under gravity: the
/// physics-invariant test problem of the integrator studies. State x = (q, η):
///
///     ẋ = (S(q) η, η̇(q, η, 0)),     η̇ from nh_forward_dynamics
///     E(x) = ½ ηᵀ M_η(q) η − Σᵢ mᵢ gᵀ p_cᵢ(q)      (conserved by the exact motion)
///     residual(x) = max |A(q) S(q) η|               (zero by construction; rounding only)
///
/// Used by tests/test_simulation.cpp, examples/long_horizon.cpp and
/// examples/work_precision.cpp.
#include "../constraints/constraint.hpp"
#include "../constraints/forward_dynamics.hpp"
#include "../kinematics/kinematics.hpp"
#include "../model/chain.hpp"

namespace nhdyn {

template <class S, int N, class C>
class free_motion {
 public:
  static constexpr int M = C::m_at_compile_time;
  static constexpr int NX = (N == dynamic || M == dynamic) ? dynamic : N + M;
  using state = vecN<S, NX>;

  free_motion(const chain<S, N>& ch, const C& c)
      : ch_(ch), c_(c), kin_(ch), fd_(nh_forward_dynamics(ch, c)), n_(c.dof()), m_(c.m()) {}

  /// ẋ = f(t, x), generic over the scalar (duals for the implicit integrator's Jacobian).
  auto rhs() const {
    return [this](const auto& t, const auto& x) {
      using T = std::decay_t<decltype(t)>;
      const vecN<T, N> q = x.head(n_);
      const vecN<T, M> eta = x.tail(m_);
      vecN<T, NX> dx(n_ + m_);
      dx << apply_S(c_, q, eta), fd_(q, eta, vecN<T, M>::Zero(m_));
      return dx;
    };
  }
  /// Kinetic plus potential energy.
  double energy(const state& x) const {
    const vecN<S, N> q = x.head(n_);
    const vecN<S, M> eta = x.tail(m_);
    double V = 0;
    for (int i = 0; i < n_; ++i)
      V -= value_of(ch_[i].mass) * value_of(S(ch_.gravity().dot(kin_.point(q, i + 1, ch_[i].com))));
    return 0.5 * value_of(S(eta.dot(fd_.reduced_inertia(q) * eta))) + V;
  }
  /// max |A(q) S(q) η|.
  double constraint_residual(const state& x) const {
    const vecN<S, N> q = x.head(n_);
    const vecN<S, M> eta = x.tail(m_);
    if (c_.k() == 0) return 0.0;
    return value_of(S((c_.A(q) * apply_S(c_, q, eta)).cwiseAbs().maxCoeff()));
  }
  const chain<S, N>& model() const { return ch_; }
  const C& constraint() const { return c_; }

 private:
  chain<S, N> ch_;
  C c_;
  kinematics<S, N> kin_;
  decltype(nh_forward_dynamics(std::declval<const chain<S, N>&>(), std::declval<const C&>())) fd_;
  int n_, m_;
};

template <class S, int N, class C>
free_motion(const chain<S, N>&, const C&) -> free_motion<S, N, C>;

}  // namespace nhdyn
