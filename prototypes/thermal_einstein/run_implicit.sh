#!/bin/bash
# issue 28: the Einstein relation in the implicit scheme with noise at 1 ns (D with the drift, the
# defaults; the full-Hessian filter), 100 bp ring at 32^3 in a 725 A box: seeds 1-3, T us each
# (default 4), a frame every step (1 ns); then pool.py pi_x pi_z LAGS ti_s1 ti_s2 ti_s3
# (docs/thermal.md "The Einstein relation in the implicit scheme")
B=../../build/app/ibrod
for s in 1 2 3; do
  nice -n 5 $B run ../thermal/ring.toml -o ti_s$s --overwrite --set grid.n=32 --set grid.box_A=725 \
    --set time.scheme='"implicit"' --set time.implicit_local_mobility='"overlap"' --set time.dt_ns=1 \
    --set run.threads=1 --set output.checkpoint_every_steps=0 --set run.seed=$s --set time.t_end_us=${T:-4} \
    --set output.every_steps=100 --set output.frame_every_steps=1 2>&1 | tail -1
done
