#!/bin/bash
# Time per step of one grid on 1 rank × 1 thread, 1 rank × 2 threads or 2 MPI ranks × 1 thread
# (docs/sweeps.md, "One large grid over MPI ranks"). Usage, from the repository root:
#   scripts/time_mpi.sh N STEPS MODE      MODE: 1r1t | 1r2t | 2r1t
# Prints "N STEPS MODE steps loop_seconds ms_per_step" from summary.json. The time per step is
# (loop_seconds(long) − loop_seconds(short)) / (steps(long) − steps(short)): the difference
# cancels the start-up, the step-0 diagnostics and the start and end checkpoints.
set -euo pipefail
N=$1; S=$2; MODE=$3
B=${IBROD:-./build/app/ibrod}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_WAIT_POLICY=passive
T=$(/usr/bin/python3 -c "print($S * 0.005 / 1000)")  # µs: S steps of 0.005 ns
D=$(mktemp -d)/run
ARGS=(--set grid.n=$N --set time.dt_ns=0.005 --set time.t_end_us=$T
      --set output.every_steps=100000 --set output.frame_every_steps=0
      --set output.checkpoint_every_steps=0 --set run.fftw_measure=false)
case $MODE in
  1r1t) $B run "${ARGS[@]}" --set run.threads=1 -o $D > $D.log 2>&1 ;;
  1r2t) $B run "${ARGS[@]}" --set run.threads=2 -o $D > $D.log 2>&1 ;;
  2r1t) mpirun --oversubscribe -np 2 $B run "${ARGS[@]}" --set run.threads=1 -o $D > $D.log 2>&1 ;;
  *) echo "MODE must be 1r1t, 1r2t or 2r1t" >&2; exit 2 ;;
esac
/usr/bin/python3 -c "import json; j = json.load(open('$D/summary.json')); \
print('$N $S $MODE', j['steps'], round(j['ms_per_step'] * j['steps'] / 1000, 3), j['ms_per_step'])"
rm -rf "$(dirname $D)"
