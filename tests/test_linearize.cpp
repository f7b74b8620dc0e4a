// Exact linearisation by duals, checked against two independent references:
//  - central finite differences in double over a sweep of steps (the error must follow
//    the O(h²) truncation law at large h and reach ≈1e-9 at the best step), and
//  - central finite differences in 50-digit arithmetic (step 1e-20: truncation 1e-40),
//    which are the derivatives to ≥ 30 digits: the dual Jacobian must agree to 1e-9 relative
//    (in fact to a few ulps), and a dual<mp50> Jacobian to 1e-30.
#include <catch2/catch.hpp>
#include <algorithm>
#include <numbers>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/scalar/multiprecision.hpp>

namespace {
using nhdyn::mp50;
using V5 = Eigen::Matrix<double, 5, 1>;
using V4 = Eigen::Matrix<double, 4, 1>;
using V13 = Eigen::Matrix<double, 13, 1>;

const V5 q0(0.1, -0.2, 0.7, 0.4, -0.9);
const V4 eta0(0.3, 0.5, 1.2, -0.7), etad0(0.2, -0.3, 1.0, 0.5);

/// τ(ζ) of paper5, generic over the scalar of ζ (a model in the same scalar).
template <class Z>
auto paper5_tau(const Z& z) {
  using T = typename Z::Scalar;
  const auto r = nhdyn::presets::paper5<T>();
  return nhdyn::vecN<T, 4>(nhdyn::inverse_dynamics(r.chain, r.constraint)(z.head(5), z.segment(4 + 1, 4), z.tail(4)));
}

template <class A, class B>
double rel_err(const A& a, const B& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

/// S(q) of constraint c with its columns scaled by 0.5, 1.2, 1.9, 2.6 (SᵀS ≠ I), as a
/// generic function of q for make_constraint.
template <class C>
auto scaled_S(const C& c) {
  return [c](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> S = c.S(q);
    for (int j = 0; j < 4; ++j) S.col(j) *= T(0.5 + 0.7 * j);
    return S;
  };
}

/// 50-digit central differences of τ(ζ), converted to double.
Eigen::Matrix<double, 4, 13> mp_reference(const V13& z) {
  const Eigen::Matrix<mp50, 13, 1> zm = z.cast<mp50>();
  const auto f = [](const Eigen::Matrix<mp50, 13, 1>& x) { return paper5_tau(x); };
  const auto J = nhdyn::central_difference_jacobian(f, zm, 1e-20);
  return J.unaryExpr([](const mp50& v) { return static_cast<double>(v); });
}
}  // namespace

TEST_CASE("linearize: dtau/dzeta of paper5 by duals matches 50-digit finite differences to 1e-9") {
  const auto r = nhdyn::presets::paper5();
  const auto lin = nhdyn::linearize_inverse_dynamics(r.chain, r.constraint, q0, eta0, etad0);
  V13 z;
  z << q0, eta0, etad0;
  const auto ref = mp_reference(z);
  INFO("dual J:\n" << lin.J << "\nmp50 FD:\n" << ref);
  CHECK(rel_err(lin.J, ref) < 1e-9);
  CHECK(rel_err(lin.J, ref) < 1e-13);  // duals are exact up to rounding: a few ulps
  // ∂τ/∂η̇ is the reduced inertia M_η = SᵀMS (E = S, SᵀS = I); the linearizer takes it from
  // CRBA, so compare with M_η built the other way, column by column from rne (q̈ = S e_j).
  const auto Me = nhdyn::nh_forward_dynamics(r.chain, r.constraint, {}, nhdyn::reduced_inertia_method::rne_columns)
                      .reduced_inertia(q0);
  CHECK(rel_err(lin.deta_dot(), Me) < 1e-13);
  // τ does not depend on the base position (q₁, q₂): translation invariance in the ground plane.
  CHECK(lin.dq().leftCols(2).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("linearize: duals in 50 digits agree with 50-digit finite differences to 1e-30") {
  V13 z;
  z << q0, eta0, etad0;
  const Eigen::Matrix<mp50, 13, 1> zm = z.cast<mp50>();
  const auto Jd = nhdyn::jacobian([](const auto& x) { return paper5_tau(x); }, zm);
  // Step 1e-17 ≈ ε₅₀^(1/3): truncation ≈ h² ≈ 1e-34, rounding ≈ ε₅₀/h ≈ 1e-33. The
  // differences are taken through dual<mp50, 1> numbers with zero derivative part, so that
  // both sides evaluate the very same model (a real type snaps cos α ≈ 6e-17 of α = −π/2 to
  // 0, a dual keeps it for ∂/∂α: in 50 digits that difference would show).
  using D1 = nhdyn::dual<mp50, 1>;
  const auto fvalue = [](const Eigen::Matrix<mp50, 13, 1>& x) {
    const Eigen::Matrix<D1, 13, 1> xd = x.unaryExpr([](const mp50& v) { return D1(v); });
    return Eigen::Matrix<mp50, 4, 1>(paper5_tau(xd).unaryExpr([](const D1& d) { return d.value(); }));
  };
  const auto Jf = nhdyn::central_difference_jacobian(fvalue, zm, 1e-17);
  mp50 worst = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 13; ++j) worst = std::max(worst, mp50(abs(Jd(i, j) - Jf(i, j))));
  INFO("max |dual − FD| in 50 digits: " << static_cast<double>(worst));
  CHECK(static_cast<double>(worst) < 1e-30);
}

TEST_CASE("linearize: central differences over a step sweep converge to the dual Jacobian") {
  const auto r = nhdyn::presets::paper5();
  const auto lin = nhdyn::linearize_inverse_dynamics(r.chain, r.constraint, q0, eta0, etad0);
  V13 z;
  z << q0, eta0, etad0;
  const auto f = [](const auto& x) { return paper5_tau(x); };
  std::vector<double> err;
  for (double h : {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8}) {
    err.push_back(rel_err(nhdyn::central_difference_jacobian(f, z, h), lin.J));
    INFO("h = " << h << ": error " << err.back());
  }
  // Truncation regime: the error falls ≈ 100× per 10× smaller step (O(h²)).
  CHECK(err[1] < err[0] / 30);
  CHECK(err[2] < err[1] / 30);
  // Best step ≈ ε^(1/3) ≈ 1e-5: ≈ 1e-10; the dual Jacobian has no step to choose.
  CHECK(*std::min_element(err.begin(), err.end()) < 1e-8);
  // Rounding regime: too small a step is worse again (ε/h).
  CHECK(err.back() > *std::min_element(err.begin(), err.end()));
}

TEST_CASE("linearize: A and B of paper5's forward dynamics match 50-digit finite differences") {
  const auto r = nhdyn::presets::paper5();
  const V4 tau = nhdyn::inverse_dynamics(r.chain, r.constraint)(q0, eta0, etad0);
  const auto ss = nhdyn::linearize_forward_dynamics(r.chain, r.constraint, q0, eta0, tau);
  REQUIRE(ss.A.rows() == 9);
  REQUIRE(ss.B.cols() == 4);
  // Reference: f(x, u) = (Sη, η̇) in 50 digits, central differences.
  const auto rm = nhdyn::presets::paper5<mp50>();
  const auto fdm = nhdyn::nh_forward_dynamics(rm.chain, rm.constraint);
  const auto f = [&](const Eigen::Matrix<mp50, 13, 1>& x) {
    Eigen::Matrix<mp50, 9, 1> out;
    out << nhdyn::apply_S(rm.constraint, x.head(5), x.segment(5, 4)), fdm(x.head(5), x.segment(5, 4), x.tail(4));
    return out;
  };
  Eigen::Matrix<double, 13, 1> x;
  x << q0, eta0, tau;
  const auto J = nhdyn::central_difference_jacobian(f, Eigen::Matrix<mp50, 13, 1>(x.cast<mp50>()), 1e-20);
  const Eigen::MatrixXd Jd = J.unaryExpr([](const mp50& v) { return static_cast<double>(v); });
  CHECK(rel_err(ss.A, Jd.leftCols(9)) < 1e-9);
  CHECK(rel_err(ss.B, Jd.rightCols(4)) < 1e-9);
  // Structure: ∂(Sη)/∂η = S, ∂(Sη)/∂τ = 0, ∂η̇/∂τ = M_η⁻¹.
  CHECK(rel_err(ss.A.block(0, 5, 5, 4), r.constraint.S(q0)) < 1e-15);
  CHECK(ss.B.topRows(5).cwiseAbs().maxCoeff() == 0.0);
  const Eigen::Matrix4d Me = nhdyn::nh_forward_dynamics(r.chain, r.constraint).reduced_inertia(q0);
  CHECK(rel_err(ss.B.bottomRows(4) * Me, Eigen::Matrix4d::Identity()) < 1e-12);
}

TEST_CASE("linearize: A and B from the inverse-dynamics Jacobian equal every column seeded through the forward dynamics") {
  // linearize_forward_dynamics takes A, B from the linearizer's ∂τ/∂(q, η, η̇) at
  // (q, η, fd(q, η, τ)) by the implicit function theorem. The reference here differentiates
  // the forward dynamics itself: duals along all of (q, η, τ) through nh_forward_dynamics
  // (CRBA, LDLᵀ and rne in duals) — a different computation, equal to rounding. paper5
  // (fixed size), the same run-time sized, a base with a 4-joint arm and gravity tilted
  // (no symmetry: the heading column computed), and a constraint with SᵀS ≠ I and E ≠ S.
  const auto reference = [](const auto& ch, const auto& c, const Eigen::VectorXd& q, const Eigen::VectorXd& eta,
                            const Eigen::VectorXd& tau) {
    const int n = c.dof(), m = c.m();
    const auto fd = nhdyn::nh_forward_dynamics(ch, c);
    const auto f = [&](const auto& x) {
      using D = typename std::decay_t<decltype(x)>::Scalar;
      Eigen::Matrix<D, Eigen::Dynamic, 1> out(n + m);
      out << nhdyn::apply_S(c, x.head(n), x.segment(n, m)), fd(x.head(n), x.segment(n, m), x.tail(m));
      return out;
    };
    Eigen::VectorXd x(n + 2 * m);
    x << q, eta, tau;
    return Eigen::MatrixXd(nhdyn::jacobian(f, x));
  };
  const auto check = [&](const auto& ch, const auto& c, const Eigen::VectorXd& q, const Eigen::VectorXd& eta,
                         const Eigen::VectorXd& tau) {
    const int n = c.dof(), m = c.m();
    const auto ss = nhdyn::linearize_forward_dynamics(ch, c, q, eta, tau);
    const Eigen::MatrixXd J = reference(ch, c, q, eta, tau);
    INFO("A:\n" << ss.A << "\nreference:\n" << J.leftCols(n + m));
    CHECK(rel_err(ss.A, J.leftCols(n + m)) < 1e-12);
    CHECK(rel_err(ss.B, J.rightCols(m)) < 1e-12);
    CHECK(ss.B.topRows(n).cwiseAbs().maxCoeff() == 0.0);
  };
  const auto r = nhdyn::presets::paper5();
  const auto id = nhdyn::inverse_dynamics(r.chain, r.constraint);
  for (double s : {1.0, -0.4, 2.0}) {
    const V5 q = s * q0;
    const V4 eta = s * eta0, tau = id(q, eta, V4(s * etad0));
    const auto ss = nhdyn::linearize_forward_dynamics(r.chain, r.constraint, q, eta, tau);
    const Eigen::MatrixXd J = reference(r.chain, r.constraint, q, eta, tau);
    CHECK(rel_err(ss.A, J.leftCols(9)) < 1e-12);
    CHECK(rel_err(ss.B, J.rightCols(4)) < 1e-12);
    check(r.chain.dynamic_size(), nhdyn::differential_drive<double>(5, 0, 1, 2, 0.0, -1.0), q, eta, tau);
  }
  {  // a 4-joint arm on paper5's base, gravity tilted
    std::vector<nhdyn::link<double>> L(r.chain.begin(), r.chain.end());
    L.push_back(L[3]);
    L.push_back(L[4]);
    const nhdyn::chain<double> arm(L, Eigen::Vector3d(-9.7, 1.5, 0.8), "tilted base + 4 joints");
    const nhdyn::differential_drive<double> dd(7, 0, 1, 2, 0.2, -1.0);
    Eigen::VectorXd q(7), eta(6), etad(6);
    q << q0, 0.3, -0.6;
    eta << eta0, 0.4, -0.2;
    etad << etad0, -0.3, 0.6;
    check(arm, dd, q, eta, nhdyn::inverse_dynamics(arm, dd)(q, eta, etad));
  }
  {  // SᵀS ≠ I, E ≠ S (as in the linearizer's test below)
    const auto c = r.constraint;
    const auto scaledS = scaled_S(c);
    const auto inputE = [scaledS](const auto& q) {
      using T = typename std::decay_t<decltype(q)>::Scalar;
      Eigen::MatrixXd G(4, 4);
      G << 1.0, 0.2, 0, 0, -0.1, 0.9, 0, 0.3, 0, 0, 1.2, 0.1, 0.2, 0, 0, 0.8;
      return Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>(scaledS(q) * G.cast<T>());
    };
    const auto userE = nhdyn::make_constraint(
        5, 1, [c](const auto& q) { return c.A(q); }, scaledS, nullptr, inputE);
    const auto dyn = r.chain.dynamic_size();
    const Eigen::VectorXd q = q0, eta = eta0;
    check(dyn, userE, q, eta, nhdyn::inverse_dynamics(dyn, userE)(q, eta, Eigen::VectorXd(etad0)));
  }
}

TEST_CASE("linearize: a holonomic chain gives x = (q, qd), A = [0 I; dqdd/dq dqdd/dqd], B = [0; M^-1]") {
  const auto p = nhdyn::presets::puma560();
  using V6 = Eigen::Matrix<double, 6, 1>;
  const V6 q(0.3, -0.8, 1.1, 0.2, -0.5, 0.9), qd(0.5, -0.3, 0.8, -1.0, 0.4, 0.7), tau(1, 20, 3, 0.1, 0.2, 0.05);
  const auto ss = nhdyn::linearize_forward_dynamics(p, q, qd, tau);
  REQUIRE(ss.A.rows() == 12);
  CHECK((ss.A.topLeftCorner(6, 6)).cwiseAbs().maxCoeff() == 0.0);
  CHECK((ss.A.topRightCorner(6, 6) - Eigen::Matrix<double, 6, 6>::Identity()).cwiseAbs().maxCoeff() == 0.0);
  const Eigen::Matrix<double, 6, 6> M = nhdyn::mass_matrix(p)(q);
  CHECK(rel_err(M * ss.B.bottomRows(6), Eigen::Matrix<double, 6, 6>::Identity()) < 1e-10);
  // ∂q̈/∂(q, q̇) against 50-digit central differences.
  const auto pm = nhdyn::presets::puma560<mp50>();
  const auto fdm = nhdyn::forward_dynamics(pm);
  const auto f = [&](const Eigen::Matrix<mp50, 12, 1>& x) {
    return Eigen::Matrix<mp50, 6, 1>(fdm(x.head(6), x.tail(6), tau.cast<mp50>()));
  };
  Eigen::Matrix<double, 12, 1> x;
  x << q, qd;
  const auto J = nhdyn::central_difference_jacobian(f, Eigen::Matrix<mp50, 12, 1>(x.cast<mp50>()), 1e-20);
  const Eigen::MatrixXd Jd = J.unaryExpr([](const mp50& v) { return static_cast<double>(v); });
  CHECK(rel_err(ss.A.bottomRows(6), Jd) < 1e-9);
}

TEST_CASE("linearize: parameter sensitivities of paper5's torques by a dual-parameter model") {
  // ∂τ/∂(mass factors 1…5, d₃, a₄, a₅ factors) with presets::paper5<dual>(seeded factors).
  const auto sens = [&](const auto& p) {
    using D = typename std::decay_t<decltype(p)>::Scalar;
    nhdyn::presets::paper5_parameters<D> par{{p(0), p(1), p(2), p(3), p(4)}, p(5), p(6), p(7)};
    const auto r = nhdyn::presets::paper5<D>(par);
    return nhdyn::vecN<D, 4>(nhdyn::inverse_dynamics(r.chain, r.constraint)(q0, eta0, etad0));
  };
  const Eigen::Matrix<double, 8, 1> ones = Eigen::Matrix<double, 8, 1>::Ones();
  const auto J = nhdyn::jacobian(sens, ones);
  const auto Jm = nhdyn::central_difference_jacobian(sens, Eigen::Matrix<mp50, 8, 1>(ones.cast<mp50>()), 1e-20);
  const Eigen::MatrixXd Jr = Jm.unaryExpr([](const mp50& v) { return static_cast<double>(v); });
  INFO("dual:\n" << J << "\nmp50 FD:\n" << Jr);
  CHECK(rel_err(J, Jr) < 1e-9);
  // Links 1 and 2 are massless: their mass factors do not matter.
  CHECK(J.leftCols(2).cwiseAbs().maxCoeff() == 0.0);
  // τ is linear in each mass factor (inertia scales with it): τ(2·m₃) − τ(m₃) = ∂τ/∂m₃.
  Eigen::Matrix<double, 8, 1> two = ones;
  two(2) = 2;
  CHECK(rel_err(sens(two.cast<mp50>()).unaryExpr([](const mp50& v) { return static_cast<double>(v); }) -
                    sens(ones.cast<mp50>()).unaryExpr([](const mp50& v) { return static_cast<double>(v); }),
                J.col(2)) < 1e-12);
}

TEST_CASE("linearize: link parameter Jacobian matches 50-digit finite differences") {
  const auto r = nhdyn::presets::paper5();
  const auto J = nhdyn::link_parameter_jacobian(r.chain, r.constraint, q0, eta0, etad0);
  REQUIRE(J.cols() == 30);
  // Reference: the same parameters perturbed in a 50-digit model.
  const auto c50 = r.chain.cast<mp50>();
  Eigen::Matrix<double, 4, 30> ref;
  for (int j = 0; j < 30; ++j) {
    const int i = j / 6, f = j % 6;
    const mp50 h = 1e-20;
    auto tau_at = [&](const mp50& dp) {
      auto L = c50.links();
      auto& l = L[static_cast<std::size_t>(i)];
      if (f == 0) l.mass += dp;
      if (f == 1) l.a += dp;
      if (f == 2) l.d += dp;
      if (f >= 3) l.inertia(f - 3, f - 3) += dp;
      const nhdyn::chain<mp50, 5> c(L, c50.gravity(), "p", nhdyn::validation{false});  // a lone Izz on a massless link
      return Eigen::Matrix<mp50, 4, 1>(nhdyn::inverse_dynamics(c, r.constraint)(q0, eta0, etad0));
    };
    // Forward differences (a massless link cannot take a negative mass): error O(h) = 1e-20.
    const Eigen::Matrix<mp50, 4, 1> d = (tau_at(h) - tau_at(mp50(0))) / h;
    ref.col(j) = d.unaryExpr([](const mp50& v) { return static_cast<double>(v); });
  }
  CHECK(rel_err(J, ref) < 1e-9);
  CHECK(J.cwiseAbs().maxCoeff() > 0.1);  // not all zero
}

TEST_CASE("linearize: jacobian of a user pipeline with a user stage, and bad sizes are named") {
  const auto r = nhdyn::presets::paper5();
  // A user stage after the inverse dynamics: wheel torques from (v, ω) torques.
  const double radius = 0.1, track = 0.4;
  const auto wheels = nhdyn::stage([&](const auto& tau) {
    using T = typename std::decay_t<decltype(tau)>::Scalar;
    Eigen::Matrix<T, 2, 1> w;
    w << T(radius / 2) * tau(0) - T(radius / track) * tau(1), T(radius / 2) * tau(0) + T(radius / track) * tau(1);
    return w;
  });
  const auto id = nhdyn::inverse_dynamics(r.chain, r.constraint);
  const auto pipeline = [&](const auto& e) { return wheels(id(q0, e, etad0)); };
  const auto J = nhdyn::jacobian(pipeline, eta0);
  const auto Jf = nhdyn::central_difference_jacobian(pipeline, eta0, 1e-6);
  CHECK(J.rows() == 2);
  CHECK(rel_err(J, Jf) < 1e-8);
  const Eigen::VectorXd bad(3);
  CHECK_THROWS_WITH(nhdyn::linearize_inverse_dynamics(r.chain, r.constraint, q0, bad, etad0),
                    Catch::Contains("eta has 3 entries"));
}

TEST_CASE("linearize: the linearizer skips only columns that vanish, and the rest equal full seeding") {
  const auto r = nhdyn::presets::paper5();
  const nhdyn::inverse_dynamics_linearizer lin(r.chain, r.constraint);
  // paper5: dual directions q₄, q₅ and η; not q₁, q₂ (the base's x and y, prismatic,
  // before every revolute joint) nor q₃ (the heading: a planar base under vertical gravity
  // turns freely); η̇ from the mass matrix.
  REQUIRE(lin.computed_columns() == std::vector<int>{3, 4, 5, 6, 7, 8});
  V13 z;
  z << q0, eta0, etad0;
  const auto id = nhdyn::inverse_dynamics(r.chain, r.constraint);
  const auto f = [&](const auto& x) { return id(x.template head<5>(), x.template segment<4>(5), x.template tail<4>()); };
  for (double s : {1.0, -0.3, 2.5}) {
    const V13 zs = s * z;
    const auto full = nhdyn::jacobian(f, zs);  // every column seeded (dual<double, 13>)
    const auto J = lin(zs.head<5>(), zs.segment<4>(5), zs.tail<4>()).J;
    // Columns 1–2 vanish in the full computation too: exactly, not just to rounding;
    // column 3 (the heading) to rounding.
    CHECK(full.leftCols(2).cwiseAbs().maxCoeff() == 0.0);
    CHECK(J.leftCols(3).cwiseAbs().maxCoeff() == 0.0);
    CHECK(full.col(2).cwiseAbs().maxCoeff() < 1e-15 * full.cwiseAbs().maxCoeff());
    // Each seeded derivative lane is computed by the same operations: the same numbers.
    CHECK((J.middleCols(3, 6) - full.middleCols(3, 6)).cwiseAbs().maxCoeff() == 0.0);
    // ∂τ/∂η̇ by CRBA (SᵀMS) against the η̇ lanes of the dual rne: a different algorithm,
    // equal to rounding.
    CHECK(rel_err(J.rightCols(4), full.rightCols(4)) < 1e-14);
  }
  // A user constraint may depend on any joint: nothing skipped. The same S as paper5's.
  const auto c = r.constraint;
  const auto user = nhdyn::make_constraint(
      5, 1, [c](const auto& q) { return c.A(q); }, [c](const auto& q) { return c.S(q); });
  const nhdyn::inverse_dynamics_linearizer lu(r.chain.dynamic_size(), user);
  CHECK(lu.computed_columns().size() == 9u);  // all of (q, η)
  const Eigen::VectorXd qd = q0, ed = eta0, edd = etad0;
  CHECK(rel_err(lu(qd, ed, edd).J, lin(q0, eta0, etad0).J) < 1e-13);
  // SᵀS ≠ I and an input map E ≠ S: ∂τ/∂η̇ = (SᵀE)⁻¹SᵀMS, against every column seeded.
  using MX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic>;
  const auto scaledS = scaled_S(c);
  const auto inputE = [c, scaledS](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    MX G(4, 4), W(1, 4);
    G << 1.0, 0.2, 0, 0, -0.1, 0.9, 0, 0.3, 0, 0, 1.2, 0.1, 0.2, 0, 0, 0.8;
    W << 0.3, -0.4, 0.1, 0.2;
    return Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>(scaledS(q) * G.cast<T>() +
                                                            Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>(c.A(q)).transpose() * W.cast<T>());
  };
  const auto userE = nhdyn::make_constraint(
      5, 1, [c](const auto& q) { return c.A(q); }, scaledS, nullptr, inputE);
  const auto dyn = r.chain.dynamic_size();
  const auto idE = nhdyn::inverse_dynamics(dyn, userE);
  const auto fE = [&](const auto& x) { return idE(x.head(5), x.segment(5, 4), x.tail(4)); };
  const Eigen::VectorXd zd = z;
  const auto fullE = nhdyn::jacobian(fE, zd);
  const auto JE = nhdyn::inverse_dynamics_linearizer(dyn, userE)(qd, ed, edd).J;
  INFO("linearizer:\n" << JE << "\nfull seeding:\n" << fullE);
  CHECK(rel_err(JE.leftCols(9), fullE.leftCols(9)) == 0.0);
  CHECK(rel_err(JE.rightCols(4), fullE.rightCols(4)) < 1e-13);
  CHECK(rel_err(JE, nhdyn::central_difference_jacobian(fE, zd, 1e-6)) < 1e-8);
  // The heading is skipped only when turning it is a symmetry. Each of these breaks it, and
  // the full computation then has a heading column far from zero: gravity not along the
  // heading axis; the heading's sign against the x–y orientation; a third base joint
  // sliding across the heading axis.
  {
    const V13 zs = z;
    auto tilted = r;
    tilted.chain = nhdyn::chain<double, 5>(r.chain.links(), Eigen::Vector3d(-9.7, 1.5, 0.8), "tilted");
    auto flipped = r;
    flipped.constraint.heading_sign = -r.constraint.heading_sign;
    for (const auto* m : {&tilted, &flipped}) {
      const nhdyn::inverse_dynamics_linearizer lm(m->chain, m->constraint);
      CHECK(lm.computed_columns().front() == 2);
      const auto idm = nhdyn::inverse_dynamics(m->chain, m->constraint);
      const auto fm = [&](const auto& x) { return idm(x.template head<5>(), x.template segment<4>(5), x.template tail<4>()); };
      const auto fullm = nhdyn::jacobian(fm, zs);
      CHECK(fullm.col(2).cwiseAbs().maxCoeff() > 1e-3);
      CHECK((lm(zs.head<5>(), zs.segment<4>(5), zs.tail<4>()).J.leftCols(9) - fullm.leftCols(9)).cwiseAbs().maxCoeff() == 0.0);
    }
    // A third base joint before the heading, sliding across the heading axis (inserted first,
    // massless, turning the frames after it by α = π/2 about the x axis, which is the heading
    // axis and gravity's: those stay parallel). Not a symmetry: the heading is seeded.
    std::vector<nhdyn::link<double>> links6{nhdyn::link<double>{nhdyn::joint_type::prismatic, std::numbers::pi / 2}};
    links6.insert(links6.end(), r.chain.begin(), r.chain.end());
    const nhdyn::chain<double> six(links6, r.chain.gravity(), "six");
    const nhdyn::differential_drive<double> dd6(6, 1, 2, 3, r.constraint.forward_offset, r.constraint.heading_sign);
    const nhdyn::inverse_dynamics_linearizer l6(six, dd6);
    const auto& cols6 = l6.computed_columns();
    CHECK(std::find(cols6.begin(), cols6.end(), 3) != cols6.end());
    Eigen::VectorXd z6(16);
    z6 << 0.3, q0, 0.2, eta0, -0.4, etad0;
    const auto id6 = nhdyn::inverse_dynamics(six, dd6);
    const auto f6 = [&](const auto& x) { return id6(x.head(6), x.segment(6, 5), x.tail(5)); };
    const auto full6 = nhdyn::jacobian(f6, z6);
    CHECK(full6.col(3).cwiseAbs().maxCoeff() > 1e-3);
    const auto J6 = l6(z6.head(6), z6.segment(6, 5), z6.tail(5)).J;
    CHECK((J6.leftCols(11) - full6.leftCols(11)).cwiseAbs().maxCoeff() == 0.0);
    CHECK(rel_err(J6.rightCols(5), full6.rightCols(5)) < 1e-14);
  }
  // A revolute joint first: a translation after it is not a symmetry; nothing skipped.
  auto links = std::vector<nhdyn::link<double>>(r.chain.begin(), r.chain.end());
  std::swap(links[0], links[2]);
  const nhdyn::chain<double> turned(links, r.chain.gravity(), "turned");
  const nhdyn::differential_drive<double> dd(5, 1, 2, 0, 0.0, -1.0);
  CHECK(nhdyn::inverse_dynamics_linearizer(turned, dd).computed_columns().size() == 9u);  // all of (q, η)
}
