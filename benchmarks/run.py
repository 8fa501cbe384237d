"""Run every benchmark: ``python benchmarks/run.py``.

Each ``bench_*.py`` module beside this file has a ``main()`` that prints its
figures. Figures are ratios measured within one run, because machines are noisy.

Started with a Python that does not have artic installed (a system
``python``), it runs itself again with the checkout's ``.venv/bin/python`` if
there is one, and otherwise says how to make it.
"""

from __future__ import annotations

import importlib.util
import os
import platform
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
VENV_PYTHON = HERE.parent / ".venv" / "bin" / "python"


def _has_artic() -> bool:
    return all(importlib.util.find_spec(m) is not None for m in ("numpy", "mujoco", "artic"))


def main() -> int:
    if not _has_artic():
        if VENV_PYTHON.is_file() and Path(sys.prefix).resolve() != VENV_PYTHON.parents[1].resolve():
            os.execv(VENV_PYTHON, [str(VENV_PYTHON), __file__, *sys.argv[1:]])
        print(f"benchmarks/run.py: artic is not installed for {sys.executable}; install it "
              f"with `python3 -m venv .venv && .venv/bin/pip install -e .`, then run "
              f"`.venv/bin/python benchmarks/run.py`", file=sys.stderr)
        return 2
    from artic.validation.plumbing import runtime

    runtime.configure()  # as the artic command does: numba's cache folder first
    print(f"artic benchmarks on {platform.machine()}, Python {platform.python_version()}")
    for path in sorted(HERE.glob("bench_*.py")):
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        print(f"\n== {path.stem}")
        mod.main()
    return 0


if __name__ == "__main__":
    sys.exit(main())
