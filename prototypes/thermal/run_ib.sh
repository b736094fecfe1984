#!/bin/bash
# The IB half of the equilibrium check (docs/thermal.md): thermal runs of the 100 bp ring of
# ring.toml at ΔLk = 0 and 1, two seeds each, T_US µs each (10 by default), one thread, niced.
# Usage: prototypes/thermal/run_ib.sh OUTDIR [T_US]   (from the repository root; ~13 s per µs here)
set -euo pipefail
out=${1:?usage: run_ib.sh OUTDIR [T_US]}
t_us=${2:-10}
ibrod=${IBROD:-./build/app/ibrod}
mkdir -p "$out"
for dlk in 0 1; do
  for seed in 1 2; do
    nice -n 10 "$ibrod" run prototypes/thermal/ring.toml -o "$out/ib_dlk${dlk}_s${seed}" \
      --set rod.excess_link=$dlk --set run.seed=$seed --set time.t_end_us="$t_us" >/dev/null
  done
done
