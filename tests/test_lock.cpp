// Locked joints (model/lock.hpp): the reduced tree against the full tree it came from — rne's
// rows of the kept joints, the kept block of M, the held forward dynamics solved here from the
// full tree's M and bias, the poses and Jacobians of the merged bodies' frames —, against the
// URDF loader's own merge of the same joints written as fixed (when urdfdom is there), and
// the patterns: globs, and the errors that name the culprit.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/kinematics/tree.hpp>
#include <nhdyn/model/lock.hpp>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#ifdef NHDYN_HAVE_URDF
#include <unistd.h>

#include <filesystem>
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/io/urdf.hpp>
#include <nhdyn/nhdyn.hpp>
#endif

#include "reference/random_tree.hpp"

using namespace nhdyn;
using Catch::Contains;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

using lock_list = std::vector<std::pair<std::string, double>>;

double rel(const MatrixXd& a, const MatrixXd& b) { return (a - b).norm() / std::max(1.0, b.norm()); }

VectorXd random_state(std::mt19937_64& rng, int n, double r = 1.5) {
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = nhdyn_ref::uniform(rng, -r, r);
  return v;
}

/// The entries idx of v, and the block idx × idx of M.
VectorXd rows(const VectorXd& v, const std::vector<int>& idx) {
  VectorXd out(static_cast<Eigen::Index>(idx.size()));
  for (std::size_t k = 0; k < idx.size(); ++k) out(Eigen::Index(k)) = v(idx[k]);
  return out;
}
MatrixXd block(const MatrixXd& M, const std::vector<int>& idx) {
  const auto k = static_cast<Eigen::Index>(idx.size());
  MatrixXd out(k, k);
  for (Eigen::Index r = 0; r < k; ++r)
    for (Eigen::Index c = 0; c < k; ++c) out(r, c) = M(idx[std::size_t(r)], idx[std::size_t(c)]);
  return out;
}

/// A random tree (tests/reference/random_tree.hpp: branches, prismatic joints, body offsets
/// X_JB, a massless body, a point mass) with armature and damping on its joints and named
/// frames fixed on some bodies and on the base.
tree<double> decorated(std::mt19937_64& rng, int n) {
  const tree<double> t = nhdyn_ref::random_tree(rng, n);
  std::vector<body<double>> B = t.bodies();
  for (auto& b : B) {
    if (nhdyn_ref::uniform(rng, 0, 1) < 0.6) b.armature = nhdyn_ref::uniform(rng, 0.01, 0.5);
    b.damping = nhdyn_ref::uniform(rng, 0, 1);
    b.limits.lower = -2;
    b.limits.upper = 2;
  }
  std::vector<frame<double>> F;
  F.push_back(frame<double>{"marker_base", -1, nhdyn_ref::random_rotation(rng), nhdyn_ref::random_vector(rng, 0.5)});
  for (int i = 0; i < n; ++i)
    if (nhdyn_ref::uniform(rng, 0, 1) < 0.5)
      F.push_back(frame<double>{"marker" + std::to_string(i), i, nhdyn_ref::random_rotation(rng),
                                nhdyn_ref::random_vector(rng, 0.3)});
  return tree<double>(std::move(B), t.gravity(), t.name(), t.validation_policy(), t.root_name(), std::move(F));
}

/// What a random lock list holds, worked out here from the list (not by lock_map_of).
struct held {
  lock_list list;
  std::vector<bool> locked;  // per full-tree joint
  std::vector<int> kept;     // full-tree indices of the kept joints, ascending
  VectorXd q_locked;         // the locked joints' positions (0 elsewhere)

  /// The full-tree vector of a reduced one: v at the kept joints, `other` at the locked ones.
  VectorXd full(const VectorXd& v, const VectorXd& other) const {
    VectorXd out = other;
    for (std::size_t k = 0; k < kept.size(); ++k) out(kept[k]) = v(Eigen::Index(k));
    return out;
  }
  /// The reduced-tree body that full-tree body i ends on (−1: the base).
  int survivor(const tree<double>& t, int i) const {
    while (i >= 0 && locked[std::size_t(i)]) i = t.parent(i);
    if (i < 0) return -1;
    for (std::size_t k = 0; k < kept.size(); ++k)
      if (kept[k] == i) return int(k);
    return -2;  // unreachable
  }
};

/// Each joint of t locked by its name with probability p at a random position; never all of
/// them (the 0-joint tree has its own test below).
held random_locks(std::mt19937_64& rng, const tree<double>& t, double p) {
  const int n = t.dof();
  held h;
  h.locked.assign(std::size_t(n), false);
  h.q_locked = VectorXd::Zero(n);
  for (int i = 0; i < n; ++i)
    if (nhdyn_ref::uniform(rng, 0, 1) < p) h.locked[std::size_t(i)] = true;
  if (std::count(h.locked.begin(), h.locked.end(), true) == n)
    h.locked[std::size_t(std::uniform_int_distribution<int>(0, n - 1)(rng))] = false;
  for (int i = 0; i < n; ++i) {
    if (!h.locked[std::size_t(i)]) {
      h.kept.push_back(i);
      continue;
    }
    h.q_locked(i) = nhdyn_ref::uniform(rng, -1.5, 1.5);
    h.list.emplace_back(t[i].joint_name, h.q_locked(i));
  }
  // the list in a shuffled order: the reduced q order must not depend on it
  std::shuffle(h.list.begin(), h.list.end(), rng);
  return h;
}

/// A small robot with the examples' joint names: a torso on the base, a two-joint head on it,
/// a three-joint arm on it (arm_1, arm_2, arm_10), a two-finger hand at the arm's end (the
/// index finger mimics the thumb), a camera frame on the head and a tool frame on the arm.
tree<double> named_tree() {
  struct spec {
    const char* joint;
    int parent;
    joint_type type;
    Eigen::Vector3d axis;
  };
  const std::vector<spec> S{
      {"torso_lift_joint", -1, joint_type::prismatic, Eigen::Vector3d::UnitZ()},
      {"head_1_joint", 0, joint_type::revolute, Eigen::Vector3d::UnitZ()},
      {"head_2_joint", 1, joint_type::revolute, Eigen::Vector3d::UnitY()},
      {"arm_1_joint", 0, joint_type::revolute, Eigen::Vector3d::UnitZ()},
      {"arm_2_joint", 3, joint_type::revolute, Eigen::Vector3d::UnitY()},
      {"arm_10_joint", 4, joint_type::revolute, Eigen::Vector3d::UnitX()},
      {"hand_thumb_joint", 5, joint_type::revolute, Eigen::Vector3d::UnitZ()},
      {"hand_index_joint", 5, joint_type::prismatic, Eigen::Vector3d::UnitY()},
  };
  std::mt19937_64 rng(5);
  std::vector<body<double>> B;
  for (const spec& s : S) {
    body<double> b;
    b.joint_name = s.joint;
    b.name = b.joint_name.substr(0, b.joint_name.size() - 6) + "_link";  // "…_joint" → "…_link"
    b.parent = s.parent;
    b.joint = s.type;
    b.axis = s.axis;
    b.R_PJ = nhdyn_ref::random_rotation(rng);
    b.p_PJ = nhdyn_ref::random_vector(rng, 0.3);
    b.mass = nhdyn_ref::uniform(rng, 0.5, 3.0);
    b.com = nhdyn_ref::random_vector(rng, 0.1);
    b.inertia = nhdyn_ref::random_inertia(rng, b.mass);
    b.armature = 0.05;
    b.damping = 0.3;
    b.friction = 0.1;
    b.limits.lower = -1;
    b.limits.upper = 1 + 0.1 * double(B.size());
    B.push_back(b);
  }
  B[7].mimic = mimic_info{"hand_thumb_joint", -1.0, 0.25};
  std::vector<frame<double>> F;
  F.push_back(frame<double>{"camera", 2, nhdyn_ref::random_rotation(rng), nhdyn_ref::random_vector(rng, 0.1)});
  F.push_back(frame<double>{"tool", 5, nhdyn_ref::random_rotation(rng), nhdyn_ref::random_vector(rng, 0.1)});
  return tree<double>(std::move(B), Eigen::Vector3d(0, 0, -9.81), "named", validation{}, "base_link", std::move(F));
}

}  // namespace

TEST_CASE("lock: the reduced tree's rne, mass matrix and forward dynamics are the full tree's at the kept joints, "
          "the locked ones held at their positions",
          "[lock]") {
  std::mt19937_64 rng(32);
  for (int trial = 0; trial < 72; ++trial) {
    const int n = 1 + trial % 24;
    const tree<double> t = decorated(rng, n);
    const held h = random_locks(rng, t, trial % 3 == 0 ? 0.7 : 0.35);
    const int k = static_cast<int>(h.kept.size());
    INFO("trial " << trial << ": " << n << " joints, " << n - k << " locked");
    const tree<double> r = nhdyn::lock(t, h.list);
    REQUIRE(r.dof() == k);
    CHECK(reduced_indices(t, h.list) == h.kept);
    for (int j = 0; j < k; ++j) {  // the kept joints as they were, in q order
      const body<double>& a = r[j];
      const body<double>& b = t[h.kept[std::size_t(j)]];
      CHECK(a.joint_name == b.joint_name);
      CHECK(a.joint == b.joint);
      CHECK(a.armature == b.armature);
      CHECK(a.damping == b.damping);
      CHECK(a.limits.upper == b.limits.upper);
    }
    CHECK(r.gravity() == t.gravity());
    CHECK(r.name() == t.name());
    CHECK(r.root_name() == t.root_name());

    const auto id_full = rne(t);
    const auto id_red = rne(r);
    const auto M_full = mass_matrix(t);
    const auto M_red = mass_matrix(r);
    const auto h_full = bias(t);
    for (int s = 0; s < 3; ++s) {
      const VectorXd qk = random_state(rng, k), qdk = random_state(rng, k), qddk = random_state(rng, k);
      const VectorXd tauk = random_state(rng, k, 20);
      const VectorXd q = h.full(qk, h.q_locked), qd = h.full(qdk, VectorXd::Zero(n)),
                     qdd = h.full(qddk, VectorXd::Zero(n));
      // rne: the kept rows (the locked rows are the torques that hold those joints)
      CHECK(rel(id_red(qk, qdk, qddk), rows(id_full(q, qd, qdd), h.kept)) < 1e-12);
      CHECK(rel(id_red.with({.gravity = false})(qk, qdk, qddk),
                rows(id_full.with({.gravity = false})(q, qd, qdd), h.kept)) < 1e-12);
      CHECK(rel(id_red.with({.velocity = false})(qk, qdk, qddk),
                rows(id_full.with({.velocity = false})(q, qd, qdd), h.kept)) < 1e-12);
      // the mass matrix: the kept block
      const MatrixXd Mkk = block(M_full(q), h.kept);
      CHECK(rel(M_red(qk), Mkk) < 1e-12);
      // forward dynamics with the locked joints held (q̈ = 0 there): M_kk q̈_k = τ_k − h_k,
      // solved here from the full tree's M and bias
      const VectorXd qdd_ref = Mkk.ldlt().solve(VectorXd(tauk - rows(h_full(q, qd), h.kept)));
      for (fd_method m : {fd_method::crba_ldlt, fd_method::aba}) {
        INFO("method " << int(m));
        CHECK(rel(forward_dynamics(r, rne_options{}, fd_options{.method = m})(qk, qdk, tauk), qdd_ref) < 1e-9);
      }
    }
  }
}

TEST_CASE("lock: every body's frame and every named frame keep their poses, by name, on the surviving ancestor",
          "[lock]") {
  std::mt19937_64 rng(33);
  for (int trial = 0; trial < 48; ++trial) {
    const int n = 1 + trial % 24;
    const tree<double> t = decorated(rng, n);
    const held h = random_locks(rng, t, trial % 2 == 0 ? 0.7 : 0.35);
    const int k = static_cast<int>(h.kept.size());
    INFO("trial " << trial << ": " << n << " joints, " << n - k << " locked");
    const tree<double> r = nhdyn::lock(t, h.list);
    const tree_kinematics<double> kf(t), kr(r);
    const VectorXd qk = random_state(rng, k);
    const VectorXd q = h.full(qk, h.q_locked);
    const Eigen::Vector3d on_body(0.1, -0.2, 0.3);  // a point fixed on each body, in its frame
    for (int i = 0; i < n; ++i) {
      INFO("body " << t[i].name << (h.locked[std::size_t(i)] ? " (locked)" : ""));
      // its frame, by name: where the full tree has it
      const auto Xr = kr.frame(qk, t[i].name);
      const auto Xf = kf.frame(q, i + 1);
      CHECK(rel(Xr.R, Xf.R) < 1e-12);
      CHECK(rel(Xr.p, Xf.p) < 1e-12);
      // on the nearest kept ancestor (or the base)
      const frame<double> f = r.find_frame(t[i].name);
      CHECK(f.body == h.survivor(t, i));
      // a point of it moves with the kept joints only: the Jacobian is the full one's kept columns
      const Eigen::Vector3d p_on = f.R * on_body + f.p;
      const MatrixXd Jf = kf.jacobian(q, i + 1, on_body);
      MatrixXd Jk(6, k);
      for (int j = 0; j < k; ++j) Jk.col(j) = Jf.col(h.kept[std::size_t(j)]);
      CHECK(rel(kr.jacobian(qk, f.body + 1, p_on), Jk) < 1e-12);
    }
    // the frames fixed on bodies (kept, locked, the base)
    for (const frame<double>& g : t.frames()) {
      INFO("frame " << g.name << " on body " << g.body);
      const auto Xr = kr.frame(qk, g.name);
      const auto Xf = kf.frame(q, g.name);
      CHECK(rel(Xr.R, Xf.R) < 1e-12);
      CHECK(rel(Xr.p, Xf.p) < 1e-12);
      CHECK(r.find_frame(g.name).body == h.survivor(t, g.body));
    }
    CHECK(r.frames().size() == t.frames().size() + std::size_t(n - k));
  }
}

TEST_CASE("lock: an empty lock list gives the same tree, and lock_map converts joint vectors both ways", "[lock]") {
  const tree<double> t = named_tree();
  const tree<double> same = nhdyn::lock(t, {});
  REQUIRE(same.dof() == t.dof());
  const VectorXd q = VectorXd::LinSpaced(8, -0.7, 0.7), qd = VectorXd::LinSpaced(8, 0.5, -0.3),
                 qdd = VectorXd::LinSpaced(8, 1.0, -1.0);
  CHECK(rne(same)(q, qd, qdd) == rne(t)(q, qd, qdd));
  CHECK(same.frames().size() == t.frames().size());

  const lock_map m = lock_map_of(t, {{"head_*", 0.3}, {"hand_thumb_joint", -0.2}});
  CHECK(m.full_dof == 8);
  CHECK(m.dof() == 5);
  CHECK(m.kept == std::vector<int>{0, 3, 4, 5, 7});
  CHECK(m.locked == std::vector<std::pair<int, double>>{{1, 0.3}, {2, 0.3}, {6, -0.2}});
  CHECK(lock_positions(t, {{"head_*", 0.3}, {"hand_thumb_joint", -0.2}}) == m.locked);
  const VectorXd qk = VectorXd::LinSpaced(5, 1.0, 5.0);
  const VectorXd qf = m.expand_q(qk);
  VectorXd want(8);
  want << 1.0, 0.3, 0.3, 2.0, 3.0, 4.0, -0.2, 5.0;
  CHECK(qf == want);
  want << 1.0, 0.0, 0.0, 2.0, 3.0, 4.0, 0.0, 5.0;
  CHECK(m.expand(qk) == want);
  CHECK(m.reduce(qf) == qk);
  CHECK_THROWS_AS(m.reduce(qk), input_error);
  CHECK_THROWS_AS(m.expand(qf), input_error);
}

TEST_CASE("lock: '*', '?' and [sets] match whole joint names as a shell's patterns do", "[lock]") {
  using nhdyn::detail::glob_match;
  CHECK(glob_match("*", ""));
  CHECK(glob_match("*", "anything"));
  CHECK_FALSE(glob_match("?", ""));
  CHECK(glob_match("a?c", "abc"));
  CHECK_FALSE(glob_match("a?c", "abbc"));
  CHECK(glob_match("a*b*c", "axxbyybzc"));
  CHECK_FALSE(glob_match("a*b*c", "axxbyybzcd"));
  CHECK(glob_match("head_[12]_joint", "head_2_joint"));
  CHECK_FALSE(glob_match("head_[12]_joint", "head_3_joint"));
  CHECK(glob_match("head_[!1]_joint", "head_2_joint"));
  CHECK_FALSE(glob_match("head_[!1]_joint", "head_1_joint"));
  CHECK(glob_match("head_[^1]_joint", "head_2_joint"));
  CHECK(glob_match("arm_[0-9]_joint", "arm_7_joint"));
  CHECK_FALSE(glob_match("arm_[0-9]_joint", "arm_10_joint"));
  CHECK(glob_match("[]]", "]"));
  CHECK(glob_match("[a-]", "-"));
  CHECK(glob_match("a[", "a["));  // an unclosed '[' is an ordinary character
  CHECK(glob_match("a\\*", "a*"));
  CHECK_FALSE(glob_match("a\\*", "ab"));
  CHECK_FALSE(glob_match("arm", "arm_1_joint"));  // the whole name, not a part of it
  CHECK(glob_match("arm_1_joint", "arm_1_joint"));

  const tree<double> t = named_tree();
  CHECK(nhdyn::lock(t, {{"hand_*", 0.0}}).joint_names() ==
        std::vector<std::string>{"torso_lift_joint", "head_1_joint", "head_2_joint", "arm_1_joint", "arm_2_joint",
                                 "arm_10_joint"});
  CHECK(nhdyn::lock(t, {{"arm_?_joint", 0.1}}).joint_names() ==
        std::vector<std::string>{"torso_lift_joint", "head_1_joint", "head_2_joint", "arm_10_joint",
                                 "hand_thumb_joint", "hand_index_joint"});
  CHECK(nhdyn::lock(t, {{"head_[12]_joint", 0.0}, {"*_10_*", 0.5}}).joint_names() ==
        std::vector<std::string>{"torso_lift_joint", "arm_1_joint", "arm_2_joint", "hand_thumb_joint",
                                 "hand_index_joint"});
}

TEST_CASE("lock: kept joints keep their limits, friction, armature and mimic; locked ones leave theirs", "[lock]") {
  const tree<double> t = named_tree();
  const tree<double> r = nhdyn::lock(t, {{"hand_thumb_joint", 0.4}, {"head_2_joint", -0.3}});
  REQUIRE(r.dof() == 6);
  for (int j = 0; j < r.dof(); ++j) {
    const body<double>& a = r[j];
    const body<double>& b = t[t.body_index(a.name)];
    INFO(a.joint_name);
    CHECK(a.limits.lower == b.limits.lower);
    CHECK(a.limits.upper == b.limits.upper);
    CHECK(a.friction_law() == b.friction_law());
    CHECK(a.armature == b.armature);
    CHECK(a.continuous == b.continuous);
  }
  // the index finger still says it mimics the thumb (information only, as every mimic)
  const body<double>& index = r[r.body_index("hand_index_link")];
  REQUIRE(index.mimic.has_value());
  CHECK(index.mimic->joint == "hand_thumb_joint");
  CHECK(index.mimic->multiplier == -1.0);
  CHECK(index.mimic->offset == 0.25);
  // the locked bodies are frames now, not bodies
  CHECK_THROWS_AS(r.body_index("hand_thumb_link"), input_error);
  CHECK(r.find_frame("hand_thumb_link").body == r.body_index("arm_10_link"));
  CHECK(r.find_frame("head_2_link").body == r.body_index("head_1_link"));
  CHECK(r.find_frame("camera").body == r.body_index("head_1_link"));  // it was on head_2_link
  CHECK(r.find_frame("tool").body == r.body_index("arm_10_link"));
}

TEST_CASE("lock: a pattern that matches no joint, or a joint that two patterns match, is an error naming them",
          "[lock]") {
  const tree<double> t = named_tree();
  CHECK_THROWS_AS(nhdyn::lock(t, {{"foot_*", 0.0}}), model_error);
  CHECK_THROWS_WITH(nhdyn::lock(t, {{"foot_*", 0.0}}), Contains("'foot_*'") && Contains("matches no movable joint") &&
                                                    Contains("model 'named'") && Contains("arm_10_joint"));
  CHECK_THROWS_WITH(nhdyn::lock(t, {{"arm_1_joint", 0.0}, {"head_3_joint", 0.0}}), Contains("'head_3_joint'") &&
                                                                                 Contains("matches no movable joint"));
  CHECK_THROWS_AS(nhdyn::lock(t, {{"head_*", 0.0}, {"head_1_joint", 0.3}}), model_error);
  CHECK_THROWS_WITH(nhdyn::lock(t, {{"head_*", 0.0}, {"head_1_joint", 0.3}}),
                    Contains("'head_1_joint'") && Contains("'head_*'") && Contains("both"));
  CHECK_THROWS_WITH(nhdyn::lock(t, {{"arm_1_joint", 0.0}, {"arm_1_joint", 0.0}}), Contains("'arm_1_joint'") && Contains("both"));
  CHECK_THROWS_AS(nhdyn::lock(t, {{"arm_1_joint", std::nan("")}}), model_error);
  CHECK_THROWS_WITH(nhdyn::lock(t, {{"arm_1_joint", INFINITY}}), Contains("'arm_1_joint'") && Contains("not finite"));
  CHECK_THROWS_AS(reduced_indices(t, {{"foot_*", 0.0}}), model_error);
  CHECK_THROWS_AS(lock_indices(t, {{8, 0.0}}), model_error);
  CHECK_THROWS_AS(lock_indices(t, {{2, 0.0}, {2, 0.1}}), model_error);
}

// Needs model/tree.hpp to accept a tree of 0 bodies (its constructor refuses an empty body
// list today: "a tree needs at least one moving body").
TEST_CASE("lock: locking every joint gives a tree of 0 joints whose frames stand where the full tree's bodies stood",
          "[lock]") {
  const tree<double> t = named_tree();
  const tree<double> r = nhdyn::lock(t, {{"*", 0.5}});
  REQUIRE(r.dof() == 0);
  CHECK(r.name() == "named");
  CHECK(r.root_name() == "base_link");
  const VectorXd none = VectorXd::Zero(0);
  CHECK(rne(r)(none, none, none).size() == 0);
  CHECK(mass_matrix(r)(none).size() == 0);
  CHECK(forward_dynamics(r)(none, none, none).size() == 0);
  const tree_kinematics<double> kf(t), kr(r);
  const VectorXd q = VectorXd::Constant(t.dof(), 0.5);
  for (int i = 0; i < t.dof(); ++i) {
    INFO(t[i].name);
    CHECK(r.find_frame(t[i].name).body == -1);
    const auto Xr = kr.frame(none, t[i].name);
    const auto Xf = kf.frame(q, i + 1);
    CHECK(rel(Xr.R, Xf.R) < 1e-12);
    CHECK(rel(Xr.p, Xf.p) < 1e-12);
  }
  for (const std::string name : {"camera", "tool"}) {
    const auto Xr = kr.frame(none, name);
    const auto Xf = kf.frame(q, name);
    CHECK(rel(Xr.R, Xf.R) < 1e-12);
    CHECK(rel(Xr.p, Xf.p) < 1e-12);
  }
  // a list that locks every joint by name does the same
  lock_list all;
  for (const auto& name : t.joint_names()) all.emplace_back(name, 0.5);
  CHECK(nhdyn::lock(t, all).dof() == 0);
}

#ifdef NHDYN_HAVE_URDF
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The URDF text with joint `name` made fixed, its <origin …/> replaced by `origin` (kept if
/// empty): the joint written as held at a position.
std::string fix_joint(std::string text, const std::string& name, const std::string& origin) {
  const std::size_t at = text.find("<joint name=\"" + name + "\"");
  REQUIRE(at != std::string::npos);
  const std::size_t type = text.find("type=\"", at) + 6;
  text.replace(type, text.find('"', type) - type, "fixed");
  if (!origin.empty()) {
    const std::size_t o = text.find("<origin", at);
    text.replace(o, text.find("/>", o) + 2 - o, origin);
  }
  return text;
}

tree<double> parse_quietly(const std::string& text, const std::string& where) {
  io::urdf_options o;
  o.warn = [](const std::string&) {};
  return io::parse_urdf(text, where, o);
}

}  // namespace

TEST_CASE("lock: on the mobile manipulator, locking joints equals the URDF loader's merge of them written as fixed",
          "[lock][urdf]") {
  const std::string text = read_text(std::string(NHDYN_SOURCE_DIR) + "/examples/urdf/mobile_manipulator.urdf");
  const tree<double> full = parse_quietly(text, "mobile_manipulator.urdf");
  REQUIRE(full.dof() == 16);
  using fix_list = std::vector<std::pair<std::string, std::string>>;
  // (what is locked, the same joints as fixed joints at those positions)
  const std::vector<std::pair<lock_list, fix_list>> variants{
      // casters (chains of two locked joints onto the base), the head onto the kept torso at
      // non-zero angles, the last arm joint with its fixed gripper onto arm_6
      {lock_list{{"caster_*", 0.0}, {"head_pan_joint", 0.4}, {"head_tilt_joint", -0.3}, {"arm_7_joint", 0.0}},
       fix_list{{"caster_front_swivel_joint", ""},
                {"caster_front_wheel_joint", ""},
                {"caster_rear_swivel_joint", ""},
                {"caster_rear_wheel_joint", ""},
                {"head_pan_joint", R"(<origin xyz="0 0 0.65" rpy="0 0 0.4"/>)"},
                {"head_tilt_joint", R"(<origin xyz="0 0 0.08" rpy="0 -0.3 0"/>)"},
                {"arm_7_joint", ""}}},
      // the torso onto the base (arm and head re-hung from the base), the caster swivels
      // turned, their wheels kept and re-hung from the base
      {lock_list{{"torso_lift_joint", 0.2}, {"caster_front_swivel_joint", 0.7}, {"caster_rear_swivel_joint", -1.2}},
       fix_list{{"torso_lift_joint", R"(<origin xyz="-0.1 0 0.35" rpy="0 0 0"/>)"},
                {"caster_front_swivel_joint", R"(<origin xyz="0.24 0 -0.05" rpy="0 0 0.7"/>)"},
                {"caster_rear_swivel_joint", R"(<origin xyz="-0.24 0 -0.05" rpy="0 0 -1.2"/>)"}}},
  };
  std::mt19937_64 rng(34);
  for (std::size_t v = 0; v < variants.size(); ++v) {
    INFO("variant " << v);
    const auto& [locks, fixes] = variants[v];
    std::string fixed_text = text;
    for (const auto& [name, origin] : fixes) fixed_text = fix_joint(fixed_text, name, origin);
    const tree<double> ref = parse_quietly(fixed_text, "fixed.urdf");
    const tree<double> r = nhdyn::lock(full, locks);
    REQUIRE(r.joint_names() == ref.joint_names());
    CHECK(r.root_name() == ref.root_name());
    for (int j = 0; j < r.dof(); ++j) {  // body by body
      const body<double>& a = r[j];
      const body<double>& b = ref[j];
      INFO("body " << b.name);
      CHECK(a.name == b.name);
      CHECK(a.parent == b.parent);
      CHECK(rel(a.R_PJ, b.R_PJ) < 1e-12);
      CHECK(rel(a.p_PJ, b.p_PJ) < 1e-12);
      CHECK(rel(a.axis, b.axis) < 1e-15);
      CHECK(std::abs(a.mass - b.mass) < 1e-12 * std::max(1.0, b.mass));
      CHECK(rel(a.com, b.com) < 1e-12);
      CHECK(rel(a.inertia, b.inertia) < 1e-12);
      CHECK(a.limits.lower == b.limits.lower);
      CHECK(a.limits.upper == b.limits.upper);
      CHECK(a.friction_law() == b.friction_law());
    }
    REQUIRE(r.frames().size() == ref.frames().size());
    for (const frame<double>& f : ref.frames()) {
      INFO("frame " << f.name);
      const frame<double> g = r.find_frame(f.name);
      CHECK(g.body == f.body);
      CHECK(rel(g.R, f.R) < 1e-12);
      CHECK(rel(g.p, f.p) < 1e-12);
    }
    const lock_map m = lock_map_of(full, locks);
    for (int s = 0; s < 3; ++s) {
      const VectorXd q = random_state(rng, r.dof()), qd = random_state(rng, r.dof()), qdd = random_state(rng, r.dof());
      const VectorXd v_red = rne(r)(q, qd, qdd);
      CHECK(rel(v_red, rne(ref)(q, qd, qdd)) < 1e-12);
      CHECK(rel(v_red, m.reduce(rne(full)(m.expand_q(q), m.expand(qd), m.expand(qdd)))) < 1e-12);
      CHECK(rel(mass_matrix(r)(q), mass_matrix(ref)(q)) < 1e-12);
    }
  }
}

namespace {
/// The locked robot file's τ (kept actuators), λ and forward dynamics equal the full one's,
/// with the locked joints at their positions and at rest.
/// λ to 1e-11 by default: the two models' λ differ by rounding, up to 1.2e-12 relative on
/// castor_drive_arm (seed 35) since the lift's closed-form rows (theory.md §11).
void check_locked_robot(const io::robot_model& full, const io::robot_model& r, std::uint64_t seed, double lambda_tol = 1e-11) {
  const auto& cf = std::get<wheeled_base<double>>(*full.constraint);
  const auto& cr = std::get<wheeled_base<double>>(*r.constraint);
  const auto jf = full.model.joint_names(), jr = r.model.joint_names();
  const auto ef = cf.eta_names(jf), er = cr.eta_names(jr);
  const auto tf = full.tau_names(), tr = r.tau_names();
  REQUIRE(int(ef.size()) == cf.m());
  REQUIRE(cr.k() == cf.k());
  std::mt19937_64 rng(seed);
  for (int s = 0; s < 5; ++s) {
    VectorXd q = random_state(rng, cf.dof()), eta = random_state(rng, cf.m()), eta_dot = random_state(rng, cf.m());
    for (const auto& [name, x] : r.locked) {
      q(std::find(jf.begin(), jf.end(), name) - jf.begin()) = x;
      const auto e = std::find(ef.begin(), ef.end(), name) - ef.begin();
      eta(e) = eta_dot(e) = 0;
    }
    const auto index = [](const std::vector<std::string>& from, const std::vector<std::string>& names) {
      std::vector<int> out;
      for (const auto& n : names) out.push_back(int(std::find(from.begin(), from.end(), n) - from.begin()));
      return out;
    };
    const VectorXd qr = rows(q, index(jf, jr)), etar = rows(eta, index(ef, er)), eta_dotr = rows(eta_dot, index(ef, er));
    const auto ff = inverse_dynamics_with_forces(full.model, cf)(q, eta, eta_dot);
    const auto fr = inverse_dynamics_with_forces(r.model, cr)(qr, etar, eta_dotr);
    CHECK(rel(fr.tau, rows(ff.tau, index(tf, tr))) < 1e-12);  // τ: the drive wheels and the kept arm joints
    INFO("lambda: " << rel(fr.lambda, ff.lambda));
    CHECK(rel(fr.lambda, ff.lambda) < lambda_tol);            // the floor's forces on the wheels
    // forward dynamics of the locked robot returns the motion from those torques
    CHECK(rel(nh_forward_dynamics(r.model, cr)(qr, etar, VectorXd(fr.tau)), eta_dotr) < 1e-9);
  }
}
}  // namespace

TEST_CASE("lock: a robot file's \"locked\" arm on a castor base keeps the paper's method exact", "[lock][urdf]") {
  const std::string robots = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/";
  const auto full = io::load_robot_file(robots + "castor_drive_arm.json");
  io::json j = io::json::parse(read_text(robots + "castor_drive_arm.json"));
  j["urdf"] = std::string(NHDYN_SOURCE_DIR) + "/examples/urdf/castor_drive_arm.urdf";
  j["locked"] = io::json::parse(R"({"arm_wrist_*": 0.4})");
  const auto dir = std::filesystem::temp_directory_path();
  const std::string path = (dir / ("nhdyn_test_lock_" + std::to_string(::getpid()) + ".json")).string();
  std::ofstream(path) << j.dump();
  const auto r = io::load_robot_file(path);
  REQUIRE(r.model.dof() == full.model.dof() - 3);
  CHECK(r.locked == lock_list{{"arm_wrist_1_joint", 0.4}, {"arm_wrist_2_joint", 0.4}, {"arm_wrist_3_joint", 0.4}});
  check_locked_robot(full, r, 35);
  // a castor's swivel is the constraint's: it cannot be locked
  j["locked"] = io::json::parse(R"({"caster_front_swivel_joint": 0.0})");
  std::ofstream(path) << j.dump();
  CHECK_THROWS_WITH(io::load_robot_file(path), Contains("field 'locked'") && Contains("'caster_front_swivel_joint'") &&
                                                   Contains("belongs to the constraint (wheeled_base)"));
  j["locked"] = io::json::parse(R"({"arm_*": "up"})");
  std::ofstream(path) << j.dump();
  CHECK_THROWS_WITH(io::load_robot_file(path), Contains("field 'locked'") && Contains("'arm_*'") &&
                                                   Contains("expected a finite position"));
  std::filesystem::remove(path);
}
TEST_CASE("lock: the TIAGo-style robot with its hand and head held keeps the paper's method exact", "[lock][urdf]") {
  // 59 coordinates (a planar base, 2 drive wheels, 4 castors, torso, 2 head, 7 arm, a
  // five-finger hand of 36 joints); held: the hand and the head (38 joints)
  const std::string robots = std::string(NHDYN_SOURCE_DIR) + "/examples/robots/";
  const auto full = io::load_robot_file(robots + "tiago_style.json");
  REQUIRE(full.model.dof() == 59);
  const auto r = io::lock_robot(full, {{"hand_*", 0.1}, {"head_*", 0.2}}, "test: ");
  REQUIRE(r.model.dof() == 21);
  REQUIRE(r.locked.size() == 38);
  // λ solves through the full robot's M, whose finger links of 1e-7 kg m² cost it digits
  // (2e-12 relative seen): 1e-10
  check_locked_robot(full, r, 36, 1e-10);
}
#endif

#ifdef NHDYN_HAVE_URDF
namespace {
/// A JSON (DH) model with "locked", as io::as_robot gives it, against the full chain (the DH
/// kernels): the nonholonomic τ and λ of the kept η entries with the locked joints at their
/// positions, at rest.
void check_locked_chain(const io::model<double>& m, std::uint64_t seed) {
  const io::robot_model r = io::as_robot(m, "test: ");
  const int n = m.chain.dof();
  REQUIRE(r.model.dof() == n - int(m.locked.size()));
  const auto& cf = *m.constraint;
  const auto& cr = std::get<differential_drive<double>>(*r.constraint);
  std::vector<std::string> jf;
  for (int i = 1; i <= n; ++i) jf.push_back("joint" + std::to_string(i));
  const auto jr = r.model.joint_names();
  const auto ef = cf.eta_names(jf), er = cr.eta_names(jr);
  const auto index = [](const std::vector<std::string>& from, const std::vector<std::string>& names) {
    std::vector<int> out;
    for (const auto& name : names) out.push_back(int(std::find(from.begin(), from.end(), name) - from.begin()));
    return out;
  };
  std::mt19937_64 rng(seed);
  for (int s = 0; s < 5; ++s) {
    VectorXd q = random_state(rng, n), eta = random_state(rng, cf.m()), eta_dot = random_state(rng, cf.m());
    for (const auto& [name, x] : r.locked) {
      q(std::find(jf.begin(), jf.end(), name) - jf.begin()) = x;
      const auto e = std::find(ef.begin(), ef.end(), name) - ef.begin();
      eta(e) = eta_dot(e) = 0;
    }
    const auto ff = inverse_dynamics_with_forces(m.chain, cf)(q, eta, eta_dot);
    const auto fr = inverse_dynamics_with_forces(r.model, cr)(rows(q, index(jf, jr)), rows(eta, index(ef, er)),
                                                              rows(eta_dot, index(ef, er)));
    CHECK(rel(fr.tau, rows(ff.tau, index(ef, er))) < 1e-12);
    CHECK(rel(fr.lambda, ff.lambda) < 1e-12);
  }
}
}  // namespace

TEST_CASE("lock: a JSON (DH) model's \"locked\" is its chain as a tree with those joints held; the paper's method stays exact",
          "[lock][urdf]") {
  // paper5 with its last arm joint held; the file's round trip carries "locked"
  auto p5 = io::load("paper5");
  p5.locked = {{"joint5", 0.7}};
  const auto m = io::parse_model(io::to_string(p5), "test");
  REQUIRE(m.locked == lock_list{{"joint5", 0.7}});
  REQUIRE(m.chain.dof() == 5);  // io::load keeps the full chain
  check_locked_chain(m, 41);
  // puma560 under a differential drive on joints 3-5 with joints 1 and 6 held: the
  // constraint's indices move down by one in the smaller tree
  auto j = io::to_json(io::load("puma560"));
  j["constraint"] = io::ordered_json::parse(R"({"type": "differential_drive", "x": 2, "y": 3, "heading": 4})");
  j["locked"] = io::ordered_json::parse(R"({"joint1": 0.3, "joint6": -0.2})");
  const auto puma = io::parse_model(j.dump(), "test");
  const auto r = io::as_robot(puma);
  const auto& c = std::get<differential_drive<double>>(*r.constraint);
  CHECK((c.n == 4 && c.x == 1 && c.y == 2 && c.heading == 3));
  CHECK(r.locked == lock_list{{"joint1", 0.3}, {"joint6", -0.2}});
  check_locked_chain(puma, 42);
  // a joint of the constraint cannot be held; "locked" is checked as a robot file's is
  p5.locked = {{"joint[2-3]", 0.0}};
  CHECK_THROWS_WITH(io::as_robot(p5, "model 'p', locked: "),
                    Contains("model 'p', locked: ") && Contains("'joint2' belongs to the constraint (differential_drive)"));
  j["locked"] = io::ordered_json::parse(R"({"joint2": "up"})");
  CHECK_THROWS_WITH(io::parse_model(j.dump(), "file 'x.json'"),
                    Contains("file 'x.json'") && Contains("field 'locked'") && Contains("'joint2': expected a finite position"));
}
#endif
