// LQR for paper5 about a straight-line motion, designed on the exact linearisation by duals
// (analysis/linearize.hpp), then simulated on the full nonlinear nonholonomic dynamics.
//
// Reference: constant forward speed v₀ along a straight line at constant heading, arm still:
//   q_ref(t) = q₀ + S(q₀) η_ref t,  η_ref = (v₀, 0, 0, 0),  τ_ref = τ(q_ref, η_ref, 0).
// Why a time-invariant design is sound here: the dynamics do not depend on the base position
// (q₁, q₂ are ground-plane translations, perpendicular to gravity), and along a straight
// line q₃, q₄, q₅ and η are constant, so A = ∂f/∂x and B = ∂f/∂τ are the same at every
// point of the reference and the error e = x − x_ref(t) obeys ė = A e + B δτ exactly to
// first order. The pair (A, B) is controllable only because v₀ ≠ 0 (the lateral error is
// steered through the heading, ė_lat = v₀ e_ψ); at v₀ = 0 the linearisation loses the
// lateral direction (Brockett's obstruction) and the program shows the rank dropping.
//
// The Riccati equation AᵀP + PA − PBR⁻¹BᵀP + Q = 0 is solved with Eigen only: the matrix
// sign function of the Hamiltonian (Newton iteration with determinant scaling), then one
// Newton–Kleinman step (a Lyapunov equation solved as a Kronecker system) to polish P.
#include <Eigen/Dense>
#include <cstdio>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/nhdyn.hpp>
#include <unsupported/Eigen/KroneckerProduct>

namespace {
using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;

/// Stabilising solution of the continuous algebraic Riccati equation.
Mat care(const Mat& A, const Mat& B, const Mat& Q, const Mat& R) {
  const int n = static_cast<int>(A.rows());
  const Mat G = B * R.inverse() * B.transpose();
  Mat Z(2 * n, 2 * n);
  Z << A, -G, -Q, -A.transpose();
  for (int it = 0; it < 100; ++it) {
    const Eigen::PartialPivLU<Mat> lu(Z);
    const double c = std::pow(std::abs(lu.determinant()), -1.0 / (2 * n));  // determinant scaling
    const Mat Zn = 0.5 * (c * Z + lu.inverse() / c);
    const double d = (Zn - Z).norm() / Z.norm();
    Z = Zn;
    if (d < 1e-14) break;
  }
  Mat lhs(2 * n, n), rhs(2 * n, n);
  lhs << Z.topRightCorner(n, n), Z.bottomRightCorner(n, n) + Mat::Identity(n, n);
  rhs << Z.topLeftCorner(n, n) + Mat::Identity(n, n), Z.bottomLeftCorner(n, n);
  Mat P = lhs.colPivHouseholderQr().solve(-rhs);
  P = 0.5 * (P + P.transpose());
  // Newton–Kleinman polish: (A − GP)ᵀX + X(A − GP) = −(Q + PGP).
  const Mat Ac = A - G * P;
  const Mat I = Mat::Identity(n, n);
  Mat L = Eigen::kroneckerProduct(I, Ac.transpose()) + Eigen::kroneckerProduct(Ac.transpose(), I);
  const Mat C = -(Q + P * G * P);
  const Vec x = L.partialPivLu().solve(Eigen::Map<const Vec>(C.data(), n * n));
  P = Eigen::Map<const Mat>(x.data(), n, n);
  return 0.5 * (P + P.transpose());
}

int controllability_rank(const Mat& A, const Mat& B) {
  const int n = static_cast<int>(A.rows());
  Mat C(n, n * B.cols());
  Mat blk = B;
  for (int i = 0; i < n; ++i) {
    C.middleCols(i * B.cols(), B.cols()) = blk;
    blk = A * blk;
  }
  // Scale columns so that the rank test is not fooled by the columns' magnitudes.
  for (int j = 0; j < C.cols(); ++j)
    if (C.col(j).norm() > 0) C.col(j).normalize();
  Eigen::JacobiSVD<Mat> svd(C);
  const auto& s = svd.singularValues();
  int r = 0;
  for (int i = 0; i < s.size(); ++i) r += s(i) > 1e-9 * s(0);
  return r;
}
}  // namespace

int main() {
  const auto rb = nhdyn::presets::paper5();
  const auto& ch = rb.chain;
  const auto& c = rb.constraint;
  const auto id = nhdyn::inverse_dynamics(ch, c);
  const auto fd = nhdyn::nh_forward_dynamics(ch, c);
  using V5 = Eigen::Matrix<double, 5, 1>;
  using V4 = Eigen::Matrix<double, 4, 1>;

  const double v0 = 0.5;  // m/s
  const V5 q0(0.0, 0.0, 0.3, 0.6, -0.8);
  const V4 eta_ref(v0, 0, 0, 0);
  const V4 tau_ref = id(q0, eta_ref, V4::Zero());
  const V5 qdot_ref = nhdyn::apply_S(c, q0, eta_ref);
  const auto q_ref = [&](double t) { return V5(q0 + qdot_ref * t); };

  const auto lin = nhdyn::linearize_forward_dynamics(ch, c, q0, eta_ref, tau_ref);
  const Mat A = lin.A, B = lin.B;
  // Time invariance along the reference: A does not change when the base has moved.
  const auto lin5 = nhdyn::linearize_forward_dynamics(ch, c, q_ref(5.0), eta_ref, tau_ref);
  std::printf("paper5 LQR about a straight line at v0 = %.2f m/s, heading q3 = %.2f rad\n", v0, q0(2));
  std::printf("  |A(t=5) - A(t=0)| = %.2e, |B(t=5) - B(t=0)| = %.2e (time-invariant error dynamics)\n",
              (lin5.A - lin.A).norm(), (lin5.B - lin.B).norm());
  const auto lin_rest = nhdyn::linearize_forward_dynamics(ch, c, q0, V4::Zero(), id(q0, V4::Zero(), V4::Zero()));
  std::printf("  controllability rank: %d of 9 at v0 = %.2f, %d of 9 at rest (lateral direction lost)\n",
              controllability_rank(A, B), v0, controllability_rank(lin_rest.A, lin_rest.B));

  // Weights: positions and heading [m, rad], arm angles, velocities; torques scaled by the
  // effort each channel needs (the platform is 9 kg, the arm links 0.1 kg).
  Vec qw(9);
  qw << 10, 10, 10, 10, 10, 1, 1, 0.1, 0.1;
  const Mat Qw = qw.asDiagonal();
  Vec rw(4);
  rw << 0.05, 0.05, 100, 100;
  const Mat Rw = rw.asDiagonal();
  const Mat P = care(A, B, Qw, Rw);
  const Mat K = Rw.inverse() * B.transpose() * P;
  const Mat res = A.transpose() * P + P * A - P * B * Rw.inverse() * B.transpose() * P + Qw;
  const Eigen::VectorXcd ev = (A - B * K).eigenvalues();
  double max_re = -INFINITY;
  for (int i = 0; i < ev.size(); ++i) max_re = std::max(max_re, ev(i).real());
  std::printf("  Riccati residual |A'P + PA - PBR^-1B'P + Q| / |Q| = %.2e; P symmetric positive: %s\n",
              res.norm() / Qw.norm(), Eigen::SelfAdjointEigenSolver<Mat>(P).eigenvalues().minCoeff() > 0 ? "yes" : "no");
  std::printf("  closed-loop eigenvalues: max real part %.3f 1/s\n", max_re);

  // Nonlinear closed-loop simulation, RK4 at 1 ms, from a perturbed start.
  Vec x(9);
  x << q0 + V5(0.05, 0.10, 0.10, 0.10, -0.10), eta_ref + V4(0.05, 0.0, 0.0, 0.0);
  const auto x_ref = [&](double t) {
    Vec r(9);
    r << q_ref(t), eta_ref;
    return r;
  };
  const auto f = [&](double t, const Vec& s) {
    const V5 q = s.head(5);
    const V4 eta = s.tail(4);
    const V4 tau = tau_ref - K * (s - x_ref(t));
    Vec d(9);
    d << nhdyn::apply_S(c, q, eta), fd(q, eta, tau);
    return d;
  };
  const double dt = 1e-3, T = 20.0;
  const double e0 = (x - x_ref(0)).norm();
  double max_slip = 0;
  std::printf("  %6s  %12s  %12s  %12s\n", "t [s]", "|x - x_ref|", "lateral [m]", "heading [rad]");
  for (int k = 0; k <= static_cast<int>(T / dt); ++k) {
    const double t = k * dt;
    if (k % 2000 == 0) {
      const Vec e = x - x_ref(t);
      const double psi = -q0(2);  // paper5: ψ = −q₃
      const double lateral = -std::sin(psi) * e(0) + std::cos(psi) * e(1);
      std::printf("  %6.1f  %12.3e  %12.3e  %12.3e\n", t, e.norm(), lateral, e(2));
    }
    if (k == static_cast<int>(T / dt)) break;
    const Vec k1 = f(t, x), k2 = f(t + dt / 2, x + dt / 2 * k1), k3 = f(t + dt / 2, x + dt / 2 * k2),
              k4 = f(t + dt, x + dt * k3);
    x += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    const V5 q = x.head(5);
    max_slip = std::max(max_slip, std::abs((c.A(q) * nhdyn::apply_S(c, q, V4(x.tail(4)))).value()));
  }
  const double eT = (x - x_ref(T)).norm();
  std::printf("  error %.3e -> %.3e over %.0f s (ratio %.1e); max |A(q) qdot| = %.1e (no lateral slip)\n", e0,
              eT, T, eT / e0, max_slip);
  const bool ok = eT < 1e-3 * e0 && max_re < 0;
  std::printf("%s\n", ok ? "converged: the tracking error decays to zero" : "NOT converged");
  return ok ? 0 : 1;
}
