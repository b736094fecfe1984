"""The Stokes mobility M of the IB coupling against the local mobilities, on Fourier modes of a
straight periodic line of points (issue 24, docs/large_dt.md "A local mobility with the kernel's
null space"). Peskin's 4-point kernel, h = 1, mu = 1, points 0.3 h apart (the reference: 3.4 Å
at h = 11.33 Å), a 32³ grid; the Stokes solve is the discrete one of the code (7-point Laplacian,
central-difference projection), so M here is the code's operator up to its Navier-Stokes parts.

    python3 prototypes/large_dt/mobility_spectrum.py [out.png]

Prints, per wavenumber q (in units of pi/ds), M/m_t for transverse and longitudinal forces, the
kernel overlap O = J S (no fluid) scaled to the same self mobility, and the ratio r = M/M_loc for
the diagonal M_loc = 8 m_t and for the overlap M_loc = m_t O/O_self; then the same for torques
(twist and bend). Takes ~10 s."""
import sys

import numpy as np


def phi4(r):
    r = np.abs(r)
    out = np.zeros_like(r)
    a = r < 1
    b = (r >= 1) & (r < 2)
    out[a] = (3 - 2 * r[a] + np.sqrt(1 + 4 * r[a] - 4 * r[a] ** 2)) / 8
    out[b] = (5 - 2 * r[b] - np.sqrt(-7 + 12 * r[b] - 4 * r[b] ** 2)) / 8
    return out


n = 32
N = int(round(n / 0.3))
ds = n / N
y0, z0 = 10.37, 15.61
xs = np.arange(N) * ds + 0.123
g = np.arange(n)
wx = np.array([phi4(((g - x + n / 2) % n) - n / 2) for x in xs])
wy = phi4(((g - y0 + n / 2) % n) - n / 2)
wz = phi4(((g - z0 + n / 2) % n) - n / 2)
k1 = 2 * np.pi * np.fft.fftfreq(n)
KX, KY, KZ = np.meshgrid(k1, k1, k1, indexing="ij")
DX, DY, DZ = 1j * np.sin(KX), 1j * np.sin(KY), 1j * np.sin(KZ)
L = -(2 - 2 * np.cos(KX)) - (2 - 2 * np.cos(KY)) - (2 - 2 * np.cos(KZ))
L[0, 0, 0] = 1
D2 = (DX * np.conj(DX) + DY * np.conj(DY) + DZ * np.conj(DZ)).real
D2[0, 0, 0] = 1


def stencil(k):
    w = np.einsum("i,j,l->ijl", wx[k], wy, wz)
    grad = np.array([(np.roll(w, -1, a) - np.roll(w, 1, a)) / 2 for a in range(3)])
    return w, grad


ST = [stencil(k) for k in range(N)]


def stokes(f):
    fh = [np.fft.fftn(f[d]) for d in range(3)]
    div = (np.conj(DX) * fh[0] + np.conj(DY) * fh[1] + np.conj(DZ) * fh[2]) / D2
    uh = [(fh[0] - DX * div) / (-L), (fh[1] - DY * div) / (-L), (fh[2] - DZ * div) / (-L)]
    for d in range(3):
        uh[d][0, 0, 0] = 0
    return np.array([np.real(np.fft.ifftn(uh[d])) for d in range(3)])


def spread(F, T):
    f = np.zeros((3, n, n, n))
    for k in range(N):
        w, gr = ST[k]
        f += F[k][:, None, None, None] * w
        f += 0.5 * np.cross(gr, T[k][:, None, None, None], axis=0)
    return f


def interp(u):
    U, W = np.zeros((N, 3)), np.zeros((N, 3))
    for k in range(N):
        w, gr = ST[k]
        U[k] = np.sum(u * w, axis=(1, 2, 3))
        W[k] = 0.5 * np.sum(np.cross(u, gr, axis=0), axis=(1, 2, 3))
    return U, W


def apply(F, T, fluid):
    f = spread(F, T)
    return interp(stokes(f) if fluid else f)


Z = np.zeros((N, 3))
e = np.zeros((N, 3))
e[0, 1] = 1
m_t = apply(e, Z, True)[0][0, 1]
o_t = apply(e, Z, False)[0][0, 1]
m_r = apply(Z, e, True)[1][0, 1]
o_r = apply(Z, e, False)[1][0, 1]
s = np.arange(N) * ds
rows = []
for m in [1, 2, 4, 6, 8, 10, 12, 14, 16, 20, 24, 30, 40, 53]:
    c = np.cos(2 * np.pi * m * s / n)
    out = [2 * m / N]
    for comp, torque in [(1, False), (0, False), (0, True), (1, True)]:
        G = np.zeros((N, 3))
        G[:, comp] = c
        args = (Z, G) if torque else (G, Z)
        idx = 1 if torque else 0
        mm = apply(*args, True)[idx][:, comp] @ c / (c @ c) / (m_r if torque else m_t)
        oo = apply(*args, False)[idx][:, comp] @ c / (c @ c) / (o_r if torque else o_t)
        out += [mm, oo]
    rows.append(out)
rows = np.array(rows)
print(f"# N = {N} points, ds = {ds:.3f} h; self mobilities m_t = {m_t:.4g}, m_r = {m_r:.4g}")
print("# q ds/pi | transverse F: M/m_t O/O_self r_diag8 r_overlap | longitudinal F: same |"
      " twist T: M/m_r O/O_self | bend T: M/m_r O/O_self")
for r in rows:
    q, mp, op, ml, ol, mtw, otw, mb, ob = r
    print(f"{q:6.3f} | {mp:8.4f} {op:8.4f} {mp/8:8.4f} {mp/max(op,1e-30):8.3f} |"
          f" {ml:8.4f} {ol:8.4f} {ml/8:8.4f} {ml/max(ol,1e-30):8.3f} |"
          f" {mtw:8.4f} {otw:8.4f} | {mb:8.4f} {ob:8.4f}")
if len(sys.argv) > 1:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogy(rows[:, 0], rows[:, 1], "o-", label="Stokes M, transverse force")
    ax.semilogy(rows[:, 0], rows[:, 2], "s--", label="overlap O (scaled to m_t)")
    ax.semilogy(rows[:, 0], rows[:, 5], "^-", label="Stokes M, twist torque (/m_r)")
    ax.axhline(8, color="k", lw=1, label="diagonal M_loc, beta = 8")
    ax.set_xlabel("wavenumber along the rod, q ds / pi")
    ax.set_ylabel("mobility of the mode / self mobility")
    ax.set_ylim(1e-5, 50)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(sys.argv[1], dpi=120)
