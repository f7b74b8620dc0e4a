#pragma once
/// \file config.hpp
/// Header-only or compiled (issue 33 item 4). nhdyn is header-only; the optional library
/// `nhdyn::compiled` (CMake target, built by default when urdfdom, tinyxml2, nlohmann_json and
/// Boost are found) holds the file loaders (io/urdf.hpp, io/robot_file.hpp), `simulate_scene`
/// and `lyapunov_P` (simulation/), and `robot_dynamics` (robot_dynamics.hpp), compiled once, so
/// that a program that links it does not compile them again in every file that includes them
/// (docs/install.md lists them).
///
/// - Header-only (nothing defined): every function is defined in its header. A compiled
///   function is a template: one defaulted, unused parameter (`template <class = void>`), or
///   `run_spec` (simulate_scene, setup_scene), or a member of basic_robot_dynamics<double>
///   (robot_dynamics), so that header-only its body is compiled only in the files that call
///   it, not in every file that includes its header.
/// - `NHDYN_COMPILED` (set by linking `nhdyn::compiled`): the headers declare the compiled
///   functions and leave out their definitions (and the urdfdom and tinyxml2 headers they
///   need); the program links them from the library, which instantiates each once
///   (src/compiled/).
/// - `NHDYN_COMPILED_SOURCE` = a part (the library's own sources, src/compiled/, one per
///   part): the headers define that part's compiled functions and declare the other parts'.
///
/// The same definitions are compiled either way, from the same headers: a program gives the
/// same numbers bit for bit header-only or compiled (tests/compiled/).

/// The parts of nhdyn::compiled, one source file each (src/compiled/).
#define NHDYN_PART_IO 1          ///< io/urdf.hpp, io/robot_file.hpp (src/compiled/io.cpp)
#define NHDYN_PART_SIMULATION 2  ///< simulation/robot_scene.hpp, controller.hpp (simulation.cpp)
#define NHDYN_PART_DYNAMICS 3    ///< robot_dynamics.hpp (dynamics.cpp)

/// NHDYN_DEFINES(part): whether this translation unit defines the part's compiled functions.
#if defined(NHDYN_COMPILED_SOURCE)
/// The library's source file of part NHDYN_COMPILED_SOURCE: that part's definitions; the other
/// parts declared only (another source file defines them).
#define NHDYN_DEFINES(part) (NHDYN_COMPILED_SOURCE == (part))
#elif defined(NHDYN_COMPILED)
/// A program linking nhdyn::compiled: the compiled functions are declared only.
#define NHDYN_DEFINES(part) 0
#else
/// Header-only: the compiled functions are defined here.
#define NHDYN_DEFINES(part) 1
#endif
