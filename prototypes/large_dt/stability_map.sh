#!/bin/bash
# Issue 14 stability map: the largest stable Δt of each scheme at 64³, 600 bp, 0.1 M, ΔLk = 2, 4, 6,
# from the reference configs (perturbation ε1 = 1). Implicit: at a FIXED Δt (the controller's
# displacement and energy limits lifted: 1e4 Å, 1e6 kT; its 0.2 rad rotation limit stays) and
# with the adaptive controller (defaults), to 2 µs. Explicit: to 0.5 µs (blow-ups come early).
B=${B:-./build/app/ibrod}
O=${O:-/tmp/smap}
export OMP_WAIT_POLICY=passive
common="--set output.frame_every_steps=0 --set output.checkpoint_every_steps=0 --set run.threads=1"
imp="--set time.scheme='\"implicit\"' --set time.t_end_us=2 --set output.every_us=0.02"
for dlk in ${DLKS:-2 4 6}; do
  cfg=examples/reference/dlk${dlk}_cs0.1.toml
  for dt in ${FIXED_DTS:-1 2 4.4}; do
    d=$O/imp_dlk${dlk}_fixed$dt; [ -e $d/summary.json ] && continue; rm -rf $d
    eval $B run $cfg -o $d $common $imp --set time.dt_ns=$dt \
      --set time.max_displacement_A=1e4 --set time.energy_tolerance_kT=1e6 > $d.log 2>&1
    echo "implicit fixed dlk=$dlk dt=$dt rc=$?" >> $O/summary.txt
  done
  for dt in ${ADAPT_DTS:-2 4.4}; do
    d=$O/imp_dlk${dlk}_adaptive$dt; [ -e $d/summary.json ] && continue; rm -rf $d
    eval $B run $cfg -o $d $common $imp --set time.dt_ns=$dt > $d.log 2>&1
    echo "implicit adaptive dlk=$dlk dt=$dt rc=$?" >> $O/summary.txt
  done
  for dt in ${EXPL_DTS:-0.22 0.25}; do
    d=$O/exp_dlk${dlk}_dt$dt; [ -e $d/summary.json ] && continue; rm -rf $d
    $B run $cfg -o $d $common --set time.t_end_us=0.5 --set time.dt_ns=$dt --set output.every_steps=100 > $d.log 2>&1
    echo "explicit dlk=$dlk dt=$dt rc=$?" >> $O/summary.txt
  done
done
