// `nhdyn linearize` and `nhdyn bound`, driven as a user would: the real binary, JSON lines.
// Expected values come from other routes: A, B against central finite differences of the
// library's forward dynamics; bounds against 1000 random states evaluated in double; the
// printed decimal text of every bound compared exactly (50 digits) with the library's
// enclosure, so that printing provably never narrowed it.
#define NHDYN_NO_FLOAT128 1  // only cpp_bin_float is used here: no libquadmath needed
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nhdyn/analysis/bounds.hpp>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/io/json.hpp>
#include <nhdyn/nhdyn.hpp>
#include <nhdyn/scalar/multiprecision.hpp>
#include <random>
#include <regex>
#include <sstream>

#include "../support/scratch_dir.hpp"

namespace fs = std::filesystem;
using nhdyn::io::json;

namespace {

struct run_result {
  int status = -1;
  std::vector<std::string> lines;
};

run_result run_tool(const std::string& args, const std::string& input) {
  static int count = 0;
  const auto& dir = nhdyn_test::scratch_dir("lb");
  const auto base = (dir / ("run" + std::to_string(++count))).string();
  std::ofstream(base + ".in", std::ios::binary) << input;
  const std::string cmd = std::string("'") + NHDYN_TOOL_PATH + "' " + args + " < '" + base + ".in' > '" + base +
                          ".out' 2> '" + base + ".err'";
  const int raw = std::system(cmd.c_str());
  run_result r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream out(base + ".out");
  for (std::string s; std::getline(out, s);) r.lines.push_back(s);
  return r;
}

std::string vec(const Eigen::VectorXd& v) {
  std::ostringstream os;
  os.precision(17);
  os << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) os << (i ? ", " : "") << v(i);
  return os.str() + "]";
}
std::string boxes(const Eigen::VectorXd& c, double r) {
  std::ostringstream os;
  os.precision(17);
  os << "[";
  for (Eigen::Index i = 0; i < c.size(); ++i) os << (i ? ", " : "") << "[" << c(i) - r << ", " << c(i) + r << "]";
  return os.str() + "]";
}
Eigen::MatrixXd matrix(const json& j) {
  Eigen::MatrixXd m(j.size(), j[0].size());
  for (std::size_t r = 0; r < j.size(); ++r)
    for (std::size_t c = 0; c < j[r].size(); ++c) m(r, c) = j[r][c].get<double>();
  return m;
}

const Eigen::VectorXd q0 = (Eigen::VectorXd(5) << 0.1, -0.2, 0.7, 0.4, -0.9).finished();
const Eigen::VectorXd eta0 = (Eigen::VectorXd(4) << 0.3, 0.5, 1.2, -0.7).finished();
const Eigen::VectorXd etad0 = (Eigen::VectorXd(4) << 0.2, -0.3, 1.0, 0.5).finished();

}  // namespace

TEST_CASE("tool linearize: paper5's A and B match central differences of the forward dynamics") {
  const auto r = nhdyn::presets::paper5();
  const Eigen::VectorXd tau = nhdyn::inverse_dynamics(r.chain, r.constraint)(q0, eta0, etad0);
  const auto res = run_tool("linearize --model paper5", "{\"q\": " + vec(q0) + ", \"eta\": " + vec(eta0) + ", \"tau\": " + vec(tau) + "}\n");
  REQUIRE(res.status == 0);
  REQUIRE(res.lines.size() == 1);
  const json j = json::parse(res.lines[0]);
  const Eigen::MatrixXd A = matrix(j["A"]), B = matrix(j["B"]);
  REQUIRE(A.rows() == 9);
  REQUIRE(A.cols() == 9);
  REQUIRE(B.rows() == 9);
  REQUIRE(B.cols() == 4);
  const auto fd = nhdyn::nh_forward_dynamics(r.chain, r.constraint);
  const auto f = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd d(9);
    d << nhdyn::apply_S(r.constraint, x.head(5), x.segment(5, 4)), fd(x.head(5), x.segment(5, 4), x.tail(4));
    return d;
  };
  Eigen::VectorXd x(13);
  x << q0, eta0, tau;
  const Eigen::MatrixXd J = nhdyn::central_difference_jacobian(f, x, 1e-5);
  CHECK((A - J.leftCols(9)).cwiseAbs().maxCoeff() < 1e-7 * std::max(1.0, J.cwiseAbs().maxCoeff()));
  CHECK((B - J.rightCols(4)).cwiseAbs().maxCoeff() < 1e-7 * std::max(1.0, J.cwiseAbs().maxCoeff()));
}

TEST_CASE("tool linearize: the Puma 560 gives x = (q, qd) with 12 states, and bad lines are errors") {
  const std::string z6 = "[0, 0, 0, 0, 0, 0]";
  const auto res = run_tool("linearize --model puma560",
                            "{\"q\": [0.3, -0.8, 1.1, 0.2, -0.5, 0.9], \"qd\": " + z6 + ", \"tau\": " + z6 + "}\n" +
                                "{\"q\": " + z6 + ", \"eta\": " + z6 + ", \"tau\": " + z6 + "}\n" + "{\"q\": [1, 2]}\n");
  REQUIRE(res.lines.size() == 3);
  CHECK(res.status == 1);
  const json j = json::parse(res.lines[0]);
  const Eigen::MatrixXd A = matrix(j["A"]);
  CHECK(A.rows() == 12);
  CHECK((A.topRightCorner(6, 6) - Eigen::MatrixXd::Identity(6, 6)).norm() == 0.0);
  CHECK(res.lines[1].find("line 2: ") != std::string::npos);
  CHECK(res.lines[1].find("no constraint") != std::string::npos);
  CHECK(res.lines[2].find("line 3: ") != std::string::npos);
}

TEST_CASE("tool bound: 1000 random states of the box give torques inside the printed bounds") {
  const auto r = nhdyn::presets::paper5();
  const auto id = nhdyn::inverse_dynamics(r.chain, r.constraint);
  const double rad = 0.05;
  for (int split : {0, 4}) {
    const auto res = run_tool("bound --model paper5", "{\"q\": " + boxes(q0, rad) + ", \"eta\": " + boxes(eta0, rad) +
                                                          ", \"eta_dot\": " + boxes(etad0, rad) + ", \"split\": " +
                                                          std::to_string(split) + "}\n");
    REQUIRE(res.status == 0);
    REQUIRE(res.lines.size() == 1);
    const json j = json::parse(res.lines[0]);
    REQUIRE(j["tau"].size() == 4);
    std::mt19937 g(5);
    std::uniform_real_distribution<double> u(-rad, rad);
    int outside = 0;
    for (int k = 0; k < 1000; ++k) {
      Eigen::VectorXd q = q0, e = eta0, ed = etad0;
      for (auto* v : {&q, &e, &ed})
        for (Eigen::Index i = 0; i < v->size(); ++i) (*v)(i) += u(g);
      const Eigen::VectorXd t = id(q, e, ed);
      for (int i = 0; i < 4; ++i) outside += !(j["tau"][i][0].get<double>() <= t(i) && t(i) <= j["tau"][i][1].get<double>());
    }
    CHECK(outside == 0);
    // The printed decimal text, read exactly, encloses the library's enclosure of the same
    // (outward-rounded) box: printing did not narrow.
    nhdyn::box<5> Q;
    nhdyn::box<4> H, HD;
    for (int i = 0; i < 5; ++i) Q(i) = nhdyn::outward(q0(i) - rad, q0(i) + rad);
    for (int i = 0; i < 4; ++i) {
      H(i) = nhdyn::outward(eta0(i) - rad, eta0(i) + rad);
      HD(i) = nhdyn::outward(etad0(i) - rad, etad0(i) + rad);
    }
    const auto T = nhdyn::torque_bounds(r.chain, r.constraint, Q, H, HD, split);
    const std::regex num(R"(-?[0-9][0-9.]*(?:[eE][-+]?[0-9]+)?)");
    const std::string body = res.lines[0];
    std::vector<std::string> texts;
    for (auto it = std::sregex_iterator(body.begin(), body.end(), num); it != std::sregex_iterator(); ++it)
      texts.push_back(it->str());
    REQUIRE(texts.size() == 8);
    for (int i = 0; i < 4; ++i) {
      INFO("tau[" << i << "] printed [" << texts[2 * i] << ", " << texts[2 * i + 1] << "], enclosure " << T(i));
      CHECK(nhdyn::mp50(texts[2 * i].c_str()) <= nhdyn::mp50(T(i).lower()));
      CHECK(nhdyn::mp50(texts[2 * i + 1].c_str()) >= nhdyn::mp50(T(i).upper()));
    }
  }
}

TEST_CASE("tool bound: unbounded enclosures, bad boxes and bad split are error lines naming what") {
  const std::string q = boxes(q0, 0.01), e = boxes(eta0, 0.01);
  const std::string huge = "[[0.3, 0.31], [-1e200, 1e200], [1.2, 1.21], [-0.7, -0.69]]";
  const auto res = run_tool("bound --model paper5",
                            "{\"q\": " + q + ", \"eta\": " + huge + ", \"eta_dot\": " + e + "}\n" +
                                "{\"q\": " + q + ", \"eta\": [[1, 0], [0, 1], [0, 1], [0, 1]], \"eta_dot\": " + e + "}\n" +
                                "{\"q\": " + q + ", \"eta\": " + e + ", \"eta_dot\": " + e + ", \"split\": 99}\n" +
                                "{\"q\": " + q + ", \"eta\": " + e + ", \"eta_dot\": " + e + ", \"split\": 2}\n");
  REQUIRE(res.lines.size() == 4);
  CHECK(res.status == 1);
  CHECK(res.lines[0].find("tau") != std::string::npos);
  CHECK(res.lines[0].find("unbounded") != std::string::npos);
  CHECK(res.lines[1].find("'eta'[0]") != std::string::npos);
  CHECK(res.lines[2].find("split") != std::string::npos);
  CHECK(res.lines[3].find("\"tau\"") != std::string::npos);
}
