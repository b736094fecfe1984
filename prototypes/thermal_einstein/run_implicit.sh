#!/bin/bash
# issue 28: the Einstein relation in the implicit scheme with noise at 1 ns (D with the drift, the
# defaults; the full-Hessian filter), 100 bp ring at 32^3 in a 725 A box: SEEDS (default 1 2 3),
# T us each (default 4), a frame every step (1 ns); then pool.py pi_x pi_z LAGS ti_s1 ti_s2 ...
# (docs/thermal.md "The Einstein relation in the implicit scheme"; 2026-12-07: SEEDS="$(seq 1 16)"
# T=8, two such scripts side by side)
# PULL=1: instead, the thermal ring pulled with 10 pN (noise on) along x (seeds 101-103) and z
# (104-106), 4 us each, a frame every 10 steps; then thermal_pull.py tp_x1,tp_x2,tp_x3 tp_z1,tp_z2,tp_z3
# PULL=1 PULL_PN=3 PULL_N=4: the linear-response check, 3 pN, 4 runs an axis (seeds 201-208), runs
# t3_x1..t3_x4, t3_z1..t3_z4; then PULL_PN=3 thermal_pull.py t3_x1,...,t3_x4 t3_z1,...,t3_z4
B=../../build/app/ibrod
if [ -n "${PULL:-}" ]; then
  pn=${PULL_PN:-10}; n=${PULL_N:-3}; pre=tp; base=100
  if [ "$pn" != 10 ]; then pre=t$pn; base=200; fi
  for i in $(seq 1 $((2 * n))); do
    d=x; f="[$pn,0,0]"; j=$i
    if [ $i -gt $n ]; then d=z; f="[0,0,$pn]"; j=$((i - n)); fi
    nice -n 5 $B run ../thermal/ring.toml -o ${pre}_$d$j --overwrite --set grid.n=32 --set grid.box_A=725 \
      --set time.scheme='"implicit"' --set time.implicit_local_mobility='"overlap"' --set time.dt_ns=1 \
      --set run.threads=1 --set output.checkpoint_every_steps=0 --set run.seed=$((base + i)) \
      --set time.t_end_us=4 --set output.every_steps=100 --set output.frame_every_steps=10 \
      --set "external.force_pN=$f" 2>&1 | tail -1
  done
  exit 0
fi
for s in ${SEEDS:-1 2 3}; do
  nice -n 5 $B run ../thermal/ring.toml -o ti_s$s --overwrite --set grid.n=32 --set grid.box_A=725 \
    --set time.scheme='"implicit"' --set time.implicit_local_mobility='"overlap"' --set time.dt_ns=1 \
    --set run.threads=1 --set output.checkpoint_every_steps=0 --set run.seed=$s --set time.t_end_us=${T:-4} \
    --set output.every_steps=100 --set output.frame_every_steps=1 2>&1 | tail -1
done
