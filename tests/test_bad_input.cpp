// Bad input never crashes and is never silently wrong (issue 6, docs/errors.md): every
// public function object, given wrong sizes, NaN or Inf, throws the documented exception
// (input_error for states, model_error for models, numerical_error for results that cannot
// be trusted) with a message naming what is wrong and where. Also the loaders: malformed,
// truncated, unknown fields and presets, huge numbers, missing files.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <limits>

#include <nhdyn/io/json.hpp>
#include <nhdyn/nhdyn.hpp>

using namespace nhdyn;
using Catch::Matchers::Contains;
using Eigen::VectorXd;

namespace {
constexpr double nan_ = std::numeric_limits<double>::quiet_NaN();
constexpr double inf_ = std::numeric_limits<double>::infinity();

nhdyn::link<double> good_link() {
  nhdyn::link<double> L;
  L.a = 0.5;
  L.mass = 2.0;
  L.com = vec3<double>(-0.25, 0, 0);
  L.inertia = box_inertia(2.0, 0.5, 0.05, 0.05);
  return L;
}
chain<double> two_links() { return chain<double>({good_link(), good_link()}, vec3<double>(0, -9.81, 0), "arm"); }

/// Runs f and returns the message of the exception E it must throw.
template <class E, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  FAIL("expected an exception");
  return {};
}

VectorXd with(VectorXd v, int i, double x) {
  v(i) = x;
  return v;
}
}  // namespace

TEST_CASE("bad input: a chain with a non-physical link names the link and the field") {
  const auto build = [](auto mutate) {
    auto L = good_link();
    mutate(L);
    return chain<double>({good_link(), L}, vec3<double>(0, 0, -9.81), "bad");
  };
  CHECK_THAT(message_of<model_error>([&] { build([](auto& L) { L.mass = -1; }); }),
             Contains("model 'bad', link 2, field 'mass'") && Contains("negative"));
  CHECK_THAT(message_of<model_error>([&] { build([](auto& L) { L.a = nan_; }); }),
             Contains("link 2, field 'a'") && Contains("not finite"));
  CHECK_THAT(message_of<model_error>([&] { build([](auto& L) { L.alpha = inf_; }); }), Contains("field 'alpha'"));
  CHECK_THAT(message_of<model_error>([&] { build([](auto& L) { L.theta = -inf_; }); }), Contains("field 'theta'"));
  CHECK_THAT(message_of<model_error>([&] { build([](auto& L) { L.d = nan_; }); }), Contains("field 'd'"));
  CHECK_THAT(message_of<model_error>([&] { build([](auto& L) { L.com(1) = inf_; }); }), Contains("field 'com'"));
  CHECK_THAT(message_of<model_error>([&] { build([](auto& L) { L.inertia(0, 1) = 0.3; }); }),
             Contains("field 'inertia'") && Contains("not symmetric"));
  CHECK_THAT(message_of<model_error>([&] { build([](auto& L) { L.inertia(2, 2) = -1; }); }),
             Contains("not positive semi-definite"));
  CHECK_THAT(message_of<model_error>([&] { build([](auto& L) { L.inertia = Eigen::Vector3d(1, 1, 5).asDiagonal(); }); }),
             Contains("triangle inequality"));
  CHECK_THAT(message_of<model_error>([] { chain<double>({}, vec3<double>::Zero(), "empty"); }), Contains("at least one link"));
  CHECK_THAT(message_of<model_error>([] { chain<double>({good_link()}, vec3<double>(0, nan_, 0), "g"); }),
             Contains("field 'gravity'"));
  CHECK_THROWS_AS(two_links().fixed<3>(), model_error);
}

TEST_CASE("bad input: rne, M(q), bias and forward dynamics reject wrong sizes naming the argument") {
  const auto ch = two_links();
  const VectorXd z2 = VectorXd::Zero(2), z3 = VectorXd::Zero(3), z1 = VectorXd::Zero(1);
  CHECK_THAT(message_of<input_error>([&] { rne(ch)(z3, z2, z2); }), Contains("q has 3 entries; the model needs 2"));
  CHECK_THAT(message_of<input_error>([&] { rne(ch)(z2, z1, z2); }), Contains("qd has 1"));
  CHECK_THAT(message_of<input_error>([&] { rne(ch)(z2, z2, z3); }), Contains("qdd has 3"));
  CHECK_THAT(message_of<input_error>([&] { mass_matrix(ch)(z1); }), Contains("q has 1"));
  CHECK_THAT(message_of<input_error>([&] { bias(ch)(z2, z3); }), Contains("qd has 3"));
  CHECK_THAT(message_of<input_error>([&] { forward_dynamics(ch)(z2, z2, z3); }), Contains("tau has 3"));
  CHECK_THAT(message_of<input_error>([&] { forward_dynamics(ch)(z3, z2, z2); }), Contains("q has 3"));
  // A compile-time-sized model given run-time-sized vectors of the wrong size: no overrun.
  const auto p5 = presets::paper5_chain<double>();
  const VectorXd z4 = VectorXd::Zero(4), z5 = VectorXd::Zero(5), z6 = VectorXd::Zero(6);
  CHECK_THAT(message_of<input_error>([&] { rne(p5)(z4, z4, z4); }), Contains("q has 4 entries; the model needs 5"));
  CHECK_THAT(message_of<input_error>([&] { rne(p5)(z5, z6, z5); }), Contains("qd has 6"));
  CHECK_THAT(message_of<input_error>([&] { mass_matrix(p5)(z6); }), Contains("q has 6"));
  CHECK_THAT(message_of<input_error>([&] { forward_dynamics(p5)(z5, z5, z4); }), Contains("tau has 4"));
  kinematics<double, 5> k5(p5);
  CHECK_THAT(message_of<input_error>([&] { k5.forward(z4); }), Contains("q has 4"));
  CHECK_THAT(message_of<input_error>([&] { k5.jdot_qdot(z5, z4, 5, vec3<double>::Zero()); }), Contains("qd has 4"));
  // A short q is reported, not read past its end (it was, before: issue 12).
  CHECK_THAT(message_of<input_error>([&] { k5.jdot_qdot(z4, z5, 5, vec3<double>::Zero()); }), Contains("q has 4"));
  CHECK_THAT(message_of<input_error>([&] { k5.jacobian(z6, 5); }), Contains("q has 6"));
  CHECK_THAT(message_of<input_error>([&] { k5.point(z4, 5); }), Contains("q has 4"));
}

TEST_CASE("bad input: NaN and Inf in a state are errors naming the entry, never NaN results") {
  const auto ch = two_links();
  const VectorXd z = VectorXd::Zero(2);
  for (const double bad : {nan_, inf_, -inf_}) {
    CHECK_THAT(message_of<input_error>([&] { rne(ch)(with(z, 1, bad), z, z); }), Contains("q[1] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { rne(ch)(z, with(z, 0, bad), z); }), Contains("qd[0] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { rne(ch)(z, z, with(z, 1, bad)); }), Contains("qdd[1] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { mass_matrix(ch)(with(z, 0, bad)); }), Contains("q[0] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { forward_dynamics(ch)(z, z, with(z, 1, bad)); }), Contains("tau[1]"));
    CHECK_THAT(message_of<input_error>([&] { forward_dynamics(ch)(z, with(z, 1, bad), z); }), Contains("qd[1]"));
    kinematics<double> k(ch);
    CHECK_THAT(message_of<input_error>([&] { k.forward(with(z, 0, bad)); }), Contains("q[0]"));
    CHECK_THAT(message_of<input_error>([&] { k.jacobian(with(z, 1, bad), 2); }), Contains("q[1]"));
    CHECK_THAT(message_of<input_error>([&] { k.jdot_qdot(z, with(z, 1, bad), 2); }), Contains("qd[1]"));
    CHECK_THAT(message_of<input_error>([&] { k.jdot_qdot(with(z, 0, bad), z, 2); }), Contains("q[0]"));
    CHECK_THAT(message_of<input_error>([&] { k.point(z, 2, vec3<double>(0, bad, 0)); }), Contains("p_i[1]"));
    CHECK_THAT(message_of<input_error>([&] { k.jacobian(z, 2, vec3<double>(bad, 0, 0)); }), Contains("p_i[0]"));
  }
  kinematics<double> k(ch);
  CHECK_THAT(message_of<input_error>([&] { k.frame(z, 3); }), Contains("link index 3"));
  CHECK_THAT(message_of<input_error>([&] { k.jacobian(z, -1); }), Contains("link index -1"));
}

TEST_CASE("bad input: a non-finite entry the result does not depend on is reported all the same") {
  // rne reads neither q nor q̇ of the joints before the first revolute one (a mobile base's
  // x and y: they only translate), and nothing of links after the last one with inertia can
  // reach v: NaN there gave a finite, plausible v. Every entry of every input, NaN or Inf,
  // must be an input_error naming it — rne on paper5 and on a base with a prismatic lift
  // joint and a massless tip link, and the nonholonomic inverse dynamics (fixed and
  // run-time sized, heading sin/cos shared with rne or not) naming q, eta, eta_dot.
  const auto p5 = presets::paper5_chain<double>();
  std::vector<nhdyn::link<double>> L{p5[0], p5[1]};
  nhdyn::link<double> lift_joint;
  lift_joint.joint = joint_type::prismatic;
  L.push_back(lift_joint);
  for (int i = 2; i < 5; ++i) L.push_back(p5[i]);
  nhdyn::link<double> tip;  // massless
  tip.a = 0.1;
  L.push_back(tip);
  const chain<double> lifted(L, p5.gravity(), "base, lift, arm, massless tip");
  for (const double bad : {nan_, inf_, -inf_}) {
    for (const auto& ch : {p5.dynamic_size(), lifted}) {
      const int n = ch.dof();
      const VectorXd z = VectorXd::Constant(n, 0.2);
      for (int i = 0; i < n; ++i) {
        const std::string at = "[" + std::to_string(i) + "] is not finite";
        CHECK_THAT(message_of<input_error>([&] { rne(ch)(with(z, i, bad), z, z); }), Contains("q" + at));
        CHECK_THAT(message_of<input_error>([&] { rne(ch)(z, with(z, i, bad), z); }), Contains("qd" + at));
        CHECK_THAT(message_of<input_error>([&] { rne(ch)(z, z, with(z, i, bad)); }), Contains("qdd" + at));
      }
      const int heading = n == 5 ? 2 : 3;
      for (const double offset : {0.0, 0.3}) {
        const differential_drive<double> c(n, 0, 1, heading, offset, -1.0);
        const auto id = inverse_dynamics(ch, c);
        const VectorXd e = VectorXd::Constant(n - 1, -0.1);
        for (int i = 0; i < n; ++i)
          CHECK_THAT(message_of<input_error>([&] { id(with(z, i, bad), e, e); }),
                     Contains("q[" + std::to_string(i) + "] is not finite"));
        for (int i = 0; i < n - 1; ++i) {
          CHECK_THAT(message_of<input_error>([&] { id(z, with(e, i, bad), e); }),
                     Contains("eta[" + std::to_string(i) + "] is not finite"));
          CHECK_THAT(message_of<input_error>([&] { id(z, e, with(e, i, bad)); }),
                     Contains("eta_dot[" + std::to_string(i) + "] is not finite"));
        }
      }
    }
    {  // Without velocity terms rne reads no q̇: η is still checked.
      const auto ch = p5.dynamic_size();
      const auto id = inverse_dynamics(ch, differential_drive<double>(5, 0, 1, 2, 0.0, -1.0), rne_options{true, false});
      const VectorXd z = VectorXd::Constant(5, 0.2), e = VectorXd::Constant(4, -0.1);
      for (int i = 0; i < 4; ++i)
        CHECK_THAT(message_of<input_error>([&] { id(z, with(e, i, bad), e); }),
                   Contains("eta[" + std::to_string(i) + "] is not finite"));
    }
    const auto r = presets::paper5<double>();
    const auto id = inverse_dynamics(r.chain, r.constraint);
    const Eigen::Matrix<double, 5, 1> q = Eigen::Matrix<double, 5, 1>::Constant(0.2);
    const Eigen::Matrix<double, 4, 1> e = Eigen::Matrix<double, 4, 1>::Constant(-0.1);
    for (int i = 0; i < 5; ++i) {
      Eigen::Matrix<double, 5, 1> qb = q;
      qb(i) = bad;
      CHECK_THAT(message_of<input_error>([&] { id(qb, e, e); }), Contains("q[" + std::to_string(i) + "] is not finite"));
    }
    for (int i = 0; i < 4; ++i) {
      Eigen::Matrix<double, 4, 1> eb = e;
      eb(i) = bad;
      CHECK_THAT(message_of<input_error>([&] { id(q, eb, e); }), Contains("eta[" + std::to_string(i) + "] is not finite"));
      CHECK_THAT(message_of<input_error>([&] { id(q, e, eb); }), Contains("eta_dot[" + std::to_string(i) + "] is not finite"));
    }
  }
}

TEST_CASE("finite_range: every kind of non-finite double and float is seen, no finite one, at any position") {
  using L = std::numeric_limits<double>;
  const std::vector<double> finite{0.0, -0.0, 1.0, -2.5, L::max(), L::lowest(), L::min(), L::denorm_min(), -L::denorm_min()};
  const std::vector<double> not_finite{L::infinity(), -L::infinity(), L::quiet_NaN(), -L::quiet_NaN(), L::signaling_NaN()};
  for (int pos : {0, 5, 16}) {  // first, middle, last of 17 (past a vector register's width)
    for (double x : finite) {
      VectorXd v = VectorXd::Constant(17, 3.0);
      v(pos) = x;
      CHECK(detail::finite_range(v, 0, 17));
      Eigen::VectorXf f = v.cast<float>();
      CHECK(detail::finite_range(f, 0, 17) == std::isfinite(float(x)));  // L::max() is +Inf as a float
    }
    for (double x : not_finite) {
      VectorXd v = VectorXd::Constant(17, 3.0);
      v(pos) = x;
      INFO("position " << pos << ", " << x);
      CHECK_FALSE(detail::finite_range(v, 0, 17));
      CHECK(detail::finite_range(v, 0, pos));  // the range before it is finite
      Eigen::VectorXf f = v.cast<float>();
      CHECK_FALSE(detail::finite_range(f, 0, 17));
    }
  }
  CHECK(detail::finite_range(VectorXd(0), 0, 0));
}

TEST_CASE("bad input: finite inputs whose result overflows are a numerical_error, not Inf") {
  const auto ch = two_links();
  const VectorXd z = VectorXd::Zero(2);
  CHECK_THAT(message_of<numerical_error>([&] { rne(ch)(z, VectorXd::Constant(2, 1e200), z); }),
             Contains("not finite although every input is"));
  CHECK_THROWS_AS(rne(ch)(z, z, VectorXd::Constant(2, 1e308)), numerical_error);
  CHECK_THROWS_AS(forward_dynamics(ch)(z, z, VectorXd::Constant(2, 1.7e308)), numerical_error);
}

TEST_CASE("bad input: the nonholonomic stages check sizes and finiteness of q, eta, eta_dot, v and tau") {
  const auto r = presets::paper5<double>();
  const auto id = inverse_dynamics(r.chain, r.constraint);
  const auto fd = nh_forward_dynamics(r.chain, r.constraint);
  const VectorXd q = VectorXd::Zero(5), e = VectorXd::Zero(4);
  CHECK_THAT(message_of<input_error>([&] { id(VectorXd::Zero(4), e, e); }), Contains("q has 4"));
  CHECK_THAT(message_of<input_error>([&] { id(q, VectorXd::Zero(5), e); }), Contains("eta has 5"));
  CHECK_THAT(message_of<input_error>([&] { id(q, e, VectorXd::Zero(3)); }), Contains("eta_dot has 3"));
  CHECK_THAT(message_of<input_error>([&] { fd(q, e, VectorXd::Zero(5)); }), Contains("tau has 5"));
  CHECK_THAT(message_of<input_error>([&] { fd(q, VectorXd::Zero(2), e); }), Contains("eta has 2"));
  CHECK_THAT(message_of<input_error>([&] { fd.reduced_inertia(VectorXd::Zero(4)); }), Contains("q has 4"));
  CHECK_THAT(message_of<input_error>([&] { fd.reduced_bias(q, VectorXd::Zero(3)); }), Contains("eta has 3"));
  CHECK_THAT(message_of<input_error>([&] { project(r.constraint)(q, VectorXd::Zero(4)); }), Contains("v has 4"));
  CHECK_THAT(message_of<input_error>([&] { project(r.constraint)(VectorXd::Zero(3), q); }), Contains("q has 3"));
  CHECK_THAT(message_of<input_error>([&] { constraint_forces(r.constraint)(VectorXd::Zero(6), q); }), Contains("q has 6"));
  for (const double bad : {nan_, inf_}) {
    CHECK_THAT(message_of<input_error>([&] { id(with(q, 2, bad), e, e); }), Contains("q[2] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { id(q, with(e, 0, bad), e); }), Contains("eta[0] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { id(q, e, with(e, 3, bad)); }), Contains("eta_dot[3] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { fd(q, with(e, 1, bad), e); }), Contains("eta[1] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { fd(with(q, 4, bad), e, e); }), Contains("q[4] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { fd(q, e, with(e, 2, bad)); }), Contains("tau[2] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { fd.reduced_inertia(with(q, 2, bad)); }), Contains("q[2] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { fd.reduced_bias(q, with(e, 3, bad)); }), Contains("eta[3] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { lift(r.constraint)(q, e, with(e, 1, bad)); }), Contains("eta_dot[1]"));
    CHECK_THAT(message_of<input_error>([&] { project(r.constraint)(with(q, 2, bad), q); }), Contains("q[2] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { project(r.constraint)(q, with(q, 4, bad)); }), Contains("v[4] is not finite"));
    CHECK_THAT(message_of<input_error>([&] { constraint_forces(r.constraint)(q, with(q, 0, bad)); }), Contains("v[0]"));
  }
  // Constraint and chain that do not match, a bad differential drive.
  CHECK_THAT(message_of<model_error>([&] { nh_forward_dynamics(two_links(), differential_drive<double>(3, 0, 1, 2)); }),
             Contains("constraint is over 3 joints, the chain has 2"));
  CHECK_THROWS_AS(differential_drive<double>(3, 0, 0, 2), model_error);
  CHECK_THROWS_AS(differential_drive<double>(3, 0, 1, 5), model_error);
  CHECK_THROWS_AS(differential_drive<double>(3, 0, 1, 2, 0.0, 2.0), model_error);
  CHECK_THROWS_AS(differential_drive<double>(3, 0, 1, 2, nan_), model_error);
  // every flaw named, one after another: "…: n = 0 but the chain has 5; …: joint index 1 outside 0…-1; …"
  CHECK(message_of<model_error>([&] { differential_drive<double, 5>(0, 1, 2, 0); }) ==
        "differential_drive: n = 0 but the chain has 5; differential_drive: joint index 1 outside 0…-1; "
        "differential_drive: joint index 2 outside 0…-1; differential_drive: joint index 0 outside 0…-1");
}

TEST_CASE("bad input: a user constraint whose functions return the wrong shapes is an input_error") {
  const auto ch = chain<double>({good_link(), good_link(), good_link()}, vec3<double>::Zero(), "three");
  const auto c = make_constraint(
      3, 1, [](const auto& q) { return Eigen::Matrix<typename std::decay_t<decltype(q)>::Scalar, -1, -1>::Zero(1, 2).eval(); },
      [](const auto& q) { return Eigen::Matrix<typename std::decay_t<decltype(q)>::Scalar, -1, -1>::Identity(3, 2).eval(); });
  const VectorXd q = VectorXd::Zero(3), e = VectorXd::Zero(2);
  CHECK_THAT(message_of<input_error>([&] { c.A(q); }), Contains("A(q) is 1×2, expected 1×3"));
  const auto bad_S = make_constraint(
      3, 1, [](const auto& q) { return Eigen::Matrix<typename std::decay_t<decltype(q)>::Scalar, -1, -1>::Zero(1, 3).eval(); },
      [](const auto& q) { return Eigen::Matrix<typename std::decay_t<decltype(q)>::Scalar, -1, -1>::Identity(3, 3).eval(); });
  CHECK_THAT(message_of<input_error>([&] { inverse_dynamics(ch, bad_S)(q, e, e); }), Contains("S(q) is 3×3, expected 3×2"));
}

TEST_CASE("ill-conditioning: a singular or near-singular SᵀE is an error, never a silent Inf") {
  const auto ch = chain<double>({good_link(), good_link(), good_link()}, vec3<double>::Zero(), "three");
  using M = Eigen::MatrixXd;
  const auto A = [](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    Eigen::Matrix<T, -1, -1> a = Eigen::Matrix<T, -1, -1>::Zero(1, 3);
    a(0, 2) = T(1);
    return a;
  };
  const auto S = [](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    return Eigen::Matrix<T, -1, -1>(Eigen::Matrix<T, -1, -1>::Identity(3, 2));
  };
  const auto none = [](const auto& q, const auto&) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    return Eigen::Matrix<T, -1, -1>(Eigen::Matrix<T, -1, -1>::Zero(3, 2));
  };
  const VectorXd q = VectorXd::Zero(3), e = VectorXd::Ones(2);
  for (const double eps : {0.0, 1e-17}) {
    // E drives joint 1 twice (and joint 2 only by eps): SᵀE = [[1, 1], [0, eps]].
    const auto E = [eps](const auto& q) {
      using T = typename std::decay_t<decltype(q)>::Scalar;
      Eigen::Matrix<T, -1, -1> m = Eigen::Matrix<T, -1, -1>::Zero(3, 2);
      m(0, 0) = m(0, 1) = T(1);
      m(1, 1) = T(eps);
      return m;
    };
    const auto c = make_constraint(3, 1, A, S, none, E);
    CHECK_THAT(message_of<numerical_error>([&] { inverse_dynamics(ch, c)(q, e, e); }), Contains("SᵀE is"));
    CHECK_THAT(message_of<numerical_error>([&] { inverse_dynamics(ch, c)(q, e, e); }),
               Contains(eps == 0 ? "singular" : "numerically singular"));
  }
  // A well-conditioned E passes and its condition number is what it is.
  const auto E_ok = [](const auto& q) {
    using T = typename std::decay_t<decltype(q)>::Scalar;
    Eigen::Matrix<T, -1, -1> m = Eigen::Matrix<T, -1, -1>::Zero(3, 2);
    m(0, 0) = T(2);
    m(1, 1) = T(1);
    return m;
  };
  const auto c_ok = make_constraint(3, 1, A, S, none, E_ok);
  CHECK(inverse_dynamics(ch, c_ok)(q, e, e).allFinite());
  CHECK(condition_number(M(c_ok.S(q).transpose() * c_ok.E(q))) == Approx(2.0));
}

TEST_CASE("ill-conditioning: tiny masses make M_eta near singular; the caller sees the condition number") {
  auto p = presets::paper5_parameters<double>{};
  const VectorXd q = (VectorXd(5) << 0, 0, 0.3, 0.5, -0.4).finished(), eta = VectorXd::Ones(4), tau = VectorXd::Ones(4);
  double previous = 0;
  for (const double f : {1.0, 1e-4, 1e-8, 1e-12}) {
    p.mass_factor = {1, 1, 1, f, f};  // arm links 0.1·f kg on a 9 kg platform
    const auto r = presets::paper5<double>(p);
    const auto fd = nh_forward_dynamics(r.chain, r.constraint);
    const double kappa = fd.reduced_inertia_condition(q);
    // Independent check: the eigenvalues of M_eta itself.
    const Eigen::MatrixXd Me = fd.reduced_inertia(q);
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Me).eigenvalues();
    // (both are double computations of an ill-conditioned matrix: they agree to about ε·κ)
    if (kappa < 1e12) CHECK(kappa == Approx(ev(3) / ev(0)).epsilon(1e-14 * kappa + 1e-12));
    CHECK(kappa > previous * 1e3);  // grows like 1/f
    previous = kappa;
    const auto ldl = ldlt_factor<double, 4>(Eigen::Matrix4d(Me), "M_eta", INFINITY);
    if (kappa < 1e12) CHECK(ldl.pivot_ratio() <= kappa * (1 + 1e-6));  // the pivot ratio is a lower bound
    if (kappa < 1e15) {
      CHECK(fd(q, eta, tau).allFinite());
    }
  }
  // κ past 1/ε, yet the problem is benign once M_η is scaled by its diagonal (the arm's rows
  // are tiny, not dependent): the forward dynamics answers, as long double does.
  p.mass_factor = {1, 1, 1, 1e-17, 1e-17};
  const auto r = presets::paper5<double>(p);
  const auto fd = nh_forward_dynamics(r.chain, r.constraint);
  CHECK(fd.reduced_inertia_condition(q) > 1e16);
  presets::paper5_parameters<long double> pl;
  pl.mass_factor = {1, 1, 1, 1e-17L, 1e-17L};
  const auto rl = presets::paper5<long double>(pl);
  const VectorXd a = fd(q, eta, tau);
  const VectorXd b = nh_forward_dynamics(rl.chain, rl.constraint)(q.cast<long double>().eval(), eta.cast<long double>().eval(),
                                                                  tau.cast<long double>().eval())
                         .cast<double>();
  CHECK((a - b).lpNorm<Eigen::Infinity>() <= 1e-12 * b.lpNorm<Eigen::Infinity>());
  // Near-dependent rows stay near-dependent after scaling: scaled pivot 1e-12, refused at a
  // threshold of 1e10 (the default is 1/ε), naming the matrix and the scaled pivot; the same
  // matrix with its rows scaled by 1e-8 is the same problem and gets the same verdict.
  Eigen::Matrix4d Ms = Eigen::Matrix4d::Identity();
  Ms.block<2, 2>(2, 2) << 1.0, 1.0 - 5e-13, 1.0 - 5e-13, 1.0;
  CHECK_THAT(message_of<numerical_error>([&] { ldlt_factor<double, 4>(Ms, "M_η = SᵀMS", 1e10); }),
             Contains("M_η = SᵀMS is numerically singular") && Contains("scaled pivot 3"));
  const Eigen::Vector4d d(1, 1e-8, 1, 1e-8);
  const Eigen::Matrix4d Ms_scaled = d.asDiagonal() * Ms * d.asDiagonal();
  const Eigen::Matrix4d I_scaled = d.asDiagonal() * Eigen::Matrix4d::Identity() * d.asDiagonal();  // κ = 1e16
  const auto factor = [](const Eigen::Matrix4d& A) { return ldlt_factor<double, 4>(A, "M", 1e10); };
  CHECK_THROWS_AS(factor(Ms_scaled), numerical_error);
  CHECK_NOTHROW(factor(I_scaled));
  // A massless tip makes M exactly singular: holonomic forward dynamics says so.
  auto L = good_link();
  L.mass = 0;
  L.inertia.setZero();
  L.com.setZero();
  const auto ch = chain<double>({good_link(), L}, vec3<double>::Zero(), "massless tip");
  CHECK(forward_dynamics(ch).mass_matrix_condition(VectorXd::Zero(2)) == inf_);
  CHECK_THAT(message_of<numerical_error>([&] { forward_dynamics(ch)(VectorXd::Zero(2), VectorXd::Zero(2), VectorXd::Zero(2)); }),
             Contains("mass matrix M(q) is not positive definite"));
}

// ---- loaders -------------------------------------------------------------------------

namespace {
std::string paper5_text() { return io::to_string(io::preset<double>("paper5")); }
std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  REQUIRE(p != std::string::npos);
  return s.replace(p, from.size(), to);
}
std::string load_error(const std::string& text) {
  return message_of<model_error>([&] { io::parse_model<double>(text, "file 'm.json'"); });
}
}  // namespace

TEST_CASE("bad input: a malformed or truncated model file is an error with its line and column") {
  const auto text = paper5_text();
  CHECK_THAT(load_error(""), Contains("file 'm.json'") && Contains("invalid JSON"));
  for (const std::size_t cut : {std::size_t(1), text.size() / 3, text.size() / 2, text.size() - 2})
    CHECK_THAT(load_error(text.substr(0, cut)), Contains("file 'm.json': invalid JSON") && Contains("line"));
  CHECK_THAT(load_error("{\"name\": \"x\",,}"), Contains("invalid JSON") && Contains("column"));
  CHECK_THAT(load_error("[1, 2]"), Contains("top level"));
  CHECK_THAT(load_error("{\"name\": \"x\", \"name\": \"y\", \"gravity\": [0, 0, 0], \"links\": []}"),
             Contains("duplicate key 'name'"));
}

TEST_CASE("bad input: a model file with wrong fields names the link and the field") {
  const auto text = paper5_text();
  CHECK_THAT(load_error(replace(text, "\"mass\": 9", "\"mass\": -9")), Contains("link 3, field 'mass'") && Contains("negative"));
  CHECK_THAT(load_error(replace(text, "\"mass\": 9", "\"mass\": \"heavy\"")), Contains("link 3, field 'mass'") && Contains("expected a number"));
  CHECK_THAT(load_error(replace(text, "\"mass\": 9", "\"mass\": 1e999")), Contains("too large for a double"));
  CHECK_THAT(load_error(replace(text, "\"mass\": 9", "\"mass\": 9, \"colour\": 1")), Contains("unknown field(s) 'colour'") && Contains("link 3"));
  CHECK_THAT(load_error(replace(text, "\"name\"", "\"nmae\"")), Contains("unknown field(s) 'nmae'"));
  CHECK_THAT(load_error(replace(text, "\"revolute\"", "\"rotary\"")), Contains("unknown joint type 'rotary'"));
  CHECK_THAT(load_error(replace(text, "\"differential_drive\"", "\"tracked\"")), Contains("unknown constraint type 'tracked'"));
  CHECK_THAT(load_error(replace(text, "\"heading\": 2", "\"heading\": 9")), Contains("field 'heading'") && Contains("outside"));
  CHECK_THAT(load_error(replace(text, "\"heading\": 2", "\"heading\": 1")), Contains("must differ"));
  CHECK_THAT(load_error(replace(text, "\"gravity\": [", "\"gravity\": [1, ")), Contains("field 'gravity'") && Contains("3 numbers"));
  CHECK_THAT(load_error(replace(text, "\"heading_sign\": -1", "\"heading_sign\": 0.5")), Contains("heading_sign"));
}

TEST_CASE("bad input: unknown presets and missing files say what is known") {
  CHECK_THAT(message_of<model_error>([] { io::preset<double>("paper6"); }), Contains("unknown preset 'paper6'") && Contains("paper5"));
  CHECK_THAT(message_of<model_error>([] { io::load<double>("/nonexistent/robot.json"); }), Contains("no such file, and not a preset"));
  CHECK_THAT(message_of<model_error>([] { io::load_model<double>(std::filesystem::temp_directory_path()); }), Contains("is a directory"));
  // Huge but finite numbers load; what they do to the dynamics is reported, not hidden.
  const auto path = std::filesystem::temp_directory_path() / "nhdyn_bad_input_huge.json";
  {
    std::ofstream(path) << replace(paper5_text(), "\"mass\": 9", "\"mass\": 1e300");
  }
  const auto m = io::load_model<double>(path);
  std::filesystem::remove(path);
  const auto id = inverse_dynamics(m.chain, *m.constraint);
  CHECK_THROWS_AS(id(VectorXd::Zero(5), VectorXd::Constant(4, 1e10), VectorXd::Constant(4, 1e10)), numerical_error);
}
