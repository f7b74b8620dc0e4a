#!/usr/bin/env bash
# Fuzzes nhdyn's input parsers with libFuzzer (clang, -fsanitize=fuzzer,address,undefined).
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]      default: 600 s each, every target
#
# Targets (tests/fuzz/fuzz_<target>.cpp): model_json (the JSON model loader), tool_lines (the
# nhdyn tool's JSON-lines loop with id and fd), scene (the scene loader, when built).
# Each run starts from the kept corpus tests/fuzz/corpus/<target>/ plus a working corpus in
# the build folder, and at the end the new inputs are merged back, minimised, into the kept
# corpus (libFuzzer -merge=1: only inputs that add coverage). A crash, leak or sanitizer
# report stops with a non-zero status; libFuzzer leaves the input as crash-* in the build folder.
# Env: NHDYN_FUZZ_BUILD (default build-fuzz), CXX_FUZZ (default clang++-14), FUZZ_JOBS (1).
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-600}; shift || true
build=${NHDYN_FUZZ_BUILD:-build-fuzz}
cxx=${CXX_FUZZ:-clang++-14}
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(model_json tool_lines scene)
cmake -S . -B "$build" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DNHDYN_FUZZ=ON -DNHDYN_BUILD_TESTS=ON -DNHDYN_BUILD_EXAMPLES=ON >/dev/null
status=0
for t in "${targets[@]}"; do
  [ -f "tests/fuzz/fuzz_$t.cpp" ] || { echo "fuzz: no target $t, skipped"; continue; }
  cmake --build "$build" -j2 --target "fuzz_$t"
  work="$build/fuzz-corpus/$t"; kept="tests/fuzz/corpus/$t"
  mkdir -p "$work" "$kept"
  echo "fuzz: $t for $secs s"
  if ! (cd "$build" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
        "./fuzz_$t" -max_total_time="$secs" -jobs=1 -workers=1 -timeout=10 -rss_limit_mb=2048 \
        -max_len=8192 -dict="../tests/fuzz/json.dict" -print_final_stats=1 \
        "fuzz-corpus/$t" "../$kept" 2>&1 | tee "fuzz-$t.log" | grep -E "^(#[0-9]+ *DONE|stat::|==[0-9]+==ERROR|SUMMARY|fuzz oracle)" ); then
    :
  fi
  if grep -qE "ERROR: (libFuzzer|AddressSanitizer|UndefinedBehaviorSanitizer|LeakSanitizer)|runtime error|fuzz oracle failed" "$build/fuzz-$t.log"; then
    echo "fuzz: $t FAILED (see $build/fuzz-$t.log and $build/crash-*)"; status=1; continue
  fi
  # Keep a minimised corpus: merge the working corpus into a fresh copy of the kept one.
  tmp=$(mktemp -d)
  (cd "$build" && "./fuzz_$t" -merge=1 "$tmp" "../$kept" "fuzz-corpus/$t" >/dev/null 2>&1)
  rm -f "$kept"/*; cp "$tmp"/* "$kept"/ 2>/dev/null || true; rm -rf "$tmp"
  echo "fuzz: $t ok, kept corpus $(ls "$kept" | wc -l) files, $(du -sk "$kept" | cut -f1) KB"
done
exit $status
