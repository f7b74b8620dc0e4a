#!/usr/bin/env bash
# nhdyn beside Pinocchio, timed by hand (docs/performance.md, "Beside Pinocchio"); not part of
# the build, the tests or CI:
#   bench/beside_pinocchio/run.sh <Pinocchio source tree> <example-robot-data source tree> [blocks]
# Builds the harness by g++ and by clang++-14 in build-beside-pinocchio/ (-O3 -march=native
# -DNDEBUG; under clang also -ffp-contract=fast, which the nhdyn CMake target gives every file of
# a program that links it, so Pinocchio's file gets it too), runs both (their output:
# build-beside-pinocchio/<compiler>.txt) and prints the table of docs/performance.md (table.py).
# Pinocchio is used header-only, compiled with the harness's flags (no
# PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION; -w: g++ 12 warns inside its joint code); the three
# headers its CMake would generate are written below. Needs Eigen, Boost's headers, urdfdom and
# tinyxml2 (the project's own dependencies).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 <Pinocchio source tree> <example-robot-data source tree> [blocks = 21]" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
pin=$(cd "$1" && pwd)
erd=$(cd "$2" && pwd)
blocks=${3:-21}
out=$root/build-beside-pinocchio
mkdir -p "$out/gen/pinocchio"
version=$(sed -n 's:.*<version>\(.*\)</version>.*:\1:p' "$pin/package.xml")
IFS=. read -r major minor patch <<< "$version"
cat > "$out/gen/pinocchio/config.hpp" <<H
#pragma once
#define PINOCCHIO_MAJOR_VERSION $major
#define PINOCCHIO_MINOR_VERSION $minor
#define PINOCCHIO_PATCH_VERSION $patch
#define PINOCCHIO_VERSION "$version"
#define PINOCCHIO_EXPLICIT_INSTANTIATION_DECLARATION_DLLAPI
H
cat > "$out/gen/pinocchio/deprecated.hpp" <<'H'
#pragma once
#define PINOCCHIO_DEPRECATED __attribute__((deprecated))
#define PINOCCHIO_DEPRECATED_MESSAGE(message) __attribute__((deprecated(message)))
H
cat > "$out/gen/pinocchio/warning.hpp" <<'H'
#pragma once
#define PINOCCHIO_WARNING(message)
H
flags=(-O3 -march=native -DNDEBUG -std=c++20 -isystem /usr/include/eigen3)
for cxx in g++ clang++-14; do
  dir=$out/$cxx
  mkdir -p "$dir"
  nh=(); [[ $cxx == clang* ]] && nh=(-ffp-contract=fast)
  "$cxx" "${flags[@]}" "${nh[@]}" -I"$root/include" -I"$root/tests" -c "$here/nh.cpp" -o "$dir/nh.o"
  "$cxx" "${flags[@]}" "${nh[@]}" -I"$root/include" -I"$root/tests" "-DNHDYN_SOURCE_DIR=\"$root\"" -c "$here/main.cpp" -o "$dir/main.o"
  "$cxx" "${flags[@]}" "${nh[@]}" -w -isystem "$out/gen" -isystem "$pin/include" -I"$root/include" -c "$here/pin.cpp" -o "$dir/pin.o"
  "$cxx" "$dir/main.o" "$dir/nh.o" "$dir/pin.o" -o "$dir/harness" -lurdfdom_model -ltinyxml2 -lconsole_bridge
done
for cxx in g++ clang++-14; do
  echo "== both libraries built by $cxx ($("$cxx" --version | head -1)), Pinocchio $version"
  "$out/$cxx/harness" "$erd" "$blocks" | tee "$out/$cxx.txt"
done
python3 "$here/table.py" "$out/g++.txt" "$out/clang++-14.txt"
