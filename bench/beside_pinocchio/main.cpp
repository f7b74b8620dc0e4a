/// \file bench/beside_pinocchio/main.cpp
/// The models, the agreement check and the alternating timing (api.hpp; run.sh builds it).
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/io/urdf.hpp>
#include <reference/random_tree.hpp>
#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include "api.hpp"
// the same tree with its bodies in depth-first pre-order (Pinocchio's CRBA and derivatives
// take each subtree's velocities as one contiguous block, as its URDF parser numbers them)
static nhdyn::tree<double> dfs_order(const nhdyn::tree<double>& t) {
  const int n = t.dof();
  std::vector<std::vector<int>> kids(n + 1);
  for (int i = 0; i < n; ++i) kids[t[i].parent + 1].push_back(i);
  std::vector<int> order, newid(n), stack{-1};
  while (!stack.empty()) {
    const int i = stack.back(); stack.pop_back();
    if (i >= 0) { newid[i] = int(order.size()); order.push_back(i); }
    for (auto it = kids[i + 1].rbegin(); it != kids[i + 1].rend(); ++it) stack.push_back(*it);
  }
  std::vector<nhdyn::body<double>> B;
  for (int i : order) { auto b = t[i]; b.parent = b.parent < 0 ? -1 : newid[b.parent]; B.push_back(b); }
  return nhdyn::tree<double>(B, t.gravity(), t.name());
}
static double med(std::vector<double> v) { std::sort(v.begin(), v.end()); return v[v.size() / 2]; }
static double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return 1e300;
  return (a - b).cwiseAbs().maxCoeff() / (1.0 + b.cwiseAbs().maxCoeff());
}
int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s <example-robot-data directory> [blocks = 21]\n", argv[0]);
    return 2;
  }
  const std::string erd = argv[1];
  const int blocks = argc > 2 ? std::atoi(argv[2]) : 21;
  std::vector<std::pair<std::string, nhdyn::tree<double>>> models;
  // published files (example-robot-data, as published), then the project's own
  for (const auto& [name, file] : {std::pair{"panda", "panda_description/urdf/panda.urdf"},
                                   std::pair{"ur5", "ur_description/urdf/ur5_robot.urdf"},
                                   std::pair{"tiago", "tiago_description/robots/tiago.urdf"},
                                   std::pair{"pr2", "pr2_description/urdf/pr2.urdf"},
                                   std::pair{"talos", "talos_data/robots/talos_full_v2.urdf"}})
    models.emplace_back(name, nhdyn::io::load_urdf(erd + "/robots/" + file));
  for (const char* f : {"mobile_manipulator", "powered_castors_arm", "tiago_style"})
    models.emplace_back(f, nhdyn::io::load_urdf(std::string(NHDYN_SOURCE_DIR "/examples/urdf/") + f + ".urdf"));
  std::mt19937_64 tree_rng(41);  // the benchmark's trees (bench/nhdyn_bench.cpp)
  for (int n : {12, 24, 48, 96})
    models.emplace_back("tree" + std::to_string(n), dfs_order(nhdyn_ref::random_tree(tree_rng, n, 0.4, false)));
  const char* names[] = {"rne", "crba", "aba", "rne_derivatives", "crba", "aba"};
  std::printf("ns per call, medians of %d paired blocks of about 1 ms each (64 states); "
              "ratio = nhdyn / Pinocchio\n", blocks);
  for (auto& [name, t] : models) {
    const int n = t.dof();
    states s{n};
    std::mt19937_64 rng(7 + n);
    std::uniform_real_distribution<double> U(-1, 1);
    const auto id = nhdyn::rne(t);
    for (int k = 0; k < 64; ++k) {
      Eigen::VectorXd q(n), qd(n), qdd(n);
      for (int i = 0; i < n; ++i) q(i) = 3 * U(rng), qd(i) = U(rng), qdd(i) = U(rng);
      s.q.push_back(q), s.qd.push_back(qd), s.qdd.push_back(qdd), s.tau.push_back(id(q, qd, qdd));
    }
    void* a = nh_make(t);
    void* b = pin_make(t);
    outs oa, ob;
    nh_outs(a, s, oa);
    pin_outs(b, s, ob);
    const double e[] = {rel(oa.tau, ob.tau), rel(oa.M, ob.M), rel(oa.qdd, ob.qdd), rel(oa.dq, ob.dq), rel(oa.dv, ob.dv),
                        rel(oa.tau_d, ob.tau_d), rel(oa.M_d, ob.M_d)};
    std::printf("%s n=%d  agree (max |nhdyn - Pinocchio| / (1 + max |Pinocchio|)): "
                "tau %.1e M %.1e qdd %.1e dq %.1e dv %.1e (derivatives' tau %.1e, M %.1e)\n",
                name.c_str(), n, e[0], e[1], e[2], e[3], e[4], e[5], e[6]);
    if (!(*std::max_element(std::begin(e), std::end(e)) < 1e-9)) {
      std::printf("the two libraries disagree on %s: not timed\n", name.c_str());
      nh_free(a);
      pin_free(b);
      return 1;
    }
    for (int algo : {0, 1, 4, 2, 5, 3}) {
      const double one = nh_run(a, algo, s, 256) / 256;
      const long K = std::max<long>(64, long(1e-3 / one));
      std::vector<double> ta, tb, r;
      for (int k = 0; k < blocks; ++k) {
        double x, y;
        if (k & 1) { y = pin_run(b, algo, s, K); x = nh_run(a, algo, s, K); }
        else { x = nh_run(a, algo, s, K); y = pin_run(b, algo, s, K); }
        ta.push_back(x / K * 1e9), tb.push_back(y / K * 1e9), r.push_back(x / y);
      }
      std::printf("  %-16s %-6s nhdyn %9.0f ns  pinocchio %9.0f ns  ratio %.2f (paired median; range %.2f-%.2f)\n",
                  names[algo], algo == 1 || algo == 2 ? "local" : algo >= 4 ? "world" : "", med(ta), med(tb), med(r),
                  *std::min_element(r.begin(), r.end()), *std::max_element(r.begin(), r.end()));
    }
    nh_free(a);
    pin_free(b);
    std::fflush(stdout);
  }
}
