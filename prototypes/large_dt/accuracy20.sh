#!/bin/bash
# Issue 14 accuracy at the reference grid (64³, 600 bp): (ΔLk, Cs) = (4, 0.1 M) and (6, 0.01 M)
# to 20 µs, explicit at 0.1 ns against implicit (adaptive, time.dt_ns = 2), rows every 20 ns, one
# thread each; then prototypes/large_dt/accuracy20.py compares them (docs/large_dt.md).
B=${B:-./build/app/ibrod}
O=${O:-/tmp/acc}
export OMP_WAIT_POLICY=passive
for c in "4 0.1" "6 0.01"; do set -- $c
  cfg=examples/reference/dlk${1}_cs${2}.toml
  $B run $cfg -o $O/exp_dlk$1_cs$2 --set time.t_end_us=20 --set output.every_steps=200 \
    --set output.frame_every_steps=2000 --set run.threads=1 --set output.checkpoint_every_steps=20000 &
  $B run $cfg -o $O/imp_dlk$1_cs$2 --set time.scheme='"implicit"' --set time.dt_ns=2 \
    --set time.t_end_us=20 --set output.every_us=0.02 --set output.frame_every_us=0.2 \
    --set output.checkpoint_every_us=1 --set run.threads=1 &
done
wait
/usr/bin/python3 prototypes/large_dt/accuracy20.py $O/exp_dlk4_cs0.1 $O/imp_dlk4_cs0.1 $O/exp_dlk6_cs0.01 $O/imp_dlk6_cs0.01
