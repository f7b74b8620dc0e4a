// Scenes choose the terms of their plant and of their controller's model (run_spec::plant_terms,
// model_terms; the scene fields plant.terms, model.terms, smooth_coulomb; docs/simulation.md):
// - the default written out is the default, bit for bit (paper5 by `simulate`, a robot file as
//   a tree), and choosing terms on paper5 keeps its default factors;
// - paper5 with other terms runs as a tree: with terms its model has nothing for (no friction
//   laws, no armature) it gives the DH path's rows; without gravity in the plant it does not;
// - plant friction: the logged motion obeys the inverse dynamics with the joints' friction
//   (rne + τ_f, another code path than the plant's CRBA forward dynamics) and not without it,
//   while the frictionless run obeys the frictionless one; the controller, not knowing the
//   friction, tracks worse; a controller whose model has the same friction tracks as before;
// - a controller's model without gravity: its first torque differs from the default's by
//   exactly the projected gradient of the potential energy (central differences of
//   −Σ mᵢ gᵀ p_cᵢ(q), no rne), and it tracks worse;
// - errors name the scene and the field;
// - a scene's "locked" (run_spec::locked) gives its robot file's own "locked", bit for bit.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/simulation/robot_scene.hpp>
#include <nhdyn/simulation/scene.hpp>

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
std::string source(const std::string& rel) { return std::string(NHDYN_SOURCE_DIR) + "/" + rel; }

/// paper-circle (the defaults), 2 s of it, with `extra` fields (JSON members, or empty).
run_spec paper_scene(const std::string& extra) {
  const std::string text = R"({"name": "p", "duration": 2, "success": {"tail_from": 1, "max_tail_error": 1})" +
                           (extra.empty() ? std::string() : ", " + extra) + "}";
  return scene::parse_run(scene::json::parse(text));
}

/// The shipped mobile-manipulator-circle scene (plant = model), its first second at tight
/// tolerances (the tail from 0.6 s, after the start's transient), with a JSON merge patch.
run_spec mm_scene(const std::string& patch) {
  auto f = scene::open(source("examples/scenes/mobile-manipulator-circle.json"));
  f.j.merge_patch(scene::json::parse(R"({"duration": 1.0, "output": {"step": 0.005},
      "integrator": {"method": "dopri5", "rtol": 1e-8, "atol": 1e-10},
      "success": {"tail_from": 0.6, "max_tail_error": 1}})"));
  f.j.merge_patch(scene::json::parse(patch));
  return scene::parse_run(f.j, f.dirs);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const input_error& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST_CASE("scene terms: the default written out is the default, bit for bit", "[scene_terms]") {
  SECTION("paper5 (by simulate, DH kernels); terms alone keep paper-circle's plant factors") {
    const run_spec a = paper_scene("");
    const run_spec b = paper_scene(R"("plant": {"terms": "gravity,velocity,armature"}, "model": {"terms": "armature, velocity, gravity"})");
    CHECK(b.plant_terms == terms{});
    CHECK(b.model_terms == terms{});
    for (int i = 0; i < 5; ++i) CHECK(b.plant.mass_factor[std::size_t(i)] == a.plant.mass_factor[std::size_t(i)]);
    CHECK(a.plant.mass_factor[2] == 1.1);  // paper-circle's mismatch, not reset by "plant": {"terms"}
    const run_result ra = simulate_scene(a), rb = simulate_scene(b);
    REQUIRE(ra.success);
    REQUIRE(rb.success);
    REQUIRE(ra.rows.rows() == rb.rows.rows());
    CHECK((ra.rows.array() == rb.rows.array()).all());
    const run_result rc = simulate(a);  // and simulate_scene of the default is simulate's
    CHECK((ra.rows.array() == rc.rows.array()).all());
  }
  SECTION("a robot file (as a tree)") {
    const run_spec a = mm_scene("{}");
    const run_spec b = mm_scene(R"({"plant": {"terms": "gravity,velocity,armature"}, "model": {"terms": "gravity,velocity,armature"}})");
    CHECK(b.plant_terms == terms{});
    CHECK(b.model_terms == terms{});
    auto shorter = [](run_spec s) {
      s.duration = 0.3, s.tail_from = 0.2;
      return s;
    };
    const run_result ra = simulate_scene(shorter(a)), rb = simulate_scene(shorter(b));
    REQUIRE(ra.success);
    REQUIRE(rb.success);
    REQUIRE(ra.rows.rows() == rb.rows.rows());
    CHECK((ra.rows.array() == rb.rows.array()).all());
  }
}

TEST_CASE("scene terms: paper5 with other terms runs as a tree", "[scene_terms]") {
  const run_spec dh = paper_scene("");
  const run_result a = simulate_scene(dh);
  REQUIRE(a.success);
  // friction and armature in: paper5 has neither (no laws, no rotor inertia), so the tree path
  // must give the DH path's run (two implementations: rounding-level differences only)
  const run_spec all = paper_scene(R"("plant": {"terms": "all"}, "model": {"terms": "all"})");
  CHECK(all.plant_terms == terms::parse("gravity,velocity,armature,friction"));
  CHECK(all.plant.mass_factor[2] == 1.1);
  CHECK_THROWS_WITH(simulate(all), Catch::Contains("simulate_scene"));  // the DH path refuses, not ignores
  const run_result b = simulate_scene(all);
  INFO((b.failure ? *b.failure : std::string("ok")));
  REQUIRE(b.success);
  REQUIRE(a.rows.rows() == b.rows.rows());
  CHECK((a.rows - b.rows).cwiseAbs().maxCoeff() <= 1e-6 * std::max(1.0, a.rows.cwiseAbs().maxCoeff()));
  CHECK(b.columns[1] == "q_joint1");  // the tree's names: it did run as a tree
  // gravity out of the plant only: the model compensates a gravity the plant does not have
  const run_result c = simulate_scene(paper_scene(R"("plant": {"terms": "velocity,armature"})"));
  REQUIRE(c.rows.rows() > 10);
  const Eigen::Index k = std::min(a.rows.rows(), c.rows.rows());
  CHECK((a.rows.topRows(k) - c.rows.topRows(k)).cwiseAbs().maxCoeff() > 1e-3);
}

TEST_CASE("scene terms: plant friction — the motion obeys the dynamics with the joints' friction", "[scene_terms]") {
  const run_spec s0 = mm_scene("{}");
  const run_spec sf = mm_scene(R"({"plant": {"terms": "gravity,velocity,armature,friction", "smooth_coulomb": 0.1}})");
  REQUIRE(sf.plant_terms.friction);
  CHECK(sf.plant_terms.coulomb.velocity_scale == 0.1);
  CHECK(sf.model_terms == terms{});
  const run_result r0 = simulate_scene(s0), rf = simulate_scene(sf);
  INFO((rf.failure ? *rf.failure : std::string("ok")));
  REQUIRE(r0.success);
  REQUIRE(rf.success);
  REQUIRE(rf.rows.rows() == r0.rows.rows());

  // The URDF's <dynamics damping friction> laws, and the inverse dynamics with and without them.
  const io::robot_model robot = io::load_robot_file(sf.robot);
  const auto& c = std::get<differential_drive<double>>(*robot.constraint);
  const tree<double>& model = robot.model;
  const int n = model.dof(), m = c.m();
  REQUIRE(rf.columns.size() == std::size_t(1 + n + 2 * m + 7));
  const auto id_f = inverse_dynamics(model, c, rne_options{}, friction(model, coulomb_law::smooth(0.1)));
  const auto id_0 = inverse_dynamics(model, c);
  // |id(q, η, η̇) − τ| over the rows from 0.3 s, η̇ by central differences of the rows
  const auto residual = [&](const run_result& r, const auto& id) {
    const double h = r.rows(1, 0) - r.rows(0, 0);
    double worst = 0;
    for (Eigen::Index i = 1; i + 1 < r.rows.rows(); ++i) {
      if (r.rows(i, 0) < 0.3) continue;
      const VectorXd q = r.rows.row(i).segment(1, n).transpose();
      const VectorXd eta = r.rows.row(i).segment(1 + n, m).transpose();
      const VectorXd tau = r.rows.row(i).segment(1 + n + m, m).transpose();
      const VectorXd eta_dot =
          (r.rows.row(i + 1).segment(1 + n, m) - r.rows.row(i - 1).segment(1 + n, m)).transpose() / (2 * h);
      worst = std::max(worst, (VectorXd(id(q, eta, eta_dot)) - tau).cwiseAbs().maxCoeff());
    }
    return worst;
  };
  const double with = residual(rf, id_f), without = residual(rf, id_0), frictionless = residual(r0, id_0);
  INFO("with friction " << with << ", without " << without << ", frictionless run " << frictionless);
  CHECK(without > 1e-2);  // the friction is felt (0.5 N·m·s/rad and 0.2 N·m on the arm's joints)
  CHECK(with < 0.05 * without);
  CHECK(frictionless < 0.05 * without);
  // the controller does not know the friction: it tracks worse
  INFO("tail errors: no friction " << r0.max_tail_error << ", plant friction " << rf.max_tail_error);
  CHECK(rf.max_tail_error > 10 * r0.max_tail_error);
  // a controller whose model has the same friction compensates it (plant = model again)
  const run_spec sff = mm_scene(R"({"plant": {"terms": "gravity,velocity,armature,friction", "smooth_coulomb": 0.1},
                                    "model": {"terms": "all", "smooth_coulomb": 0.1}})");
  CHECK(sff.model_terms == sff.plant_terms);
  const run_result rff = simulate_scene(sff);
  INFO("both with friction " << rff.max_tail_error);
  REQUIRE(rff.success);
  CHECK(rff.max_tail_error < 0.1 * rf.max_tail_error);
}

TEST_CASE("scene terms: a controller's model without gravity", "[scene_terms]") {
  const run_spec s0 = mm_scene("{}");
  const run_spec sg = mm_scene(R"({"model": {"terms": "velocity,armature"}})");
  CHECK(!sg.model_terms.gravity);
  CHECK(sg.plant_terms == terms{});
  const run_result r0 = simulate_scene(s0), rg = simulate_scene(sg);
  INFO((rg.failure ? *rg.failure : std::string("ok")));
  REQUIRE(r0.success);
  REQUIRE(rg.rows.rows() > 0);

  const io::robot_model robot = io::load_robot_file(sg.robot);
  const auto& c = std::get<differential_drive<double>>(*robot.constraint);
  const tree<double>& model = robot.model;
  const tree_kinematics<double> kin(model);
  const int n = model.dof(), m = c.m();
  // t = 0: the same state and the same commanded η̇ (kinematics only), so the torques differ by
  // the projected gravity (SᵀS)⁻¹Sᵀ g(q₀), g = ∇V, V(q) = −Σ mᵢ gᵀ p_cᵢ(q)
  const VectorXd q0 = r0.rows.row(0).segment(1, n).transpose();
  REQUIRE((q0 - rg.rows.row(0).segment(1, n).transpose()).cwiseAbs().maxCoeff() == 0);
  const auto V = [&](const VectorXd& q) {
    double v = 0;
    for (int b = 0; b < n; ++b) v -= model[b].mass * model.gravity().dot(kin.point(q, b + 1, model[b].com));
    return v;
  };
  VectorXd g(n);
  for (int j = 0; j < n; ++j) {
    const double d = 1e-6;
    VectorXd qp = q0, qm = q0;
    qp(j) += d, qm(j) -= d;
    g(j) = (V(qp) - V(qm)) / (2 * d);
  }
  const MatrixXd S = c.S(q0);
  const VectorXd expected = (S.transpose() * S).ldlt().solve(S.transpose() * g);
  const VectorXd dtau = (r0.rows.row(0).segment(1 + n + m, m) - rg.rows.row(0).segment(1 + n + m, m)).transpose();
  INFO("projected gravity " << expected.transpose() << "\ntorque difference " << dtau.transpose());
  CHECK(expected.cwiseAbs().maxCoeff() > 1);  // gravity is felt (the torso carries the arm)
  CHECK((dtau - expected).cwiseAbs().maxCoeff() <= 1e-6 * (1 + expected.cwiseAbs().maxCoeff()));
  // and the controller, not compensating gravity, tracks worse
  REQUIRE(rg.success);
  INFO("tail errors: default " << r0.max_tail_error << ", no gravity in the model " << rg.max_tail_error);
  CHECK(rg.max_tail_error > 10 * r0.max_tail_error);
}

TEST_CASE("scene terms: errors name the scene and the field", "[scene_terms]") {
  const auto parse = [](const std::string& text) {
    return scene::parse_run(scene::json::parse(text), {source("examples/scenes")});
  };
  const std::string mm = R"({"name": "x", "robot": "../robots/mobile_manipulator.json", "task": {"frame": "tool_frame"}, )";
  const auto fails = [&](const std::string& text, std::initializer_list<const char*> parts) {
    const std::string e = error_of([&] { (void)parse(text); });
    INFO(e);
    for (const char* p : parts) CHECK(e.find(p) != std::string::npos);
  };
  fails(mm + R"("plant": {"terms": "gravity,coriolis"}})", {"scene 'x'", "field 'plant.terms'", "no term named 'coriolis'"});
  fails(mm + R"("model": {"terms": "gravity,,velocity"}})", {"scene 'x'", "field 'model.terms'", "empty entry"});
  fails(mm + R"("model": {"terms": 3}})", {"scene 'x'", "field 'model.terms'", "string"});
  fails(mm + R"("plant": {"smooth_coulomb": 0.01}})", {"scene 'x'", "field 'plant.smooth_coulomb'", "friction"});
  fails(mm + R"("model": {"terms": "gravity,velocity", "smooth_coulomb": 0.01}})",
        {"scene 'x'", "field 'model.smooth_coulomb'", "friction"});
  fails(mm + R"("plant": {"terms": "all", "smooth_coulomb": 0}})", {"scene 'x'", "field 'plant.smooth_coulomb'", "> 0"});
  fails(mm + R"("plant": {"terms": "all", "coulomb": 0.1}})", {"scene 'x'", "unknown field 'plant.coulomb'"});
  // paper5's plant and model take the keys too, beside its own factors
  fails(R"({"name": "y", "plant": {"terms": "gravity,friction,armature,inertia"}})", {"scene 'y'", "field 'plant.terms'", "'inertia'"});
  fails(R"({"name": "y", "model": {"smooth_coulomb": 0.1, "d3_factor": 1.1}})", {"scene 'y'", "field 'model.smooth_coulomb'"});
  const run_spec p = parse(R"({"name": "y", "plant": {"d3_factor": 1.05, "terms": "all", "smooth_coulomb": 0.02},
                               "model": {"terms": "velocity"}})");
  CHECK(p.plant.d3_factor == 1.05);
  CHECK(p.plant.mass_factor[2] == 1.0);  // an object with factors gives all four, as before
  CHECK(p.plant_terms == terms{true, true, true, true, coulomb_law::smooth(0.02)});
  CHECK(p.model_terms == terms{false, true, false, false});
  const run_spec r = parse(mm + R"("plant": {"mass_factor": {"arm_7_link": 2}, "terms": "none"}})");
  CHECK(r.plant_terms == terms{false, false, false, false});
  CHECK(r.plant_mass.size() == 1);
}

TEST_CASE("scene locked: a scene's \"locked\" holds joints as its robot file's own \"locked\" does, bit for bit",
          "[scene_terms]") {
  // the mobile manipulator with its head held at 0.2 rad: its q is the 17 other joints
  const std::string common = R"("duration": 0.3, "success": {"tail_from": 0.2, "max_tail_error": 1},
      "initial": {"q": [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.9, 0, -1.4, 0, 0.5, 0]},
      "controller": {"posture_joints": ["wheel_left_joint", "wheel_right_joint", "torso_lift_joint", "arm_1_joint"]})";
  const run_spec a = mm_scene("{" + common + R"(, "locked": {"head_*": 0.2}})");
  REQUIRE(a.locked == std::vector<std::pair<std::string, double>>{{"head_*", 0.2}});
  // the same robot written as a robot file with "locked"
  const std::string path = (std::filesystem::temp_directory_path() / "nhdyn_test_scene_locked.json").string();
  {
    std::ifstream in(source("examples/robots/mobile_manipulator.json"));
    auto r = scene::json::parse(in);
    r["urdf"] = source("examples/urdf/mobile_manipulator.urdf");
    r["locked"] = scene::json::parse(R"({"head_*": 0.2})");
    std::ofstream(path) << r.dump();
  }
  const run_spec b = mm_scene("{" + common + R"(, "robot": ")" + path + R"("})");
  const run_spec full = mm_scene(R"({"duration": 0.3, "success": {"tail_from": 0.2, "max_tail_error": 1}})");
  const run_result ra = simulate_scene(a), rb = simulate_scene(b), rf = simulate_scene(full);
  std::filesystem::remove(path);
  REQUIRE(ra.rows.rows() == rb.rows.rows());
  REQUIRE(ra.rows.cols() == rb.rows.cols());
  CHECK((ra.rows.array() == rb.rows.array()).all());
  CHECK(ra.rows.cols() == rf.rows.cols() - 2 * 3);  // two fewer q, η and τ columns
  CHECK(ra.max_tail_error < 0.05);

  // errors name the scene, the field and the joint or pattern
  const auto bad = [&](const std::string& locked) {
    try {
      (void)simulate_scene(mm_scene(R"({"locked": )" + locked + "}"));
    } catch (const error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  using Catch::Contains;
  CHECK_THAT(bad(R"({"base_x": 0})"), Contains("scene 'mobile-manipulator-circle': field 'locked': ") &&
                                          Contains("'base_x' belongs to the constraint (differential_drive)"));
  CHECK_THAT(bad(R"({"hand_*": 0})"), Contains("field 'locked'") && Contains("'hand_*' matches no movable joint"));
  CHECK_THAT(bad(R"({"head_pan_joint": "up"})"),
             Contains("scene 'mobile-manipulator-circle', field 'locked': 'head_pan_joint': expected a finite position"));
  CHECK_THAT(error_of([] { paper_scene(R"("locked": {"joint5": 0})"); }),
             Contains("scene 'p': field 'locked': paper5 runs on its 5-joint chains"));
}
