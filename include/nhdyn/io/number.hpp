#pragma once
/// \file io/number.hpp
/// Numbers as text, the one way nhdyn writes them (model files, tool lines, CSV): the
/// shortest decimal form that reads back to the same double (std::to_chars), e.g. −9.81 as
/// "-9.81", not "-9.8100000000000005". Needs nothing but the standard library.
#include <charconv>
#include <cmath>
#include <string>

#include "../errors.hpp"

namespace nhdyn::io {

/// Appends x in its shortest round-trip form (NaN and Inf as "nan", "inf": CSV readers
/// such as NumPy's and gnuplot's take them).
inline void append_number(std::string& out, double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  out.append(buf, r.ptr);
}

/// x in its shortest round-trip form, as a JSON number: "-0.0" for −0 (so that a JSON
/// reader keeps its sign; "-0" would read back as the integer 0). Throws numerical_error for
/// NaN or Inf, which JSON cannot represent.
inline std::string format_number(double x) {
  if (!std::isfinite(x)) throw numerical_error(std::isnan(x) ? "result is NaN" : "result is infinite");
  if (x == 0 && std::signbit(x)) return "-0.0";
  std::string s;
  append_number(s, x);
  return s;
}

}  // namespace nhdyn::io
