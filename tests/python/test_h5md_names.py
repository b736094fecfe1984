"""The trajectory is trajectory.h5md, which MDAnalysis opens by its name alone; a run directory
written before that (trajectory.h5, the same layout) is still read, analysed, rendered and
resumed in place."""
import os
import shutil

import numpy as np

import ibrod
from conftest import run_cli


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


def test_mdanalysis_opens_the_trajectory_by_name(binary, tmp_path, cfg):
    import MDAnalysis as mda

    cfg["output.frame_every_steps"] = 50
    out = cli_run(binary, cfg, tmp_path, "run")
    assert (out / "trajectory.h5md").exists() and not (out / "trajectory.h5").exists()
    run = ibrod.read_run(out)
    u = mda.Universe(str(out / "trajectory.h5md"))  # no topology, no format= argument
    assert len(u.atoms) == 100
    assert len(u.trajectory) == len(run["frames"]["step"]) == 5  # steps 0, 50, …, 200
    for i, ts in enumerate(u.trajectory):
        np.testing.assert_allclose(ts.positions, run["frames"]["positions"][i], atol=1e-3)
        assert abs(ts.time - run["frames"]["time_us"][i] * 1e6) < 1e-6  # ps
        np.testing.assert_allclose(ts.dimensions, [200, 200, 200, 90, 90, 90])


def test_a_run_with_the_old_name_is_still_read_and_resumed(binary, tmp_path, cfg):
    cfg["output.frame_every_steps"] = 50
    ref = cli_run(binary, cfg, tmp_path, "ref", "time.t_end_us=0.03")  # 300 steps straight
    old = cli_run(binary, cfg, tmp_path, "old")  # 200 steps, then renamed as an old run's file
    os.rename(old / "trajectory.h5md", old / "trajectory.h5")
    frames = ibrod.read_run(old)["frames"]
    assert frames is not None and list(frames["step"]) == [0, 50, 100, 150, 200]

    r = run_cli(binary, ["analyze", "--quiet", "--frames", str(old)])
    assert r.returncode == 0, r.stderr
    summary = ibrod.read_run(old)["summary"]
    assert summary["contacts"]["source"] == "trajectory.h5"
    r = run_cli(binary, ["render", str(old), "--time", "0.01", "--views", "top",
                         "--size", "64x64"])
    assert r.returncode == 0, r.stderr
    assert (old / "render").is_dir() and any((old / "render").iterdir())

    # the resume extends the old file in place (no second trajectory), bit for bit the
    # frames of the straight run
    r = run_cli(binary, ["run", "--resume", str(old), "--set", "time.t_end_us=0.03"])
    assert r.returncode == 0, r.stderr
    assert not (old / "trajectory.h5md").exists()
    a, b = ibrod.read_run(old)["frames"], ibrod.read_run(ref)["frames"]
    assert list(a["step"]) == list(b["step"]) == [0, 50, 100, 150, 200, 250, 300]
    np.testing.assert_array_equal(a["positions"], b["positions"])

    # rod.initial_shape names either file
    shutil.copy(old / "trajectory.h5", tmp_path / "copy.h5")
    c = ibrod.Config()
    c["rod.initial_shape"] = f"{tmp_path / 'copy.h5'}@2"
    c["rod.base_pairs"] = 100
    c["grid.n"] = 16
    c["grid.box_A"] = 200
    c["rod.excess_link"] = 2
    sim = ibrod.Simulation(c)
    np.testing.assert_array_equal(sim.positions, a["positions"][2])
