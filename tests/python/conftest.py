"""Shared pieces of the Python module's tests (run by CTest: PYTHONPATH=build/python and
IBROD_BINARY=build/app/ibrod are set there)."""
import os
import subprocess

import pytest

import ibrod


def small_config():
    """The integration tests' small case (tests/integration/helpers.hpp): a 100-point ring
    (r0 ≈ 54 Å) in a 200 Å box on a 16³ grid, Δt = 0.1 ns, FFTW_ESTIMATE plans (the same plans
    in every process, so that runs compare bit for bit), one thread."""
    c = ibrod.Config()
    c.update({"grid.n": 16, "grid.box_A": 200, "rod.base_pairs": 100, "rod.excess_link": 2,
              "time.dt_ns": 0.1, "time.t_end_us": 0.02, "output.every_steps": 50,
              "run.fftw_measure": False, "run.threads": 1})
    return c


@pytest.fixture
def cfg():
    return small_config()


@pytest.fixture
def binary():
    b = os.environ.get("IBROD_BINARY")
    if not b:
        pytest.skip("IBROD_BINARY is not set (CTest sets it)")
    return b


def run_cli(binary, args, **kw):
    """`ibrod ARGS`; returns the CompletedProcess (text)."""
    return subprocess.run([binary, *args], capture_output=True, text=True,
                          stdin=subprocess.DEVNULL, timeout=120, **kw)
