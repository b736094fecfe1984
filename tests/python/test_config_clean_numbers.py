"""config.toml carries the numbers the user gave, and clean defaults: every key's value
round-trips as written (0.1 stays 0.1), no default is a unit conversion's noise
(steric.stiffness read 0.0999988652679525), and a Python segment of N steps ends at a clean
time.t_end_us (0.02, not 0.020000000000000004)."""
import re

import pytest

import ibrod
from conftest import run_cli

NUMBER = re.compile(r"^([a-z_]+) = (.*?)\s+# ", re.M)


def significant_digits(text):
    """Significant digits of each number in a TOML value text (arrays and inline tables too)."""
    out = []
    for m in re.finditer(r"-?\d+\.?\d*(?:[eE][-+]?\d+)?", text):
        mant = re.split(r"[eE]", m.group(0))[0].lstrip("-").replace(".", "").lstrip("0")
        out.append(len(mant.rstrip("0")) if "." in m.group(0) else len(mant))
    return out


def floats(cfg):
    return [k for k in cfg.keys() if isinstance(cfg[k], float)]


def test_defaults_are_clean():
    text = ibrod.Config().to_toml()
    values = dict(NUMBER.findall(text))
    assert values["stiffness"] == "0.1"
    noisy = {k: v for k, v in values.items() if any(d > 10 for d in significant_digits(v))}
    assert not noisy, f"defaults with float noise: {noisy}"


def test_every_float_key_round_trips_the_value_given():
    cfg = ibrod.Config()
    keys = floats(cfg)
    assert len(keys) >= 20  # the dimensional parameters, times, tolerances
    tried = 0
    for key in keys:
        default = cfg[key]
        # a "typed by hand" value near the default: 3 significant digits, ×1.1
        for v in (float(f"{default * 1.1:.3g}"), float(f"{default:.3g}")):
            c = ibrod.Config()
            try:
                c[key] = v
            except ibrod.ConfigError:
                continue
            line = [ln for ln in c.to_toml().splitlines()
                    if ln.startswith(key.split(".", 1)[1] + " = ")]
            section = "[" + key.split(".")[0] + "]"
            text = c.to_toml()
            after = text[text.index(section):]
            m = re.search(rf"^{re.escape(key.split('.', 1)[1])} = (\S+)", after, re.M)
            assert m and float(m.group(1)) == v and m.group(1) == repr(v), (key, v, line)
            tried += 1
            break
    assert tried >= len(keys) - 2, (tried, len(keys))


def test_cli_and_python_write_clean_numbers(binary, tmp_path, cfg):
    p = tmp_path / "c.toml"
    p.write_text(cfg.to_toml())
    out = tmp_path / "cli"
    r = run_cli(binary, ["run", str(p), "-o", str(out), "--set", "steric.stiffness=0.3",
                         "--set", "solvent.salt_M=0.07", "--set", "time.t_end_us=0.003"])
    assert r.returncode == 0, r.stderr
    text = (out / "config.toml").read_text()
    for line in ("stiffness = 0.3 ", "salt_M = 0.07 ", "t_end_us = 0.003 ", "dt_ns = 0.1 "):
        assert line in text, line
    # Python segments: the end time is the steps run, written cleanly
    sim = ibrod.Simulation(cfg, output=str(tmp_path / "py"))
    sim.run(steps=30)
    sim.run(steps=170)
    assert sim.step == 200
    text = (tmp_path / "py" / "config.toml").read_text()
    assert re.search(r"^t_end_us = 0\.02 ", text, re.M), text
    assert sim.config["time.t_end_us"] == pytest.approx(0.02, abs=0)


def test_the_default_steric_stiffness_is_the_documented_one():
    # docs/config.md: 0.1 kT/Å²
    assert ibrod.Config()["steric.stiffness"] == 0.1
