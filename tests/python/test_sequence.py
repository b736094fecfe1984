"""The sequence-dependent DNA examples (examples/sequence/, issue 17): a DNA sequence and a
per-dinucleotide table (ILLUSTRATIVE values) become rod.intrinsic_file and rod.moduli_file
(examples/sequence/sequence_rod.py), and runs reach the closed forms.

- poly(A), 60 bp, open (examples/sequence/polyA.toml, run for 0.4 µs instead of 0.6): every step
  alike, so the relaxed rod is the helix of curvature |roll|/Δs and torsion twist/Δs — radius
  κ/(κ² + τ²) = 0.308 Å, pitch 33.80 Å for the discrete rod (34.37 Å continuous). Measured at
  0.4 µs (32³, 250 Å box): radius +7.9 % (0.024 Å), pitch +1.0 %, 0.13 Å rms from the stress-free
  shape built by sequence_rod.stress_free_shape, E_total 1761.3 → 0.187 kT (at 0.3 µs: +18 %,
  +1.9 %, 0.20 Å; at 0.6 µs +1.6 %, +0.3 %, 0.056 Å: the short wobble relaxes last). Tolerances:
  15 % on the radius, 2 % on the pitch, 0.3 Å rms, E down by more than 99.9 %.
- (A25 G25)2 ring, 100 bp, moduli only (examples/sequence/ring_a25g25.toml, 0.3 µs instead of
  0.5): the stiffer AA steps bend less, a1 · 2 sin(θ/2) = M Δs on every link. Measured at 0.3 µs:
  θ(AA) +0.4 %, θ(GG) −0.2 % from the closed form inside the blocks (5 links from either
  junction left out: the junctions are still relaxing), ratio 0.671, E_bend 21.730 kT against
  21.685 (+0.2 %). The whole file: 10 s on an idle 2-core machine, 35 s on a busy one.
  Tolerances: 4 % on the block means, 1 % on E_bend, θ(AA)/θ(GG) below 0.72 (1/1.5 = 0.667).

Also: the committed files are what the script makes of the sequences, and the conversion keeps
the helix when the rod's frame is the base-pair frame turned back by a reference twist.
"""
import os
import sys

import numpy as np
import pytest

from conftest import run_cli

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SEQ = os.path.join(ROOT, "examples", "sequence")
sys.path.insert(0, SEQ)
sys.path.insert(0, os.path.join(ROOT, "examples", "python"))
import helix_fit  # noqa: E402
import sequence_rod  # noqa: E402

KT = 1.380649e-16 * 300 * 1e16  # g Å² s⁻² at 300 K (erg = 1e16 g Å² s⁻²)


def rmsd_after_alignment(P, Q):
    P = P - P.mean(0)
    Q = Q - Q.mean(0)
    U, _, Vt = np.linalg.svd(P.T @ Q)
    d = np.sign(np.linalg.det(U @ Vt))
    return float(np.sqrt(np.mean(np.sum((P @ U @ np.diag([1, 1, d]) @ Vt - Q) ** 2, axis=1))))


def read_state(run):
    a = np.genfromtxt(os.path.join(run, "final_state.csv"), delimiter=",", names=True)
    X = np.stack([a["x_A"], a["y_A"], a["z_A"]], axis=1)
    D = np.stack([np.stack([a[f"d{i}x"], a[f"d{i}y"], a[f"d{i}z"]], axis=1) for i in (1, 2, 3)],
                 axis=2)  # D[k][:, i] = D^(i+1)
    return X, D


def test_committed_files_are_the_scripts_output(tmp_path):
    table = sequence_rod.read_table(os.path.join(SEQ, "step_table.csv"))
    for name, seq, closed in [("polyA60", "A" * 60, False),
                              ("ring_a25g25", ("A" * 25 + "G" * 25) * 2, True)]:
        om, mod = sequence_rod.convert(seq, table, closed=closed)
        committed = np.loadtxt(os.path.join(SEQ, name + "_moduli.csv"), delimiter=",")
        assert np.allclose(committed, mod, rtol=1e-11, atol=0)
        if not closed:
            committed = np.loadtxt(os.path.join(SEQ, name + "_intrinsic.csv"), delimiter=",")
            assert np.allclose(committed, om, rtol=1e-11, atol=1e-15)


def test_reference_twist_only_turns_the_frame():
    """The stress-free shape of poly(A) is the same helix with the rod's frame the base-pair frame
    (θ_ref = 0: constant Ω₀) or turned back by θ_ref = the step's twist (no Ω³₀, the roll turning
    with the helix)."""
    table = sequence_rod.read_table(os.path.join(SEQ, "step_table.csv"))
    roll, _, twist, _, _ = table["AA"]
    r0, p0 = helix_fit.helix_closed_form(abs(roll) / 3.4, twist / 3.4)
    for ref in (0.0, 35.5):
        om, _ = sequence_rod.convert("A" * 60, table, twist_ref_deg=ref)
        f = helix_fit.fit_helix(sequence_rod.stress_free_shape(om)[0])
        assert f["radius"] == pytest.approx(r0, rel=0.02)
        assert f["pitch"] == pytest.approx(p0, rel=0.02)
        assert f["rms_radial"] < 1e-9


def test_poly_a_relaxes_to_its_helix(binary, tmp_path):
    out = tmp_path / "polyA"
    r = run_cli(binary, ["run", os.path.join(SEQ, "polyA.toml"), "-o", str(out),
                         "--set", "time.t_end_us=0.4", "--set", "run.threads=2",
                         "--set", "run.fftw_measure=false"], cwd=ROOT)
    assert r.returncode == 0, r.stderr
    X, _ = read_state(str(out))
    table = sequence_rod.read_table(os.path.join(SEQ, "step_table.csv"))
    roll, _, twist, _, _ = table["AA"]
    kappa, tau = abs(roll) / 3.4, twist / 3.4
    r0, _ = helix_fit.helix_closed_form(kappa, tau)
    turn = 2 * np.arcsin(3.4 * np.hypot(kappa, tau) / 2)  # the discrete rod's turn per step
    p0 = 2 * np.pi * 3.4 * (tau / np.hypot(kappa, tau)) / turn
    f = helix_fit.fit_helix(X)
    om = np.loadtxt(os.path.join(SEQ, "polyA60_intrinsic.csv"), delimiter=",")
    rms = rmsd_after_alignment(X, sequence_rod.stress_free_shape(om)[0])
    ts = np.genfromtxt(out / "timeseries.csv", delimiter=",", names=True)
    print(f"poly(A): radius {f['radius']:.4f} Å ({f['radius'] / r0 - 1:+.2%}), pitch "
          f"{f['pitch']:.3f} Å ({f['pitch'] / p0 - 1:+.2%}), rms from the stress-free shape "
          f"{rms:.3f} Å, E_total {ts['E_total_kT'][0]:.1f} → {ts['E_total_kT'][-1]:.3f} kT")
    assert abs(f["radius"] / r0 - 1) < 0.15
    assert abs(f["pitch"] / p0 - 1) < 0.02  # right-handed: the sign too
    assert rms < 0.3
    assert ts["E_total_kT"][-1] < 1e-3 * ts["E_total_kT"][0]


def test_stiffer_steps_bend_less_in_a_ring(binary, tmp_path):
    out = tmp_path / "ring"
    r = run_cli(binary, ["run", os.path.join(SEQ, "ring_a25g25.toml"), "-o", str(out),
                         "--set", "time.t_end_us=0.3", "--set", "run.threads=2",
                         "--set", "run.fftw_measure=false"], cwd=ROOT)
    assert r.returncode == 0, r.stderr
    _, D = read_state(str(out))
    n = len(D)
    theta = np.array([np.arccos(np.clip((np.trace(D[(k + 1) % n] @ D[k].T) - 1) / 2, -1, 1))
                      for k in range(n)])
    a1 = np.loadtxt(os.path.join(SEQ, "ring_a25g25_moduli.csv"), delimiter=",")[:, 0]
    th0 = sequence_rod.ring_bend_angles(a1)
    inner_a = np.r_[5:20, 55:70]   # AA links (0-23, 50-73) away from the junctions
    inner_g = np.r_[30:44, 80:94]  # GG links (25-48, 75-98)
    ea = theta[inner_a].mean() / th0[inner_a].mean() - 1
    eg = theta[inner_g].mean() / th0[inner_g].mean() - 1
    e0 = (1.7 * a1 * 1e24 * (2 * np.sin(th0 / 2) / 3.4) ** 2).sum() / KT
    ts = np.genfromtxt(out / "timeseries.csv", delimiter=",", names=True)
    ratio = theta[inner_a].mean() / theta[inner_g].mean()
    print(f"ring: θ(AA) {theta[inner_a].mean():.5f} ({ea:+.2%}), θ(GG) "
          f"{theta[inner_g].mean():.5f} ({eg:+.2%}), ratio {ratio:.3f}; E_bend "
          f"{ts['E_bend_kT'][-1]:.3f} kT against {e0:.3f}")
    assert abs(theta.sum() - 2 * np.pi) < 1e-6  # planar, untwisted
    assert abs(ea) < 0.04 and abs(eg) < 0.04
    assert ratio < 0.72
    assert ts["E_bend_kT"][-1] == pytest.approx(e0, rel=0.01)
