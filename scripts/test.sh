#!/usr/bin/env bash
# Builds and runs the whole test suite (g++, Release; the test programs at -O1, see
# tests/CMakeLists.txt). With --sanitize: the same suite under AddressSanitizer and
# UndefinedBehaviorSanitizer, built by clang++-14 at -O0 with line tables, in its own build
# folder (a second compiler, and the one the fuzz targets use).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
if [ "${1:-}" = "--sanitize" ]; then
  dir=build-asan
  extra=(-DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=None "-DCMAKE_CXX_FLAGS=-O0 -gline-tables-only"
         -DNHDYN_TEST_OPT= -DNHDYN_SANITIZE=address,undefined)
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
else
  dir=build
  extra=(-DCMAKE_BUILD_TYPE=Release)
fi
cmake -S . -B "$dir" -DNHDYN_BUILD_TESTS=ON -DNHDYN_BUILD_EXAMPLES=ON "${extra[@]}" >/dev/null
cmake --build "$dir" -j"$(nproc)"
cd "$dir" && ctest --output-on-failure -j"$(nproc)"
