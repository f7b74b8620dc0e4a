#pragma once
/// \file version.hpp
/// nhdyn's version (semantic versioning). The top-level CMakeLists.txt reads it from here,
/// so these three lines are the one place it is written.
#define NHDYN_VERSION_MAJOR 0
#define NHDYN_VERSION_MINOR 2
#define NHDYN_VERSION_PATCH 0

#define NHDYN_VERSION_STRINGIFY_(x) #x
#define NHDYN_VERSION_STRINGIFY(x) NHDYN_VERSION_STRINGIFY_(x)
/// "MAJOR.MINOR.PATCH" as a string literal.
#define NHDYN_VERSION_STRING                                                                        \
  NHDYN_VERSION_STRINGIFY(NHDYN_VERSION_MAJOR) "." NHDYN_VERSION_STRINGIFY(NHDYN_VERSION_MINOR) "." \
      NHDYN_VERSION_STRINGIFY(NHDYN_VERSION_PATCH)

namespace nhdyn {

/// The version as "MAJOR.MINOR.PATCH", and its parts.
inline constexpr const char* version_string = NHDYN_VERSION_STRING;
inline constexpr int version_major = NHDYN_VERSION_MAJOR;
inline constexpr int version_minor = NHDYN_VERSION_MINOR;
inline constexpr int version_patch = NHDYN_VERSION_PATCH;

}  // namespace nhdyn
