"""The Python module and `ibrod run` are one program: the same configuration gives the same
states bit for bit; read_run reads what either writes; rod.initial_shape starts a run from
another run's end state exactly."""
import numpy as np
import pytest

import ibrod
from conftest import run_cli

STEPS = 200  # time.t_end_us = 0.02 at Δt = 0.1 ns


def cli_run(binary, cfg, tmp_path, name, *sets):
    p = tmp_path / f"{name}.toml"
    p.write_text(cfg.to_toml())
    out = tmp_path / name
    args = ["run", str(p), "-o", str(out)]
    for s in sets:
        args += ["--set", s]
    r = run_cli(binary, args)
    assert r.returncode == 0, r.stderr
    return out


@pytest.mark.parametrize("scheme", ["explicit", "implicit"])
def test_python_and_cli_give_identical_states(binary, tmp_path, cfg, scheme):
    cfg["time.scheme"] = scheme
    if scheme == "implicit":
        cfg["time.dt_ns"] = 1.0
        cfg["time.t_end_us"] = 0.05  # 50 steps of at most 1 ns
    cli = ibrod.read_run(cli_run(binary, cfg, tmp_path, "cli"))
    out = tmp_path / "py"
    sim = ibrod.Simulation(cfg, output=str(out))
    r = sim.run()  # to time.t_end_us, as the CLI
    assert r["stop_reason"] == "end_time"
    py = ibrod.read_run(out)
    # the same state, bit for bit (final_state.csv holds 17 digits: the doubles themselves)
    np.testing.assert_array_equal(sim.positions, cli["final_state"]["positions"])
    np.testing.assert_array_equal(sim.triads, cli["final_state"]["triads"])
    np.testing.assert_array_equal(py["final_state"]["positions"], cli["final_state"]["positions"])
    # the same rows and frames
    for col, v in cli["timeseries"].items():
        np.testing.assert_array_equal(py["timeseries"][col], v, err_msg=col)
        # in memory: the doubles that timeseries.csv rounds to 10 or 12 digits
        np.testing.assert_allclose(sim.observables()[col], v, rtol=1e-9, atol=1e-300,
                                   err_msg=col)
    np.testing.assert_array_equal(py["frames"]["positions"], cli["frames"]["positions"])
    np.testing.assert_array_equal(py["frames"]["triads"], cli["frames"]["triads"])
    assert py["summary"]["steps"] == cli["summary"]["steps"]


def test_segments_equal_one_run(binary, tmp_path, cfg):
    # run(steps=…) in pieces reaches the state of one CLI run of the same length
    cli = ibrod.read_run(cli_run(binary, cfg, tmp_path, "cli"))
    sim = ibrod.Simulation(cfg)
    for k in (1, 49, 100, 50):
        sim.run(steps=k)
    assert sim.step == STEPS
    np.testing.assert_array_equal(sim.positions, cli["final_state"]["positions"])
    np.testing.assert_array_equal(sim.triads, cli["final_state"]["triads"])


def test_read_run(binary, tmp_path, cfg):
    out = cli_run(binary, cfg, tmp_path, "cli")
    run = ibrod.read_run(out)
    ts = run["timeseries"]
    assert list(ts["step"]) == list(range(0, STEPS + 1, 50))
    assert run["frames"]["positions"].shape == (5, 100, 3)
    assert run["frames"]["triads"].shape == (5, 100, 3, 3)
    np.testing.assert_array_equal(run["frames"]["positions"][-1], run["final_state"]["positions"])
    np.testing.assert_array_equal(run["frames"]["step"], ts["step"])
    assert run["summary"]["stop_reason"] == "end_time"
    assert run["config"]["grid"]["n"] == 16
    with pytest.raises(FileNotFoundError):
        ibrod.read_run(tmp_path / "nothing")


def test_initial_shape_from_final_state_and_trajectory(binary, tmp_path, cfg):
    a = cli_run(binary, cfg, tmp_path, "a")
    A = ibrod.read_run(a)
    # from final_state.csv: the run starts exactly where A ended
    c = cfg.copy()
    c["rod.initial_shape"] = str(a / "final_state.csv")
    c["rod.excess_link"] = 5  # ignored: the shape is the file's
    sim = ibrod.Simulation(c)
    np.testing.assert_array_equal(sim.positions, A["final_state"]["positions"])
    np.testing.assert_array_equal(sim.triads, A["final_state"]["triads"])
    sim.run(steps=10)
    assert abs(sim.observables()["link"][0] - A["timeseries"]["link"][-1]) < 1e-9
    # from the CLI too: step 0 of B is A's end
    b = ibrod.read_run(cli_run(binary, cfg, tmp_path, "b",
                               f'rod.initial_shape="{a / "final_state.csv"}"'))
    np.testing.assert_array_equal(b["frames"]["positions"][0], A["final_state"]["positions"])
    np.testing.assert_array_equal(b["frames"]["triads"][0], A["final_state"]["triads"])
    # an H5MD frame: PATH@FRAME (from 0; -1 the last)
    for spec, frame in ((f"{a}/trajectory.h5md@2", 2), (f"{a}/trajectory.h5md@-1", -1),
                        (f"{a}/trajectory.h5md", -1)):
        c["rod.initial_shape"] = spec
        s = ibrod.Simulation(c)
        np.testing.assert_array_equal(s.positions, A["frames"]["positions"][frame])
        np.testing.assert_array_equal(s.triads, A["frames"]["triads"][frame])


def test_initial_shape_errors(binary, tmp_path, cfg):
    a = cli_run(binary, cfg, tmp_path, "a")
    cases = [
        (str(tmp_path / "missing.csv"), "no such file"),
        (f"{a}/trajectory.h5md@9", "5 frames"),
        (f"{a}/timeseries.csv", "no column x_A"),
    ]
    for spec, words in cases:
        c = cfg.copy()
        c["rod.initial_shape"] = spec
        with pytest.raises(ibrod.ConfigError) as e:
            ibrod.Simulation(c)
        assert "rod.initial_shape" in str(e.value) and words in str(e.value), str(e.value)
        r = run_cli(binary, ["run", "--set", f'rod.initial_shape="{spec}"', "--set", "grid.n=16",
                             "--set", "grid.box_A=200", "--set", "rod.base_pairs=100",
                             "-o", str(tmp_path / "x")])
        assert r.returncode == 2 and str(e.value) in r.stderr
        assert not (tmp_path / "x").exists()  # refused before anything is written
    c = cfg.copy()
    c["rod.base_pairs"] = 120
    c["rod.initial_shape"] = str(a / "final_state.csv")
    with pytest.raises(ibrod.ConfigError) as e:
        ibrod.Simulation(c)
    assert "100 positions" in str(e.value) and "rod.base_pairs" in str(e.value)


def test_a_python_run_directory_continues_with_the_cli(binary, tmp_path, cfg):
    # Python runs 120 steps into DIR; `ibrod run --resume DIR` extends it to the 200 steps of
    # time.t_end_us = 0.02 and ends where one CLI run of 200 steps ends, bit for bit
    ref = ibrod.read_run(cli_run(binary, cfg, tmp_path, "cli"))
    out = tmp_path / "py"
    sim = ibrod.Simulation(cfg, output=str(out))
    sim.run(steps=120)
    assert ibrod.read_run(out)["config"]["time"]["t_end_us"] == pytest.approx(0.012)
    del sim  # closes the directory (one writer at a time)
    r = run_cli(binary, ["run", "--resume", str(out), "--set", "time.t_end_us=0.02"])
    assert r.returncode == 0, r.stderr
    got = ibrod.read_run(out)
    np.testing.assert_array_equal(got["final_state"]["positions"], ref["final_state"]["positions"])
    np.testing.assert_array_equal(got["final_state"]["triads"], ref["final_state"]["triads"])
    np.testing.assert_array_equal(got["timeseries"]["step"], ref["timeseries"]["step"])
