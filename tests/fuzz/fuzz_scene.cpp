/// libFuzzer target: the scene/study/suite loader (nhdyn::scene::expand). See
/// scene_entry_points.hpp for the oracles.
#include "scene_entry_points.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return nhdyn_fuzz::scene(data, size);
}
