# issue 28: the mobility of the thermal ring: the slope of the centroid under a 10 pN pull with the
# noise on (docs/thermal.md "The Einstein relation in the implicit scheme"); the first 0.1 µs dropped.
#   /usr/bin/python3 thermal_pull.py tp_x1,tp_x2,tp_x3 tp_z1,tp_z2,tp_z3   (in this folder)
# PULL_PN=3 for runs pulled with 3 pN (the linear-response check; run_implicit.sh PULL_PN)
import os, sys, numpy as np
exec(open("einstein.py").read().split("px,pz=")[0])
kT = KB * 300
PULL_PN = float(os.environ.get("PULL_PN", "10"))


def slope(run, d, F=10.0 * PULL_PN, skip_us=0.1):
    t, c, _ = cen(run); k = t >= skip_us * 1e-6
    return np.polyfit(t[k], c[k, d], 1)[0] / F
xs = [slope(r, 0) for r in sys.argv[1].split(",")]
zs = [slope(r, 2) for r in sys.argv[2].split(",")]
print("x:", " ".join(f"{m:.4g}" for m in xs), " z:", " ".join(f"{m:.4g}" for m in zs))
mx, mz = np.mean(xs), np.mean(zs)
ex, ez = np.std(xs, ddof=1) / np.sqrt(len(xs)), np.std(zs, ddof=1) / np.sqrt(len(zs))
mu = (mx + mx + mz) / 3
emu = np.sqrt(4 * ex**2 + ez**2) / 3
print(f"thermal M_x {mx:.4g} ± {ex:.2g}, M_z {mz:.4g} ± {ez:.2g} s/g; (2 M_x + M_z)/3 = {mu:.4g} ± {emu:.2g}; "
      f"kT μ = {kT * mu * 1e-9:.4g} ± {kT * emu * 1e-9:.2g} Å²/ns")
allm = xs + zs
print(f"all {len(allm)} runs pooled (the thermal ring turns): {np.mean(allm):.4g} ± {np.std(allm, ddof=1)/np.sqrt(len(allm)):.2g} s/g")
