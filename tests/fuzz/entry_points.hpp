#pragma once
/// \file tests/fuzz/entry_points.hpp
/// The entry points the fuzz targets drive (tests/fuzz/fuzz_*.cpp, built with libFuzzer by
/// tests/fuzz.cmake and scripts/fuzz.sh) and tests/test_fuzz_regression.cpp replays over the
/// kept corpus in the normal build. Each takes arbitrary bytes and either returns normally
/// or calls std::abort() with a message when an oracle fails: an exception that is not an
/// nhdyn::error escaping, an error message that does not say where, a model that does not
/// survive save → load, a tool whose output lines do not match its input lines.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include <nhdyn/io/json.hpp>
#include <nhdyn/nhdyn.hpp>

namespace nhdyn_fuzz {

[[noreturn]] inline void fail(const std::string& what, std::string_view input) {
  std::fprintf(stderr, "fuzz oracle failed: %s\ninput (%zu bytes): %.*s\n", what.c_str(), input.size(),
               static_cast<int>(std::min<std::size_t>(input.size(), 2000)), input.data());
  std::abort();
}

/// JSON model loader: parse_model must give a valid model or throw nhdyn::model_error whose
/// message starts with the source; a model it gives must save and load back to the same
/// text, and rne / M(q) on it must return finite values or throw nhdyn::error.
inline int model_json(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  nhdyn::io::model<double> m;
  try {
    m = nhdyn::io::parse_model<double>(text, "fuzz");
  } catch (const nhdyn::model_error& e) {
    if (std::string_view(e.what()).rfind("fuzz", 0) != 0) fail(std::string("error without source: ") + e.what(), text);
    return 0;
  } catch (const std::exception& e) {
    fail(std::string("exception other than nhdyn::model_error: ") + e.what(), text);
  }
  // Save → load is exact.
  const std::string saved = nhdyn::io::to_string(m);
  try {
    const auto back = nhdyn::io::parse_model<double>(saved, "saved");
    if (nhdyn::io::to_string(back) != saved) fail("save → load → save differs", text);
  } catch (const std::exception& e) {
    fail(std::string("a loaded model does not load back after saving: ") + e.what(), text);
  }
  // The algorithms on it: finite results or a clear nhdyn::error, never a crash.
  if (m.chain.dof() > 64) return 0;  // keep each input fast
  try {
    const Eigen::VectorXd q = Eigen::VectorXd::Constant(m.chain.dof(), 0.3);
    const Eigen::VectorXd tau = nhdyn::rne(m.chain)(q, q, q);
    if (!tau.allFinite()) fail("rne returned a non-finite value without an error", text);
    const Eigen::MatrixXd M = nhdyn::mass_matrix(m.chain)(q);
    (void)nhdyn::forward_dynamics(m.chain)(q, q, tau);
    if (m.constraint) {
      const auto& c = *m.constraint;
      const Eigen::VectorXd eta = Eigen::VectorXd::Constant(c.m(), 0.2);
      const Eigen::VectorXd t = nhdyn::inverse_dynamics(m.chain, c)(q, eta, eta);
      if (!t.allFinite()) fail("inverse_dynamics returned a non-finite value without an error", text);
      (void)nhdyn::nh_forward_dynamics(m.chain, c)(q, eta, t);
    }
    (void)M;
  } catch (const nhdyn::error&) {
  } catch (const std::exception& e) {
    fail(std::string("algorithm threw something other than nhdyn::error: ") + e.what(), text);
  }
  return 0;
}

}  // namespace nhdyn_fuzz
