// Simulation of any robot (simulation/simulation.hpp simulate_closed_loop and simulate_robot,
// simulation/robot_scene.hpp): the generic engine against the paper5 path (a second
// implementation: tree kernels, tree kinematics, a run-time-sized constraint), physics
// invariants on the shipped mobile manipulator's robot file (no lateral slip of the base,
// tracking), plant–model mismatch by body name, and the scene format's errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/simulation/robot_scene.hpp>
#include <nhdyn/simulation/scene.hpp>

using namespace nhdyn;

namespace {
std::string source(const std::string& rel) { return std::string(NHDYN_SOURCE_DIR) + "/" + rel; }
std::vector<run_spec> runs_of(const std::string& rel) {
  const auto f = scene::open(source(rel));
  return scene::expand(f.j, f.dirs);
}
int column(const run_result& r, const std::string& name) {
  for (std::size_t j = 0; j < r.columns.size(); ++j)
    if (r.columns[j] == name) return int(j);
  FAIL("no column " << name);
  return -1;
}
}  // namespace

TEST_CASE("robot simulation: the generic engine on paper5 as a tree reproduces the paper5 path") {
  // paper-circle by simulate (chain kernels, compile-time sizes) and by simulate_robot (the
  // chain as a URDF-like tree, tree kernels and kinematics, dynamic sizes, the same
  // differential drive at run-time size): two implementations of one closed loop.
  run_spec s;  // paper-circle's numbers
  s.duration = 6;
  s.tail_from = 4;
  const run_result a = simulate(s);
  REQUIRE(a.success);
  const auto plant = presets::paper5<double>(s.plant), nominal = presets::paper5<double>(s.model);
  const differential_drive<double> c(5, 0, 1, 2, 0.0, -1.0);
  const Eigen::VectorXd q0 = s.q0, eta0 = s.eta0, mask = s.posture_mask;
  const run_result b = simulate_robot("paper5-tree", as_tree(plant.chain), as_tree(nominal.chain), c, 5,
                                      vec3<double>::Zero(), s.reference, s.gains, q0, eta0, mask, options_of(s),
                                      {"v", "omega", "q4", "q5"});
  REQUIRE(b.success);
  REQUIRE(a.rows.rows() == b.rows.rows());
  REQUIRE(a.rows.cols() == b.rows.cols());
  // same states, torques and errors; the adaptive step sequences may differ at rounding level
  CHECK((a.rows - b.rows).cwiseAbs().maxCoeff() <= 1e-6 * std::max(1.0, a.rows.cwiseAbs().maxCoeff()));
  CHECK(std::abs(a.max_tail_error - b.max_tail_error) <= 1e-8);
  CHECK(b.columns[1] == "q_joint1");
  CHECK(b.columns[6] == "eta_v");
  CHECK(b.columns[10] == "tau_v");
  CHECK(b.columns.back() == "err");
}

TEST_CASE("robot simulation: the shipped mobile manipulator tracks a circle from its robot file without slipping") {
  const auto runs = runs_of("examples/scenes/mobile-manipulator-circle.json");
  REQUIRE(runs.size() == 1);
  const run_result r = simulate_scene(runs[0]);
  INFO((r.failure ? *r.failure : std::string("ok")));
  REQUIRE(r.success);
  CHECK(r.max_tail_error < 0.01);
  CHECK(r.columns.size() == 1 + 19 + 2 * 18 + 7);
  const int x = column(r, "q_base_x"), y = column(r, "q_base_y"), yaw = column(r, "q_base_yaw");
  const int v = column(r, "eta_v"), err = column(r, "err");
  // no lateral slip: the base's velocity (central differences of x, y) along its lateral axis
  // is zero, while it drives at up to v; and it does drive (the circle needs the base)
  double lateral = 0, speed = 0;
  const double h = r.rows(1, 0) - r.rows(0, 0);
  for (Eigen::Index i = 1; i + 1 < r.rows.rows(); ++i) {
    const double vx = (r.rows(i + 1, x) - r.rows(i - 1, x)) / (2 * h), vy = (r.rows(i + 1, y) - r.rows(i - 1, y)) / (2 * h);
    const double psi = r.rows(i, yaw);
    lateral = std::max(lateral, std::abs(-std::sin(psi) * vx + std::cos(psi) * vy));
    speed = std::max(speed, std::abs(r.rows(i, v)));
  }
  CHECK(speed > 0.05);
  CHECK(lateral < 1e-3 * speed);
  // the error decays: the tail is far below the start's transient
  double early = 0;
  for (Eigen::Index i = 0; r.rows(i, 0) < 2; ++i) early = std::max(early, r.rows(i, err));
  CHECK(r.max_tail_error < early);
}

TEST_CASE("robot simulation: plant–model mismatch by body name, and the scene's errors name what is wrong") {
  auto s = runs_of("examples/scenes/mobile-manipulator-circle.json").front();
  s.duration = 2;
  s.tail_from = 1;
  s.tail_tolerance = 1;
  const run_result nominal = simulate_scene(s);
  REQUIRE(nominal.success);
  s.plant_mass = {{"arm_7_link", 1.5}, {"arm_6_link", 1.5}};  // a payload the model does not know (3x diverges)
  const run_result heavy = simulate_scene(s);
  INFO((heavy.failure ? *heavy.failure : std::string("ok")));
  REQUIRE(heavy.success);
  const int tau = column(heavy, "tau_arm_6_joint");
  CHECK(std::abs(heavy.rows(heavy.rows.rows() - 1, tau) - nominal.rows(nominal.rows.rows() - 1, tau)) > 1e-3);

  const auto fails = [&](auto edit, const std::string& what) {
    auto t = runs_of("examples/scenes/mobile-manipulator-circle.json").front();
    edit(t);
    CHECK_THROWS_WITH(simulate_scene(t), Catch::Contains(what));
  };
  fails([](run_spec& t) { t.task_frame = "no_such_frame"; }, "no_such_frame");
  fails([](run_spec& t) { t.q_start = Eigen::VectorXd::Zero(5); }, "initial.q");
  fails([](run_spec& t) { t.posture_joints = {"elbow"}; }, "elbow");
  fails([](run_spec& t) { t.plant_mass = {{"no_body", 2.0}}; }, "no_body");
  fails([](run_spec& t) { t.plant_mass = {{"gripper_link", 2.0}}; }, "merged into body 'arm_7_link'");
  // scene files: a robot that is not there, a task frame missing, paper5 with a task
  const auto parse = [](const std::string& text) { return scene::parse_run(scene::json::parse(text), {source("examples/scenes")}); };
  CHECK_THROWS_WITH(parse(R"({"name": "x", "robot": "nowhere.json", "task": {"frame": "tool_frame"}})"),
                    Catch::Contains("nowhere.json"));
  CHECK_THROWS_WITH(parse(R"({"name": "x", "robot": "../robots/mobile_manipulator.json"})"), Catch::Contains("task.frame"));
  CHECK_THROWS_WITH(parse(R"({"name": "x", "task": {"frame": "link5"}})"), Catch::Contains("link 5"));
  CHECK_THROWS_WITH(parse(R"({"name": "x", "robot": "../robots/mobile_manipulator.json", "task": {"frame": "tool_frame"},
                              "plant": {"mass_factor": [1, 2]}})"),
                    Catch::Contains("plant.mass_factor"));
  CHECK_THROWS_WITH(parse(R"({"name": "x", "robot": "../robots/mobile_manipulator.json", "task": {"frame": "tool_frame"},
                              "initial": {"q": []}})"),
                    Catch::Contains("initial.q"));
  // a study elsewhere whose base names its robot relative to the base's own folder
  const auto study = scene::json::parse(R"({"name": "far", "study": {"base": ")" + source("examples/scenes/mobile-manipulator-circle.json") +
                                        R"(", "set": {"duration": 0.5}, "factors": [{"path": "/controller/kN", "levels": [3, 4]}]}})");
  const auto far = scene::expand(study, {std::filesystem::temp_directory_path()});
  REQUIRE(far.size() == 2);
  CHECK(far[0].robot == source("examples/scenes/../robots/mobile_manipulator.json"));
  // simulate (paper5's) refuses a robot file rather than simulating paper5 instead
  auto t = runs_of("examples/scenes/mobile-manipulator-circle.json").front();
  CHECK_THROWS_WITH(simulate(t), Catch::Contains("simulate_scene"));
}
