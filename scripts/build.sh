#!/usr/bin/env bash
# Installs the dependencies (if missing), configures and builds ibrod with a CMake preset
# (default: "default", the Release build in build/).
# Usage: scripts/build.sh [PRESET] [TARGET...]   no TARGET: everything (tests, benchmarks,
# prototypes); scripts/run-default.sh builds only the targets a run needs.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-default}
shift || true
bash scripts/install-deps.sh
cmake --preset "$preset" >/dev/null
if [ $# -gt 0 ]; then
  cmake --build --preset "$preset" -j "$(nproc)" --target "$@"
else
  cmake --build --preset "$preset" -j "$(nproc)"
fi
