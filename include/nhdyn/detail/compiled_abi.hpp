#pragma once
/// \file detail/compiled_abi.hpp
/// The link-time check that a program and the nhdyn::compiled it links agree on Eigen's
/// alignment (config.hpp). Included by every header with functions nhdyn::compiled defines.
#include <Eigen/Core>

#include "../config.hpp"

// nhdyn::compiled and a program that links it exchange Eigen objects (tree<double>), so both
// must be built with the same alignment of fixed-size Eigen objects, which -march sets (16
// bytes for SSE, 32 for AVX). The library defines a symbol whose name holds its alignment;
// each file of a program that links it refers to the symbol of its own: other flags do not
// link (an undefined reference to nhdyn_compiled_eigen_align_N names the mismatch).
#define NHDYN_ABI_CAT_(a, b) a##b
#define NHDYN_ABI_CAT(a, b) NHDYN_ABI_CAT_(a, b)
#define NHDYN_COMPILED_ABI_SYMBOL NHDYN_ABI_CAT(nhdyn_compiled_eigen_align_, EIGEN_MAX_STATIC_ALIGN_BYTES)
// (src/compiled/io.cpp defines it.)
#if defined(NHDYN_COMPILED) && !defined(NHDYN_COMPILED_SOURCE)
extern "C" const int NHDYN_COMPILED_ABI_SYMBOL;
namespace nhdyn::detail {
[[maybe_unused]] __attribute__((used)) static const int* const compiled_abi_check = &NHDYN_COMPILED_ABI_SYMBOL;
}
#endif
