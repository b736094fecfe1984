#!/bin/bash
# Issue 14 at the reference grid, low salt: 64³, 600 bp, ΔLk = 6, 0.01 M, 2 threads, to 3 µs:
# explicit at 0.1 ns against the implicit scheme (adaptive, Δt ≤ 2 and ≤ 4.4 ns, max
# displacement 0.2 min(1/κ, D) = 4 Å). docs/large_dt.md.
X=./build/prototypes/large_dt/large_dt_experiment
D=prototypes/large_dt
export OMP_WAIT_POLICY=passive
R="grid.n=64 grid.box_A=725 rod.base_pairs=600 rod.excess_link=6 solvent.salt_M=0.01 run.threads=2 run.fftw_measure=true"
T=${T:-3000}
$X $R scheme=explicit dt_ns=0.1 t_end_ns=$T out_ns=20 save=/tmp/ref64ls_X.txt > $D/ref64ls_explicit_0.1.txt
for dt in 2 4.4; do
  $X $R scheme=imex beta=8 adaptive=1 dmax=4 etol=1e-6 dt_ns=$dt jac_every=4 t_end_ns=$T out_ns=20 ref=/tmp/ref64ls_X.txt > $D/ref64ls_implicit_$dt.txt
done
grep -h SUMMARY $D/ref64ls_*.txt
