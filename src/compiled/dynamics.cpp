/// \file src/compiled/dynamics.cpp
/// nhdyn::compiled (include/nhdyn/config.hpp): robot_dynamics (include/nhdyn/robot_dynamics.hpp),
/// a loaded robot's double dynamics behind a class a program does not instantiate (robot_dynamics
/// is basic_robot_dynamics<double>), compiled once: every member, and every function object it
/// holds (rne, CRBA, forward dynamics, derivatives, and each built-in base constraint's inverse
/// and forward dynamics and their derivatives), is instantiated here.
#define NHDYN_COMPILED_SOURCE 3  // NHDYN_PART_DYNAMICS (include/nhdyn/config.hpp)
#include <nhdyn/robot_dynamics.hpp>

namespace nhdyn {
template class basic_robot_dynamics<double>;
}  // namespace nhdyn
