#!/usr/bin/env bash
# Builds and runs the whole test suite (g++, Release; the test programs, the tool, the examples
# and the Python module at -O1: NHDYN_TEST_OPT, NHDYN_PROGRAM_OPT). With --sanitize: the
# sanitizer set (tests/CMakeLists.txt, NHDYN_SANITIZE_SET: the code that handles memory,
# indices and bad input; without the tool and the examples) under AddressSanitizer and
# UndefinedBehaviorSanitizer, built by clang++-14 at -O0 with line tables in its own build folder
# (a second compiler, and the one the fuzz targets use); --sanitize --all: every test, the tool
# and the examples included, under the sanitizers.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
targets=()
select=()
if [ "${1:-}" = "--sanitize" ]; then
  dir=build-asan
  extra=(-DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=None "-DCMAKE_CXX_FLAGS=-O0 -gline-tables-only"
         -DNHDYN_TEST_OPT= -DNHDYN_PROGRAM_OPT= -DNHDYN_SANITIZE=address,undefined)
  if [ "${2:-}" != "--all" ]; then
    extra+=(-DNHDYN_BUILD_EXAMPLES=OFF)
    targets=(--target nhdyn_sanitize_set)
    select=(-L sanitize)
  else
    extra+=(-DNHDYN_BUILD_EXAMPLES=ON)
  fi
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
else
  dir=build
  extra=(-DCMAKE_BUILD_TYPE=Release -DNHDYN_PROGRAM_OPT=-O1 -DNHDYN_BUILD_EXAMPLES=ON)
fi
cmake -S . -B "$dir" -DNHDYN_BUILD_TESTS=ON "${extra[@]}" >/dev/null
t0=$SECONDS
cmake --build "$dir" -j"$(nproc)" "${targets[@]}"
echo "test.sh: $dir built in $(( SECONDS - t0 )) s"
t0=$SECONDS
(cd "$dir" && ctest --output-on-failure -j"$(nproc)" "${select[@]}")
echo "test.sh: $dir tested in $(( SECONDS - t0 )) s"
