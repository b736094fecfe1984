#!/usr/bin/env python3
"""Issue 28: the stationary covariance of the implicit thermal step on a real ring, linearised
at its circle (docs/thermal.md, "The implicit step with noise"). Reads dump_linear's matrices
(M the Stokes mobility, M_loc the overlap, K = K_stretch + K_bend + K_twist, all 6n x 6n) and,
per noise candidate and dt, solves C = B C B^T + Q on the range of K (its null space, the rigid
motions, is a random walk that carries no energy) and reports each energy part
<E_part> = tr(K_part C)/2 against equipartition (3, 2, 1 quadratic terms per link).

    build/prototypes/thermal_implicit/dump_linear prototypes/thermal/ring.toml DIR \\
        time.scheme='"implicit"' time.implicit_local_mobility='"overlap"'
    /usr/bin/python3 prototypes/thermal_implicit/linear_ring.py DIR --dt-ns 0.1 0.25 1 2
"""
import argparse
import numpy as np
from scipy.linalg import solve_discrete_lyapunov, eigh


def load(d, name, N):
    return np.fromfile(f"{d}/{name}.bin").reshape(N, N, order="F")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--dt-ns", type=float, nargs="+", default=[0.1, 0.25, 1, 2])
    ap.add_argument("--cands", nargs="+", default=["A", "C", "D", "G", "exact"])
    ap.add_argument("--hessian", action="store_true",
                    help="the deterministic step and the energy with the full Hessian H (H.bin) "
                         "in place of the Gauss-Newton K (the filter and f_K keep K)")
    ap.add_argument("--onestep", type=float, default=0,
                    help="dt (ns) of dump_linear's onestep.bin: its sample covariance against Q")
    a = ap.parse_args()
    n, ds, kT, mt, mr = np.loadtxt(f"{a.dir}/info.txt")
    n = int(n)
    N = 6 * n
    M = load(a.dir, "M", N)
    M = 0.5 * (M + M.T)
    Ml = load(a.dir, "Mloc", N)
    parts = {p: load(a.dir, "K_" + p, N) for p in ("stretch", "bend", "twist")}
    terms = {"stretch": 3 * n, "bend": 2 * n, "twist": n}
    K = sum(parts.values())
    lam, V = eigh(K)
    keep = lam > 1e-8 * lam.max()
    Vr = V[:, keep]
    print(f"n={n}: K rank {keep.sum()} of {N}; M eig/m_t {np.linalg.eigvalsh(M)[[0, -1]] / mt}")
    # the explicit limit: largest real eigenvalue of M K
    rho = np.max(np.real(np.linalg.eigvals(M @ K)))
    print(f"explicit (Euler) limit: {2 / rho * 1e9:.3f} ns")
    I = np.eye(N)
    if a.onestep > 0:
        dt = a.onestep * 1e-9
        S = np.fromfile(f"{a.dir}/onestep.bin").reshape(N, -1, order="F") * dt
        S = S - S.mean(axis=1, keepdims=True)
        Sig = S @ S.T / (S.shape[1] - 1)
        A = np.linalg.inv(I + dt * Ml @ K)
        for c, Q in {"A": A @ (2 * kT * dt * M) @ A.T,
                     "C": A @ (2 * kT * dt * M + kT * dt**2 * Ml @ K @ Ml) @ A.T,
                     "D": A @ (2 * kT * dt * M + kT * dt**2 * M @ K @ M) @ A.T,
                     "G": A @ (2 * kT * dt * M + kT * dt**2 * (M + Ml) @ K @ (M + Ml) / 4) @ A.T}.items():
            t = np.arange(N) % 6 < 3
            out = "  ".join(f"{p} {np.trace(parts[p] @ Sig) / np.trace(parts[p] @ Q):.3f}" for p in parts)
            print(f"one-step sample ({S.shape[1]}) / model {c}: tr(K .) {np.trace(K @ Sig) / np.trace(K @ Q):.3f}  {out}"
                  f"  translations {np.trace(Sig[np.ix_(t, t)]) / np.trace(Q[np.ix_(t, t)]):.3f}"
                  f"  rotations {np.trace(Sig[np.ix_(~t, ~t)]) / np.trace(Q[np.ix_(~t, ~t)]):.3f}")
        return
    for dt_ns in a.dt_ns:
        dt = dt_ns * 1e-9
        A = np.linalg.inv(I + dt * Ml @ K)
        H = 0.5 * (load(a.dir, "H", N) + load(a.dir, "H", N).T) if a.hessian else K
        B = I - dt * A @ M @ H
        Br = Vr.T @ B @ Vr
        rad = np.max(np.abs(np.linalg.eigvals(Br)))
        cands = {
            "A": A @ (2 * kT * dt * M) @ A.T,
            "C": A @ (2 * kT * dt * M + kT * dt**2 * Ml @ K @ Ml) @ A.T,
            "D": A @ (2 * kT * dt * M + kT * dt**2 * M @ K @ M) @ A.T,
            "G": A @ (2 * kT * dt * M + kT * dt**2 * (M + Ml) @ K @ (M + Ml) / 4) @ A.T,
            "exact": kT * (dt * (A @ M + M @ A.T) - dt**2 * A @ M @ K @ M @ A.T),
        }
        print(f"\n== dt = {dt_ns:g} ns ({dt_ns / (2 / rho * 1e9):.2f} x the explicit limit), "
              f"spectral radius of B on range(K) {rad:.4f}")
        for c in a.cands:
            if rad >= 1:
                print(f"{c:6s} unstable")
                continue
            Q = Vr.T @ cands[c] @ Vr
            Cr = solve_discrete_lyapunov(Br, 0.5 * (Q + Q.T))
            C = Vr @ Cr @ Vr.T
            out = "  ".join(f"{p} {0.5 * np.trace(parts[p] @ C) / (0.5 * terms[p] * kT):.3f}"
                            for p in parts)
            tot = 0.5 * np.trace(H @ C) / (0.5 * keep.sum() * kT)
            print(f"{c:6s} total {tot:.3f}  {out}")


if __name__ == "__main__":
    main()
