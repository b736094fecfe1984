#!/bin/bash
# The Monte-Carlo half of the equilibrium check (docs/thermal.md): mc_ring on the ring of
# ring.toml at ΔLk = 0 and 1, SWEEPS sweeps each (25000 by default; ~10 ms of CPU a sweep here),
# one row every 10 sweeps, the two in parallel. Usage: prototypes/thermal/run_mc.sh OUTDIR [SWEEPS]  (repository root;
# build it first: cmake --build --preset default --target mc_ring)
set -euo pipefail
out=${1:?usage: run_mc.sh OUTDIR [SWEEPS]}
sweeps=${2:-25000}
mc=${MC_RING:-./build/prototypes/thermal/mc_ring}
mkdir -p "$out"
for dlk in 0 1; do
  nice -n 10 "$mc" prototypes/thermal/ring.toml rod.excess_link=$dlk sweeps="$sweeps" burn=1000 \
    every=10 seed=$((dlk + 1)) out="$out/mc_dlk$dlk.csv" 2>"$out/mc_dlk$dlk.log" &
done
wait
