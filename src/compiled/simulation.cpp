/// \file src/compiled/simulation.cpp
/// nhdyn::compiled (include/nhdyn/config.hpp): a scene's run on its robot (`simulate_scene`,
/// every constraint type's closed loop) and the controller's Lyapunov matrix, compiled once.
/// A program that links nhdyn::compiled calls these instead of instantiating them.
#define NHDYN_COMPILED_SOURCE 2  // NHDYN_PART_SIMULATION (include/nhdyn/config.hpp)
#include <nhdyn/simulation/controller.hpp>
#include <nhdyn/simulation/robot_scene.hpp>

namespace nhdyn {
template run_result simulate_scene_fn::operator()<run_spec>(const run_spec&) const;
template detail::scene_setup detail::setup_scene<run_spec>(const run_spec&);
template Eigen::Matrix<double, 6, 6> lyapunov_P<>(const Eigen::Matrix3d&, const Eigen::Matrix3d&);
}  // namespace nhdyn
