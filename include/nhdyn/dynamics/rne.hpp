#pragma once
/// \file dynamics/rne.hpp
/// `rne`: the holonomic recursive Newton–Euler inverse dynamics of a serial chain,
///
///     v = rne(q, q̇, q̈) = M(q) q̈ + C(q, q̇) q̇ + g(q)          (n joint forces/torques)
///
/// in link frames (Luh, Walker & Paul 1980; Spong, Hutchinson & Vidyasagar 2006, §7.5),
/// generic over the scalar. A joint's armature I_a (link::armature, the reflected rotor
/// inertia G²·J_m) adds I_a q̈_i to v_i, as it adds I_a to M's diagonal. Gravity enters as a base acceleration a_0 = −g. Links with zero
/// mass and zero inertia are skipped; a link with zero mass but rotational inertia is not.
///
/// Options say what a scene needs, and a call pays only for that:
/// `gravity = false` drops g(q); `velocity = false` drops C(q, q̇)q̇ (then q̇ is not read).
///
/// Example:
///     auto id = nhdyn::rne(nhdyn::presets::puma560());
///     Eigen::VectorXd tau = id(q, qd, qdd);
#include "../model/dh_kernel.hpp"
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
  v3<T> F, Nn;  // net force on link i and net moment about o_i, frame i
};

/// What rne_kernel runs between its joint angles and its passes: nothing (this), or a
/// stage that writes the q̇ and q̈ the passes read from the kernel's joint angles (the
/// nonholonomic lift of inverse_dynamics, constraints/stages.hpp, whose heading is one of
/// them or one more taken in their batch). Such a prelude p has
///   `bool p.extra_angle(angle_sum<T>& a)`: whether it needs one more angle (then a is it);
///   `p(const T* c, const T* s)`: cos and sin of the n joint angles, and at n the extra one's.
struct no_prelude {};
/// A prelude whose call is another's (rne_fn: the prelude's own, then a check).
template <class P, class F>
struct prelude_with {
  const P& p;
  const F& f;
  template <class A>
  bool extra_angle(A& a) const {
    return p.extra_angle(a);
  }
  template <class T>
  void operator()(const T* c, const T* s) const {
    f(c, s);
  }
};

/// The recursion. Gravity and Velocity are compile-time so that a call that needs
/// neither pays for neither. Written on plain scalars (detail::v3): this is the hot loop
/// of the library, and the benchmark (docs/performance.md) chose this form.
/// The n results go to `tau` (any writable vector of T, already of size n). `tau` may be the
/// storage of `qdd`: q̈_i is read only in the forward pass, τ_i written only in the backward pass.
/// `prelude` (no_prelude above) runs after the joint angles, before q̇ and q̈ are read.
template <bool Gravity, bool Velocity, class T, int N, class Links, class Q, class QD, class QDD, class Tau,
          class Prelude = no_prelude>
void rne_kernel(const Links& L, const vec3<T>& g, const Q& q, const QD& qd, const QDD& qdd, Tau& tau,
                const Prelude& prelude = {}) {
  const int n = static_cast<int>(q.size());
  constexpr bool has_prelude = !std::is_same_v<Prelude, no_prelude>;
  small_buffer<rne_scratch<T>, N> ws(n);
  // cos θ_i, sin θ_i (and the prelude's angle at n)
  constexpr int NA = N == dynamic ? dynamic : N + int(has_prelude);
  small_buffer<T, NA> cs(n + int(has_prelude)), sn(n + int(has_prelude));
  if constexpr (has_prelude) {
    angle_sum<T> extra{T(0), T(0)};
    const bool more = prelude.extra_angle(extra);
    joint_angles<T, N>(L, q, n, cs.data(), sn.data(), more ? &extra : nullptr);
    prelude(static_cast<const T*>(cs.data()), static_cast<const T*>(sn.data()));
  } else {
    joint_angles<T, N>(L, q, n, cs.data(), sn.data());
  }
  const T zero(0);
  v3<T> w{zero, zero, zero}, dw{zero, zero, zero};  // ω_i, ω̇_i  (frame i)
  v3<T> acc = Gravity ? v3<T>{-g.x(), -g.y(), -g.z()} : v3<T>{zero, zero, zero};  // a_{o_i} − g
  // Forward pass: velocities and accelerations, base to tip. Model constants (cos α, sin α,
  // m, m c, I_o, and p for a revolute joint) stay in the model's scalar: mixed products
  // (model/dh_kernel.hpp) are cheaper for duals and intervals, and the same for double.
  //
  // Links before the first revolute joint (a mobile base's x and y, say) only translate:
  // ω = ω̇ = 0 there, so a_i = R_iᵀ a_{i−1} + z q̈_i and every cross product vanishes. They
  // get that short form (the same numbers; for a dual it saves most of the work of those
  // links), and the backward pass skips their moments, which no τ reads.
  int prefix = 0;
  while (prefix < n && !L[static_cast<std::size_t>(prefix)].revolute) ++prefix;
  for (int i = 0; i < prefix; ++i) {
    const auto& k = L[static_cast<std::size_t>(i)];
    const T qddi(qdd(i));
    acc = rot_T(k.ca, k.sa, k.ct0, k.st0, acc);
    acc = v3<T>{acc.x, T(acc.y + qddi * k.sa), T(acc.z + qddi * k.ca)};  // + z q̈_i, z = (0, sin α, cos α)
    auto& s = ws[i];
    if (k.has_inertia) {
      const v3<std::remove_cvref_t<decltype(k.ca)>> h{k.hs[0], k.hs[1], k.hs[2]};
      s.F = scale(k.m, acc);
      s.Nn = c_cross(h, acc);
    } else {
      s.F = v3<T>{zero, zero, zero};
      s.Nn = s.F;
    }
  }
  for (int i = prefix; i < n; ++i) {
    const auto& k = L[static_cast<std::size_t>(i)];
    const auto& ca = k.ca;
    const auto& sa = k.sa;
    const T qddi(qdd(i));
    if (k.revolute) {
      const T ct = cs[i], st = sn[i];
      const v3<std::remove_cvref_t<decltype(ca)>> p{k.p0[0], k.p0[1], k.p0[2]};
      // ω_i = Rᵀ(ω_{i−1} + z q̇_i), ω̇_i = Rᵀ(ω̇_{i−1} + z q̈_i + ω_{i−1} × z q̇_i)
      if constexpr (Velocity) {
        const T qdi(qd(i));
        dw = rot_T(ca, sa, ct, st, v3<T>{T(dw.x + w.y * qdi), T(dw.y - w.x * qdi), T(dw.z + qddi)});
        w = rot_T(ca, sa, ct, st, v3<T>{w.x, w.y, T(w.z + qdi)});
        acc = rot_T(ca, sa, ct, st, acc) + cross_c(dw, p) + cross(w, cross_c(w, p));
      } else {
        dw = rot_T(ca, sa, ct, st, v3<T>{dw.x, dw.y, T(dw.z + qddi)});
        acc = rot_T(ca, sa, ct, st, acc) + cross_c(dw, p);
      }
    } else {
      // a_i gains z q̈_i (and 2 ω_i × z q̇_i) for a prismatic joint. θ is constant: for a
      // floating-point T its cos/sin come from the link constants (measured faster); for
      // duals from the batch above (the mixed forms made the dual kernel slower there).
      const auto prismatic = [&](const auto ct, const auto st) __attribute__((always_inline)) {  // by value: no aliasing with w, ω̇, a
        const T d(k.d0 + q(i));
        const v3<T> p{T(k.a), T(d * sa), T(d * ca)};
        const v3<std::remove_cvref_t<decltype(ca)>> z{decltype(ca)(0), sa, ca};
        if constexpr (Velocity) {
          w = rot_T(ca, sa, ct, st, w);
          dw = rot_T(ca, sa, ct, st, dw);
          acc = rot_T(ca, sa, ct, st, acc) + scale(qddi, z_as<T>(z)) + cross(dw, p) + cross(w, cross(w, p)) +
                scale(T(T(2) * T(qd(i))), cross_c(w, z));
        } else {
          dw = rot_T(ca, sa, ct, st, dw);
          acc = rot_T(ca, sa, ct, st, acc) + scale(qddi, z_as<T>(z)) + cross(dw, p);
        }
      };
      if constexpr (std::is_floating_point_v<T>)
        prismatic(k.ct0, k.st0);
      else
        prismatic(cs[i], sn[i]);
    }
    auto& s = ws[i];
    if (k.has_inertia) {
      const v3<std::remove_cvref_t<decltype(ca)>> h{k.hs[0], k.hs[1], k.hs[2]};
      // F_i = m a_{c_i} = m a_i + ω̇×h + ω×(ω×h);  N_i = I_o ω̇ + ω×(I_o ω) + h×a_i
      if constexpr (Velocity) {
        s.F = scale(k.m, acc) + cross_c(dw, h) + cross(w, cross_c(w, h));
        s.Nn = sym_times<T>(k.Is, dw) + cross(w, sym_times<T>(k.Is, w)) + c_cross(h, acc);
      } else {
        s.F = scale(k.m, acc) + cross_c(dw, h);
        s.Nn = sym_times<T>(k.Is, dw) + c_cross(h, acc);
      }
    } else {
      s.F = v3<T>{zero, zero, zero};
      s.Nn = s.F;
    }
  }
  // Backward pass: f_i = R_{i+1} f_{i+1} + F_i, n_i = R_{i+1} n_{i+1} + p_i × f_i + N_i.
  v3<T> f{zero, zero, zero}, m{zero, zero, zero};
  for (int i = n - 1; i >= prefix; --i) {
    const auto& k = L[static_cast<std::size_t>(i)];
    const auto& ca = k.ca;
    const auto& sa = k.sa;
    const auto& s = ws[i];
    if (i + 1 < n) {
      const auto& k1 = L[static_cast<std::size_t>(i + 1)];
      if (k1.revolute) {
        const T ct1 = cs[i + 1], st1 = sn[i + 1];
        f = rot(k1.ca, k1.sa, ct1, st1, f);
        m = rot(k1.ca, k1.sa, ct1, st1, m);
      } else {
        f = rot(k1.ca, k1.sa, k1.ct0, k1.st0, f);
        m = rot(k1.ca, k1.sa, k1.ct0, k1.st0, m);
      }
    }
    f = f + s.F;
    if (k.revolute) {
      const v3<std::remove_cvref_t<decltype(ca)>> p{k.p0[0], k.p0[1], k.p0[2]};
      m = m + c_cross(p, f) + s.Nn;
      T t = sa * m.y + ca * m.z;  // z_{i−1} · n_i
      if (k.has_armature) t += T(k.Ia) * T(qdd(i));  // read before τ_i overwrites it (in place)
      tau(i) = t;
    } else {
      const T d(k.d0 + q(i));
      m = m + cross(v3<T>{T(k.a), T(d * sa), T(d * ca)}, f) + s.Nn;
      T t = sa * f.y + ca * f.z;  // z_{i−1} · f_i
      if (k.has_armature) t += T(k.Ia) * T(qdd(i));
      tau(i) = t;
    }
  }
  // The translating prefix: forces only (τ_i = z_{i−1} · f_i; their moments are not needed).
  for (int i = prefix - 1; i >= 0; --i) {
    const auto& k = L[static_cast<std::size_t>(i)];
    if (i + 1 < n) {  // (a chain of prismatic joints only: its last link has no successor)
      const auto& k1 = L[static_cast<std::size_t>(i + 1)];
      if (k1.revolute)
        f = rot(k1.ca, k1.sa, cs[i + 1], sn[i + 1], f);
      else
        f = rot(k1.ca, k1.sa, k1.ct0, k1.st0, f);
    }
    f = f + ws[i].F;
    T t = k.sa * f.y + k.ca * f.z;
    if (k.has_armature) t += T(k.Ia) * T(qdd(i));
    tau(i) = t;
  }
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

/// Throws numerical_error if a result computed from finite inputs is not finite.
template <class R>
void check_overflow(const R& out, const char* algorithm) {
  if (finite_range(out, 0, out.size())) [[likely]]
    return;
  for (Eigen::Index i = 0; i < out.size(); ++i)
    if (!is_finite_scalar(out(i)))
      throw numerical_error(std::string(algorithm) + ": result " + std::to_string(i) +
                            " is not finite although every input is (overflow)");
  // reached only where std::isfinite cannot see it (-ffinite-math-only): still refused
  throw numerical_error(std::string(algorithm) + ": a result is not finite although every input is (overflow)");
}

}  // namespace detail

/// The rne function object over a chain (see the file comment).
template <class S, int N = dynamic>
class rne_fn : public stage_tag {
 public:
  using model_scalar = S;
  static constexpr int size_at_compile_time = N;

  explicit rne_fn(const chain<S, N>& c, rne_options o = {})
      : links_(detail::make_dh_links(c)), g_(c.gravity()), n_(c.dof()), opt_(o) {
    while (prefix_ < n_ && !links_[static_cast<std::size_t>(prefix_)].revolute) ++prefix_;
    for (int i = 0; i < n_; ++i)
      if (links_[static_cast<std::size_t>(i)].has_inertia) tail_ = i + 1;
  }

  int dof() const { return n_; }
  rne_options options() const { return opt_; }
  const vec3<S>& gravity() const { return g_; }

  /// v = M q̈ + C q̇ + g (sizes n; q [rad or m], q̇, q̈ per joint). The result's scalar is
  /// the common type of the model's and of q's, q̇'s and q̈'s (a dual q̇ with a double q, say).
  template <class Q, class QD, class QDD>
    requires scalar<typename Q::Scalar> && scalar<typename QD::Scalar> && scalar<typename QDD::Scalar>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                  const Eigen::MatrixBase<QDD>& qdd) const {
    using T = promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>, typename QDD::Scalar>;
    vecN<T, N> v(n_);
    evaluate(q, qd, qdd, v);
    return v;
  }

  /// v = rne(q, q̇, q̈) into v (n entries, of the model's and the inputs' promoted scalar; a
  /// vector or a map: no allocation): the call's numbers and checks. v may be q̈'s own storage
  /// (the same start, size and stride: then it runs as overwrite_qdd, whose error on a
  /// non-finite q̈ is overwrite_qdd's numerical_error, not an input_error naming q̈); it must
  /// not alias q or q̇.
  template <class Q, class QD, class QDD, class V>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                Eigen::MatrixBase<V>& v) const {
    static_assert(std::is_same_v<typename V::Scalar, promote_t<promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>,
                                                              typename QDD::Scalar>>,
                  "v's scalar is the model's and the inputs' promoted scalar");
    if constexpr ((int(QDD::Flags) & int(V::Flags) & Eigen::DirectAccessBit) != 0) {
      if (static_cast<const void*>(qdd.derived().data()) == static_cast<const void*>(v.derived().data()) &&
          qdd.size() == v.size() && qdd.derived().innerStride() == v.derived().innerStride()) {
        detail::check_size(v, n_, "v");
        run_checked(q.derived(), qd.derived(), v.derived(), v.derived());
        return;
      }
    }
    detail::check_size(q, n_, "q");
    detail::check_size(qd, n_, "qd");
    detail::check_size(qdd, n_, "qdd");
    detail::check_size(v, n_, "v");
    check_unseen(q, qd, qdd);
    run(q, qd, qdd, v.derived());
    detail::check_result(v, q, qd, qdd, "rne");
  }
  /// v = rne(q, q̇, q̈) − Q_ext(q) into v (applied forces: external wrenches,
  /// dynamics/wrench.hpp): the call's numbers bit for bit, no allocation (Q_ext in stack
  /// scratch) where the applied forces write into storage, as external_wrenches does.
  template <class Q, class QD, class QDD, applied_forces F, class V>
  void evaluate(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                const F& fx, Eigen::MatrixBase<V>& v) const {
    evaluate(q, qd, qdd, v);
    detail::add_applied<-1>(fx, q, v);
  }

  /// With applied forces (external wrenches, dynamics/wrench.hpp): v − Q_ext(q).
  template <class Q, class QD, class QDD, applied_forces F>
  auto operator()(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<QDD>& qdd,
                  const F& fx) const {
    return detail::minus_applied<N>((*this)(q, qd, qdd), fx, q);
  }

  /// Pipeline form: ξ = (q, q̇, q̈) → (q, v).
  template <class X>
  generalized_forces<promote_t<S, X>, N> operator()(const joint_state<X, N>& xi) const {
    return {xi.q.template cast<promote_t<S, X>>(), (*this)(xi.q, xi.qd, xi.qdd)};
  }
  /// Pipeline form on a temporary ξ: q moves on, and v is written over q̈'s storage (q̈_i is
  /// read before v_i is written), so the stage allocates nothing.
  template <class X>
  generalized_forces<promote_t<S, X>, N> operator()(joint_state<X, N>&& xi) const {
    if constexpr (std::is_same_v<promote_t<S, X>, X>) {
      run_in_place(xi);
      return {std::move(xi.q), std::move(xi.qdd)};
    } else {
      return (*this)(static_cast<const joint_state<X, N>&>(xi));
    }
  }
  /// …and with a memo, which travels on with (q, v).
  template <class X, class Memo>
  auto operator()(with_memo<joint_state<X, N>, Memo>&& xi) const {
    if constexpr (std::is_same_v<promote_t<S, X>, X>) {
      // The result object first, v computed straight into it (no copy of freshly written v).
      with_memo<generalized_forces<X, N>, Memo> out{{std::move(xi.q), {}}, std::move(xi.memo)};
      if constexpr (N == dynamic) {
        out.v = std::move(xi.qdd);  // q̈'s buffer, overwritten by v as in run_in_place
        run_checked(out.q, xi.qd, out.v, out.v);
      } else {
        run_checked(out.q, xi.qd, xi.qdd, out.v);
      }
      return out;
    } else {
      return (*this)(static_cast<const joint_state<X, N>&>(xi));
    }
  }

  /// v = rne(q, q̇, q̈) written over q̈ (`qdd_then_v`: any writable Eigen vector of the
  /// result's scalar, e.g. a map of stack scratch), checked as the pipeline form. What the
  /// run-time-sized inverse_dynamics calls to stay as allocation-free as the fixed-size one.
  /// With a prelude (detail::no_prelude): what writes q̇ and q̈ runs inside the kernel, after
  /// its joint angles, and gets the sin/cos of its own angle from their batch.
  template <class Q, class QD, class V, class Prelude = detail::no_prelude>
    requires std::is_same_v<typename V::Scalar, promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>>
  void overwrite_qdd(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, Eigen::MatrixBase<V>& qdd_then_v,
                     const Prelude& prelude = {}) const {
    run_checked(q.derived(), qd.derived(), qdd_then_v.derived(), qdd_then_v.derived(), prelude);
  }

  /// The same algorithm with other options.
  rne_fn with(rne_options o) const {
    rne_fn r = *this;
    r.opt_ = o;
    return r;
  }

  const typename detail::dh_links<S, N>::type& links() const { return links_; }

 private:
  /// v over ξ.qdd.
  template <class X>
  void run_in_place(joint_state<X, N>& xi) const {
    run_checked(xi.q, xi.qd, xi.qdd, xi.qdd);
  }
  /// v = rne(q, q̇, q̈) into v, which may be q̈'s storage. Then q̈ may be gone (v in its place),
  /// so a non-finite result names q or q̇ when they are the cause, and otherwise says "q̈ or
  /// overflow". Not checking q̈ before is measurable (4 ns of a 115 ns paper5 call); the
  /// entries v does not depend on are checked before (check_unseen).
  template <class Qx, class QDx, class QDDx, class V, class Prelude = detail::no_prelude>
  void run_checked(const Qx& q, const QDx& qd, const QDDx& qdd, V& v, const Prelude& prelude = {}) const {
    detail::check_size(q, n_, "q");
    detail::check_size(qd, n_, "qd");
    detail::check_size(qdd, n_, "qdd");
    if constexpr (std::is_same_v<Prelude, detail::no_prelude>) {
      check_unseen(q, qd, qdd);
      run(q, qd, qdd, v);
    } else {
      // q̇ and q̈ are the prelude's to write: their unseen entries are checked after it.
      check_unseen(q, std::false_type{}, std::false_type{});
      const auto checked = [&](const auto* c, const auto* s) __attribute__((always_inline)) {
        prelude(c, s);
        check_unseen(std::false_type{}, qd, qdd);
      };
      run(q, qd, qdd, v, detail::prelude_with<Prelude, decltype(checked)>{prelude, checked});
    }
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (!is_finite_scalar(v(i))) [[unlikely]] {
        detail::check_finite(q, "q");
        detail::check_finite(qd, "qd");
        throw numerical_error("rne: result " + std::to_string(i) +
                              " is not finite: qdd has a non-finite entry, or the computation overflowed");
      }
  }
  /// Checks the inputs that cannot reach v, so that no non-finite input goes unreported: a
  /// non-finite input that v depends on makes v non-finite, and the result check names it.
  /// Not read by the kernel: q and q̇ of the translating prefix (and q̇ at all without
  /// velocity terms); reaching no mass: q, q̇, q̈ of the links after the last with inertia.
  /// paper5: q₁, q₂, q̇₁, q̇₂ (its x and y) — before this, a NaN there gave a finite v.
  /// An argument std::false_type: that vector is not checked here.
  template <class Qx, class QDx, class QDDx>
  void check_unseen(const Qx& q, const QDx& qd, const QDDx& qdd) const {
    const auto check = [](const auto& v, int begin, int end, const char* what) {
      if (begin < end && !detail::finite_range(v, begin, end)) [[unlikely]]
        detail::check_finite(v, what);  // names the first non-finite entry (it is one)
    };
    if constexpr (!std::is_same_v<Qx, std::false_type>) {
      check(q, 0, prefix_, "q");
      check(q, tail_, n_, "q");
    }
    if constexpr (!std::is_same_v<QDx, std::false_type>) {
      if (opt_.velocity) {
        check(qd, 0, prefix_, "qd");
        check(qd, tail_, n_, "qd");
      }
    }
    if constexpr (!std::is_same_v<QDDx, std::false_type>) check(qdd, tail_, n_, "qdd");
  }

  /// The kernel on maps of the vectors (detail::kernel_vector): one kernel per scalar, size and
  /// prelude, whatever Eigen types the caller passes.
  template <class Q, class QD, class QDD, class V, class Prelude = detail::no_prelude>
  void run(const Q& q, const QD& qd, const QDD& qdd, V& v, const Prelude& prelude = {}) const {
    const detail::kernel_input<N, Q> qi(q);
    const detail::kernel_input<N, QD> qdi(qd);
    const detail::kernel_input<N, QDD> qddi(qdd);
    decltype(auto) vv = detail::kernel_vector<N>(v);
    run_kernel(qi.get(), qdi.get(), qddi.get(), vv, prelude);
  }
  template <class Q, class QD, class QDD, class V, class Prelude>
  void run_kernel(const Q& q, const QD& qd, const QDD& qdd, V& v, const Prelude& prelude) const {
    using T = typename V::Scalar;
    const vec3<T> g = g_.template cast<T>();
    if (opt_.gravity) {
      opt_.velocity ? detail::rne_kernel<true, true, T, N>(links_, g, q, qd, qdd, v, prelude)
                    : detail::rne_kernel<true, false, T, N>(links_, g, q, qd, qdd, v, prelude);
    } else {
      opt_.velocity ? detail::rne_kernel<false, true, T, N>(links_, g, q, qd, qdd, v, prelude)
                    : detail::rne_kernel<false, false, T, N>(links_, g, q, qd, qdd, v, prelude);
    }
  }

  typename detail::dh_links<S, N>::type links_;
  vec3<S> g_;
  int n_;
  rne_options opt_;
  int prefix_ = 0;  // links before the first revolute joint (they only translate)
  int tail_ = 0;    // one past the last link with inertia
};

/// rne over chain c: `rne(c)(q, qd, qdd)`.
template <class S, int N>
rne_fn<S, N> rne(const chain<S, N>& c, rne_options o = {}) {
  return rne_fn<S, N>(c, o);
}

}  // namespace nhdyn
