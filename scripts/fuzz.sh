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
# The kept corpus is capped (NHDYN_FUZZ_CORPUS_FILES, default 1000 files, and
# NHDYN_FUZZ_CORPUS_BYTES, default 131072 bytes per target): a larger merge is not written back.
# Env: NHDYN_FUZZ_BUILD (default build-fuzz), CXX_FUZZ (default clang++-14), FUZZ_JOBS (1).
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-600}; shift || true
build=${NHDYN_FUZZ_BUILD:-build-fuzz}
cap_files=${NHDYN_FUZZ_CORPUS_FILES:-1000}; cap_bytes=${NHDYN_FUZZ_CORPUS_BYTES:-131072}
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
  # Keep a minimised corpus: merge the working corpus into a fresh copy of the kept one, and
  # write it back only while it stays within the cap (the corpus lives in git).
  tmp=$(mktemp -d)
  (cd "$build" && "./fuzz_$t" -merge=1 "$tmp" "../$kept" "fuzz-corpus/$t" >/dev/null 2>&1)
  files=$(ls "$tmp" | wc -l); bytes=$(cat "$tmp"/* 2>/dev/null | wc -c)
  if [ "$files" -gt "$cap_files" ] || [ "$bytes" -gt "$cap_bytes" ]; then
    echo "fuzz: $t ok; merged corpus ($files files, $bytes bytes) exceeds the cap ($cap_files files, $cap_bytes bytes): kept corpus unchanged"
  else
    rm -f "$kept"/*; cp "$tmp"/* "$kept"/ 2>/dev/null || true
    echo "fuzz: $t ok, kept corpus $files files, $bytes bytes"
  fi
  rm -rf "$tmp"
done
exit $status
