#!/bin/bash
# The IB half of the equilibrium check (docs/thermal.md): thermal runs of the 100 bp ring of
# ring.toml at ΔLk = 0 and 1, two seeds each, T_US µs each (10 by default), one thread, niced.
# Usage: prototypes/thermal/run_ib.sh OUTDIR [T_US]   (from the repository root; ~3-15 s per µs here)
#        PROBES=1 prototypes/thermal/run_ib.sh OUTDIR [T_US]: the two probes at the end instead
#        PROBES=2 prototypes/thermal/run_ib.sh OUTDIR: the time-step probes of "Which suspect it
#                 was" (ΔLk = 0 at Δt = 0.05 ns, seeds 2, 4, 5 µs, and 0.025 ns, seed 3, 3 µs;
#                 ΔLk = 1 at 0.05 ns, seeds 3, 4, 8 µs)
#        DRIFT=false …: without the stochastic drift (solvent.thermal_drift = false), as the runs
#                 of "Writhe and shape against Monte Carlo" were made; default true
#        IMPLICIT_DT=1 …: the implicit scheme (overlap M_loc, the thermal defaults) at this fixed
#                 Δt in ns instead of the explicit one at 0.1 ns: a row every step, a frame every
#                 2 ns (issue 28, "The implicit scheme against Monte Carlo")
set -euo pipefail
out=${1:?usage: run_ib.sh OUTDIR [T_US]}
t_us=${2:-10}
ibrod=${IBROD:-./build/app/ibrod}
drift=${DRIFT:-true}
mkdir -p "$out"
scheme=()
if [ -n "${IMPLICIT_DT:-}" ]; then
  frame=$(/usr/bin/python3 -c "print(max(1, round(2 / $IMPLICIT_DT)))")
  scheme=(--set time.scheme='"implicit"' --set time.implicit_local_mobility='"overlap"'
          --set time.dt_ns="$IMPLICIT_DT" --set output.every_steps=1
          --set output.frame_every_steps="$frame")
fi
run() {
  nice -n 10 "$ibrod" run prototypes/thermal/ring.toml --set solvent.thermal_drift="$drift" \
    ${scheme[@]+"${scheme[@]}"} "$@" >/dev/null
}
[ "${PROBES:-0}" != 0 ] || for dlk in 0 1; do
  for seed in 1 2; do
    run -o "$out/ib_dlk${dlk}_s${seed}" --set rod.excess_link=$dlk --set run.seed=$seed \
      --set time.t_end_us="$t_us"
  done
done
# the two probes of what differs (ΔLk = 0, seed 3): half the time step at 16³, and 32³ (h halved;
# its explicit limit is ~0.07 ns, so Δt = 0.05 ns), T_US/2 and T_US/5 µs
if [ "${PROBES:-0}" = 1 ]; then
  run -o "$out/ib_dlk0_dt05" --set run.seed=3 \
    --set time.dt_ns=0.05 --set output.every_steps=20 --set output.frame_every_steps=40 \
    --set time.t_end_us="$(echo "$t_us / 2" | bc -l)"
  run -o "$out/ib_dlk0_n32" --set run.seed=3 \
    --set grid.n=32 --set time.dt_ns=0.05 --set output.every_steps=20 \
    --set output.frame_every_steps=40 --set time.t_end_us="$(echo "$t_us / 5" | bc -l)"
fi
# the time-step probes (one frame every 2 ns, one row every 1 ns at each Δt)
if [ "${PROBES:-0}" = 2 ]; then
  for seed in 2 4; do
    run -o "$out/ib_dlk0_dt05_s$seed" --set run.seed=$seed --set time.dt_ns=0.05 \
      --set output.every_steps=20 --set output.frame_every_steps=40 --set time.t_end_us=5
  done
  run -o "$out/ib_dlk0_dt025_s3" --set run.seed=3 --set time.dt_ns=0.025 \
    --set output.every_steps=40 --set output.frame_every_steps=80 --set time.t_end_us=3
  for seed in 3 4; do
    run -o "$out/ib_dlk1_dt05_s$seed" --set run.seed=$seed --set rod.excess_link=1 \
      --set time.dt_ns=0.05 --set output.every_steps=20 --set output.frame_every_steps=40 \
      --set time.t_end_us=8
  done
fi
