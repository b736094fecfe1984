"""rod.moduli_file (per-link moduli from a CSV) through a whole run: a file of rows equal to the
scalar keys gives the same trajectory bit for bit (the open helix rod of examples/helix.toml, 200
steps; and a closed ring under the implicit scheme), a file that varies along the rod gives
another, and a bad file raises ibrod.ConfigError naming the key, the file and the line. (Forces:
tests/unit/rod/test_moduli_per_link.cpp.)"""
import numpy as np
import pytest

import ibrod

N, K0 = 100, 0.04
ROW = [1.3e-19, 1.3e-19, 1.82e-19, 5e-5, 5e-5, 5e-5]  # the scalar keys' defaults


def helix_cfg():
    c = ibrod.Config()
    c.update({"grid.n": 16, "grid.box_A": 400, "rod.closed": False, "rod.excess_link": 0,
              "rod.base_pairs": N, "rod.perturbation": [], "electrostatics.enabled": False,
              "steric.enabled": False, "time.dt_ns": 0.1, "run.threads": 1,
              "run.fftw_measure": False, "output.every_steps": 100,
              "rod.intrinsic_curvature_per_A": [K0, 0.0], "rod.intrinsic_twist_per_A": K0})
    return c


def run(cfg, steps=200):
    sim = ibrod.Simulation(cfg)
    sim.run(steps=steps)
    return sim.positions, sim.triads, sim.observables()


def test_file_of_the_scalar_keys_equals_them_bitwise(tmp_path):
    path = tmp_path / "moduli.csv"
    np.savetxt(path, np.tile(ROW, (N, 1)), delimiter=",", header="a1,a2,a3 (erg cm),b1,b2,b3 (dyn)")
    from_file = helix_cfg()
    from_file["rod.moduli_file"] = str(path)
    X1, D1, o1 = run(helix_cfg())
    X2, D2, o2 = run(from_file)
    assert o1["E_bend_kT"][0] > 1  # the straight start is stressed: the moduli are in use
    assert np.array_equal(X1, X2) and np.array_equal(D1, D2)
    assert np.array_equal(o1["E_total_kT"], o2["E_total_kT"])
    # the second half of the rod 3× stiffer in bending: a different trajectory, and the initial
    # bending energy (uniform strain along the straight start) the per-link sum: links 0-49 at
    # 1×, 50-98 at 3× (the open rod's last row unused)
    rows = np.tile(ROW, (N, 1))
    rows[N // 2:, :2] *= 3
    np.savetxt(path, rows, delimiter=",")
    X3, _, o3 = run(from_file)
    assert np.max(np.abs(X3 - X1)) > 1e-3
    assert o3["E_bend_kT"][0] == pytest.approx(o1["E_bend_kT"][0] * (50 + 3 * 49) / 99, rel=1e-12)
    assert o3["E_twist_kT"][0] == pytest.approx(o1["E_twist_kT"][0], rel=1e-12)


def test_implicit_scheme_reads_the_file(tmp_path, cfg):
    """A closed ring (conftest's small case) under the implicit scheme: the same file of scalar
    rows gives the scalar run bit for bit; a stiffer file another run."""
    cfg.update({"time.scheme": "implicit", "time.dt_ns": 1.0})
    n = cfg["rod.base_pairs"]
    path = tmp_path / "moduli.csv"
    np.savetxt(path, np.tile(ROW, (n, 1)), delimiter=",")
    X1, _, _ = run(cfg, steps=5)
    cfg["rod.moduli_file"] = str(path)
    X2, _, _ = run(cfg, steps=5)
    assert np.array_equal(X1, X2)
    rows = np.tile(ROW, (n, 1))
    rows[::2, :3] *= 2
    np.savetxt(path, rows, delimiter=",")
    X3, _, _ = run(cfg, steps=5)
    assert np.max(np.abs(X3 - X1)) > 1e-6


@pytest.mark.parametrize("rows,what", [
    (np.tile(ROW, (N - 1, 1)), f"{N} rows"),
    (np.tile(ROW[:5], (N, 1)), "line 1"),
    (np.vstack([np.tile(ROW, (N - 1, 1)), [ROW[:3] + [5e-5, -5e-5, 5e-5]]]), "b2 = -5e-05 is not > 0"),
    (np.vstack([np.tile(ROW, (N - 1, 1)), [[0.0] + ROW[1:]]]), "a1 = 0 is not > 0"),
    (np.vstack([np.tile(ROW, (N - 1, 1)), [ROW[:2] + [np.nan] + ROW[3:]]]), "line 100"),
])
def test_bad_file_is_refused(tmp_path, rows, what):
    path = tmp_path / "bad.csv"
    np.savetxt(path, rows, delimiter=",")
    cfg = helix_cfg()
    cfg["rod.moduli_file"] = str(path)
    with pytest.raises(ibrod.ConfigError) as e:
        ibrod.Simulation(cfg)
    assert "rod.moduli_file" in str(e.value) and "bad.csv" in str(e.value)
    assert what in str(e.value)


def test_missing_file_is_refused(tmp_path):
    cfg = helix_cfg()
    cfg["rod.moduli_file"] = str(tmp_path / "none.csv")
    with pytest.raises(ibrod.ConfigError) as e:
        ibrod.Simulation(cfg)
    assert "rod.moduli_file" in str(e.value) and "it does not exist" in str(e.value)
