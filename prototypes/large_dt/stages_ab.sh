#!/bin/bash
# A/B: GMRES per stage (old binary) against GCR with the stages' directions shared (new), from a frame of an explicit run
# usage: OLD=ibrod_without NEW=ibrod_with prototypes/large_dt/stages_ab.sh EXPDIR FRAME T_US CELL
# (from the repository root; docs/large_dt.md §12, "Tried and dropped: the second stage on the
# first stage's Krylov directions"; the patch: prototypes/large_dt/gcr_recycle.patch)
cd "${AB_DIR:-.}"
E=$1; F=$2; T=$3; C=$4
for v in old new; do
  B=${NEW:-build/app/ibrod}; [ $v = old ] && B=${OLD:?the binary without the patch}
  nice -n 5 $B run ${ROOT:-.}/examples/reference/$C.toml -o ${v}_${C}_$F --overwrite \
    --set time.scheme='"implicit"' --set time.dt_ns=4.4 --set time.implicit_local_mobility='"overlap"' \
    --set time.implicit_order=2 --set time.implicit_krylov_iterations=3 --set time.implicit_krylov_tol=1e-3 \
    --set time.error_tolerance_A=0.001 --set rod.initial_shape="\"$E/trajectory.h5md@$F\"" --set time.t_end_us=$T \
    --set run.threads=1 --set output.every_us=0.05 --set run.fftw_measure=false > ${v}_${C}_$F.log 2>&1
  tail -1 ${v}_${C}_$F.log
  python3 -c "
import json;d=json.load(open('${v}_${C}_$F/summary.json'));print('$v',d['steps'],d['implicit_stokes_solves'],round(d['implicit_stokes_solves']/d['steps'],2),d['implicit_factorizations'],round(d['wall_time_s'],1))"
done
