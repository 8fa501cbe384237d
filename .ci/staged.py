"""Run a tool on artic as its wheel lays it out: ``artic/`` with the four folders inside.

The four folders (``mjcf``, ``plant``, ``reduced``, ``validation``) stay at the
repository root and setup.py maps them under the import name ``artic``
(setuptools' package-dir). Tools that find modules by walking folders
(import-linter's grimp, mypy) cannot follow that mapping. This script stages the
pure-Python part of the package with setuptools' own ``build_py``, the step
that lays out the wheel, into a temporary folder with a copy of
``pyproject.toml`` (the tools' settings), then runs the command in that folder,
with it first on ``PYTHONPATH`` and ``MYPYPATH``. Paths in the command are
taken from the repository root::

    python .ci/staged.py lint-imports
    python .ci/staged.py mypy --follow-imports=silent .ci/public_api.py

Its exit status is the command's.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def stage(target: Path) -> Path:
    """Lay out the package under ``target`` as the wheel does; return ``target``."""
    build = target / "_build_temp"
    done = subprocess.run(
        [sys.executable, "setup.py", "-q", "build_py", "--build-lib", str(target),
         "--force"],
        cwd=ROOT, capture_output=True, text=True,
        env={**os.environ, "PYTHONWARNINGS": "ignore"})
    shutil.rmtree(ROOT / "build", ignore_errors=True)  # setup.py's own scratch folder
    shutil.rmtree(build, ignore_errors=True)
    if done.returncode != 0 or not (target / "artic" / "mjcf" / "__init__.py").is_file():
        sys.exit(f"staged.py: setup.py build_py failed:\n{done.stderr[-3000:]}")
    shutil.copy(ROOT / "pyproject.toml", target / "pyproject.toml")
    return target


def main(argv: list[str]) -> int:
    """Stage the package, then run ``argv`` against it."""
    if not argv:
        sys.exit("usage: python .ci/staged.py COMMAND [ARGS...]")
    with tempfile.TemporaryDirectory(prefix="artic-staged-") as tmp:
        staged = stage(Path(tmp))
        paths = [str(staged), *filter(None, [os.environ.get("PYTHONPATH")])]
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths),
               "MYPYPATH": str(staged)}
        tool = shutil.which(argv[0], path=f"{Path(sys.executable).parent}{os.pathsep}"
                                           f"{os.environ.get('PATH', '')}")
        args = [str(ROOT / a) if (ROOT / a).exists() and not a.startswith("-") else a
                for a in argv[1:]]
        return subprocess.run([tool or argv[0], *args], cwd=staged, env=env).returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
