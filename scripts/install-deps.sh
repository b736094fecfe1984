#!/usr/bin/env bash
# Installs everything ibrod needs on a fresh Debian (bookworm) machine. Idempotent: packages that
# are already present are left alone. Run as root (or through sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libfftw3-dev          # FFTs of the periodic fluid grid (with libfftw3 threads)
  libeigen3-dev         # small vectors, rotations, quaternions
  libtomlplusplus-dev   # TOML configs
  libcli11-dev          # command line
  libgtest-dev libgmock-dev libbenchmark-dev   # tests and micro-benchmarks
  libhdf5-dev           # H5MD trajectories
  nlohmann-json3-dev    # summary.json (reads and writes, with null)
  libopenmpi-dev openmpi-bin   # optional: mpirun -np K ibrod sweep (points shared among ranks)
  libfftw3-mpi-dev      # optional: distributed FFTs for large grids (docs/sweeps.md)
  libpng-dev            # rendered pictures of the rod
  zlib1g-dev            # the animated PNG of render --movie (deflate, CRC)
  python3 python3-numpy python3-matplotlib python3-h5py python3-pil   # analysis, plots; Pillow reads the movie in a test
  python3-dev pybind11-dev python3-pytest   # the Python module ibrod (docs/python.md) and its tests
  python3-venv python3-setuptools python3-wheel   # pip install --no-build-isolation . into a venv (docs/python.md)
  python3-mdanalysis    # tests: MDAnalysis reads trajectory.h5md (H5MD)
  chromium              # tests: headless Chromium draws the HTML report's 3-D view (--html)
  python3-vtk9          # tests: VTK's own readers open the .vtp/.vti files
  ffmpeg                # render --movie encodes the frames as MP4 (and ffprobe for its test)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
