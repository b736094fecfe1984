"""`pip install --no-build-isolation .`: builds the CMake targets `ibrod` (the command line) and
`ibrod_python` (the module's _core) and packs into the package `ibrod`:

    ibrod/__init__.py, _cli.py, test_installation.py   python/ibrod/*.py
    ibrod/_core*.so                                     the compiled module
    ibrod/bin/ibrod                                     the command line (the `ibrod` console
                                                        command runs it: ibrod/_cli.py)
    ibrod/share/ibrod/ibrod_{report,plot,study,html}.py the scripts `ibrod report` runs (found
                                                        beside the binary as after cmake --install)

The CMake build directory is build/pip (kept, so a second install rebuilds only what changed), or
$IBROD_CMAKE_BUILD_DIR: an existing, configured build directory whose targets are brought up to
date and packed (the test tests/python/test_pip_install.py passes the tests' own build).
"""
import glob
import os
import re
import shutil
import subprocess
import sys

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

ROOT = os.path.dirname(os.path.abspath(__file__))
SCRIPTS = ["ibrod_report.py", "ibrod_plot.py", "ibrod_study.py", "ibrod_html.py"]


def version():
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        return re.search(r"project\(ibrod VERSION ([0-9.]+)", f.read()).group(1)


class BuildWithCMake(build_py):
    def run(self):
        super().run()
        build = os.environ.get("IBROD_CMAKE_BUILD_DIR") or os.path.join(ROOT, "build", "pip")
        if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            gen = ["-G", "Ninja"] if shutil.which("ninja") else []
            subprocess.check_call(
                ["cmake", "-S", ROOT, "-B", build, *gen, "-DCMAKE_BUILD_TYPE=Release",
                 "-DIBROD_BUILD_TESTS=OFF", "-DIBROD_BUILD_BENCH=OFF", "-DIBROD_PYTHON=ON",
                 f"-DPYTHON_EXECUTABLE={sys.executable}"])
        jobs = str(os.cpu_count() or 1)
        subprocess.check_call(["cmake", "--build", build, "-j", jobs,
                               "--target", "ibrod", "ibrod_python"])
        pkg = os.path.join(self.build_lib, "ibrod")
        for so in glob.glob(os.path.join(build, "python", "ibrod", "_core*.so")):
            shutil.copy2(so, pkg)
        os.makedirs(os.path.join(pkg, "bin"), exist_ok=True)
        shutil.copy2(os.path.join(build, "app", "ibrod"), os.path.join(pkg, "bin", "ibrod"))
        share = os.path.join(pkg, "share", "ibrod")
        os.makedirs(share, exist_ok=True)
        for s in SCRIPTS:
            shutil.copy2(os.path.join(ROOT, "python", s), share)


class BinaryDistribution(Distribution):
    def has_ext_modules(self):  # a platform wheel: it holds a compiled module and a binary
        return True


os.makedirs(os.path.join(ROOT, "build"), exist_ok=True)  # egg_base below
setup(
    version=version(),
    packages=["ibrod"],
    package_dir={"ibrod": "python/ibrod"},
    cmdclass={"build_py": BuildWithCMake},
    distclass=BinaryDistribution,
    # setuptools' own build folder, apart from CMake's build/ of the presets
    options={"build": {"build_base": "build/setuptools"}, "egg_info": {"egg_base": "build"}},
    zip_safe=False,
)
