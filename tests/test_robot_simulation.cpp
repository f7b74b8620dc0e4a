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
                                      vec3<double>::Zero(), std::get<circle_reference>(s.reference), s.gains, q0, eta0, mask, options_of(s),
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

TEST_CASE("robot simulation: the mecanum base translates sideways while its tool follows a drifting circle") {
  const auto runs = runs_of("examples/scenes/mecanum-sideways-circle.json");
  REQUIRE(runs.size() == 1);
  const run_result r = simulate_scene(runs[0]);
  INFO((r.failure ? *r.failure : std::string("ok")));
  REQUIRE(r.success);
  CHECK(r.max_tail_error < 1e-4);
  CHECK(r.columns.size() == 1 + 12 + 8 + 9 + 7);  // q, η = (base_x, base_y, base_yaw, arm), τ = 4 wheels + arm
  CHECK(r.columns[1 + 12 + 8] == "tau_wheel_fl_joint");
  const int y = column(r, "q_base_y"), yaw = column(r, "q_base_yaw"), x = column(r, "q_base_x");
  double worst_yaw = 0, travel_x = 0;
  for (Eigen::Index i = 0; i < r.rows.rows(); ++i) {
    worst_yaw = std::max(worst_yaw, std::abs(r.rows(i, yaw)));
    travel_x = std::max(travel_x, std::abs(r.rows(i, x)));
  }
  // sideways: 1.9 m along y at a heading within 0.1 rad, never more than 0.3 m along x
  CHECK(r.rows(r.rows.rows() - 1, y) > 1.9);
  CHECK(worst_yaw < 0.1);
  CHECK(travel_x < 0.3);
  // the integrated wheel angles turn at the textbook mecanum rates of the integrated base motion
  // (Lynch and Park eq. 13.10; both by central differences of the output rows)
  const double R = 0.0475, l = 0.228, w = 0.158, h = r.rows(1, 0) - r.rows(0, 0);
  const int fl = column(r, "q_wheel_fl_joint"), fr = column(r, "q_wheel_fr_joint"), rl = column(r, "q_wheel_rl_joint"),
            rr = column(r, "q_wheel_rr_joint");
  double worst = 0, peak = 0;
  for (Eigen::Index i = 1; i + 1 < r.rows.rows(); ++i) {
    const auto d = [&](int col) { return (r.rows(i + 1, col) - r.rows(i - 1, col)) / (2 * h); };
    const double psi = r.rows(i, yaw), vx = std::cos(psi) * d(x) + std::sin(psi) * d(y),
                 vy = -std::sin(psi) * d(x) + std::cos(psi) * d(y), om = d(yaw);
    const double expect[4] = {(vx - vy - (l + w) * om) / R, (vx + vy + (l + w) * om) / R, (vx + vy - (l + w) * om) / R,
                              (vx - vy + (l + w) * om) / R};
    const int cols[4] = {fl, fr, rl, rr};
    for (int k = 0; k < 4; ++k) {
      worst = std::max(worst, std::abs(d(cols[k]) - expect[k]));
      peak = std::max(peak, std::abs(expect[k]));
    }
  }
  CHECK(peak > 1);  // the wheels do turn
  CHECK(worst < 1e-4 * peak);  // central differences of 10 ms output steps: 1e-5 seen
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

TEST_CASE("robot simulation: any model a scene names — a URDF arm (holonomic) on a line, a preset under computed torque") {
  const auto parse = [](const std::string& text) { return scene::parse_run(scene::json::parse(text), {source("examples/scenes")}); };
  // The URDF puma560 (fixed base, no constraint: S = I), its tool point from q0 to 12 cm away on a
  // straight line in 1.5 s, by the task-space controller.
  const tree<double> puma = io::load_urdf(source("examples/urdf/puma560.urdf"));
  const tree_kinematics<double> kin(puma);
  Eigen::VectorXd q0(6);
  q0 << 0.1, -0.6, 0.4, 0.3, -0.5, 0.7;
  const Eigen::Vector3d a = kin.point(q0, 6), b = a + Eigen::Vector3d(0.08, -0.06, 0.06);
  std::ostringstream text;
  text.precision(17);
  text << R"({"name": "puma-line", "robot": "../urdf/puma560.urdf", "task": {"frame": "link6"},
              "initial": {"q": [0.1, -0.6, 0.4, 0.3, -0.5, 0.7]},
              "reference": {"type": "line", "from": [)" << a(0) << ", " << a(1) << ", " << a(2) << R"(], "to": [)"
       << b(0) << ", " << b(1) << ", " << b(2) << R"(], "start": 0.2, "end": 1.7},
              "duration": 2.5, "success": {"tail_from": 1.7, "max_tail_error": 1e-3}})";
  const run_spec line = parse(text.str());
  const run_result r = simulate_scene(line);
  INFO((r.failure ? *r.failure : std::string("ok")));
  REQUIRE(r.success);
  CHECK(r.columns.size() == 1 + 6 + 2 * 6 + 7);
  CHECK(r.columns[1 + 6] == "eta_joint1");
  const int rx = column(r, "r_x");
  CHECK((r.rows.row(r.rows.rows() - 1).segment<3>(rx).transpose() - b).norm() < 1e-3);

  // The preset puma560 (a DH chain, as a tree) under computed torque along a joint spline.
  const run_spec ct = parse(R"({"name": "puma-ct", "robot": "puma560", "task": {"frame": "link6"},
      "controller": {"type": "computed_torque", "kp": 400, "kd": 40},
      "initial": {"q": [0.05, -0.55, 0.45, 0.25, -0.45, 0.75]},
      "reference": {"type": "joint_spline", "times": [0, 1, 2],
                    "q": [[0, -0.6, 0.4, 0.3, -0.5, 0.7], [0.5, -0.3, 0.6, 0, 0, 1], [0.2, -0.5, 0.5, 0.2, -0.2, 0.9]]},
      "duration": 2.5, "success": {"tail_from": 2, "max_tail_error": 1e-4}})");
  const run_result c = simulate_scene(ct);
  INFO((c.failure ? *c.failure : std::string("ok")));
  REQUIRE(c.success);
  const auto& last = c.rows.row(c.rows.rows() - 1);
  const Eigen::VectorXd qe = last.segment(1, 6).transpose(), qref = (Eigen::VectorXd(6) << 0.2, -0.5, 0.5, 0.2, -0.2, 0.9).finished();
  CHECK((qe - qref).norm() < 1e-4);

  // errors: the computed-torque controller with a task-space reference or task-space gains,
  // unknown reference types and fields, badly formed waypoints
  const auto base = std::string(R"({"name": "x", "robot": "puma560", "task": {"frame": "link6"}, )");
  CHECK_THROWS_WITH(parse(base + R"("controller": {"type": "computed_torque"}})"), Catch::Contains("joint-space reference"));
  CHECK_THROWS_WITH(parse(base + R"("controller": {"type": "computed_torque", "K0": 3}, "reference": {"type": "joint_spline", "times": [0, 1], "q": [[0,0,0,0,0,0],[0,0,0,0,0,0]]}})"),
                    Catch::Contains("controller.K0"));
  CHECK_THROWS_WITH(parse(base + R"("controller": {"kp": 3}})"), Catch::Contains("controller.kp"));
  CHECK_THROWS_WITH(parse(base + R"("controller": {"type": "pid"}})"), Catch::Contains("controller.type"));
  CHECK_THROWS_WITH(parse(base + R"("reference": {"type": "spiral"}})"), Catch::Contains("reference.type"));
  CHECK_THROWS_WITH(parse(base + R"("reference": {"type": "line", "from": [0,0,0], "to": [1,0,0]}})"), Catch::Contains("reference.end"));
  CHECK_THROWS_WITH(parse(base + R"("reference": {"type": "line", "from": [0,0,0], "to": [1,0,0], "end": 1, "radius": 2}})"),
                    Catch::Contains("reference.radius"));
  CHECK_THROWS_WITH(parse(base + R"("reference": {"type": "spline", "times": [0, 2, 1], "points": [[0,0,0],[1,0,0],[0,1,0]]}})"),
                    Catch::Contains("increase strictly"));
  CHECK_THROWS_WITH(parse(base + R"("reference": {"type": "spline", "times": [0, 1], "points": [[0,0,0],[1,0]]}})"),
                    Catch::Contains("reference.points"));
  CHECK_THROWS_WITH(parse(base + R"("reference": {"type": "spline", "times": [0, 1, 2], "points": [[0,0,0],[1,0,0]]}})"),
                    Catch::Contains("3 times for 2 waypoints"));
  auto wrong = parse(base + R"("controller": {"type": "computed_torque"}, "reference": {"type": "joint_spline", "times": [0, 1], "q": [[0,0],[0,0]]}})");
  CHECK_THROWS_WITH(simulate_scene(wrong), Catch::Contains("waypoints of 2 joints, the robot has 6"));
  CHECK_THROWS_WITH(parse(R"({"name": "x", "robot": "puma561", "task": {"frame": "link6"}})"), Catch::Contains("puma560_motors"));
  auto world = parse(R"({"name": "x", "robot": "puma560", "task": {"frame": "link6"}})");
  world.task_frame = "base";
  CHECK_THROWS_WITH(simulate_scene(world), Catch::Contains("fixed to the world"));
}

TEST_CASE("robot simulation: length factors scale joint placements as the DH lengths would; constraints follow them") {
  // with_length_factors on puma560 as a tree = the DH chain with d₃ and a₃ scaled, as a tree
  const auto chain = presets::puma560<double>();
  const double f = 1.3;
  std::vector<nhdyn::link<double>> links(chain.begin(), chain.end());
  links[2].d *= f, links[2].a *= f;
  const tree<double> scaled = with_length_factors(as_tree(chain), {{"joint3", f}}, "");
  const tree_kinematics<double> k1(scaled), k2(as_tree(nhdyn::chain<double>(links, chain.gravity(), "p", chain.validation_policy())));
  Eigen::VectorXd q(6);
  q << 0.3, -0.2, 0.9, -1.1, 0.4, 0.2;
  CHECK((k1.point(q, 6) - k2.point(q, 6)).norm() < 1e-15);
  CHECK((k1.point(q, 6) - tree_kinematics<double>(as_tree(chain)).point(q, 6)).norm() > 1e-3);
  CHECK_THROWS_WITH(with_length_factors(as_tree(chain), {{"elbow", 2.0}}, "plant: "), Catch::Contains("no movable joint named 'elbow'"));

  // a wheel's placement scaled: the rolling constraint read again on that tree has it there
  const io::robot_model r = io::load_robot_file(source("examples/robots/mobile_manipulator_wheels.json"));
  const auto& w0 = std::get<rolling_wheels<double>>(*r.constraint);
  const auto moved = io::constraint_on(r, with_length_factors(r.model, {{"wheel_left_joint", 1.1}}, ""));
  const auto& w1 = std::get<rolling_wheels<double>>(*moved);
  CHECK(w1.left_y == Approx(1.1 * w0.left_y).epsilon(1e-14));
  CHECK(w1.right_y == w0.right_y);
  CHECK(w1.radius == w0.radius);
}

TEST_CASE("robot simulation: a wheel-radius mismatch — the plant rolls on its own wheels, the controller still tracks") {
  auto s = runs_of("examples/scenes/mobile-manipulator-circle.json").front();
  s.robot = source("examples/robots/mobile_manipulator_wheels.json");
  // the wheels drive the base now (η = their rates): the posture term must not hold them
  std::erase_if(s.posture_joints, [](const std::string& j) { return j.rfind("wheel_", 0) == 0; });
  {  // the tool 0.8 m forward in 3 s, further than the arm reaches: the base must drive
    const io::robot_model m = io::load_robot_file(s.robot);
    const auto fr = m.model.find_frame("tool_frame");
    const Eigen::Vector3d a = tree_kinematics<double>(m.model).point(s.q_start, fr.body + 1, fr.p);
    line_reference l;
    l.from = a, l.to = a + Eigen::Vector3d(0.8, 0, 0), l.start = 0, l.end = 3;
    s.reference = l;
  }
  s.duration = 4, s.tail_from = 3, s.tail_tolerance = 0.02;
  const run_result nominal = simulate_scene(s);
  INFO((nominal.failure ? *nominal.failure : std::string("ok")));
  REQUIRE(nominal.success);
  s.plant_wheel_radius = 1.05;  // the real wheels are 5 % larger than the model's
  const run_result r = simulate_scene(s);
  INFO((r.failure ? *r.failure : std::string("ok")));
  REQUIRE(r.success);
  // The base's forward speed u = cos ψ ẋ + sin ψ ẏ (central differences of the rows) is the
  // plant's wheel kinematics, r_plant (φ̇_L s_L + φ̇_R s_R)/2 at a centred axle: not the model's.
  const io::robot_model wheels = io::load_robot_file(s.robot);
  const auto& w = std::get<rolling_wheels<double>>(*wheels.constraint);
  REQUIRE(std::abs(w.left_y + w.right_y) < 1e-12);
  const int x = column(r, "q_base_x"), y = column(r, "q_base_y"), yaw = column(r, "q_base_yaw");
  const int wl = column(r, "eta_wheel_left_joint"), wr = column(r, "eta_wheel_right_joint");
  double worst_plant = 0, worst_model = 0, peak = 0;
  const double h = r.rows(1, 0) - r.rows(0, 0);
  for (Eigen::Index i = 1; i + 1 < r.rows.rows(); ++i) {
    const double vx = (r.rows(i + 1, x) - r.rows(i - 1, x)) / (2 * h), vy = (r.rows(i + 1, y) - r.rows(i - 1, y)) / (2 * h);
    const double u = std::cos(r.rows(i, yaw)) * vx + std::sin(r.rows(i, yaw)) * vy;
    const double wheels = 0.5 * (w.left_sign * r.rows(i, wl) + w.right_sign * r.rows(i, wr)) * w.radius;
    worst_plant = std::max(worst_plant, std::abs(u - 1.05 * wheels));
    worst_model = std::max(worst_model, std::abs(u - wheels));
    peak = std::max(peak, std::abs(u));
  }
  CHECK(peak > 0.02);
  CHECK(worst_plant < 2e-3 * peak);
  CHECK(worst_model > 2e-2 * peak);

  s.robot = source("examples/robots/mobile_manipulator.json");  // a differential drive: no wheel radius
  CHECK_THROWS_WITH(simulate_scene(s), Catch::Contains("wheel_radius_factor"));
  s.plant_wheel_radius = 1;
  s.plant_length = {{"no_joint", 1.1}};
  CHECK_THROWS_WITH(simulate_scene(s), Catch::Contains("no movable joint named 'no_joint'"));
}
