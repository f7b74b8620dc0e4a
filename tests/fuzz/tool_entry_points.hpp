#pragma once
/// \file tests/fuzz/tool_entry_points.hpp
/// The `nhdyn` tool's line loop as a fuzz entry point: the tool's own line subcommands (id,
/// fd, linearize, bound) run on the given bytes as their standard input, exactly as
/// `nhdyn id --model paper5 < in`. The first byte picks the subcommand and the model; the
/// rest is stdin. (A bound line asking for more than 2^10 sub-boxes is left out: correct,
/// but slow enough under the sanitizers to look like a hang to libFuzzer.) Oracles: the
/// subcommand returns 0 or 1 and throws nothing; there is exactly one output line per input
/// line; every output line is a JSON object, and an error line says "line k: …" with its k.
#include <iostream>
#include <sstream>

#include "entry_points.hpp"
#include "tool.hpp"

namespace nhdyn_tool {
command command_id();
command command_fd();
command command_linearize();
command command_bound();
}  // namespace nhdyn_tool

namespace nhdyn_fuzz {

/// True if a line asks `bound` for more than 10 levels of bisection.
inline bool deep_split(const std::string& input) {
  std::istringstream in(input);
  std::string l;
  while (std::getline(in, l)) {
    const auto j = nlohmann::json::parse(l, nullptr, false);
    if (j.is_object() && j.contains("split") && j["split"].is_number() && j["split"].get<double>() > 10) return true;
  }
  return false;
}

inline int tool_lines(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const nhdyn_tool::command cmds[] = {nhdyn_tool::command_id(), nhdyn_tool::command_fd(),
                                             nhdyn_tool::command_linearize(), nhdyn_tool::command_bound()};
  static const char* models[] = {"paper5", "puma560"};
  const auto& cmd = cmds[data[0] % 4];
  const char* model = models[(data[0] / 4) % 2];
  const std::string input(reinterpret_cast<const char*>(data + 1), size - 1);
  if (cmd.name == "bound" && deep_split(input)) return 0;

  std::istringstream in(input);
  std::ostringstream out;
  auto* cin_buf = std::cin.rdbuf(in.rdbuf());
  auto* cout_buf = std::cout.rdbuf(out.rdbuf());
  int status = -1;
  std::string escaped;
  try {
    status = cmd.run({"--model", model});
  } catch (const std::exception& e) {
    escaped = e.what();
  }
  std::cin.rdbuf(cin_buf);
  std::cin.clear();
  std::cout.rdbuf(cout_buf);
  std::cout.clear();
  if (!escaped.empty()) fail("the tool let an exception escape: " + escaped, input);
  if (status != 0 && status != 1) fail("exit status " + std::to_string(status), input);

  // One output line per input line (std::getline's count), in order.
  std::size_t lines = 0;
  for (char c : input) lines += c == '\n';
  if (!input.empty() && input.back() != '\n') ++lines;
  std::istringstream res(out.str());
  std::string l;
  std::size_t k = 0;
  bool any_error = false;
  while (std::getline(res, l)) {
    ++k;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(l);
    } catch (const std::exception& e) {
      fail("output line " + std::to_string(k) + " is not JSON: " + l, input);
    }
    if (!j.is_object()) fail("output line " + std::to_string(k) + " is not an object: " + l, input);
    if (j.contains("error")) {
      any_error = true;
      const std::string prefix = "line " + std::to_string(k) + ": ";
      if (!j["error"].is_string() || j["error"].get<std::string>().rfind(prefix, 0) != 0)
        fail("error line " + std::to_string(k) + " does not name its line: " + l, input);
    }
  }
  if (k != lines) fail(std::to_string(lines) + " input lines but " + std::to_string(k) + " output lines", input);
  if ((status == 1) != any_error) fail("exit status does not match the error lines", input);
  return 0;
}

}  // namespace nhdyn_fuzz
