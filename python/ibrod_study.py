"""The study logic of the sweep report (python/ibrod_report.py) that works on run records alone,
without plotting, so that it can be tested on constructed inputs (tests/unit/python):

  perturbation sampling (MODEL §7, second item)
      sampling_groups(runs)   the runs that differ only in their perturbation
                              (rod.perturbation, rod.perturbation_random), grouped
      class_census(group)     their final states grouped by shape class: count, how many reached
                              equilibrium, the perturbations, the energy range, a representative
  stability of the twisted circle (MODEL §7, third item)
      circle_stability(run)   whether the circle was stable, as the stability test decided
      stability_bracket(...)  per Cs, the ΔLk between which the circle loses its stability

A run record is anything with `config` (the parsed config.toml), `summary` (the parsed
summary.json) and `ts` (timeseries.csv as a numpy structured array with `time_us` and `writhe`),
as ibrod_plot.Run. docs/analysis.md describes the rules.
"""
import copy
import json

# the keys whose values make the perturbation of a run; runs differing only in these (and in the
# sections below, which do not change the physics) sample perturbations at one (ΔLk, Cs)
PERTURBATION_KEYS = (("rod", "perturbation"), ("rod", "perturbation_random"))
IGNORED_SECTIONS = ("run", "output")

# a state with |Wr| below this is still the circle (as `stays_circular` of ibrod analyze)
CIRCLE_WRITHE = 0.05


def _physics_key(config):
    """The config without its perturbation and without the sections that do not change the
    physics, as a canonical string."""
    c = copy.deepcopy(config)
    for sec in IGNORED_SECTIONS:
        c.pop(sec, None)
    for sec, key in PERTURBATION_KEYS:
        c.get(sec, {}).pop(key, None)
    return json.dumps(c, sort_keys=True, default=str)


def _perturbation(config):
    rod = config.get("rod", {})
    return json.dumps([rod.get(k) for _, k in PERTURBATION_KEYS], sort_keys=True, default=str)


def perturbation_label(run):
    """How a run was perturbed: "seed S" for a random perturbation (with the deterministic list
    when it is not empty), else "ε = [...]", else "none"."""
    rod = run.config.get("rod", {})
    eps = list(rod.get("perturbation") or [])
    rnd = rod.get("perturbation_random") or {}
    parts = []
    if rnd.get("modes", 0) and rnd.get("amplitude", 0):
        parts.append(f"seed {rnd.get('seed', 0)}")
    if any(e != 0 for e in eps):
        parts.append("ε = [" + ", ".join(f"{e:g}" for e in eps) + "]")
    return " + ".join(parts) or "none"


def sampling_groups(runs):
    """Groups of at least two runs whose configurations are equal except for the perturbation
    (and the `run`/`output` sections), with at least two different perturbations. Each group is
    a list of runs in the given order; the groups are ordered by (ΔLk, Cs) of their first run."""
    by_key = {}
    for r in runs:
        by_key.setdefault(_physics_key(r.config), []).append(r)
    groups = [g for g in by_key.values()
              if len(g) >= 2 and len({_perturbation(r.config) for r in g}) >= 2]

    def order(g):
        c = g[0].config
        return (c.get("rod", {}).get("excess_link", 0), c.get("solvent", {}).get("salt_M", 0))
    return sorted(groups, key=order)


def _final(run, key):
    ts = run.ts
    return float(ts[key][-1]) if key in (ts.dtype.names or ()) else None


def shape_class(run):
    """The final state's class of `ibrod analyze` (summary.json shape.class), or "not analysed"."""
    return (run.summary.get("shape") or {}).get("class") or "not analysed"


def class_census(group):
    """The final states of `group` by shape class, most frequent first (ties by name). Each entry:
    class, count, equilibrium (how many stopped as a verified-or-not equilibrium: stop_reason
    "equilibrium"), runs, labels (perturbation_label of each), E_min_kT, E_max_kT (final
    E_total), writhe_min, writhe_max, representative (the run of lowest final E_total among those
    at equilibrium, else among all)."""
    classes = {}
    for r in group:
        classes.setdefault(shape_class(r), []).append(r)
    out = []
    for cls, members in classes.items():
        energies = [_final(r, "E_total_kT") for r in members]
        writhes = [_final(r, "writhe") for r in members]
        at_eq = [r for r in members if r.summary.get("stop_reason") == "equilibrium"]
        pool = at_eq or members
        rep = min(pool, key=lambda r: (_final(r, "E_total_kT") is None, _final(r, "E_total_kT") or 0))
        known_e = [e for e in energies if e is not None]
        known_w = [w for w in writhes if w is not None]
        out.append({
            "class": cls,
            "count": len(members),
            "equilibrium": len(at_eq),
            "runs": members,
            "labels": [perturbation_label(r) for r in members],
            "E_min_kT": min(known_e) if known_e else None,
            "E_max_kT": max(known_e) if known_e else None,
            "writhe_min": min(known_w) if known_w else None,
            "writhe_max": max(known_w) if known_w else None,
            "representative": rep,
        })
    out.sort(key=lambda e: (-e["count"], e["class"]))
    return out


def circle_stability(run):
    """Whether the twisted circle of `run` was stable, as its stability test decided.

    Returns a dict: verdict, one of
      "stable"        the first test found the circle (|Wr| < CIRCLE_WRITHE) stable
      "unstable"      the first test found the circle unstable (the kicked copy's energy ended
                      below the unperturbed continuation's)
      "left_circle"   a run without perturbation left the circle (|Wr| ≥ CIRCLE_WRITHE) before
                      any test: unstable without the test's help (round-off grew)
      "perturbed_away" a perturbed run left the circle before any test: undecided (the
                      perturbation may have been too large to tell)
      "not_tested"    no test at the circle and the rod stayed circular (the run ended before
                      E_K fell below time.stop_kinetic_kT, or the test is off)
    and time_us, E_before_kT, E_reference_kT, E_after_kT, writhe_after, seed, amplitude_rad,
    kick_A, dE_kT (of the deciding test, else None), reason (a short text). dE_kT is what the
    test decided on: the lowest the kicked copy's energy came relative to the unperturbed
    continuation's during the probe (E_difference_min_kT); in a summary.json written before that
    was recorded, E_after_kT − E_reference_kT, where E_reference_kT is the continuation's energy
    at the end (E_total_continuation_kT) or, older still, the energy at the test
    (E_total_before_kT)."""
    tests = run.summary.get("stability_tests") or []
    first = tests[0] if tests else None
    out = {"verdict": "not_tested", "time_us": None, "E_before_kT": None, "E_reference_kT": None,
           "E_after_kT": None, "writhe_after": None, "seed": None, "amplitude_rad": None,
           "kick_A": None, "dE_kT": None, "reason": ""}
    # the first time the rod left the circle, from the time series
    left_at = None
    ts = run.ts
    if "writhe" in (ts.dtype.names or ()):
        for t, w in zip(ts["time_us"], ts["writhe"]):
            if abs(w) >= CIRCLE_WRITHE:
                left_at = float(t)
                break
    if first is not None and abs(first.get("writhe_before", 1.0)) < CIRCLE_WRITHE and (
            left_at is None or first.get("time_us", 0) <= left_at):
        out.update(verdict="stable" if first.get("stable") else "unstable",
                   time_us=first.get("time_us"), E_before_kT=first.get("E_total_before_kT"),
                   E_reference_kT=first.get("E_total_continuation_kT",
                                            first.get("E_total_before_kT")),
                   E_after_kT=first.get("E_total_after_kT"),
                   writhe_after=first.get("writhe_after"), seed=first.get("seed"),
                   amplitude_rad=first.get("amplitude_rad"), kick_A=first.get("kick_A"))
        if first.get("E_difference_min_kT") is not None:
            out["dE_kT"] = first["E_difference_min_kT"]
        elif out["E_after_kT"] is not None and out["E_reference_kT"] is not None:
            out["dE_kT"] = out["E_after_kT"] - out["E_reference_kT"]
        out["reason"] = "the stability test at the circle"
        return out
    if left_at is not None:
        perturbed = perturbation_label(run) != "none"
        out.update(verdict="perturbed_away" if perturbed else "left_circle", time_us=left_at)
        out["reason"] = (f"|Wr| reached {CIRCLE_WRITHE} before any test at the circle"
                         + (f" (perturbation {perturbation_label(run)})" if perturbed else ""))
        return out
    if not run.config.get("time", {}).get("stability_test", True):
        out["reason"] = "time.stability_test = false"
    else:
        stop = run.summary.get("stop_reason", "no summary.json")
        out["reason"] = f"E_K never fell below time.stop_kinetic_kT (stop: {stop})"
    return out


def stability_bracket(verdicts):
    """`verdicts`: {ΔLk: verdict of circle_stability} at one Cs. Returns (the ΔLk of largest |ΔLk|
    found stable, the ΔLk of smallest |ΔLk| found unstable or left the circle, consistent):
    consistent is False when some |ΔLk| is stable above an unstable one (the threshold is then not
    one bracket). Either bound is None when no run gives it."""
    stable = sorted((k for k, v in verdicts.items() if v == "stable"), key=abs)
    unstable = sorted((k for k, v in verdicts.items() if v in ("unstable", "left_circle")), key=abs)
    hi_stable = stable[-1] if stable else None
    lo_unstable = unstable[0] if unstable else None
    consistent = hi_stable is None or lo_unstable is None or abs(hi_stable) < abs(lo_unstable)
    return hi_stable, lo_unstable, consistent
