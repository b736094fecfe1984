#!/usr/bin/env python3
"""Issue 28: the linear model with the full Hessian H in the filter (docs/thermal.md, "The
geometric stiffness in the filter"): B = I - dt A M H with A = (I + dt M_loc F)^-1, F = K_GN or H;
its largest |eigenvalues| on range(K_GN) and, where it is stable, the stationary energies of
candidates A and D (f_K ~ N(0, kT K_GN)) against equipartition.

    /usr/bin/python3 prototypes/thermal_implicit/hfilter.py DIR 1 2
"""
import sys
import numpy as np
from scipy.linalg import eigh, solve_discrete_lyapunov
d = sys.argv[1]
n, ds, kT, mt, mr = np.loadtxt(f"{d}/info.txt"); n = int(n); N = 6 * n
L = lambda s: np.fromfile(f"{d}/{s}.bin").reshape(N, N, order="F")
M = L("M"); M = .5 * (M + M.T); Ml = L("Mloc"); Ml = .5 * (Ml + Ml.T)
parts = {p: L("K_" + p) for p in ("stretch", "bend", "twist")}
K = sum(parts.values())
H = L("H"); H = .5 * (H + H.T)
I = np.eye(N)
w, V = eigh(K); keep = w > 1e-8 * w.max(); Vr = V[:, keep]
terms = {"stretch": 3 * n, "bend": 2 * n, "twist": n}
for dt_ns in [float(x) for x in sys.argv[2:]]:
    dt = dt_ns * 1e-9
    for filt in ("K", "H"):
        F = K if filt == "K" else H
        A = np.linalg.inv(I + dt * Ml @ F)
        B = I - dt * A @ M @ H
        Br = Vr.T @ B @ Vr
        ev = np.linalg.eigvals(Br)
        i = np.argsort(-np.abs(ev))[:3]
        line = f"dt {dt_ns} filter {filt}, true H: |eig B| top {np.round(ev[i].real, 3)}"
        if np.max(np.abs(ev)) < 1:
            for nm, Q in (("A", A @ (2 * kT * dt * M) @ A.T), ("D", A @ (2 * kT * dt * M + kT * dt**2 * M @ K @ M) @ A.T)):
                Qr = Vr.T @ Q @ Vr
                C = Vr @ solve_discrete_lyapunov(Br, .5 * (Qr + Qr.T)) @ Vr.T
                line += f"   {nm}: " + " ".join(f"{p} {0.5*np.trace(parts[p]@C)/(0.5*terms[p]*kT):.3f}" for p in parts)
        print(line)
