#!/usr/bin/env bash
# Sets up, builds and runs the default test suite (unit + integration tiers; the validation tier
# is `ctest --preset validation`). Usage: scripts/test.sh [PRESET]   (PRESET: default or asan)
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-default}
bash scripts/build.sh "$preset"
ctest --preset "$preset"
