#pragma once
/// \file constraints/constraint.hpp
/// Every built-in constraint type and the `pfaffian_constraint` concept (concept.hpp):
/// `holonomic` (holonomic.hpp), `differential_drive` (differential_drive.hpp),
/// `rolling_wheels` (rolling_wheels.hpp), `bicycle` (bicycle.hpp),
/// `user_constraint` / `make_constraint` (user_constraint.hpp), `wheeled_base` (any set of
/// fixed, steered, castor and Swedish wheels, wheeled_base.hpp).
#include <variant>

#include "concept.hpp"
#include "bicycle.hpp"
#include "differential_drive.hpp"
#include "holonomic.hpp"
#include "rolling_wheels.hpp"
#include "user_constraint.hpp"
#include "wheeled_base.hpp"

namespace nhdyn {
/// The built-in constraints of a wheeled base as one value type (robot files load into it,
/// io/robot_file.hpp); run-time sized, double. Use with std::visit: every alternative is a
/// `pfaffian_constraint`.
using base_constraint =
    std::variant<differential_drive<double>, rolling_wheels<double>, bicycle<double>, wheeled_base<double>>;
}  // namespace nhdyn
