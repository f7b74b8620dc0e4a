#!/usr/bin/env bash
# Builds and runs nhdyn's benchmarks, writes docs/performance.json (nhdyn_bench) and
# docs/performance-scalar.json (nhdyn_bench_scalar), and regenerates the tables of
# docs/performance.md and the plot docs/performance_scaling.png from them.
#
#   scripts/bench.sh                       # 9 repetitions in random interleaved order, medians
#   NHDYN_BENCH_REPS=15 scripts/bench.sh   # more repetitions
#   NHDYN_BENCH_FILTER='^rne/' scripts/bench.sh --no-docs   # a subset, JSON only (build-bench/performance.json;
#                                          # scripts/merge_bench.py merges it into docs/performance.json)
#   NHDYN_BENCH_CLANG=1 scripts/bench.sh   # the two-compiler table's kernels built by clang++-14
#                                          # (build-bench-clang/), run alternating with the g++
#                                          # build (build-bench/) in NHDYN_BENCH_SITTINGS sittings
#                                          # (4): docs/performance-clang.json and
#                                          # docs/performance-clang-gcc.json; the tables are then
#                                          # regenerated from the JSON files
#
# Environment: NHDYN_BENCH_BUILD (build dir, default build-bench), NHDYN_BENCH_REPS (9),
# NHDYN_BENCH_MIN_TIME (seconds per repetition, 0.1), NHDYN_BENCH_FILTER (regex, all),
# NHDYN_BENCH_SCALAR (1: also the scalar-type benchmarks; 0: skip them),
# CXX (compiler of a fresh build directory).
# The repetitions of all cases run interleaved in random order
# (--benchmark_enable_random_interleaving): on a shared machine whose speed drifts, the two
# sides of a ratio then sample the same drift instead of different minutes.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# Debian's python3 carries matplotlib (python3-matplotlib); prefer it over other pythons on PATH.
py=/usr/bin/python3
[ -x "$py" ] || py=python3
clang="${NHDYN_BENCH_CLANG:-0}"
if [ "$clang" = 1 ]; then
  export CXX="${CXX:-clang++-14}"
  build="${NHDYN_BENCH_BUILD:-$root/build-bench-clang}"
  filter="${NHDYN_BENCH_FILTER:-$("$py" "$root/scripts/perf_table.py" --print-clang-filter)}"
  NHDYN_BENCH_SCALAR=0
else
  build="${NHDYN_BENCH_BUILD:-$root/build-bench}"
  filter="${NHDYN_BENCH_FILTER:-.}"
fi
reps="${NHDYN_BENCH_REPS:-9}"
min_time="${NHDYN_BENCH_MIN_TIME:-0.1}"
docs=1
[ "${1:-}" = "--no-docs" ] && docs=0

"$root/scripts/install-deps.sh"
# CXX, if set, picks the compiler of a fresh build directory (CMake reads it at first configure).
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DNHDYN_BUILD_BENCH=ON -DNHDYN_BUILD_TESTS=OFF -DNHDYN_BUILD_EXAMPLES=OFF >/dev/null
scalar="${NHDYN_BENCH_SCALAR:-1}"
targets=(nhdyn_bench); [ "$scalar" = 1 ] && targets+=(nhdyn_bench_scalar)
make -C "$build" -j2 "${targets[@]}"

run_bench() {  # run_bench BINARY OUT.json
  "$1" --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true \
    --benchmark_min_time="$min_time" --benchmark_filter="$filter" --benchmark_out="$2" --benchmark_out_format=json
}
json="$root/docs/performance.json"
[ $docs -eq 0 ] && json="$build/performance.json"
if [ "$clang" = 1 ] && [ $docs -eq 1 ] && [ -x "$root/build-bench/bench/nhdyn_bench" ]; then
  # clang: the clang build and the g++ build on the same cases, alternating in NHDYN_BENCH_SITTINGS
  # sittings (default 4): the machine's speed drifts from minute to minute, and one case's
  # clang/g++ ratio differed by up to 0.3 between sittings (2026-12-02); the table takes each
  # case's median over the sittings
  tmp="$(mktemp -d)"
  sittings="${NHDYN_BENCH_SITTINGS:-4}"
  for k in $(seq -w 1 "$sittings"); do  # (zero-padded: the globs below list them in order)
    run_bench "$build/bench/nhdyn_bench" "$tmp/clang-$k.json"
    run_bench "$root/build-bench/bench/nhdyn_bench" "$tmp/gcc-$k.json"
  done
  "$py" "$root/scripts/merge_bench.py" "$root/docs/performance-clang.json" --sittings "$tmp"/clang-*.json
  "$py" "$root/scripts/merge_bench.py" "$root/docs/performance-clang-gcc.json" --sittings "$tmp"/gcc-*.json
  rm -rf "$tmp"
else
  if [ "$clang" = 1 ] && [ $docs -eq 1 ]; then
    json="$root/docs/performance-clang.json"
    # no g++ binary to alternate with: an older g++ run is not of this sitting (the table then
    # draws a ratio only where performance.json's run is within 12 hours of this one)
    rm -f "$root/docs/performance-clang-gcc.json"
  fi
  run_bench "$build/bench/nhdyn_bench" "$json"
  echo "bench.sh: wrote $json"
  [ $docs -eq 0 ] && exit 0
fi

cpu="$(lscpu | sed -n 's/^Model name:[[:space:]]*//p' | head -1)"
compiler_of() { "$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$1/CMakeCache.txt")" --version | head -1; }
# The tables: from the g++ build's JSON, with the clang build's beside it when there is one.
main_build="$root/build-bench" clang_build="$root/build-bench-clang"
[ "$clang" = 1 ] && clang_build="$build" || main_build="$build"
main_json="$root/docs/performance.json" clang_json="$root/docs/performance-clang.json"
compiler="$(compiler_of "$main_build")"
second=()
[ -f "$clang_json" ] && [ -f "$clang_build/CMakeCache.txt" ] && second=(--second "$clang_json" --second-compiler "$(compiler_of "$clang_build")")
[ ${#second[@]} -gt 0 ] && [ -f "$root/docs/performance-clang-gcc.json" ] && second+=(--second-baseline "$root/docs/performance-clang-gcc.json")
"$py" "$root/scripts/perf_table.py" "$main_json" "$root/docs/performance.md" "$root/docs/performance_scaling.png" \
  --cpu "$cpu" --compiler "$compiler" "${second[@]}"
[ "$clang" = 1 ] && exit 0

# The Python module's call overhead and batch throughput (issue 16), when it can be built.
if grep -q '^NHDYN_BUILD_PYTHON:BOOL=ON' "$build/CMakeCache.txt"; then
  make -C "$build" -j2 nhdyn_python   # a failure here is a real one: it stops the script
  PYTHONPATH="$build/python" "$py" "$root/bench/python_bench.py" "$root/docs/performance-python.json" \
    --doc "$root/docs/performance.md"
else
  echo "bench.sh: the Python module is not configured (pybind11-dev, python3-dev, python3-numpy): no Python benchmark"
fi

if [ "$scalar" = 1 ]; then
  sjson="$root/docs/performance-scalar.json"
  "$build/bench/nhdyn_bench_scalar" --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true \
    --benchmark_min_time="$min_time" --benchmark_out="$sjson" --benchmark_out_format=json
  echo "bench.sh: wrote $sjson"
  "$py" "$root/scripts/scalar_table.py" "$sjson" "$root/docs/performance.md" --cpu "$cpu" --compiler "$compiler"
fi
