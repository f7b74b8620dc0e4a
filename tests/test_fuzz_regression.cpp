// Replays the kept fuzz corpus (tests/fuzz/corpus/<target>/*) through the entry points the
// libFuzzer targets drive (tests/fuzz/entry_points.hpp): every input must pass the oracles
// there (no exception other than nhdyn::error, errors that say where, save → load exact, one
// tool output line per input line). An oracle failure aborts, which fails this test.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "entry_points.hpp"
#include "scene_entry_points.hpp"
#ifdef NHDYN_FUZZ_TOOL
#include "tool_entry_points.hpp"
#endif

namespace fs = std::filesystem;

namespace {
std::vector<fs::path> corpus(const std::string& target) {
  const fs::path dir = fs::path(NHDYN_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / target;
  std::vector<fs::path> files;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}
std::string bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
template <class F>
std::size_t replay(const std::string& target, F entry) {
  const auto files = corpus(target);
  for (const auto& f : files) {
    const std::string b = bytes(f);
    entry(reinterpret_cast<const std::uint8_t*>(b.data()), b.size());
  }
  return files.size();
}
}  // namespace

TEST_CASE("fuzz regression: every kept model_json input loads or fails with a clear model_error") {
  const auto n = replay("model_json", nhdyn_fuzz::model_json);
  CHECK(n >= 20);  // the kept corpus is there
}

TEST_CASE("fuzz regression: every kept scene input expands or fails with a clear nhdyn::error") {
  const auto n = replay("scene", nhdyn_fuzz::scene);
  CHECK(n >= 5);
}

#ifdef NHDYN_FUZZ_TOOL
TEST_CASE("fuzz regression: the tool answers every kept input line by line, never crashing") {
  const auto n = replay("tool_lines", nhdyn_fuzz::tool_lines);
  CHECK(n >= 20);
}
#endif

TEST_CASE("fuzz regression: the oracle accepts a good model and rejects nothing valid") {
  // The entry point itself is checked on inputs whose outcome is known, so that a broken
  // oracle (one that returns early on everything) would be noticed.
  const std::string good = nhdyn::io::to_string(nhdyn::io::preset<double>("paper5"));
  CHECK(nhdyn_fuzz::model_json(reinterpret_cast<const std::uint8_t*>(good.data()), good.size()) == 0);
  CHECK_NOTHROW(nhdyn::io::parse_model<double>(good, "x"));
  CHECK_THROWS_AS(nhdyn::io::parse_model<double>(good.substr(0, good.size() / 2), "x"), nhdyn::model_error);
}
