#!/bin/bash
# docs/large_dt.md §13: Stokes solves a step at the path settings of §12 with
# time.implicit_krylov_error_share = each SHARE, from frame F of an explicit run, for T µs.
# From the repository root; runs go to $RUNS (default runs/share).
#   prototypes/large_dt/share.sh EXPLICIT_RUN F T CELL SHARE...
#   e.g. prototypes/large_dt/share.sh runs/exp_dlk6_cs0.01 100 1 dlk6_cs0.01 0 0.03 0.1 0.3 1
ROOT=$(pwd); B=${IBROD:-$ROOT/build/app/ibrod}
E=$(realpath "$1"); F=$2; T=$3; C=$4; shift 4
mkdir -p "${RUNS:=runs/share}"; cd "$RUNS"
for s in "$@"; do
  o=sh_${C}_${F}_$s
  nice -n 5 $B run $ROOT/examples/reference/$C.toml -o $o --overwrite \
    --set time.scheme='"implicit"' --set time.dt_ns=4.4 --set time.implicit_local_mobility='"overlap"' \
    --set time.implicit_order=2 --set time.implicit_krylov_iterations=3 --set time.implicit_krylov_tol=1e-3 \
    --set time.error_tolerance_A=0.001 --set rod.initial_shape="\"$E/trajectory.h5md@$F\"" \
    --set time.t_end_us=$T --set run.threads=1 --set output.every_us=0.05 --set run.fftw_measure=false \
    --set time.implicit_krylov_error_share=$s > $o.log 2>&1
  /usr/bin/python3 -c "
import json; d = json.load(open('$o/summary.json'))
print('share $s: steps', d['steps'], 'Stokes solves', d['implicit_stokes_solves'],
      'a step %.2f' % (d['implicit_stokes_solves'] / d['steps']), 'LUs', d['implicit_factorizations'])"
  tail -1 $o/timeseries.csv
done
