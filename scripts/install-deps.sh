#!/usr/bin/env bash
# Installs everything nhdyn needs to build, test, benchmark and plot, from Debian 12's
# packages only. Safe to run again; run as root (no sudo needed) or with sudo.
set -euo pipefail
pkgs=(
  build-essential cmake g++ clang-14 libclang-rt-14-dev
  libeigen3-dev librange-v3-dev catch2 libbenchmark-dev
  libboost-dev liborocos-kdl-dev nlohmann-json3-dev libcli11-dev libxsimd-dev
  liburdfdom-dev libtinyxml2-dev
  gnuplot-nox python3 python3-matplotlib
  pybind11-dev python3-dev python3-numpy python3-pytest python3-scipy
  libopenmpi-dev openmpi-bin
  chromium
)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# node and npm: Debian's (nodejs, npm) unless the machine has them already (another node,
# e.g. NodeSource's, which brings its own npm and which Debian's npm would fight).
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends nodejs npm >/dev/null
fi
# The page of `nhdyn view`: three.js, urdf-loader, esbuild and puppeteer-core (the browser
# test), exactly as viewer/package-lock.json pins them, from the npm registry. Again only when
# the lock file changed since the last install.
viewer="$(cd "$(dirname "$0")/.." && pwd)/viewer"
if [ ! -f "$viewer/node_modules/.package-lock.json" ] || [ "$viewer/package-lock.json" -nt "$viewer/node_modules/.package-lock.json" ]; then
  (cd "$viewer" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
fi
echo "nhdyn: dependencies present"
