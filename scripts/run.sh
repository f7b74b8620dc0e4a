#!/usr/bin/env bash
# The main job: install what is needed, build the nhdyn tool, and reproduce the paper's
# experiment — the circle, then both 16-run studies — printing the summary. Results (CSV per
# run, summary.json, figures) go to out/paper.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# -O3 even after scripts/test.sh; by the compiler build/ was configured with: on a fresh clone
# the system's c++ (g++ 12 on Debian), after scripts/test.sh clang 14 (its ctest entry
# simulate_cli_paper_33_of_33 checks the same 33 runs under clang).
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DNHDYN_BUILD_TESTS=OFF -DNHDYN_PROGRAM_OPT= >/dev/null
cmake --build build -j"$(nproc)" --target nhdyn_tool
./build/bin/nhdyn simulate paper --out out/paper
