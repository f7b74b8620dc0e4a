/// \file src/compiled/io.cpp
/// nhdyn::compiled (include/nhdyn/config.hpp): the file loaders' definitions, compiled once.
/// The headers define them here, not inline (NHDYN_COMPILED_SOURCE); a program that links
/// nhdyn::compiled sees their declarations only (NHDYN_COMPILED).
#define NHDYN_COMPILED_SOURCE 1  // NHDYN_PART_IO (include/nhdyn/config.hpp)
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/io/urdf.hpp>

/// The alignment check of detail/compiled_abi.hpp: programs built with other flags do not link.
extern "C" const int NHDYN_COMPILED_ABI_SYMBOL = EIGEN_MAX_STATIC_ALIGN_BYTES;
