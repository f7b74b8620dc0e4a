/// \file bench/alloc_counter.cpp
/// See alloc_counter.hpp. The benchmarks run on one thread; the counter is bumped with a
/// relaxed load and store (no locked read-modify-write), so counting adds about a cycle to an
/// allocation instead of the ~20 of an atomic increment, and run-time-sized cases are not
/// charged for the instrument.
#include "alloc_counter.hpp"

#include <atomic>
#include <cerrno>
#include <cstddef>

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {
std::atomic<std::uint64_t> count{0};
void bump() { count.store(count.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed); }
}  // namespace

namespace nhdyn_bench {
std::uint64_t allocations() { return count.load(std::memory_order_relaxed); }
}  // namespace nhdyn_bench

extern "C" {
void* malloc(std::size_t n) {
  bump();
  return __libc_malloc(n);
}
void* calloc(std::size_t k, std::size_t n) {
  bump();
  return __libc_calloc(k, n);
}
void* realloc(void* p, std::size_t n) {
  bump();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
void* memalign(std::size_t a, std::size_t n) {
  bump();
  return __libc_memalign(a, n);
}
void* aligned_alloc(std::size_t a, std::size_t n) {
  bump();
  return __libc_memalign(a, n);
}
int posix_memalign(void** out, std::size_t a, std::size_t n) {
  bump();
  void* p = __libc_memalign(a, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
}
