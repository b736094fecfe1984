# D(τ)/(kT μ) pooled over runs: non-overlapping windows of every run, mean and standard error
# over the windows (the first 0.1 µs of each run dropped); μ = (2 M_x + M_z)/3 from the pulls
import sys, numpy as np
exec(open("einstein.py").read().split("px,pz=")[0])
px, pz, lags = sys.argv[1], sys.argv[2], [int(x) for x in sys.argv[3].split(",")]
mx, mz = mob(px, 0), mob(pz, 2); kT = KB * 300; Dp = kT * (2 * mx + mz) / 3 * 1e-9
print(f"pulled: M_x {mx:.4g} M_z {mz:.4g} s/g, kT μ = {Dp:.4g} Å²/ns")
runs = sys.argv[4:]
out = []
for lag in lags:
    s = []
    for run in runs:
        t, c, _ = cen(run); dt = t[1] - t[0]; c = c[int(round(1e-7 / dt)):]
        m = (len(c) - 1) // lag
        dc = c[lag:m * lag + 1:lag] - c[0:(m - 1) * lag + 1:lag]
        s.extend((dc**2).sum(1) / (6 * lag * dt) * 1e-9 / Dp)
    s = np.array(s)
    out.append(f"{lag * dt * 1e9:g} ns: {s.mean():.3f} ± {s.std(ddof=1) / np.sqrt(len(s)):.3f}")
print(" | ".join(out))
