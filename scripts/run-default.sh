#!/usr/bin/env bash
# Sets up, builds and runs the built-in default simulation into runs/default (replacing it).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh default
./build/app/ibrod run -o runs/default --overwrite "$@"
