"""The `ibrod` console command of a pip install (pyproject.toml [project.scripts]): runs the
command-line program packed beside the module (ibrod/bin/ibrod), with $IBROD_PYTHON set to this
interpreter so that `ibrod report` runs its script in the same environment."""
import os
import shutil
import sys


def binary():
    """The path of the `ibrod` command line that belongs to this module: $IBROD_BINARY, else
    ibrod/bin/ibrod of a pip install, else build/app/ibrod beside a build's build/python/ibrod,
    else `ibrod` on PATH; None when there is none."""
    env = os.environ.get("IBROD_BINARY")
    if env:
        return env
    here = os.path.dirname(os.path.abspath(__file__))
    for p in (os.path.join(here, "bin", "ibrod"), os.path.join(here, "..", "..", "app", "ibrod")):
        if os.path.isfile(p) and os.access(p, os.X_OK):
            return os.path.normpath(p)
    found = shutil.which("ibrod")
    if found and os.path.realpath(found) != os.path.realpath(sys.argv[0]):
        return found
    return None


def main():
    b = binary()
    if b is None:
        sys.exit("ibrod: the command-line program is not installed beside the module "
                 "(ibrod/bin/ibrod); set IBROD_BINARY to its path")
    env = dict(os.environ)
    env.setdefault("IBROD_PYTHON", sys.executable)
    os.execve(b, [b, *sys.argv[1:]], env)


if __name__ == "__main__":
    main()
