/// The terms a computation includes (dynamics/terms.hpp), against independent references:
/// - names: parsing, every subset written and read back, errors naming the culprit;
/// - armature off: M(q) loses exactly diag(G²J_m) (Corke's published drive parameters, typed
///   here), rne loses G²J_m q̈;
/// - friction in the forward dynamics: fd.with(friction) inverts rne + friction (holonomic, by
///   CRBA + LDLᵀ and by ABA; constrained, project ∘ (rne + friction) ∘ lift on a chain and a
///   tree); the power the friction takes is q̇ᵀτ_f ≥ 0 (a physics invariant: τ = 0 and no
///   gravity: the energy falls by exactly it, checked against M's kinetic energy by central
///   differences along the motion);
/// - bounds with friction enclose point values; the linearisation with friction equals central
///   differences of the forward dynamics.
#include <catch2/catch.hpp>

#include <nhdyn/analysis/bounds.hpp>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>

#include "reference/random_tree.hpp"

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
VectorXd rand_vec(std::mt19937_64& g, int n, double s = 1) {
  std::uniform_real_distribution<double> u(-s, s);
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = u(g);
  return v;
}
/// paper5 with friction on every joint (viscous and asymmetric Coulomb).
chain<double> paper5_with_friction() {
  const auto r = presets::paper5<double>();
  auto links = r.chain.links();
  std::vector<nhdyn::link<double>> L(links.begin(), links.end());
  for (std::size_t i = 0; i < L.size(); ++i) L[i].friction = {0.3 + 0.1 * double(i), 0.2, -0.15};
  return chain<double>(L, r.chain.gravity(), "paper5_friction");
}
}  // namespace

TEST_CASE("terms: names parse in any order, every subset reads back, errors name the entry", "[terms]") {
  CHECK(terms{} == terms::parse("gravity,velocity,armature"));
  CHECK(terms::parse("all") == terms{true, true, true, true});
  CHECK(terms::parse(" none ") == terms{false, false, false, false});
  CHECK(terms::parse("friction , gravity") == terms{true, false, false, true});
  for (int mask = 0; mask < 16; ++mask) {
    const terms t{bool(mask & 1), bool(mask & 2), bool(mask & 4), bool(mask & 8)};
    CHECK(terms::parse(t.list()) == t);
  }
  CHECK(terms{}.list() == "gravity,velocity,armature");
  CHECK(terms{false, false, false, false}.list() == "none");
  const auto error_of = [](const std::string& s) {
    try {
      (void)terms::parse(s);
    } catch (const input_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(error_of("gravity,coriolis").find("no term named 'coriolis'") != std::string::npos);
  CHECK(error_of("gravity,coriolis").find("gravity, velocity, armature, friction") != std::string::npos);
  CHECK(error_of("gravity,,friction").find("an empty entry") != std::string::npos);
  CHECK(error_of("").find("an empty entry") != std::string::npos);
  CHECK(error_of("velocity,velocity").find("'velocity' is named twice") != std::string::npos);
  CHECK(error_of("all,friction").find("no term named 'all'") != std::string::npos);
}

TEST_CASE("terms: without armature, M and rne lose exactly G²J_m (Corke's drive parameters)", "[terms]") {
  const auto p = presets::puma560_motors();
  const double Jm[6] = {200e-6, 200e-6, 200e-6, 33e-6, 33e-6, 33e-6};
  const double G[6] = {-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686};
  VectorXd Ia(6);
  for (int i = 0; i < 6; ++i) Ia(i) = G[i] * G[i] * Jm[i];
  std::mt19937_64 g(3);
  for (int k = 0; k < 5; ++k) {
    const VectorXd q = rand_vec(g, 6, 3), qd = rand_vec(g, 6), qdd = rand_vec(g, 6);
    const auto bare = without_armature(p);
    const MatrixXd dM = mass_matrix(p)(q) - mass_matrix(bare)(q);
    CHECK((dM - MatrixXd(Ia.asDiagonal())).cwiseAbs().maxCoeff() <= 1e-13);
    CHECK((rne(p)(q, qd, qdd) - rne(bare)(q, qd, qdd) - Ia.cwiseProduct(qdd)).cwiseAbs().maxCoeff() <= 1e-12);
    CHECK(mass_matrix(with_terms(p, terms{}))(q) == mass_matrix(p)(q));
    CHECK(mass_matrix(with_terms(p, terms::parse("gravity")))(q) == mass_matrix(bare)(q));
    // a tree: the same numbers, frames and names kept
    const auto t = as_tree(p), tb = without_armature(t);
    CHECK(tb.joint_names() == t.joint_names());
    CHECK((mass_matrix(t)(q) - mass_matrix(tb)(q) - MatrixXd(Ia.asDiagonal())).cwiseAbs().maxCoeff() <= 1e-13);
  }
}

TEST_CASE("terms: forward dynamics with friction inverts rne + friction, holonomic and constrained", "[terms]") {
  std::mt19937_64 g(11);
  SECTION("holonomic: a chain and random trees, CRBA + LDLT and ABA, exact and smooth Coulomb") {
    const auto p = presets::puma560_motors();
    for (const auto law : {coulomb_law::exact(), coulomb_law::smooth(0.05)}) {
      for (const auto method : {fd_method::crba_ldlt, fd_method::aba}) {
        const auto fr = friction(p, law);
        const auto fd = forward_dynamics(p, {}, {method}).with(fr);
        const auto id = rne(p) + fr;
        for (int k = 0; k < 5; ++k) {
          const VectorXd q = rand_vec(g, 6, 3), qd = rand_vec(g, 6), qdd = rand_vec(g, 6);
          CHECK((fd(q, qd, id(q, qd, qdd)) - qdd).cwiseAbs().maxCoeff() <= 1e-9);
          // and the friction is what makes the difference
          CHECK((forward_dynamics(p, {}, {method})(q, qd, id(q, qd, qdd)) - qdd).cwiseAbs().maxCoeff() > 1e-3);
        }
      }
    }
    for (int n : {7, 15}) {
      auto t = nhdyn_ref::random_tree(g, n);
      std::vector<body<double>> B(t.bodies());
      for (auto& b : B) b.set_friction_law({0.2, 0.1, -0.1});
      const tree<double> tf(B, t.gravity(), "friction_tree");
      const auto fr = friction(tf);
      for (const auto method : {fd_method::crba_ldlt, fd_method::aba}) {
        const VectorXd q = rand_vec(g, n, 3), qd = rand_vec(g, n), qdd = rand_vec(g, n);
        CHECK((forward_dynamics(tf, {}, {method}).with(fr)(q, qd, (rne(tf) + fr)(q, qd, qdd)) - qdd).cwiseAbs().maxCoeff() <= 1e-8);
      }
    }
  }
  SECTION("constrained: paper5 (a chain) and the same as a tree") {
    const auto ch = paper5_with_friction();
    const auto c = presets::paper5<double>().constraint;
    const auto fr = friction(ch);
    const auto id = inverse_dynamics(ch, c, {}, fr);
    const auto fd = nh_forward_dynamics(ch, c).with(fr);
    const auto t = as_tree(ch);
    const auto id_t = inverse_dynamics_with_forces(t, c, {}, friction(t));
    const auto fd_t = nh_forward_dynamics(t, c).with(friction(t));
    for (int k = 0; k < 10; ++k) {
      const VectorXd q = rand_vec(g, 5, 2), eta = rand_vec(g, 4), eta_dot = rand_vec(g, 4);
      const VectorXd tau = id(q, eta, eta_dot);
      CHECK((fd(q, eta, tau) - eta_dot).cwiseAbs().maxCoeff() <= 1e-10);
      CHECK((fd_t(q, eta, tau) - eta_dot).cwiseAbs().maxCoeff() <= 1e-10);
      CHECK((VectorXd(id_t(q, eta, eta_dot).tau) - tau).cwiseAbs().maxCoeff() <= 1e-10);
      nh_forward_dynamics_result<double, dynamic, 4> into;  // evaluate adds τ_f in place: the call's numbers
      fd_t.evaluate(q, eta, tau, into);
      CHECK((into.eta_dot.array() == fd_t(q, eta, tau).array()).all());
      const VectorXd w = rand_vec(g, 5);
      VectorXd v = rand_vec(g, 5);
      const VectorXd sum = v + fr(w);
      fr.add_to(w, v);
      CHECK((v.array() == sum.array()).all());
      // with friction the torques differ from the frictionless ones by the projected
      // friction: (SᵀE)⁻¹Sᵀ τ_f(Sη), E = S here
      const MatrixXd S = c.S(q);
      const VectorXd tf = fr(S * eta);
      const VectorXd expected = (S.transpose() * S).ldlt().solve(S.transpose() * tf);
      CHECK((tau - VectorXd(inverse_dynamics(ch, c)(q, eta, eta_dot)) - expected).cwiseAbs().maxCoeff() <= 1e-10);
    }
  }
  SECTION("friction only takes energy: no gravity, τ = 0, dE/dt = −q̇ᵀτ_f(q̇) ≤ 0") {
    const auto p = presets::puma560_motors();
    const auto fr = friction(p);
    const auto fd = forward_dynamics(p, {.gravity = false, .velocity = true}).with(fr);
    const auto M = mass_matrix(p);
    for (int k = 0; k < 5; ++k) {
      const VectorXd q = rand_vec(g, 6, 3), qd = rand_vec(g, 6);
      const VectorXd qdd = fd(q, qd, VectorXd::Zero(6));
      // E(s) = ½ q̇(s)ᵀ M(q(s)) q̇(s) along q(s) = q + s q̇, q̇(s) = q̇ + s q̈: dE/ds at 0
      const double h = 1e-6;
      const auto E = [&](double s) {
        const VectorXd v = qd + s * qdd;
        return 0.5 * v.dot(M(VectorXd(q + s * qd)) * v);
      };
      const double dE = (E(h) - E(-h)) / (2 * h);
      const double power = -qd.dot(fr(qd));
      CHECK(power < 0);
      CHECK(std::abs(dE - power) <= 1e-6 * (1 + std::abs(power)));
    }
  }
}

TEST_CASE("terms: bounds and linearisations with friction", "[terms]") {
  std::mt19937_64 g(23);
  const auto ch = paper5_with_friction();
  const auto c = presets::paper5<double>().constraint;
  const auto fr = friction(ch, coulomb_law::smooth(0.05));
  const VectorXd q = rand_vec(g, 5, 1), eta = rand_vec(g, 4), eta_dot = rand_vec(g, 4);
  SECTION("torque_bounds with friction enclose id at points of the box, and differ from those without") {
    const double w = 1e-3;
    box<dynamic> Q(5), H(4), HD(4);
    for (int i = 0; i < 5; ++i) Q(i) = interval(q(i) - w, q(i) + w);
    for (int i = 0; i < 4; ++i) {
      H(i) = interval(eta(i) - w, eta(i) + w);
      HD(i) = interval(eta_dot(i) - w, eta_dot(i) + w);
    }
    const chain<double> dyn = ch;
    const auto T = torque_bounds(dyn, c, Q, H, HD, 0, {}, fr);
    const auto T0 = torque_bounds(dyn, c, Q, H, HD, 0, {});
    const auto id = inverse_dynamics(ch, c, {}, fr);
    for (int k = 0; k < 20; ++k) {
      const VectorXd dq = rand_vec(g, 5, w), de = rand_vec(g, 4, w), dd = rand_vec(g, 4, w);
      const VectorXd tau = id(VectorXd(q + dq), VectorXd(eta + de), VectorXd(eta_dot + dd));
      for (int i = 0; i < 4; ++i) CHECK((T(i).lower() <= tau(i) && tau(i) <= T(i).upper()));
    }
    bool differs = false;
    for (int i = 0; i < 4; ++i) differs = differs || T(i).lower() > T0(i).upper() || T(i).upper() < T0(i).lower();
    CHECK(differs);
  }
  SECTION("linearize_forward_dynamics with friction = central differences of fd.with(friction)") {
    const auto fd = nh_forward_dynamics(ch, c).with(fr);
    const VectorXd tau = inverse_dynamics(ch, c, {}, fr)(q, eta, eta_dot);
    const auto ss = linearize_forward_dynamics(ch, c, q, eta, tau, {}, fr);
    VectorXd z(13);
    z << q, eta, tau;
    const auto f = [&](const VectorXd& x) {
      VectorXd out(9);
      out << c.S(VectorXd(x.head(5))) * x.segment(5, 4), fd(VectorXd(x.head(5)), VectorXd(x.segment(5, 4)), VectorXd(x.tail(4)));
      return out;
    };
    const MatrixXd J = central_difference_jacobian(f, z, 1e-6);
    CHECK((MatrixXd(ss.A) - J.leftCols(9)).cwiseAbs().maxCoeff() <= 1e-6);
    CHECK((MatrixXd(ss.B) - J.rightCols(4)).cwiseAbs().maxCoeff() <= 1e-6);
    // holonomic
    const auto p = presets::puma560_motors();
    const auto pf = friction(p, coulomb_law::smooth(0.05));
    const VectorXd qp = rand_vec(g, 6, 2), qdp = rand_vec(g, 6), taup = rand_vec(g, 6, 5);
    const auto hs = linearize_forward_dynamics(p, qp, qdp, taup, {}, pf);
    const auto fdp = forward_dynamics(p).with(pf);
    VectorXd zp(18);
    zp << qp, qdp, taup;
    const MatrixXd Jp = central_difference_jacobian(
        [&](const VectorXd& x) {
          VectorXd out(12);
          out << x.segment(6, 6), fdp(VectorXd(x.head(6)), VectorXd(x.segment(6, 6)), VectorXd(x.tail(6)));
          return out;
        },
        zp, 1e-6);
    CHECK((MatrixXd(hs.A) - Jp.leftCols(12)).cwiseAbs().maxCoeff() <= 1e-5 * (1 + Jp.cwiseAbs().maxCoeff()));
    CHECK((MatrixXd(hs.B) - Jp.rightCols(6)).cwiseAbs().maxCoeff() <= 1e-5 * (1 + Jp.cwiseAbs().maxCoeff()));
  }
}
