// Closed-loop and open-loop simulation of paper5 (simulation/simulation.hpp, scene.hpp):
// physics invariants (energy, no lateral slip), the paper's scene against paper5.md's
// expectation, sampled control, seeded noise, failure reporting and the scene format.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <set>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/simulation/free_motion.hpp>
#include <nhdyn/simulation/scene.hpp>
#include <nhdyn/simulation/simulation.hpp>

using namespace nhdyn;

namespace {
std::string scene_file(const std::string& name) { return std::string(NHDYN_SOURCE_DIR) + "/examples/scenes/" + name + ".json"; }
/// The runs of a shipped scene file; the names it uses are looked up in its own folder.
std::vector<run_spec> runs_of(const std::string& name) {
  const auto f = scene::open(scene_file(name));
  return scene::expand(f.j, f.dirs);
}

/// paper5, unforced (simulation/free_motion.hpp).
using unforced = free_motion<double, 5, differential_drive<double, 5>>;
inline unforced make_unforced() {
  const auto r = presets::paper5<double>();
  return unforced(r.chain, r.constraint);
}

vecN<double, 9> moving_start() {
  vecN<double, 9> x;
  x << -0.2, 1.0, 2.8, 1.9, 1.1, 0.5, -0.8, 2.0, -3.0;  // driving, turning, arm swinging
  return x;
}
}  // namespace

TEST_CASE("simulation: the unforced undamped constrained robot conserves energy, less drift at tighter tolerance") {
  const unforced u = make_unforced();
  const vecN<double, 9> x0 = moving_start();
  const double E0 = u.energy(x0);
  std::vector<double> out;
  for (int i = 0; i <= 500; ++i) out.push_back(0.01 * i);
  double prev = INFINITY;
  for (double tol : {1e-5, 1e-7, 1e-9}) {
    double drift = 0;
    const auto r = integrate<9>(u.rhs(), x0, 0.0, 5.0, {method::dopri5, 1e-3, tol, tol}, out,
                                [&](int, const vecN<double, 9>& x) { drift = std::max(drift, std::abs(u.energy(x) - E0)); });
    REQUIRE(r.success());
    CHECK(drift < 1e3 * tol * std::abs(E0));
    CHECK(drift < prev / 10);
    prev = drift;
  }
  // The stiff method conserves it too (it has no special structure for it; tolerance bound).
  double drift = 0;
  const auto r = integrate<9>(u.rhs(), x0, 0.0, 1.0, {method::rosenbrock4, 1e-3, 1e-8, 1e-8},
                              std::span<const double>(out.data(), 101),
                              [&](int, const vecN<double, 9>& x) { drift = std::max(drift, std::abs(u.energy(x) - E0)); });
  REQUIRE(r.success());
  CHECK(drift < 1e-4 * std::abs(E0));
}

TEST_CASE("simulation: the integrated base path never slips sideways (ṗ_b · z₃ = 0)") {
  const unforced u = make_unforced();
  std::vector<double> out;
  for (int i = 0; i <= 2000; ++i) out.push_back(0.001 * i);
  std::vector<vecN<double, 9>> xs;
  const auto r = integrate<9>(u.rhs(), moving_start(), 0.0, 2.0, {method::dopri5, 1e-3, 1e-10, 1e-10}, out,
                              [&](int, const vecN<double, 9>& x) { xs.push_back(x); });
  REQUIRE(r.success());
  // Base point p_b = (0, q₂, q₁) differentiated along the computed path; lateral axis
  // z₃ = (0, cos q₃, sin q₃) (paper5.md). Central differences: error O(h²) ≈ 1e-6 m/s.
  double worst = 0, speed = 0;
  for (std::size_t i = 1; i + 1 < xs.size(); ++i) {
    const Eigen::Vector2d v((xs[i + 1](1) - xs[i - 1](1)) / 0.002, (xs[i + 1](0) - xs[i - 1](0)) / 0.002);
    const Eigen::Vector2d z3(std::cos(xs[i](2)), std::sin(xs[i](2)));
    worst = std::max(worst, std::abs(v.dot(z3)));
    speed = std::max(speed, v.norm());
  }
  CHECK(speed > 0.1);
  CHECK(worst < 1e-5 * speed);
}

TEST_CASE("simulation: paper-circle succeeds with paper5.md's ≈3 mm tail error, the same under rk4 and dopri5") {
  const auto specs = runs_of("paper-circle");
  REQUIRE(specs.size() == 1);
  const auto a = simulate(specs[0]);
  REQUIRE(a.success);
  CHECK(a.max_tail_error > 0.002);
  CHECK(a.max_tail_error < 0.005);
  CHECK(a.peak_tau > 100);  // the start-up spike, paper5.md: ≈100–250 N
  CHECK(a.peak_tau < 250);
  CHECK(a.rows.rows() == 2001);
  CHECK(a.rows(2000, 0) == 20.0);
  auto s = specs[0];
  s.integrator = {method::rk4, 2e-3};
  const auto b = simulate(s);
  REQUIRE(b.success);
  CHECK(std::abs(a.max_tail_error - b.max_tail_error) < 1e-6);
  CHECK((a.rows - b.rows).cwiseAbs().maxCoeff() < 1e-3);
}

TEST_CASE("simulation: the stiff method with the closed loop's exact dual Jacobian follows dopri5 on paper-circle") {
  // rosenbrock4 differentiates the whole closed loop (plant forward dynamics, controller,
  // reference) on dual<double, 10> numbers; a wrong Jacobian would cost it its order and show
  // up as a different trajectory. Both at tight tolerances over the start-up transient.
  run_spec s;
  s.duration = 1.5;
  s.tail_from = 1.0;
  s.tail_tolerance = 1;  // not the criterion under test
  s.integrator = {method::dopri5, 1e-3, 1e-10, 1e-12};
  const auto a = simulate(s);
  s.integrator = {method::rosenbrock4, 1e-3, 1e-8, 1e-10};
  const auto b = simulate(s);
  REQUIRE(a.success);
  REQUIRE(b.success);
  REQUIRE(a.rows.rows() == b.rows.rows());
  // q, η (columns 1…9) and r (14…16) agree to the tolerances' level.
  CHECK((a.rows.middleCols(1, 9) - b.rows.middleCols(1, 9)).cwiseAbs().maxCoeff() < 1e-5);
  CHECK((a.rows.middleCols(14, 3) - b.rows.middleCols(14, 3)).cwiseAbs().maxCoeff() < 1e-6);
}

TEST_CASE("simulation: under zero-order hold τ is constant between samples and changes at them") {
  run_spec s;
  s.duration = 0.2;
  s.output_step = 0.001;
  s.sample_rate = 100;
  s.tail_from = 0;
  s.tail_tolerance = 1;
  const auto r = simulate(s);
  REQUIRE(r.success);
  REQUIRE(r.rows.rows() == 201);
  for (Eigen::Index i = 1; i < 200; ++i) {
    const bool sample = i % 10 == 0;
    const double jump = (r.rows.row(i).segment<4>(10) - r.rows.row(i - 1).segment<4>(10)).norm();
    if (sample)
      CHECK(jump > 0);
    else
      CHECK(jump == 0);
  }
}

TEST_CASE("simulation: seeded measurement noise is reproducible and differs between seeds") {
  run_spec s;
  s.duration = 0.5;
  s.sample_rate = 1000;
  s.noise_sigma = 0.0005;
  s.integrator = {method::rk4, 1e-3};
  s.tail_from = 0;
  s.tail_tolerance = 1;
  s.seed = 3;
  const auto a = simulate(s), b = simulate(s);
  s.seed = 4;
  const auto c = simulate(s);
  CHECK((a.rows - b.rows).cwiseAbs().maxCoeff() == 0);
  CHECK((a.rows - c.rows).cwiseAbs().maxCoeff() > 0);
  s.noise_sigma = 0;
  const auto quiet = simulate(s);
  // τ responds to the noise: K₀σ ≈ 0.2 m/s² of commanded acceleration.
  CHECK((a.rows.col(12) - quiet.rows.col(12)).cwiseAbs().maxCoeff() > 1e-3);
}

TEST_CASE("simulation: failing runs are reported as failed with their reason") {
  SECTION("absurd gains make the loop too stiff for the step budget") {
    run_spec s;
    s.gains.K0 = 1e8 * Eigen::Matrix3d::Identity();  // ω_n = 10⁴ rad/s
    s.gains.K1 = 2e4 * Eigen::Matrix3d::Identity();
    s.integrator.max_steps = 2000;
    const auto r = simulate(s);
    CHECK_FALSE(r.success);
    REQUIRE(r.failure);
    CHECK_THAT(*r.failure, Catch::Contains("too many steps") || Catch::Contains("NaN"));
    CHECK_THAT(*r.failure, Catch::Contains("at t = "));
  }
  SECTION("a NaN in the scene's start state") {
    run_spec s;
    s.eta0(1) = NAN;
    const auto r = simulate(s);
    CHECK_FALSE(r.success);
    CHECK_THAT(*r.failure, Catch::Contains("not finite"));
  }
  SECTION("a run that ends but misses the criterion says by how much") {
    run_spec s;
    s.duration = 1;
    s.tail_from = 0.5;
    s.tail_tolerance = 1e-6;
    const auto r = simulate(s);
    CHECK_FALSE(r.success);
    CHECK_THAT(*r.failure, Catch::Contains("tail error"));
    CHECK(std::isfinite(r.max_tail_error));
  }
}

TEST_CASE("scene: the shipped studies expand to paper5.md's designs") {
  const auto fact = runs_of("paper-factorial");
  REQUIRE(fact.size() == 16);
  std::set<std::array<double, 4>> combos;
  for (const auto& s : fact) {
    combos.insert({s.plant.d3_factor, s.plant.mass_factor[2], s.plant.a4_factor, s.plant.a5_factor});
    for (int i : {0, 1, 3, 4}) CHECK(s.plant.mass_factor[std::size_t(i)] == 1.0);
    for (double f : {s.plant.d3_factor, s.plant.mass_factor[2], s.plant.a4_factor, s.plant.a5_factor})
      CHECK((f == 0.9 || f == 1.1));
    CHECK(s.model.mass_factor[2] == 1.0);
    CHECK(s.sample_rate == 0);
  }
  CHECK(combos.size() == 16);
  const auto noise = runs_of("paper-noise");
  REQUIRE(noise.size() == 16);
  for (std::size_t i = 0; i < 16; ++i) {
    CHECK(noise[i].seed == i + 1);
    CHECK(noise[i].noise_sigma == 0.0005);
    CHECK(noise[i].sample_rate == 1000);
    CHECK(noise[i].plant.mass_factor[2] == 1.1);
    CHECK(noise[i].plant.d3_factor == 1.0);
  }
  const auto circle = runs_of("paper-circle")[0];
  CHECK(std::get<circle_reference>(circle.reference).omega == 2 * 3.14159265358979323846 / 20);
  CHECK(circle.q0(2) == 3.141592653589793);
  CHECK(circle.gains.K0(1, 1) == 400);
  CHECK(circle.gains.lambda == 0.02);
}

TEST_CASE("scene: names in a scene file resolve in its own folder, whatever the current folder") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("nhdyn_scene_dirs_" + std::to_string(::getpid()));
  fs::create_directories(dir / "mine");
  fs::create_directories(dir / "elsewhere");
  // A study in its own folder whose base is a scene of that folder, named by name.
  std::ofstream(dir / "mine" / "short.json") << R"({"name": "short", "duration": 0.5})";
  std::ofstream(dir / "mine" / "study.json")
      << R"({"name": "st", "study": {"base": "short", "factors": [{"name": "d", "path": "/duration", "levels": [0.25, 0.75]}]}})";
  const fs::path before = fs::current_path();
  fs::current_path(dir / "elsewhere");
  const auto f = scene::open((dir / "mine" / "study.json").string(), {});
  const auto runs = scene::expand(f.j, f.dirs);
  REQUIRE(runs.size() == 2);
  CHECK(runs[0].duration == 0.25);
  CHECK(runs[1].name == "st-d_0.75");
  // A name found nowhere: the error lists the folders looked in.
  try {
    scene::open("no-such-scene", {dir / "mine"});
    FAIL("no error");
  } catch (const input_error& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains("no-such-scene") && Catch::Contains((dir / "mine").string()));
  }
  fs::current_path(before);
  fs::remove_all(dir);
}

TEST_CASE("scene: unknown or malformed fields are errors naming the field") {
  const auto err = [](const std::string& text) {
    try {
      scene::expand(nlohmann::json::parse(text));
    } catch (const input_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(err(R"({"name": "x", "controller": {"K2": 1}})"), Catch::Contains("controller.K2"));
  CHECK_THAT(err(R"({"name": "x", "durations": 3})"), Catch::Contains("'durations'"));
  CHECK_THAT(err(R"({"name": "x", "integrator": {"method": "euler"}})"), Catch::Contains("euler"));
  CHECK_THAT(err(R"({"name": "x", "initial": {"q": [1, 2]}})"), Catch::Contains("initial.q"));
  CHECK_THAT(err(R"({"name": "x", "noise": {"sigma": 0.1}})"), Catch::Contains("no error"));  // checked at run time
  CHECK_THAT(err(R"({"name": "s", "study": {"base": {"name": "b"}, "factors": [{"path": "/duration", "levels": []}]}})"),
             Catch::Contains("levels"));
  CHECK_THROWS_WITH(simulate(scene::parse_run(nlohmann::json::parse(R"({"name": "x", "noise": {"sigma": 0.1}})"))),
                    Catch::Contains("sampled"));
}

TEST_CASE("simulation: CSV numbers read back bit for bit") {
  run_spec s;
  s.duration = 0.05;
  const auto r = simulate(s);
  const auto path = std::filesystem::temp_directory_path() / "nhdyn_test_simulation.csv";
  write_csv(path.string(), r);
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  CHECK(line == "t,q1,q2,q3,q4,q5,eta1,eta2,eta3,eta4,tau1,tau2,tau3,tau4,r_x,r_y,r_z,rd_x,rd_y,rd_z,err");
  Eigen::Index i = 0;
  while (std::getline(f, line)) {
    std::stringstream ss(line);
    std::string cell;
    for (Eigen::Index j = 0; std::getline(ss, cell, ','); ++j) CHECK(std::strtod(cell.c_str(), nullptr) == r.rows(i, j));
    ++i;
  }
  CHECK(i == r.rows.rows());
  std::filesystem::remove(path);
}

TEST_CASE("scene: Monte Carlo studies draw each run from its own seed, and a run replays alone from it") {
  const std::string base = R"("base": "paper-circle", "set": {"duration": 1.5, "success": {"tail_from": 1, "max_tail_error": 1}})";
  const auto study = [&](const std::string& mc) {
    const auto j = scene::json::parse(R"({"name": "mc", "study": {)" + base + R"(, "monte_carlo": )" + mc + R"(,
      "factors": [{"name": "m3", "path": "/plant/mass_factor/2", "distribution": {"uniform": [0.8, 1.2]}},
                  {"name": "d3", "path": "/plant/d3_factor", "distribution": {"normal": [1, 0.02]}},
                  {"name": "seed", "path": "/noise/seed", "distribution": {"integer": [1, 1000]}},
                  {"name": "K1", "path": "/controller/K1", "distribution": {"choice": [30, 40, 50]}}]}})");
    return scene::expand(j, {std::string(NHDYN_SOURCE_DIR) + "/examples/scenes"});
  };
  const auto a = study(R"({"runs": 12, "seed": 7})"), b = study(R"({"runs": 12, "seed": 7})"), c = study(R"({"runs": 12, "seed": 8})");
  REQUIRE(a.size() == 12);
  CHECK(a[0].name == "mc-00");
  CHECK(a[11].name == "mc-11");
  std::set<std::uint64_t> seeds;
  int differ = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    REQUIRE(a[k].run_seed);
    seeds.insert(*a[k].run_seed);
    CHECK(a[k].factors == b[k].factors);  // deterministic
    differ += a[k].factors != c[k].factors;
    CHECK(a[k].plant.mass_factor[2] >= 0.8);
    CHECK(a[k].plant.mass_factor[2] <= 1.2);
    CHECK(a[k].seed >= 1);
    CHECK(a[k].seed <= 1000);
    CHECK((a[k].gains.K1(0, 0) == 30 || a[k].gains.K1(0, 0) == 40 || a[k].gains.K1(0, 0) == 50));
  }
  CHECK(seeds.size() == 12);
  CHECK(differ == 12);
  // run 5 alone, from its seed: the same factors, the same simulation bit for bit
  const auto r = study(R"({"replay": [)" + std::to_string(*a[5].run_seed) + "]}");
  REQUIRE(r.size() == 1);
  CHECK(r[0].name == "mc-seed_" + std::to_string(*a[5].run_seed));
  CHECK(r[0].factors == a[5].factors);
  const run_result x = simulate(a[5]), y = simulate(r[0]);
  REQUIRE(x.success);
  CHECK(x.rows.rows() == y.rows.rows());
  CHECK((x.rows - y.rows).cwiseAbs().maxCoeff() == 0.0);
  // the draws follow their distributions: 4000 uniform draws have mean (lo+hi)/2 within 4σ
  const auto many = scene::expand(scene::json::parse(R"({"name": "u", "study": {)" + base + R"(, "monte_carlo": {"runs": 4000},
      "factors": [{"path": "/plant/d3_factor", "distribution": {"uniform": [0.5, 1.5]}}]}})"),
                                  {std::string(NHDYN_SOURCE_DIR) + "/examples/scenes"});
  double mean = 0;
  for (const auto& s : many) mean += s.plant.d3_factor / double(many.size());
  CHECK(std::abs(mean - 1.0) < 4 * std::sqrt(1.0 / 12 / 4000));
  // errors name the field
  const scene::search_path dirs{std::string(NHDYN_SOURCE_DIR) + "/examples/scenes"};
  const auto bad = [&](const std::string& factors, const std::string& mc) {
    return scene::json::parse(R"({"name": "bad", "study": {)" + base + R"(, "monte_carlo": )" + mc + R"(, "factors": )" + factors + "}}");
  };
  CHECK_THROWS_WITH(scene::expand(bad(R"([{"path": "/duration", "distribution": {"gamma": [1, 2]}}])", R"({"runs": 2})"), dirs),
                    Catch::Contains("unknown distribution 'gamma'"));
  CHECK_THROWS_WITH(scene::expand(bad(R"([{"path": "/duration", "levels": [1, 2]}])", R"({"runs": 2})"), dirs),
                    Catch::Contains("levels"));
  CHECK_THROWS_WITH(scene::expand(bad(R"([{"path": "/duration", "distribution": {"uniform": [2, 1]}}])", R"({"runs": 2})"), dirs),
                    Catch::Contains("lo ≤ hi"));
  CHECK_THROWS_WITH(scene::expand(bad(R"([])", R"({"runs": 0})"), dirs), Catch::Contains("monte_carlo.runs"));
  CHECK_THROWS_WITH(scene::expand(bad(R"([])", R"({"runs": 2, "replay": [5]})"), dirs), Catch::Contains("replay"));
  // integer and choice draws stay inside their ranges (the top of the unit interval excluded)
  const auto ints = scene::expand(scene::json::parse(R"({"name": "i", "study": {)" + base + R"(, "monte_carlo": {"runs": 3000},
      "factors": [{"path": "/noise/seed", "distribution": {"integer": [0, 2]}}]}})"), dirs);
  std::set<std::uint64_t> seen;
  for (const auto& s : ints) seen.insert(s.seed);
  CHECK(seen == std::set<std::uint64_t>{0, 1, 2});
}
