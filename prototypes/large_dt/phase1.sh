#!/bin/bash
# Issue 14, phase 1 measurements (docs/large_dt.md). Run from the repository root after a build:
#   prototypes/large_dt/phase1.sh > prototypes/large_dt/phase1.out
# 32³ grid (h = 11.33 Å as at the reference), 150 bp ring, ΔLk = 3, 0.1 M, electrostatics and
# steric on, one thread. Buckling ~60-120 ns, first contact ~160 ns.
X=./build/prototypes/large_dt/large_dt_experiment
export OMP_WAIT_POLICY=passive OMP_NUM_THREADS=1
S="grep -E ^SUMMARY"
echo "## references: explicit Stokes-limit Euler at 0.01 ns"
$X scheme=stokes dt_ns=0.01 t_end_ns=100 out_ns=100 save=/tmp/ld_ref100.txt | $S
$X scheme=stokes dt_ns=0.01 t_end_ns=300 out_ns=300 save=/tmp/ld_ref300.txt | $S
echo "## stability to 300 ns (blown=1: non-finite, spacing off by 50 %, or |ΔLk| > 0.1)"
for dt in 0.1 0.15 0.2 0.25 0.3; do $X scheme=explicit dt_ns=$dt t_end_ns=300 ref=/tmp/ld_ref300.txt 2>&1 | $S; done
for dt in 0.1 0.15 0.2; do $X scheme=stokes dt_ns=$dt t_end_ns=300 ref=/tmp/ld_ref300.txt 2>&1 | $S; done
echo "### IMEX, velocity form, Gauss-Newton K + steric contacts"
for b in 4 8 16; do for dt in 1 2 4 8; do $X scheme=imex beta=$b dt_ns=$dt t_end_ns=300 ref=/tmp/ld_ref300.txt 2>&1 | $S; done; done
echo "### IMEX, force form (g = (I + dt K M_loc)^-1 F, delta = dt M g)"
for dt in 1 2 4 8; do $X scheme=imex form=force beta=8 dt_ns=$dt t_end_ns=300 ref=/tmp/ld_ref300.txt 2>&1 | $S; done
echo "### IMEX, velocity form, full finite-difference K (not Gauss-Newton)"
for dt in 1 2 4; do $X scheme=imex K=full beta=8 dt_ns=$dt t_end_ns=300 ref=/tmp/ld_ref300.txt 2>&1 | $S; done
echo "### IMEX, velocity form, steric explicit"
for dt in 1 2; do $X scheme=imex steric_implicit=0 beta=8 dt_ns=$dt t_end_ns=300 ref=/tmp/ld_ref300.txt 2>&1 | $S; done
echo "### linearly implicit Euler by GMRES (velocity form), preconditioned by the IMEX system"
for dt in 2 4 8; do $X scheme=krylov kiter=10 tol=1e-2 beta=8 dt_ns=$dt t_end_ns=300 ref=/tmp/ld_ref300.txt 2>&1 | $S; done
$X scheme=krylov form=force kiter=20 tol=1e-2 beta=8 dt_ns=2 t_end_ns=300 ref=/tmp/ld_ref300.txt 2>&1 | $S
echo "## accuracy: max_k |X_k - X_ref,k| at 100 ns (before contact)"
for dt in 0.0125 0.025 0.05 0.1; do $X scheme=stokes dt_ns=$dt t_end_ns=100 ref=/tmp/ld_ref100.txt | $S; done
for dt in 0.125 0.25 0.5 1 2; do $X scheme=imex beta=8 dt_ns=$dt t_end_ns=100 ref=/tmp/ld_ref100.txt | $S; done
for dt in 0.25 0.5 1; do $X scheme=imex beta=8 jac_every=10 dt_ns=$dt t_end_ns=100 ref=/tmp/ld_ref100.txt | $S; done
echo "## adaptive (displacement <= 2 A, energy non-increasing to 1e-3 kT, dt <= dt_max), 300 ns"
for dt in 1 2 4 8; do $X scheme=imex beta=8 adaptive=1 dmax=2 dt_ns=$dt t_end_ns=300 ref=/tmp/ld_ref300.txt | $S; done
echo "## time series for the figure"
D=prototypes/large_dt
$X scheme=stokes dt_ns=0.1 t_end_ns=300 out_ns=5 > $D/ld_series_explicit.txt
for dt in 0.5 1 2; do $X scheme=imex beta=8 dt_ns=$dt t_end_ns=300 out_ns=5 > $D/ld_series_imex_$dt.txt; done
$X scheme=imex beta=8 adaptive=1 dmax=2 dt_ns=4 t_end_ns=300 out_ns=5 > $D/ld_series_adaptive.txt
/usr/bin/python3 $D/plot_phase1.py
