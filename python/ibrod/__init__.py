"""ibrod from Python: configure, run and read simulations of elastic rods in a viscous fluid.

The same C++ core as the command line `ibrod` (docs/python.md)::

    import ibrod
    cfg = ibrod.Config("run.toml")        # or ibrod.Config() for the defaults
    cfg["rod.excess_link"] = 4             # the keys, types and checks of TOML and --set
    sim = ibrod.Simulation(cfg)            # output="DIR" writes the usual run directory
    sim.run(steps=1000)                    # or sim.run(until_us=2.0); Ctrl-C stops cleanly
    X, D = sim.positions, sim.triads       # (n, 3) Å; (n, 3, 3), row i of D[k] is D^(i+1)
    obs = sim.observables()                # the time-series columns as numpy arrays
    run = ibrod.read_run("DIR")            # a run directory's files as numpy arrays / dicts

Import it with the build's python folder on the path: PYTHONPATH=build/python.
"""
import io
import json
import math
import numbers
import os
import tomllib
import warnings

import numpy as np

from ._core import Config as _CoreConfig
from ._core import ConfigError, RunError
from ._core import Simulation as _CoreSimulation

__all__ = ["Config", "Simulation", "ConfigError", "RunError", "read_run", "trajectory_path"]
ConfigError.__module__ = RunError.__module__ = "ibrod"  # shown as ibrod.ConfigError


def _toml_value(value, key):
    """A Python value as TOML value text (what `--set key=TEXT` would be given)."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        v = float(value)
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(value, (str, os.PathLike)):
        return json.dumps(os.fspath(value))  # a TOML basic string (JSON's escapes are TOML's)
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(v, key)}" for k, v in value.items()) + " }"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_value(v, key) for v in value) + "]"
    raise ConfigError(f"config: {key} = {value!r}: a {type(value).__name__} is not a TOML "
                      "number, boolean, string, array or table")


class Config(_CoreConfig):
    """A configuration: every key of docs/config.md with its default.

    Config(path=None) reads a TOML file on top of the defaults. cfg["section.key"] = value sets
    a key through the same schema as TOML and `ibrod run --set` (a bad key or value raises
    ibrod.ConfigError with the CLI's message); cfg["section.key"] reads it back as resolved.
    """

    def __init__(self, path=None):
        super().__init__(None if path is None else os.fspath(path))

    def __setitem__(self, key, value):
        self._set_toml(key, _toml_value(value, key))

    def __getitem__(self, key):
        node = tomllib.loads(self.to_toml())
        for part in key.split("."):
            if not isinstance(node, dict) or part not in node:
                raise KeyError(f"config: unknown key '{key}' (keys: {', '.join(self.keys())})")
            node = node[part]
        return node

    def keys(self):
        """Every key as "section.key", in the order of docs/config.md."""
        return [f"{s}.{k}" for s, t in tomllib.loads(self.to_toml()).items() for k in t]

    def update(self, values):
        """Set several keys: cfg.update({"grid.n": 32, "rod.excess_link": 2})."""
        for k, v in dict(values).items():
            self[k] = v

    def copy(self):
        """An independent copy."""
        c = Config()
        c._assign(self)
        return c

    def __repr__(self):
        return "ibrod.Config(\n" + self.describe() + ")"


class Simulation(_CoreSimulation):
    __doc__ = _CoreSimulation.__doc__

    @property
    def config(self):
        """The configuration as run (a copy; time.t_end_us: the end of the latest segment)."""
        c = Config()
        c._assign(_CoreSimulation.config.fget(self))
        return c


def _damaged(path, e):
    """A file of a run that cannot be read: a ValueError naming it (the cause chained)."""
    return ValueError(f"read_run: {path} cannot be read: {e}")


def _read_csv(path):
    """A CSV of a run as dict column -> array. A last row cut short by a killed run (no newline at
    its end) is dropped, as `ibrod analyze` and `--resume` drop it."""
    try:
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as e:
        raise _damaged(path, e) from e
    if text and not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    if not text.strip():
        raise _damaged(path, "it is empty (no header line)")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a header without rows: an empty table
            a = np.genfromtxt(io.StringIO(text), delimiter=",", names=True, dtype=float)
    except ValueError as e:
        raise _damaged(path, e) from e
    a = np.atleast_1d(a)
    if a.dtype.names is None:
        raise _damaged(path, "no header line of column names")
    out = {n: np.asarray(a[n]) for n in a.dtype.names}
    if "step" in out:
        out["step"] = np.nan_to_num(out["step"]).astype(np.int64)
    return out


def _triads(d1, d2, d3):
    """(…, n, 3) columns D¹, D², D³ → (…, n, 3, 3) with row i = D^(i+1)."""
    return np.stack([d1, d2, d3], axis=-2)


def trajectory_path(path):
    """The H5MD trajectory of run directory `path`: trajectory.h5md, or trajectory.h5 of a run
    written before the file took H5MD's extension; None when there is neither."""
    for name in ("trajectory.h5md", "trajectory.h5"):
        p = os.path.join(os.fspath(path), name)
        if os.path.exists(p):
            return p
    return None


def read_run(path):
    """Read a run directory (of `ibrod run` or Simulation(output=...)) into numpy arrays.

    Returns a dict with:
      "timeseries":  dict column -> (R,) array (timeseries.csv: step, time_us, energies in kT, …)
      "frames":      dict "step" (T,), "time_us" (T,), "positions" (T, n, 3) Å, "triads"
                     (T, n, 3, 3) (row i = D^(i+1)) from trajectory.h5md (or an older run's
                     trajectory.h5); None without one (needs h5py)
      "final_state": dict "positions" (n, 3), "triads" (n, 3, 3) from final_state.csv, or None;
                     with several rods also "rod" (n,): each point's rod
      "rods":        several rods: rods.csv as dict column -> (R,) array (step, time_us,
                     writhe_r, twist_r, link_r of each rod r); None for one rod
      "summary":     summary.json as a dict, or None
      "config":      config.toml as a dict (section -> key -> value)
    Missing directory, or one that holds none of these files: FileNotFoundError. A file that
    cannot be read (damaged, cut short, not what its name says): ValueError naming the file.
    """
    path = os.fspath(path)
    if not os.path.isdir(path):
        raise FileNotFoundError(f"read_run: {path} is not a directory")
    names = ("timeseries.csv", "trajectory.h5md", "trajectory.h5", "final_state.csv", "summary.json", "config.toml",
             "rods.csv")
    if not any(os.path.exists(os.path.join(path, n)) for n in names):
        raise FileNotFoundError(f"read_run: {path} holds none of a run's files ({', '.join(names)})"
                                ": it is not the output directory of a run")
    out = {"timeseries": None, "frames": None, "final_state": None, "summary": None,
           "config": None, "rods": None}
    p = os.path.join(path, "rods.csv")
    if os.path.exists(p):
        out["rods"] = _read_csv(p)
    p = os.path.join(path, "timeseries.csv")
    if os.path.exists(p):
        out["timeseries"] = _read_csv(p)
    p = os.path.join(path, "final_state.csv")
    if os.path.exists(p):
        f = _read_csv(p)
        col = lambda *names: np.stack([f[n] for n in names], axis=-1)
        try:
            out["final_state"] = {
                "positions": col("x_A", "y_A", "z_A"),
                "triads": _triads(col("d1x", "d1y", "d1z"), col("d2x", "d2y", "d2z"),
                                  col("d3x", "d3y", "d3z")),
            }
        except KeyError as e:
            raise _damaged(p, f"no column {e}") from e
        if "rod" in f:
            out["final_state"]["rod"] = f["rod"].astype(int)
    p = os.path.join(path, "summary.json")
    if os.path.exists(p):
        try:
            with open(p) as fh:
                out["summary"] = json.load(fh)
        except (OSError, ValueError) as e:  # json.JSONDecodeError, UnicodeDecodeError
            raise _damaged(p, e) from e
    p = os.path.join(path, "config.toml")
    if os.path.exists(p):
        try:
            with open(p, "rb") as fh:
                out["config"] = tomllib.load(fh)
        except (OSError, ValueError) as e:  # tomllib.TOMLDecodeError
            raise _damaged(p, e) from e
    p = trajectory_path(path)
    if p is not None:
        import h5py

        # without file locking, as ibrod writes it (io/h5md.cpp): a Simulation of this process
        # may hold the file open
        try:
            with h5py.File(p, "r", locking=False) as h:
                rod = h["particles/rod"]
                t = rod["position/time"]
                unit = t.attrs.get("unit", b"ns")
                unit = unit.decode() if isinstance(unit, bytes) else str(unit)
                out["frames"] = {
                    "step": rod["position/step"][()],
                    # ns since the units are MDAnalysis's; µs in the oldest files
                    "time_us": t[()] * (1.0 if unit == "µs" else 1e-3),
                    "positions": rod["position/value"][()],
                    "triads": _triads(rod["d1/value"][()], rod["d2/value"][()],
                                      rod["d3/value"][()]),
                }
        except (OSError, KeyError, ValueError) as e:  # h5py: not HDF5, truncated, no such group
            raise _damaged(p, e) from e
    return out
