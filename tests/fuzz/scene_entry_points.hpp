#pragma once
/// \file tests/fuzz/scene_entry_points.hpp
/// The scene loader as a fuzz entry point: JSON text → io::parse_strict → scene::expand
/// (scenes, studies, suites; shipped scenes referred to by name are read from
/// examples/scenes). Oracles: only nhdyn::error escapes, and an error message is not empty.
/// The runs are not simulated (that is the simulation tests' business, and slow).
#include <nhdyn/simulation/scene.hpp>

#include "entry_points.hpp"

namespace nhdyn_fuzz {

inline int scene(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto j = nhdyn::io::parse_strict<nhdyn::input_error>(text, "scene file 'fuzz': ");
    const auto runs = nhdyn::scene::expand(j);
    if (runs.empty()) fail("a scene expanded to no runs without an error", text);
  } catch (const nhdyn::error& e) {
    if (std::string_view(e.what()).empty()) fail("empty error message", text);
  } catch (const std::exception& e) {
    fail(std::string("exception other than nhdyn::error: ") + e.what(), text);
  }
  return 0;
}

}  // namespace nhdyn_fuzz
