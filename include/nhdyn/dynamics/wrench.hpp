#pragma once
/// \file dynamics/wrench.hpp
/// External wrenches: a force and a moment that the environment applies to a body (a payload's
/// weight, a contact, a push), at a point fixed on it. Their generalized force is the principle
/// of virtual work (Featherstone, RBDA §5.3; Spong eq. 4.96):
///
///     Q_ext(q) = Σ_k J_k(q)ᵀ [f_k; m_k]          (J_k: the geometric Jacobian of point k)
///
/// with f and m in the base (world) frame, m about the point. With it
///
///     τ = rne(q, q̇, q̈) − Q_ext(q),      M q̈ = τ + Q_ext − h,      τ_η = project(rne − Q_ext),
///
/// which is what `rne(model)(q, qd, qdd, w)`, `forward_dynamics(model)(q, qd, tau, w)`, aba and
/// the constrained forward dynamics compute when given `w = external_wrenches(model, {…})`, and
/// what the stage does in a pipeline: `lift(c) | rne(model) | w | project(c)` (or
/// `| constraint_forces(c)` for λ), since (q, v) ↦ (q, v − Q_ext(q)).
///
/// Conventions: the wrench acts *on* the body *from* the environment (as KDL's f_ext and
/// Pinocchio's fext; Corke's toolbox takes the opposite sign: what the end effector exerts).
/// The point is fixed on the body, in the body frame's coordinates [m]; `frame` says whether
/// force [N] and moment [N·m] are given in the base frame's axes (`world`: a constant weight)
/// or the body frame's (`body`: a thrust that turns with the body). The base is the model's
/// world-fixed root (a mobile robot's planar base joints are ordinary joints before it).
///
/// Cost: one kinematic pass for all the wrenches, then a walk from each wrench's body to the root;
/// no allocation in `generalized_force_into` and in the dynamics' `evaluate` forms that take
/// wrenches.
#include <Eigen/Core>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "../errors.hpp"
#include "../functional/compose.hpp"
#include "../functional/values.hpp"
#include "../kinematics/kinematics.hpp"
#include "../kinematics/tree.hpp"

namespace nhdyn {

enum class wrench_frame { world, body };

inline const char* to_string(wrench_frame f) { return f == wrench_frame::world ? "world" : "body"; }

/// One external wrench on body `body` (1…n in q order, as the kinematics count; 0 is the base,
/// whose wrench moves nothing).
template <class W = double>
struct wrench {
  int body = 0;
  vec3<W> force = vec3<W>::Zero();   ///< [N], on the body, in `frame`'s axes
  vec3<W> moment = vec3<W>::Zero();  ///< [N·m] about `point`, in `frame`'s axes
  vec3<W> point = vec3<W>::Zero();   ///< on the body, body-frame coordinates [m]
  wrench_frame frame = wrench_frame::world;
};

/// The external wrenches on a model as applied forces (see the file comment). Kin: the model's
/// kinematics (kinematics<S, N> or tree_kinematics<S>).
template <class Kin, class W = double>
class external_wrenches_fn : public stage_tag {
 public:
  using applied_forces_tag = void;

  external_wrenches_fn(Kin kin, std::vector<wrench<W>> w) : kin_(std::move(kin)), w_(std::move(w)) {
    for (std::size_t k = 0; k < w_.size(); ++k) {
      const auto& x = w_[k];
      const int b = x.body;
      const std::string where = "external wrench " + std::to_string(k) + " (body " + std::to_string(b) + ")";
      if (b < 0 || b > kin_.dof())
        throw input_error(where + ": body index is outside 0…" + std::to_string(kin_.dof()));
      for (int r = 0; r < 3; ++r)
        if (!is_finite_scalar(x.force(r)) || !is_finite_scalar(x.moment(r)) || !is_finite_scalar(x.point(r)))
          throw input_error(where + ": force, moment or point has a non-finite entry (NaN or Inf)");
    }
  }

  int dof() const { return kin_.dof(); }
  const std::vector<wrench<W>>& wrenches() const { return w_; }
  /// The same model with other wrenches (a payload that changes, a contact force per step).
  external_wrenches_fn with(std::vector<wrench<W>> w) const { return external_wrenches_fn(kin_, std::move(w)); }

  /// Q_ext(q) = Σ Jᵀ[f; m] (n entries): the joint forces the wrenches apply.
  template <class Q>
  auto generalized_force(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<promote_t<typename Kin::scalar_type, typename Q::Scalar>, W>;
    Eigen::Matrix<T, Eigen::Dynamic, 1> out(kin_.dof());
    generalized_force_into(q, out);
    return out;
  }
  /// The same into out (n entries, of the model's, q's and the wrenches' promoted scalar; a
  /// vector or a map the caller reuses): no allocation. The dynamics' `evaluate` forms use it.
  template <class Q, class Out>
  void generalized_force_into(const Eigen::MatrixBase<Q>& q, Eigen::MatrixBase<Out>& out) const {
    static_assert(std::is_same_v<typename Out::Scalar,
                                 promote_t<promote_t<typename Kin::scalar_type, typename Q::Scalar>, W>>,
                  "out's scalar is the model's, q's and the wrenches' promoted scalar");
    detail::check_size(out, kin_.dof(), "Q_ext");
    out.setZero();
    kin_.add_point_forces(q, w_, [](const wrench<W>& x) { return x.frame == wrench_frame::body; }, out);
  }

  /// Pipeline form: (q, v) ↦ (q, v − Q_ext(q)), after rne, before the projection.
  template <class F>
    requires requires(F& x) {
      x.q;
      x.v;
    }
  auto operator()(F f) const {
    using V = typename decltype(f.v)::Scalar;
    if constexpr (std::is_same_v<promote_t<V, detail::applied_scalar_t<external_wrenches_fn, decltype(f.q)>>, V>) {
      detail::add_applied<-1>(*this, f.q, f.v);  // Q_ext in stack scratch: no allocation
    } else {
      const auto Qx = generalized_force(f.q);
      f.v -= Qx.template cast<V>();
    }
    return f;
  }

 private:
  Kin kin_;
  std::vector<wrench<W>> w_;
};

/// External wrenches on a chain's links (body i = link i, its DH frame).
template <class S, int N, class W = double>
auto external_wrenches(const chain<S, N>& c, std::vector<wrench<W>> w) {
  return external_wrenches_fn<kinematics<S, N>, W>(kinematics<S, N>(c), std::move(w));
}
/// External wrenches on a tree's bodies.
template <class S, class W = double>
auto external_wrenches(const tree<S>& t, std::vector<wrench<W>> w) {
  return external_wrenches_fn<tree_kinematics<S>, W>(tree_kinematics<S>(t), std::move(w));
}

/// A wrench on the body called `name` of a chain or a tree (find_frame: a tree's bodies and
/// merged fixed-joint frames, a chain's "link1" … "link<n>"): `point` and, for
/// wrench_frame::body, force and moment are given in that named frame, and moved to its body.
template <class Model, class W = double>
wrench<W> wrench_on(const Model& model, const std::string& name, wrench_frame frame, const vec3<W>& point,
                    const vec3<W>& force, const vec3<W>& moment = vec3<W>::Zero()) {
  const auto f = find_frame(model, name);  // throws input_error naming the model for an unknown name
  wrench<W> w;
  w.body = f.body + 1;
  w.frame = frame;
  const mat3<W> R = f.R.template cast<W>();
  w.point = R * point + f.p.template cast<W>();
  w.force = frame == wrench_frame::body ? vec3<W>(R * force) : force;
  w.moment = frame == wrench_frame::body ? vec3<W>(R * moment) : moment;
  return w;
}

}  // namespace nhdyn
