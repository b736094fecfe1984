#!/usr/bin/env python3
"""Issue 24's table of the reference cells: implicit against explicit, each to 20 µs.

    cells_table.py RUNS_DIR

RUNS_DIR holds exp_CELL/ and imp_CELL/ run directories, CELL = dlkN_csC (examples/reference), and
imp_CELL.compare, the output of `ibrod compare exp_CELL imp_CELL --max-dwr 0.1 --max-final-de 0.5`.
Prints one markdown row per cell found: the comparison's numbers, the verdict, each run's steps
and wall time (from its summary.json and log) and the ratio of wall times.
"""
import json
import re
import sys
from pathlib import Path


def final_line(log):
    """(steps, wall s) from a run log's last 'ibrod: stopped' line, or (None, None)."""
    for line in reversed(Path(log).read_text().splitlines()):
        m = re.search(r"after (\d+) steps.*?; ([0-9.]+) s wall", line)
        if m:
            return int(m.group(1)), float(m.group(2))
    return None, None


def compare_numbers(path):
    text = Path(path).read_text()
    m = re.search(r"^compare: common_rows=.*$", text, re.M)
    if not m:
        return None
    kv = dict(re.findall(r"(\w+)=([^ ]+)", m.group(0)))
    kv["at"] = re.search(r"max_dWr=[^ ]+ at t=([^ ]+)", m.group(0)).group(1)
    kv["verdict"] = "PASS" if "compare: PASS" in text else "FAIL"
    last = [l for l in text.splitlines() if re.match(r"^\s+[0-9.]+\s", l)]
    kv["final_class"] = last[-1].split()[7] if last else "?"
    return kv


def main(root):
    root = Path(root)
    print("| cell (ΔLk, Cs) | max \\|ΔWr\\| (at µs) | ΔE_total at 20 µs (kT) | frames / shape mismatches "
          "| final shape | explicit steps, wall | implicit steps, wall | wall ratio | verdict |")
    print("|---|---|---|---|---|---|---|---|---|")
    for cmp in sorted(root.glob("imp_*.compare")):
        cell = cmp.name[len("imp_"):-len(".compare")]
        kv = compare_numbers(cmp)
        if kv is None:
            continue
        m = re.match(r"dlk(\d)_cs([0-9.]+)", cell)
        es, ew = final_line(root / f"exp_{cell}.log")
        is_, iw = final_line(root / f"imp_{cell}.log")
        ratio = f"{ew / iw:.1f}×" if ew and iw else "?"
        print(f"| ({m.group(1)}, {m.group(2)} M) | {float(kv['max_dWr']):.3f} ({float(kv['at']):g}) "
              f"| {float(kv['final_dE_kT']):+.3f} | {kv['common_frames']} / {kv['shape_mismatches']} "
              f"| {kv['final_class']} | {es}, {ew:.0f} s | {is_}, {iw:.0f} s | {ratio} | {kv['verdict']} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
