// URDF import (io/urdf.hpp): the documented joint order, fixed joints merged, what real robot
// files carry (warnings, mimic joints, extra tags), errors that name the file and the element,
// and the dynamics of the loaded tree against Orocos KDL's tree solver, whose tree is built in
// this file from urdfdom's model (KDL keeps fixed joints as segments: it merges nothing).
#include <catch2/catch.hpp>

#include <nhdyn/dynamics/reference.hpp>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/io/urdf.hpp>
#include <nhdyn/kinematics/tree.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>

#include "reference/random_tree.hpp"

#ifdef NHDYN_HAVE_KDL
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#endif

using namespace nhdyn;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

double rel(const MatrixXd& a, const MatrixXd& b) { return (a - b).norm() / std::max(1.0, b.norm()); }

VectorXd random_state(std::mt19937_64& rng, int n) {
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = nhdyn_ref::uniform(rng, -1.5, 1.5);
  return v;
}

/// Loads text, collecting the warnings.
tree<double> load(const std::string& text, std::vector<std::string>& warnings, bool strict = false) {
  io::urdf_options o;
  o.strict = strict;
  o.warn = [&](const std::string& w) { warnings.push_back(w); };
  return io::parse_urdf(text, "test.urdf", o);
}
tree<double> load(const std::string& text) {
  std::vector<std::string> w;
  auto t = load(text, w);
  if (!w.empty()) FAIL("unexpected warning: " << w.front());
  return t;
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

#ifdef NHDYN_HAVE_KDL
// The KDL tree of a URDF, as kdl_parser builds it (ROS's kdl_parser links all of ROS, so the
// twenty lines are here): a segment per link, fixed joints as Joint::None, inertias moved to
// the link frame.
KDL::Frame kdl_frame(const urdf::Pose& p) {
  return KDL::Frame(KDL::Rotation::Quaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
                    KDL::Vector(p.position.x, p.position.y, p.position.z));
}
void add_children(const urdf::ModelInterface& m, const urdf::LinkConstSharedPtr& link, KDL::Tree& t) {
  for (const auto& child : link->child_links) {
    const auto& j = *child->parent_joint;
    const KDL::Frame F = kdl_frame(j.parent_to_joint_origin_transform);
    const KDL::Vector axis(j.axis.x, j.axis.y, j.axis.z);
    KDL::Joint kj(j.name, KDL::Joint::None);
    if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS)
      kj = KDL::Joint(j.name, F.p, F.M * axis, KDL::Joint::RotAxis);
    else if (j.type == urdf::Joint::PRISMATIC)
      kj = KDL::Joint(j.name, F.p, F.M * axis, KDL::Joint::TransAxis);
    KDL::RigidBodyInertia I = KDL::RigidBodyInertia::Zero();
    if (child->inertial) {
      const auto& in = *child->inertial;
      const KDL::Frame o = kdl_frame(in.origin);
      const KDL::RotationalInertia urdf_I(in.ixx, in.iyy, in.izz, in.ixy, in.ixz, in.iyz);
      const KDL::RotationalInertia Ic = (o.M * KDL::RigidBodyInertia(0, KDL::Vector::Zero(), urdf_I)).getRotationalInertia();
      I = KDL::RigidBodyInertia(in.mass, o.p, Ic);
    }
    t.addSegment(KDL::Segment(child->name, kj, F, I), link->name);
    add_children(m, child, t);
  }
}

struct kdl_model {
  KDL::Tree tree;
  std::vector<int> qnr;  // KDL's q index of each of nhdyn's joints
  explicit kdl_model(const std::string& text, const nhdyn::tree<double>& t) {
    const auto m = urdf::parseURDF(text);
    REQUIRE(m);
    tree = KDL::Tree(m->getRoot()->name);
    add_children(*m, m->getRoot(), tree);
    for (int i = 0; i < t.dof(); ++i)
      for (const auto& [name, e] : tree.getSegments())
        if (GetTreeElementSegment(e).getJoint().getName() == t[i].joint_name) qnr.push_back(int(GetTreeElementQNr(e)));
    REQUIRE(static_cast<int>(qnr.size()) == t.dof());
    REQUIRE(static_cast<int>(tree.getNrOfJoints()) == t.dof());
  }
  VectorXd rne(const VectorXd& q, const VectorXd& qd, const VectorXd& qdd, const Eigen::Vector3d& g) const {
    const int n = static_cast<int>(qnr.size());
    KDL::JntArray kq(n), kqd(n), kqdd(n), tau(n);
    for (int i = 0; i < n; ++i) {
      kq(qnr[i]) = q(i);
      kqd(qnr[i]) = qd(i);
      kqdd(qnr[i]) = qdd(i);
    }
    KDL::TreeIdSolver_RNE solver(tree, KDL::Vector(g.x(), g.y(), g.z()));
    REQUIRE(solver.CartToJnt(kq, kqd, kqdd, KDL::WrenchMap(), tau) >= 0);
    VectorXd out(n);
    for (int i = 0; i < n; ++i) out(i) = tau(qnr[i]);
    return out;
  }
};
#endif

}  // namespace

TEST_CASE("URDF joint order: movable joints depth-first from the root, siblings in document order", "[urdf]") {
  const std::string text = R"(<robot name="order">
    <link name="base"/><link name="torso"/><link name="zeta_arm"/><link name="alpha_arm"/>
    <link name="zeta_hand"/><link name="camera"/><link name="alpha_hand"/>
    <joint name="torso_lift" type="prismatic"><parent link="base"/><child link="torso"/><axis xyz="0 0 1"/>
      <limit lower="0" upper="0.4" effort="500" velocity="0.1"/></joint>
    <joint name="zz_first" type="continuous"><parent link="torso"/><child link="zeta_arm"/></joint>
    <joint name="aa_second" type="continuous"><parent link="torso"/><child link="alpha_arm"/></joint>
    <joint name="alpha_wrist" type="revolute"><parent link="alpha_arm"/><child link="alpha_hand"/><axis xyz="0 1 0"/>
      <limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
    <joint name="camera_mount" type="fixed"><parent link="zeta_arm"/><child link="camera"/><origin xyz="0 0 0.1"/></joint>
    <joint name="zeta_wrist" type="continuous"><parent link="zeta_arm"/><child link="zeta_hand"/></joint>
  </robot>)";
  const tree<double> t = load(text);
  CHECK(t.joint_names() == std::vector<std::string>{"torso_lift", "zz_first", "zeta_wrist", "aa_second", "alpha_wrist"});
  CHECK(t.root_name() == "base");
  CHECK(t[2].parent == 1);
  CHECK(t[4].parent == 3);
  CHECK(t[0].joint == joint_type::prismatic);
  CHECK(t[1].continuous);
  CHECK(t[0].limits.upper == 0.4);
  CHECK(t[0].limits.effort == 500);
  CHECK(t[1].axis == Eigen::Vector3d(1, 0, 0));  // URDF's default axis
  const auto cam = t.find_frame("camera");
  CHECK(cam.body == 1);
  CHECK(cam.p == Eigen::Vector3d(0, 0, 0.1));
  CHECK(t.gravity() == Eigen::Vector3d(0, 0, -9.81));
}

TEST_CASE("a fixed joint merges its link's inertia into the parent body", "[urdf]") {
  // two point masses on one body, one through a fixed joint: the merged body's M is exact
  const std::string text = R"(<robot name="merge">
    <link name="base"/>
    <link name="arm"><inertial><origin xyz="1 0 0"/><mass value="2"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
    <link name="tip"><inertial><origin xyz="0 0.5 0"/><mass value="3"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
    <joint name="shoulder" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
    <joint name="weld" type="fixed"><parent link="arm"/><child link="tip"/><origin xyz="1 0 0" rpy="0 0 1.5707963267949"/></joint>
  </robot>)";
  const tree<double> t = load(text);
  REQUIRE(t.dof() == 1);
  CHECK(t[0].mass == 5);
  // about the axis: 2·1² + 3·|(1,0,0) + Rz(90°)(0,0.5,0)|² + 0.1 = 2 + 3·(0.5² + 1²) + 0.1
  const double M = mass_matrix(t)(VectorXd::Zero(1))(0, 0);
  CHECK(M == Approx(2 + 3 * 0.25 + 0.1).epsilon(1e-12));
}

TEST_CASE("a file in the style of real robot descriptions loads, warns per link, and strict refuses", "[urdf]") {
  const std::string path = std::string(NHDYN_SOURCE_DIR) + "/tests/urdf/real_style.urdf";
  const std::string text = read(path);
  REQUIRE(!text.empty());
  std::vector<std::string> warnings;
  const tree<double> t = load(text, warnings);
  REQUIRE(warnings.size() == 2);
  CHECK_THAT(warnings[0], Catch::Contains("link 'antenna_link'") && Catch::Contains("not positive semi-definite") &&
                              Catch::Contains("used as given"));
  CHECK_THAT(warnings[1], Catch::Contains("link 'sensor_link'") &&
                              Catch::Contains("principal moments violate the triangle inequality by 8.00e-03 kg m^2; used as given"));
  CHECK_THROWS_WITH(load(text, warnings, true), Catch::Contains("test.urdf: link 'antenna_link'") &&
                                                     Catch::Contains("not positive semi-definite"));
  // mimic fingers are independent coordinates, and the mimic is kept
  const int left = [&] {
    for (int i = 0; i < t.dof(); ++i)
      if (t[i].joint_name == "gripper_left_finger_joint") return i;
    return -1;
  }();
  REQUIRE(left >= 0);
  REQUIRE(t[left].mimic);
  CHECK(t[left].mimic->joint == "gripper_right_finger_joint");
  CHECK(t[left].mimic->multiplier == -1);
  CHECK(t[left].damping == 0.5);
  CHECK(t[left].friction == 0.1);
  // a massless body and a point mass are fine
  std::mt19937_64 rng(3);
  const VectorXd q = random_state(rng, t.dof()), qd = random_state(rng, t.dof()), qdd = random_state(rng, t.dof());
  CHECK(rel(rne(t)(q, qd, qdd), reference::rne<double>(t, q, qd, qdd)) < 1e-12);
#ifdef NHDYN_HAVE_KDL
  const kdl_model kdl(text, t);
  CHECK(rel(rne(t)(q, qd, qdd), kdl.rne(q, qd, qdd, t.gravity())) < 1e-12);
  const int n = t.dof();
  MatrixXd Mk(n, n);
  for (int j = 0; j < n; ++j) Mk.col(j) = kdl.rne(q, VectorXd::Zero(n), VectorXd::Unit(n, j), Eigen::Vector3d::Zero());
  CHECK(rel(mass_matrix(t)(q), Mk) < 1e-12);
  const VectorXd tau = rne(t)(q, qd, qdd);
  const VectorXd bias_k = kdl.rne(q, qd, VectorXd::Zero(n), t.gravity());
  CHECK(rel(forward_dynamics(t)(q, qd, tau), Mk.ldlt().solve(tau - bias_k)) < 1e-9);
#endif
}

TEST_CASE("a mass matrix that a file's inertias make indefinite is named as such by forward dynamics", "[urdf][errors]") {
  // a leaf link whose inertia about its only joint's axis is negative: loads with a warning,
  // rne runs as given, forward dynamics refuses and says why
  const std::string text = R"(<robot name="bad"><link name="base"/>
    <link name="wheel"><inertial><mass value="0"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="-0.5"/></inertial></link>
    <joint name="spin" type="continuous"><parent link="base"/><child link="wheel"/><axis xyz="0 0 1"/></joint></robot>)";
  std::vector<std::string> warnings;
  const tree<double> t = load(text, warnings);
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Contains("not positive semi-definite"));
  CHECK(rne(t)(VectorXd::Zero(1), VectorXd::Zero(1), VectorXd::Ones(1))(0) == Approx(-0.5));
  CHECK_THROWS_WITH(forward_dynamics(t)(VectorXd::Zero(1), VectorXd::Zero(1), VectorXd::Ones(1)),
                    Catch::Contains("mass matrix M(q) is not positive definite"));
}

TEST_CASE("URDF errors name the file, the element and the problem", "[urdf][errors]") {
  const auto robot = [](const std::string& body) { return "<robot name=\"r\">" + body + "</robot>"; };
  const std::string two_links = R"(<link name="a"/><link name="b"/>)";
  const auto joint = [](const std::string& type, const std::string& extra = "") {
    return "<joint name=\"j\" type=\"" + type + "\"><parent link=\"a\"/><child link=\"b\"/>" + extra + "</joint>";
  };
  const auto error = [](const std::string& text) {
    try {
      io::parse_urdf(text, "robot.urdf");
    } catch (const model_error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  CHECK_THAT(error("<robot name=\"r\">\n<link name=\"a\">\n</robot>"), Catch::Contains("robot.urdf: malformed XML (line"));
  CHECK_THAT(error(robot(two_links)), Catch::Contains("robot.urdf: not a valid URDF") && Catch::Contains("root"));
  CHECK_THAT(error(robot(two_links + joint("revolute", "<axis xyz=\"0 0 0\"/><limit effort=\"1\" velocity=\"1\"/>"))),
             Catch::Contains("joint 'j' (line 1): axis is zero"));
  CHECK_THAT(error(robot(two_links + joint("continuous", "<axis xyz=\"0 0 2\"/>"))), Catch::Contains("axis has length 2, not 1"));
  // a floating joint on the root link floats the robot (below); inside the tree it is refused
  CHECK_THAT(error(robot(R"(<link name="a"/><link name="b"/><link name="c"/>
                 <joint name="f" type="fixed"><parent link="a"/><child link="b"/></joint>
                 <joint name="j" type="floating"><parent link="b"/><child link="c"/></joint>)")),
             Catch::Contains("joint 'j' (line 3)") && Catch::Contains("'floating' is supported only on the root link"));
  CHECK_THAT(error(robot(two_links + joint("floating", "<origin xyz=\"0 0 1\"/>"))),
             Catch::Contains("floating joint's <origin> must be the identity"));
  CHECK_THAT(error(robot(two_links + joint("planar", "<axis xyz=\"0 0 1\"/>"))), Catch::Contains("type 'planar' is not supported"));
  CHECK_THAT(error(robot("<link name=\"a\"/><link name=\"b\"><inertial><mass value=\"-1\"/><inertia ixx=\"1\" ixy=\"0\" "
                         "ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>" +
                         joint("continuous"))),
             Catch::Contains("link 'b' (line 1)") && Catch::Contains("mass is negative"));
  CHECK_THAT(error(robot("<link name=\"a\"/><link name=\"b\"><inertial><mass value=\"nan\"/><inertia ixx=\"1\" ixy=\"0\" "
                         "ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>" +
                         joint("continuous"))),
             Catch::Contains("robot.urdf: ") && (Catch::Contains("not finite") || Catch::Contains("mass")));
  CHECK_THAT(error(robot(two_links + "<joint name=\"j\" type=\"continuous\"><parent link=\"x\"/><child link=\"b\"/></joint>")),
             Catch::Contains("robot.urdf: not a valid URDF"));
  // joints that form a cycle: named with their lines (urdfdom says only "no root link")
  CHECK_THAT(error(robot("<link name=\"a\"/><link name=\"b\"/><link name=\"c\"/><link name=\"d\"/>\n"
                         "<joint name=\"ab\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/></joint>\n"
                         "<joint name=\"bc\" type=\"continuous\"><parent link=\"b\"/><child link=\"c\"/></joint>\n"
                         "<joint name=\"ca\" type=\"continuous\"><parent link=\"c\"/><child link=\"a\"/></joint>\n"
                         "<joint name=\"cd\" type=\"continuous\"><parent link=\"c\"/><child link=\"d\"/></joint>")),
             Catch::Contains("robot.urdf: the joints form a cycle (") && Catch::Contains("'ab' (line 2)") &&
                 Catch::Contains("'bc' (line 3)") && Catch::Contains("'ca' (line 4)") && !Catch::Contains("'cd'"));
  {  // no movable joint: a model of 0 joints whose links are frames of the root (KDL loads such files)
    const tree<double> t0 = io::parse_urdf(robot(two_links + joint("fixed")), "robot.urdf");
    CHECK(t0.dof() == 0);
    CHECK(t0.find_frame("b").body == -1);
    const Eigen::VectorXd none(0);
    CHECK(rne(t0)(none, none, none).size() == 0);
    CHECK(tree_kinematics<double>(t0).frame(none, "b").p.allFinite());
  }
  CHECK_THROWS_WITH(io::load_urdf("/nonexistent/robot.urdf"), Catch::Contains("/nonexistent/robot.urdf: cannot open"));
}

TEST_CASE("random URDF trees: the loader's tree agrees with the reference and with KDL's tree solver", "[urdf][kdl]") {
  std::mt19937_64 rng(29);
  for (int n : {1, 2, 5, 12, 24, 48, 60}) {
    const std::string text = nhdyn_ref::random_urdf(rng, n);
    const tree<double> t = load(text);
    REQUIRE(t.dof() == n);
    const auto id = rne(t);
    const auto M = mass_matrix(t);
    for (int s = 0; s < 2; ++s) {
      const VectorXd q = random_state(rng, n), qd = random_state(rng, n), qdd = random_state(rng, n);
      INFO("n = " << n);
      const VectorXd tau = id(q, qd, qdd);
      CHECK(rel(tau, reference::rne<double>(t, q, qd, qdd)) < 1e-12);
#ifdef NHDYN_HAVE_KDL
      const kdl_model kdl(text, t);
      CHECK(rel(tau, kdl.rne(q, qd, qdd, t.gravity())) < 1e-12);
      MatrixXd Mk(n, n);
      for (int j = 0; j < n; ++j) Mk.col(j) = kdl.rne(q, VectorXd::Zero(n), VectorXd::Unit(n, j), Eigen::Vector3d::Zero());
      CHECK(rel(M(q), Mk) < 1e-12);
      const VectorXd tk = kdl.rne(q, qd, VectorXd::Zero(n), t.gravity());
      CHECK(rel(forward_dynamics(t)(q, qd, tau), Mk.ldlt().solve(tau - tk)) < 1e-9);
#endif
    }
  }
}

TEST_CASE("shipped URDFs: paper5 and puma560 written as URDF give the DH presets' rne and M to 1e-12", "[urdf]") {
  const std::string dir = std::string(NHDYN_SOURCE_DIR) + "/examples/urdf/";
  std::mt19937_64 rng(31);
  const auto check = [&](const chain<double>& c, const std::string& file, std::vector<std::string> expected_warnings) {
    std::vector<std::string> warnings;
    io::urdf_options o;
    o.gravity = c.gravity();  // a URDF carries no gravity; paper5's is along −x₀
    o.warn = [&](const std::string& w) { warnings.push_back(w); };
    const tree<double> t = io::load_urdf(dir + file, o);
    REQUIRE(t.dof() == c.dof());
    REQUIRE(warnings.size() == expected_warnings.size());
    for (std::size_t k = 0; k < warnings.size(); ++k) CHECK_THAT(warnings[k], Catch::Contains(expected_warnings[k]));
    for (int s = 0; s < 10; ++s) {
      const VectorXd q = random_state(rng, c.dof()), qd = random_state(rng, c.dof()), qdd = random_state(rng, c.dof());
      CHECK(rel(rne(t)(q, qd, qdd), rne(c)(q, qd, qdd)) < 1e-12);
      CHECK(rel(mass_matrix(t)(q), mass_matrix(c)(q)) < 1e-12);
    }
  };
  // the Puma's links 1 and 3 break the triangle inequality as published (Corke's parameters)
  check(presets::puma560().dynamic_size(), "puma560.urdf", {"link 'link1'", "link 'link3'"});
  check(presets::paper5_chain().dynamic_size(), "paper5.urdf", {});
}

TEST_CASE("the shipped mobile manipulator: 16 joints in the documented order, physical, equal to KDL", "[urdf][kdl]") {
  const std::string file = std::string(NHDYN_SOURCE_DIR) + "/examples/urdf/mobile_manipulator.urdf";
  io::urdf_options strict;
  strict.strict = true;  // every inertia is a solid box's or cylinder's
  const tree<double> t = io::load_urdf(file, strict);
  CHECK(t.joint_names() ==
        std::vector<std::string>{"wheel_left_joint", "wheel_right_joint", "caster_front_swivel_joint",
                                 "caster_front_wheel_joint", "caster_rear_swivel_joint", "caster_rear_wheel_joint",
                                 "torso_lift_joint", "arm_1_joint", "arm_2_joint", "arm_3_joint", "arm_4_joint",
                                 "arm_5_joint", "arm_6_joint", "arm_7_joint", "head_pan_joint", "head_tilt_joint"});
  CHECK(t.find_frame("tool_frame").body == t.body_index("arm_7_link"));
  std::mt19937_64 rng(37);
  const int n = t.dof();
  for (int s = 0; s < 5; ++s) {
    const VectorXd q = random_state(rng, n), qd = random_state(rng, n), qdd = random_state(rng, n);
    const VectorXd tau = rne(t)(q, qd, qdd);
    CHECK(rel(tau, reference::rne<double>(t, q, qd, qdd)) < 1e-12);
#ifdef NHDYN_HAVE_KDL
    const kdl_model kdl(read(file), t);
    CHECK(rel(tau, kdl.rne(q, qd, qdd, t.gravity())) < 1e-12);
#endif
  }
}

TEST_CASE("robot files: a URDF on a planar base with the no-slip constraint runs the paper's method", "[urdf][robot_file]") {
  const std::string dir = std::string(NHDYN_SOURCE_DIR) + "/examples/";
  const io::robot_model r = io::load_robot_file(dir + "robots/mobile_manipulator.json");
  const tree<double>& t = r.model;
  REQUIRE(r.constraint);
  const auto& c = std::get<differential_drive<double>>(*r.constraint);
  REQUIRE(t.dof() == 19);
  CHECK(t[0].joint_name == "base_x");
  CHECK(t[1].joint_name == "base_y");
  CHECK(t[2].joint_name == "base_yaw");
  CHECK(t[3].joint_name == "wheel_left_joint");
  CHECK(t.body_index("base_footprint") == 2);  // the root link moves now
  CHECK(c.k() == 1);
  CHECK(c.m() == 18);
  // the total mass, read from the URDF by urdfdom (no merging): pushing the robot forward at
  // rest with everything else still takes (Σ m) · a along the root link's x axis
  const auto urdf_model = urdf::parseURDF(read(dir + "urdf/mobile_manipulator.urdf"));
  double total = 0;
  for (const auto& [name, link] : urdf_model->links_)
    if (link->inertial) total += link->inertial->mass;
  const auto id = inverse_dynamics(t, c);
  VectorXd q = VectorXd::Zero(19), eta = VectorXd::Zero(18), eta_dot = VectorXd::Zero(18);
  q(2) = 0.7;  // any heading
  eta_dot(0) = 1.3;
  CHECK(id(q, eta, eta_dot)(0) == Approx(total * 1.3).epsilon(1e-12));
  // at random states: τ = Sᵀ(M S η̇ + h) from CRBA and the holonomic rne; FD inverts it;
  // and the lifted velocity never slips sideways (A S η = 0)
  std::mt19937_64 rng(61);
  const auto fd = nh_forward_dynamics(t, c);
  for (int s = 0; s < 3; ++s) {
    q = random_state(rng, 19), eta = random_state(rng, 18), eta_dot = random_state(rng, 18);
    const VectorXd tau = id(q, eta, eta_dot);
    const MatrixXd S = c.S(q);
    const VectorXd qd = S * eta, qdd = S * eta_dot + c.Sdot(q, qd) * eta;
    CHECK(rel(tau, S.transpose() * (mass_matrix(t)(q) * qdd + bias(t)(q, qd))) < 1e-12);
    CHECK(rel(fd(q, eta, tau), eta_dot) < 1e-9);
    // the root link's origin moves along its own x axis only
    const tree_kinematics<double> kin(t);
    const auto X = kin.frame(q, "base_footprint");
    const Eigen::Vector3d v = (kin.jacobian(q, 3) * qd).head<3>();
    CHECK(std::abs(X.R.col(1).dot(v)) < 1e-12 * std::max(1.0, v.norm()));
  }
}

TEST_CASE("robot file errors name the file and the field", "[urdf][robot_file][errors]") {
  const std::string dir = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/x.json";
  const auto error = [&](const std::string& text) {
    try {
      io::parse_robot_file(text, dir);
    } catch (const model_error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  CHECK_THAT(error(R"({"name": "r"})"), Catch::Contains("field 'urdf': missing"));
  CHECK_THAT(error(R"({"urdf": "../urdf/mobile_manipulator.urdf", "constraint": {"type": "differential_drive"}})"),
             Catch::Contains("needs a planar base"));
  CHECK_THAT(error(R"({"urdf": "../urdf/mobile_manipulator.urdf", "base": {"type": "holonomic"}})"),
             Catch::Contains("unknown base type 'holonomic' (known: planar, floating)"));
  CHECK_THAT(error(R"({"urdf": "../urdf/mobile_manipulator.urdf", "base": {"type": "floating"},
                      "constraint": {"type": "differential_drive", "x": "a", "y": "b", "heading": "c"}})"),
             Catch::Contains("constraints on a floating base are not supported yet"));
  CHECK_THAT(error(R"({"urdf": "../urdf/mobile_manipulator.urdf", "base": {"type": "planar"}, "constraint": {"type": "omni"}})"),
             Catch::Contains("unknown constraint type 'omni'"));
  CHECK_THAT(error(R"({"urdf": "../urdf/mobile_manipulator.urdf", "wheels": 2})"), Catch::Contains("unknown field(s) 'wheels'"));
  CHECK_THAT(error(R"({"urdf": "missing.urdf"})"), Catch::Contains("missing.urdf: cannot open the file"));
  CHECK_THAT(error(R"({"urdf": "../urdf/mobile_manipulator.urdf", "gravity": [0, 0]})"), Catch::Contains("field 'gravity'"));
  // a fixed base: the URDF's joints only
  CHECK(io::parse_robot_file(R"({"urdf": "../urdf/mobile_manipulator.urdf"})", dir).model.dof() == 16);
}

TEST_CASE("CRBA far from the origin: a planar base's M does not depend on where the base stands", "[urdf][crba]") {
  // M(q) of a robot on a planar base is invariant under the base's translation (a physics
  // invariant): 10 km away it must keep its digits (a CRBA that sums inertias about the world
  // origin loses them: 1.5e-11 seen; performance.md, kernel note 16).
  const auto r = io::load_robot_file(std::string(NHDYN_SOURCE_DIR) + "/examples/robots/mobile_manipulator.json");
  const auto M = mass_matrix(r.model);
  std::mt19937_64 rng(71);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int s = 0; s < 5; ++s) {
    VectorXd q = VectorXd::NullaryExpr(r.model.dof(), [&] { return u(rng); });
    q(0) = q(1) = 0;
    const MatrixXd M0 = M(q);
    q(0) = 1e4, q(1) = -7e3;
    const MatrixXd Mfar = M(q);
    CHECK((Mfar - M0).norm() <= 1e-12 * M0.norm());
    CHECK((Mfar - reference::crba<double>(r.model, q)).norm() <= 1e-12 * M0.norm());
  }
}

TEST_CASE("URDF: a floating root joint, or a robot file's floating base, gives a free-flyer tree", "[urdf][floating]") {
  // a two-link pendulum on a free body, and a frame fixed to the world: the floating joint in
  // the file, or the same URDF without it and "base": {"type": "floating"} in a robot file
  const std::string links = R"(
    <link name="trunk"><inertial><origin xyz="0.05 0 0.02"/><mass value="12"/>
      <inertia ixx="0.3" ixy="0.01" ixz="0" iyy="0.5" iyz="0" izz="0.6"/></inertial></link>
    <link name="arm"><inertial><origin xyz="0 0 -0.2"/><mass value="2"/>
      <inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.004"/></inertial></link>
    <link name="hand"><inertial><origin xyz="0 0 -0.1"/><mass value="0.5"/>
      <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"/></inertial></link>
    <joint name="shoulder" type="revolute"><parent link="trunk"/><child link="arm"/><origin xyz="0.2 0.1 0" rpy="0.3 0 0"/>
      <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="50" velocity="5"/></joint>
    <joint name="elbow" type="continuous"><parent link="arm"/><child link="hand"/><origin xyz="0 0 -0.4"/>
      <axis xyz="1 0 0"/></joint>)";
  const std::string with_joint = R"(<robot name="flyer"><link name="world"/><link name="marker"/>
    <joint name="root_joint" type="floating"><parent link="world"/><child link="trunk"/></joint>
    <joint name="mark" type="fixed"><parent link="world"/><child link="marker"/><origin xyz="1 2 0"/></joint>)" +
                                 links + "</robot>";
  std::vector<std::string> warnings;
  const tree<double> t = load(with_joint, warnings);
  CHECK(warnings.empty());
  REQUIRE(t.floating());
  CHECK(t.dof() == 8);
  CHECK(t.nq() == 9);
  CHECK(t.joint_names() ==
        std::vector<std::string>{"root_x", "root_y", "root_z", "root_rx", "root_ry", "root_rz", "shoulder", "elbow"});
  CHECK(t[5].name == "trunk");
  CHECK(t[5].mass == 12);
  CHECK(t.root_name() == "world");
  CHECK(t.find_frame("marker").body == -1);  // fixed to the world, not to the trunk
  io::urdf_options o;
  o.floating_base = true;
  const tree<double> u = io::parse_urdf("<robot name=\"flyer\">" + links + "</robot>", "flyer.urdf", o);
  REQUIRE(u.floating());
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const VectorXd q = random_configuration(t, rng), v = random_state(rng, 8), a = random_state(rng, 8);
    const VectorXd tau = rne(t)(q, v, a);
    CHECK(rel(tau, rne(u)(q, v, a)) == 0);
    CHECK(rel(tau, reference::rne_floating<double>(t, q, v, a)) < 1e-12);
    const tree_kinematics<double> kin(t);
    CHECK((kin.frame(q, "marker").p - Eigen::Vector3d(1, 2, 0)).norm() == 0);
    CHECK((kin.frame(q, "trunk").p - q.head<3>()).norm() == 0);
  }
  // a movable joint on the world beside the floating joint is refused, naming it
  CHECK_THROWS_WITH(io::parse_urdf(R"(<robot name="r"><link name="world"/><link name="a"/><link name="b"/>
      <joint name="root_joint" type="floating"><parent link="world"/><child link="a"/></joint>
      <joint name="j" type="continuous"><parent link="world"/><child link="b"/><axis xyz="0 0 1"/></joint></robot>)"),
                    Catch::Contains("joint 'j' (line 3)") && Catch::Contains("must hang below the floating link 'a'"));
  CHECK_THROWS_WITH(io::parse_urdf(with_joint, "flyer.urdf", o), Catch::Contains("give it once"));
}
