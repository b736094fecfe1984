"""rod.intrinsic_file (per-link intrinsic curvature and twist from a CSV) through a whole run: a
file of constant rows equal to the scalar keys gives the same trajectory bit for bit (the open
helix rod of examples/helix.toml, 200 steps), a file that varies along the rod gives another,
and a bad file raises ibrod.ConfigError naming the key. (Forces: tests/unit/rod/
test_intrinsic_per_link.cpp.)"""
import numpy as np
import pytest

import ibrod

N, K0 = 100, 0.04


def helix_cfg():
    c = ibrod.Config()
    c.update({"grid.n": 16, "grid.box_A": 400, "rod.closed": False, "rod.excess_link": 0,
              "rod.base_pairs": N, "rod.perturbation": [], "electrostatics.enabled": False,
              "steric.enabled": False, "time.dt_ns": 0.1, "run.threads": 1,
              "output.every_steps": 100})
    return c


def run(cfg, steps=200):
    sim = ibrod.Simulation(cfg)
    sim.run(steps=steps)
    return sim.positions, sim.triads, sim.observables()


def test_constant_file_equals_scalar_keys_bitwise(tmp_path):
    scalar = helix_cfg()
    scalar.update({"rod.intrinsic_curvature_per_A": [K0, 0.0], "rod.intrinsic_twist_per_A": K0})
    path = tmp_path / "omega0.csv"
    np.savetxt(path, np.tile([K0, 0.0, K0], (N, 1)), delimiter=",", header="k1, k2, tau (rad/A)")
    from_file = helix_cfg()
    from_file["rod.intrinsic_file"] = str(path)
    X1, D1, o1 = run(scalar)
    X2, D2, o2 = run(from_file)
    assert o1["E_bend_kT"][0] > 1  # the straight start is stressed: the keys are in use
    assert np.array_equal(X1, X2) and np.array_equal(D1, D2)
    assert np.array_equal(o1["E_total_kT"], o2["E_total_kT"])
    # half the rod with the opposite twist: a different trajectory and energy
    rows = np.tile([K0, 0.0, K0], (N, 1))
    rows[N // 2:, 2] = -K0
    np.savetxt(path, rows, delimiter=",")
    X3, _, o3 = run(from_file)
    assert np.max(np.abs(X3 - X1)) > 1e-3
    assert o3["E_total_kT"][0] == pytest.approx(o1["E_total_kT"][0], rel=1e-12)  # |τ0| alike
    assert o3["E_total_kT"][-1] != o1["E_total_kT"][-1]


def test_bad_file_is_refused(tmp_path):
    path = tmp_path / "short.csv"
    np.savetxt(path, np.zeros((N - 1, 3)), delimiter=",")
    cfg = helix_cfg()
    cfg["rod.intrinsic_file"] = str(path)
    with pytest.raises(ibrod.ConfigError) as e:
        ibrod.Simulation(cfg)
    assert "rod.intrinsic_file" in str(e.value) and f"{N} rows" in str(e.value)
