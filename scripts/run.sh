#!/usr/bin/env bash
# The main job: install what is needed, build, and run the paper's example.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DNHDYN_BUILD_TESTS=OFF >/dev/null
cmake --build build -j"$(nproc)" --target paper5_id
./build/examples/paper5_id
