#!/usr/bin/env bash
# A build outside the source tree (`cmake -S . -B ELSEWHERE`, the usual CMake habit): configures
# into a folder outside the clone, builds the command line alone and runs the tests that find
# files through the binary: `ibrod report` (its scripts: the plots and the HTML report) and the
# outputs read by standard tools. CI runs it after scripts/test.sh (.ci/run); the whole default
# suite out of the tree passes too (docs: README "Tests"), but would build everything twice.
# Usage: scripts/test-out-of-tree.sh [BUILD_DIR]   (default: a new folder under /tmp, removed after)
set -euo pipefail
cd "$(dirname "$0")/.."
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
if [ $# -gt 0 ]; then
  dir=$1
else
  dir=$(mktemp -d /tmp/ibrod-out-of-tree.XXXXXX)
  trap 'rm -rf "$dir"' EXIT
fi
generator=()
if command -v ninja >/dev/null; then generator=(-G Ninja); fi
cmake -S . -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$dir" -j "$(nproc)" --target ibrod
cd "$dir"
ctest --output-on-failure -j 2 \
  -R '^integration\.(plots_and_report|html_report|outputs_open_with_h5py_and_xml|examples)$'
