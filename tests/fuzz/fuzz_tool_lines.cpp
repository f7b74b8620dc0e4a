/// libFuzzer target: the `nhdyn` tool's JSON-lines loop with its id and fd subcommands.
/// See tool_entry_points.hpp for the oracles.
#include "tool_entry_points.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return nhdyn_fuzz::tool_lines(data, size);
}
