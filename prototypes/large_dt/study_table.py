#!/usr/bin/env python3
"""The whole study's table (issue 24): one row per cell of a sweep directory.

For each point of `ibrod sweep prototypes/large_dt/study_path.toml -o STUDY`: how it stopped and
when, its steps, Stokes solves and wall time, the stability tests it ran, its final Wr, E_total
and shape, and, where an explicit run of the same cell is given (--explicit CELL=DIR, e.g.
dlk5_cs0.1=runs/exp_dlk5_cs0.1), `ibrod compare` over their common times (max |ΔWr|, ΔE_total at
the explicit run's last time, shape mismatches at every frame).

    study_table.py STUDY [--ibrod build/app/ibrod] [--explicit dlk4_cs0.1=DIR ...] [--json F]

Prints a Markdown table and the sums (wall time of the cells run so far, the 2-core wall time of
the sweep from its log when given with --sweep-log).
"""
import argparse
import json
import os
import re
import subprocess
import sys


def cell_key(name):
    m = re.match(r"dlk=(\d+)_salt_M=([0-9.]+)$", name)
    return (int(m.group(1)), float(m.group(2))) if m else None


def shape_of(ibrod, run):
    """Shape class and loops of the run's last state (`ibrod analyze`, which adds them to
    summary.json, as `ibrod report --ibrod` does)."""
    subprocess.run([ibrod, "analyze", "--quiet", run], capture_output=True, text=True, timeout=600)
    sh = json.load(open(os.path.join(run, "summary.json"))).get("shape") or {}
    return "%s/%s" % (sh.get("class", "?"), sh.get("loops", "?"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("study")
    ap.add_argument("--ibrod", default="build/app/ibrod")
    ap.add_argument("--explicit", nargs="*", default=[])
    ap.add_argument("--json")
    ap.add_argument("--no-shapes", action="store_true")
    a = ap.parse_args()

    refs = {}
    for e in a.explicit:
        k, v = e.split("=", 1)
        m = re.match(r"dlk(\d+)_cs([0-9.]+)$", k)
        refs[(int(m.group(1)), float(m.group(2)))] = v

    rows = []
    for name in sorted(os.listdir(a.study), key=lambda n: cell_key(n) or (99, 0)):
        key = cell_key(name)
        run = os.path.join(a.study, name)
        if key is None or not os.path.isdir(run):
            continue
        sj = os.path.join(run, "summary.json")
        if not os.path.exists(sj):
            rows.append({"cell": key, "state": "not started or running"})
            continue
        s = json.load(open(sj))
        tests = s.get("stability_tests") or []
        verdicts = ", ".join("%.1f µs %s (%+.2g kT)" % (t["time_us"], "stable" if t["stable"] else "unstable",
                                                      t["E_difference_min_kT"]) for t in tests)
        r = {
            "cell": key, "state": s["stop_reason"], "t_us": s["time_us"], "steps": s["steps"],
            "solves": s.get("implicit_stokes_solves"), "wall_s": s.get("total_wall_time_s"),
            "tests": verdicts or "none", "verified": s.get("equilibrium_verified"),
            "Wr": s["final"]["writhe"], "E": s["final"]["E_total_kT"],
            "closest": s["final"]["closest_approach_A"],
        }
        if not a.no_shapes:
            r["shape"] = shape_of(a.ibrod, run)
        if key in refs:
            tmp = os.path.join(run, "compare_explicit.json")
            out = subprocess.run([a.ibrod, "compare", refs[key], run, "--json", tmp],
                                 capture_output=True, text=True, timeout=600)
            try:
                c = json.load(open(tmp))
                r["cmp"] = {"max_dWr": c["max_abs_dWr"], "at": c["max_abs_dWr_time_us"],
                            "until": c["final_time_us"], "dE": c["final_dE_total_kT"],
                            "mismatch": c["shape_mismatches"], "frames": c["common_frames"]}
            except Exception:  # noqa: BLE001
                r["cmp"] = {"error": (out.stderr or out.stdout)[-200:]}
        rows.append(r)

    print("| cell | stop | t (µs) | steps | Stokes solves | wall (s) | stability tests | Wr | E_total (kT) | "
          "closest (Å) | shape | vs explicit: max abs ΔWr (at), ΔE at its end, shape mismatches |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    wall = 0.0
    for r in rows:
        d, c = r["cell"]
        if "steps" not in r:
            print("| (%d, %g M) | %s |||||||||||" % (d, c, r["state"]))
            continue
        wall += r["wall_s"] or 0.0
        cmp = r.get("cmp")
        if cmp is None:
            ctext = "no explicit run"
        elif "error" in cmp:
            ctext = "compare failed: " + cmp["error"].replace("\n", " ")
        else:
            ctext = "%.4f (%.1f µs), %+.4f kT at %.0f µs, %d of %d" % (
                cmp["max_dWr"], cmp["at"], cmp["dE"], cmp["until"], cmp["mismatch"], cmp["frames"])
        print("| (%d, %g M) | %s | %.1f | %d | %s | %.0f | %s | %.4f | %.3f | %.1f | %s | %s |" % (
            d, c, r["state"] + (" (verified)" if r["verified"] else ""), r["t_us"], r["steps"],
            r["solves"], r["wall_s"] or 0, r["tests"], r["Wr"], r["E"], r["closest"],
            r.get("shape", ""), ctext))
    print()
    print("cells with a summary: %d; their wall time summed: %.0f s (%.2f h; on 2 cores at best half)" % (
        sum(1 for r in rows if "steps" in r), wall, wall / 3600))
    if a.json:
        json.dump(rows, open(a.json, "w"), indent=1, default=str)


if __name__ == "__main__":
    sys.exit(main())
