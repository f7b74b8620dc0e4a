#pragma once
/// \file nhdyn.hpp
/// Everything in one include. See README.md and docs/.
#include "constraints/constraint.hpp"
#include "constraints/forward_dynamics.hpp"
#include "constraints/stages.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/mass_matrix.hpp"
#include "dynamics/rne.hpp"
#include "errors.hpp"
#include "functional/compose.hpp"
#include "functional/values.hpp"
#include "kinematics/kinematics.hpp"
#include "model/chain.hpp"
#include "robots/presets.hpp"
#include "robots/robot.hpp"
#include "scalar/dual.hpp"
#include "scalar/traits.hpp"
