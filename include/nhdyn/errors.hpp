#pragma once
/// \file errors.hpp
/// nhdyn reports bad input by exceptions, all derived from nhdyn::error (itself a
/// std::runtime_error): the message names what is wrong and where.
#include <stdexcept>
#include <string>

namespace nhdyn {

/// Base class of every error nhdyn throws.
struct error : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A model that is not physical or not well formed (negative mass, bad inertia, NaN…).
struct model_error : error {
  using error::error;
};
/// A state or input of the wrong size, or non-finite where a finite value is required.
struct input_error : error {
  using error::error;
};
/// A computation that cannot give a trustworthy result (singular or near-singular matrix).
struct numerical_error : error {
  using error::error;
};

}  // namespace nhdyn
