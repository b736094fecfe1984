#!/usr/bin/env python3
"""Issue 28: the geometric stiffness at a thermal state (docs/thermal.md, "The geometric stiffness
in the filter"). From dump_linear's matrices at a state (M, M_loc, K_GN by parts, the full Hessian
H): the extreme eigenvalues of H and K, of K^-1 H on range(K), and, per dt (ns), the largest
|eigenvalues| of the deterministic map B = I - dt A M X, A = (I + dt M_loc K_GN)^-1, with X = K_GN
(the linear model's assumption) and X = H (the ring's own forces).

    /usr/bin/python3 prototypes/thermal_implicit/linear_hessian.py DIR 0.5 1 2
"""
import sys
import numpy as np
from scipy.linalg import eigh
d = sys.argv[1]
n, ds, kT, mt, mr = np.loadtxt(f"{d}/info.txt"); n = int(n); N = 6 * n
L = lambda s: np.fromfile(f"{d}/{s}.bin").reshape(N, N, order="F")
M = L("M"); M = .5 * (M + M.T); Ml = L("Mloc")
K = L("K_stretch") + L("K_bend") + L("K_twist")
H = L("H"); H = .5 * (H + H.T)
I = np.eye(N)
lh = np.linalg.eigvalsh(H); lk = np.linalg.eigvalsh(K)
print("H eig: min", lh[:4], "max", lh[-2:], " K eig max", lk[-2:])
# generalized: H v = mu K v on range K
w, V = eigh(K); keep = w > 1e-8 * w.max(); Vr = V[:, keep]
Kr = Vr.T @ K @ Vr; Hr = Vr.T @ H @ Vr
mu = np.sort(np.real(np.linalg.eigvals(np.linalg.solve(Kr, Hr))))
print("eig of K^-1 H on range K: min", mu[:3], "max", mu[-3:])
for dt_ns in [float(x) for x in sys.argv[2:]]:
    dt = dt_ns * 1e-9
    A = np.linalg.inv(I + dt * Ml @ K)
    for nm, HH in (("K", K), ("H", H)):
        ev = np.linalg.eigvals(I - dt * A @ M @ HH)
        i = np.argsort(-np.abs(ev))[:4]
        print(f"dt {dt_ns} B with {nm}: largest |eig|", np.round(ev[i], 4))
