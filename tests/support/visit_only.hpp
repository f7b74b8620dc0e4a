// visit_only<Cs...>(constraint, f): f on a robot file's constraint when the test knows which of
// the built-in types it is. std::visit would compile f for every alternative of
// nhdyn::base_constraint (four pipelines, each in every scalar type f uses); this compiles it for
// Cs only, and fails the test, naming the type index, when the file holds another.
#pragma once
#include <catch2/catch.hpp>
#include <nhdyn/constraints/constraint.hpp>
#include <variant>

namespace nhdyn_test {
template <class... Cs, class F>
void visit_only(const nhdyn::base_constraint& c, F&& f) {
  const bool done = ((std::holds_alternative<Cs>(c) ? (f(std::get<Cs>(c)), true) : false) || ...);
  if (!done) FAIL("the robot file's constraint (alternative " << c.index() << " of base_constraint) is not one this test compiles");
}
}  // namespace nhdyn_test
