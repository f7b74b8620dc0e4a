#pragma once
/// \file bench/alloc_counter.hpp
/// Counts heap allocations made by this process: alloc_counter.cpp replaces malloc, calloc,
/// realloc, aligned_alloc, posix_memalign and memalign (glibc lets a program interpose them)
/// and forwards to glibc. Everything that reaches the heap goes through one of them —
/// operator new (libstdc++ calls malloc) and Eigen's aligned_malloc (std::malloc) included.
#include <cstdint>

namespace nhdyn_bench {
/// Heap allocations so far in this process.
std::uint64_t allocations();
}  // namespace nhdyn_bench
