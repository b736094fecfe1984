#!/usr/bin/env bash
# Sets up, builds and runs the default test suite (unit + integration tiers; the validation tier
# is `ctest --preset validation`). Usage: scripts/test.sh [PRESET]   (PRESET: default or asan)
set -euo pipefail
# OpenMP threads sleep instead of spinning while they wait: on a busy 2-core machine spinning
# costs up to 8x per step (docs/performance.md). An explicit setting by the caller wins.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
cd "$(dirname "$0")/.."
preset=${1:-default}
bash scripts/build.sh "$preset"
ctest --preset "$preset"
