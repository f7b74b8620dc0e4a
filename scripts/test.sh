#!/usr/bin/env bash
# Builds and runs the whole test suite. With --sanitize: the same under AddressSanitizer and
# UndefinedBehaviorSanitizer, in its own build folder.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
dir=build; extra=()
if [ "${1:-}" = "--sanitize" ]; then
  dir=build-asan; extra=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DNHDYN_SANITIZE=address,undefined)
else
  extra=(-DCMAKE_BUILD_TYPE=Release)
fi
cmake -S . -B "$dir" -DNHDYN_BUILD_TESTS=ON -DNHDYN_BUILD_EXAMPLES=ON "${extra[@]}" >/dev/null
cmake --build "$dir" -j"$(nproc)"
cd "$dir" && ctest --output-on-failure -j"$(nproc)"
