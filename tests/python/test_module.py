"""The Python module: configuration through the CLI's schema and messages, a simulation's
state, observables and fluid, set_state checks, Ctrl-C."""
import os
import signal
import threading

import numpy as np
import pytest

import ibrod
from conftest import run_cli


def test_config_defaults_and_item_access():
    c = ibrod.Config()
    assert c["grid.n"] == 64 and c["rod.excess_link"] == 6
    c["rod.excess_link"] = 4
    c["rod.perturbation"] = np.array([0.5, 0.25])
    c["time.scheme"] = "implicit"
    c["steric.enabled"] = False
    assert c["rod.excess_link"] == 4
    assert c["rod.perturbation"] == [0.5, 0.25]
    assert c["time.scheme"] == "implicit" and c["steric.enabled"] is False
    assert "rod.initial_shape" in c.keys()
    d = c.copy()
    d["rod.excess_link"] = 1
    assert c["rod.excess_link"] == 4  # a copy is independent


@pytest.mark.parametrize("key,value,cli", [
    ("rod.excess_link", 4.5, "4.5"),
    ("grid.n", 7, "7"),
    ("time.scheme", "sideways", '"sideways"'),
    ("rod.no_such_key", 1, "1"),
    ("nosection.key", 1, "1"),
    ("steric.enabled", 1, "1"),
])
def test_bad_config_raises_the_cli_message(binary, key, value, cli):
    with pytest.raises(ibrod.ConfigError) as e:
        ibrod.Config()[key] = value
    assert isinstance(e.value, ValueError)
    r = run_cli(binary, ["check", "--set", f"{key}={cli}"])
    assert r.returncode == 2
    assert str(e.value) in r.stderr, (str(e.value), r.stderr)


def test_config_file_and_cross_key_check(tmp_path, cfg):
    p = tmp_path / "run.toml"
    p.write_text(cfg.to_toml())
    c = ibrod.Config(p)
    assert c["grid.n"] == 16 and c["rod.base_pairs"] == 100
    c["grid.box_A"] = 50  # the ring (r0 ≈ 54 Å) no longer fits
    with pytest.raises(ibrod.ConfigError):
        c.validate()
    with pytest.raises(ibrod.ConfigError):
        ibrod.Simulation(c)


def test_run_state_and_observables(cfg):
    sim = ibrod.Simulation(cfg)
    X, D = sim.positions, sim.triads
    assert X.shape == (100, 3) and D.shape == (100, 3, 3)
    # row i of D[k] is D^(i+1): orthonormal rows, right-handed, D³ along the tangent
    eye = np.einsum("kij,klj->kil", D, D)
    assert np.abs(eye - np.eye(3)).max() < 1e-12
    assert np.allclose(np.cross(D[:, 0], D[:, 1]), D[:, 2], atol=1e-12)
    t = np.roll(X, -1, axis=0) - X
    cos = np.einsum("ki,ki->k", t / np.linalg.norm(t, axis=1)[:, None], D[:, 2])
    assert cos.min() > 0.99
    r = sim.run(steps=120)
    assert r["stop_reason"] == "end_time" and sim.step == 120 and r["steps"] == 120
    assert abs(sim.time_us - 0.012) < 1e-12
    obs = sim.observables()
    # rows at steps 0, 50, 100 and at the segment's end
    assert list(obs["step"]) == [0, 50, 100, 120]
    assert np.allclose(obs["link"], obs["writhe"] + obs["twist"], atol=1e-12)
    assert abs(obs["link"][-1] - obs["link"][0]) < 1e-6  # Lk is conserved
    assert np.all(np.isfinite(obs["E_total_kT"]))
    sim.run(until_us=0.015)
    assert sim.step == 150 and sim.observables()["step"][-1] == 150
    u = sim.fluid_velocity
    assert u.shape == (3, 16, 16, 16) and np.abs(u).max() > 0
    # the fluid's kinetic energy ½ρΣ|u|²h³ is the row's E_kinetic_kT (u in Å/ns)
    h = 200.0 / 16
    rho = 1.0e-24  # g/Å³
    e_k = 0.5 * rho * np.sum((u * 1e9) ** 2) * h**3  # g Å² s⁻²
    kT = 1.380649e-16 * 300 * 1e16  # erg → g Å² s⁻²
    assert e_k / kT == pytest.approx(sim.observables()["E_kinetic_kT"][-1], rel=1e-9)
    with pytest.raises(ValueError):
        sim.run(steps=0)
    with pytest.raises(ValueError):
        sim.run(until_us=0.01)  # in the past


def test_set_state_round_trip_and_bad_shapes(cfg):
    sim = ibrod.Simulation(cfg)
    X, D = sim.positions, sim.triads
    # a rigid rotation and a shift of the whole state: a valid state
    a = 0.3
    R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    X2 = X @ R.T + np.array([1.0, -2.0, 3.0])
    D2 = D @ R.T
    sim.set_state(X2, D2)
    assert np.array_equal(sim.positions, X2) and np.array_equal(sim.triads, D2)
    sim.set_state(X2.tolist(), D2)  # lists are arrays too
    assert np.array_equal(sim.positions, X2)

    def raises(Xb, Db, words):
        with pytest.raises(ValueError) as e:
            sim.set_state(Xb, Db)
        for w in words:
            assert w in str(e.value), str(e.value)

    raises(X2[:-1], D2, ["X has shape (99, 3)", "expected (100, 3)"])
    raises(X2, D2[:, :2], ["D has shape (100, 2, 3)", "expected (100, 3, 3)"])
    Xn = X2.copy()
    Xn[7, 1] = np.nan
    raises(Xn, D2, ["point 7", "not finite"])
    Db = D2.copy()
    Db[3, 0] *= 1.01
    raises(X2, Db, ["triad of point 3", "orthonormal"])
    Dl = D2.copy()
    Dl[5, 2] *= -1
    raises(X2, Dl, ["point 5", "left-handed"])
    Xs = X2.copy()
    Xs[10] += 3.0 * D2[10, 2]  # a gap of ~1.9 Δs
    raises(Xs, D2, ["spacing of points", "0.5 to 1.5"])
    # a refused state leaves the state as it was
    assert np.array_equal(sim.positions, X2)
    sim.run(steps=10)
    assert np.all(np.isfinite(sim.positions))


def test_ctrl_c_stops_cleanly(tmp_path, cfg):
    cfg["time.dt_ns"] = 0.01  # many cheap steps
    out = tmp_path / "run"
    sim = ibrod.Simulation(cfg, output=str(out))
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.run(steps=10_000_000)
    finally:
        timer.cancel()
    assert 0 < sim.step < 10_000_000
    run = ibrod.read_run(out)
    assert run["summary"]["stop_reason"] == "interrupted"
    assert (out / "checkpoint.bin").exists()
    np.testing.assert_array_equal(run["final_state"]["positions"], sim.positions)
    # it goes on afterwards
    before = sim.step
    sim.run(steps=5)
    assert sim.step == before + 5


def test_output_directory_refused_unless_overwrite(tmp_path, cfg):
    out = tmp_path / "run"
    ibrod.Simulation(cfg, output=str(out)).run(steps=5)
    with pytest.raises(ibrod.ConfigError) as e:
        ibrod.Simulation(cfg, output=str(out))
    assert "overwrite" in str(e.value)
    ibrod.Simulation(cfg, output=str(out), overwrite=True).run(steps=5)


def test_the_state_is_refused_to_other_threads_while_running(cfg):
    import time

    sim = ibrod.Simulation(cfg)
    t = threading.Thread(target=sim.run, kwargs={"steps": 2000})
    t.start()
    refused = False
    while t.is_alive() and not refused:
        try:
            sim.positions
        except RuntimeError as e:
            refused = "another thread" in str(e)
        time.sleep(0.005)
    t.join()
    assert refused
    assert sim.step == 2000  # the run itself was not disturbed
