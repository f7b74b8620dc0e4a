#pragma once
/// \file kinematics/tree.hpp
/// Kinematics of a tree (model/tree.hpp), with the chain kinematics' call forms: poses of
/// every body frame, the geometric Jacobian and J̇q̇ of a point fixed on a body, all in the
/// base frame. Body index i: 0 is the base, 1…n the bodies in q order (as a chain's link
/// frames); named forms take a body's or a merged frame's name.
///
///     X_0i = X_0λ(i) · X_λ(i)i(q_i)
///     J column j (j supports i): revolute (z_j × (p − o_j); z_j), prismatic (z_j; 0);
///     zero for joints that do not move body i (other branches, and i's descendants).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "../detail/small_buffer.hpp"
#include "../model/floating.hpp"
#include "../model/tree_kernel.hpp"
#include "../spatial/spatial.hpp"
#include "kinematics.hpp"

namespace nhdyn {

template <class S>
class tree_kinematics {
 public:
  using scalar_type = S;
  explicit tree_kinematics(const tree<S>& t) : tree_(t), links_(detail::make_tree_links(t)), n_(t.dof()) {}
  int dof() const { return n_; }
  /// q's entries: dof() + 1 for a floating tree (model/floating.hpp), else dof().
  int nq() const { return tree_.nq(); }
  const tree<S>& model() const { return tree_; }

  /// Poses of the base (entry 0) and of the n body frames (entries 1…n) in the base frame.
  template <class Q>
  auto forward(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<S, typename Q::Scalar>;
    const auto K = kernel_frames(q);
    std::vector<pose<T>> X(static_cast<std::size_t>(n_ + 1));
    for (int i = 0; i < n_; ++i) {
      const auto& k = links_[std::size_t(i)];
      X[std::size_t(i + 1)] = {K[i].R * k.R_KB.template cast<T>(), K[i].p + K[i].R * k.p_KB.template cast<T>()};
    }
    return X;
  }

  /// Pose of body frame i (0…n) in the base frame.
  template <class Q>
  auto frame(const Eigen::MatrixBase<Q>& q, int i) const {
    check_body(i);
    return forward(q)[std::size_t(i)];
  }
  /// Pose of the named body or merged frame in the base frame.
  template <class Q>
  auto frame(const Eigen::MatrixBase<Q>& q, const std::string& name) const {
    using T = promote_t<S, typename Q::Scalar>;
    const auto f = tree_.find_frame(name);
    const auto X = frame(q, f.body + 1);
    return pose<T>{X.R * f.R.template cast<T>(), X.p + X.R * f.p.template cast<T>()};
  }

  /// Position in the base frame of the point p_i (in body i's frame) of body i (0 = base).
  template <class Q>
  auto point(const Eigen::MatrixBase<Q>& q, int i, const vec3<S>& p_i = vec3<S>::Zero()) const {
    using T = promote_t<S, typename Q::Scalar>;
    check_point(p_i);
    const auto X = frame(q, i);
    return vec3<T>(X.p + X.R * p_i.template cast<T>());
  }

  /// Geometric Jacobian (6×n, rows v then ω, base frame) of point p_i of body i.
  template <class Q>
  auto jacobian(const Eigen::MatrixBase<Q>& q, int i, const vec3<S>& p_i = vec3<S>::Zero()) const {
    using T = promote_t<S, typename Q::Scalar>;
    check_body(i);
    check_point(p_i);
    const auto K = kernel_frames(q);
    Eigen::Matrix<T, 6, Eigen::Dynamic> J = Eigen::Matrix<T, 6, Eigen::Dynamic>::Zero(6, n_);
    if (i == 0) return J;
    const auto& kb = links_[std::size_t(i - 1)];
    const vec3<T> r = kb.R_KB.template cast<T>() * p_i.template cast<T>() + kb.p_KB.template cast<T>();
    const vec3<T> p = K[i - 1].p + K[i - 1].R * r;
    for (int j = i - 1; j >= 0; j = links_[std::size_t(j)].parent) {
      const vec3<T> z = K[j].R.col(2);
      if (links_[std::size_t(j)].revolute) {
        J.col(j).template head<3>() = z.cross(p - K[j].p);
        J.col(j).template tail<3>() = z;
      } else {
        J.col(j).template head<3>() = z;
      }
    }
    return J;
  }

  /// out += Σ_x J(q, x.body, x.point)ᵀ [f_x; m_x] (n entries, of the model's and q's promoted
  /// scalar or a wider one): the joint forces of forces f_x at points fixed on bodies and of
  /// moments m_x (the principle of virtual work). Each x of `xs` has members `body` (0…n; 0, the
  /// base, moves nothing), `point` (body coordinates), `force` and `moment`, given in the base
  /// frame's axes, or in body x.body's where `in_body_axes(x)`. One pass for the frames, then
  /// each point walks to the root: no allocation (the frames on the stack; beyond 340 bodies, a
  /// block the thread keeps, detail/small_buffer.hpp).
  template <class Q, class Xs, class InBody, class Out>
  void add_point_forces(const Eigen::MatrixBase<Q>& q, const Xs& xs, InBody in_body_axes, Eigen::MatrixBase<Out>& out) const {
    using TK = promote_t<S, typename Q::Scalar>;
    using T = typename Out::Scalar;
    detail::check_size(out, n_, "out");
    detail::small_buffer<pose<TK>, dynamic> K(n_);
    kernel_frames_into(q, K.data());
    for (const auto& x : xs) {
      check_body(x.body);
      if (x.body == 0) continue;
      const int i = x.body - 1;
      const auto& kb = links_[std::size_t(i)];
      const vec3<TK> r = kb.R_KB.template cast<TK>() * x.point.template cast<TK>() + kb.p_KB.template cast<TK>();
      const vec3<T> p = (K[i].p + K[i].R * r).template cast<T>();
      vec3<T> f = x.force.template cast<T>(), m = x.moment.template cast<T>();
      if (in_body_axes(x)) {
        const mat3<T> Rb = (K[i].R * kb.R_KB.template cast<TK>()).template cast<T>();
        f = Rb * f;
        m = Rb * m;
      }
      for (int j = i; j >= 0; j = links_[std::size_t(j)].parent) {  // z_j · ((p − o_j) × f + m), or z_j · f
        const vec3<T> z = K[j].R.col(2).template cast<T>();
        out(j) += links_[std::size_t(j)].revolute ? T(z.dot(vec3<T>((p - K[j].p.template cast<T>()).cross(f) + m)))
                                                  : T(z.dot(f));
      }
    }
  }

  /// J̇q̇ of point p_i of body i, in the base frame: its acceleration at q̈ = 0, no gravity.
  template <class Q, class QD>
  auto jdot_qdot(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, int i,
                 const vec3<S>& p_i = vec3<S>::Zero()) const {
    using T = promote_t<promote_t<S, typename Q::Scalar>, typename QD::Scalar>;
    check_body(i);
    detail::check_size(qd, n_, "qd");
    detail::check_finite(qd, "qd");
    check_point(p_i);
    const auto K = kernel_frames(q);
    point_acceleration<T> out;
    if (i == 0) return out;
    // the path from the root to body i, then the velocity recursion of rne along it
    std::vector<int> path;
    for (int j = i - 1; j >= 0; j = links_[std::size_t(j)].parent) path.insert(path.begin(), j);
    vec3<T> w = vec3<T>::Zero(), dw = vec3<T>::Zero(), acc = vec3<T>::Zero();  // in K_j
    // a floating tree (model/floating.hpp): its six root joints at zero with q̈_K = −b(v), the
    // acceleration at a = 0
    spatial_bias<T> b(tree_.floating(), qd);
    for (int j : path) {
      const auto k = links_[std::size_t(j)].template cast<T>();
      mat3<T> R;
      vec3<T> p;
      detail::kernel_placement(k, T(joint_position(q, j)), R, p);
      acc = R.transpose() * vec3<T>(acc + dw.cross(p) + w.cross(w.cross(p)));
      w = R.transpose() * w;
      dw = R.transpose() * dw;
      const T qdj = T(qd(j));
      if (k.revolute) {
        dw += vec3<T>(w.y() * qdj, -w.x() * qdj, T(0));
        w.z() += qdj;
        if (j < 6 && b.on) dw.z() += b.qdd(j);
      } else {
        acc += T(2) * qdj * vec3<T>(w.y(), -w.x(), T(0));
        if (j < 6 && b.on) acc.z() += b.qdd(j);
      }
    }
    const auto& kb = links_[std::size_t(i - 1)];
    const vec3<T> r = kb.R_KB.template cast<T>() * p_i.template cast<T>() + kb.p_KB.template cast<T>();
    out.linear = K[i - 1].R * vec3<T>(acc + dw.cross(r) + w.cross(w.cross(r)));
    out.angular = K[i - 1].R * dw;
    return out;
  }

  /// The joints' frames at q, once for several points: entry j's axes and origin in the base
  /// frame (world), its third column the joint's axis z_j through the origin o_j (the kernel
  /// frame, model/tree_kernel.hpp). A floating tree's are placed by the root's pose.
  template <class Q>
  auto joint_frames(const Eigen::MatrixBase<Q>& q) const {
    return kernel_frames(q);
  }
  /// Body frame i (0…n, 0 the base) from joint_frames(q).
  template <class T>
  pose<T> body_pose(const std::vector<pose<T>>& K, int i) const {
    check_body(i);
    if (i == 0) return {};
    const auto& kb = links_[std::size_t(i - 1)];
    return {K[std::size_t(i - 1)].R * kb.R_KB.template cast<T>(),
            K[std::size_t(i - 1)].p + K[std::size_t(i - 1)].R * kb.p_KB.template cast<T>()};
  }
  /// The translational Jacobian (3 × n, base frame) of the point of body i (0…n) that is at
  /// p_W (base frame, any scalar: a point that moves on the body, as a wheel's contact point
  /// does) from joint_frames(q): column j is z_j × (p_W − o_j) for a revolute joint j on i's
  /// path, z_j for a prismatic one, zero otherwise.
  template <class T, class P>
  Eigen::Matrix<promote_t<T, typename P::Scalar>, 3, Eigen::Dynamic> point_jacobian(const std::vector<pose<T>>& K, int i,
                                                                                    const Eigen::MatrixBase<P>& p_W) const {
    using R = promote_t<T, typename P::Scalar>;
    check_body(i);
    Eigen::Matrix<R, 3, Eigen::Dynamic> J = Eigen::Matrix<R, 3, Eigen::Dynamic>::Zero(3, n_);
    const vec3<R> p = p_W.template cast<R>();
    for (int j = i - 1; j >= 0; j = links_[std::size_t(j)].parent) {
      const vec3<R> z = K[std::size_t(j)].R.col(2).template cast<R>();
      if (links_[std::size_t(j)].revolute)
        J.col(j) = z.cross(vec3<R>(p - K[std::size_t(j)].p.template cast<R>()));
      else
        J.col(j) = z;
    }
    return J;
  }

  /// 1-based body index of a body or frame name (0: the base) and the point on that body of
  /// the frame's origin, for the index forms above.
  std::pair<int, vec3<S>> locate(const std::string& name) const {
    const auto f = tree_.find_frame(name);
    return {f.body + 1, f.p};
  }

 private:
  /// q̈_K = −b(v) of a floating tree's six root joints (model/floating.hpp); off otherwise.
  template <class T>
  struct spatial_bias {
    bool on;
    spatial::vec6<T> qdd = spatial::vec6<T>::Zero();
    template <class QD>
    spatial_bias(bool floating, const QD& qd) : on(floating) {
      if (on) detail::subtract_root_bias(qd, qdd);
    }
  };
  /// The position the kernel reads for joint j: q(j), or a floating tree's q_K(j).
  template <class Q>
  auto joint_position(const Q& q, int j) const {
    using T = typename Q::Scalar;
    if (!tree_.floating()) return T(q(j));
    return j < 6 ? T(0) : T(q(j + 1));
  }
  /// Poses of the kernel frames K_0…K_{n−1} in the base frame.
  template <class Q>
  auto kernel_frames(const Eigen::MatrixBase<Q>& q) const {
    std::vector<pose<promote_t<S, typename Q::Scalar>>> K(static_cast<std::size_t>(n_));
    kernel_frames_into(q, K.data());
    return K;
  }
  /// …into K (n poses).
  template <class Q, class T>
  void kernel_frames_into(const Eigen::MatrixBase<Q>& q, pose<T>* K) const {
    // a floating tree: the tree in the root's frame at q_K, placed in the world by X_WB
    pose<T> root;
    if (tree_.floating()) {
      detail::check_floating_configuration(q, n_ + 1, "q");
      root = {detail::root_rotation<T>(q), vec3<T>(T(q(0)), T(q(1)), T(q(2)))};
    } else {
      detail::check_size(q, n_, "q");
      detail::check_finite(q, "q");
    }
    for (int i = 0; i < n_; ++i) {
      const auto k = links_[std::size_t(i)].template cast<T>();
      mat3<T> R;
      vec3<T> p;
      detail::kernel_placement(k, T(joint_position(q, i)), R, p);
      if (k.parent < 0 && tree_.floating())
        K[i] = {root.R * R, root.p + root.R * p};
      else if (k.parent < 0)
        K[i] = {R, p};
      else
        K[i] = {K[k.parent].R * R, K[k.parent].p + K[k.parent].R * p};
    }
  }
  static void check_point(const vec3<S>& p_i) {
    for (int r = 0; r < 3; ++r)
      if (!is_finite_scalar(p_i(r))) detail::throw_not_finite("p_i", r, value_of(p_i(r)));
  }
  void check_body(int i) const {
    if (i < 0 || i > n_) throw input_error("body index " + std::to_string(i) + " is outside 0…" + std::to_string(n_));
  }
  tree<S> tree_;
  std::vector<detail::tree_link<S>> links_;
  int n_;
};

}  // namespace nhdyn
