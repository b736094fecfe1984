"""Checks that ibrod works where it is installed: `python -m ibrod.test_installation`.

In a few seconds (at most 30 on 2 cores) it runs small rings through the compiled module and the
command line packed with it and checks, printing each number:
  1. a closed form: the bending energy of the untwisted discrete circle,
     E = (Δs/2) n a (2 sin(π/n)/Δs)² (relative error ≤ 1e-9);
  2. Σf = 0: the rod's forces add up to nothing, so the fluid's momentum stays 0 (its mean
     velocity ≤ 1e-12 of its largest) through 200 steps of a twisted ring (ΔLk = 2);
  3. the link kept: Lk = ΔLk at every row (|Lk − 2| ≤ 1e-9);
  4. Python and the command line are one program: `ibrod run` of the same configuration ends in
     the same state, bit for bit.
Exit status 0 when every check passes, 1 otherwise.
"""
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import ibrod
from ibrod._cli import binary

KB = 1.380649e-16  # erg/K


def small_ring():
    """A 100-point ring (r0 ≈ 54 Å) in a 200 Å box on a 16³ grid, Δt = 0.1 ns, 200 steps."""
    c = ibrod.Config()
    c.update({"grid.n": 16, "grid.box_A": 200, "rod.base_pairs": 100, "rod.excess_link": 2,
              "time.dt_ns": 0.1, "time.t_end_us": 0.02, "output.every_steps": 50,
              "run.fftw_measure": False, "run.threads": 1})
    return c


class Checks:
    def __init__(self):
        self.failed = 0

    def __call__(self, ok, what):
        print(f"  {'ok  ' if ok else 'FAIL'}  {what}", flush=True)
        self.failed += not ok


def main():
    t0 = time.monotonic()
    check = Checks()
    exe = binary()
    print(f"ibrod {ibrod.__file__}")
    print(f"      command line: {exe or 'not found'}")

    # 1. closed form
    c = small_ring()
    c.update({"rod.excess_link": 0, "rod.perturbation": [], "electrostatics.enabled": False,
              "steric.enabled": False})
    n, ds = c["rod.base_pairs"], c["rod.rise_A"]
    a = c["rod.bend_modulus_erg_cm"] * 1e24  # erg·cm → g Å³ s⁻²
    kT = KB * c["solvent.temperature_K"] * 1e16  # erg → g Å² s⁻²
    exact = n * ds / 2 * a * (2 * math.sin(math.pi / n) / ds) ** 2 / kT
    sim = ibrod.Simulation(c)
    sim.run(steps=1)
    e = sim.observables()["E_bend_kT"][0]
    check(abs(e / exact - 1) <= 1e-9,
          f"closed form: E_bend of the untwisted circle {e:.12g} kT, exact {exact:.12g} kT "
          f"(relative error {abs(e / exact - 1):.1e} ≤ 1e-9)")

    # 2.–3. a twisted ring in Python, into a run directory
    with tempfile.TemporaryDirectory(prefix="ibrod-selfcheck-") as tmp:
        c = small_ring()
        sim = ibrod.Simulation(c, output=os.path.join(tmp, "py"))
        worst_u = 0.0
        for _ in range(4):
            sim.run(steps=50)
            u = sim.fluid_velocity.reshape(3, -1)
            mean = np.abs(u.mean(axis=1)).max()
            worst_u = max(worst_u, mean / np.abs(u).max())
        check(worst_u <= 1e-12,
              f"Σf = 0: the fluid's mean velocity ≤ {worst_u:.1e} of its largest over "
              f"{sim.step} steps (≤ 1e-12)")
        lk = sim.observables()["link"]
        drift = float(np.abs(lk - 2).max())
        check(drift <= 1e-9, f"link kept: |Lk − 2| ≤ {drift:.1e} at {len(lk)} rows (≤ 1e-9)")

        # 4. the command line, same configuration
        if exe is None:
            check(False, "Python/CLI identity: no ibrod command line beside the module")
        else:
            toml = os.path.join(tmp, "ring.toml")
            with open(toml, "w") as f:
                f.write(c.to_toml())
            out = os.path.join(tmp, "cli")
            r = subprocess.run([exe, "run", toml, "-o", out], capture_output=True, text=True,
                               stdin=subprocess.DEVNULL, timeout=120)
            if r.returncode != 0:
                check(False, f"Python/CLI identity: `ibrod run` failed ({r.returncode}): "
                      f"{r.stderr.strip()}")
            else:
                X = ibrod.read_run(out)["final_state"]["positions"]
                same = np.array_equal(X, sim.positions)
                check(same, f"Python/CLI identity: `{os.path.basename(exe)} run` ends in the "
                      f"Python run's state bit for bit ({len(X)} points, max |ΔX| = "
                      f"{np.abs(X - sim.positions).max():.1e} Å)")

    dt = time.monotonic() - t0
    if check.failed:
        print(f"ibrod.test_installation: {check.failed} check(s) FAILED ({dt:.1f} s)")
        return 1
    print(f"ibrod.test_installation: all checks passed ({dt:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
