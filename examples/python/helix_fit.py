#!/usr/bin/env python3
"""Fit a helix to a rod's centreline: axis, radius, pitch, handedness (examples/helix.toml).

An open rod with intrinsic curvature κ0 and intrinsic twist τ0 relaxes to the helix of curvature
κ0 and torsion τ0: radius κ0/(κ0² + τ0²), pitch 2π τ0/(κ0² + τ0²) (right-handed for τ0 > 0).
The fit does not care where the rod went or how it turned (a free rod translates and rotates):

  1. the axis a: a helix's unit tangents lie on a cone about a, so a is the direction in which the
     (centred) tangents vary least — the eigenvector of the smallest eigenvalue of their
     covariance;
  2. the radius: the points projected on the plane ⟂ a lie on a circle, fitted by linear least
     squares (|p − c|² = r², the Kåsa fit);
  3. the pitch: the height along a against the unwrapped angle about c, fitted by a straight
     line: pitch = 2π dh/dφ; its sign is the handedness (+ right-handed).

`trim` points are dropped at each end (0: all).

    /usr/bin/python3 examples/python/helix_fit.py RUN_DIR [KAPPA0 TAU0]

reads RUN_DIR/final_state.csv and prints the fit (and, given κ0 and τ0 in rad/Å, the closed-form
radius and pitch and the relative differences).
"""
import os
import sys

import numpy as np


def fit_helix(X, trim=0):
    """X: (n, 3) positions, Å. Returns dict axis (3,), center (3,) (a point on the axis),
    radius (Å), pitch (Å, signed: + right-handed), turns, rms_radial (Å, the rms distance of the
    points from the fitted cylinder)."""
    X = np.asarray(X, dtype=float)
    if trim > 0:
        X = X[trim:-trim]
    if len(X) < 8:
        raise ValueError(f"fit_helix: {len(X)} points; at least 8 are needed")
    t = np.diff(X, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    w, v = np.linalg.eigh(np.cov(t.T))
    a = v[:, 0]
    if np.dot(X[-1] - X[0], a) < 0:  # the axis points from the first end to the last
        a = -a
    # an orthonormal basis (e1, e2, a) of space
    e1 = np.cross(a, [1.0, 0.0, 0.0])
    if np.linalg.norm(e1) < 0.5:
        e1 = np.cross(a, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    p = np.stack([X @ e1, X @ e2], axis=1)
    h = X @ a
    # Kåsa: x² + y² = 2 cx x + 2 cy y + (r² − c²)
    A = np.column_stack([2 * p[:, 0], 2 * p[:, 1], np.ones(len(p))])
    sol, *_ = np.linalg.lstsq(A, (p ** 2).sum(axis=1), rcond=None)
    c = sol[:2]
    r = float(np.sqrt(sol[2] + c @ c))
    phi = np.unwrap(np.arctan2(p[:, 1] - c[1], p[:, 0] - c[0]))
    slope = np.polyfit(phi, h, 1)[0]  # dh/dφ, φ counter-clockwise about a
    rho = np.linalg.norm(p - c, axis=1)
    return {
        "axis": a,
        "center": c[0] * e1 + c[1] * e2,
        "radius": r,
        "pitch": float(2 * np.pi * slope),
        "turns": float(abs(phi[-1] - phi[0]) / (2 * np.pi)),
        "rms_radial": float(np.sqrt(np.mean((rho - r) ** 2))),
    }


def helix_closed_form(kappa0, tau0):
    """(radius, pitch) in Å of the helix of curvature κ0 and torsion τ0 (rad/Å)."""
    w2 = kappa0 ** 2 + tau0 ** 2
    return kappa0 / w2, 2 * np.pi * tau0 / w2


def read_final_state(run_dir):
    """(n, 3) positions of RUN_DIR/final_state.csv, Å."""
    a = np.genfromtxt(os.path.join(run_dir, "final_state.csv"), delimiter=",", names=True)
    return np.stack([a["x_A"], a["y_A"], a["z_A"]], axis=1)


def main(argv):
    if len(argv) not in (2, 4):
        print(__doc__)
        return 2
    f = fit_helix(read_final_state(argv[1]))
    print(f"radius = {f['radius']:.3f} Å, pitch = {f['pitch']:.3f} Å "
          f"({'right' if f['pitch'] > 0 else 'left'}-handed), turns = {f['turns']:.2f}, "
          f"rms off the cylinder = {f['rms_radial']:.3f} Å")
    if len(argv) == 4:
        r0, p0 = helix_closed_form(float(argv[2]), float(argv[3]))
        print(f"closed form: radius = {r0:.3f} Å, pitch = {p0:.3f} Å; "
              f"differences {f['radius'] / r0 - 1:+.2%} and {f['pitch'] / p0 - 1:+.2%}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
