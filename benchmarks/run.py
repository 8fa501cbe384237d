"""Run every benchmark: ``python benchmarks/run.py``.

Each ``bench_*.py`` module beside this file has a ``main()`` that prints its
figures. Figures are ratios measured within one run, because machines are noisy.
"""

from __future__ import annotations

import importlib.util
import platform
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> int:
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
