#!/usr/bin/env python3
"""Issue 28, part 2: which noise makes the IMEX velocity-form step sample exp(-E/kT)?

A linear (Gaussian) model on which the stationary covariance of each candidate is exact (a
discrete Lyapunov equation, no sampling error): a closed chain of n points threading a periodic
N^3 box (spacing ds = L/n, below the grid spacing h as in the reference), the dense IB mobility
M = J (-mu L_h)^-1 P S of Peskin's 4-point kernel (the code's symbols: central-difference
gradient, 7-point Laplacian, k = 0 dropped), a quadratic energy E = q^T K q / 2 (stretch springs
ks/ds, bending kb/ds^3, a weak tether so that K is positive definite) and a local mobility
M_loc: the diagonal beta m_t I (m_t the kernel's self mobility, `self:beta`) or the kernel overlap
beta D O D (`overlap:beta`; O = J S, spreading then interpolation without the fluid solve, D
scaling the self blocks to beta m_t, as integrate/local_mobility.hpp; translations only here).
One step of each candidate is q' = B q + noise, noise ~ N(0, Q);
the stationary C solves C = B C B^T + Q and Gibbs is C = kT K^-1. Per mode of K (K v = lam v) the
ratio lam <(v.q)^2>/kT is 1 at equipartition.

    /usr/bin/python3 prototypes/thermal_implicit/imex_noise.py [--mloc self:8 overlap:1] [--sample]
        [--modes]   (--modes: every mode's ratio, stiffest first, for each candidate)
"""
import argparse
import numpy as np
from scipy.linalg import solve_discrete_lyapunov, sqrtm, eigh


def phi(r):
    r = np.abs(r)
    out = np.zeros_like(r)
    a = r <= 1
    out[a] = (3 - 2 * r[a] + np.sqrt(1 + 4 * r[a] - 4 * r[a] ** 2)) / 8
    b = (r > 1) & (r <= 2)
    out[b] = (5 - 2 * r[b] - np.sqrt(-7 + 12 * r[b] - 4 * r[b] ** 2)) / 8
    return out


def kernel_weights(x, N, h):
    """the 4x4x4 stencil of point x: indices and weights (sum 1)"""
    idx, w = [], []
    for d in range(3):
        i0 = int(np.floor(x[d] / h)) - 1
        ii = np.arange(i0, i0 + 4)
        idx.append(ii % N)
        w.append(phi(ii - x[d] / h))
    return idx, w


def overlap(X, N, h):
    """dense 3n x 3n O = J S without the fluid solve (translations): O_kl = h^3 sum_x d_k d_l I,
    d_k = delta_c(x - X_k) (integrate/local_mobility.cpp's FF block)"""
    n = len(X)
    w1 = np.zeros((n, 3, N))
    for k, x in enumerate(X):
        idx, w = kernel_weights(x, N, h)
        for d in range(3):
            np.add.at(w1[k, d], idx[d], w[d])
    O1 = np.ones((n, n))
    for d in range(3):
        O1 *= w1[:, d, :] @ w1[:, d, :].T
    return np.kron(O1 / h**3, np.eye(3))


def mobility(X, N, h, mu):
    """dense 3n x 3n M = J (-mu L_h)^-1 P S (point forces -> point velocities)"""
    n = len(X)
    k = np.fft.fftfreq(N) * N
    kx, ky, kz = np.meshgrid(k, k, k, indexing="ij")
    g = [np.sin(2 * np.pi * kk / N) / h for kk in (kx, ky, kz)]
    lam = (4 / h**2) * (np.sin(np.pi * kx / N) ** 2 + np.sin(np.pi * ky / N) ** 2
                        + np.sin(np.pi * kz / N) ** 2)
    g2 = g[0] ** 2 + g[1] ** 2 + g[2] ** 2
    lam[0, 0, 0] = 1.0
    W = [kernel_weights(x, N, h) for x in X]
    M = np.zeros((3 * n, 3 * n))
    for l in range(n):
        (ix, iy, iz), (wx, wy, wz) = W[l]
        w3 = wx[:, None, None] * wy[None, :, None] * wz[None, None, :] / h**3
        for j in range(3):
            f = np.zeros((3, N, N, N))
            f[j][np.ix_(ix, iy, iz)] += w3
            fh = np.fft.fftn(f, axes=(1, 2, 3))
            dot = sum(g[c] * fh[c] for c in range(3))
            uh = np.empty_like(fh)
            for c in range(3):
                proj = fh[c] - np.where(g2 > 0, g[c] * dot / np.where(g2 > 0, g2, 1), 0)
                uh[c] = proj / (mu * lam)
                uh[c][0, 0, 0] = 0
            u = np.real(np.fft.ifftn(uh, axes=(1, 2, 3)))
            for k_ in range(n):
                (jx, jy, jz), (vx, vy, vz) = W[k_]
                w3k = vx[:, None, None] * vy[None, :, None] * vz[None, None, :]
                for c in range(3):
                    M[3 * k_ + c, 3 * l + j] = np.sum(u[c][np.ix_(jx, jy, jz)] * w3k)
    return 0.5 * (M + M.T)


def stiffness(n, ds, ks, kb, tether):
    """K of E = sum ks/(2ds) |X_k+1 - X_k - ds e|^2 (linearised: all components, i.e. stretch and
    a shear-like transverse spring) + kb/(2ds^3) |X_k+1 - 2X_k + X_k-1|^2 + tether/2 |X|^2"""
    D1 = np.zeros((n, n))
    D2 = np.zeros((n, n))
    for k in range(n):
        D1[k, k], D1[k, (k + 1) % n] = -1, 1
        D2[k, (k - 1) % n], D2[k, k], D2[k, (k + 1) % n] = 1, -2, 1
    K1 = ks / ds * D1.T @ D1 + kb / ds**3 * D2.T @ D2 + tether * np.eye(n)
    return np.kron(K1, np.eye(3))


def psd_sqrt(Q):
    w, V = eigh(0.5 * (Q + Q.T))
    return V @ np.diag(np.sqrt(np.clip(w, 0, None))) @ V.T


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--N", type=int, default=12)
    ap.add_argument("--n", type=int, default=24)
    ap.add_argument("--mloc", nargs="+", default=["self:1", "self:8", "overlap:1"],
                    help="local mobilities, KIND:beta with KIND self (beta m_t I) or overlap (beta D O D)")
    ap.add_argument("--fracs", type=float, nargs="+", default=[0.25, 1.0, 4.0, 10.0])
    ap.add_argument("--band", type=int, nargs="*", default=[2, 6, 12])
    ap.add_argument("--eps", type=float, default=1e-2)
    ap.add_argument("--eps-loc", action="store_true",
                    help="add the free-draining eps m_t I to the overlap M_loc too (its part of M is known)")
    ap.add_argument("--dir", type=int, nargs=3, default=[1, 0, 0],
                    help="the chain's direction in box lengths (1 0 0: along a grid line, where S has a "
                         "null space of 13 force patterns per component; 1 1 0: generic, M and O definite)")
    ap.add_argument("--modes", action="store_true", help="print every mode's ratio")
    ap.add_argument("--sample", action="store_true", help="also sample one scheme (checks the Lyapunov solution)")
    a = ap.parse_args()
    N, h, mu, kT = a.N, 1.0, 1.0, 1.0
    L = N * h
    n = a.n
    d = np.array(a.dir, dtype=float)
    ds = L * np.linalg.norm(d) / n
    X = np.array([(k / n) * L * d + np.array([0.3 * h, 0.37 * L, 0.61 * L]) for k in range(n)]) % L
    M = mobility(X, N, h, mu)
    mt = np.mean(np.diag(M))
    # the code's scaling of the overlap (ImplicitStepper's constructor): the self mobility and the
    # overlap's self block of one point at the generic position x0 = (0.31, 0.57, 0.73) h
    x0 = np.array([[0.31, 0.57, 0.73]]) * h
    mt0 = mobility(x0, N, h, mu)[0, 0]
    Ov = overlap(X, N, h)
    ov2 = mt0 / overlap(x0, N, h)[0, 0]
    # the IB mobility of points closer than h is near singular (force patterns the kernel does not
    # spread); a free-draining part eps m_t keeps every mode relaxing (reported: eps)
    M = M + a.eps * mt * np.eye(3 * n)
    K = stiffness(n, ds, ks=1.0, kb=0.2 * ds**2, tether=1e-3)  # isotropic: the direction is free
    lam, V = eigh(K)
    # the explicit limit of forward Euler on this problem: dt M K < 2 on every mode
    rho = np.max(np.real(np.linalg.eigvals(M @ K)))
    dt_lim = 2 / rho
    Mv = np.einsum("ij,jk,ki->i", V.T, M, V)  # v^T M v per mode
    print(f"N={N} n={n} dir={a.dir} ds={ds:.3f}h eps={a.eps:g}{' (also in the overlap)' if a.eps_loc else ''}  m_t={mt:.4g} (at x0 {mt0:.4g})  explicit limit dt={dt_lim:.4g}  "
          f"vMv/m_t per mode: stiffest {Mv[-1]/mt:.3g}, softest {Mv[0]/mt:.3g}")
    I = np.eye(3 * n)

    def stationary(B, Q):
        if np.max(np.abs(np.linalg.eigvals(B))) >= 1 - 1e-12:
            return None
        return solve_discrete_lyapunov(B, 0.5 * (Q + Q.T))

    def report(name, C, x, r):
        """<E>/equipartition over all modes, and the mean (min-max) per-mode ratio of the soft
        (x <= 0.5), mid and stiff (x > 10) modes, x = dt lam v^T M_loc v the filter's stiffness"""
        if C is None:
            return f"{name:44s} unstable", None
        e = lam * np.einsum("ij,jk,ki->i", V.T, C, V) / kT
        Eratio = 0.5 * np.trace(K @ C) / (0.5 * 3 * n * kT)
        groups = [("soft", x <= 0.5), ("mid", (x > 0.5) & (x <= 10)), ("stiff", x > 10)]
        f = lambda m: (f"{e[m].mean():.3f} ({e[m].min():.3f}-{e[m].max():.3f})" if m.any() else "-")
        txt = f"{name:44s} <E>/equip {Eratio:.3f} modes {e.min():.3f}-{e.max():.3f}  " + "  ".join(f"{g} {f(m)}" for g, m in groups)
        if (x > 10).any():
            txt += f"  [stiff r {r[x > 10].min():.2f}-{r[x > 10].max():.2f}]"
        return txt, e

    for frac in a.fracs:
        dt = frac * dt_lim
        print(f"\n== dt = {frac:g} x the explicit limit ==")
        B = I - dt * M @ K
        print(report("explicit Euler-Maruyama", stationary(B, 2 * kT * dt * M), dt * mt * lam, Mv / mt)[0])
        for spec in a.mloc:
            kind, beta = spec.split(":")
            beta = float(beta)
            Ml = beta * mt * I if kind == "self" else beta * ov2 * Ov + (a.eps * mt * I if a.eps_loc else 0)
            Mlv = np.einsum("ij,jk,ki->i", V.T, Ml, V)
            x = dt * Mlv * lam
            r = Mv / np.maximum(Mlv, 1e-300)
            A = np.linalg.inv(I + dt * Ml @ K)
            B = I - dt * A @ M @ K
            cands = {
                "A: noise through the filter A": A @ (2 * kT * dt * M) @ A.T,
                "B: noise past the filter": 2 * kT * dt * M,
                "C: filter + thermal force kT K via M_loc": A @ (2 * kT * dt * M + kT * dt**2 * Ml @ K @ Ml) @ A.T,
                "D: filter + thermal force kT K via M (Stokes)": A @ (2 * kT * dt * M + kT * dt**2 * M @ K @ M) @ A.T,
                "G: thermal force via (M + M_loc)/2": A @ (2 * kT * dt * M + kT * dt**2 * (M + Ml) @ K @ (M + Ml) / 4) @ A.T,
                "E: exact Q = kT(dt(AM+MA^T) - dt^2 AMKMA^T)": kT * (dt * (A @ M + M @ A.T) - dt**2 * A @ M @ K @ M @ A.T),
            }
            print(f"-- IMEX velocity form, M_loc {kind} beta = {beta:g} (x = dt lam vM_loc v up to {x.max():.3g}; "
                  f"r = vMv/vM_loc v on modes {r.min():.3g}-{r.max():.3g})")
            for name, Q in cands.items():
                txt, e = report(name, stationary(B, Q), x, r)
                print(txt)
                if a.modes and e is not None:
                    order = np.argsort(-lam)
                    print("   per mode (stiffest first; lam, x, r, ratio): " + "; ".join(
                        f"{lam[i]:.3g} {x[i]:.3g} {r[i]:.2f} {e[i]:.3f}" for i in order))
            # the theta = 1/2 local filter (trapezoidal), noise through it
            Ah = np.linalg.inv(I + 0.5 * dt * Ml @ K)
            Bh = I - dt * Ah @ M @ K
            print(report("F: theta=1/2 filter, noise through it", stationary(Bh, Ah @ (2 * kT * dt * M) @ Ah.T), x, r)[0])
            if kind == "self" and beta == 8:
                # a banded pair mobility as M_loc (M itself within |k - l| <= w points): r ~ 1 on
                # the stiff modes, the filter and the thermal force of C through it
                for w in a.band:
                    idx = np.arange(n)
                    dist = np.abs(idx[:, None] - idx[None, :])
                    dist = np.minimum(dist, n - dist)
                    Mb = M * np.kron((dist <= w).astype(float), np.ones((3, 3)))
                    Ab = np.linalg.inv(I + dt * Mb @ K)
                    Bb = I - dt * Ab @ M @ K
                    Qb = Ab @ (2 * kT * dt * M + kT * dt**2 * Mb @ K @ Mb) @ Ab.T
                    print(report(f"C, M_loc = M banded |k-l| <= {w}", stationary(Bb, Qb), x, r)[0])
            if a.sample and spec == a.mloc[-1] and frac == a.fracs[-1]:
                rng = np.random.default_rng(1)
                Q = cands["C: filter + thermal force kT K via M_loc"]
                S = psd_sqrt(Q)
                q = np.zeros(3 * n)
                acc = np.zeros(3 * n)
                steps, burn = 40000, 4000
                for i in range(steps):
                    q = B @ q + S @ rng.standard_normal(3 * n)
                    if i >= burn:
                        acc += (V.T @ q) ** 2
                e = lam * acc / (steps - burn) / kT
                print(f"   sampled C ({steps - burn} steps): <E>/equip {e.mean():.3f}, stiff {e[x > 10].mean():.3f}")


if __name__ == "__main__":
    main()
