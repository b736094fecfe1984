#!/usr/bin/env bash
# Installs the dependencies (if missing), configures and builds ibrod with a CMake preset
# (default: "default", the Release build in build/). Usage: scripts/build.sh [PRESET]
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-default}
bash scripts/install-deps.sh
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" -j "$(nproc)"
