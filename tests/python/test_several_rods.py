"""Several rods ([[rods]], docs/config.md "Several rods") from Python: two charged rings stacked
30 Å apart repel through the fluid, mirror images of each other (the grid is symmetric about the
box centre and both rings are untwisted), so their centroids move apart by equal and opposite
amounts while the pair's mean stays put (Newton's third law between rods, through the fluid);
each ring's link is conserved; positions/set_state cover all points; a run's final_state.csv of
several rods restarts each rod exactly (rod.initial_shape per [[rods]] table); overlapping rods
and a wrong point count are refused with clear errors."""
import numpy as np
import pytest

import ibrod


def two_rings(gap=30.0):
    c = ibrod.Config()
    c.update({"grid.n": 16, "grid.box_A": 200, "rod.base_pairs": 100, "rod.excess_link": 0,
              "rod.perturbation": [0.0], "time.dt_ns": 0.1, "run.threads": 1,
              "run.fftw_measure": False, "output.every_steps": 100})
    c["rods.0.offset_A"] = [0.0, 0.0, -gap / 2]
    c["rods.1.offset_A"] = [0.0, 0.0, gap / 2]
    return c


def test_two_rings_repel_symmetrically_and_keep_their_link(tmp_path):
    sim = ibrod.Simulation(two_rings(), output=str(tmp_path / "run"))
    rods = sim.rods
    assert [(r["start"], r["stop"], r["closed"]) for r in rods] == [(0, 100, True),
                                                                    (100, 200, True)]
    X0 = sim.positions
    assert X0.shape == (200, 3)
    sim.run(steps=1000)
    X = sim.positions
    z0 = [X0[r["start"]:r["stop"], 2].mean() for r in rods]
    z = [X[r["start"]:r["stop"], 2].mean() for r in rods]
    d0, d1 = z[0] - z0[0], z[1] - z0[1]
    print(f"centroid z moves: rod 0 {d0:+.6g} Å, rod 1 {d1:+.6g} Å")
    assert d0 < -1e-3 and d1 > 1e-3  # apart: rod 0 down, rod 1 up
    assert abs(d0 + d1) < 1e-9 * abs(d0)  # mirror images: equal and opposite
    o = sim.observables()
    for r in range(2):
        assert np.all(np.abs(o[f"link_{r}"] - o[f"link_{r}"][0]) < 1e-6)
    assert o["closest_approach_A"][-1] > o["closest_approach_A"][0]
    assert o["dE_electro_kT"][-1] < 0  # the rings' mutual repulsion falls as they part
    # the run directory: rods.csv and the final state's rod column
    run = ibrod.read_run(tmp_path / "run")
    assert run["rods"] is not None and set(run["rods"]) >= {"link_0", "writhe_1", "twist_1"}
    assert np.array_equal(run["final_state"]["rod"], np.repeat([0, 1], 100))
    assert np.array_equal(run["final_state"]["positions"], X)


def test_initial_shape_of_each_rod_from_a_run_of_several(tmp_path):
    a = ibrod.Simulation(two_rings(), output=str(tmp_path / "a"))
    a.run(steps=200)
    del a
    c = two_rings()
    path = str(tmp_path / "a" / "final_state.csv")
    c["rods.0.initial_shape"] = path
    c["rods.1.initial_shape"] = path
    c["rods.0.offset_A"] = [0.0, 0.0, 0.0]
    c["rods.1.offset_A"] = [0.0, 0.0, 0.0]
    b = ibrod.Simulation(c)
    ref = ibrod.read_run(tmp_path / "a")["final_state"]
    assert np.array_equal(b.positions, ref["positions"])
    assert np.array_equal(b.triads, ref["triads"])
    # a run of one rod cannot take a file of several
    one = ibrod.Config()
    one.update({"grid.n": 16, "grid.box_A": 400, "rod.base_pairs": 200, "rod.excess_link": 0,
                "rod.initial_shape": path})
    with pytest.raises(ibrod.ConfigError, match="holds 2 rods"):
        ibrod.Simulation(one)


def test_bad_states_and_overlaps_are_refused():
    with pytest.raises(ibrod.ConfigError, match="overlap"):
        ibrod.Simulation(two_rings(gap=0.0))
    sim = ibrod.Simulation(two_rings())
    X, D = sim.positions, sim.triads
    with pytest.raises(ValueError, match=r"\(200, 3\)"):
        sim.set_state(X[:100], D[:100])
    Y = X.copy()
    Y[100:] = X[:100] + [0.0, 0.0, 1.0]  # rod 1 onto rod 0
    with pytest.raises(ValueError, match="overlap"):
        sim.set_state(Y, D)
    sim.set_state(X, D)  # its own state is fine


def test_cli_resume_of_several_rods_is_bitwise_and_python_equals_cli(tmp_path, binary):
    """`ibrod run` of two rings stopped at 0.02 µs and resumed to 0.04 µs equals the run straight
    to 0.04 µs in every file that grows (timeseries.csv, rods.csv) and in the final state; the
    Python module's run of the same configuration gives the same final state."""
    from conftest import run_cli

    toml = tmp_path / "two.toml"
    toml.write_text(two_rings().to_toml())
    full, part = str(tmp_path / "full"), str(tmp_path / "part")
    r = run_cli(binary, ["run", str(toml), "-o", full, "--set", "time.t_end_us=0.04"])
    assert r.returncode == 0, r.stderr
    r = run_cli(binary, ["run", str(toml), "-o", part, "--set", "time.t_end_us=0.02"])
    assert r.returncode == 0, r.stderr
    r = run_cli(binary, ["run", "--resume", part, "--set", "time.t_end_us=0.04"])
    assert r.returncode == 0, r.stderr
    for name in ("timeseries.csv", "rods.csv", "final_state.csv"):
        a = (tmp_path / "full" / name).read_bytes()
        b = (tmp_path / "part" / name).read_bytes()
        assert a == b, name
    c = two_rings()
    c["time.t_end_us"] = 0.04
    sim = ibrod.Simulation(c)
    sim.run(until_us=0.04)
    ref = ibrod.read_run(full)["final_state"]
    assert np.array_equal(sim.positions, ref["positions"])
