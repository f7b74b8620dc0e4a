#pragma once
/// \file bench/lagrange.hpp
/// The formulation the paper argues against, as a reasonable implementation: the projected
/// Euler–Lagrange equations
///
///     τ = Sᵀ ( M(q) (S η̇ + Ṡ η) + C(q, q̇) S η + g(q) ),   q̇ = S η
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
        for (int j = 0; j < w; ++j) {
          const Eigen::Vector3d zj = X[std::size_t(j)].R.col(2);
          if (rev(k)) {
            if (rev(j)) {
              dJv.col(j) = k < j ? Eigen::Vector3d(zk.cross(Jv.col(j))) : Eigen::Vector3d(zj.cross(zk.cross(pc - ok)));
              dJw.col(j) = k < j ? Eigen::Vector3d(zk.cross(zj)) : Eigen::Vector3d::Zero();
            } else {
              dJv.col(j) = k < j ? Eigen::Vector3d(zk.cross(zj)) : Eigen::Vector3d::Zero();
              dJw.col(j).setZero();
            }
          } else {
            dJv.col(j) = (rev(j) && k >= j) ? Eigen::Vector3d(zj.cross(zk)) : Eigen::Vector3d::Zero();
            dJw.col(j).setZero();
          }
        }
        const auto djv = dJv.leftCols(w);
        const auto djw = dJw.leftCols(w);
        Eigen::MatrixXd P = L.mass * djv.transpose() * jv;
        P.noalias() += djw.transpose() * I0 * jw;
        auto D = dM[std::size_t(k)].topLeftCorner(w, w);
        D += P + P.transpose();
        if (rev(k)) {
          const Eigen::Matrix3d Z = skew(zk);
          const Eigen::Matrix3d dI0 = Z * I0 - I0 * Z;
          D.noalias() += jw.transpose() * dI0 * jw;
        }
      }
    }
    // C = ½(Ṁ + D − Dᵀ): Christoffel symbols of the first kind contracted with q̇.
    Eigen::MatrixXd Mdot = Eigen::MatrixXd::Zero(n, n), D(n, n);
    for (int k = 0; k < n; ++k) {
      Mdot += qd(k) * dM[std::size_t(k)];
      D.col(k) = dM[std::size_t(k)] * qd;
    }
    t.C = 0.5 * (Mdot + D - D.transpose());
    return t;
  }

 private:
  bool rev(int j) const { return c_[j].joint == nhdyn::joint_type::revolute; }
  nhdyn::chain<double> c_;
  nhdyn::kinematics<double> kin_;
  int n_;
};

/// τ = Sᵀ(M(Sη̇ + Ṡη) + C Sη + g) for a constraint with SᵀS = I (the differential drive).
template <class Constraint>
class projected_lagrange {
 public:
  projected_lagrange(const nhdyn::chain<double>& c, Constraint con) : terms_(c), c_(std::move(con)) {}
  Eigen::VectorXd operator()(const Eigen::VectorXd& q, const Eigen::VectorXd& eta,
                             const Eigen::VectorXd& eta_dot) const {
    const Eigen::MatrixXd S = c_.S(q);
    const Eigen::VectorXd qd = S * eta;
    const Eigen::MatrixXd Sd = c_.Sdot(q, qd);
    const auto t = terms_(q, qd);
    const Eigen::VectorXd qdd = S * eta_dot + Sd * eta;
    return S.transpose() * (t.M * qdd + t.C * qd + t.g);
  }

 private:
  lagrange_terms terms_;
  Constraint c_;
};

}  // namespace nhdyn_bench
