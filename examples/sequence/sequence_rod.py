#!/usr/bin/env python3
"""A DNA sequence and a per-dinucleotide table → ibrod's rod.intrinsic_file and rod.moduli_file.

    /usr/bin/python3 examples/sequence/sequence_rod.py TABLE SEQUENCE OUT_PREFIX \\
        [--closed] [--twist-ref DEG] [--rise A] [--bend ERG_CM] [--twist ERG_CM] \\
        [--shear DYN] [--stretch DYN]

writes OUT_PREFIX_intrinsic.csv (Ω¹₀, Ω²₀, Ω³₀ in rad/Å) and OUT_PREFIX_moduli.csv (a1, a2, a3 in
erg·cm, b1, b2, b3 in dyn), one row per base pair: row k is the step k → k+1 (for --closed the
last row is the step from the last base pair to the first; for an open rod it is unused and holds
the reference values). SEQUENCE is a string of A, C, G, T or a file holding one.

TABLE: a CSV with the columns step, roll_deg, tilt_deg, twist_deg, bend_mult, twist_mult (one row
per dinucleotide 5'-XY-3'; '#' lines are comments). examples/sequence/step_table.csv holds
ILLUSTRATIVE values (made up by a simple rule, not a published parameter set).

The conversion (first order in the step angles, which it treats as a rotation vector):
  the base-pair frame of step k has the rotation vector (tilt, roll, twist) about (D¹, D², D³);
  the rod's frame turns by the reference twist θ_ref less per step than the base pairs, so it
  lags the base-pair frame by ψ = (k + ½) θ_ref at the middle of step k, and
      Ω¹₀ = (tilt cos ψ − roll sin ψ)/Δs,  Ω²₀ = (tilt sin ψ + roll cos ψ)/Δs,
      Ω³₀ = (twist − θ_ref)/Δs.
  θ_ref = 0 (the default): the rod's frame is the base-pair frame and Ω₀ = (tilt, roll, twist)/Δs;
  θ_ref = the mean twist: Ω³₀ is the excess twist and the roll turns with the helix (the phasing
  of A-tract bends). Moduli: a1 = a2 = bend_mult × --bend, a3 = twist_mult × --twist, b1 = b2 =
  --shear, b3 = --stretch (default: ibrod's scalar keys, MODEL §1).

stress_free_shape() builds the open rod's shape of zero elastic energy for given Ω₀ (the discrete
model's, docs/model.md): D_{k+1} = exp(θ_k [u_k]×) D_k with the body axis u_k = Ω₀/|Ω₀| and
2 sin(θ_k/2) = |Ω₀| Δs, X_{k+1} = X_k + Δs D³_{k+½}. A relaxed open rod reaches it (up to a rigid
motion): tests/python/test_sequence.py.
"""
import argparse
import os
import sys

import numpy as np

SCALAR = {"bend": 1.3e-19, "twist": 1.82e-19, "shear": 5e-5, "stretch": 5e-5}


def read_table(path):
    """dict step → (roll, tilt, twist in rad, bend_mult, twist_mult)."""
    table = {}
    header = None
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            cells = [c.strip() for c in line.split(",")]
            if header is None:
                header = cells
                need = ["step", "roll_deg", "tilt_deg", "twist_deg", "bend_mult", "twist_mult"]
                if header != need:
                    raise ValueError(f"{path}: the columns must be {','.join(need)}, got {line}")
                continue
            step = cells[0].upper()
            roll, tilt, twist, bm, tm = map(float, cells[1:])
            if not (bm > 0 and tm > 0):
                raise ValueError(f"{path}: step {step}: the multipliers must be > 0")
            table[step] = (np.radians(roll), np.radians(tilt), np.radians(twist), bm, tm)
    return table


def read_sequence(arg):
    text = open(arg).read() if os.path.isfile(arg) else arg
    seq = "".join(ch for ch in text.upper() if not ch.isspace())
    if not seq or set(seq) - set("ACGT"):
        raise ValueError(f"the sequence must be made of A, C, G, T, got {seq[:40]!r}")
    return seq


def convert(seq, table, closed=False, twist_ref_deg=0.0, rise=3.4, bend=SCALAR["bend"],
            twist=SCALAR["twist"], shear=SCALAR["shear"], stretch=SCALAR["stretch"]):
    """(omega0 (n, 3) rad/Å, moduli (n, 6) erg·cm and dyn) for the n base pairs of seq."""
    n = len(seq)
    if n < 2:
        raise ValueError("the sequence needs at least 2 base pairs")
    ref = np.radians(twist_ref_deg)
    omega0 = np.zeros((n, 3))
    moduli = np.tile([bend, bend, twist, shear, shear, stretch], (n, 1)).astype(float)
    for k in range(n if closed else n - 1):
        step = seq[k] + seq[(k + 1) % n]
        if step not in table:
            raise ValueError(f"step {step} (base pairs {k}, {k + 1}) is not in the table")
        roll, tilt, tw, bm, tm = table[step]
        psi = (k + 0.5) * ref
        omega0[k] = [(tilt * np.cos(psi) - roll * np.sin(psi)) / rise,
                     (tilt * np.sin(psi) + roll * np.cos(psi)) / rise, (tw - ref) / rise]
        moduli[k, :3] = [bm * bend, bm * bend, tm * twist]
    return omega0, moduli


def _rotation(v):
    """The rotation matrix of the rotation vector v (Rodrigues)."""
    th = np.linalg.norm(v)
    if th == 0:
        return np.eye(3)
    u = v / th
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K


def stress_free_shape(omega0, rise=3.4):
    """(X (n, 3), D (n, 3, 3) with columns D¹ D² D³) of the open rod of zero elastic energy whose
    links k → k+1 have the intrinsic strains omega0[k] (the first n − 1 rows), starting at the
    origin with D_0 = I."""
    n = len(omega0)
    X = np.zeros((n, 3))
    D = np.zeros((n, 3, 3))
    D[0] = np.eye(3)
    for k in range(n - 1):
        w = np.asarray(omega0[k]) * rise
        s = np.linalg.norm(w)
        if s > 2:
            raise ValueError(f"step {k}: |Ω₀| Δs = {s} > 2 has no rotation")
        theta = 2 * np.arcsin(s / 2)
        body = w / s * theta if s > 0 else np.zeros(3)
        D[k + 1] = D[k] @ _rotation(body)          # body-frame rotation about u_k
        Dh = D[k] @ _rotation(0.5 * body)          # the half-point triad
        X[k + 1] = X[k] + rise * Dh[:, 2]
    return X, D


def ring_bend_angles(a1, total=2 * np.pi):
    """The planar ring of links with bending moduli a1[k] (any unit) and no intrinsic curvature,
    twist or excess link: its equilibrium carries no force and one bending moment M throughout
    (when the pattern of a1 has a rotational symmetry, as a repeated block), so link k turns by
    θ_k with a1[k] · 2 sin(θ_k/2)/Δs = M (the discrete strain of a turn θ is 2 sin(θ/2)/Δs) and
    Σ θ_k = 2π: the stiffer links bend less, θ_k ≈ 2π (1/a1[k]) / Σ_j (1/a1[j]). Returns θ (rad)."""
    a1 = np.asarray(a1, dtype=float)
    lo, hi = 0.0, 2 * a1.min()
    f = lambda m: (2 * np.arcsin(np.minimum(m / a1 / 2, 1))).sum() - total
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    return 2 * np.arcsin(0.5 * (lo + hi) / a1 / 2)


def write(prefix, omega0, moduli, seq, closed, twist_ref_deg, table_path):
    what = (f"# from sequence_rod.py: {len(seq)} bp, {'closed' if closed else 'open'}, "
            f"twist_ref = {twist_ref_deg} deg, table {os.path.basename(table_path)} "
            "(ILLUSTRATIVE values, not a published parameter set)\n")
    last = "" if closed else "# the last row: no step (an open rod does not use it)\n"
    with open(prefix + "_intrinsic.csv", "w") as f:
        f.write(what + "# Omega1_0, Omega2_0, Omega3_0 (rad/A), row k: step k -> k+1\n")
        for k, r in enumerate(omega0):
            if k == len(omega0) - 1:
                f.write(last)
            f.write("%.12g,%.12g,%.12g\n" % tuple(r))
    with open(prefix + "_moduli.csv", "w") as f:
        f.write(what + "# a1, a2, a3 (erg cm), b1, b2, b3 (dyn), row k: step k -> k+1\n")
        for k, r in enumerate(moduli):
            if k == len(moduli) - 1:
                f.write(last)
            f.write("%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n" % tuple(r))


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("table")
    ap.add_argument("sequence")
    ap.add_argument("out_prefix")
    ap.add_argument("--closed", action="store_true")
    ap.add_argument("--twist-ref", type=float, default=0.0, help="θ_ref, degrees per step")
    ap.add_argument("--rise", type=float, default=3.4, help="Δs, Å (rod.rise_A)")
    for k, v in SCALAR.items():
        ap.add_argument("--" + k, type=float, default=v)
    a = ap.parse_args(argv[1:])
    seq = read_sequence(a.sequence)
    table = read_table(a.table)
    omega0, moduli = convert(seq, table, a.closed, a.twist_ref, a.rise, a.bend, a.twist,
                             a.shear, a.stretch)
    write(a.out_prefix, omega0, moduli, seq, a.closed, a.twist_ref, a.table)
    print(f"{len(seq)} bp: wrote {a.out_prefix}_intrinsic.csv and {a.out_prefix}_moduli.csv "
          f"(max |Ω₀| Δs = {np.abs(omega0).max() * a.rise:.3f} rad)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
