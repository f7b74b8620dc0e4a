// Numerical stability at the extremes (issue 6; docs/accuracy.md, "Numerical stability"):
// float, double and long double evaluations against a 50-digit evaluation of the SAME
// model and inputs. Every parameter and input is first rounded to the scalar under test, and
// the 50-digit path computes with those rounded values exactly as given: what is measured is
// the algorithm's rounding error, not the representation error of the inputs (a heading of
// 1e6 rad held in a double is off by up to 6e-11 rad from the decimal 1e6 before nhdyn sees
// it; that is the input's error, not the algorithm's).
//
// The bounds asserted are the measured errors times a margin (×10 to ×30, rounded up to
// a power of ten or so); set NHDYN_PRINT_ERRORS=1 to print the measured table.
#define NHDYN_NO_FLOAT128  // the 50-digit reference needs no libquadmath
#include <catch2/catch.hpp>

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/eigen.hpp>
#include <cstdio>
#include <cstdlib>
#include <random>

#include <nhdyn/nhdyn.hpp>

using namespace nhdyn;

namespace {
using mp = boost::multiprecision::number<boost::multiprecision::cpp_bin_float<50>, boost::multiprecision::et_off>;
template <class T>
using vec = Eigen::Matrix<T, Eigen::Dynamic, 1>;

/// x rounded to S, held in T (the 50-digit path gets exactly the value S holds).
template <class S, class T>
T r(double x) {
  return T(S(x));
}
template <class S, class T>
vec<T> rv(std::initializer_list<double> xs) {
  vec<T> v(static_cast<Eigen::Index>(xs.size()));
  Eigen::Index i = 0;
  for (double x : xs) v(i++) = r<S, T>(x);
  return v;
}

/// A link from double parameters, rounded to S, in T. Box inertia of a slender link.
template <class S, class T>
nhdyn::link<T> make_link(joint_type j, double alpha, double a, double theta, double d, double m, double len) {
  nhdyn::link<T> L;
  L.joint = j;
  L.alpha = r<S, T>(alpha);
  L.a = r<S, T>(a);
  L.theta = r<S, T>(theta);
  L.d = r<S, T>(d);
  L.mass = r<S, T>(m);
  L.com = vec3<T>(r<S, T>(-0.5 * a), r<S, T>(0.01 * len), r<S, T>(0.02 * len));
  const double w = 0.1 * len;
  L.inertia = mat3<T>::Zero();
  L.inertia(0, 0) = r<S, T>(m * (2 * w * w) / 12);
  L.inertia(1, 1) = r<S, T>(m * (len * len + w * w) / 12);
  L.inertia(2, 2) = r<S, T>(m * (len * len + w * w) / 12);
  return L;
}

/// paper5 in T with parameters rounded to S. (The preset computes d3/2 etc. in its scalar;
/// building it in double and rounding keeps both paths on the same numbers.)
template <class S, class T>
chain<T, 5> paper5_in() {
  const auto c = presets::paper5_chain<double>();
  std::array<nhdyn::link<T>, 5> L{};
  for (int i = 0; i < 5; ++i) L[std::size_t(i)] = c[i].template cast<S>().template cast<T>();
  return chain<T, 5>(L, c.gravity().template cast<S>().template cast<T>(), "paper5");
}

/// A spatial chain of n joints with per-joint masses and lengths from the given functions,
/// twists cycling through 0, ±π/2, one prismatic joint in five.
template <class S, class T, class Mass, class Len>
chain<T> spatial_chain(int n, Mass mass, Len len) {
  std::vector<nhdyn::link<T>> L;
  const double twist[4] = {1.5707963267948966, 0.0, -1.5707963267948966, 0.3};
  for (int i = 0; i < n; ++i) {
    const double l = len(i);
    L.push_back(make_link<S, T>(i % 5 == 4 ? joint_type::prismatic : joint_type::revolute, twist[i % 4], l, 0.1 * (i % 3),
                                0.2 * l, mass(i), l));
  }
  return chain<T>(std::move(L), vec3<T>(r<S, T>(0.0), r<S, T>(0.0), r<S, T>(-9.81)), "spatial");
}

template <class S, class T>
vec<T> state(int n, double scale, unsigned seed, double speed = 1.0) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  vec<T> v(n);
  for (int i = 0; i < n; ++i) v(i) = r<S, T>(scale * u(g) * speed);
  return v;
}

/// Relative error, normwise (∞-norm) and worst componentwise, of x against the reference.
struct error {
  double normwise = 0, componentwise = 0;
};
template <class S>
error compare(const vec<S>& x, const vec<mp>& ref) {
  REQUIRE(x.size() == ref.size());
  mp nref = 0, nerr = 0;
  double comp = 0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const mp d = abs(mp(x(i)) - ref(i));
    if (abs(ref(i)) > nref) nref = abs(ref(i));
    if (d > nerr) nerr = d;
    if (abs(ref(i)) > 0) comp = std::max(comp, static_cast<double>(d / abs(ref(i))));
  }
  return {static_cast<double>(nerr / nref), comp};
}

bool print() { return std::getenv("NHDYN_PRINT_ERRORS") != nullptr; }

template <class S>
const char* name() {
  if constexpr (std::is_same_v<S, float>) return "float";
  else if constexpr (std::is_same_v<S, double>) return "double";
  else return "long double";
}

/// Evaluates case F in S and in 50 digits, prints, checks against the bound for S.
template <class S, class F>
error measure(const char* what, F f, double bound, double comp_bound = INFINITY) {
  const vec<S> x = f.template operator()<S, S>();
  const vec<mp> ref = f.template operator()<S, mp>();
  const error e = compare<S>(x, ref);
  if (print()) std::printf("| %s | %s | %.1e | %.1e |\n", what, name<S>(), e.normwise, e.componentwise);
  INFO(what << " in " << name<S>() << ": normwise " << e.normwise << ", componentwise " << e.componentwise);
  CHECK(e.normwise <= bound);
  CHECK(e.componentwise <= comp_bound);
  return e;
}

// Unit roundoffs, to state bounds as multiples of them.
template <class S>
constexpr double u() {
  return static_cast<double>(std::numeric_limits<S>::epsilon()) / 2;
}

}  // namespace

// ---------------------------------------------------------------------------------------

TEST_CASE("extremes: paper5 inverse and forward dynamics at joint speeds up to 1e4 rad/s") {
  const auto id = []<class S, class T>() {
    const auto ch = paper5_in<S, T>();
    const auto c = presets::paper5_constraint<T>();
    // v = 1e3 m/s, ω = 1e4 rad/s, arm joints ±1e4 rad/s.
    return vec<T>(inverse_dynamics(ch, c)(rv<S, T>({0.3, -0.2, 0.7, 0.5, -1.1}), rv<S, T>({1e3, 1e4, -1e4, 1e4}),
                                          rv<S, T>({10, -20, 30, 5})));
  };
  const auto fd = []<class S, class T>() {
    const auto ch = paper5_in<S, T>();
    const auto c = presets::paper5_constraint<T>();
    return vec<T>(nh_forward_dynamics(ch, c)(rv<S, T>({0.3, -0.2, 0.7, 0.5, -1.1}), rv<S, T>({1e3, 1e4, -1e4, 1e4}),
                                             rv<S, T>({1, 2, 3, 4})));
  };
  measure<float>("paper5 id, speeds 1e4 rad/s", id, 100 * u<float>());
  measure<double>("paper5 id, speeds 1e4 rad/s", id, 100 * u<double>());
  measure<long double>("paper5 id, speeds 1e4 rad/s", id, 100 * u<long double>());
  measure<float>("paper5 fd, speeds 1e4 rad/s", fd, 1000 * u<float>());
  measure<double>("paper5 fd, speeds 1e4 rad/s", fd, 1000 * u<double>());
  measure<long double>("paper5 fd, speeds 1e4 rad/s", fd, 1000 * u<long double>());
}

TEST_CASE("extremes: a heading of 1e6 rad costs nothing beyond the input's own rounding") {
  // The heading joint has θ⁰ = 0, so sin/cos see the input exactly; the library's sin/cos
  // (libm's, with exact argument reduction) are then correctly rounded or nearly so.
  const auto id = []<class S, class T>() {
    const auto ch = paper5_in<S, T>();
    const auto c = presets::paper5_constraint<T>();
    return vec<T>(inverse_dynamics(ch, c)(rv<S, T>({1e3, -2e3, 1e6, 0.5, -1.1}), rv<S, T>({1, 0.5, -1, 2}),
                                          rv<S, T>({0.1, -0.2, 0.3, 0.4})));
  };
  const auto fd = []<class S, class T>() {
    const auto ch = paper5_in<S, T>();
    const auto c = presets::paper5_constraint<T>();
    return vec<T>(nh_forward_dynamics(ch, c)(rv<S, T>({1e3, -2e3, -1e6, 0.5, -1.1}), rv<S, T>({1, 0.5, -1, 2}),
                                             rv<S, T>({1, 2, 3, 4})));
  };
  measure<float>("paper5 id, q3 = 1e6 rad", id, 100 * u<float>());
  measure<double>("paper5 id, q3 = 1e6 rad", id, 100 * u<double>());
  measure<long double>("paper5 id, q3 = 1e6 rad", id, 100 * u<long double>());
  measure<float>("paper5 fd, q3 = -1e6 rad", fd, 1000 * u<float>());
  measure<double>("paper5 fd, q3 = -1e6 rad", fd, 1000 * u<double>());
  measure<long double>("paper5 fd, q3 = -1e6 rad", fd, 1000 * u<long double>());
  // A joint with an angle offset θ⁰ ≠ 0: θ = θ⁰ + q is rounded before sin/cos; the library
  // corrects sin/cos for that rounding (compensated sum), so the error stays at the ulp level.
  const auto offset = []<class S, class T>() {
    auto ch = spatial_chain<S, T>(3, [](int) { return 2.0; }, [](int) { return 0.5; });
    return vec<T>(rne(ch)(rv<S, T>({1e6, -3e5 - 0.25, 0.4}), rv<S, T>({1, -2, 0.5}), rv<S, T>({0.5, 1, -1})));
  };
  // The same for the differential drive's heading ψ = −q₃ + forward offset (an offset of
  // 0.3 rad: the platform's forward axis turned from the DH x axis).
  const auto drive_offset = []<class S, class T>() {
    const auto ch = paper5_in<S, T>();
    const differential_drive<T, 5> c(5, 0, 1, 2, r<S, T>(0.3), T(-1));
    return vec<T>(inverse_dynamics(ch, c)(rv<S, T>({1e3, -2e3, 1e6 + 0.1, 0.5, -1.1}), rv<S, T>({1, 0.5, -1, 2}),
                                          rv<S, T>({0.1, -0.2, 0.3, 0.4})));
  };
  measure<float>("paper5 id, q3 = 1e6 rad, heading offset 0.3 rad", drive_offset, 100 * u<float>());
  measure<double>("paper5 id, q3 = 1e6 rad, heading offset 0.3 rad", drive_offset, 100 * u<double>());
  measure<long double>("paper5 id, q3 = 1e6 rad, heading offset 0.3 rad", drive_offset, 100 * u<long double>());
  measure<float>("3-joint chain id, q = 1e6 with θ⁰ ≠ 0", offset, 1000 * u<float>());
  measure<double>("3-joint chain id, q = 1e6 with θ⁰ ≠ 0", offset, 1000 * u<double>());
  measure<long double>("3-joint chain id, q = 1e6 with θ⁰ ≠ 0", offset, 1000 * u<long double>());
}

TEST_CASE("extremes: the arm stretched straight and within 1e-12 rad of it") {
  for (const double q5 : {0.0, 1e-12}) {
    const auto id = [q5]<class S, class T>() {
      const auto ch = paper5_in<S, T>();
      const auto c = presets::paper5_constraint<T>();
      return vec<T>(inverse_dynamics(ch, c)(rv<S, T>({0.1, 0.2, 0.3, 0.4, q5}), rv<S, T>({0.5, 1, 2, -2}),
                                            rv<S, T>({1, -1, 3, 4})));
    };
    const auto fd = [q5]<class S, class T>() {
      const auto ch = paper5_in<S, T>();
      const auto c = presets::paper5_constraint<T>();
      return vec<T>(nh_forward_dynamics(ch, c)(rv<S, T>({0.1, 0.2, 0.3, 0.4, q5}), rv<S, T>({0.5, 1, 2, -2}),
                                               rv<S, T>({1, 2, 3, 4})));
    };
    // The arm's tip Jacobian (task space, 3×5 linear part): its entries are fine; what is lost
    // near the singularity is its smallest singular value, a property of J, not of the code.
    const auto jac = [q5]<class S, class T>() {
      const auto ch = paper5_in<S, T>();
      const kinematics<T, 5> k(ch);
      const auto J = k.jacobian(rv<S, T>({0.1, 0.2, 0.3, 0.4, q5}), 5);
      vec<T> v(15);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 5; ++j) v(3 * j + i) = J(i, j);
      return v;
    };
    const std::string tag = q5 == 0 ? "q5 = 0 (stretched)" : "q5 = 1e-12";
    measure<float>(("paper5 id, " + tag).c_str(), id, 100 * u<float>());
    measure<double>(("paper5 id, " + tag).c_str(), id, 100 * u<double>());
    measure<long double>(("paper5 id, " + tag).c_str(), id, 100 * u<long double>());
    measure<float>(("paper5 fd, " + tag).c_str(), fd, 1000 * u<float>());
    measure<double>(("paper5 fd, " + tag).c_str(), fd, 1000 * u<double>());
    measure<long double>(("paper5 fd, " + tag).c_str(), fd, 1000 * u<long double>());
    measure<float>(("paper5 tip Jacobian, " + tag).c_str(), jac, 100 * u<float>());
    measure<double>(("paper5 tip Jacobian, " + tag).c_str(), jac, 100 * u<double>());
    measure<long double>(("paper5 tip Jacobian, " + tag).c_str(), jac, 100 * u<long double>());
  }
}

TEST_CASE("extremes: masses from 1e-9 to 1e6 kg in one chain") {
  // Heavy base to light tip and the reverse: 16 joints, masses 10^(6 − i) or 10^(−9 + i).
  for (const bool heavy_base : {true, false}) {
    const auto mass = [heavy_base](int i) { return std::pow(10.0, heavy_base ? 6 - i : -9 + i); };
    const auto id = [mass]<class S, class T>() {
      const auto ch = spatial_chain<S, T>(16, mass, [](int) { return 0.4; });
      return vec<T>(rne(ch)(state<S, T>(16, 1.0, 1), state<S, T>(16, 1.0, 2), state<S, T>(16, 1.0, 3)));
    };
    const std::string tag = heavy_base ? "1e6 → 1e-9 kg" : "1e-9 → 1e6 kg";
    // The light links' torques are small beside the heavy ones': normwise they are exact to
    // rounding; componentwise each torque is exact to rounding of the links it carries.
    measure<float>(("16-joint id, masses " + tag).c_str(), id, 100 * u<float>(), 1e4 * u<float>());
    measure<double>(("16-joint id, masses " + tag).c_str(), id, 100 * u<double>(), 1e4 * u<double>());
    measure<long double>(("16-joint id, masses " + tag).c_str(), id, 100 * u<long double>(), 1e4 * u<long double>());
    // Forward dynamics: M spans 15 orders of magnitude. κ(M) is enormous, yet LDLᵀ is
    // invariant under the diagonal scaling that removes most of it (van der Sluis), so the
    // error follows the scaled condition number, not κ(M).
    const auto fd = [mass]<class S, class T>() {
      const auto ch = spatial_chain<S, T>(16, mass, [](int) { return 0.4; });
      return vec<T>(forward_dynamics(ch)(state<S, T>(16, 1.0, 1), state<S, T>(16, 1.0, 2), state<S, T>(16, 1.0, 3)));
    };
    const double kappa = forward_dynamics(spatial_chain<double, double>(16, mass, [](int) { return 0.4; }))
                             .mass_matrix_condition(state<double, double>(16, 1.0, 1));
    if (print()) std::printf("| (κ(M) = %.1e) | | | |\n", kappa);
    CHECK(kappa > 1e13);
    // float: the heavy-base chain is benign once scaled (scaled κ ≈ 7) and is answered to a
    // few ulps; the light-base one (scaled κ ≈ 1.3e13 > 1/ε of float) is refused.
    if (heavy_base)
      measure<float>(("16-joint fd, masses " + tag).c_str(), fd, 100 * u<float>());
    else
      CHECK_THROWS_AS(measure<float>(("16-joint fd, masses " + tag).c_str(), fd, 1.0), numerical_error);
    // Measured: heavy base ~2u (scaled κ ≈ 7); light base ~1e12·u (scaled κ ≈ 1.3e13).
    const double k = heavy_base ? 100 : 3e13;
    measure<double>(("16-joint fd, masses " + tag).c_str(), fd, k * u<double>());
    measure<long double>(("16-joint fd, masses " + tag).c_str(), fd, k * u<long double>());
  }
}

TEST_CASE("extremes: link lengths from 1e-6 to 1e3 m in one chain") {
  const auto len = [](int i) { return std::pow(10.0, -6 + (i % 10)); };
  const auto id = [len]<class S, class T>() {
    const auto ch = spatial_chain<S, T>(10, [](int) { return 1.0; }, len);
    return vec<T>(rne(ch)(state<S, T>(10, 1.0, 4), state<S, T>(10, 1.0, 5), state<S, T>(10, 1.0, 6)));
  };
  const auto fd = [len]<class S, class T>() {
    const auto ch = spatial_chain<S, T>(10, [](int) { return 1.0; }, len);
    return vec<T>(forward_dynamics(ch)(state<S, T>(10, 1.0, 4), state<S, T>(10, 1.0, 5), state<S, T>(10, 1.0, 6)));
  };
  measure<float>("10-joint id, lengths 1e-6 … 1e3 m", id, 100 * u<float>());
  measure<double>("10-joint id, lengths 1e-6 … 1e3 m", id, 100 * u<double>());
  measure<long double>("10-joint id, lengths 1e-6 … 1e3 m", id, 100 * u<long double>());
  CHECK_THROWS_AS(measure<float>("10-joint fd, lengths 1e-6 … 1e3 m", fd, 1.0), numerical_error);
  // Measured ~9e13·u in both: the scaled condition number of M is 7e14 (docs/accuracy.md).
  measure<double>("10-joint fd, lengths 1e-6 … 1e3 m", fd, 3e15 * u<double>());
  measure<long double>("10-joint fd, lengths 1e-6 … 1e3 m", fd, 3e15 * u<long double>());
}

TEST_CASE("extremes: chains of 256 joints") {
  constexpr int n = 256;
  const auto mass = [](int) { return 1.0; };
  const auto len = [](int) { return 0.1; };
  const auto id = [&]<class S, class T>() {
    const auto ch = spatial_chain<S, T>(n, mass, len);
    return vec<T>(rne(ch)(state<S, T>(n, 1.0, 7), state<S, T>(n, 1.0, 8), state<S, T>(n, 1.0, 9)));
  };
  const auto M = [&]<class S, class T>() {
    const auto ch = spatial_chain<S, T>(n, mass, len);
    const auto Mq = mass_matrix(ch)(state<S, T>(n, 1.0, 7));
    return vec<T>(Eigen::Map<const vec<T>>(Mq.data(), Mq.size()));
  };
  const auto fd = [&]<class S, class T>() {
    const auto ch = spatial_chain<S, T>(n, mass, len);
    return vec<T>(forward_dynamics(ch)(state<S, T>(n, 1.0, 7), state<S, T>(n, 1.0, 8), state<S, T>(n, 1.0, 9)));
  };
  measure<float>("256-joint id", id, 300 * u<float>());
  measure<double>("256-joint id", id, 300 * u<double>());
  measure<long double>("256-joint id", id, 300 * u<long double>());
  measure<float>("256-joint M(q)", M, 300 * u<float>());
  measure<double>("256-joint M(q)", M, 300 * u<double>());
  measure<long double>("256-joint M(q)", M, 300 * u<long double>());
  measure<double>("256-joint fd", fd, 1e8 * u<double>());
  measure<long double>("256-joint fd", fd, 1e8 * u<long double>());
  const double kappa = forward_dynamics(spatial_chain<double, double>(n, mass, len)).mass_matrix_condition(state<double, double>(n, 1.0, 7));
  if (print()) std::printf("| (256 joints: κ(M) = %.1e) | | | |\n", kappa);
}
