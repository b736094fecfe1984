#!/usr/bin/env bash
# Sets up, builds and runs the built-in default simulation into runs/default (replacing it).
# Builds only what the run needs: the `ibrod` command line, and the Python module (build/python,
# one more file to compile, a few per cent of the build; docs/python.md); the tests,
# benchmarks and prototypes are built by scripts/test.sh (or scripts/build.sh).
set -euo pipefail
# OpenMP threads sleep instead of spinning while they wait: on a busy 2-core machine spinning
# costs up to 8x per step (docs/performance.md). An explicit setting by the caller wins.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
cd "$(dirname "$0")/.."
bash scripts/build.sh default ibrod ibrod_python
./build/app/ibrod run -o runs/default --overwrite "$@"
