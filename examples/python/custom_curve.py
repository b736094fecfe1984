#!/usr/bin/env python3
"""A closed curve built in numpy, run by ibrod (docs/python.md).

An ellipse of 100 base pairs (axes 3:2) carrying one turn of twist (ΔLk = 1, below the
buckling threshold), on the 16³ grid of the tests: the state is built here (positions at equal
arc length, a frame that closes on itself), handed to the simulation with set_state, run for
0.2 µs and compared before and after: the linking number stays the integer it was built with,
the writhe stays near 0, the elastic energy falls as the ellipse rounds towards a circle.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/custom_curve.py [OUT_DIR]

With OUT_DIR the run directory is written there too (read back with ibrod.read_run).
"""
import sys
import time

import numpy as np

import ibrod

N_BP = 100       # rod points (base pairs)
RISE = 3.4       # Δs, Å
EXCESS_LINK = 1  # full turns of twist added to the frame (below Michell's √3 a1/a3 ≈ 1.24)


def ellipse(n, rise, aspect=1.5):
    """n points at equal arc length on an ellipse of perimeter n·rise in the z = 0 plane."""
    t = np.linspace(0, 2 * np.pi, 20001)
    c = np.stack([aspect * np.cos(t), np.sin(t), 0 * t], axis=1)
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))])
    c *= n * rise / s[-1]  # perimeter n Δs
    s *= n * rise / s[-1]
    si = np.arange(n) * rise
    return np.stack([np.interp(si, s, c[:, i]) for i in range(3)], axis=1)


def closed_frame(X, turns):
    """Triads (n, 3, 3), row i = D^(i+1): D³ along the chord to the next point, D¹ carried
    along by parallel transport, its mismatch after one round spread evenly, plus `turns` full
    turns of twist. The frame closes on itself, so Lk = Wr + Tw is an integer."""
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
    return np.stack([e1, e2, t], axis=1)


def aspect(X):
    r = np.linalg.norm(X - X.mean(axis=0), axis=1)
    return r.max() / r.min()


def main():
    cfg = ibrod.Config()
    cfg.update({"grid.n": 16, "grid.box_A": 200, "rod.base_pairs": N_BP, "rod.rise_A": RISE,
                "time.dt_ns": 0.1, "output.every_steps": 500, "run.threads": 2})
    X = ellipse(N_BP, RISE)
    D = closed_frame(X, EXCESS_LINK)
    out = sys.argv[1] if len(sys.argv) > 1 else None
    sim = ibrod.Simulation(cfg, output=out, overwrite=True)
    sim.set_state(X, D)
    t0 = time.perf_counter()
    r = sim.run(until_us=0.2)
    wall = time.perf_counter() - t0
    o = sim.observables()
    E_el = o["E_bend_kT"] + o["E_twist_kT"] + o["E_stretch_kT"]
    print(f"steps {r['steps']}, t = {r['time_us']:.3f} us, stop: {r['stop_reason']}")
    print(f"aspect ratio      {aspect(X):.4f} -> {aspect(sim.positions):.4f}")
    print(f"link Lk           {o['link'][0]:+.6f} -> {o['link'][-1]:+.6f}")
    print(f"writhe Wr         {o['writhe'][0]:+.6f} -> {o['writhe'][-1]:+.6f}")
    print(f"elastic energy    {E_el[0]:.3f} -> {E_el[-1]:.3f} kT")
    print(f"wall time         {wall:.1f} s ({r['ms_per_step']:.3f} ms/step)")


if __name__ == "__main__":
    main()
