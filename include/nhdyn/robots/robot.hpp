#pragma once
/// \file robots/robot.hpp
/// A robot: a chain and the constraint on its joints (holonomic<N> for none).
#include "../constraints/constraint.hpp"
#include "../model/chain.hpp"

namespace nhdyn {

template <class S, int N, class C>
struct robot {
  ::nhdyn::chain<S, N> chain;
  C constraint;
};

template <class S, int N, class C>
robot(chain<S, N>, C) -> robot<S, N, C>;

}  // namespace nhdyn
