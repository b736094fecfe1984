#!/usr/bin/python3
"""python/ibrod_study.py on constructed run records (no simulation): which runs form a
perturbation-sampling group, how their final states are counted by shape class, and how the
stability test's records decide whether the twisted circle was stable and bracket the threshold.

    /usr/bin/python3 tests/unit/python/test_study_logic.py

Registered in CTest (label unit) as unit.python_study_logic.
"""
import os
import sys
import unittest
from types import SimpleNamespace

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(ROOT, "python"))
import ibrod_study as st  # noqa: E402


def timeseries(times, writhes, energies=None):
    energies = energies if energies is not None else [100.0] * len(times)
    a = np.zeros(len(times), dtype=[("time_us", float), ("writhe", float), ("E_total_kT", float)])
    a["time_us"], a["writhe"], a["E_total_kT"] = times, writhes, energies
    return a


def run(dlk=4, cs=0.1, seed=None, eps=(), cls="plectonemic", stop="equilibrium", energy=100.0,
        wr=2.0, tests=None, writhes=None, threads=1, name=None, extra=None):
    rod = {"excess_link": dlk, "perturbation": list(eps), "base_pairs": 100}
    if seed is not None:
        rod["perturbation_random"] = {"modes": 6, "amplitude": 1.0, "seed": seed}
    config = {"rod": rod, "solvent": {"salt_M": cs}, "grid": {"n": 16},
              "run": {"threads": threads}, "output": {"every_steps": 10}}
    for sec, kv in (extra or {}).items():
        config.setdefault(sec, {}).update(kv)
    summary = {"stop_reason": stop, "shape": {"class": cls} if cls else None}
    if tests is not None:
        summary["stability_tests"] = tests
    w = writhes if writhes is not None else [0.0, wr]
    ts = timeseries(np.linspace(0, 1, len(w)), w, [energy + 10.0] * (len(w) - 1) + [energy])
    return SimpleNamespace(config=config, summary=summary, ts=ts, name=name or f"seed={seed}",
                           finished=stop == "equilibrium")


def probe(t, stable, wr_before=0.0, e0=150.0, e1=None, wr_after=0.0, seed=1):
    return {"step": 10, "time_us": t, "amplitude_rad": 0.05, "seed": seed,
            "E_total_before_kT": e0, "E_total_after_kT": e1 if e1 is not None else e0 + 0.01,
            "writhe_before": wr_before, "writhe_after": wr_after, "stable": stable}


class SamplingGroups(unittest.TestCase):
    def test_runs_differing_only_in_the_perturbation_form_one_group(self):
        seeds = [run(seed=s) for s in (1, 2, 3)]
        # a different (ΔLk, Cs), a different grid, and a lone run: not in the group
        other = [run(dlk=5, seed=1), run(dlk=5, seed=2), run(seed=4, extra={"grid": {"n": 32}})]
        # threads and output frequency do not change the physics: still in the group
        seeds.append(run(seed=5, threads=2))
        groups = st.sampling_groups(seeds + other)
        self.assertEqual([[r.config["rod"]["excess_link"] for r in g] for g in groups],
                         [[4, 4, 4, 4], [5, 5]])
        self.assertEqual([r.config["rod"]["perturbation_random"]["seed"] for r in groups[0]],
                         [1, 2, 3, 5])

    def test_deterministic_perturbations_sample_too_and_equal_ones_do_not(self):
        g = st.sampling_groups([run(eps=[1.0]), run(eps=[0.0, 1.0])])
        self.assertEqual(len(g), 1)
        # the same point twice (two copies of one configuration): no sampling
        self.assertEqual(st.sampling_groups([run(seed=1), run(seed=1)]), [])
        # a sweep over ΔLk is not a perturbation sampling
        self.assertEqual(st.sampling_groups([run(dlk=k, seed=1) for k in (1, 2, 3)]), [])

    def test_perturbation_label(self):
        self.assertEqual(st.perturbation_label(run(seed=7)), "seed 7")
        self.assertEqual(st.perturbation_label(run(eps=[1.0])), "ε = [1]")
        self.assertEqual(st.perturbation_label(run(seed=7, eps=[0.0, 0.5])), "seed 7 + ε = [0, 0.5]")
        self.assertEqual(st.perturbation_label(run(eps=[0.0])), "none")


class ClassCensus(unittest.TestCase):
    def test_counts_each_class_with_its_energies_and_lowest_energy_representative(self):
        g = [run(seed=1, cls="plectonemic", energy=120.0, wr=2.1),
             run(seed=2, cls="toroidal", energy=140.0, wr=1.8),
             run(seed=3, cls="plectonemic", energy=118.0, wr=2.2),
             run(seed=4, cls="plectonemic", energy=110.0, wr=2.0, stop="end_time"),
             run(seed=5, cls=None)]
        census = st.class_census(g)
        self.assertEqual([(e["class"], e["count"]) for e in census],
                         [("plectonemic", 3), ("not analysed", 1), ("toroidal", 1)])
        self.assertEqual(sum(e["count"] for e in census), len(g))
        p = census[0]
        self.assertEqual(p["equilibrium"], 2)
        self.assertEqual(p["labels"], ["seed 1", "seed 3", "seed 4"])
        self.assertEqual((p["E_min_kT"], p["E_max_kT"]), (110.0, 120.0))
        self.assertEqual((p["writhe_min"], p["writhe_max"]), (2.0, 2.2))
        # the lowest energy among the runs at equilibrium, not the unfinished seed 4
        self.assertIs(p["representative"], g[2])
        self.assertEqual(census[2]["E_min_kT"], 140.0)

    def test_without_an_equilibrium_the_lowest_energy_of_all(self):
        g = [run(seed=1, energy=50.0, stop="end_time"), run(seed=2, energy=40.0, stop="end_time")]
        self.assertIs(st.class_census(g)[0]["representative"], g[1])


class CircleStability(unittest.TestCase):
    def test_the_first_test_at_the_circle_decides(self):
        stable = run(dlk=1, tests=[probe(0.06, True)], writhes=[0.0, 0.0])
        v = st.circle_stability(stable)
        self.assertEqual(v["verdict"], "stable")
        self.assertEqual((v["time_us"], v["seed"], v["amplitude_rad"]), (0.06, 1, 0.05))
        unstable = run(dlk=3, tests=[probe(0.04, False, e1=140.0, wr_after=1.5),
                                     probe(3.0, True, wr_before=1.5)],
                       writhes=[0.0, 0.0, 1.5, 1.5], stop="equilibrium")
        v = st.circle_stability(unstable)
        self.assertEqual(v["verdict"], "unstable")  # the later, stable test is of the buckled rod
        self.assertEqual((v["E_before_kT"], v["E_after_kT"], v["writhe_after"]), (150.0, 140.0, 1.5))

    def test_the_energy_compared_is_the_continuation_s_when_recorded(self):
        t = probe(0.06, True, e0=150.0, e1=149.5)
        t["E_total_continuation_kT"] = 149.4  # the kicked copy ended above the continuation
        v = st.circle_stability(run(dlk=1, tests=[t], writhes=[0.0, 0.0]))
        self.assertEqual((v["E_before_kT"], v["E_reference_kT"], v["E_after_kT"]),
                         (150.0, 149.4, 149.5))
        self.assertAlmostEqual(v["dE_kT"], 0.1)
        # the lowest difference during the probe decides when recorded (a strongly unstable
        # state: both copies buckled by the end, the kicked one first)
        t["E_difference_min_kT"] = -6.8
        self.assertEqual(st.circle_stability(run(dlk=1, tests=[t], writhes=[0.0]))["dE_kT"], -6.8)
        # a summary.json from before the continuation was recorded: the energy at the test
        v = st.circle_stability(run(dlk=1, tests=[probe(0.06, True, e0=150.0)], writhes=[0.0]))
        self.assertEqual(v["E_reference_kT"], 150.0)

    def test_a_first_test_after_the_rod_left_the_circle_does_not_decide(self):
        # no perturbation: the circle buckled on its own before the kinetic-energy rule fired
        r = run(dlk=3, tests=[probe(2.0, True, wr_before=1.5)], writhes=[0.0, 0.01, 0.2, 1.5])
        v = st.circle_stability(r)
        self.assertEqual(v["verdict"], "left_circle")
        self.assertAlmostEqual(v["time_us"], 2 / 3)
        # perturbed: undecided
        r = run(dlk=3, seed=2, tests=[], writhes=[0.0, 0.2, 1.5])
        self.assertEqual(st.circle_stability(r)["verdict"], "perturbed_away")

    def test_no_test_at_a_circle_is_not_a_verdict(self):
        v = st.circle_stability(run(dlk=2, tests=[], writhes=[0.0, 0.001], stop="end_time"))
        self.assertEqual(v["verdict"], "not_tested")
        self.assertIn("end_time", v["reason"])
        off = run(dlk=2, tests=[], writhes=[0.0, 0.0], extra={"time": {"stability_test": False}})
        self.assertIn("stability_test = false", st.circle_stability(off)["reason"])

    def test_bracket(self):
        self.assertEqual(st.stability_bracket({1: "stable", 2: "stable", 3: "unstable",
                                               4: "left_circle", 5: "not_tested"}), (2, 3, True))
        self.assertEqual(st.stability_bracket({1: "stable", 2: "unstable", 3: "stable"}),
                         (3, 2, False))
        self.assertEqual(st.stability_bracket({1: "stable"}), (1, None, True))
        self.assertEqual(st.stability_bracket({4: "perturbed_away", 5: "not_tested"}),
                         (None, None, True))
        self.assertEqual(st.stability_bracket({-1: "stable", -3: "unstable"}), (-1, -3, True))


if __name__ == "__main__":
    unittest.main(verbosity=2)
