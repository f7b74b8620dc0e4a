#pragma once
/// \file functional/compose.hpp
/// Composition of stages. The law, tested in tests/test_compose.cpp:
///
///     compose(f, g)(x) == f(g(x))          (x | …: read right to left)
///     (g | f)(x)       == f(g(x))          (pipe: read left to right)
///     compose(f, compose(g, h)) == compose(compose(f, g), h)  (associative)
///
/// Every nhdyn algorithm object is a stage; `stage(callable)` makes any callable one, so
/// users can insert their own (a friction model, a wheel-speed map, a logger).
#include <concepts>
#include <functional>
#include <tuple>
#include <type_traits>
#include <utility>

namespace nhdyn {

/// Marks a function object as usable with `|`. Algorithm objects derive from it.
struct stage_tag {};

template <class F>
concept stage_like = std::derived_from<std::remove_cvref_t<F>, stage_tag>;

/// Wraps any callable as a stage.
template <class F>
struct stage_fn : stage_tag {
  F f;
  template <class... X>
  constexpr decltype(auto) operator()(X&&... x) const {
    return std::invoke(f, std::forward<X>(x)...);
  }
};
template <class F>
constexpr auto stage(F f) {
  return stage_fn<F>{{}, std::move(f)};
}

/// compose(f, g)(x) = f(g(x)); compose(f, g, h)(x) = f(g(h(x))).
template <class F, class G>
struct composed : stage_tag {
  F f;
  G g;
  template <class... X>
  constexpr decltype(auto) operator()(X&&... x) const {
    return f(g(std::forward<X>(x)...));
  }
};

template <class F>
constexpr F compose(F f) {
  return f;
}
template <class F, class G, class... H>
constexpr auto compose(F f, G g, H... h) {
  auto inner = compose(std::move(g), std::move(h)...);
  return composed<F, decltype(inner)>{{}, std::move(f), std::move(inner)};
}

/// Pipe: (g | f)(x) = f(g(x)), so `lift(c) | rne(chain) | project(c)` reads in the order
/// the data flows.
template <stage_like G, stage_like F>
constexpr auto operator|(G g, F f) {
  return composed<F, G>{{}, std::move(f), std::move(g)};
}

}  // namespace nhdyn
