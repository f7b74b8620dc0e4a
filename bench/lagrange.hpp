#pragma once
/// \file bench/lagrange.hpp
/// The formulation the paper argues against, as a reasonable implementation: the projected
/// Euler–Lagrange equations
///
///     τ = P Sᵀ ( M(q) (S η̇ + Ṡ η) + C(q, q̇) S η + g(q) ),   q̇ = S η
///
/// (P = (SᵀE)⁻¹, I for the built-in types but wheeled_base, whose actuation gives the
/// least-norm τ of its p actuators)
///
/// with every term built explicitly (run-time sized, double):
///   M = Σ_i m_i J_viᵀ J_vi + J_ωiᵀ R_i I_i R_iᵀ J_ωi      (J_vi: geometric Jacobian of the
///                                                          centre of mass c_i, frame 0)
///   ∂M/∂q_k by the closed-form derivatives of the geometric Jacobians
///       (revolute k: ∂z_j/∂q_k = z_k × z_j for k < j, ∂c_i/∂q_k = z_k × (c_i − o_k), …;
///        ∂(R I Rᵀ)/∂q_k = [z_k]× R I Rᵀ − R I Rᵀ [z_k]×),
///   C_ij = Σ_k Γ_ijk q̇_k with the Christoffel symbols Γ_ijk = ½(∂_k M_ij + ∂_j M_ik − ∂_i M_jk),
///       assembled as C = ½(Ṁ + D − Dᵀ), Ṁ = Σ_k ∂_k M q̇_k, column j of D = ∂_j M q̇,
///   g = −Σ_i m_i J_viᵀ g₀.
/// The cost is O(n⁴) (n link Jacobians × n derivative directions × O(n²) products), which is
/// what building C from ∂M/∂q costs.
#include <nhdyn/nhdyn.hpp>
#include <vector>

namespace nhdyn_bench {

/// The cross-product matrix: skew(v) w = v × w.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

/// ∂J_v,j/∂q_k and ∂J_ω,j/∂q_k for a point pc of a body that joints k and j both move, in
/// closed form: `k_first` when joint k comes before joint j on the path from the base.
inline void jacobian_column_derivative(bool rev_k, bool rev_j, bool k_first, const Eigen::Vector3d& zk,
                                       const Eigen::Vector3d& zj, const Eigen::Vector3d& ok, const Eigen::Vector3d& pc,
                                       const Eigen::Vector3d& Jv_j, Eigen::Ref<Eigen::Vector3d> dJv,
                                       Eigen::Ref<Eigen::Vector3d> dJw) {
  if (rev_k) {
    if (rev_j) {
      dJv = k_first ? Eigen::Vector3d(zk.cross(Jv_j)) : Eigen::Vector3d(zj.cross(zk.cross(pc - ok)));
      dJw = k_first ? Eigen::Vector3d(zk.cross(zj)) : Eigen::Vector3d::Zero();
    } else {
      dJv = k_first ? Eigen::Vector3d(zk.cross(zj)) : Eigen::Vector3d::Zero();
      dJw.setZero();
    }
  } else {
    dJv = (rev_j && !k_first) ? Eigen::Vector3d(zj.cross(zk)) : Eigen::Vector3d::Zero();
    dJw.setZero();
  }
}

/// One body's share of ∂M/∂q_k: m(∂Jvᵀ Jv + Jvᵀ ∂Jv) + ∂Jωᵀ I Jω + Jωᵀ I ∂Jω + Jωᵀ ∂I Jω,
/// ∂I = [z_k]× I − I [z_k]× for a revolute k (I in the base frame).
template <class A, class B>
Eigen::MatrixXd mass_matrix_derivative_share(double m, const A& djv, const B& jv, const A& djw, const B& jw,
                                             const Eigen::Matrix3d& I0, bool rev_k, const Eigen::Vector3d& zk) {
  Eigen::MatrixXd P = m * djv.transpose() * jv;
  P.noalias() += djw.transpose() * I0 * jw;
  Eigen::MatrixXd D = P + P.transpose();
  if (rev_k) {
    const Eigen::Matrix3d Z = skew(zk);
    D.noalias() += jw.transpose() * (Z * I0 - I0 * Z) * jw;
  }
  return D;
}

/// C = ½(Ṁ + D − Dᵀ), Ṁ = Σ_k ∂_k M q̇_k, column j of D = ∂_j M q̇: the Christoffel symbols of
/// the first kind contracted with q̇.
inline Eigen::MatrixXd coriolis_matrix(const std::vector<Eigen::MatrixXd>& dM, const Eigen::VectorXd& qd) {
  const auto n = qd.size();
  Eigen::MatrixXd Mdot = Eigen::MatrixXd::Zero(n, n), D(n, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    Mdot += qd(k) * dM[std::size_t(k)];
    D.col(k) = dM[std::size_t(k)] * qd;
  }
  return 0.5 * (Mdot + D - D.transpose());
}

class lagrange_terms {
 public:
  explicit lagrange_terms(const nhdyn::chain<double>& c) : c_(c), kin_(c), n_(c.dof()) {}

  struct terms {
    Eigen::MatrixXd M, C;
    Eigen::VectorXd g;
  };

  terms operator()(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const {
    const int n = n_;
    const auto X = kin_.forward(q);  // frames 0…n; joint j (0-based) turns about z of frame j
    std::vector<Eigen::MatrixXd> dM(static_cast<std::size_t>(n), Eigen::MatrixXd::Zero(n, n));
    terms t{Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd::Zero(n)};
    const Eigen::Vector3d g0 = c_.gravity();
    Eigen::Matrix3Xd Jv(3, n), Jw(3, n), dJv(3, n), dJw(3, n);
    for (int li = 0; li < n; ++li) {
      const auto& L = c_[li];
      const int w = li + 1;  // columns 0…li are non-zero
      const auto& F = X[std::size_t(li + 1)];
      const Eigen::Vector3d pc = F.p + F.R * L.com;
      const Eigen::Matrix3d I0 = F.R * L.inertia * F.R.transpose();
      for (int j = 0; j < w; ++j) {
        const Eigen::Vector3d z = X[std::size_t(j)].R.col(2);
        if (rev(j)) {
          Jv.col(j) = z.cross(pc - X[std::size_t(j)].p);
          Jw.col(j) = z;
        } else {
          Jv.col(j) = z;
          Jw.col(j).setZero();
        }
      }
      const auto jv = Jv.leftCols(w);
      const auto jw = Jw.leftCols(w);
      t.M.topLeftCorner(w, w).noalias() += L.mass * jv.transpose() * jv;
      t.M.topLeftCorner(w, w).noalias() += jw.transpose() * I0 * jw;
      t.g.head(w).noalias() -= L.mass * jv.transpose() * g0;
      for (int k = 0; k < w; ++k) {
        const Eigen::Vector3d zk = X[std::size_t(k)].R.col(2);
        const Eigen::Vector3d ok = X[std::size_t(k)].p;
        for (int j = 0; j < w; ++j)
          jacobian_column_derivative(rev(k), rev(j), k < j, zk, X[std::size_t(j)].R.col(2), ok, pc, Jv.col(j),
                                     dJv.col(j), dJw.col(j));
        dM[std::size_t(k)].topLeftCorner(w, w) +=
            mass_matrix_derivative_share(L.mass, dJv.leftCols(w), jv, dJw.leftCols(w), jw, I0, rev(k), zk);
      }
    }
    t.C = coriolis_matrix(dM, qd);
    return t;
  }

 private:
  bool rev(int j) const { return c_[j].joint == nhdyn::joint_type::revolute; }
  nhdyn::chain<double> c_;
  nhdyn::kinematics<double> kin_;
  int n_;
};

/// The same terms for a kinematic tree: body i's Jacobian has columns for its ancestors j
/// only (and itself), each joint turning about (or sliding along) the z axis of its kernel
/// frame K_j (model/tree_kernel.hpp: the moved joint frame with the axis as z). On the path
/// from the root to i, q order is ancestry order, so the chain's "k < j" (k before j) is
/// "k is an ancestor of j" and the closed forms carry over; blocks are w×w over the w
/// ancestors and scattered into M and ∂M/∂q_k.
class tree_lagrange_terms {
 public:
  explicit tree_lagrange_terms(const nhdyn::tree<double>& t)
      : t_(t), links_(nhdyn::detail::make_tree_links(t)), n_(t.dof()) {
    for (int i = 0; i < n_; ++i) {
      std::vector<int> a;
      for (int j = i; j >= 0; j = t.parent(j)) a.insert(a.begin(), j);
      path_.push_back(std::move(a));
    }
  }

  lagrange_terms::terms operator()(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const {
    const int n = n_;
    std::vector<Eigen::Matrix3d> KR(static_cast<std::size_t>(n));
    std::vector<Eigen::Vector3d> Kp(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {  // kernel frames K_i(q) in the base frame
      const auto& k = links_[std::size_t(i)];
      Eigen::Matrix3d R;
      Eigen::Vector3d p;
      nhdyn::detail::kernel_placement(k, q(i), R, p);
      if (k.parent < 0) {
        KR[std::size_t(i)] = R;
        Kp[std::size_t(i)] = p;
      } else {
        KR[std::size_t(i)] = KR[std::size_t(k.parent)] * R;
        Kp[std::size_t(i)] = Kp[std::size_t(k.parent)] + KR[std::size_t(k.parent)] * p;
      }
    }
    // a prismatic joint's axis passes wherever; a revolute's through K's origin (fixed by q_j)
    std::vector<Eigen::MatrixXd> dM(static_cast<std::size_t>(n), Eigen::MatrixXd::Zero(n, n));
    lagrange_terms::terms t{Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd::Zero(n)};
    const Eigen::Vector3d g0 = t_.gravity();
    for (int li = 0; li < n; ++li) {
      const auto& L = links_[std::size_t(li)];
      if (!(L.m > 0)) continue;
      const auto& idx = path_[std::size_t(li)];
      const int w = int(idx.size());
      const Eigen::Vector3d c = L.h / L.m;  // centre of mass in K_li
      const Eigen::Matrix3d Ic = L.Io - L.m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
      const Eigen::Matrix3d& R = KR[std::size_t(li)];
      const Eigen::Vector3d pc = Kp[std::size_t(li)] + R * c;
      const Eigen::Matrix3d I0 = R * Ic * R.transpose();
      Eigen::Matrix3Xd Jv(3, w), Jw(3, w), dJv(3, w), dJw(3, w);
      const auto z = [&](int a) -> Eigen::Vector3d { return KR[std::size_t(idx[std::size_t(a)])].col(2); };
      const auto o = [&](int a) -> const Eigen::Vector3d& { return Kp[std::size_t(idx[std::size_t(a)])]; };
      const auto rev = [&](int a) { return links_[std::size_t(idx[std::size_t(a)])].revolute; };
      for (int j = 0; j < w; ++j) {
        if (rev(j)) {
          Jv.col(j) = z(j).cross(pc - o(j));
          Jw.col(j) = z(j);
        } else {
          Jv.col(j) = z(j);
          Jw.col(j).setZero();
        }
      }
      const Eigen::MatrixXd Mi = L.m * Jv.transpose() * Jv + Jw.transpose() * I0 * Jw;
      const Eigen::VectorXd gi = -L.m * Jv.transpose() * g0;
      for (int a = 0; a < w; ++a) {
        t.g(idx[std::size_t(a)]) += gi(a);
        for (int b = 0; b < w; ++b) t.M(idx[std::size_t(a)], idx[std::size_t(b)]) += Mi(a, b);
      }
      for (int k = 0; k < w; ++k) {
        for (int j = 0; j < w; ++j)
          jacobian_column_derivative(rev(k), rev(j), k < j, z(k), z(j), o(k), pc, Jv.col(j), dJv.col(j), dJw.col(j));
        const Eigen::MatrixXd D = mass_matrix_derivative_share(L.m, dJv, Jv, dJw, Jw, I0, rev(k), z(k));
        auto& dMk = dM[std::size_t(idx[std::size_t(k)])];
        for (int a = 0; a < w; ++a)
          for (int b = 0; b < w; ++b) dMk(idx[std::size_t(a)], idx[std::size_t(b)]) += D(a, b);
      }
    }
    t.C = coriolis_matrix(dM, qd);
    return t;
  }

 private:
  nhdyn::tree<double> t_;
  std::vector<nhdyn::detail::tree_link<double>> links_;
  std::vector<std::vector<int>> path_;  // ancestors of each body, root first, then itself
  int n_;
};

/// τ = Sᵀ(M(Sη̇ + Ṡη) + C Sη + g) for a constraint whose projection is Sᵀ (SᵀS = I and E = S:
/// the differential drive; or SᵀE = I: rolling_wheels, bicycle), on a chain or a tree.
template <class Constraint, class Terms = lagrange_terms>
class projected_lagrange {
 public:
  template <class Model>
  projected_lagrange(const Model& c, Constraint con) : terms_(c), c_(std::move(con)) {}
  Eigen::VectorXd operator()(const Eigen::VectorXd& q, const Eigen::VectorXd& eta,
                             const Eigen::VectorXd& eta_dot) const {
    const Eigen::MatrixXd S = c_.S(q);
    const Eigen::VectorXd qd = S * eta;
    const Eigen::MatrixXd Sd = c_.Sdot(q, qd);
    const auto t = terms_(q, qd);
    const Eigen::VectorXd qdd = S * eta_dot + Sd * eta;
    // τ = (SᵀE)⁺ Sᵀ v: Sᵀ v itself where SᵀE = I (the built-in types but wheeled_base), the
    // constraint's actuation otherwise (wheeled_base: the least-norm τ of p actuators)
    return nhdyn::detail::solve_StE(c_, q, Eigen::VectorXd(S.transpose() * (t.M * qdd + t.C * qd + t.g)));
  }

 private:
  Terms terms_;
  Constraint c_;
};

}  // namespace nhdyn_bench
