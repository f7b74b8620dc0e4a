/// \file tests/compiled/same_numbers.cpp
/// Header-only or compiled, the same numbers (issue 33 item 4; include/nhdyn/config.hpp).
/// Prints in hexadecimal floating point everything the URDF and robot-file loaders give for
/// each shipped robot file: every body's constants, the frames, gravity; the constraint's A(q)
/// and S(q)η at a state; and one rne at that state; then every call of robot_dynamics (the front
/// end compiled in the library, robot_dynamics.hpp) at a state, its rne and inverse dynamics checked
/// equal to the template API's bit for bit. Then the first 0.3 s of three shipped scenes
/// (`simulate_scene`: a mecanum base, the wheeled mobile manipulator, paper5 as a DH chain),
/// every logged row. tests/compiled.cmake builds this file
/// twice, linking nhdyn::compiled and header-only, and its ctest entry compares the two
/// outputs byte for byte.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/robot_dynamics.hpp>
#include <nhdyn/simulation/robot_scene.hpp>
#include <nhdyn/simulation/scene.hpp>

namespace {
void put(const char* what, double x) { std::printf("%s %a\n", what, x); }
template <class M>
void put(const char* what, const M& m) {
  std::printf("%s", what);
  for (Eigen::Index i = 0; i < m.size(); ++i) std::printf(" %a", m.data()[i]);
  std::printf("\n");
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: same_numbers ROBOTS_DIR SCENES_DIR\n");
    return 2;
  }
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(argv[1]))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    nhdyn::io::urdf_options opt;
    opt.warn = [](const std::string&) {};
    const nhdyn::io::robot_model r = nhdyn::io::load_robot_file(f.string(), opt);
    const auto& t = r.model;
    std::printf("robot %s (%s): %d joints\n", f.filename().c_str(), r.name.c_str(), t.dof());
    put("gravity", t.gravity());
    for (const auto& b : t) {
      std::printf("body %s joint %s parent %d\n", b.name.c_str(), b.joint_name.c_str(), b.parent);
      put(" R_PJ", b.R_PJ), put(" p_PJ", b.p_PJ), put(" axis", b.axis), put(" R_JB", b.R_JB), put(" p_JB", b.p_JB);
      put(" mass", b.mass), put(" com", b.com), put(" inertia", b.inertia), put(" armature", b.armature);
      put(" damping", b.damping), put(" friction", b.friction);
    }
    for (const auto& fr : t.frames()) std::printf("frame %s on %d\n", fr.name.c_str(), fr.body), put(" R", fr.R), put(" p", fr.p);
    const int n = t.dof();
    Eigen::VectorXd w(n), qd(n), qdd(n);
    for (int i = 0; i < n; ++i) w(i) = std::sin(0.7 * i + 0.3), qd(i) = std::cos(1.3 * i), qdd(i) = 0.5 - 0.1 * i;
    const Eigen::VectorXd q = nhdyn::integrate(t, nhdyn::neutral_configuration(t), w);  // w itself on a fixed base
    put("rne", Eigen::VectorXd(nhdyn::rne(t)(q, qd, qdd)));
    if (r.constraint)
      std::visit(
          [&](const auto& c) {
            put("A", Eigen::MatrixXd(c.A(q)));
            Eigen::VectorXd eta(c.m());
            for (int i = 0; i < c.m(); ++i) eta(i) = 0.2 * i - 0.4;
            put("S eta", Eigen::VectorXd(nhdyn::apply_S(c, q, eta)));
          },
          *r.constraint);
    for (const auto& name : r.tau_names()) std::printf("tau %s\n", name.c_str());

    // robot_dynamics: every call, compiled (in nhdyn::compiled) or header-only (instantiated here)
    const nhdyn::robot_dynamics rd(r);
    const Eigen::VectorXd v = rd.rne(q, qd, qdd);
    if (v != nhdyn::rne(t)(q, qd, qdd)) {
      std::fprintf(stderr, "same_numbers: %s: robot_dynamics::rne differs from rne(tree)\n", f.c_str());
      return 1;
    }
    put("rd rne", v), put("rd M", rd.mass_matrix(q)), put("rd bias", rd.bias(q, qd));
    put("rd fd", rd.forward_dynamics(q, qd, v));
    const auto d = rd.rne_derivatives(q, qd, qdd);
    put("rd drne", d.tau), put(" dq", d.dq), put(" dqd", d.dqd), put(" M", d.M);
    const auto fdd = rd.forward_dynamics_derivatives(q, qd, v);
    put("rd dfd", fdd.qdd), put(" dq", fdd.dq), put(" dqd", fdd.dqd), put(" Minv", fdd.Minv);
    if (rd.constrained()) {
      Eigen::VectorXd eta(rd.m()), eta_dot(rd.m());
      for (int i = 0; i < rd.m(); ++i) eta(i) = 0.2 * i - 0.4, eta_dot(i) = std::cos(0.9 * i);
      const auto forces = rd.inverse_dynamics_with_forces(q, eta, eta_dot);
      const bool same = std::visit(
          [&](const auto& c) {
            const auto ref = nhdyn::inverse_dynamics_with_forces(t, c)(q, eta, eta_dot);
            return forces.tau == ref.tau && forces.lambda == ref.lambda;
          },
          *r.constraint);
      if (!same) {
        std::fprintf(stderr, "same_numbers: %s: robot_dynamics::inverse_dynamics_with_forces differs from "
                     "inverse_dynamics_with_forces(tree, c)\n", f.c_str());
        return 1;
      }
      put("rd tau", forces.tau), put("rd lambda", forces.lambda), put("rd id", rd.inverse_dynamics(q, eta, eta_dot));
      put("rd fd eta", rd.nh_forward_dynamics(q, eta, forces.tau));
      const auto xi = rd.lift(q, eta, eta_dot);
      put("rd lift", xi.q), put(" qd", xi.qd), put(" qdd", xi.qdd);
      put("rd S eta", rd.apply_S(q, eta)), put("rd S", rd.S(q)), put("rd A", rd.A(q)), put("rd E", rd.input_map(q));
      const auto did = rd.inverse_dynamics_derivatives(q, eta, eta_dot);
      put("rd did", did.tau), put(" dq", did.dq), put(" deta", did.deta), put(" deta_dot", did.deta_dot);
      const auto dfd = rd.nh_forward_dynamics_derivatives(q, eta, forces.tau);
      put("rd dnhfd", dfd.eta_dot), put(" A", dfd.A), put(" B", dfd.B);
    }
  }
  for (const char* name : {"mecanum-sideways-circle", "mobile-manipulator-circle", "paper-circle"}) {
    auto f = nhdyn::scene::open(std::string(argv[2]) + "/" + name + ".json");
    f.j.merge_patch(nhdyn::scene::json::parse(R"({"duration": 0.3, "output": {"step": 0.01}, "success": {"tail_from": 0.2}})"));
    const nhdyn::run_result res = nhdyn::simulate_scene(nhdyn::scene::parse_run(f.j, f.dirs));
    std::printf("scene %s: success %d, %ld steps, %ld rows\n", name, int(res.success), res.steps, long(res.rows.rows()));
    put("max_tail_error", res.max_tail_error), put("peak_tau", res.peak_tau), put("rows", res.rows);
  }
  return 0;
}
