"""Issue 26 ([no-data-lost-2]) from Python: SIGTERM during Simulation.run() stops as Ctrl-C does
(checkpoint and final files) instead of killing the process (T3-9); a simulation advanced in a
worker thread gives the main thread's states bit for bit (T3-10); read_run and `ibrod report`
cope with a last CSV row cut short, name a damaged file, and refuse a directory that holds no
run (T3-6)."""
import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import ibrod

from conftest import run_cli

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON_DIR = os.path.join(HERE, "..", "..", "python")

CHILD = """
import sys
import ibrod
cfg = ibrod.Config()
cfg.update({"grid.n": 16, "grid.box_A": 200, "rod.base_pairs": 100, "rod.excess_link": 2,
            "time.dt_ns": 0.01, "output.every_steps": 20, "output.checkpoint_every_steps": 0,
            "run.fftw_measure": False, "run.threads": 1})
sim = ibrod.Simulation(cfg, output=sys.argv[1])
sim.run(steps=10_000_000)
"""


def test_sigterm_inside_run_writes_the_checkpoint_and_final_files(tmp_path):
    out = tmp_path / "run"
    p = subprocess.Popen([sys.executable, "-c", CHILD, str(out)], stdin=subprocess.DEVNULL,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    ts = out / "timeseries.csv"
    t0 = time.monotonic()
    while time.monotonic() - t0 < 120 and p.poll() is None:
        if ts.exists() and ts.read_text().count("\n") >= 5:  # header + rows at 0, 20, 40, 60
            break
        time.sleep(0.01)
    assert p.poll() is None, p.communicate()[0]
    p.send_signal(signal.SIGTERM)
    log = p.communicate(timeout=120)[0]
    # stopped as `ibrod run` stops on SIGTERM: after the checkpoint and the final files
    assert p.returncode == 128 + signal.SIGTERM, log
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stop_reason"] == "interrupted"
    # the only periodic checkpoint is step 0: the steps since then are kept, not lost
    assert summary["steps"] >= 60
    assert summary["checkpoint_step"] == summary["steps"]
    assert (out / "final_state.csv").exists()


def test_a_worker_thread_gives_the_main_threads_states_bit_for_bit(cfg):
    # the difference came from OpenMP's thread count, which is per thread: it needs more than one
    # core for the worker's default count to differ from run.threads = 1
    if (os.cpu_count() or 1) < 2 or os.environ.get("OMP_NUM_THREADS") == "1":
        pytest.skip("one core: a worker thread's default OpenMP thread count is 1 as well")

    def run(in_thread):
        sim = ibrod.Simulation(cfg)
        go = lambda: sim.run(steps=200)
        if in_thread:
            t = threading.Thread(target=go)
            t.start()
            t.join()
        else:
            go()
        return sim.positions, sim.triads

    (x0, d0), (x1, d1) = run(False), run(True)
    np.testing.assert_array_equal(x0, x1)
    np.testing.assert_array_equal(d0, d1)


def cut_run(tmp_path, cfg):
    """A run directory whose timeseries.csv ends in a row cut short (a killed writer)."""
    out = tmp_path / "run"
    ibrod.Simulation(cfg, output=str(out)).run(steps=100)  # rows at steps 0, 50, 100
    ts = out / "timeseries.csv"
    ts.write_text(ts.read_text() + "150,0.015,1.25,0.5")
    return out


def test_read_run_drops_a_cut_last_row_names_damaged_files_and_refuses_an_empty_dir(tmp_path, cfg):
    out = cut_run(tmp_path, cfg)
    run = ibrod.read_run(out)
    assert list(run["timeseries"]["step"]) == [0, 50, 100]
    for name, damage in [("summary.json", '{"steps": 1'), ("config.toml", "[grid\n"),
                         ("trajectory.h5md", "not HDF5"), ("final_state.csv", "x_A,y_A\n1,2\n")]:
        good = (out / name).read_bytes()
        (out / name).write_text(damage)
        with pytest.raises(ValueError, match=name):
            ibrod.read_run(out)
        (out / name).write_bytes(good)
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(FileNotFoundError, match="none of a run's files"):
        ibrod.read_run(empty)


def test_report_reads_a_run_whose_last_row_is_cut(tmp_path, cfg, binary):
    pytest.importorskip("matplotlib")
    out = cut_run(tmp_path, cfg)
    sys.path.insert(0, PYTHON_DIR)
    try:
        import ibrod_plot
    finally:
        sys.path.remove(PYTHON_DIR)
    assert list(ibrod_plot.Run(str(out)).ts["step"]) == [0, 50, 100]
    r = run_cli(binary, ["report", str(out), "-o", str(tmp_path / "report")])
    assert "Traceback" not in r.stderr, r.stderr
    assert r.returncode == 0, r.stderr
