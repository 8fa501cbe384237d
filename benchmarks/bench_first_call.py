"""The first reduced-model call of a fresh process: loaded from numba's cache, or compiled.

``pip install`` fills numba's cache of KIN and the STM (``artic.reduced.precompile``),
so a user's first ``artic.KIN(vehicle).rollout(...)`` loads compiled code. Each
figure is the median and range over fresh processes, with ``NUMBA_CACHE_DIR``
unset as in a user's process:

- ``import artic``, loading the vehicle and building KIN;
- the first ``rollout`` (200 steps), wall and CPU time, from the install's cache
  (the issue's target: at most 0.5 s);
- for comparison, the same first call compiling, in a process whose numba cache
  is an empty folder.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile

ROUNDS = 5

SCRIPT = """
import json, time
t0, c0 = time.perf_counter(), time.process_time()
import numpy as np
import artic
kin = artic.KIN(artic.load_vehicle("gosar2022-unloaded"))
t1, c1 = time.perf_counter(), time.process_time()
kin.rollout(np.zeros(4), np.tile([0.0, -1.0], (200, 1)), 0.01)
t2, c2 = time.perf_counter(), time.process_time()
print(json.dumps({"setup": t1 - t0, "wall": t2 - t1, "cpu": c2 - c1}))
"""


def _run(env: dict[str, str]) -> dict[str, float]:
    out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _fmt(xs: list[float]) -> str:
    return f"{statistics.median(xs):.3f} s ({min(xs):.3f}-{max(xs):.3f})"


def main(rounds: int = ROUNDS) -> None:
    """Print the figures (``rounds`` fresh processes from the cache, one compiling)."""
    user = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    runs = [_run(user) for _ in range(rounds)]
    print(f"import artic, load the vehicle, build KIN: {_fmt([r['setup'] for r in runs])}")
    print(f"first KIN.rollout, from the install's cache: wall {_fmt([r['wall'] for r in runs])}, "
          f"CPU {_fmt([r['cpu'] for r in runs])}")
    with tempfile.TemporaryDirectory() as empty:
        cold = _run({**user, "NUMBA_CACHE_DIR": empty})
    print(f"first KIN.rollout, compiling (an empty cache): wall {cold['wall']:.2f} s, "
          f"CPU {cold['cpu']:.2f} s")


if __name__ == "__main__":
    main()
