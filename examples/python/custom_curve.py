#!/usr/bin/env python3
"""A closed curve built in numpy, run by ibrod (docs/python.md).

An ellipse of 100 base pairs (axes 3:2) carrying one turn of twist (ΔLk = 1, below the
buckling threshold), on the 16³ grid of the tests: the state is built here (positions at equal
arc length, a frame that closes on itself), handed to the simulation with set_state, run for
0.2 µs and compared before and after: the linking number stays the integer it was built with,
the writhe stays near 0, the elastic energy falls as the ellipse rounds towards a circle.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/custom_curve.py [OUT_DIR]
    PYTHONPATH=build/python /usr/bin/python3 examples/python/custom_curve.py --shape coil

With OUT_DIR the run directory is written there too (read back with ibrod.read_run).

--shape coil: a non-planar curve instead, a ring wound 3 times round a torus (radii 54 and
12 Å, 100 bp), given a frame with the parallel-transport mismatch spread evenly (no turns
added), so Lk = Wr + Tw is the integer nearest the Gauss integral's writhe plus that spread. Its
writhe is computed here independently, as the Gauss double integral of the smooth curve in
numpy (4000 points), and compared with ibrod's exact polygon writhe of the 100 points at t = 0.
Then a frame with COIL_TURNS = −1 added makes Lk = −1, below the buckling threshold: the coil
unwinds into a flat ring (Wr → 0), the twist taking up the link. It prints (measured on
2026-12-02, 2 cores shared with other jobs: about 1.5 s in all, 1 s of it the numpy integral):

    steps 2000, t = 0.200 us, stop: end_time
    numpy: Wr (Gauss integral, smooth curve) -0.481022, Tw (frame) -0.522976, Wr + Tw -1.003998
    aspect ratio      1.5714 -> 1.0162
    link Lk           -1.000000 -> -1.000000
    writhe Wr         -0.477024 -> -0.000778
    elastic energy    84.173 -> 44.842 kT
    total energy      143.781 -> 101.606 kT (largest change between rows -0.004)
    wall time         0.6 s (0.318 ms/step)

ibrod's writhe at t = 0 (the exact writhe of the 100-point polygon) is 0.0040 from the smooth
curve's: the polygon's discretisation, O(Δs²); Lk stays −1 to 1e-6 and E_total (elastic,
electrostatic, steric and the fluid's kinetic energy) never rises between rows 0.01 µs apart.
tests/python/test_example.py asserts these for both shapes.
"""
import sys
import time

import numpy as np

import ibrod

N_BP = 100       # rod points (base pairs)
RISE = 3.4       # Δs, Å
EXCESS_LINK = 1  # full turns of twist added to the frame (below Michell's √3 a1/a3 ≈ 1.24)
COIL_TURNS = -1  # --shape coil: turns added to its frame (Wr ≈ −0.48, so Lk = −1)


def ellipse(n, rise, aspect=1.5):
    """n points at equal arc length on an ellipse of perimeter n·rise in the z = 0 plane."""
    t = np.linspace(0, 2 * np.pi, 20001)
    c = np.stack([aspect * np.cos(t), np.sin(t), 0 * t], axis=1)
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))])
    c *= n * rise / s[-1]  # perimeter n Δs
    s *= n * rise / s[-1]
    si = np.arange(n) * rise
    return np.stack([np.interp(si, s, c[:, i]) for i in range(3)], axis=1)


def closed_frame(X, turns, with_twist=False):
    """Triads (n, 3, 3), row i = D^(i+1): D³ along the chord to the next point, D¹ carried
    along by parallel transport, its mismatch after one round spread evenly, plus `turns` full
    turns of twist. The frame closes on itself, so Lk = Wr + Tw is an integer. with_twist: also
    return that frame's twist in turns, (mismatch + 2π turns) / 2π."""
    n = len(X)
    t = np.roll(X, -1, axis=0) - X
    t /= np.linalg.norm(t, axis=1)[:, None]

    def transport(v, a, b):  # rotate v by the rotation taking unit a to unit b
        ax = np.cross(a, b)
        s, c = np.linalg.norm(ax), np.dot(a, b)
        if s < 1e-15:
            return v
        k = ax / s
        return v * c + np.cross(k, v) * s + k * np.dot(k, v) * (1 - c)

    d1 = np.zeros((n, 3))
    d1[0] = np.cross(t[0], [0, 0, 1.0])
    d1[0] /= np.linalg.norm(d1[0])
    for k in range(1, n + 1):
        v = transport(d1[k - 1], t[k - 1], t[k % n])
        if k < n:
            d1[k] = v - np.dot(v, t[k]) * t[k]
            d1[k] /= np.linalg.norm(d1[k])
    # the angle by which the transported D¹ misses D¹(0) after one round
    v -= np.dot(v, t[0]) * t[0]
    miss = np.arctan2(np.dot(np.cross(v, d1[0]), t[0]), np.dot(v, d1[0]))
    phi = (miss + 2 * np.pi * turns) * np.arange(n) / n
    d2 = np.cross(t, d1)
    e1 = np.cos(phi)[:, None] * d1 + np.sin(phi)[:, None] * d2
    e2 = np.cross(t, e1)
    D = np.stack([e1, e2, t], axis=1)
    return (D, (miss + 2 * np.pi * turns) / (2 * np.pi)) if with_twist else D


def toroidal_coil(n, rise, R=54.0, a=12.0, q=3):
    """n points at equal arc length on the closed curve wound q times round a torus of radii R
    (centre line) and a (tube): ((R + a cos qθ) cos θ, (R + a cos qθ) sin θ, a sin qθ), scaled so
    that its length is n·rise. Non-planar and chiral: its writhe is not 0."""
    t = np.linspace(0, 2 * np.pi, 20001)
    c = coil_curve(t, R, a, q)
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))])
    c *= n * rise / s[-1]
    s *= n * rise / s[-1]
    si = np.arange(n) * rise
    return np.stack([np.interp(si, s, c[:, i]) for i in range(3)], axis=1)


def coil_curve(t, R=54.0, a=12.0, q=3):
    r = R + a * np.cos(q * t)
    return np.stack([r * np.cos(t), r * np.sin(t), a * np.sin(q * t)], axis=1)


def gauss_writhe_smooth(curve, m=2000):
    """Writhe of the smooth closed curve t -> curve(t), t in [0, 2π), by the Gauss double integral
    Wr = (1/4π) ∮∮ (r'(s) × r'(t))·(r(s) − r(t)) / |r(s) − r(t)|³ ds dt, with the trapezoidal rule
    on m equally spaced parameters (spectrally accurate for a smooth periodic integrand; the
    diagonal s = t, where the integrand tends to 0, left out). Independent of ibrod's polygon
    formula (signed solid angles of segment pairs)."""
    t = np.arange(m) * 2 * np.pi / m
    h = 1e-4  # the derivative by central differences of the closed form (error ~h²)
    r = curve(t)
    dr = (curve(t + h) - curve(t - h)) / (2 * h)
    total = 0.0
    for i0 in range(0, m, 250):
        ri, di = r[i0:i0 + 250, None, :], dr[i0:i0 + 250, None, :]
        d = ri - r[None, :, :]
        dist = np.linalg.norm(d, axis=2)
        np.fill_diagonal(dist[:, i0:i0 + 250], np.inf)
        cr = np.cross(di, dr[None, :, :])
        total += np.sum(np.einsum("ijk,ijk->ij", cr, d) / dist**3)
    return total * (2 * np.pi / m) ** 2 / (4 * np.pi)


def aspect(X):
    r = np.linalg.norm(X - X.mean(axis=0), axis=1)
    return r.max() / r.min()


def simulate(shape="ellipse", out=None, until_us=0.2, threads=2):
    """Build the curve, run it, and return the numbers main() prints: a dict with the time
    series (obs), the start and end positions, the numpy writhe and frame twist, the run info."""
    cfg = ibrod.Config()
    cfg.update({"grid.n": 16, "grid.box_A": 200, "rod.base_pairs": N_BP, "rod.rise_A": RISE,
                "time.dt_ns": 0.1, "run.threads": threads,
                # a row every 0.01 µs; writing a directory, every 0.05 µs (each row writes a
                # frame and a checkpoint there)
                "output.every_steps": 500 if out else 100})
    if shape == "ellipse":
        X = ellipse(N_BP, RISE)
        D, tw_numpy = closed_frame(X, EXCESS_LINK, with_twist=True)
        wr_numpy = 0.0  # planar: the Gauss integrand (r'×r')·(r−r) vanishes identically
    elif shape == "coil":
        X = toroidal_coil(N_BP, RISE)
        D, tw_numpy = closed_frame(X, COIL_TURNS, with_twist=True)
        # the same curve, scaled as toroidal_coil scales it (writhe is scale-invariant)
        wr_numpy = gauss_writhe_smooth(coil_curve)
    else:
        raise ValueError(f"shape must be 'ellipse' or 'coil', not {shape!r}")
    sim = ibrod.Simulation(cfg, output=out, overwrite=True)
    sim.set_state(X, D)
    t0 = time.perf_counter()
    r = sim.run(until_us=until_us)
    wall = time.perf_counter() - t0
    return {"obs": sim.observables(), "X0": X, "X1": sim.positions, "run": r, "wall_s": wall,
            "wr_numpy": wr_numpy, "tw_numpy": tw_numpy}


def main():
    import argparse
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=None, help="run directory to write (optional)")
    ap.add_argument("--shape", choices=["ellipse", "coil"], default="ellipse")
    args = ap.parse_args()
    res = simulate(args.shape, args.out)
    o, r, X = res["obs"], res["run"], res["X0"]
    E_el = o["E_bend_kT"] + o["E_twist_kT"] + o["E_stretch_kT"]
    print(f"steps {r['steps']}, t = {r['time_us']:.3f} us, stop: {r['stop_reason']}")
    if args.shape == "coil":
        print(f"numpy: Wr (Gauss integral, smooth curve) {res['wr_numpy']:+.6f}, Tw (frame)"
              f" {res['tw_numpy']:+.6f}, Wr + Tw {res['wr_numpy'] + res['tw_numpy']:+.6f}")
    print(f"aspect ratio      {aspect(X):.4f} -> {aspect(res['X1']):.4f}")
    print(f"link Lk           {o['link'][0]:+.6f} -> {o['link'][-1]:+.6f}")
    print(f"writhe Wr         {o['writhe'][0]:+.6f} -> {o['writhe'][-1]:+.6f}")
    print(f"elastic energy    {E_el[0]:.3f} -> {E_el[-1]:.3f} kT")
    print(f"total energy      {o['E_total_kT'][0]:.3f} -> {o['E_total_kT'][-1]:.3f} kT"
          f" (largest change between rows {np.max(np.diff(o['E_total_kT'])):+.3f})")
    print(f"wall time         {res['wall_s']:.1f} s ({r['ms_per_step']:.3f} ms/step)")


if __name__ == "__main__":
    main()
