#pragma once
/// \file dynamics/rne.hpp
/// `rne`: the holonomic recursive Newton–Euler inverse dynamics of a serial chain,
///
///     v = rne(q, q̇, q̈) = M(q) q̈ + C(q, q̇) q̇ + g(q)          (n joint forces/torques)
///
/// in link frames (Luh, Walker & Paul 1980; Spong, Hutchinson & Vidyasagar 2006, §7.5),
/// generic over the scalar. Gravity enters as a base acceleration a_0 = −g. Links with zero
/// mass and zero inertia are skipped; a link with zero mass but rotational inertia is not.
///
/// Options say what a scene needs, and a call pays only for that:
/// `gravity = false` drops g(q); `velocity = false` drops C(q, q̇)q̇ (then q̇ is not read).
///
/// Example:
///     auto id = nhdyn::rne(nhdyn::presets::puma560());
///     Eigen::VectorXd tau = id(q, qd, qdd);
#include "../detail/dh.hpp"
#include "../detail/small_buffer.hpp"
#include "../functional/compose.hpp"
#include "../functional/values.hpp"

namespace nhdyn {

struct rne_options {
  bool gravity = true;   ///< include g(q)
  bool velocity = true;  ///< include C(q, q̇) q̇
};

namespace detail {

template <class T>
struct rne_scratch {
  vec3<T> F, Nn;  // net force on link i and net moment about o_i, frame i
  T ct, st;       // cos θ_i, sin θ_i
};

/// The recursion. Gravity and Velocity are compile-time so that a call that needs
/// neither pays for neither.
template <bool Gravity, bool Velocity, class T, int N, class Links, class Q, class QD, class QDD>
vecN<T, N> rne_kernel(const Links& L, const vec3<T>& g, const Q& q, const QD& qd, const QDD& qdd) {
  const int n = static_cast<int>(q.size());
  small_buffer<rne_scratch<T>, N> ws(n);
  vec3<T> w = vec3<T>::Zero(), dw = vec3<T>::Zero();  // ω_i, ω̇_i  (frame i)
  vec3<T> acc = Gravity ? vec3<T>(-g) : vec3<T>::Zero();  // a_{o_i} − g (frame i)
  // Forward pass: velocities and accelerations, base to tip.
  for (int i = 0; i < n; ++i) {
    const auto& k = L[static_cast<std::size_t>(i)];
    const auto [ct, st, d] = geometry(k, T(q(i)));
    const vec3<T> p = offset<T>(k, d);
    if (k.revolute) {
      // ω_i = Rᵀ(ω_{i−1} + z q̇_i), ω̇_i = Rᵀ(ω̇_{i−1} + z q̈_i + ω_{i−1} × z q̇_i)
      if constexpr (Velocity) {
        const T qdi = T(qd(i));
        dw = rot_T(k, ct, st, vec3<T>(dw.x() + w.y() * qdi, dw.y() - w.x() * qdi, dw.z() + T(qdd(i))));
        w = rot_T(k, ct, st, vec3<T>(w.x(), w.y(), w.z() + qdi));
        acc = rot_T(k, ct, st, acc) + dw.cross(p) + w.cross(w.cross(p));
      } else {
        dw = rot_T(k, ct, st, vec3<T>(dw.x(), dw.y(), dw.z() + T(qdd(i))));
        acc = rot_T(k, ct, st, acc) + dw.cross(p);
      }
    } else {
      const vec3<T> z = axis<T>(k);
      if constexpr (Velocity) {
        w = rot_T(k, ct, st, w);
        dw = rot_T(k, ct, st, dw);
        acc = rot_T(k, ct, st, acc) + T(qdd(i)) * z + dw.cross(p) + w.cross(w.cross(p)) +
              T(2) * T(qd(i)) * w.cross(z);
      } else {
        dw = rot_T(k, ct, st, dw);
        acc = rot_T(k, ct, st, acc) + T(qdd(i)) * z + dw.cross(p);
      }
    }
    auto& s = ws[i];
    s.ct = ct;
    s.st = st;
    if (k.inert) {
      const vec3<T> h = k.h.template cast<T>();
      const mat3<T> Io = k.Io.template cast<T>();
      // F_i = m a_{c_i} = m a_i + ω̇×h + ω×(ω×h);  N_i = I_o ω̇ + ω×(I_o ω) + h×a_i
      if constexpr (Velocity) {
        s.F = T(k.m) * acc + dw.cross(h) + w.cross(w.cross(h));
        s.Nn = Io * dw + w.cross(Io * w) + h.cross(acc);
      } else {
        s.F = T(k.m) * acc + dw.cross(h);
        s.Nn = Io * dw + h.cross(acc);
      }
    } else {
      s.F.setZero();
      s.Nn.setZero();
    }
  }
  // Backward pass: f_i = R_{i+1} f_{i+1} + F_i, n_i = R_{i+1} n_{i+1} + p_i × f_i + N_i.
  vecN<T, N> tau(n);
  vec3<T> f = vec3<T>::Zero(), m = vec3<T>::Zero();
  for (int i = n - 1; i >= 0; --i) {
    const auto& k = L[static_cast<std::size_t>(i)];
    auto& s = ws[i];
    if (i + 1 < n) {
      const auto& k1 = L[static_cast<std::size_t>(i + 1)];
      const auto& s1 = ws[i + 1];
      f = rot(k1, s1.ct, s1.st, f);
      m = rot(k1, s1.ct, s1.st, m);
    }
    const T d = k.revolute ? T(k.d0) : T(k.d0) + T(q(i));
    f += s.F;
    m += offset<T>(k, d).cross(f) + s.Nn;
    const vec3<T> z = axis<T>(k);
    tau(i) = k.revolute ? T(m.dot(z)) : T(f.dot(z));
  }
  return tau;
}

/// Throws a clear error when a result is not finite: names the non-finite input, or says
/// the computation overflowed.
template <class R, class Q, class QD, class QDD>
void check_result(const R& out, const Q& q, const QD& qd, const QDD& qdd, const char* algorithm) {
  for (Eigen::Index i = 0; i < out.size(); ++i)
    if (!is_finite_scalar(out(i))) {
      check_finite(q, "q");
      check_finite(qd, "qd");
      check_finite(qdd, "qdd");
      throw numerical_error(std::string(algorithm) + ": result " + std::to_string(i) +
                            " is not finite although every input is (overflow)");
    }
}

}  // namespace detail

/// The rne function object over a chain (see the file comment).
template <class S, int N = dynamic>
class rne_fn : public stage_tag {
 public:
  using model_scalar = S;
  static constexpr int size_at_compile_time = N;

  explicit rne_fn(const chain<S, N>& c, rne_options o = {})
      : links_(detail::make_dh_links(c)), g_(c.gravity()), n_(c.dof()), opt_(o) {}

  int dof() const { return n_; }
  rne_options options() const { return opt_; }
  const vec3<S>& gravity() const { return g_; }

  /// v = M q̈ + C q̇ + g (sizes n; q [rad or m], q̇, q̈ per joint). The result's scalar is
  /// the common type of the model's and the state's.
  template <class Q, class QD, class QDD>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<QDD>& qdd) const {
    using T = promote_t<S, typename Q::Scalar>;
    if constexpr (N == dynamic) {
      detail::check_size(q, n_, "q");
      detail::check_size(qd, n_, "qd");
      detail::check_size(qdd, n_, "qdd");
    }
    const vec3<T> g = g_.template cast<T>();
    vecN<T, N> v;
    if (opt_.gravity) {
      v = opt_.velocity ? detail::rne_kernel<true, true, T, N>(links_, g, q, qd, qdd)
                        : detail::rne_kernel<true, false, T, N>(links_, g, q, qd, qdd);
    } else {
      v = opt_.velocity ? detail::rne_kernel<false, true, T, N>(links_, g, q, qd, qdd)
                        : detail::rne_kernel<false, false, T, N>(links_, g, q, qd, qdd);
    }
    detail::check_result(v, q, qd, qdd, "rne");
    return v;
  }

  /// Pipeline form: ξ = (q, q̇, q̈) → (q, v).
  template <class X>
  generalized_forces<promote_t<S, X>, N> operator()(const joint_state<X, N>& xi) const {
    return {xi.q.template cast<promote_t<S, X>>(), (*this)(xi.q, xi.qd, xi.qdd)};
  }

  /// The same algorithm with other options.
  rne_fn with(rne_options o) const {
    rne_fn r = *this;
    r.opt_ = o;
    return r;
  }

  const typename detail::dh_links<S, N>::type& links() const { return links_; }

 private:
  typename detail::dh_links<S, N>::type links_;
  vec3<S> g_;
  int n_;
  rne_options opt_;
};

/// rne over chain c: `rne(c)(q, qd, qdd)`.
template <class S, int N>
rne_fn<S, N> rne(const chain<S, N>& c, rne_options o = {}) {
  return rne_fn<S, N>(c, o);
}

}  // namespace nhdyn
