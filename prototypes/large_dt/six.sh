#!/bin/bash
# Reference cells to 20 µs: explicit at 0.1 ns, then the path settings of docs/large_dt.md §12,
# then `ibrod compare`; the cells given (default dlk6_cs0.1 dlk6_cs0.05), one after the other.
# Run from the repository root; runs go to $RUNS (default runs/s7).
#   prototypes/large_dt/six.sh [CELL ...]     e.g. dlk5_cs0.01
# T: the end time in µs (default 20); EXTRA: more --set options for the implicit run, e.g.
#   EXTRA='--set time.implicit_krylov_error_share=0.3' T=50 prototypes/large_dt/six.sh dlk5_cs0.1
# (docs/large_dt.md §13); SKIP_EXPLICIT=1: the implicit run alone, against an explicit run there
ROOT=$(pwd); mkdir -p "${RUNS:=runs/s7}"; cd "$RUNS"
B=${IBROD:-$ROOT/build/app/ibrod}
O="--set time.t_end_us=${T:-20} --set output.every_us=0.2 --set output.frame_every_us=0.2 --set run.threads=1"
P="--set time.scheme=\"implicit\" --set time.dt_ns=4.4 --set time.implicit_local_mobility=\"overlap\" --set time.implicit_order=2 --set time.implicit_krylov_iterations=3 --set time.implicit_krylov_tol=1e-3 --set time.error_tolerance_A=0.001"
for c in ${@:-dlk6_cs0.1 dlk6_cs0.05}; do
  [ -n "${SKIP_EXPLICIT:-}" ] ||
    /usr/bin/time -f "exp_$c wall %e s" nice -n 19 $B run $ROOT/examples/reference/$c.toml -o exp_$c $O > exp_$c.log 2>&1
  /usr/bin/time -f "one_$c wall %e s" nice -n 19 $B run $ROOT/examples/reference/$c.toml -o one_$c $O $P ${EXTRA:-} > one_$c.log 2>&1
  $B compare exp_$c one_$c > cmp_$c.txt 2>&1
done
echo ALLDONE
