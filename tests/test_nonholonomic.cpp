// Nonholonomic inverse and forward dynamics against independent references.
//
// The reference is written here from scratch and shares no code with the library's
// dynamics: 4×4 Denavit–Hartenberg forward kinematics (four elementary matrices per link),
// link Jacobians from that geometry, M(q) = Σ m Jvᵀ Jv + Jωᵀ R I Rᵀ Jω, Coriolis from the
// Christoffel symbols of M, gravity from the potential energy, and the projected
// Euler–Lagrange equations
//
//     Sᵀ M S η̇ + Sᵀ (M Ṡ η + C(q, Sη) S η + g) = Sᵀ E τ                (paper eq. 15–18)
//
// with S and Ṡ written out by hand. Partial derivatives of M and V come from duals; the
// energy rate dE/dt from nested duals in time (no Jacobian, no M). The library's rne and
// CRBA are never used as a reference.
#include <catch2/catch.hpp>
#include <cstdio>
#include <nhdyn/nhdyn.hpp>
#include <numbers>
#include <random>

namespace {

using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;
template <class T>
using VecT = Eigen::Matrix<T, Eigen::Dynamic, 1>;
template <class T>
using MatT = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
template <class T>
using M4 = Eigen::Matrix<T, 4, 4>;

// ---------------------------------------------------------------------------------------
// Reference: Euler–Lagrange from our own forward kinematics.

struct el_model {
  std::vector<nhdyn::link<double>> links;
  Eigen::Vector3d g;
};

template <class S, int N>
el_model el_of(const nhdyn::chain<S, N>& ch) {
  el_model m;
  for (const auto& L : ch) m.links.push_back(L);
  m.g = ch.gravity();
  return m;
}

/// A_i = Rz(θ) · Tz(d) · Tx(a) · Rx(α), each factor a 4×4 matrix (Spong's standard DH).
template <class T>
M4<T> dh_matrix(const nhdyn::link<double>& L, const T& qi) {
  using std::cos;
  using std::sin;
  const bool rev = L.joint == nhdyn::joint_type::revolute;
  const T th = rev ? T(L.theta) + qi : T(L.theta);
  const T d = rev ? T(L.d) : T(L.d) + qi;
  M4<T> Rz = M4<T>::Identity(), Tz = M4<T>::Identity(), Tx = M4<T>::Identity(), Rx = M4<T>::Identity();
  Rz(0, 0) = cos(th);
  Rz(0, 1) = -sin(th);
  Rz(1, 0) = sin(th);
  Rz(1, 1) = cos(th);
  Tz(2, 3) = d;
  Tx(0, 3) = T(L.a);
  Rx(1, 1) = T(std::cos(L.alpha));
  Rx(1, 2) = T(-std::sin(L.alpha));
  Rx(2, 1) = T(std::sin(L.alpha));
  Rx(2, 2) = T(std::cos(L.alpha));
  return M4<T>(Rz * Tz * Tx * Rx);
}

/// X[0] = I, X[i] = A_1 ⋯ A_i.
template <class T>
std::vector<M4<T>> fk(const el_model& m, const VecT<T>& q) {
  std::vector<M4<T>> X(m.links.size() + 1, M4<T>::Identity());
  for (std::size_t i = 0; i < m.links.size(); ++i) X[i + 1] = X[i] * dh_matrix(m.links[i], q(Eigen::Index(i)));
  return X;
}

template <class T>
Eigen::Matrix<T, 3, 1> com_position(const el_model& m, const std::vector<M4<T>>& X, std::size_t i) {
  const Eigen::Matrix<T, 4, 1> c(T(m.links[i].com(0)), T(m.links[i].com(1)), T(m.links[i].com(2)), T(1));
  return (X[i + 1] * c).template head<3>();
}

/// M(q) = Σ_i m_i Jv_iᵀ Jv_i + Jω_iᵀ (R_i I_i R_iᵀ) Jω_i, Jacobians of the centres of mass.
template <class T>
MatT<T> el_mass(const el_model& m, const VecT<T>& q) {
  const auto X = fk(m, q);
  const Eigen::Index n = q.size();
  MatT<T> M = MatT<T>::Zero(n, n);
  for (std::size_t i = 0; i < m.links.size(); ++i) {
    const auto& L = m.links[i];
    const Eigen::Matrix<T, 3, 1> pc = com_position(m, X, i);
    MatT<T> Jv = MatT<T>::Zero(3, n), Jw = MatT<T>::Zero(3, n);
    for (std::size_t j = 0; j <= i; ++j) {
      const Eigen::Matrix<T, 3, 1> z = X[j].template block<3, 1>(0, 2);
      const Eigen::Matrix<T, 3, 1> o = X[j].template block<3, 1>(0, 3);
      if (m.links[j].joint == nhdyn::joint_type::revolute) {
        Jv.col(Eigen::Index(j)) = z.cross(pc - o);
        Jw.col(Eigen::Index(j)) = z;
      } else {
        Jv.col(Eigen::Index(j)) = z;
      }
    }
    const Eigen::Matrix<T, 3, 3> R = X[i + 1].template block<3, 3>(0, 0);
    const Eigen::Matrix<T, 3, 3> Iw = R * L.inertia.template cast<T>() * R.transpose();
    M += T(L.mass) * Jv.transpose() * Jv + Jw.transpose() * Iw * Jw;
  }
  return M;
}

/// V(q) = −Σ m_i gᵀ p_ci.
template <class T>
T el_potential(const el_model& m, const VecT<T>& q) {
  const auto X = fk(m, q);
  T V(0);
  for (std::size_t i = 0; i < m.links.size(); ++i)
    V -= T(m.links[i].mass) * com_position(m, X, i).dot(m.g.template cast<T>());
  return V;
}

struct el_terms {
  Mat M;  // M(q)
  Mat C;  // C(q, q̇), Christoffel form: C_kj = Σ_i c_ijk q̇_i
  Vec g;  // ∂V/∂q
};

/// M, C(q, q̇) and g with ∂M/∂q_i and ∂V/∂q_i exact, from duals with NJ seed directions.
template <int NJ>
el_terms el_compute(const el_model& m, const Vec& q, const Vec& qd) {
  using D = nhdyn::dual<double, NJ>;
  const int n = int(q.size());
  REQUIRE(n == NJ);
  VecT<D> qq(n);
  for (int j = 0; j < n; ++j) qq(j) = D::variable(q(j), j);
  const MatT<D> MD = el_mass(m, qq);
  const D VD = el_potential(m, qq);
  el_terms t;
  t.M = MD.unaryExpr([](const D& x) { return x.value(); });
  std::vector<Mat> dM(std::size_t(n), Mat(n, n));
  for (int i = 0; i < n; ++i) dM[std::size_t(i)] = MD.unaryExpr([i](const D& x) { return x.derivative(i); });
  t.C = Mat::Zero(n, n);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        t.C(k, j) += 0.5 * (dM[std::size_t(i)](k, j) + dM[std::size_t(j)](k, i) - dM[std::size_t(k)](i, j)) * qd(i);
  t.g.resize(n);
  for (int k = 0; k < n; ++k) t.g(k) = VD.derivative(k);
  return t;
}

/// dE/dt of E = kinetic + potential energy at (q, q̇, q̈), with no Jacobian and no M: the
/// path q(t) = q + t q̇ + ½t² q̈ runs through the forward kinematics in nested duals; body
/// velocities are its time derivatives, and the outer dual differentiates E in time.
double energy_rate(const el_model& m, const Vec& q, const Vec& qd, const Vec& qdd) {
  using D1 = nhdyn::dual<double, 1>;
  using D2 = nhdyn::dual<D1, 1>;
  const D2 t(D1(0.0, {1.0}), {D1(1.0, {0.0})});
  const int n = int(q.size());
  VecT<D2> qt(n);
  for (int j = 0; j < n; ++j) qt(j) = D2(q(j)) + t * D2(qd(j)) + t * t * D2(0.5 * qdd(j));
  const auto X = fk(m, qt);
  const auto val = [](const D2& x) { return x.value(); };
  const auto der = [](const D2& x) { return x.derivative(0); };
  D1 E(0.0);
  for (std::size_t i = 0; i < m.links.size(); ++i) {
    const auto& L = m.links[i];
    const Eigen::Matrix<D2, 3, 1> pc = com_position(m, X, i);
    const Eigen::Matrix<D1, 3, 1> p = pc.unaryExpr(val), v = pc.unaryExpr(der);
    const Eigen::Matrix<D2, 3, 3> R2 = X[i + 1].template block<3, 3>(0, 0);
    const Eigen::Matrix<D1, 3, 3> R = R2.unaryExpr(val), Rd = R2.unaryExpr(der);
    const Eigen::Matrix<D1, 3, 3> W = Rd * R.transpose();  // ω^ (world)
    const Eigen::Matrix<D1, 3, 1> w(W(2, 1), W(0, 2), W(1, 0));
    const Eigen::Matrix<D1, 3, 3> Iw = R * L.inertia.template cast<D1>() * R.transpose();
    E += D1(0.5 * L.mass) * v.dot(v) + D1(0.5) * w.dot(Iw * w) - D1(L.mass) * p.dot(m.g.template cast<D1>());
  }
  return E.derivative(0);
}

// ---------------------------------------------------------------------------------------
// Hand-written S, Ṡ of a differential-drive base on joints (0, 1, 2) as paper5.md writes it:
// η = (v, ω, q̇₄, …), q̇₁ = cos q₃ v, q̇₂ = −sin q₃ v.

Mat S_hand(const Vec& q) {
  const int n = int(q.size());
  Mat S = Mat::Zero(n, n - 1);
  S(0, 0) = std::cos(q(2));
  S(1, 0) = -std::sin(q(2));
  for (int j = 2; j < n; ++j) S(j, j - 1) = 1.0;
  return S;
}
Mat Sdot_hand(const Vec& q, const Vec& qd) {
  const int n = int(q.size());
  Mat Sd = Mat::Zero(n, n - 1);
  Sd(0, 0) = -std::sin(q(2)) * qd(2);
  Sd(1, 0) = -std::cos(q(2)) * qd(2);
  return Sd;
}
Mat A_hand(const Vec& q) {
  Mat A = Mat::Zero(1, q.size());
  A(0, 0) = std::sin(q(2));
  A(0, 1) = std::cos(q(2));
  return A;
}

/// Sᵀ M S η̇ + Sᵀ (M Ṡ η + C S η + g): the projected Euler–Lagrange left-hand side.
template <int NJ>
Vec projected_el(const el_model& m, const Mat& S, const Mat& Sd, const Vec& q, const Vec& eta, const Vec& eta_dot) {
  const Vec qd = S * eta;
  const el_terms t = el_compute<NJ>(m, q, qd);
  return S.transpose() * t.M * S * eta_dot + S.transpose() * (t.M * Sd * eta + t.C * qd + t.g);
}

/// A differential-drive base (paper5's joints 1–3, with joint 3 about the vertical x₀ and
/// z₃ vertical) carrying a Puma 560 arm: 9 joints.
nhdyn::chain<double, 9> dd_puma() {
  const auto p5 = nhdyn::presets::paper5_chain<double>();
  const auto puma = nhdyn::presets::puma560<double>();
  std::array<nhdyn::link<double>, 9> L{};
  L[0] = p5[0];
  L[1] = p5[1];
  // Platform: box 0.445 (x₃, forward) × 0.393 (y₃, lateral) × 0.237 (z₃, up), frame 3 on top.
  L[2] = {nhdyn::joint_type::revolute, 0.0, 0.0, 0.0, 0.237, 9.0, Eigen::Vector3d(0, 0, -0.1185),
          nhdyn::box_inertia<double>(9.0, 0.445, 0.393, 0.237)};
  for (int i = 0; i < 6; ++i) L[std::size_t(3 + i)] = puma[i];
  return nhdyn::chain<double, 9>(L, Eigen::Vector3d(-9.81, 0, 0), "dd_puma", nhdyn::validation{false});
}

struct rng {
  std::mt19937 gen{20261121};
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  Vec vec(int n, double scale = 1.0) {
    Vec v(n);
    for (int i = 0; i < n; ++i) v(i) = scale * u(gen);
    return v;
  }
};

double rel(const Vec& a, const Vec& ref) { return (a - ref).norm() / std::max(1.0, ref.norm()); }

void report(const char* what, double value) { std::printf("[measured] %-70s %.3e\n", what, value); }

}  // namespace

TEST_CASE("nonholonomic id: paper5 equals the projected Euler-Lagrange equations of an independent model") {
  const auto r = nhdyn::presets::paper5();
  const el_model ref = el_of(r.chain);
  const auto id = nhdyn::inverse_dynamics(r.chain, r.constraint);
  rng R;
  double worst = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Vec q = R.vec(5);
    q(2) *= std::numbers::pi;
    const Vec eta = R.vec(4, 2.0), eta_dot = R.vec(4, 3.0);
    const Eigen::Matrix<double, 5, 1> qf = q;
    const Eigen::Matrix<double, 4, 1> ef = eta, edf = eta_dot;
    const Vec tau = id(qf, ef, edf);
    // paper5: SᵀS = I, so τ = Sᵀv is the projected equation itself.
    const Vec tau_ref = projected_el<5>(ref, S_hand(q), Sdot_hand(q, S_hand(q) * eta), q, eta, eta_dot);
    worst = std::max(worst, rel(tau, tau_ref));
    REQUIRE(rel(tau, tau_ref) < 1e-12);
  }
  report("paper5 id vs projected Euler-Lagrange (rel, 200 states)", worst);
}

TEST_CASE("nonholonomic id: a differential-drive base carrying a 6R arm equals projected Euler-Lagrange") {
  const auto ch = dd_puma();
  const nhdyn::differential_drive<double, 9> c(9, 0, 1, 2, 0.0, -1.0);
  const el_model ref = el_of(ch);
  const auto id = nhdyn::inverse_dynamics(ch, c);
  const auto id_dyn = nhdyn::inverse_dynamics(ch.dynamic_size(), nhdyn::differential_drive<double>(9, 0, 1, 2, 0.0, -1.0));
  rng R;
  double worst = 0, worst_dyn = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Vec q = R.vec(9, std::numbers::pi);
    q(0) = R.u(R.gen);
    q(1) = R.u(R.gen);
    const Vec eta = R.vec(8, 2.0), eta_dot = R.vec(8, 3.0);
    const Eigen::Matrix<double, 9, 1> qf = q;
    const Eigen::Matrix<double, 8, 1> ef = eta, edf = eta_dot;
    const Vec tau = id(qf, ef, edf);
    const Vec tau_ref = projected_el<9>(ref, S_hand(q), Sdot_hand(q, S_hand(q) * eta), q, eta, eta_dot);
    worst = std::max(worst, rel(tau, tau_ref));
    REQUIRE(rel(tau, tau_ref) < 1e-12);
    const Vec tau_dyn = id_dyn(q, eta, eta_dot);
    worst_dyn = std::max(worst_dyn, rel(tau_dyn, tau));
    REQUIRE(rel(tau_dyn, tau) < 1e-14);
  }
  report("dd+puma (9 joints) id vs projected Euler-Lagrange (rel, 100 states)", worst);
  report("dd+puma fixed-size vs run-time-size id (rel)", worst_dyn);
}

TEST_CASE("nonholonomic id: the base does not slip in the kinematics of the 6R-arm robot") {
  // The constraint row must be the lateral axis of the platform as the chain's own geometry
  // has it: v_{o2} · y₃ = 0 (y₃ is lateral here, z₃ vertical). Checked with the library's
  // Jacobian and with our own forward kinematics.
  const auto ch = dd_puma();
  const nhdyn::differential_drive<double, 9> c(9, 0, 1, 2, 0.0, -1.0);
  const nhdyn::kinematics kin(ch);
  const el_model ref = el_of(ch);
  rng R;
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Vec q = R.vec(9, 3.0), eta = R.vec(8, 2.0);
    const Eigen::Matrix<double, 9, 1> qf = q;
    const Eigen::Matrix<double, 8, 1> ef = eta;
    const Eigen::Matrix<double, 9, 1> qd = nhdyn::apply_S(c, qf, ef);
    const Eigen::Vector3d v2 = (kin.jacobian(qf, 2) * qd).head<3>();
    const auto X = fk(ref, q);
    const Eigen::Vector3d y3 = X[3].block<3, 1>(0, 1), x3 = X[3].block<3, 1>(0, 0);
    worst = std::max(worst, std::abs(v2.dot(y3)));
    REQUIRE(std::abs(v2.dot(y3)) < 1e-14);
    REQUIRE(v2.dot(x3) == Approx(eta(0)).margin(1e-14));  // v is the forward speed along x₃
  }
  report("dd+puma lateral slip |v_o2 . y3| (m/s)", worst);
}

TEST_CASE("constraint forces: v = E tau + A^T lambda exactly, and lambda does no work") {
  const auto r = nhdyn::presets::paper5();
  const el_model ref = el_of(r.chain);
  const auto idf = nhdyn::inverse_dynamics_with_forces(r.chain, r.constraint);
  const auto lift = nhdyn::lift(r.constraint);
  const auto rne = nhdyn::rne(r.chain);
  rng R;
  double worst_v = 0, worst_work = 0, worst_power = 0, worst_lambda = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix<double, 5, 1> q = R.vec(5, 2.0);
    const Eigen::Matrix<double, 4, 1> eta = R.vec(4, 2.0), eta_dot = R.vec(4, 3.0);
    const auto out = idf(q, eta, eta_dot);
    const auto xi = lift(q, eta, eta_dot);
    const Vec v = rne(xi.q, xi.qd, xi.qdd);
    const Mat A = A_hand(q), S = S_hand(q);
    const Vec recon = S * out.tau + A.transpose() * out.lambda;
    worst_v = std::max(worst_v, rel(recon, v));
    REQUIRE(rel(recon, v) < 1e-14);
    // λ from the independent model: the lateral component of v, A v / (A Aᵀ) with |A| = 1.
    const Vec qd = S * eta;
    const el_terms t = el_compute<5>(ref, q, qd);
    const Vec v_ref = t.M * Vec(xi.qdd) + t.C * qd + t.g;
    const double lambda_ref = (A * v_ref)(0);
    worst_lambda = std::max(worst_lambda, std::abs(out.lambda(0) - lambda_ref) / std::max(1.0, std::abs(lambda_ref)));
    REQUIRE(std::abs(out.lambda(0) - lambda_ref) < 1e-12 * std::max(1.0, std::abs(lambda_ref)));
    // No work: q̇ᵀ Aᵀ λ = 0.
    const double work = qd.dot(A.transpose() * out.lambda);
    worst_work = std::max(worst_work, std::abs(work) / std::max(1.0, std::abs(out.lambda(0))));
    REQUIRE(std::abs(work) < 1e-14 * std::max(1.0, std::abs(out.lambda(0))));
    // Power balance: q̇ᵀv = dE/dt (energy from nested duals) = ηᵀ τ (actuator power).
    const double dE = energy_rate(ref, q, qd, xi.qdd);
    worst_power = std::max(worst_power, std::abs(qd.dot(v) - dE) / std::max(1.0, std::abs(dE)));
    REQUIRE(qd.dot(v) == Approx(dE).epsilon(1e-12).margin(1e-12));
    REQUIRE(eta.dot(out.tau) == Approx(dE).epsilon(1e-12).margin(1e-12));
  }
  report("paper5 |v - (S tau + A^T lambda)| (rel)", worst_v);
  report("paper5 lambda vs independent A v_ref (rel)", worst_lambda);
  report("paper5 constraint-force power qd^T A^T lambda (rel to |lambda|)", worst_work);
  report("paper5 power balance qd^T v vs dE/dt (rel)", worst_power);
}

TEST_CASE("constraint forces: power balance on the 6R-arm robot") {
  const auto ch = dd_puma();
  const nhdyn::differential_drive<double, 9> c(9, 0, 1, 2, 0.0, -1.0);
  const el_model ref = el_of(ch);
  const auto idf = nhdyn::inverse_dynamics_with_forces(ch, c);
  rng R;
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix<double, 9, 1> q = R.vec(9, 3.0);
    const Eigen::Matrix<double, 8, 1> eta = R.vec(8, 2.0), eta_dot = R.vec(8, 3.0);
    const auto out = idf(q, eta, eta_dot);
    const Vec qd = S_hand(q) * eta;
    const Vec qdd = S_hand(q) * eta_dot + Sdot_hand(q, qd) * eta;
    const double dE = energy_rate(ref, q, qd, qdd);
    worst = std::max(worst, std::abs(eta.dot(out.tau) - dE) / std::max(1.0, std::abs(dE)));
    REQUIRE(eta.dot(out.tau) == Approx(dE).epsilon(1e-12).margin(1e-12));
    REQUIRE(std::abs(qd.dot(A_hand(q).transpose() * out.lambda)) < 1e-13 * std::max(1.0, out.lambda.norm()));
  }
  report("dd+puma power balance eta^T tau vs dE/dt (rel)", worst);
}

// A user constraint that acts on an arm joint as well as the base: paper5's no-slip row
// plus a coupling of the shoulder to the heading, q̇₄ = c·cos q₅ · q̇₃ (not integrable, as
// ∂(c cos q₅)/∂q₅ ≠ 0). η = (v, ω, q̇₅), k = 2, m = 3; S is not orthonormal, and an input
// map E = S Γ + Aᵀ W ≠ S (E has a component along the constraint, which λ takes up).
namespace {
constexpr double kc = 0.7;
auto coupled_A = [](const auto& q) {
  using T = typename std::decay_t<decltype(q)>::Scalar;
  using std::cos;
  using std::sin;
  MatT<T> A = MatT<T>::Zero(2, 5);
  A(0, 0) = sin(q(2));
  A(0, 1) = cos(q(2));
  A(1, 2) = -T(kc) * cos(q(4));
  A(1, 3) = T(1);
  return A;
};
auto coupled_S = [](const auto& q) {
  using T = typename std::decay_t<decltype(q)>::Scalar;
  using std::cos;
  using std::sin;
  MatT<T> S = MatT<T>::Zero(5, 3);
  S(0, 0) = cos(q(2));
  S(1, 0) = -sin(q(2));
  S(2, 1) = T(1);
  S(3, 1) = T(kc) * cos(q(4));
  S(4, 2) = T(1);
  return S;
};
Mat coupled_Sdot(const Vec& q, const Vec& qd) {
  Mat Sd = Mat::Zero(5, 3);
  Sd(0, 0) = -std::sin(q(2)) * qd(2);
  Sd(1, 0) = -std::cos(q(2)) * qd(2);
  Sd(3, 1) = -kc * std::sin(q(4)) * qd(4);
  return Sd;
}
Mat Gamma() {
  Mat G(3, 3);
  G << 2.0, 0.5, 0.0, -0.3, 1.5, 0.2, 0.1, 0.0, 0.8;
  return G;
}
Mat W() {
  Mat w(2, 3);
  w << 0.4, -0.2, 0.3, 0.1, 0.6, -0.5;
  return w;
}
auto coupled_E = [](const auto& q) {
  using T = typename std::decay_t<decltype(q)>::Scalar;
  const MatT<T> S = coupled_S(q);
  const MatT<T> A = coupled_A(q);
  return MatT<T>(S * Gamma().cast<T>() + A.transpose() * W().cast<T>());
};
}  // namespace

TEST_CASE("user constraint on an arm joint: id, lambda and fd agree with projected Euler-Lagrange") {
  const auto ch = nhdyn::presets::paper5_chain<double>().dynamic_size();
  const el_model ref = el_of(ch);
  const auto c = nhdyn::make_constraint(5, 2, coupled_A, coupled_S);                      // E = S, Ṡ by duals
  const auto cE = nhdyn::make_constraint(5, 2, coupled_A, coupled_S, nullptr, coupled_E);  // E ≠ S
  const auto id = nhdyn::inverse_dynamics_with_forces(ch, c);
  const auto idE = nhdyn::inverse_dynamics_with_forces(ch, cE);
  const auto fd = nhdyn::nh_forward_dynamics(ch, c);
  const auto fdE = nhdyn::nh_forward_dynamics(ch, cE, {}, nhdyn::reduced_inertia_method::rne_columns);
  const auto rne = nhdyn::rne(ch);
  rng R;
  double worst_id = 0, worst_idE = 0, worst_fd = 0, worst_recon = 0, worst_power = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const Vec q = R.vec(5, 2.0), eta = R.vec(3, 2.0), eta_dot = R.vec(3, 3.0);
    const Mat S = coupled_S(q), A = coupled_A(q), E = coupled_E(q);
    REQUIRE((A * S).norm() < 1e-15);
    const Vec qd = S * eta;
    const Vec qdd = S * eta_dot + coupled_Sdot(q, qd) * eta;
    const Vec rhs = projected_el<5>(ref, S, coupled_Sdot(q, qd), q, eta, eta_dot);  // = SᵀEτ
    // E = S: τ = (SᵀS)⁻¹ Sᵀ v.
    const auto out = id(q, eta, eta_dot);
    const Vec tau_ref = (S.transpose() * S).lu().solve(rhs);
    worst_id = std::max(worst_id, rel(out.tau, tau_ref));
    REQUIRE(rel(out.tau, tau_ref) < 1e-12);
    // E ≠ S: τ = (SᵀE)⁻¹ Sᵀ v.
    const auto outE = idE(q, eta, eta_dot);
    const Vec tauE_ref = (S.transpose() * E).lu().solve(rhs);
    worst_idE = std::max(worst_idE, rel(outE.tau, tauE_ref));
    REQUIRE(rel(outE.tau, tauE_ref) < 1e-12);
    // v = Eτ + Aᵀλ, with v from the library's rne at the lifted state; λ does no work.
    const Vec v = rne(q, qd, qdd);
    for (const auto* o : {&out, &outE}) {
      const Mat& EE = o == &out ? S : E;
      const Vec recon = EE * o->tau + A.transpose() * o->lambda;
      worst_recon = std::max(worst_recon, rel(recon, v));
      REQUIRE(rel(recon, v) < 1e-13);
      REQUIRE(std::abs(qd.dot(A.transpose() * o->lambda)) < 1e-13 * std::max(1.0, o->lambda.norm()));
    }
    // Power: the actuators deliver all of dE/dt, ηᵀ SᵀE τ.
    const double dE = energy_rate(ref, q, qd, qdd);
    worst_power = std::max(worst_power, std::abs(eta.dot(S.transpose() * E * outE.tau) - dE) / std::max(1.0, std::abs(dE)));
    REQUIRE(eta.dot(S.transpose() * E * outE.tau) == Approx(dE).epsilon(1e-12).margin(1e-12));
    // Forward dynamics inverts it, with both M_η methods; and matches the reference solve.
    const Vec ed = fd(q, eta, out.tau), edE = fdE(q, eta, outE.tau);
    worst_fd = std::max({worst_fd, rel(ed, eta_dot), rel(edE, eta_dot)});
    REQUIRE(rel(ed, eta_dot) < 1e-11);
    REQUIRE(rel(edE, eta_dot) < 1e-11);
  }
  report("coupled user constraint id (E = S) vs projected EL (rel)", worst_id);
  report("coupled user constraint id (E != S) vs projected EL (rel)", worst_idE);
  report("coupled user constraint |v - (E tau + A^T lambda)| (rel)", worst_recon);
  report("coupled user constraint power balance (rel)", worst_power);
  report("coupled user constraint fd(id) - eta_dot (rel)", worst_fd);
}

TEST_CASE("nonholonomic fd: inverts id, and both reduced-inertia methods equal S^T M S of the reference") {
  const auto r = nhdyn::presets::paper5();
  const auto ch9 = dd_puma();
  const nhdyn::differential_drive<double, 9> c9(9, 0, 1, 2, 0.0, -1.0);
  rng R;
  double worst_inv = 0, worst_methods = 0, worst_Meta = 0, worst_h = 0;
  const auto run = [&](const auto& ch, const auto& c, auto nj) {
    constexpr int N = decltype(nj)::value;
    const el_model ref = el_of(ch);
    const auto id = nhdyn::inverse_dynamics(ch, c);
    const auto fd_crba = nhdyn::nh_forward_dynamics(ch, c, {}, nhdyn::reduced_inertia_method::crba);
    const auto fd_cols = nhdyn::nh_forward_dynamics(ch, c, {}, nhdyn::reduced_inertia_method::rne_columns);
    for (int trial = 0; trial < 100; ++trial) {
      const Eigen::Matrix<double, N, 1> q = R.vec(N, 3.0);
      const Eigen::Matrix<double, N - 1, 1> eta = R.vec(N - 1, 2.0), eta_dot = R.vec(N - 1, 3.0);
      const Eigen::Matrix<double, N - 1, 1> tau = id(q, eta, eta_dot);
      for (const auto* f : {&fd_crba, &fd_cols}) {
        const Vec ed = (*f)(q, eta, tau);
        worst_inv = std::max(worst_inv, rel(ed, eta_dot));
        REQUIRE(rel(ed, eta_dot) < 1e-11);
      }
      const Mat Mc = fd_crba.reduced_inertia(q), Mr = fd_cols.reduced_inertia(q);
      worst_methods = std::max(worst_methods, (Mc - Mr).norm() / Mc.norm());
      REQUIRE((Mc - Mr).norm() < 1e-13 * Mc.norm());
      const Vec qv = q;
      const Mat S = S_hand(qv);
      const Vec qd = S * Vec(eta);
      const el_terms t = el_compute<N>(ref, qv, qd);
      const Mat Me_ref = S.transpose() * t.M * S;
      worst_Meta = std::max(worst_Meta, (Mc - Me_ref).norm() / Me_ref.norm());
      REQUIRE((Mc - Me_ref).norm() < 1e-12 * Me_ref.norm());
      const Vec h_ref = S.transpose() * (t.M * Sdot_hand(qv, qd) * Vec(eta) + t.C * qd + t.g);
      const Vec h = fd_crba.reduced_bias(q, eta);
      worst_h = std::max(worst_h, rel(h, h_ref));
      REQUIRE(rel(h, h_ref) < 1e-12);
    }
  };
  run(r.chain, r.constraint, std::integral_constant<int, 5>{});
  run(ch9, c9, std::integral_constant<int, 9>{});
  report("fd(id(eta_dot)) - eta_dot (rel), paper5 and dd+puma, both methods", worst_inv);
  report("M_eta crba vs rne_columns (rel, Frobenius)", worst_methods);
  report("M_eta vs reference S^T M S (rel)", worst_Meta);
  report("h_eta vs reference S^T (M Sdot eta + C S eta + g) (rel)", worst_h);
}

TEST_CASE("nonholonomic id is scalar-generic: d tau / d eta_dot through duals is M_eta") {
  const auto r = nhdyn::presets::paper5();
  const auto id = nhdyn::inverse_dynamics(r.chain, r.constraint);
  const auto fd = nhdyn::nh_forward_dynamics(r.chain, r.constraint);
  using D = nhdyn::dual<double, 4>;
  rng R;
  const Eigen::Matrix<double, 5, 1> q = R.vec(5, 2.0);
  const Eigen::Matrix<double, 4, 1> eta = R.vec(4), eta_dot = R.vec(4);
  Eigen::Matrix<D, 4, 1> ed;
  for (int j = 0; j < 4; ++j) ed(j) = D::variable(eta_dot(j), j);
  const Eigen::Matrix<D, 4, 1> tau = id(q.cast<D>(), eta.cast<D>(), ed);
  Mat J(4, 4);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) J(i, j) = tau(i).derivative(j);
  const Mat Me = fd.reduced_inertia(q);
  REQUIRE((J - Me).norm() < 1e-13 * Me.norm());
  const Eigen::Matrix<double, 4, 1> tau_d = id(q, eta, eta_dot);
  for (int i = 0; i < 4; ++i) REQUIRE(tau(i).value() == Approx(tau_d(i)).epsilon(1e-15).margin(1e-15));
}

TEST_CASE("simulation: paper5 under torque keeps the constraint at rounding level and does not slip") {
  // RK4 on x = (q, η): q̇ = S(q) η, η̇ = fd(q, η, τ(t)). 3 s at 2, 1 and 0.5 ms.
  const auto r = nhdyn::presets::paper5();
  const el_model ref = el_of(r.chain);
  const auto fd = nhdyn::nh_forward_dynamics(r.chain, r.constraint);
  const nhdyn::kinematics kin(r.chain);
  using V5 = Eigen::Matrix<double, 5, 1>;
  using V4 = Eigen::Matrix<double, 4, 1>;
  const auto torque = [](double t) {
    return V4(20.0 * std::sin(1.3 * t), 2.0 * std::cos(0.7 * t), 0.05 * std::sin(2.0 * t), 0.02 * std::cos(3.0 * t));
  };
  const auto f = [&](double t, const V5& q, const V4& eta) {
    const Eigen::Matrix<double, 9, 1> dx = fd.state_derivative(q, eta, torque(t));  // (S η, η̇)
    return std::pair<V5, V4>(dx.head<5>(), dx.tail<4>());
  };
  {
    const V5 q(0.1, -0.4, 0.7, 0.3, -0.2);
    const V4 eta(0.5, -0.3, 0.8, 0.1);
    const Eigen::Matrix<double, 9, 1> dx = fd.state_derivative(q, eta, torque(0.3));
    REQUIRE((Vec(dx.head<5>()) - S_hand(q) * Vec(eta)).cwiseAbs().maxCoeff() < 1e-15);
    REQUIRE(dx.tail<4>() == fd(q, eta, torque(0.3)));
  }
  // Energy check: E(T) − E(0) = W(T) = ∫ ηᵀτ dt (the constraint does no work); W rides
  // along in the RK4 state, E comes from the independent model. RK4's error in this
  // identity must shrink as h⁴: halving h divides it by ≈ 16.
  const auto energy = [&](const V5& qq, const V4& ee) {
    const Vec qv = qq, qd = S_hand(qv) * Vec(ee);
    const el_terms t = el_compute<5>(ref, qv, Vec::Zero(5));
    return 0.5 * qd.dot(t.M * qd) + el_potential(ref, qv);
  };
  struct result {
    double max_Aqd = 0, max_slip = 0, work = 0, work_err = 0, eta_norm = 0;
  };
  const auto simulate = [&](double h) {
    V5 q(-0.23710299623923958, 1.0, std::numbers::pi, 2.058145585963254, 1.2);
    V4 eta = V4::Zero();
    result res;
    const double E0 = energy(q, eta);
    const int steps = int(std::lround(3.0 / h));
    for (int step = 0; step < steps; ++step) {
      const double t = step * h;
      const auto [k1q, k1e] = f(t, q, eta);
      const V4 e2 = eta + h / 2 * k1e;
      const auto [k2q, k2e] = f(t + h / 2, V5(q + h / 2 * k1q), e2);
      const V4 e3 = eta + h / 2 * k2e;
      const auto [k3q, k3e] = f(t + h / 2, V5(q + h / 2 * k2q), e3);
      const V4 e4 = eta + h * k3e;
      const auto [k4q, k4e] = f(t + h, V5(q + h * k3q), e4);
      res.work += h / 6 * (eta.dot(torque(t)) + 2 * e2.dot(torque(t + h / 2)) + 2 * e3.dot(torque(t + h / 2)) +
                           e4.dot(torque(t + h)));
      q += h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q);
      eta += h / 6 * (k1e + 2 * k2e + 2 * k3e + k4e);
      const V5 qd = nhdyn::apply_S(r.constraint, q, eta);
      res.max_Aqd = std::max(res.max_Aqd, std::abs((r.constraint.A(q) * qd)(0)) / std::max(1.0, qd.norm()));
      // No lateral slip in the kinematics: velocity of the base point (frame 2's origin) along z₃.
      const Eigen::Vector3d vb = (kin.jacobian(q, 2) * qd).head<3>();
      const Eigen::Vector3d z3 = kin.frame(q, 3).R.col(2);
      res.max_slip = std::max(res.max_slip, std::abs(vb.dot(z3)));
    }
    res.work_err = std::abs((energy(q, eta) - E0) - res.work);
    res.eta_norm = eta.norm();
    return res;
  };
  const result coarse = simulate(2e-3), mid = simulate(1e-3), fine = simulate(5e-4);
  const double max_Aqd = std::max(coarse.max_Aqd, fine.max_Aqd), max_slip = std::max(coarse.max_slip, fine.max_slip);
  REQUIRE(max_Aqd < 1e-15);
  REQUIRE(max_slip < 1e-14);
  REQUIRE(fine.eta_norm > 0.1);  // it did move
  REQUIRE(fine.work_err < 1e-7 * std::max(1.0, std::abs(fine.work)));
  // Fourth order: ≈ 16 per halving (measured ≈ 10 from 2 ms to 1 ms, not yet asymptotic);
  // a second-order or inconsistent scheme would give ≤ 4.
  REQUIRE(coarse.work_err / mid.work_err > 8.0);
  REQUIRE(mid.work_err / fine.work_err > 8.0);
  const double max_work_err = fine.work_err;
  report("simulation 3 s: max |A q_dot| / |q_dot|", max_Aqd);
  report("simulation 3 s: max lateral slip |v_o2 . z3| (m/s)", max_slip);
  report("simulation 3 s: |E(T) - E(0) - int eta^T tau dt| (J)", max_work_err);
  std::printf("[measured] simulation 3 s: work done %.6f J, final |eta| %.4f, energy error h=2ms %.3e, h=1ms %.3e, h=0.5ms %.3e\n",
              fine.work, fine.eta_norm, coarse.work_err, mid.work_err, fine.work_err);
}
