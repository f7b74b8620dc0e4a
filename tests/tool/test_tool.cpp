// The `nhdyn` tool, driven as a user would: the real binary, JSON lines on stdin.
// Expected values come from the library through a second route (CRBA mass matrix and
// bias, the constraint's S, Ṡ, A written out), never from the tool's own output.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nhdyn/io/json.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>
#include <nhdyn/version.hpp>
#include <sstream>

#include "../support/scratch_dir.hpp"

namespace fs = std::filesystem;
using nhdyn::io::json;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

fs::path source_dir() { return NHDYN_SOURCE_DIR; }

fs::path scratch() { return nhdyn_test::scratch_dir("tool"); }

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

struct run_result {
  int status = -1;
  std::vector<std::string> lines;  // stdout, split at '\n'
  std::string out, err;
};

/// Runs `nhdyn ARGS` with `input` on stdin.
run_result run_tool(const std::string& args, const std::string& input) {
  static int count = 0;
  const auto base = scratch() / ("run" + std::to_string(++count));
  const auto in = base.string() + ".in", out = base.string() + ".out", err = base.string() + ".err";
  std::ofstream(in, std::ios::binary) << input;
  const std::string cmd = std::string("'") + NHDYN_TOOL_PATH + "' " + args + " < '" + in + "' > '" + out +
                          "' 2> '" + err + "'";
  const int raw = std::system(cmd.c_str());
  run_result r;
  REQUIRE(WIFEXITED(raw));
  r.status = WEXITSTATUS(raw);
  r.out = read_text(out);
  r.err = read_text(err);
  std::istringstream s(r.out);
  for (std::string l; std::getline(s, l);) r.lines.push_back(l);
  return r;
}

std::string num(double x) { return nhdyn::io::format_number(x); }

std::string arr(const VectorXd& v) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + num(v(i));
  return s + "]";
}

VectorXd vec(const json& j) {
  REQUIRE(j.is_array());
  VectorXd v(static_cast<Eigen::Index>(j.size()));
  for (std::size_t i = 0; i < j.size(); ++i) v(static_cast<Eigen::Index>(i)) = j[i].get<double>();
  return v;
}

/// Parses a successful output line and returns the array under `key`.
VectorXd field(const std::string& line, const std::string& key) {
  INFO("output line: " << line);
  const json j = json::parse(line);
  REQUIRE(j.is_object());
  REQUIRE_FALSE(j.contains("error"));
  REQUIRE(j.contains(key));
  return vec(j[key]);
}

VectorXd random_vector(std::mt19937_64& rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = u(rng);
  return v;
}

void require_close(const VectorXd& a, const VectorXd& b, double rel) {
  INFO("a = " << a.transpose() << "\nb = " << b.transpose());
  REQUIRE(a.size() == b.size());
  REQUIRE((a - b).norm() <= rel * std::max(1.0, b.norm()));
}

struct holonomic_state {
  VectorXd q, qd, qdd;
};

std::vector<holonomic_state> random_states(int n, int count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::vector<holonomic_state> s;
  for (int k = 0; k < count; ++k)
    s.push_back({random_vector(rng, n, 3), random_vector(rng, n, 2), random_vector(rng, n, 5)});
  return s;
}

}  // namespace

TEST_CASE("tool: id on puma560 equals the library's rne and M(q)·qdd + bias(q, qd) from CRBA") {
  const auto ch = nhdyn::presets::puma560<double>().dynamic_size();
  const auto states = random_states(6, 25, 1);
  std::string input;
  for (const auto& s : states) input += R"({"q": )" + arr(s.q) + R"(, "qd": )" + arr(s.qd) + R"(, "qdd": )" + arr(s.qdd) + "}\n";
  const auto r = run_tool("id --model puma560", input);
  REQUIRE(r.status == 0);
  REQUIRE(r.err.empty());
  REQUIRE(r.lines.size() == states.size());
  const auto M = nhdyn::mass_matrix(ch);
  const auto bias = nhdyn::bias(ch);
  const auto rne = nhdyn::rne(ch);
  for (std::size_t k = 0; k < states.size(); ++k) {
    const auto& s = states[k];
    const VectorXd tau = field(r.lines[k], "tau");
    const MatrixXd Mq = M(s.q);
    require_close(tau, Mq * s.qdd + VectorXd(bias(s.q, s.qd)), 1e-12);  // second algorithm
    require_close(tau, rne(s.q, s.qd, s.qdd), 1e-13);                    // the same algorithm
  }
}

TEST_CASE("tool: fd on puma560 equals the library's forward dynamics and inverts id through the tool") {
  const auto ch = nhdyn::presets::puma560<double>().dynamic_size();
  const auto states = random_states(6, 20, 2);
  std::string id_in;
  for (const auto& s : states) id_in += R"({"q": )" + arr(s.q) + R"(, "qd": )" + arr(s.qd) + R"(, "qdd": )" + arr(s.qdd) + "}\n";
  const auto id = run_tool("id --model puma560", id_in);
  REQUIRE(id.status == 0);
  std::string fd_in;
  for (std::size_t k = 0; k < states.size(); ++k)
    fd_in += R"({"q": )" + arr(states[k].q) + R"(, "qd": )" + arr(states[k].qd) + R"(, "tau": )" +
             arr(field(id.lines[k], "tau")) + "}\n";
  const auto fd = run_tool("fd --model puma560", fd_in);
  REQUIRE(fd.status == 0);
  REQUIRE(fd.lines.size() == states.size());
  const auto fd_lib = nhdyn::forward_dynamics(ch);
  for (std::size_t k = 0; k < states.size(); ++k) {
    const VectorXd qdd = field(fd.lines[k], "qdd");
    require_close(qdd, states[k].qdd, 1e-9);  // fd ∘ id = identity (M's condition number allows ~1e-12)
    require_close(qdd, fd_lib(states[k].q, states[k].qd, field(id.lines[k], "tau")), 1e-13);
  }
}

TEST_CASE("tool: id on paper5 gives tau and lambda of the projected equations S^T(M qdd + bias)") {
  const auto r5 = nhdyn::presets::paper5<double>();
  const auto ch = r5.chain.dynamic_size();
  const auto& c = r5.constraint;
  std::mt19937_64 rng(3);
  struct zeta {
    VectorXd q, eta, eta_dot;
  };
  std::vector<zeta> states;
  for (int k = 0; k < 20; ++k)
    states.push_back({random_vector(rng, 5, 3), random_vector(rng, 4, 2), random_vector(rng, 4, 5)});
  std::string input;
  for (const auto& s : states)
    input += R"({"q": )" + arr(s.q) + R"(, "eta": )" + arr(s.eta) + R"(, "eta_dot": )" + arr(s.eta_dot) + "}\n";
  // The same through a model file: identical output, byte for byte.
  const auto r = run_tool("id --model paper5", input);
  const auto from_file = run_tool("id --model '" + (source_dir() / "examples/models/paper5.json").string() + "'", input);
  REQUIRE(r.status == 0);
  REQUIRE(r.lines.size() == states.size());
  REQUIRE(from_file.out == r.out);
  const auto M = nhdyn::mass_matrix(ch);
  const auto bias = nhdyn::bias(ch);
  for (std::size_t k = 0; k < states.size(); ++k) {
    const auto& s = states[k];
    const MatrixXd S = c.S(s.q), A = c.A(s.q);
    const VectorXd qd = S * s.eta;
    const MatrixXd Sdot = c.Sdot(s.q, qd);
    const VectorXd qdd = S * s.eta_dot + Sdot * s.eta;  // eq. 19
    const VectorXd v = MatrixXd(M(s.q)) * qdd + VectorXd(bias(s.q, qd));
    const VectorXd tau = (S.transpose() * S).ldlt().solve(S.transpose() * v);  // eq. 18, E = S
    const VectorXd lambda = (A * A.transpose()).ldlt().solve(A * (v - S * tau));
    require_close(field(r.lines[k], "tau"), tau, 1e-12);
    require_close(field(r.lines[k], "lambda"), lambda, 1e-12);
    // Power balance: the constraint forces do no work along the allowed motion.
    CHECK(std::abs(qd.dot(A.transpose() * field(r.lines[k], "lambda"))) <= 1e-12 * (1 + lambda.norm() * qd.norm()));
  }
}

TEST_CASE("tool: fd on paper5 inverts id through the tool and equals nh_forward_dynamics") {
  const auto r5 = nhdyn::presets::paper5<double>();
  const auto fd_lib = nhdyn::nh_forward_dynamics(r5.chain.dynamic_size(), nhdyn::differential_drive<double>(5, 0, 1, 2, 0, -1));
  std::mt19937_64 rng(4);
  std::vector<std::array<VectorXd, 3>> states;
  std::string id_in;
  for (int k = 0; k < 20; ++k) {
    states.push_back({random_vector(rng, 5, 3), random_vector(rng, 4, 2), random_vector(rng, 4, 5)});
    id_in += R"({"q": )" + arr(states.back()[0]) + R"(, "eta": )" + arr(states.back()[1]) + R"(, "eta_dot": )" +
             arr(states.back()[2]) + "}\n";
  }
  const auto id = run_tool("id --model paper5", id_in);
  REQUIRE(id.status == 0);
  std::string fd_in;
  for (std::size_t k = 0; k < states.size(); ++k)
    fd_in += R"({"q": )" + arr(states[k][0]) + R"(, "eta": )" + arr(states[k][1]) + R"(, "tau": )" +
             arr(field(id.lines[k], "tau")) + "}\n";
  const auto fd = run_tool("fd --model paper5", fd_in);
  REQUIRE(fd.status == 0);
  REQUIRE(fd.lines.size() == states.size());
  for (std::size_t k = 0; k < states.size(); ++k) {
    const VectorXd eta_dot = field(fd.lines[k], "eta_dot");
    require_close(eta_dot, states[k][2], 1e-8);
    require_close(eta_dot, fd_lib(states[k][0], states[k][1], field(id.lines[k], "tau")), 1e-13);
  }
}

TEST_CASE("tool: a bad line gets an error line naming the problem, the others go on, exit status 1") {
  const std::string good = R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0]})";
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {good, {}},
      {R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0]})", {"line 2", "missing key(s) 'qdd'"}},
      {R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0], "qddd": 1})", {"line 3", "unknown key(s) 'qddd'"}},
      {R"({"q": [0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0]})", {"line 4", "'q' has 5 entries", "needs 6"}},
      {R"({"q": [0, 0, "x", 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0]})", {"line 5", "'q'[2]", "not a number"}},
      {R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 1e400], "qdd": [0, 0, 0, 0, 0, 0]})", {"line 6", "number overflow", "1e400"}},
      {R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, NaN]})", {"line 7", "invalid JSON"}},
      {R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0)", {"line 8", "invalid JSON", "column"}},
      {"", {"line 9", "empty line"}},
      {"[1, 2, 3]", {"line 10", "expected a JSON object"}},
      {R"({"q": 0, "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0]})", {"line 11", "'q' is a number, not an array"}},
      {R"({"q": [0, 0, 0, 0, 0, 0], "q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0]})", {"line 12", "duplicate key 'q'"}},
      {R"({"q": [0, 0, 0, 0, 0, 0], "qd": [1e200, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0]})", {"line 13", "not finite"}},
      {R"({"q": [0, 0, 0, 0, 0, 0], "eta": [0, 0, 0, 0, 0], "eta_dot": [0, 0, 0, 0, 0]})", {"line 14", "has no constraint"}},
      {good + "\r", {}},  // CRLF line ending
      {good, {}},
  };
  std::string input;
  for (const auto& c : cases) input += c.first + "\n";
  const auto r = run_tool("id --model puma560", input);
  CHECK(r.status == 1);
  REQUIRE(r.lines.size() == cases.size());
  const auto ref = nhdyn::rne(nhdyn::presets::puma560<double>())(VectorXd::Zero(6), VectorXd::Zero(6), VectorXd::Zero(6));
  for (std::size_t k = 0; k < cases.size(); ++k) {
    INFO("line " << k + 1 << ": " << r.lines[k]);
    const json j = json::parse(r.lines[k]);  // every output line is valid JSON
    if (cases[k].second.empty()) {
      require_close(field(r.lines[k], "tau"), ref, 1e-13);
      continue;
    }
    REQUIRE(j.size() == 1);
    REQUIRE(j.contains("error"));
    for (const auto& part : cases[k].second) {
      INFO("expected to contain: " << part);
      CHECK(j["error"].get<std::string>().find(part) != std::string::npos);
    }
  }
}

TEST_CASE("tool: the line form must match the model (constraint or not), in id and fd") {
  const auto a = run_tool("id --model paper5", R"({"q": [0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0]})" "\n"
                                               R"({"q": [0, 0, 0, 0, 0], "eta": [0, 0, 0], "eta_dot": [0, 0, 0, 0]})" "\n");
  CHECK(a.status == 1);
  REQUIRE(a.lines.size() == 2);
  CHECK(a.lines[0].find("has a constraint") != std::string::npos);
  CHECK(a.lines[1].find("'eta' has 3 entries; the model needs 4") != std::string::npos);
  const auto b = run_tool("fd --model puma560", R"({"q": [0, 0, 0, 0, 0, 0], "eta": [0, 0, 0, 0, 0], "tau": [0, 0, 0, 0, 0]})" "\n"
                                                R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "tau": [0, 0, 0, 0, 0, 0]})" "\n");
  CHECK(b.status == 1);
  REQUIRE(b.lines.size() == 2);
  CHECK(b.lines[0].find("has no constraint") != std::string::npos);
  CHECK_FALSE(json::parse(b.lines[1]).contains("error"));
  const auto c = run_tool("fd --model paper5", R"({"q": [0, 0, 0, 0, 0], "eta": [0, 0, 0, 0], "tau": [0, 0, 0, "1"]})" "\n");
  CHECK(c.status == 1);
  REQUIRE(c.lines.size() == 1);
  CHECK(c.lines[0].find("'tau'[3]") != std::string::npos);
}

TEST_CASE("tool: an invalid or unreadable model is an error on stderr before any line is read") {
  const std::string line = R"({"q": [0], "qd": [0], "qdd": [0]})" "\n";
  auto bad = json::parse(read_text(source_dir() / "examples/models/paper5.json"));
  bad["links"][3]["mass"] = -1;
  const auto bad_path = scratch() / "negative_mass.json";
  std::ofstream(bad_path) << bad.dump(2);
  const auto broken_path = scratch() / "broken.json";
  std::ofstream(broken_path) << "{\"name\": \"x\",\n \"gravity\": [0, 0,\n";
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"id --model " + (scratch() / "missing.json").string(), {"missing.json", "no such file", "paper5, puma560"}},
      {"fd --model " + bad_path.string(), {"negative_mass.json", "link 4", "field 'mass'", "negative"}},
      {"id --model " + broken_path.string(), {"broken.json", "invalid JSON", "line 3"}},
      {"fd --model paper6", {"'paper6'", "not a preset"}},
      {"id --model " + scratch().string(), {"is a directory"}},
  };
  for (const auto& [args, parts] : cases) {
    INFO(args);
    const auto r = run_tool(args, line);
    CHECK(r.status == 1);
    CHECK(r.out.empty());
    for (const auto& p : parts) {
      INFO("stderr: " << r.err << "\nexpected to contain: " << p);
      CHECK(r.err.find(p) != std::string::npos);
    }
  }
}

TEST_CASE("tool: --help documents every subcommand; a bad command line is exit status 2") {
  const auto h = run_tool("--help", "");
  CHECK(h.status == 0);
  for (const auto& s : {"nhdyn id --model MODEL", "nhdyn fd --model MODEL", "eta_dot", "lambda", "paper5, puma560"}) {
    INFO(s);
    CHECK(h.out.find(s) != std::string::npos);
  }
  // Every registered subcommand (listed under "Commands:") has a --help whose text is in
  // nhdyn --help, so a subcommand added later is documented or this fails.
  const auto from = h.out.find("Commands:\n");
  REQUIRE(from != std::string::npos);
  std::istringstream listing(h.out.substr(from + 10));
  int listed = 0;
  for (std::string l; std::getline(listing, l) && !l.empty();) {
    const std::string name = l.substr(2, l.find(' ', 2) - 2);
    INFO("subcommand " << name);
    const auto sub = run_tool(name + " --help", "");
    CHECK(sub.status == 0);
    CHECK(sub.out.size() > 40);
    CHECK(h.out.find(sub.out) != std::string::npos);
    ++listed;
  }
  CHECK(listed >= 2);
  const auto id_help = run_tool("id --help", "");
  CHECK(id_help.status == 0);
  CHECK(id_help.out.find("{\"q\": [n], \"eta\": [m], \"eta_dot\": [m]}") != std::string::npos);
  const auto fd_help = run_tool("fd --help", "");
  CHECK(fd_help.status == 0);
  CHECK(fd_help.out.find("eta_dot = M_eta^-1") != std::string::npos);
  const std::vector<std::pair<std::string, std::string>> usage_errors = {
      {"", "Usage"},
      {"frobnicate", "unknown command 'frobnicate'"},
      {"id", "--model is required"},
      {"id --model", "--model: 1 required"},
      {"id --model paper5 --speed 3", "unexpected argument(s): --speed"},
      {"id --model paper5 --model puma560", "--model: At Most 1"},
      {"fd --model paper5 extra", "unexpected argument(s): extra"},
      {"id -- --model paper5", "--model is required"},  // after --, nothing is an option
      {"--version extra", "--version takes no arguments"},
      {"simulate paper --out x --threads -1", "--threads: '-1' is outside 0…4096"},
      {"simulate paper --out x --threads 4x", "--threads: '4x' is not a decimal integer"},
      {"simulate paper --out x --threads 0x10", "--threads: '0x10' is not a decimal integer"},
      {"simulate paper --out x --threads ' 4'", "--threads: ' 4' is not a decimal integer"},
      {"simulate paper --out x --threads 99999999999999999999", "is not a decimal integer"},
      {"simulate paper --out x --no-plots=maybe", "--no-plots"},
  };
  for (const auto& [args, msg] : usage_errors) {
    INFO(args);
    const auto r = run_tool(args, "");
    CHECK(r.status == 2);
    CHECK(r.out.empty());
    CHECK(r.err.find(msg) != std::string::npos);
  }
  // Numbers are decimal: 010 is ten threads (CLI11 alone reads it as octal 8).
  const auto ten = run_tool("simulate paper-circle --no-plots --threads 010 --out '" + (scratch() / "ten").string() + "'", "");
  CHECK(ten.status == 0);
  CHECK(ten.out.find("(10 threads)") != std::string::npos);
  // --version prints the version of nhdyn/version.hpp.
  const auto v = run_tool("--version", "");
  CHECK(v.status == 0);
  CHECK(v.out == std::string("nhdyn ") + nhdyn::version_string + "\n");
  // --model=MODEL works too; no input lines, no output, success.
  const auto eq = run_tool("id --model=puma560", "");
  CHECK(eq.status == 0);
  CHECK(eq.out.empty());
}

TEST_CASE("tool: f_ext on id and fd lines: the toolbox's published fext case, a constrained model, errors") {
  // Corke's robotics-toolbox-python test_rne: puma.rne(qn, 0, 0, fext=[1, 2, 3, 1, 2, 3]) =
  // [0.642756, 29.0866, 4.70321, 2.82843, -1.97175, 3]; its fext is what the end effector
  // exerts (in frame 6), so the wrench on link6 is its negative.
  const std::string qn = "[0, 0.7853981633974483, 3.141592653589793, 0, 0.7853981633974483, 0]";
  const std::string f = R"(, "f_ext": [{"body": "link6", "frame": "body", "force": [-1, -2, -3], "moment": [-1, -2, -3]}])";
  const auto r = run_tool("id --model puma560_motors",
                          R"({"q": )" + qn + R"(, "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0])" + f + "}\n");
  REQUIRE(r.status == 0);
  const VectorXd tau = field(r.lines[0], "tau");
  const VectorXd published = (VectorXd(6) << 0.642756, 29.0866, 4.70321, 2.82843, -1.97175, 3).finished();
  const VectorXd half_unit = (VectorXd(6) << 5e-7, 5e-5, 5e-6, 5e-6, 5e-6, 5e-6).finished();  // of the printed digits
  for (int i = 0; i < 6; ++i) CHECK(std::abs(tau(i) - published(i)) <= half_unit(i));
  // fd with the same wrench at that tau gives back qdd = 0
  const auto fd = run_tool("fd --model puma560_motors",
                           R"({"q": )" + qn + R"(, "qd": [0, 0, 0, 0, 0, 0], "tau": )" + arr(tau) + f + "}\n");
  REQUIRE(fd.status == 0);
  CHECK(field(fd.lines[0], "qdd").cwiseAbs().maxCoeff() <= 1e-9);
  // a constrained model: a payload's weight on the arm's last link changes tau and lambda as
  // the library's composition lift | rne | wrenches | constraint_forces does
  const auto p = nhdyn::presets::paper5();
  const VectorXd q = (VectorXd(5) << 0.1, 0.2, 0.3, 0.4, 0.5).finished(), eta = (VectorXd(4) << 0.3, -0.2, 0.1, 0.4).finished(),
                 eta_dot = (VectorXd(4) << 0.5, 0.1, -0.3, 0.2).finished();
  const auto c = run_tool("id --model paper5", R"({"q": )" + arr(q) + R"(, "eta": )" + arr(eta) + R"(, "eta_dot": )" + arr(eta_dot) +
                                                   R"(, "f_ext": [{"body": "link5", "point": [0, 0, 0], "force": [-4.905, 0, 0]}]})" "\n");
  REQUIRE(c.status == 0);
  nhdyn::wrench<double> w;
  w.body = 5;
  w.force = Eigen::Vector3d(-4.905, 0, 0);
  const auto ch = p.chain.dynamic_size();
  const nhdyn::differential_drive<double> dd(5, 0, 1, 2, 0.0, -1.0);
  const auto ref = (nhdyn::lift(dd) | nhdyn::rne(ch) | nhdyn::external_wrenches(ch, {w}) | nhdyn::constraint_forces(dd))(
      nhdyn::reduced_state<double>{q, eta, eta_dot});
  require_close(field(c.lines[0], "tau"), VectorXd(ref.tau), 1e-14);
  require_close(field(c.lines[0], "lambda"), VectorXd(ref.lambda), 1e-14);
  // errors name the entry and the field; the other lines go on
  const auto bad = run_tool("id --model puma560",
                            R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0], "f_ext": [{"body": "link7"}]})" "\n"
                            R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0], "f_ext": [{"body": "link1", "force": [1, 2]}]})" "\n"
                            R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0], "f_ext": [{"body": "link1", "frame": "tool"}]})" "\n"
                            R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0], "f_ext": [{"body": "link1", "torque": [0, 0, 1]}]})" "\n"
                            R"({"q": [0, 0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0], "f_ext": []})" "\n");
  CHECK(bad.status == 1);
  REQUIRE(bad.lines.size() == 5);
  CHECK_THAT(bad.lines[0], Catch::Contains("no body 'link7'"));
  CHECK_THAT(bad.lines[1], Catch::Contains("'f_ext'[0].force is not a list of 3 numbers"));
  CHECK_THAT(bad.lines[2], Catch::Contains("'frame' must be"));
  CHECK_THAT(bad.lines[3], Catch::Contains("unknown key 'torque'"));
  CHECK_THAT(bad.lines[4], Catch::Contains("\"tau\""));
}
