// Model files (io/json.hpp): the shipped files equal the presets and paper5.md's numbers,
// save → load is exact, and every malformed file gets an error naming file, link and field.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <cstring>
#include <functional>
#include <filesystem>
#include <fstream>
#include <nhdyn/io/json.hpp>
#include <nhdyn/nhdyn.hpp>
#include <random>

#include "support/scratch_dir.hpp"

namespace fs = std::filesystem;
using nhdyn::io::json;

namespace {

fs::path source_dir() { return NHDYN_SOURCE_DIR; }

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

/// A scratch directory for this test binary's files.
fs::path scratch() { return nhdyn_test::scratch_dir("model_io"); }

template <class S, int N, int M>
void require_same_chain(const nhdyn::chain<S, N>& a, const nhdyn::chain<S, M>& b) {
  REQUIRE(a.name() == b.name());
  REQUIRE(a.dof() == b.dof());
  REQUIRE(a.gravity() == b.gravity());
  REQUIRE(a.validation_policy().triangle_inequality == b.validation_policy().triangle_inequality);
  for (int i = 0; i < a.dof(); ++i) {
    INFO("link " << i + 1);
    const auto &p = a[i], &q = b[i];
    REQUIRE(p.joint == q.joint);
    REQUIRE(p.alpha == q.alpha);  // bit for bit: 17 significant digits round-trip exactly
    REQUIRE(p.a == q.a);
    REQUIRE(p.theta == q.theta);
    REQUIRE(p.d == q.d);
    REQUIRE(p.mass == q.mass);
    REQUIRE(p.com == q.com);
    REQUIRE(p.inertia == q.inertia);
  }
}

template <class S, int N, int M>
void require_same_constraint(const nhdyn::differential_drive<S, N>& a, const nhdyn::differential_drive<S, M>& b) {
  REQUIRE(a.n == b.n);
  REQUIRE(a.x == b.x);
  REQUIRE(a.y == b.y);
  REQUIRE(a.heading == b.heading);
  REQUIRE(a.forward_offset == b.forward_offset);
  REQUIRE(a.heading_sign == b.heading_sign);
}

/// Loads `text` from a file named `name` in the scratch dir and returns the error message
/// (failing the test if loading succeeds).
std::string load_error(const std::string& text, const std::string& name = "bad.json") {
  const auto path = scratch() / name;
  std::ofstream(path, std::ios::binary) << text;
  try {
    nhdyn::io::load_model(path);
  } catch (const nhdyn::model_error& e) {
    return e.what();
  }
  FAIL("loading succeeded but should have failed:\n" << text);
  return "";
}

json paper5_json() { return json::parse(read_text(source_dir() / "examples/models/paper5.json")); }

void require_contains(const std::string& msg, std::initializer_list<std::string> parts) {
  INFO("message: " << msg);
  for (const auto& p : parts) {
    INFO("expected to contain: " << p);
    CHECK(msg.find(p) != std::string::npos);
  }
}

/// A random physical chain: random DH rows, masses, centres of mass, and inertias
/// R·diag(principal moments satisfying the triangle inequality)·Rᵀ.
nhdyn::chain<double> random_chain(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(-1, 1), pos(0.01, 5);
  std::vector<nhdyn::link<double>> links(static_cast<std::size_t>(n));
  for (auto& L : links) {
    L.joint = u(rng) > 0 ? nhdyn::joint_type::revolute : nhdyn::joint_type::prismatic;
    L.alpha = 3 * u(rng);
    L.a = u(rng);
    L.theta = 3 * u(rng);
    L.d = u(rng);
    L.mass = pos(rng);
    L.com = Eigen::Vector3d(u(rng), u(rng), u(rng));
    const double a = pos(rng), b = pos(rng), c = pos(rng);  // a box's edges
    const Eigen::Matrix3d D = nhdyn::box_inertia(L.mass, a, b, c);
    const Eigen::Matrix3d R = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    Eigen::Matrix3d I = R * D * R.transpose();
    L.inertia = 0.5 * (I + I.transpose());
  }
  return nhdyn::chain<double>(links, Eigen::Vector3d(u(rng), u(rng), -9.81), "random");
}

}  // namespace

TEST_CASE("model files: examples/models/paper5.json loads to the paper5 preset bit for bit, with its constraint") {
  const auto m = nhdyn::io::load_model(source_dir() / "examples/models/paper5.json");
  const auto r = nhdyn::presets::paper5<double>();
  require_same_chain(m.chain, r.chain);
  REQUIRE(m.constraint.has_value());
  require_same_constraint(*m.constraint, r.constraint);
  // The preset by name is the same model.
  const auto p = nhdyn::io::preset("paper5");
  require_same_chain(p.chain, r.chain);
  require_same_constraint(*p.constraint, r.constraint);
}

TEST_CASE("model files: paper5.json holds paper5.md's numbers, inertias from the box formulas") {
  const auto ch = nhdyn::io::load_model(source_dir() / "examples/models/paper5.json").chain;
  const double pi = 3.14159265358979323846;
  using J = nhdyn::joint_type;
  CHECK(ch[0].joint == J::prismatic);
  CHECK(ch[1].joint == J::prismatic);
  CHECK(ch[2].joint == J::revolute);
  CHECK(ch[0].alpha == -pi / 2);
  CHECK(ch[1].theta == -pi / 2);
  CHECK(ch[2].alpha == pi / 2);
  CHECK(ch[2].d == 0.237);
  CHECK(ch[3].a == 0.150);
  CHECK(ch[4].a == 0.168);
  CHECK(ch[2].mass == 9.0);
  CHECK(ch[3].mass == 0.1);
  CHECK(ch[0].mass == 0.0);
  CHECK(ch[1].inertia == Eigen::Matrix3d::Zero());
  CHECK(ch.gravity() == Eigen::Vector3d(-9.81, 0, 0));
  CHECK(ch[2].com == Eigen::Vector3d(0, -0.1185, 0));
  CHECK(ch[3].com == Eigen::Vector3d(-0.075, 0, 0));
  CHECK(ch[4].com == Eigen::Vector3d(-0.084, 0, 0));
  // Box formulas written out here: Ixx = m(b²+c²)/12, Iyy = m(a²+c²)/12, Izz = m(a²+b²)/12.
  const auto box = [](double m, double a, double b, double c) {
    return Eigen::Vector3d(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12);
  };
  const Eigen::Vector3d I3 = box(9.0, 0.445, 0.237, 0.393), I4 = box(0.1, 0.150, 0.050, 0.050),
                        I5 = box(0.1, 0.168, 0.050, 0.050);
  for (int k = 0; k < 3; ++k) {
    CHECK(ch[2].inertia(k, k) == Approx(I3(k)).epsilon(4e-16));
    CHECK(ch[3].inertia(k, k) == Approx(I4(k)).epsilon(4e-16));
    CHECK(ch[4].inertia(k, k) == Approx(I5(k)).epsilon(4e-16));
  }
  // …and agree with the table's rounded figures to their printed precision.
  CHECK(ch[2].inertia(0, 0) == Approx(0.1579635).epsilon(1e-7));
  CHECK(ch[2].inertia(1, 1) == Approx(0.2643555).epsilon(1e-7));
  CHECK(ch[2].inertia(2, 2) == Approx(0.1906455).epsilon(1e-7));
  CHECK(ch[4].inertia(1, 1) == Approx(2.5603333e-4).epsilon(1e-7));
  // Products of inertia are zero.
  for (int i = 0; i < 5; ++i) CHECK(ch[i].inertia.isDiagonal(0.0));
  // The constraint: x = q1, y = q2, heading q3, ψ = −q3 (paper5.md's A = [sin q3, cos q3, 0, 0, 0]).
  const auto c = *nhdyn::io::load_model(source_dir() / "examples/models/paper5.json").constraint;
  const Eigen::VectorXd q = (Eigen::VectorXd(5) << 0.1, -0.2, 0.7, 0.3, -0.4).finished();
  const Eigen::MatrixXd A = c.A(q);
  CHECK(A(0, 0) == Approx(std::sin(0.7)).margin(1e-15));
  CHECK(A(0, 1) == Approx(std::cos(0.7)).margin(1e-15));
  CHECK(A.rightCols(3).isZero(0.0));
}

TEST_CASE("model files: examples/models/puma560.json loads to the puma560 preset bit for bit") {
  const auto m = nhdyn::io::load_model(source_dir() / "examples/models/puma560.json");
  require_same_chain(m.chain, nhdyn::presets::puma560<double>());
  CHECK_FALSE(m.constraint.has_value());
  CHECK_FALSE(m.chain.validation_policy().triangle_inequality);
  // Corke's published link 2 (mass 17.4, a = 0.4318) and gravity along −z₀.
  CHECK(m.chain[1].mass == 17.4);
  CHECK(m.chain[1].a == 0.4318);
  CHECK(m.chain.gravity() == Eigen::Vector3d(0, 0, -9.81));
  // Without the validation switch, the published link 1 is rejected, by name.
  auto j = json::parse(read_text(source_dir() / "examples/models/puma560.json"));
  j.erase("validation");
  require_contains(load_error(j.dump(2), "puma_strict.json"),
                   {"puma_strict.json", "link 1", "field 'inertia'", "triangle inequality"});
}

TEST_CASE("model files: save then load is exact, on random chains and the presets") {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 1 + trial % 9;
    nhdyn::io::model<double> m{random_chain(rng, n), std::nullopt, "trial " + std::to_string(trial)};
    if (n >= 3 && trial % 2 == 0)
      m.constraint = nhdyn::differential_drive<double>(n, n - 1, 0, 1, 0.125 * trial, trial % 4 ? 1.0 : -1.0);
    const std::string text = nhdyn::io::to_string(m);
    const auto back = nhdyn::io::parse_model(text, "round trip");
    require_same_chain(back.chain, m.chain);
    REQUIRE(back.description == m.description);
    REQUIRE(back.constraint.has_value() == m.constraint.has_value());
    if (m.constraint) require_same_constraint(*back.constraint, *m.constraint);
    REQUIRE(nhdyn::io::to_string(back) == text);  // saving is deterministic
  }
  {  // negative zeros keep their sign through save → load → save
    std::vector<nhdyn::link<double>> L(1);
    L[0].mass = 1;
    L[0].inertia = Eigen::Matrix3d::Identity();
    L[0].theta = -0.0;
    nhdyn::io::model<double> m{nhdyn::chain<double>(L, Eigen::Vector3d(-0.0, 0, -9.81), "zeros"), std::nullopt, ""};
    const auto text = nhdyn::io::to_string(m);
    const auto back = nhdyn::io::parse_model(text);
    CHECK(std::signbit(back.chain[0].theta));
    CHECK(std::signbit(back.chain.gravity()(0)));
    CHECK(nhdyn::io::to_string(back) == text);
  }
  for (const auto& name : nhdyn::io::preset_names()) {
    const auto m = nhdyn::io::preset(name);
    const auto path = scratch() / (name + "_saved.json");
    nhdyn::io::save_model(m, path);
    require_same_chain(nhdyn::io::load_model(path).chain, m.chain);
    // The shipped file is exactly what saving the preset writes.
    CHECK(read_text(path) == read_text(source_dir() / "examples" / "models" / (name + ".json")));
  }
}

TEST_CASE("model files: format_number prints the shortest decimal that reads back bit for bit") {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::uint64_t> bits;
  int tried = 0;
  while (tried < 20000) {
    const std::uint64_t b = bits(rng);
    double x;
    std::memcpy(&x, &b, sizeof x);
    if (!std::isfinite(x)) continue;
    ++tried;
    const std::string s = nhdyn::io::format_number(x);
    const double y = json::parse(s).get<double>();
    REQUIRE(std::memcmp(&x, &y, sizeof x) == 0);
    // As short as possible: no longer than the shortest %.pg (p = 1…17) that reads back to x
    // (an independent search; to_chars may write fewer characters still, e.g. "100" for 1e+02).
    std::size_t shortest = 0;
    for (int p = 1; p <= 17 && !shortest; ++p) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.*g", p, x);
      if (std::strtod(buf, nullptr) == x) shortest = std::strlen(buf);
    }
    INFO(s);
    REQUIRE(s.size() <= shortest);
  }
  CHECK(nhdyn::io::format_number(-9.81) == "-9.81");
  CHECK(nhdyn::io::format_number(0.1) == "0.1");
  for (double x : {0.1, 1.0 / 3, 5e-324, 1.7976931348623157e308, -0.0, 0.0, 9.0, -3.0, 1e22, 9007199254740993.0}) {
    const double y = json::parse(nhdyn::io::format_number(x)).get<double>();
    CHECK(std::memcmp(&x, &y, sizeof x) == 0);  // the sign of zero too
  }
  // dump() prints every number this way, and refuses NaN/Inf rather than writing null.
  CHECK(nhdyn::io::dump(nhdyn::io::ordered_json{{"a", {0.1, -0.0, 2}}}) == R"({"a": [0.1, -0.0, 2]})");
  CHECK_THROWS_AS(nhdyn::io::dump(json{{"a", {1.0, std::nan("")}}}), nhdyn::numerical_error);
  CHECK_THROWS_AS(nhdyn::io::format_number(std::numeric_limits<double>::infinity()), nhdyn::numerical_error);
  CHECK_THROWS_AS(nhdyn::io::format_number(std::nan("")), nhdyn::numerical_error);
}

TEST_CASE("model files: a file loads in other scalar types (long double)") {
  const auto m = nhdyn::io::load_model<long double>(source_dir() / "examples/models/paper5.json");
  CHECK(m.chain[2].mass == 9.0L);
  CHECK(m.chain[2].d == static_cast<long double>(0.237));
  CHECK(m.constraint->heading_sign == -1.0L);
}

TEST_CASE("model files: a missing, mistyped or misspelled field is an error naming file, link and field") {
  struct error_case {
    std::string what;
    std::function<void(json&)> mutate;
    std::vector<std::string> expected;
  };
  const std::vector<error_case> cases = {
      {"missing link field", [](json& j) { j["links"][2].erase("mass"); }, {"link 3", "field 'mass'", "missing"}},
      {"missing com", [](json& j) { j["links"][0].erase("com"); }, {"link 1", "field 'com'", "missing"}},
      {"missing top-level name", [](json& j) { j.erase("name"); }, {"field 'name'", "missing"}},
      {"missing gravity", [](json& j) { j.erase("gravity"); }, {"field 'gravity'", "missing"}},
      {"missing links", [](json& j) { j.erase("links"); }, {"field 'links'", "missing"}},
      {"string for a number", [](json& j) { j["links"][0]["alpha"] = "-pi/2"; },
       {"link 1", "field 'alpha'", "expected a number, got string"}},
      {"null for a number", [](json& j) { j["links"][4]["a"] = nullptr; }, {"link 5", "field 'a'", "got null"}},
      {"boolean for a number", [](json& j) { j["links"][3]["d"] = true; }, {"link 4", "field 'd'", "got boolean"}},
      {"number for the joint", [](json& j) { j["links"][1]["joint"] = 1; }, {"link 2", "field 'joint'", "expected a string"}},
      {"unknown joint type", [](json& j) { j["links"][3]["joint"] = "spherical"; },
       {"link 4", "field 'joint'", "unknown joint type 'spherical'", "revolute, prismatic"}},
      {"com of 2 entries", [](json& j) { j["links"][2]["com"] = {0, 1}; },
       {"link 3", "field 'com'", "3 numbers", "array of 2"}},
      {"com entry not a number", [](json& j) { j["links"][2]["com"][1] = "x"; },
       {"link 3", "field 'com'", "entry 1", "expected a number"}},
      {"gravity of 4 entries", [](json& j) { j["gravity"] = {0, 0, 0, 1}; }, {"field 'gravity'", "array of 4"}},
      {"gravity an object", [](json& j) { j["gravity"] = json::object(); }, {"field 'gravity'", "got object"}},
      {"inertia with 2 rows", [](json& j) { j["links"][2]["inertia"].erase(2); }, {"link 3", "field 'inertia'", "2 rows"}},
      {"inertia row with 2 entries", [](json& j) { j["links"][2]["inertia"][1] = {0, 1}; },
       {"link 3", "field 'inertia'", "row 2 with 2 entries"}},
      {"inertia flat", [](json& j) { j["links"][2]["inertia"] = {1, 0, 0, 0, 1, 0, 0, 0, 1}; },
       {"link 3", "field 'inertia'", "got 9 rows"}},
      {"inertia entry a string", [](json& j) { j["links"][4]["inertia"][2][0] = "0"; },
       {"link 5", "field 'inertia'", "row 3, column 1", "expected a number"}},
      {"unknown link field (typo)", [](json& j) { j["links"][3]["mas"] = 1; },
       {"link 4", "unknown field(s) 'mas'"}},
      {"unknown top-level field (typo)", [](json& j) { j["gravty"] = {0, 0, -9.81}; }, {"unknown field(s) 'gravty'"}},
      {"name not a string", [](json& j) { j["name"] = 5; }, {"field 'name'", "expected a string"}},
      {"links not an array", [](json& j) { j["links"] = json::object(); }, {"field 'links'", "array of links"}},
      {"no links", [](json& j) { j["links"] = json::array(); }, {"field 'links'", "at least one link"}},
      {"link not an object", [](json& j) { j["links"][1] = 3; }, {"link 2", "expected an object"}},
      {"negative mass", [](json& j) { j["links"][3]["mass"] = -0.1; }, {"link 4", "field 'mass'", "negative"}},
      {"inertia not symmetric", [](json& j) { j["links"][2]["inertia"][0][1] = 0.01; },
       {"link 3", "field 'inertia'", "not symmetric"}},
      {"inertia not positive semi-definite", [](json& j) { j["links"][2]["inertia"][1][1] = -1; },
       {"link 3", "field 'inertia'", "positive semi-definite"}},
      {"triangle inequality", [](json& j) { j["links"][4]["inertia"][0][0] = 1.0; },
       {"link 5", "field 'inertia'", "triangle inequality"}},
      {"validation not an object", [](json& j) { j["validation"] = false; }, {"field 'validation'", "expected an object"}},
      {"validation flag not boolean", [](json& j) { j["validation"] = {{"triangle_inequality", 0}}; },
       {"field 'triangle_inequality'", "true or false"}},
      {"validation unknown key", [](json& j) { j["validation"] = {{"triangle", false}}; }, {"unknown field(s) 'triangle'"}},
      {"constraint unknown type", [](json& j) { j["constraint"]["type"] = "ackermann"; },
       {"constraint", "field 'type'", "unknown constraint type 'ackermann'"}},
      {"constraint without type", [](json& j) { j["constraint"].erase("type"); }, {"constraint", "field 'type'", "missing"}},
      {"constraint index out of range", [](json& j) { j["constraint"]["heading"] = 5; },
       {"constraint", "field 'heading'", "outside 0…4", "0-based"}},
      {"constraint negative index", [](json& j) { j["constraint"]["x"] = -1; }, {"constraint", "field 'x'", "outside"}},
      {"constraint non-integer index", [](json& j) { j["constraint"]["y"] = 1.5; },
       {"constraint", "field 'y'", "integer joint index"}},
      {"constraint missing index", [](json& j) { j["constraint"].erase("y"); }, {"constraint", "field 'y'", "missing"}},
      {"constraint same joints", [](json& j) { j["constraint"]["y"] = 0; }, {"constraint", "must differ"}},
      {"constraint heading_sign", [](json& j) { j["constraint"]["heading_sign"] = 0.5; },
       {"constraint", "field 'heading_sign'", "1 or -1"}},
      {"constraint unknown field", [](json& j) { j["constraint"]["offset"] = 0.1; },
       {"constraint", "unknown field(s) 'offset'"}},
      {"constraint not an object", [](json& j) { j["constraint"] = "differential_drive"; },
       {"field 'constraint'", "expected an object"}},
  };
  for (const auto& c : cases) {
    SECTION(c.what) {
      json j = paper5_json();
      c.mutate(j);
      const std::string msg = load_error(j.dump(2), "case.json");
      for (const auto& part : c.expected) require_contains(msg, {part});
      require_contains(msg, {"file '", "case.json'"});
    }
  }
}

TEST_CASE("model files: malformed, truncated or overflowing JSON is an error with its line and column") {
  const std::string good = read_text(source_dir() / "examples/models/paper5.json");
  SECTION("truncated in the middle: the line of the end is reported") {
    const auto cut = good.find("\"mass\": 9");
    const std::string text = good.substr(0, cut + 8);
    const auto lines = std::count(text.begin(), text.end(), '\n') + 1;
    require_contains(load_error(text, "truncated.json"),
                     {"file '", "truncated.json'", "invalid JSON", "line " + std::to_string(lines) + ", column"});
  }
  SECTION("a syntax error reports its line") {
    const auto at = good.find("\"theta\"");
    REQUIRE(at != std::string::npos);
    const std::string text = good.substr(0, at) + "," + good.substr(at);  // ",," on that line
    const auto line = std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n') + 1;
    require_contains(load_error(text), {"invalid JSON", "line " + std::to_string(line) + ","});
  }
  SECTION("a number too large for a double") {
    std::string text = good;
    text.replace(text.find("\"mass\": 9"), 9, "\"mass\": 1e999");
    require_contains(load_error(text), {"invalid JSON", "number overflow", "1e999"});
  }
  SECTION("NaN and Infinity are not JSON") {
    std::string text = good;
    text.replace(text.find("\"mass\": 9"), 9, "\"mass\": NaN");
    require_contains(load_error(text), {"invalid JSON", "line"});
  }
  SECTION("a duplicate key is an error, not a silent overwrite") {
    std::string text = good;
    text.replace(text.find("\"mass\": 9"), 9, "\"mass\": 9, \"mass\": 90");
    require_contains(load_error(text), {"duplicate key 'mass'"});
  }
  SECTION("empty file and a top-level array") {
    require_contains(load_error(""), {"invalid JSON"});
    require_contains(load_error("[1, 2]"), {"top level", "array"});
  }
}

TEST_CASE("model files: unreadable files and unknown presets are clear errors") {
  const auto msg = [](auto f) {
    try {
      f();
    } catch (const nhdyn::model_error& e) {
      return std::string(e.what());
    }
    FAIL("no error");
    return std::string();
  };
  require_contains(msg([] { nhdyn::io::load_model(scratch() / "does_not_exist.json"); }),
                   {"does_not_exist.json", "cannot be opened"});
  require_contains(msg([] { nhdyn::io::load_model(scratch()); }), {"is a directory"});
  require_contains(msg([] { nhdyn::io::preset("paper6"); }), {"unknown preset 'paper6'", "paper5, puma560"});
  require_contains(msg([] { nhdyn::io::load("paper6"); }), {"'paper6'", "no such file", "paper5, puma560"});
  // load() takes a preset name or a path.
  require_same_chain(nhdyn::io::load("puma560").chain, nhdyn::presets::puma560<double>());
  require_same_chain(nhdyn::io::load((source_dir() / "examples/models/puma560.json").string()).chain,
                     nhdyn::presets::puma560<double>());
}

TEST_CASE("model files: parsed text without a source name gives messages without a file part") {
  json j = paper5_json();
  j["constraint"]["heading"] = 7;
  try {
    nhdyn::io::parse_model(j.dump());
    FAIL("no error");
  } catch (const nhdyn::model_error& e) {
    CHECK(std::string(e.what()).rfind("constraint, field 'heading': joint index 7", 0) == 0);
  }
  j = paper5_json();
  j["links"][1]["a"] = "0";
  try {
    nhdyn::io::parse_model(j.dump(), "my robot");
    FAIL("no error");
  } catch (const nhdyn::model_error& e) {
    CHECK(std::string(e.what()).rfind("my robot, link 2, field 'a': expected a number, got string", 0) == 0);
  }
}
