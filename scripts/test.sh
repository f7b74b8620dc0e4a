#!/usr/bin/env bash
# Builds and runs the whole test suite, and the sanitizer set.
#
#   scripts/test.sh                    every test, the tool, the examples and the Python module,
#                                      built by clang++-14 in build/ (Release), then ctest
#   scripts/test.sh --sanitize         the sanitizer set (tests/CMakeLists.txt, NHDYN_SANITIZE_SET:
#                                      the code that handles memory, indices and bad input; without
#                                      the tool and the examples) under AddressSanitizer and
#                                      UndefinedBehaviorSanitizer, built by g++ at -O0 with line
#                                      tables in build-asan/
#   scripts/test.sh --sanitize --all   every test, the tool and the examples, under the sanitizers
#   --cxx COMPILER                     build by COMPILER instead, e.g. --cxx g++
#
# Two compilers: clang for the suite, where it halves the build; g++ for the sanitizer set (the
# kernels, the loaders, the wheels, robot_dynamics and the parsers' bad input; at 2.8 times
# clang's cost there), so that both compile the core of every change. CI (.ci/run) runs both
# passes. clang 14 compiles the suite in about half g++ 12's time (clean builds measured on
# 2026-12-06: docs/performance.md, "CI time"). The test programs are built at
# NHDYN_TEST_OPT (tests/CMakeLists.txt: -O0 under clang, -O1 under g++), the tool, the examples
# and the Python module at -O1 (NHDYN_PROGRAM_OPT).
set -euo pipefail
cd "$(dirname "$0")/.."
sanitize=0
all=0
cxx=""
while [ $# -gt 0 ]; do
  case "$1" in
    --sanitize) sanitize=1 ;;
    --all) all=1 ;;
    --cxx) cxx="${2:?--cxx needs a compiler, e.g. --cxx g++}"; shift ;;
    *) echo "scripts/test.sh: unknown option '$1' (--sanitize, --all, --cxx COMPILER)" >&2; exit 2 ;;
  esac
  shift
done
if [ "$all" = 1 ] && [ "$sanitize" = 0 ]; then
  echo "scripts/test.sh: --all goes with --sanitize (the Release pass builds everything)" >&2
  exit 2
fi
bash scripts/install-deps.sh  # installs g++ and clang-14 too, so look for the compiler after it
[ "$sanitize" = 1 ] && cxx=${cxx:-g++} || cxx=${cxx:-clang++-14}
cxx_path=$(command -v "$cxx") || { echo "scripts/test.sh: compiler '$cxx' not found" >&2; exit 2; }
cxx_version=$("$cxx_path" --version | head -1)
targets=()
select=()
if [ "$sanitize" = 1 ]; then
  dir=build-asan
  # line tables for the sanitizers' reports: -gline-tables-only (clang), -g1 (g++)
  case "$cxx_version" in *clang*) lines=-gline-tables-only ;; *) lines=-g1 ;; esac
  extra=(-DCMAKE_BUILD_TYPE=None "-DCMAKE_CXX_FLAGS=-O0 $lines"
         -DNHDYN_TEST_OPT= -DNHDYN_PROGRAM_OPT= -DNHDYN_SANITIZE=address,undefined)
  if [ "$all" = 0 ]; then
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
# A build folder configured by another compiler starts again from an empty cache (CMake keeps
# the first compiler it found in a folder; compared as real paths: /usr/bin/c++ is g++-12).
if [ -f "$dir/CMakeCache.txt" ]; then
  cached=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$dir/CMakeCache.txt")
  cached_path=$(command -v "$cached" 2>/dev/null || true)
  if [ -n "$cached" ] &&
     [ "$(realpath -e "$cached_path" 2>/dev/null)" != "$(realpath -e "$cxx_path")" ]; then
    echo "test.sh: $dir was configured by $cached; configuring it again for $cxx_path"
    rm -rf "$dir/CMakeCache.txt" "$dir/CMakeFiles"
  fi
fi
cmake -S . -B "$dir" -DCMAKE_CXX_COMPILER="$cxx_path" -DNHDYN_BUILD_TESTS=ON "${extra[@]}" >/dev/null
echo "test.sh: $dir, $cxx_version"
t0=$SECONDS
cmake --build "$dir" -j"$(nproc)" "${targets[@]}"
echo "test.sh: $dir built in $(( SECONDS - t0 )) s"
t0=$SECONDS
(cd "$dir" && ctest --output-on-failure -j"$(nproc)" "${select[@]}")
echo "test.sh: $dir tested in $(( SECONDS - t0 )) s"
