#!/usr/bin/python3
"""End to end: the files of `ibrod run` open with standard tools alone, and agree with each other.

Runs IBROD (argv[1]) on a small configuration, then checks
  trajectory.h5md  with h5py: the H5MD layout (docs/outputs.md), step/time/value shapes and types,
                 the observables against timeseries.csv, the config against config.toml and the
                 last frame against final_state.csv;
  rod.pvd, vtk/*.vtp, fluid.pvd, vtk/*.vti  with xml.etree: VTKFile type/version/byte_order,
                 one Piece, array sizes against NumberOfPoints/NumberOfLines/extents, component
                 counts, a closed polyline, points equal to the H5MD frames, DataSet files present.
  trajectory.h5md  with MDAnalysis too, opened by name (mda.Universe(path)): atoms, frames,
                 positions, times, box;
  vtk/*.vtp, vtk/*.vti  with VTK's own readers too (python3-vtk9: vtkXMLPolyDataReader,
                 vtkXMLImageDataReader): points, the closed line, arrays, dimensions, spacing;
Exit status 0 if every check passes; the first failed check is printed.
Must run with /usr/bin/python3 (numpy and h5py from Debian).
"""
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import h5py
import numpy as np

CONFIG = """
[grid]
n = 16
box_A = 200
[rod]
base_pairs = 100
excess_link = 2
[time]
dt_ns = 0.1
t_end_us = 0.025
[output]
every_steps = 20
frame_every_steps = 50
checkpoint_every_steps = 100
fluid_vti = true
[run]
threads = 1
fftw_measure = false
"""
N, GRID, BOX, STEPS, FRAME_EVERY, ROW_EVERY = 100, 16, 200.0, 250, 50, 20


def check(cond, what):
    if not cond:
        raise AssertionError(what)


def numbers(array_el):
    return np.array(array_el.text.split(), dtype=float)


def check_h5md(d):
    f = h5py.File(os.path.join(d, "trajectory.h5md"), "r")
    check(list(f["h5md"].attrs["version"]) == [1, 1], "/h5md version [1, 1]")
    check(len(f["h5md/author"].attrs["name"]) > 0, "/h5md/author name")
    check(f["h5md/creator"].attrs["name"] == "ibrod", "/h5md/creator name")
    check(len(f["h5md/creator"].attrs["version"]) > 0, "/h5md/creator version")
    # the particle group rod, and the soft link MDAnalysis counts atoms in (docs/outputs.md)
    check(sorted(f["particles"].keys()) == ["rod", "trajectory"], "/particles: rod, trajectory")
    check(f["particles"].get("trajectory", getlink=True).path == "/particles/rod",
          "/particles/trajectory links to /particles/rod")
    box = f["particles/rod/box"]
    check(int(box.attrs["dimension"]) == 3, "box dimension 3")
    check([str(b) for b in box.attrs["boundary"]] == ["periodic"] * 3, "box boundary periodic")
    check(np.allclose(box["edges/value"][()],
                      [np.diag([BOX] * 3)] * len(range(0, STEPS + 1, FRAME_EVERY))),
          "box edges: the box vectors as a 3 × 3 matrix, one record per frame")

    frames = list(range(0, STEPS + 1, FRAME_EVERY))
    for el in ("position", "d1", "d2", "d3"):
        g = f["particles/rod/" + el]
        check(g["step"].dtype == np.int64 and g["time"].dtype == np.float64, el + " step/time types")
        check(list(g["step"][()]) == frames, el + " steps %s" % list(g["step"][()]))
        check(np.allclose(g["time"][()], np.array(frames) * 0.1, rtol=1e-12), el + " time in ns")
        check(g["time"].attrs["unit"] == "ns", el + " time unit ns")
        v = g["value"]
        check(v.dtype == np.float64 and v.shape == (len(frames), N, 3), el + " value shape")
        check(v.chunks is not None and v.maxshape[0] is None, el + " value chunked, extendible")
    check(f["particles/rod/position/value"].attrs["unit"] == "Angstrom", "position unit Angstrom")
    check(box["edges/value"].attrs["unit"] == "Angstrom", "box edges unit Angstrom")

    # triads orthonormal in every frame
    D = np.stack([f["particles/rod/d%d/value" % i][()] for i in (1, 2, 3)], axis=-1)
    err = np.abs(np.einsum("tnki,tnkj->tnij", D, D) - np.eye(3)).max()
    check(err < 1e-10, "triads orthonormal (%g)" % err)

    # the last frame is the final state
    fs = np.genfromtxt(os.path.join(d, "final_state.csv"), delimiter=",", names=True)
    pos = f["particles/rod/position/value"][-1]
    for i, c in enumerate("xyz"):
        check(np.allclose(pos[:, i], fs[c + "_A"], rtol=1e-10, atol=1e-9), "final positions " + c)
        for k in (1, 2, 3):
            dk = f["particles/rod/d%d/value" % k][-1]
            check(np.allclose(dk[:, i], fs["d%d%s" % (k, c)], atol=1e-13), "final d%d" % k)

    # observables: every time-series column but step and time_us
    ts = np.genfromtxt(os.path.join(d, "timeseries.csv"), delimiter=",", names=True)
    columns = [c for c in ts.dtype.names if c not in ("step", "time_us")]
    check(sorted(columns) == sorted(f["observables"].keys()), "observables = CSV columns")
    for c in columns:
        g = f["observables/" + c]
        check(list(g["step"][()]) == list(ts["step"].astype(int)), c + " steps")
        check(np.allclose(g["time"][()], ts["time_us"] * 1e3, rtol=1e-9), c + " time (ns)")
        unit = "kT" if c.endswith("_kT") else "Angstrom" if c.endswith("_A") else None
        check(g["value"].attrs.get("unit") == unit, c + " unit %s" % unit)
        # the CSV prints 10 to 12 significant digits
        check(np.allclose(g["value"][()], ts[c], rtol=1e-9, atol=1e-12), c + " values")
    rows = list(range(0, STEPS, ROW_EVERY)) + [STEPS]  # and a last row at the end
    check(list(ts["step"].astype(int)) == rows, "CSV rows")

    with open(os.path.join(d, "config.toml")) as c:
        check(f["parameters/config_toml"].asstr()[()] == c.read(), "config_toml = config.toml")
    # positions (Å) and times in µs, as the .pvd files give them
    return f["particles/rod/position/value"][()], f["particles/rod/position/time"][()] * 1e-3


def check_mdanalysis(d, positions):
    """MDAnalysis opens the trajectory by its name alone (the .h5md extension tells the format):
    N atoms, every frame with its positions in Å, its time in ps and the periodic box."""
    import MDAnalysis as mda
    u = mda.Universe(os.path.join(d, "trajectory.h5md"))
    check(len(u.atoms) == N, "MDAnalysis: %d atoms" % len(u.atoms))
    traj = u.trajectory
    check(len(traj) == len(positions), "MDAnalysis: %d frames" % len(traj))
    for i, (ts, x) in enumerate(zip(traj, positions)):
        check(np.allclose(ts.positions, x, rtol=1e-5, atol=1e-3), "MDAnalysis: positions in Å")
        check(abs(ts.time - i * FRAME_EVERY * 0.1 * 1e3) < 1e-6, "MDAnalysis: time in ps")
        check(np.allclose(ts.dimensions, [BOX] * 3 + [90.0] * 3), "MDAnalysis: box")


def check_vtkfile(path, kind):
    root = ET.parse(path).getroot()
    check(root.tag == "VTKFile", path + ": root VTKFile")
    check(root.get("type") == kind, path + ": type " + kind)
    check(root.get("version") in ("0.1", "1.0"), path + ": version")
    check(root.get("byte_order") == "LittleEndian", path + ": byte_order")
    return root


def data_arrays(parent):
    return {a.get("Name"): a for a in parent.findall("DataArray")}


def check_vtp(path, points_expected):
    root = check_vtkfile(path, "PolyData")
    pieces = root.findall("PolyData/Piece")
    check(len(pieces) == 1, path + ": one Piece")
    p = pieces[0]
    n, nl = int(p.get("NumberOfPoints")), int(p.get("NumberOfLines"))
    check(n == N and nl == 1, path + ": NumberOfPoints/NumberOfLines")
    pts = p.find("Points/DataArray")
    check(pts.get("NumberOfComponents") == "3", path + ": Points components")
    xyz = numbers(pts)
    check(xyz.size == 3 * n, path + ": Points count")
    check(np.allclose(xyz.reshape(n, 3), points_expected, rtol=1e-9, atol=1e-8),
          path + ": points = H5MD frame")
    pd = data_arrays(p.find("PointData"))
    for name, comps in (("d1", 3), ("d2", 3), ("d3", 3), ("twist_density_rad_per_A", 1),
                        ("stretch_strain", 1)):
        check(name in pd, path + ": point data " + name)
        check(int(pd[name].get("NumberOfComponents", "1")) == comps, path + ": " + name + " comps")
        v = numbers(pd[name])
        check(v.size == comps * n and np.all(np.isfinite(v)), path + ": " + name + " count")
    check(np.all(np.abs(numbers(pd["stretch_strain"])) < 0.5), path + ": stretch strain sane")
    lines = data_arrays(p.find("Lines"))
    conn, off = numbers(lines["connectivity"]), numbers(lines["offsets"])
    check(off.size == nl and int(off[-1]) == conn.size, path + ": offsets")
    check(conn.size == n + 1 and conn[0] == conn[-1] == 0, path + ": closed polyline")
    check(sorted(set(conn.astype(int))) == list(range(n)), path + ": every point on the line")


def check_vti(path):
    root = check_vtkfile(path, "ImageData")
    img = root.find("ImageData")
    ext = [int(x) for x in img.get("WholeExtent").split()]
    check(ext == [0, GRID - 1] * 3, path + ": WholeExtent")
    check(np.allclose([float(x) for x in img.get("Spacing").split()], BOX / GRID), path + ": Spacing")
    pieces = img.findall("Piece")
    check(len(pieces) == 1 and pieces[0].get("Extent") == img.get("WholeExtent"), path + ": Piece")
    arrs = data_arrays(pieces[0].find("PointData"))
    v = arrs["velocity_A_per_ns"]
    check(v.get("NumberOfComponents") == "3", path + ": velocity components")
    u = numbers(v)
    check(u.size == 3 * GRID ** 3 and np.all(np.isfinite(u)), path + ": velocity count")


def vtk_read(reader_class, path):
    """Reads path with VTK's own XML reader (python3-vtk9); fails on any VTK error."""
    import vtk
    errors = []
    reader = reader_class()
    reader.AddObserver("ErrorEvent", lambda obj, ev: errors.append(ev))
    check(reader.CanReadFile(path) == 1, path + ": VTK cannot read it")
    reader.SetFileName(path)
    reader.Update()
    check(not errors and reader.GetErrorCode() == 0, path + ": VTK reader errors")
    from vtk.util.numpy_support import vtk_to_numpy
    return reader.GetOutput(), vtk_to_numpy


def check_vtk_readers(out, positions, vtp_files, vti_files):
    """VTK's own readers (vtkXMLPolyDataReader, vtkXMLImageDataReader) open every .vtp and .vti."""
    import vtk
    for path, frame in zip(vtp_files, positions):
        poly, to_np = vtk_read(vtk.vtkXMLPolyDataReader, path)
        check(poly.GetNumberOfPoints() == N, path + ": VTK points")
        check(np.allclose(to_np(poly.GetPoints().GetData()), frame, rtol=1e-9, atol=1e-8),
              path + ": VTK points = H5MD frame")
        check(poly.GetNumberOfLines() == 1, path + ": VTK one line")
        ids = vtk.vtkIdList()
        poly.GetLines().InitTraversal()
        poly.GetLines().GetNextCell(ids)
        check(ids.GetNumberOfIds() == N + 1 and ids.GetId(0) == ids.GetId(N), path + ": VTK closed line")
        pd = poly.GetPointData()
        for name, comps in (("d1", 3), ("d2", 3), ("d3", 3), ("twist_density_rad_per_A", 1),
                            ("stretch_strain", 1)):
            a = pd.GetArray(name)
            check(a is not None and a.GetNumberOfComponents() == comps
                  and a.GetNumberOfTuples() == N, path + ": VTK array " + name)
        d1 = to_np(pd.GetArray("d1"))
        check(np.allclose(np.linalg.norm(d1, axis=1), 1, atol=1e-9), path + ": VTK d1 unit")
    for path in vti_files:
        img, to_np = vtk_read(vtk.vtkXMLImageDataReader, path)
        check(list(img.GetDimensions()) == [GRID] * 3, path + ": VTK dimensions")
        check(np.allclose(img.GetSpacing(), [BOX / GRID] * 3), path + ": VTK spacing")
        v = img.GetPointData().GetArray("velocity_A_per_ns")
        check(v is not None and v.GetNumberOfComponents() == 3
              and v.GetNumberOfTuples() == GRID ** 3, path + ": VTK velocity")
        check(np.all(np.isfinite(to_np(v))), path + ": VTK velocity finite")


def check_pvd(d, name, ext, times):
    root = check_vtkfile(os.path.join(d, name), "Collection")
    sets = root.findall("Collection/DataSet")
    check(len(sets) == len(times), name + ": one DataSet per frame")
    for s, t in zip(sets, times):
        check(os.path.isfile(os.path.join(d, s.get("file"))), name + ": " + s.get("file") + " exists")
        check(s.get("file").endswith(ext), name + ": file type")
        check(abs(float(s.get("timestep")) - t) <= 1e-12, name + ": timestep = H5MD time")
    return [os.path.join(d, s.get("file")) for s in sets]


def main():
    binary = sys.argv[1]
    tmp = tempfile.mkdtemp(prefix="ibrod_outputs_")
    try:
        cfg = os.path.join(tmp, "in.toml")
        with open(cfg, "w") as c:
            c.write(CONFIG)
        out = os.path.join(tmp, "out")
        r = subprocess.run([binary, "run", cfg, "-o", out], capture_output=True, text=True)
        check(r.returncode == 0, "ibrod run failed:\n" + r.stdout + r.stderr)
        positions, times = check_h5md(out)
        check_mdanalysis(out, positions)
        vtp_files = check_pvd(out, "rod.pvd", ".vtp", times)
        vti_files = check_pvd(out, "fluid.pvd", ".vti", times)
        for path, frame in zip(vtp_files, positions):
            check_vtp(path, frame)
        for path in vti_files:
            check_vti(path)
        check_vtk_readers(out, positions, vtp_files, vti_files)
        print("check_outputs: H5MD (h5py and MDAnalysis), %d .vtp and %d .vti files (xml.etree "
              "and VTK's readers) OK" % (len(times), len(times)))
        return 0
    except AssertionError as e:
        print("check_outputs: FAILED: %s" % e)
        return 1
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
