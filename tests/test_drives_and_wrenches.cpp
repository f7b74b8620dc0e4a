/// Rotor inertia (armature), friction stages and external wrenches (issue 15, items 1–2),
/// against independent references:
/// - Corke's Robotics Toolbox: its published tests' rne, inertia, itorque, accel and friction
///   values for the Puma 560 with its drives (robotics-toolbox-python tests/test_DHRobot.py,
///   computed by its own rne with G²J_m, G²B, |G|Tc and fext; checked to their printed digits);
/// - the textbook RNEA with external forces in body coordinates (RBDA Table 5.1,
///   reference::rne), a second algorithm to the Jacobian-transpose route of dynamics/wrench.hpp;
/// - power: τᵀq̇ = dE/dt + Σ I_a q̇ q̈ − (f·v_p + m·ω), with E and v_p, ω from the Euler–Lagrange
///   reference in long double (tests/reference/lagrangian.hpp: no library code);
/// - the tree, chain, reference and ABA paths against each other, with armature.
#include <catch2/catch.hpp>

#include <nhdyn/dynamics/aba.hpp>
#include <nhdyn/dynamics/friction.hpp>
#include <nhdyn/dynamics/reference.hpp>
#include <nhdyn/dynamics/wrench.hpp>
#include <nhdyn/io/json.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/scalar/dual.hpp>
#include <nhdyn/scalar/interval.hpp>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "reference/lagrangian.hpp"
#include "reference/random_tree.hpp"

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;
using LD = long double;

namespace {
constexpr double pi = 3.14159265358979323846;

VectorXd vec(std::initializer_list<double> x) {
  VectorXd v(static_cast<Eigen::Index>(x.size()));
  Eigen::Index i = 0;
  for (double e : x) v(i++) = e;
  return v;
}
VectorXd random_vec(std::mt19937_64& rng, int n, double r) {
  return VectorXd::NullaryExpr(n, [&] { return nhdyn_ref::uniform(rng, -r, r); });
}
double rel(const VectorXd& a, const VectorXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / std::max(1.0, b.lpNorm<Eigen::Infinity>());
}

/// `ours` rounds to the printed value: |ours − printed| ≤ half a unit in its last printed digit.
void printed(const VectorXd& ours, const std::vector<std::string>& text) {
  REQUIRE(ours.size() == Eigen::Index(text.size()));
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto dot = text[i].find('.');
    const int decimals = dot == std::string::npos ? 0 : int(text[i].size() - dot - 1);
    const double half_unit = 0.5 * std::pow(10.0, -decimals) * (1 + 1e-9);
    INFO("entry " << i + 1 << ": ours " << ours(Eigen::Index(i)) << ", published " << text[i]);
    CHECK(std::abs(ours(Eigen::Index(i)) - std::stod(text[i])) <= half_unit);
  }
}

/// Random armature and friction on every joint of a tree.
tree<double> with_drives(const tree<double>& t, std::mt19937_64& rng) {
  std::vector<body<double>> B(t.begin(), t.end());
  for (auto& b : B) {
    b.armature = nhdyn_ref::uniform(rng, 0.0, 2.0);
    b.damping = nhdyn_ref::uniform(rng, 0.0, 1.0);
    b.friction = nhdyn_ref::uniform(rng, 0.0, 1.0);
  }
  return tree<double>(std::move(B), t.gravity(), t.name());
}
}  // namespace

TEST_CASE("puma560_motors reproduces the Robotics Toolbox's published rne, inertia and accel at qn", "[drives]") {
  // robotics-toolbox-python tests/test_DHRobot.py (test_rne, test_inertia, test_itorque,
  // test_accel): qn = (0, π/4, π, 0, π/4, 0); its rne adds G²J_m q̈ + G²B q̇ + |G|Tc(sign q̇).
  const auto p = presets::puma560_motors();
  const VectorXd qn = vec({0, pi / 4, pi, 0, pi / 4, 0}), z = VectorXd::Zero(6), o = VectorXd::Ones(6);
  const auto id = rne(p) + friction(p);  // the toolbox's rne: rigid body + armature + friction
  printed(id(qn, z, z), {"-0.0000", "31.6399", "6.0351", "0.0000", "0.0283", "0"});
  printed(id(qn, z, o), {"3.35311", "36.0025", "7.42596", "0.190043", "0.203441", "0.194133"});
  printed(id(qn, o, o), {"32.4952", "60.867", "17.7436", "1.45452", "1.29911", "0.713781"});
  printed(id(qn, o, z), {"29.1421", "56.5044", "16.3528", "1.26448", "1.12392", "0.519648"});
  const auto no_g = rne(p, {.gravity = false, .velocity = true}) + friction(p);
  printed(no_g(qn, o, o), {"32.4952", "29.2271", "11.7085", "1.45452", "1.27086", "0.713781"});
  // fext = [1, 2, 3, 1, 2, 3]: the toolbox's fext is what the end effector exerts, in frame 6
  // about its origin; nhdyn's wrench acts on the body, so the wrench on link 6 is −fext.
  wrench<double> w;
  w.body = 6;
  w.frame = wrench_frame::body;
  w.force = -Vector3d(1, 2, 3);
  w.moment = -Vector3d(1, 2, 3);
  const auto fext = external_wrenches(p, {w});
  printed(rne(p)(qn, z, z, fext), {"0.642756", "29.0866", "4.70321", "2.82843", "-1.97175", "3"});
  VectorXd v(6);
  rne(p).evaluate(qn, z, z, fext, v);  // into storage: the same numbers
  CHECK((v.array() == rne(p)(qn, z, z, fext).array()).all());
  // inertia: M(qn)'s diagonal (armature included), and M q̈ (test_itorque)
  const MatrixXd M = mass_matrix(p)(qn);
  printed(M.diagonal(), {"3.6594", "4.4137", "0.9378", "0.1925", "0.1713", "0.1941"});
  printed(M * vec({1, 2, 3, 1, 2, 3}), {"3.1500", "9.4805", "3.6189", "0.1901", "0.3519", "0.5823"});
  // accel: q̈ = M⁻¹(τ − rne(q, q̇, 0)) with the toolbox's rne (friction included): here the
  // friction moves to τ's side, and both forward dynamics answer it
  const VectorXd qd = vec({0.1, 0.2, 0.8, 0.2, 0.5, 1.0}), tau = vec({1.0, 3.2, 1.8, 0.1, 0.7, 4.6});
  const VectorXd t_net = tau - friction(p)(qd);
  const std::vector<std::string> accel{"-7.4102", "-9.8432", "-10.9694", "-4.4314", "-0.9881", "21.0228"};
  printed(forward_dynamics(p)(qn, qd, t_net), accel);
  printed(aba(as_tree(p))(qn, qd, t_net), accel);
  // without the drives (the rigid-body preset) the numbers are not the toolbox's
  CHECK(std::abs(rne(presets::puma560())(qn, z, o)(0) - 3.35311) > 0.5);
}

TEST_CASE("drives from model files: motor side and joint side, and the toolbox's friction example", "[drives]") {
  // robotics-toolbox-python test_friction: RevoluteDH(B=3, G=2, Tc=[2, -1]),
  // friction([1, 2, 3, 4]) = [-16, -28, -40, -52] (the toolbox returns the force opposing the
  // motion; nhdyn's stage, what the drive adds: +16, +28, …).
  const std::string link = R"({"joint": "revolute", "alpha": 0, "a": 1, "theta": 0, "d": 0, "mass": 1,
      "com": [0, 0, 0], "inertia": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], )";
  const auto load_drive = [&](const std::string& drive) {
    return io::parse_model<double>(R"({"name": "one", "gravity": [0, 0, -9.81], "links": [)" + link + drive + "}]}",
                                   "drive.json");
  };
  const auto m = load_drive(R"("motor": {"inertia": 0.5, "gear": 2, "viscous": 3, "coulomb": [2, -1]})");
  CHECK(m.chain[0].armature == 2.0);  // G² J_m
  CHECK(m.chain[0].friction == joint_friction{12, 4, -2});
  const auto f = friction(m.chain);
  for (double v : {1.0, 2.0, 3.0, 4.0}) CHECK(f(vec({v}))(0) == 4 + 12 * v);
  CHECK(f(vec({-1}))(0) == -2 - 12);
  // joint side, symmetric Coulomb; saved and loaded back the same
  const auto j = load_drive(R"("armature": 0.25, "friction": {"viscous": 0.5, "coulomb": 0.1})");
  CHECK(j.chain[0].armature == 0.25);
  CHECK(j.chain[0].friction == joint_friction{0.5, 0.1, -0.1});
  const auto back = io::parse_model<double>(io::to_string(m), "saved.json");
  CHECK(back.chain[0].armature == m.chain[0].armature);
  CHECK(back.chain[0].friction == m.chain[0].friction);
  // errors name the link and the field
  CHECK_THROWS_WITH(load_drive(R"("armature": -1)"), Catch::Contains("link 1") && Catch::Contains("armature"));
  CHECK_THROWS_WITH(load_drive(R"("friction": {"viscous": -1})"),
                    Catch::Contains("friction") && Catch::Contains("oppose motion"));
  CHECK_THROWS_WITH(load_drive(R"("friction": {"coulomb": [1, 2]})"), Catch::Contains("negative speed"));
  CHECK_THROWS_WITH(load_drive(R"("motor": {"gear": 0})"), Catch::Contains("gear"));
  CHECK_THROWS_WITH(load_drive(R"("motor": {"inertia": 1})"), Catch::Contains("'gear'") && Catch::Contains("missing"));
  CHECK_THROWS_WITH(load_drive(R"("armature": 1, "motor": {"gear": 2})"), Catch::Contains("not both"));
  CHECK_THROWS_WITH(load_drive(R"("friction": {"stiction": 1})"), Catch::Contains("stiction"));
  CHECK(io::load("puma560_motors").chain[2].armature == presets::puma560_motors()[2].armature);
}

TEST_CASE("armature: chain, tree, reference and ABA agree, and the power balance holds", "[drives]") {
  std::mt19937_64 rng(1515);
  for (int n : {1, 3, 7, 12}) {
    for (int trial = 0; trial < 3; ++trial) {
      const auto t = with_drives(nhdyn_ref::random_tree(rng, n, 0.4, trial % 2 == 0), rng);
      const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), qdd = random_vec(rng, n, 3);
      INFO("n = " << n << ", trial " << trial);
      const VectorXd tau = rne(t)(q, qd, qdd);
      CHECK(rel(tau, reference::rne<double>(t, q, qd, qdd)) <= 1e-12);
      const MatrixXd M = mass_matrix(t)(q);
      CHECK((M - reference::crba<double>(t, q)).cwiseAbs().maxCoeff() <= 1e-12 * (1 + M.norm()));
      CHECK(rel(aba(t)(q, qd, tau), qdd) <= 1e-10);
      CHECK(rel(forward_dynamics(t)(q, qd, tau), qdd) <= 1e-10);
      // power: τᵀq̇ = dE/dt of the rigid bodies + the rotors' Σ I_a q̇ q̈ (Euler–Lagrange, long double)
      const auto ref = nhdyn_ref::from_tree<LD>(t);
      LD dE = nhdyn_ref::energy_rate<LD>(ref, q.cast<LD>(), qd.cast<LD>(), qdd.cast<LD>());
      for (int i = 0; i < n; ++i) dE += LD(t[i].armature) * qd(i) * qdd(i);
      CHECK(std::abs(double(dE) - tau.dot(qd)) <= 1e-11 * (1 + std::abs(double(dE))));
    }
  }
  // chains: the DH kernel (and its in-place pipeline form) against the tree kernel
  for (int trial = 0; trial < 5; ++trial) {
    auto base = presets::puma560_motors();
    const auto t = as_tree(base);
    const VectorXd q = random_vec(rng, 6, 3), qd = random_vec(rng, 6, 2), qdd = random_vec(rng, 6, 3);
    const Eigen::Matrix<double, 6, 1> qN = q, qdN = qd, qddN = qdd;
    const VectorXd a = rne(base)(qN, qdN, qddN);
    CHECK(rel(a, rne(t)(q, qd, qdd)) <= 1e-12);
    const auto v = rne(base)(joint_state<double, 6>{qN, qdN, qddN});  // v written over q̈'s storage
    CHECK(rel(VectorXd(v.v), a) == 0.0);
    CHECK((MatrixXd(mass_matrix(base)(qN)) - mass_matrix(t)(q)).cwiseAbs().maxCoeff() <= 1e-12);
  }
}

TEST_CASE("armature in the paper's method: the fused chain path = the tree pipeline, fd inverts id", "[drives]") {
  // paper5 with rotors on its arm joints and on the heading: the chain's fused inverse dynamics
  // and the run-time-sized tree pipeline are different code; both must carry the armature.
  std::array<nhdyn::link<double>, 5> L;
  const auto p5 = presets::paper5_chain();
  for (int i = 0; i < 5; ++i) L[std::size_t(i)] = p5[i];
  L[2].armature = 0.7;
  L[3].armature = 0.05;
  L[4].armature = 0.02;
  const chain<double, 5> ch(L, p5.gravity(), "paper5 with rotors");
  const auto c = presets::paper5_constraint();
  const auto t = as_tree(ch);
  const differential_drive<double> cd(5, 0, 1, 2, 0.0, -1.0);
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 10; ++trial) {
    const VectorXd q = random_vec(rng, 5, 2), eta = random_vec(rng, 4, 1), eta_dot = random_vec(rng, 4, 2);
    const Eigen::Matrix<double, 5, 1> qN = q;
    const Eigen::Vector4d e = eta, ed = eta_dot;
    const VectorXd a = inverse_dynamics(ch, c)(qN, e, ed);
    const VectorXd b = inverse_dynamics(t, cd)(q, eta, eta_dot);
    CHECK(rel(a, b) <= 1e-12);
    // the rotor term alone: Sᵀ diag(I_a) (S η̇ + Ṡ η) projected, is what the armature adds
    const VectorXd a0 = inverse_dynamics(p5, c)(qN, e, ed);
    CHECK(rel(a, a0) > 1e-6);
    CHECK(rel(VectorXd(nh_forward_dynamics(ch, c)(qN, e, Eigen::Vector4d(a))), eta_dot) <= 1e-10);
  }
}

TEST_CASE("friction stages: exact and smooth Coulomb laws, duals, intervals, in a pipeline", "[drives]") {
  const auto f = coulomb_friction(vec({2, 0.5}), vec({-1, -0.5}));
  CHECK(f(vec({0.3, -2}))(0) == 2);
  CHECK(f(vec({0.3, -2}))(1) == -0.5);
  CHECK(f(vec({0, 0})).isZero());
  // duals: the exact law has derivative 0 (at q̇ = 0 none exists; 0 is returned)
  using D = dual<double, 1>;
  Eigen::Matrix<D, Eigen::Dynamic, 1> x(2);
  x << D(0.0, {1.0}), D(-1.0, {1.0});
  CHECK(f(x)(0).derivative(0) == 0);
  // smooth: 0 at rest, slope c⁺/v_s there, near the exact law far from it
  const auto s = f.with(coulomb_law::smooth(0.01));
  CHECK(s(x)(0).value() == 0);
  CHECK(s(x)(0).derivative(0) == Approx(2 / 0.01));
  CHECK(s(vec({1.0, -1.0}))(0) == Approx(2).epsilon(1e-4));
  CHECK(s(vec({1.0, -1.0}))(1) == Approx(-0.5).epsilon(1e-4));
  CHECK_THROWS_WITH(coulomb_law::smooth(0), Catch::Contains("velocity scale"));
  // intervals: every value the law takes on the box is enclosed
  Eigen::Matrix<interval, Eigen::Dynamic, 1> I(2);
  I << interval(-0.1, 0.2), interval(0.0, 0.3);
  const auto fi = f(I);
  const auto tight = [](const interval& y, double lo, double hi) {  // encloses [lo, hi], outward rounding only
    return y.lower() <= lo && y.lower() >= lo - 1e-15 && y.upper() >= hi && y.upper() <= hi + 1e-15;
  };
  CHECK(tight(fi(0), -1, 2));
  CHECK(tight(fi(1), 0, 0.5));
  const auto si = s(I);
  for (double v = -0.1; v <= 0.2; v += 0.01) {
    const double y = s(vec({v, 0}))(0);
    CHECK((si(0).lower() <= y && y <= si(0).upper()));
  }
  // in the pipeline: lift | (rne + friction) | project = project(rne(lift) + friction(S η))
  const auto p = presets::paper5();
  std::vector<joint_friction> laws(5, joint_friction{0.3, 0.2, -0.1});
  const friction_fn fr(laws);
  const auto pipe = lift(p.constraint) | (rne(p.chain) + fr) | project(p.constraint);
  const Eigen::Matrix<double, 5, 1> q = VectorXd::LinSpaced(5, 0.1, 0.9);
  const Eigen::Vector4d eta(0.4, -0.3, 0.2, 0.1), eta_dot(0.1, 0.2, -0.3, 0.4);
  const auto xi = lift(p.constraint)(q, eta, eta_dot);
  const VectorXd v = VectorXd(rne(p.chain)(xi.q, xi.qd, xi.qdd)) + fr(xi.qd);
  CHECK(rel(VectorXd(pipe(reduced_state<double, 5, 4>{q, eta, eta_dot})), VectorXd(project(p.constraint)(xi.q, v))) <= 1e-15);
  CHECK_THROWS_WITH(friction_fn({joint_friction{-1, 0, 0}}), Catch::Contains("joint 0") && Catch::Contains("viscous"));
  CHECK_THROWS_WITH(fr(VectorXd::Zero(4)), Catch::Contains("qd"));
}

TEST_CASE("external wrenches: the textbook RNEA with body forces, KDL-free Jacobian check, power, fd", "[wrench]") {
  std::mt19937_64 rng(1501);
  for (int n : {1, 2, 5, 9, 16}) {
    for (int trial = 0; trial < 3; ++trial) {
      const auto t = with_drives(nhdyn_ref::random_tree(rng, n, 0.4, trial % 2 == 1), rng);
      const tree_kinematics<double> kin(t);
      std::vector<wrench<double>> W;
      for (int k = 0; k < 3; ++k) {
        wrench<double> w;
        w.body = std::uniform_int_distribution<int>(0, n)(rng);
        w.frame = k % 2 ? wrench_frame::body : wrench_frame::world;
        w.point = nhdyn_ref::random_vector(rng, 0.5);
        w.force = nhdyn_ref::random_vector(rng, 10);
        w.moment = nhdyn_ref::random_vector(rng, 3);
        W.push_back(w);
      }
      const auto fx = external_wrenches(t, W);
      const VectorXd q = random_vec(rng, n, 2), qd = random_vec(rng, n, 2), qdd = random_vec(rng, n, 3);
      INFO("n = " << n << ", trial " << trial);
      const VectorXd tau = rne(t)(q, qd, qdd, fx);
      // (1) RBDA Table 5.1 with f^x in body coordinates, moment about the body frame's origin
      std::vector<spatial::vec6<double>> fb(std::size_t(n), spatial::vec6<double>::Zero());
      for (const auto& w : W) {
        if (w.body == 0) continue;
        const auto X = kin.frame(q, w.body);
        const Vector3d f = w.frame == wrench_frame::world ? Vector3d(X.R.transpose() * w.force) : w.force;
        const Vector3d m = w.frame == wrench_frame::world ? Vector3d(X.R.transpose() * w.moment) : w.moment;
        fb[std::size_t(w.body - 1)].head<3>() += m + w.point.cross(f);
        fb[std::size_t(w.body - 1)].tail<3>() += f;
      }
      CHECK(rel(tau, reference::rne<double>(t, q, qd, qdd, true, &fb)) <= 1e-12);
      // (2) power: τᵀq̇ = dE/dt + Σ I_a q̇ q̈ − Σ (f·v_p + m·ω), velocities by the E–L reference
      const auto ref = nhdyn_ref::from_tree<LD>(t);
      LD dE = nhdyn_ref::energy_rate<LD>(ref, q.cast<LD>(), qd.cast<LD>(), qdd.cast<LD>());
      for (int i = 0; i < n; ++i) dE += LD(t[i].armature) * qd(i) * qdd(i);
      const auto tw = nhdyn_ref::twists<LD>(ref, q.cast<LD>(), qd.cast<LD>());
      LD P = 0;
      for (const auto& w : W) {
        if (w.body == 0) continue;
        using DL = dual<LD, 1>;
        nhdyn_ref::vec<DL> qe(n);
        for (int j = 0; j < n; ++j) qe(j) = DL(LD(q(j)), {LD(qd(j))});
        const auto pe = nhdyn_ref::point<DL>(ref, qe, w.body, w.point.cast<LD>().eval());
        const auto R = nhdyn_ref::rotation<LD>(nhdyn_ref::poses<LD>(ref, q.cast<LD>())[std::size_t(w.body)]);
        const Eigen::Matrix<LD, 3, 1> f = w.frame == wrench_frame::world ? w.force.cast<LD>().eval() : (R * w.force.cast<LD>()).eval();
        const Eigen::Matrix<LD, 3, 1> m = w.frame == wrench_frame::world ? w.moment.cast<LD>().eval() : (R * w.moment.cast<LD>()).eval();
        for (int r = 0; r < 3; ++r) P += f(r) * pe(r).derivative(0) + m(r) * tw[std::size_t(w.body - 1)].w(r);
      }
      CHECK(std::abs(double(dE - P) - tau.dot(qd)) <= 1e-11 * (1 + std::abs(double(dE)) + std::abs(double(P))));
      // (3) the forward dynamics with the same wrenches invert it (CRBA and ABA)
      CHECK(rel(forward_dynamics(t)(q, qd, tau, fx), qdd) <= 1e-10);
      CHECK(rel(aba(t)(q, qd, tau, fx), qdd) <= 1e-10);
      // (4) the pipeline stage: (q, v) ↦ (q, v − Q_ext)
      const auto g = fx(generalized_forces<double>{q, rne(t)(q, qd, qdd)});
      CHECK(rel(g.v, tau) <= 1e-15);
      // (5) Q_ext = Σ Jᵀ [f; m] with each wrench's Jacobian (tree_kinematics, one per wrench)
      VectorXd Qj = VectorXd::Zero(n);
      for (const auto& w : W) {
        if (w.body == 0) continue;
        const auto R = kin.frame(q, w.body).R;
        const Vector3d f = w.frame == wrench_frame::body ? Vector3d(R * w.force) : w.force;
        const Vector3d m = w.frame == wrench_frame::body ? Vector3d(R * w.moment) : w.moment;
        const MatrixXd J = kin.jacobian(q, w.body, w.point);
        Qj += J.topRows(3).transpose() * f + J.bottomRows(3).transpose() * m;
      }
      CHECK(rel(fx.generalized_force(q), Qj) <= 1e-14);
      // …and the calls with wrenches are those without at τ + Q_ext (v − Q_ext), Q_ext by hand
      CHECK(rel(forward_dynamics(t)(q, qd, tau, fx), forward_dynamics(t)(q, qd, VectorXd(tau + Qj))) <= 1e-12);
      CHECK(rel(aba(t)(q, qd, tau, fx), aba(t)(q, qd, VectorXd(tau + Qj))) <= 1e-12);
      CHECK(rel(tau, VectorXd(rne(t)(q, qd, qdd) - Qj)) <= 1e-12);
      // (6) the evaluate forms with wrenches: the calls' numbers bit for bit, into reused storage
      VectorXd v = VectorXd::Constant(n, 7.0), a = VectorXd::Constant(n, 7.0), b;
      rne(t).evaluate(q, qd, qdd, fx, v);
      CHECK((v.array() == tau.array()).all());
      aba(t).evaluate(q, qd, tau, fx, a);
      CHECK((a.array() == aba(t)(q, qd, tau, fx).array()).all());
      forward_dynamics_scratch<double, dynamic> ws;
      forward_dynamics(t).evaluate(q, qd, tau, fx, ws, b);
      CHECK((b.array() == forward_dynamics(t)(q, qd, tau, fx).array()).all());
    }
  }
}

TEST_CASE("external wrenches on a mobile manipulator: id, lambda and fd with a payload", "[wrench]") {
  const auto p = presets::paper5();
  const auto t = as_tree(p.chain);
  const differential_drive<double> c(5, 0, 1, 2, 0.0, -1.0);
  // a 0.5 kg payload's weight at the tip of link 5 (0.168 m along x₅), and a push on the platform
  const auto payload = wrench_on(t, "link5", wrench_frame::world, Vector3d(0, 0, 0), Vector3d(-0.5 * 9.81, 0, 0));
  const auto push = wrench_on(t, "link3", wrench_frame::body, Vector3d(0.2, 0, 0), Vector3d(0, 0, 4), Vector3d(0, 1, 0));
  const auto fx = external_wrenches(t, {payload, push});
  const auto id = lift(c) | rne(t) | fx | constraint_forces(c);
  const auto id0 = inverse_dynamics_with_forces(t, c);
  const auto fd = nh_forward_dynamics(t, c);
  nh_forward_dynamics_result<double> into;
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 10; ++trial) {
    const VectorXd q = random_vec(rng, 5, 2), eta = random_vec(rng, 4, 1), eta_dot = random_vec(rng, 4, 2);
    const auto with = id(reduced_state<double>{q, eta, eta_dot});
    const auto without = id0(q, eta, eta_dot);
    // τ and λ: the wrenches' generalized force split by the same projection
    const VectorXd Qx = fx.generalized_force(q);
    const auto split = constraint_forces(c)(q, Qx);
    CHECK(rel(VectorXd(with.tau), VectorXd(without.tau - split.tau)) <= 1e-12);
    CHECK(rel(VectorXd(with.lambda), VectorXd(without.lambda - split.lambda)) <= 1e-12);
    // the constrained forward dynamics with the same wrenches inverts it; evaluate = the call
    const VectorXd back = fd(q, eta, VectorXd(with.tau), fx);
    CHECK(rel(back, eta_dot) <= 1e-10);
    fd.evaluate(q, eta, VectorXd(with.tau), fx, into);
    CHECK((into.eta_dot.array() == back.array()).all());
  }
  // the named forms: a merged frame's name, an unknown name, bad numbers
  CHECK_THROWS_WITH(wrench_on(t, "gripper", wrench_frame::world, Vector3d(0, 0, 0), Vector3d(1, 1, 1)),
                    Catch::Contains("gripper"));
  wrench<double> bad;
  bad.body = 9;
  CHECK_THROWS_WITH(external_wrenches(t, {bad}), Catch::Contains("body index"));
  bad.body = 1;
  bad.force(1) = NAN;
  CHECK_THROWS_WITH(external_wrenches(t, {bad}), Catch::Contains("non-finite"));
}
