#pragma once
/// \file constraints/constraint.hpp
/// Every built-in constraint type and the `pfaffian_constraint` concept (concept.hpp):
/// `holonomic` (holonomic.hpp), `differential_drive` (differential_drive.hpp),
/// `user_constraint` / `make_constraint` (user_constraint.hpp).
#include "concept.hpp"
#include "differential_drive.hpp"
#include "holonomic.hpp"
#include "user_constraint.hpp"
