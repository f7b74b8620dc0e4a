/// libFuzzer target: the JSON model loader (nhdyn::io::parse_model) and the algorithms on
/// whatever it accepts. See entry_points.hpp for the oracles.
#include "entry_points.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return nhdyn_fuzz::model_json(data, size);
}
