#!/bin/bash
# issue 28: Einstein relation at 32^3, 725 A box, dt 0.1 ns; drift on/off paired by seed
B=../../build/app/ibrod
C="--set grid.n=32 --set grid.box_A=725"
nice -n 5 $B run ring.toml -o p32_x $C --set solvent.thermal=false --set 'external.force_pN=[1,0,0]' --set time.t_end_us=0.03 --set output.frame_every_steps=20 >/dev/null
nice -n 5 $B run ring.toml -o p32_z $C --set solvent.thermal=false --set 'external.force_pN=[0,0,1]' --set time.t_end_us=0.03 --set output.frame_every_steps=20 >/dev/null
for s in 1 2; do
 for d in true false; do
  nice -n 5 $B run ring.toml -o t32_${d}_s$s $C --set run.seed=$s --set solvent.thermal_drift=$d --set time.t_end_us=${T:-8} --set output.every_steps=100 --set output.frame_every_steps=10 | tail -1
 done
done
