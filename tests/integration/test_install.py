#!/usr/bin/python3
"""Any build directory, any install: `ibrod report` finds its scripts

  - after `cmake --install BUILD --prefix P`: P/bin/ibrod runs P/share/ibrod/ibrod_report.py
    (shown by replacing the installed script with one that prints its own path);
  - from a binary away from the source tree (an out-of-tree build directory): the source tree it
    was built from (the real script's usage);
  - after `pip install --no-build-isolation .` into a fresh virtual environment
    (python3 -m venv --system-site-packages; offline: --no-index): `import ibrod` from the
    environment, its `ibrod` console command (report included: its scripts packed in the
    environment) and `python -m ibrod.test_installation`, which must pass within 30 s. The
    install reuses this build (IBROD_CMAKE_BUILD_DIR=BUILD: the targets are up to date, so
    nothing is compiled); a build from nothing is timed in README.

    /usr/bin/python3 tests/integration/test_install.py BUILD_DIR

Registered in CTest (label integration). Exit status 0 when every check passes.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD = None  # from argv
STUB = "import sys; print('STUB', __file__, *sys.argv[1:])\n"


def sh(*args, env=None, timeout=300, cwd=None):
    r = subprocess.run(list(args), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       stdin=subprocess.DEVNULL, timeout=timeout, env=env, cwd=cwd)
    if r.returncode != 0:
        raise AssertionError(f"{' '.join(args)} exited {r.returncode}:\n{r.stdout}")
    return r.stdout


def clean_env(**extra):
    """The environment without the test's own pointers at the build (PYTHONPATH, IBROD_*)."""
    env = {k: v for k, v in os.environ.items()
           if k != "PYTHONPATH" and not k.startswith("IBROD_")}
    env.update(extra)
    return env


class Install(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="ibrod_install_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def test_cmake_install_finds_the_installed_script(self):
        prefix = os.path.join(self.tmp, "prefix")
        sh("cmake", "--install", BUILD, "--prefix", prefix)
        exe = os.path.join(prefix, "bin", "ibrod")
        share = os.path.join(prefix, "share", "ibrod")
        for s in ("ibrod_report.py", "ibrod_plot.py", "ibrod_study.py", "ibrod_html.py"):
            self.assertTrue(os.path.isfile(os.path.join(share, s)), s)
        with open(os.path.join(share, "ibrod_report.py"), "w") as f:
            f.write(STUB)
        out = sh(exe, "report", "RUN", "-o", "OUT", env=clean_env())
        self.assertIn(f"STUB {os.path.realpath(share)}/ibrod_report.py RUN -o OUT --ibrod "
                      f"{os.path.realpath(exe)}", out)

    def test_a_binary_away_from_the_source_tree_finds_the_source_scripts(self):
        # an out-of-tree build directory: nothing at ../../python or ../share/ibrod
        d = os.path.join(self.tmp, "somewhere", "app")
        os.makedirs(d)
        exe = shutil.copy(os.path.join(BUILD, "app", "ibrod"), d)
        # IBROD_PYTHON=/bin/echo: the command line the report would run, printed
        out = sh(exe, "report", "RUN", env=clean_env(IBROD_PYTHON="/bin/echo"))
        self.assertEqual(out.split()[:2],
                         [os.path.join(os.path.realpath(ROOT), "python", "ibrod_report.py"), "RUN"])

    def test_pip_install_into_a_venv(self):
        venv = os.path.join(self.tmp, "venv")
        sh(sys.executable, "-m", "venv", "--system-site-packages", venv)
        py, env = os.path.join(venv, "bin", "python"), clean_env(IBROD_CMAKE_BUILD_DIR=BUILD)
        sh(py, "-m", "pip", "install", "--no-build-isolation", "--no-index", "--no-cache-dir",
           "--quiet", ROOT,
           env=env, timeout=900)
        env = clean_env()
        where = sh(py, "-c", "import ibrod, os; print(os.path.realpath(ibrod.__file__))",
                   env=env, cwd=self.tmp)
        self.assertTrue(where.strip().startswith(os.path.realpath(venv)), where)
        cmd = os.path.join(venv, "bin", "ibrod")
        self.assertIn("ibrod", sh(cmd, "--version", env=env))
        # its report runs the script packed in the environment, with the environment's Python
        share = sh(py, "-c", "import ibrod, os; print(os.path.join(os.path.dirname("
                   "os.path.realpath(ibrod.__file__)), 'share', 'ibrod'))", env=env).strip()
        self.assertTrue(os.path.isfile(os.path.join(share, "ibrod_html.py")))
        with open(os.path.join(share, "ibrod_report.py"), "w") as f:
            f.write("import sys; print('STUB', __file__, sys.executable)\n")
        out = sh(cmd, "report", env=env)
        self.assertIn(f"STUB {share}/ibrod_report.py {py}", out)
        t0 = time.monotonic()
        out = sh(py, "-m", "ibrod.test_installation", env=env, cwd=self.tmp, timeout=120)
        took = time.monotonic() - t0
        print(out)
        for words in ("closed form", "Σf = 0", "link kept", "Python/CLI identity",
                      "all checks passed"):
            self.assertIn(words, out)
        self.assertLess(took, 30)


if __name__ == "__main__":
    BUILD = os.path.abspath(sys.argv[1])
    unittest.main(argv=[sys.argv[0], "-v"])
