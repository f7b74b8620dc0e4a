// Pfaffian constraints: A(q), S(q), Ṡ(q, q̇), E(q), against matrices written out by hand
// (paper5.md), finite differences, and the definitions (A S = 0, no lateral slip).
#include <catch2/catch.hpp>
#include <cstdio>
#include <nhdyn/nhdyn.hpp>
#include <numbers>
#include <random>

namespace {

using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;
template <class T>
using MatT = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;

struct rng {
  std::mt19937 gen{7};
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  Vec vec(int n, double scale = 1.0) {
    Vec v(n);
    for (int i = 0; i < n; ++i) v(i) = scale * u(gen);
    return v;
  }
};

void report(const char* what, double value) { std::printf("[measured] %-70s %.3e\n", what, value); }

/// Ṡ along q̇ by central differences, Richardson-extrapolated (error O(h⁴)).
template <class F>
Mat fd_along(F S, const Vec& q, const Vec& qd) {
  const auto central = [&](double h) { return Mat((S(Vec(q + h * qd)) - S(Vec(q - h * qd))) / (2 * h)); };
  const double h = 1e-3;
  return Mat((4 * central(h / 2) - central(h)) / 3);
}

/// A differential drive written from its definition: ψ = sign·q_h + offset; the base moves
/// along (cos ψ, sin ψ) in the (x, y) joints; η = (v in the place of the first of x, y,
/// then every other joint in order).
struct dd_hand {
  int n, x, y, h;
  double offset, sign;
  double psi(const Vec& q) const { return sign * q(h) + offset; }
  Mat A(const Vec& q) const {
    Mat a = Mat::Zero(1, n);
    a(0, x) = -std::sin(psi(q));
    a(0, y) = std::cos(psi(q));
    return a;
  }
  Mat S(const Vec& q) const {
    Mat s = Mat::Zero(n, n - 1);
    int c = 0;
    for (int j = 0; j < n; ++j) {
      if (j == std::min(x, y)) {
        s(x, c) = std::cos(psi(q));
        s(y, c) = std::sin(psi(q));
        ++c;
      } else if (j != std::max(x, y)) {
        s(j, c++) = 1.0;
      }
    }
    return s;
  }
};

}  // namespace

TEST_CASE("differential_drive: paper5's instance is the A and S of paper5.md") {
  const auto c = nhdyn::presets::paper5().constraint;
  rng R;
  for (int trial = 0; trial < 100; ++trial) {
    Eigen::Matrix<double, 5, 1> q = R.vec(5, 4.0);
    if (trial == 0) q << -0.23710299623923958, 1.0, std::numbers::pi, 2.058145585963254, 1.2;
    const double s3 = std::sin(q(2)), c3 = std::cos(q(2));
    Eigen::Matrix<double, 1, 5> A;
    A << s3, c3, 0, 0, 0;
    Eigen::Matrix<double, 5, 4> S;
    S << c3, 0, 0, 0,  //
        -s3, 0, 0, 0,  //
        0, 1, 0, 0,    //
        0, 0, 1, 0,    //
        0, 0, 0, 1;
    // Structure exactly (the zeros and ones); the trigonometric entries to an ulp or two
    // (the library may use its own sincos kernel rather than libm's sin and cos).
    const Eigen::Matrix<double, 1, 5> Ac = c.A(q);
    const Eigen::Matrix<double, 5, 4> Sc = c.S(q);
    REQUIRE((Ac - A).cwiseAbs().maxCoeff() <= 4.5e-16);
    REQUIRE((Sc - S).cwiseAbs().maxCoeff() <= 4.5e-16);
    REQUIRE(Ac.tail<3>() == A.tail<3>());
    REQUIRE(Sc.rightCols<3>() == S.rightCols<3>());
    REQUIRE(Sc.col(0).tail<3>() == S.col(0).tail<3>());
    // Ṡ = ∂S/∂q · q̇: only column 1 moves, with q̇₃.
    const Eigen::Matrix<double, 5, 1> qd = R.vec(5, 2.0);
    Eigen::Matrix<double, 5, 4> Sd = Eigen::Matrix<double, 5, 4>::Zero();
    Sd(0, 0) = -s3 * qd(2);
    Sd(1, 0) = -c3 * qd(2);
    REQUIRE((c.Sdot(q, qd) - Sd).cwiseAbs().maxCoeff() <= 1e-15 * std::max(1.0, std::abs(qd(2))));
  }
  REQUIRE(c.k() == 1);
  REQUIRE(c.m() == 4);
  REQUIRE(c.dof() == 5);
}

TEST_CASE("differential_drive: any (x, y, heading) triple, forward offset and heading sign") {
  const std::vector<dd_hand> cases{
      {6, 0, 1, 2, 0.0, 1.0},   {6, 0, 1, 2, 0.0, -1.0}, {6, 3, 1, 5, 0.4, 1.0},
      {6, 4, 2, 0, -1.1, -1.0}, {7, 6, 0, 3, 2.5, 1.0},  {4, 2, 3, 1, -0.3, -1.0},
  };
  rng R;
  double worst_fd = 0, worst_AS = 0;
  for (const auto& hc : cases) {
    const nhdyn::differential_drive<double> c(hc.n, hc.x, hc.y, hc.h, hc.offset, hc.sign);
    REQUIRE(c.k() == 1);
    REQUIRE(c.m() == hc.n - 1);
    for (int trial = 0; trial < 30; ++trial) {
      const Vec q = R.vec(hc.n, 4.0), qd = R.vec(hc.n, 2.0), eta = R.vec(hc.n - 1, 2.0), v = R.vec(hc.n, 5.0);
      const Mat A = c.A(q), S = c.S(q), Sd = c.Sdot(q, qd);
      REQUIRE((A - hc.A(q)).cwiseAbs().maxCoeff() <= 1e-15);
      REQUIRE((S - hc.S(q)).cwiseAbs().maxCoeff() <= 1e-15);
      worst_AS = std::max(worst_AS, (A * S).cwiseAbs().maxCoeff());
      REQUIRE((A * S).cwiseAbs().maxCoeff() < 1e-15);
      REQUIRE((S.transpose() * S - Mat::Identity(hc.n - 1, hc.n - 1)).cwiseAbs().maxCoeff() < 1e-15);
      // The admissible motion: the base point moves along its forward axis at speed v.
      const Vec qdot = S * eta;
      const int vslot = std::min(hc.x, hc.y);
      REQUIRE(qdot(hc.x) == Approx(eta(vslot) * std::cos(hc.psi(q))).margin(1e-15));
      REQUIRE(qdot(hc.y) == Approx(eta(vslot) * std::sin(hc.psi(q))).margin(1e-15));
      // Ṡ against finite differences of S along q̇.
      const Mat Sd_fd = fd_along([&](const Vec& qq) { return Mat(c.S(qq)); }, q, qd);
      worst_fd = std::max(worst_fd, (Sd - Sd_fd).cwiseAbs().maxCoeff());
      REQUIRE((Sd - Sd_fd).cwiseAbs().maxCoeff() < 1e-9);
      // The structured products equal the dense forms.
      REQUIRE((nhdyn::apply_S(c, q, eta) - S * eta).cwiseAbs().maxCoeff() < 1e-15);
      REQUIRE((nhdyn::apply_St(c, q, v) - S.transpose() * v).cwiseAbs().maxCoeff() < 1e-14);
      REQUIRE((nhdyn::apply_Sdot(c, q, qd, eta) - Sd * eta).cwiseAbs().maxCoeff() < 1e-14);
      // Sᵀ M S of a symmetric M, structured (O(n²)) against the dense products.
      Mat B(hc.n, hc.n);
      for (int j = 0; j < hc.n; ++j) B.col(j) = R.vec(hc.n, 3.0);
      const Mat M = B * B.transpose();
      const Mat MS = c.St_M_S(q, M), MS_dense = S.transpose() * M * S;
      REQUIRE((MS - MS_dense).cwiseAbs().maxCoeff() < 1e-13 * M.cwiseAbs().maxCoeff());
      REQUIRE(MS == MS.transpose());
    }
  }
  report("differential_drive max |A S|", worst_AS);
  report("differential_drive max |Sdot - finite differences|", worst_fd);
}

TEST_CASE("differential_drive: fixed and run-time sizes agree; the paper5 preset is the (0, 1, 2, 0, -1) instance") {
  const nhdyn::differential_drive<double, 5> fixed(5, 0, 1, 2, 0.0, -1.0);
  const nhdyn::differential_drive<double> dyn(5, 0, 1, 2, 0.0, -1.0);
  const auto preset = nhdyn::presets::paper5_constraint<double>();
  rng R;
  const Eigen::Matrix<double, 5, 1> q = R.vec(5, 3.0), qd = R.vec(5);
  REQUIRE(Mat(fixed.S(q)) == Mat(dyn.S(Vec(q))));
  REQUIRE(Mat(fixed.Sdot(q, qd)) == Mat(dyn.Sdot(Vec(q), Vec(qd))));
  REQUIRE(Mat(fixed.A(q)) == Mat(preset.A(q)));
}

TEST_CASE("inverse_dynamics, run-time sized: the stack-scratch call is project ∘ rne ∘ lift, bit for bit") {
  // inverse_dynamics over a run-time-sized chain runs (q, η, η̇) on stack scratch
  // (constraints/stages.hpp, scratch_inverse_dynamics); the same stages composed by hand,
  // which go through heap vectors, must give the identical numbers.
  const auto p5 = nhdyn::presets::paper5_chain<double>();
  std::vector<nhdyn::link<double>> links;
  for (int i = 0; i < 300; ++i) links.push_back(p5[i < 3 ? i : 3 + (i % 2)]);  // beyond the 256-entry scratch
  const nhdyn::chain<double> long_chain(links, p5.gravity(), "paper5 base, 297-joint arm");
  rng R;
  for (const auto& ch : {p5.dynamic_size(), long_chain}) {
    const int n = ch.dof();
    for (const auto& c : {nhdyn::differential_drive<double>(n, 0, 1, 2, 0.0, -1.0),
                          nhdyn::differential_drive<double>(n, 1, 0, 2, 0.3, 1.0)}) {
      for (const nhdyn::rne_options o : {nhdyn::rne_options{}, nhdyn::rne_options{false, true}, nhdyn::rne_options{true, false}}) {
        const auto id = nhdyn::inverse_dynamics(ch, c, o);
        const auto by_hand = nhdyn::lift(c) | nhdyn::rne(ch, o) | nhdyn::project(c);
        for (int k = 0; k < 5; ++k) {
          const Vec q = R.vec(n, 3.0), eta = R.vec(n - 1, 2.0), etad = R.vec(n - 1, 2.0);
          const Vec tau = id(q, eta, etad);
          REQUIRE(tau.size() == n - 1);
          REQUIRE(tau == Vec(by_hand(q, eta, etad)));
          REQUIRE(tau == Vec(nhdyn::project(c)(nhdyn::rne(ch, o)(nhdyn::lift(c)(q, eta, etad)))));
          REQUIRE(tau == Vec(id(nhdyn::reduced_state<double>{q, eta, etad})));
          // Expressions as arguments, and a state of another scalar (a dual η̇).
          REQUIRE(tau == Vec(id(q.head(n), 1.0 * eta, etad.segment(0, n - 1))));
          using D = nhdyn::dual<double, 1>;
          Eigen::Matrix<D, Eigen::Dynamic, 1> etad_d = etad.cast<D>();
          etad_d(n - 2).derivative(0) = 1.0;  // d/dη̇_last: a column of M_η
          const auto tau_d = id(q, eta, etad_d);
          const auto tau_d_hand = by_hand(q, eta, etad_d);
          for (int i = 0; i < n - 1; ++i) {
            REQUIRE(tau_d(i).value() == tau_d_hand(i).value());
            REQUIRE(tau_d(i).derivative(0) == tau_d_hand(i).derivative(0));
          }
        }
      }
      // Its errors are the composition's.
      const Vec q = R.vec(n), eta = R.vec(n - 1);
      Vec bad = eta;
      bad(n - 2) = std::numeric_limits<double>::quiet_NaN();
      CHECK_THROWS_WITH(nhdyn::inverse_dynamics(ch, c)(q, eta, bad), Catch::Contains("eta_dot"));
      CHECK_THROWS_WITH(nhdyn::inverse_dynamics(ch, c)(q, bad, eta), Catch::Contains("eta"));
      CHECK_THROWS_WITH(nhdyn::inverse_dynamics(ch, c)(q, Vec(eta.head(n - 2)), eta), Catch::Contains("eta has"));
      CHECK_THROWS_WITH(nhdyn::inverse_dynamics(ch, c)(Vec(q.head(n - 1)), eta, eta), Catch::Contains("q has"));
      const Vec huge = Vec::Constant(n - 1, 1e300);
      CHECK_THROWS_AS(nhdyn::inverse_dynamics(ch, c)(q, huge, huge), nhdyn::numerical_error);
    }
  }
}

TEST_CASE("run-time-sized chain: evaluate of inverse_dynamics and inverse_dynamics_with_forces (with and "
          "without friction) = the stages composed by hand; lambda makes v = E tau + A^T lambda") {
  // The evaluate forms (constraints/stages.hpp, staged_inverse_dynamics) write ξ into stack
  // scratch (a thread's heap block beyond 256 joints) and v over q̈ (the chain's rne, v on q̈'s
  // storage): τ equals the hand-composed stages' bit for bit, the fused call's too.
  const auto p5 = nhdyn::presets::paper5_chain<double>();
  std::vector<nhdyn::link<double>> links;
  for (int i = 0; i < 300; ++i) links.push_back(p5[i < 3 ? i : 3 + (i % 2)]);
  const nhdyn::chain<double> long_chain(links, p5.gravity(), "paper5 base, 297-joint arm");
  rng R;
  nhdyn::constrained_forces<double> out;  // reused across the chains: sizes change
  for (const auto& ch : {p5.dynamic_size(), long_chain}) {
    const int n = ch.dof();
    INFO(ch.name());
    const nhdyn::differential_drive<double> c(n, 0, 1, 2, 0.0, -1.0);
    std::vector<nhdyn::joint_friction> laws;
    for (int j = 0; j < n; ++j) laws.push_back({0.3 + 0.001 * j, 0.2, -0.15});
    const nhdyn::friction_fn fr(laws, nhdyn::coulomb_law::smooth(0.05));
    Vec tau = Vec::Constant(n - 1, 7.0);  // evaluate does not resize: a wrong size is an error (below)
    const auto check = [&](const auto& id, const auto& idf, const auto& by_hand, const auto& by_hand_f, const auto& dyn) {
      for (int k = 0; k < 3; ++k) {
        const Vec q = R.vec(n, 3.0), eta = R.vec(n - 1, 2.0), etad = R.vec(n - 1, 2.0);
        id.evaluate(q, eta, etad, tau);
        const Vec want = by_hand(q, eta, etad);
        REQUIRE(tau == want);
        REQUIRE(Vec(id(q, eta, etad)) == want);
        idf.evaluate(q, eta, etad, out);
        const auto call = idf(q, eta, etad);
        REQUIRE(out.tau == want);
        REQUIRE(Vec(call.tau) == want);
        REQUIRE(Vec(call.lambda) == out.lambda);
        const auto hand = by_hand_f(q, eta, etad);
        REQUIRE(hand.lambda.size() == 1);
        CHECK((out.lambda - Vec(hand.lambda)).cwiseAbs().maxCoeff() <= 1e-10 * (1 + out.lambda.cwiseAbs().maxCoeff()));
        // v = E τ + Aᵀ λ (E = S here): v the stationary chain's dynamics at the lifted state
        const Vec qd = c.S(q) * eta, qdd = c.S(q) * etad + c.Sdot(q, qd) * eta;
        const Vec v = dyn(q, qd, qdd);
        const Vec recon = c.S(q) * out.tau + c.A(q).transpose() * out.lambda;
        CHECK((recon - v).cwiseAbs().maxCoeff() <= 1e-9 * (1 + v.cwiseAbs().maxCoeff()));
      }
    };
    check(nhdyn::inverse_dynamics(ch, c), nhdyn::inverse_dynamics_with_forces(ch, c),
          nhdyn::lift(c) | nhdyn::rne(ch) | nhdyn::project(c), nhdyn::lift(c) | nhdyn::rne(ch) | nhdyn::constraint_forces(c),
          [&](const Vec& q, const Vec& qd, const Vec& qdd) { return Vec(nhdyn::rne(ch)(q, qd, qdd)); });
    check(nhdyn::inverse_dynamics(ch, c, {}, fr), nhdyn::inverse_dynamics_with_forces(ch, c, {}, fr),
          nhdyn::lift(c) | (nhdyn::rne(ch) + fr) | nhdyn::project(c),
          nhdyn::lift(c) | (nhdyn::rne(ch) + fr) | nhdyn::constraint_forces(c),
          [&](const Vec& q, const Vec& qd, const Vec& qdd) { return Vec(nhdyn::rne(ch)(q, qd, qdd) + fr(qd)); });
    // the chain's rne evaluate with v on q̈'s own storage = the call, bit for bit
    const Vec q = R.vec(n), qd = R.vec(n), qdd = R.vec(n);
    Vec v = qdd;
    nhdyn::rne(ch).evaluate(q, qd, v, v);
    REQUIRE(v == Vec(nhdyn::rne(ch)(q, qd, qdd)));
    // … whose non-finite q̈ is overwrite_qdd's error (the other path's would name qdd[i])
    v(1) = std::numeric_limits<double>::infinity();
    CHECK_THROWS_WITH(nhdyn::rne(ch).evaluate(q, qd, v, v), Catch::Contains("or the computation overflowed"));
    // errors name the argument
    const Vec eta = R.vec(n - 1);
    Vec bad = eta;
    bad(n - 2) = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(nhdyn::inverse_dynamics(ch, c).evaluate(q, eta, bad, tau), Catch::Contains("eta_dot"));
    CHECK_THROWS_WITH(nhdyn::inverse_dynamics_with_forces(ch, c).evaluate(q, bad, eta, out), Catch::Contains("eta["));
    Vec short_tau(n - 2);
    CHECK_THROWS_WITH(nhdyn::inverse_dynamics(ch, c).evaluate(q, eta, eta, short_tau), Catch::Contains("tau"));
  }
}

TEST_CASE("inverse_dynamics, compile-time sized: the stack-scratch call is project ∘ rne ∘ lift, bit for bit") {
  // Compile-time sized, (q, η, η̇) with a floating-point state also runs on stack scratch
  // (q̇, q̈, v never move between stages); the stages composed by hand pass fixed-size values
  // along. The same numbers. (A dual state takes the composition itself: checked too.)
  const auto r = nhdyn::presets::paper5();
  using V5 = Eigen::Matrix<double, 5, 1>;
  using V4 = Eigen::Matrix<double, 4, 1>;
  rng R;
  for (const auto& c : {r.constraint, nhdyn::differential_drive<double, 5>(5, 1, 0, 2, 0.3, 1.0)}) {
    for (const nhdyn::rne_options o : {nhdyn::rne_options{}, nhdyn::rne_options{false, true}, nhdyn::rne_options{true, false}}) {
      const auto id = nhdyn::inverse_dynamics(r.chain, c, o);
      const auto by_hand = nhdyn::lift(c) | nhdyn::rne(r.chain, o) | nhdyn::project(c);
      for (int k = 0; k < 20; ++k) {
        const V5 q = R.vec(5, 3.0);
        const V4 eta = R.vec(4, 2.0), etad = R.vec(4, 2.0);
        const V4 tau = id(q, eta, etad);
        REQUIRE(tau == V4(by_hand(q, eta, etad)));
        using D = nhdyn::dual<double, 2>;
        Eigen::Matrix<D, 5, 1> qd = q.cast<D>();
        qd(3).derivative(0) = 1.0;
        Eigen::Matrix<D, 4, 1> ed = eta.cast<D>();
        ed(1).derivative(1) = 1.0;
        const auto t1 = id(qd, ed, etad);
        const auto t2 = by_hand(qd, ed, etad.cast<D>().eval());
        for (int i = 0; i < 4; ++i) {
          REQUIRE(t1(i).value() == t2(i).value());
          REQUIRE(t1(i).derivative(0) == t2(i).derivative(0));
          REQUIRE(t1(i).derivative(1) == t2(i).derivative(1));
        }
      }
    }
    V4 bad = V4::Constant(0.1);
    bad(3) = std::numeric_limits<double>::infinity();
    CHECK_THROWS_WITH(nhdyn::inverse_dynamics(r.chain, c)(V5::Zero().eval(), V4::Zero().eval(), bad), Catch::Contains("eta_dot"));
  }
}

TEST_CASE("inverse_dynamics: the heading's sin/cos taken with rne's joint angles is lift's own, bit for bit") {
  // For a floating-point state the lift runs inside rne, after its joint angles
  // (stages.hpp, lift_prelude): when ψ = sign·q_h + offset equals sign·θ_h exactly
  // (offset = sign·θ⁰_h) ψ's sin/cos are the heading joint's own, otherwise one more angle
  // in rne's batch. Either way the composition's numbers: heading joints with θ⁰ = 0 and
  // 0.7, offsets equal to sign·θ⁰ and not, and headings up to 1e6 rad.
  const auto p5 = nhdyn::presets::paper5_chain<double>();
  std::vector<nhdyn::link<double>> links;
  for (int i = 0; i < 5; ++i) links.push_back(p5[i]);
  links[2].theta = 0.7;
  const nhdyn::chain<double> turned(links, p5.gravity(), "paper5, heading theta0 = 0.7");
  struct layout {
    double theta0, offset, sign;
  };
  rng R;
  for (const layout L : {layout{0.0, 0.0, -1.0}, layout{0.0, 0.0, 1.0}, layout{0.0, 0.3, -1.0}, layout{0.7, -0.7, -1.0},
                         layout{0.7, 0.7, 1.0}, layout{0.7, 0.7, -1.0}, layout{0.7, 0.0, 1.0}}) {
    const auto& ch = L.theta0 == 0.0 ? p5 : turned.fixed<5>();
    const nhdyn::differential_drive<double, 5> c(5, 0, 1, 2, L.offset, L.sign);
    const auto chd = ch.dynamic_size();
    const nhdyn::differential_drive<double> cd(5, 0, 1, 2, L.offset, L.sign);
    const auto id = nhdyn::inverse_dynamics(ch, c);
    const auto idd = nhdyn::inverse_dynamics(chd, cd);
    const auto by_hand = nhdyn::lift(c) | nhdyn::rne(ch) | nhdyn::project(c);
    for (int k = 0; k < 200; ++k) {
      Eigen::Matrix<double, 5, 1> q = R.vec(5, 3.0);
      if (k % 4 == 0) q(2) = R.vec(1, 1e6)(0);  // a heading far from 0 (the exactly summed angle)
      const Eigen::Matrix<double, 4, 1> eta = R.vec(4, 2.0), etad = R.vec(4, 2.0);
      const Eigen::Matrix<double, 4, 1> tau = by_hand(q, eta, etad);
      REQUIRE(Eigen::Matrix<double, 4, 1>(id(q, eta, etad)) == tau);
      REQUIRE(Vec(idd(Vec(q), Vec(eta), Vec(etad))) == Vec(tau));
    }
  }
}

TEST_CASE("differential_drive: bad parameters are rejected with a clear error") {
  using dd = nhdyn::differential_drive<double>;
  const auto msg = [](auto f) {
    try {
      f();
    } catch (const nhdyn::model_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(msg([] { dd(5, 0, 0, 2); }), Catch::Contains("must differ"));
  CHECK_THAT(msg([] { dd(5, 0, 1, 5); }), Catch::Contains("joint index 5"));
  CHECK_THAT(msg([] { dd(5, -1, 1, 2); }), Catch::Contains("joint index -1"));
  CHECK_THAT(msg([] { dd(5, 0, 1, 2, 0.0, 2.0); }), Catch::Contains("heading_sign"));
  CHECK_THAT(msg([] { dd(5, 0, 1, 2, std::nan(""), 1.0); }), Catch::Contains("forward_offset"));
  CHECK_THAT(msg([] { nhdyn::differential_drive<double, 5>(6, 0, 1, 2); }), Catch::Contains("n = 6"));
  // A constraint over the wrong number of joints for the chain.
  const auto ch = nhdyn::presets::paper5_chain<double>().dynamic_size();
  CHECK_THROWS_AS(nhdyn::nh_forward_dynamics(ch, dd(6, 0, 1, 2)), nhdyn::model_error);
}

namespace {
// A user constraint on paper5's joints acting on an arm joint as well as the base:
// no lateral slip, and the shoulder coupled to the heading, q̇₄ = c·cos q₅ · q̇₃.
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
/// Ṡ by hand.
auto coupled_Sdot = [](const auto& q, const auto& qd) {
  using T = typename std::decay_t<decltype(q)>::Scalar;
  using std::cos;
  using std::sin;
  MatT<T> Sd = MatT<T>::Zero(5, 3);
  Sd(0, 0) = -sin(q(2)) * qd(2);
  Sd(1, 0) = -cos(q(2)) * qd(2);
  Sd(3, 1) = -T(kc) * sin(q(4)) * qd(4);
  return Sd;
};

// A more nonlinear one on 4 joints, k = 1: q̇₀ = sin(q₁) q₂ q̇₁ + exp(q₃)·cos(q₀ q₂) q̇₂ (η = q̇₁, q̇₂, q̇₃).
auto nl_A = [](const auto& q) {
  using T = typename std::decay_t<decltype(q)>::Scalar;
  using std::cos;
  using std::exp;
  using std::sin;
  MatT<T> A = MatT<T>::Zero(1, 4);
  A(0, 0) = T(1);
  A(0, 1) = -sin(q(1)) * q(2);
  A(0, 2) = -exp(q(3)) * cos(q(0) * q(2));
  return A;
};
auto nl_S = [](const auto& q) {
  using T = typename std::decay_t<decltype(q)>::Scalar;
  using std::cos;
  using std::exp;
  using std::sin;
  MatT<T> S = MatT<T>::Zero(4, 3);
  S(0, 0) = sin(q(1)) * q(2);
  S(0, 1) = exp(q(3)) * cos(q(0) * q(2));
  S(1, 0) = T(1);
  S(2, 1) = T(1);
  S(3, 2) = T(1);
  return S;
};
Mat nl_Sdot(const Vec& q, const Vec& qd) {
  Mat Sd = Mat::Zero(4, 3);
  Sd(0, 0) = std::cos(q(1)) * qd(1) * q(2) + std::sin(q(1)) * qd(2);
  Sd(0, 1) = std::exp(q(3)) * qd(3) * std::cos(q(0) * q(2)) -
             std::exp(q(3)) * std::sin(q(0) * q(2)) * (qd(0) * q(2) + q(0) * qd(2));
  return Sd;
}
}  // namespace

TEST_CASE("make_constraint: generic lambdas give A S = 0 and S-dot by duals equal to the hand-derived S-dot") {
  const auto coupled = nhdyn::make_constraint(5, 2, coupled_A, coupled_S);
  const auto coupled_given = nhdyn::make_constraint(5, 2, coupled_A, coupled_S, coupled_Sdot);
  const auto nl = nhdyn::make_constraint(4, 1, nl_A, nl_S);
  REQUIRE(coupled.k() == 2);
  REQUIRE(coupled.m() == 3);
  rng R;
  double worst_dual = 0, worst_fd = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const Vec q = R.vec(5, 3.0), qd = R.vec(5, 2.0);
    REQUIRE((coupled.A(q) * coupled.S(q)).cwiseAbs().maxCoeff() < 1e-15);
    const Mat by_duals = coupled.Sdot(q, qd), by_hand = coupled_Sdot(q, qd);
    worst_dual = std::max(worst_dual, (by_duals - by_hand).cwiseAbs().maxCoeff());
    REQUIRE((by_duals - by_hand).cwiseAbs().maxCoeff() < 1e-15);
    REQUIRE(Mat(coupled_given.Sdot(q, qd)) == by_hand);  // a given Ṡ is used as given
    const Mat fd = fd_along([&](const Vec& qq) { return Mat(coupled.S(qq)); }, q, qd);
    worst_fd = std::max(worst_fd, (by_duals - fd).cwiseAbs().maxCoeff());
    REQUIRE((by_duals - fd).cwiseAbs().maxCoeff() < 1e-9);

    const Vec q4 = R.vec(4), qd4 = R.vec(4, 2.0);
    REQUIRE((nl.A(q4) * nl.S(q4)).cwiseAbs().maxCoeff() < 1e-15);
    const Mat nl_duals = nl.Sdot(q4, qd4), nl_hand = nl_Sdot(q4, qd4);
    worst_dual = std::max(worst_dual, (nl_duals - nl_hand).cwiseAbs().maxCoeff());
    REQUIRE((nl_duals - nl_hand).cwiseAbs().maxCoeff() < 1e-14);
    const Mat nl_fd = fd_along([&](const Vec& qq) { return Mat(nl.S(qq)); }, q4, qd4);
    worst_fd = std::max(worst_fd, (nl_duals - nl_fd).cwiseAbs().maxCoeff());
    REQUIRE((nl_duals - nl_fd).cwiseAbs().maxCoeff() < 1e-9);
  }
  report("make_constraint Sdot by duals vs by hand", worst_dual);
  report("make_constraint Sdot by duals vs finite differences", worst_fd);
}

TEST_CASE("make_constraint: wrong-sized functions are reported, naming the function") {
  const auto bad_S = nhdyn::make_constraint(5, 2, coupled_A, [](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    return MatT<T>(MatT<T>::Zero(5, 4));
  });
  const Vec q = Vec::Zero(5);
  CHECK_THROWS_WITH(bad_S.S(q), Catch::Contains("S(q) is 5×4, expected 5×3"));
  CHECK_THROWS_WITH(bad_S.Sdot(q, q), Catch::Contains("S(q)"));
  const auto bad_A = nhdyn::make_constraint(5, 1, coupled_A, coupled_S);
  CHECK_THROWS_AS(bad_A.A(q), nhdyn::input_error);
  const auto ch = nhdyn::presets::paper5_chain<double>().dynamic_size();
  const auto c = nhdyn::make_constraint(5, 2, coupled_A, coupled_S);
  const auto id = nhdyn::inverse_dynamics(ch, c);
  CHECK_THROWS_WITH(id(q, Vec::Zero(4), Vec::Zero(3)), Catch::Contains("eta has 4 entries"));
  CHECK_THROWS_AS(id(q, Vec::Zero(3), Vec::Constant(3, std::nan(""))), nhdyn::input_error);
}

TEST_CASE("project: tau = (S^T E)^-1 S^T v for E = S orthonormal, S not orthonormal, and E != S") {
  const auto dd = nhdyn::presets::paper5_constraint<double>();
  const auto user = nhdyn::make_constraint(5, 2, coupled_A, coupled_S);
  Mat G(3, 3), W(2, 3);
  G << 2.0, 0.5, 0.0, -0.3, 1.5, 0.2, 0.1, 0.0, 0.8;
  W << 0.4, -0.2, 0.3, 0.1, 0.6, -0.5;
  const auto coupled_E = [G, W](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    return MatT<T>(coupled_S(q) * G.cast<T>() + coupled_A(q).transpose() * W.cast<T>());
  };
  const auto userE = nhdyn::make_constraint(5, 2, coupled_A, coupled_S, nullptr, coupled_E);
  rng R;
  double worst = 0, worst_recon = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const Vec q = R.vec(5, 3.0), v = R.vec(5, 10.0);
    // differential drive: SᵀS = I, τ = Sᵀv.
    const Mat S0 = dd.S(q);
    const Vec t0 = nhdyn::project(dd)(q, v);
    REQUIRE((t0 - S0.transpose() * v).cwiseAbs().maxCoeff() < 1e-14);
    // E = S not orthonormal: τ is the least-squares solution of S τ ≈ v.
    const Mat S = coupled_S(q);
    const Vec t1 = nhdyn::project(user)(q, v), t1_ref = S.colPivHouseholderQr().solve(v);
    worst = std::max(worst, (t1 - t1_ref).norm() / t1_ref.norm());
    REQUIRE((t1 - t1_ref).norm() < 1e-13 * t1_ref.norm());
    // E ≠ S.
    const Mat E = coupled_E(q);
    REQUIRE((Mat(nhdyn::input_map(userE, q)) - E).norm() == 0.0);
    const Vec t2 = nhdyn::project(userE)(q, v), t2_ref = (S.transpose() * E).fullPivLu().solve(S.transpose() * v);
    worst = std::max(worst, (t2 - t2_ref).norm() / t2_ref.norm());
    REQUIRE((t2 - t2_ref).norm() < 1e-13 * t2_ref.norm());
    // Any v splits as E τ + Aᵀ λ, for every kind of constraint.
    const Mat A = coupled_A(q);
    const auto f1 = nhdyn::constraint_forces(user)(q, v);
    const auto f2 = nhdyn::constraint_forces(userE)(q, v);
    const auto f0 = nhdyn::constraint_forces(dd)(q, v);
    worst_recon = std::max({worst_recon, (S * f1.tau + A.transpose() * f1.lambda - v).norm() / v.norm(),
                            (E * f2.tau + A.transpose() * f2.lambda - v).norm() / v.norm(),
                            (S0 * f0.tau + Mat(dd.A(q)).transpose() * f0.lambda - v).norm() / v.norm()});
    REQUIRE((S * f1.tau + A.transpose() * f1.lambda - v).norm() < 1e-14 * v.norm());
    REQUIRE((E * f2.tau + A.transpose() * f2.lambda - v).norm() < 1e-14 * v.norm());
    REQUIRE((S0 * f0.tau + Mat(dd.A(q)).transpose() * f0.lambda - v).norm() < 1e-14 * v.norm());
  }
  report("project vs independent solves (rel)", worst);
  report("v - (E tau + A^T lambda) for arbitrary v (rel)", worst_recon);
}

TEST_CASE("make_constraint: paper5's constraint as user lambdas gives the same dynamics, any sizes and scalars") {
  // The same constraint twice: built in, and as plain functions (E = S, Ṡ by duals). The
  // user one is run-time sized; the chain fixed (5) or run-time sized.
  const auto user = nhdyn::make_constraint(
      5, 1,
      [](const auto& q) {
        using T = typename std::decay_t<decltype(q)>::Scalar;
        using std::cos;
        using std::sin;
        MatT<T> A = MatT<T>::Zero(1, 5);
        A(0, 0) = sin(q(2));
        A(0, 1) = cos(q(2));
        return A;
      },
      [](const auto& q) {
        using T = typename std::decay_t<decltype(q)>::Scalar;
        using std::cos;
        using std::sin;
        MatT<T> S = MatT<T>::Zero(5, 4);
        S(0, 0) = cos(q(2));
        S(1, 0) = -sin(q(2));
        S(2, 1) = S(3, 2) = S(4, 3) = T(1);
        return S;
      });
  const auto r = nhdyn::presets::paper5();
  const auto id_builtin = nhdyn::inverse_dynamics(r.chain, r.constraint);
  const auto id_fixed = nhdyn::inverse_dynamics(r.chain, user);
  const auto id_dyn = nhdyn::inverse_dynamics(r.chain.dynamic_size(), user);
  const auto id_dyn_builtin = nhdyn::inverse_dynamics(r.chain.dynamic_size(), r.constraint);
  const auto fd_fixed = nhdyn::nh_forward_dynamics(r.chain, user);
  using D = nhdyn::dual<double, 1>;
  const auto val = [](const auto& v) { return Vec(v.unaryExpr([](const D& x) { return x.value(); })); };
  const auto der = [](const auto& v) { return Vec(v.unaryExpr([](const D& x) { return x.derivative(0); })); };
  rng R;
  for (int trial = 0; trial < 30; ++trial) {
    const Eigen::Matrix<double, 5, 1> q = R.vec(5, 3.0);
    const Eigen::Matrix<double, 4, 1> eta = R.vec(4, 2.0), eta_dot = R.vec(4, 3.0);
    const Vec tau = id_builtin(q, eta, eta_dot);
    REQUIRE((Vec(id_fixed(q, eta, eta_dot)) - tau).cwiseAbs().maxCoeff() < 1e-13);
    REQUIRE((Vec(id_dyn(Vec(q), Vec(eta), Vec(eta_dot))) - tau).cwiseAbs().maxCoeff() < 1e-13);
    REQUIRE((Vec(id_dyn_builtin(Vec(q), Vec(eta), Vec(eta_dot))) - tau).cwiseAbs().maxCoeff() < 1e-13);
    REQUIRE((Vec(fd_fixed(q, eta, tau)) - Vec(eta_dot)).cwiseAbs().maxCoeff() < 1e-11);
    // Dual q with double η, and double q with dual η: ∂τ/∂q₄ and ∂τ/∂η₁ agree between the two
    // constraints and with central differences.
    Eigen::Matrix<D, 5, 1> qD = q.cast<D>();
    qD(3) = D::variable(q(3), 0);
    const auto tq_user = id_fixed(qD, eta, eta_dot);
    const auto tq_builtin = id_builtin(qD, eta, eta_dot);
    REQUIRE((val(tq_user) - tau).cwiseAbs().maxCoeff() < 1e-13);
    REQUIRE((der(tq_user) - der(tq_builtin)).cwiseAbs().maxCoeff() < 1e-13);
    const double h = 1e-6;
    Eigen::Matrix<double, 5, 1> qp = q, qm = q;
    qp(3) += h;
    qm(3) -= h;
    const Vec fdq = (Vec(id_builtin(qp, eta, eta_dot)) - Vec(id_builtin(qm, eta, eta_dot))) / (2 * h);
    REQUIRE((der(tq_builtin) - fdq).cwiseAbs().maxCoeff() < 1e-7 * std::max(1.0, fdq.norm()));
    Eigen::Matrix<D, 4, 1> eD = eta.cast<D>();
    eD(1) = D::variable(eta(1), 0);
    const auto te_user = id_fixed(q, eD, eta_dot);
    const auto te_builtin = id_builtin(q, eD, eta_dot);
    REQUIRE((der(te_user) - der(te_builtin)).cwiseAbs().maxCoeff() < 1e-13);
  }
}

TEST_CASE("constraints: a constraint over the wrong number of joints, or a wrong-sized q, is reported") {
  const auto r = nhdyn::presets::paper5();
  CHECK_THROWS_WITH(nhdyn::inverse_dynamics(r.chain, nhdyn::differential_drive<double>(6, 0, 1, 2)),
                    Catch::Contains("the constraint is over 6 joints, the chain has 5"));
  CHECK_THROWS_AS(nhdyn::inverse_dynamics_with_forces(r.chain.dynamic_size(), nhdyn::differential_drive<double>(4, 0, 1, 2)),
                  nhdyn::model_error);
  const auto user = nhdyn::make_constraint(5, 2, coupled_A, coupled_S);
  CHECK_THROWS_WITH(user.S(Vec::Zero(4)), Catch::Contains("q has 4 entries"));
  CHECK_THROWS_WITH(user.A(Vec::Zero(6)), Catch::Contains("q has 6 entries"));
  CHECK_THROWS_WITH(user.Sdot(Vec::Zero(5), Vec::Zero(3)), Catch::Contains("qd has 3 entries"));
}

namespace concept_check {
struct no_sdot {  // A and S but no Ṡ: not a constraint
  static constexpr int n_at_compile_time = nhdyn::dynamic, k_at_compile_time = nhdyn::dynamic,
                       m_at_compile_time = nhdyn::dynamic;
  int dof() const { return 2; }
  int k() const { return 1; }
  int m() const { return 1; }
  template <class Q>
  Eigen::MatrixXd A(const Q&) const { return Eigen::MatrixXd::Zero(1, 2); }
  template <class Q>
  Eigen::MatrixXd S(const Q&) const { return Eigen::MatrixXd::Zero(2, 1); }
};
}  // namespace concept_check

TEST_CASE("constraint types model the pfaffian_constraint concept; others do not") {
  STATIC_REQUIRE(nhdyn::pfaffian_constraint<nhdyn::differential_drive<double, 5>>);
  STATIC_REQUIRE(nhdyn::pfaffian_constraint<nhdyn::differential_drive<double>>);
  STATIC_REQUIRE(nhdyn::pfaffian_constraint<nhdyn::holonomic<6>>);
  STATIC_REQUIRE(nhdyn::pfaffian_constraint<nhdyn::holonomic<>>);
  const auto fA = [](const auto& q) { return Eigen::Matrix<typename std::decay_t<decltype(q)>::Scalar, -1, -1>::Zero(1, 2).eval(); };
  const auto fS = [](const auto& q) { return Eigen::Matrix<typename std::decay_t<decltype(q)>::Scalar, -1, -1>::Identity(2, 1).eval(); };
  STATIC_REQUIRE(nhdyn::pfaffian_constraint<decltype(nhdyn::make_constraint(2, 1, fA, fS))>);
  STATIC_REQUIRE_FALSE(nhdyn::pfaffian_constraint<concept_check::no_sdot>);
  STATIC_REQUIRE_FALSE(nhdyn::pfaffian_constraint<int>);
  STATIC_REQUIRE(nhdyn::has_input_map<decltype(nhdyn::make_constraint(2, 1, fA, fS, nullptr, fS)), Eigen::VectorXd>);
  STATIC_REQUIRE_FALSE(nhdyn::has_input_map<nhdyn::differential_drive<double>, Eigen::VectorXd>);
}
