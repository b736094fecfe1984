#!/bin/bash
# (5, 0.1 M) to 50 µs with the path settings of §12 but a looser error tolerance
# run from the repository root; runs go to $RUNS (default runs/s7)
ROOT=$(pwd); mkdir -p "${RUNS:=runs/s7}"; cd "$RUNS"
B=${IBROD:-$ROOT/build/app/ibrod}
O="--set time.t_end_us=50 --set output.every_us=0.2 --set output.frame_every_us=0.2 --set run.threads=1"
P="--set time.scheme=\"implicit\" --set time.implicit_local_mobility=\"overlap\" --set time.implicit_order=2 --set time.implicit_krylov_iterations=3 --set time.implicit_krylov_tol=1e-3"
CAP=${CAP:-4.4}
for tol in $*; do
  /usr/bin/time -f "tol_${tol}_cap$CAP wall %e s" nice -n 19 $B run $ROOT/examples/reference/dlk5_cs0.1.toml -o tol_${tol}_cap$CAP $O $P --set time.dt_ns=$CAP --set time.error_tolerance_A=$tol > tol_${tol}_cap$CAP.log 2>&1
done
