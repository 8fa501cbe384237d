"""Environment steps per second of artic/Dock-v0 and artic/DockKIN-v0, single and vectorised.

A step is 0.1 s of the run (the controllers' sample period): the plant's ten
10 ms steps within, the actuators, the sensors, the failure checks, and the
handover to and from the run's thread. Each round runs a fixed action (reverse
at 60 % of the speed limit, straight) on the straight scenario for
:data:`STEPS` steps per environment; an episode that ends is reset (the reset's
planning counts). Single: one environment in this process. Vectorised:
Gymnasium's ``AsyncVectorEnv``, one environment per worker process, one
worker per core this process may use (two on the reference machine). The
figures are end-to-end environment steps per second (summed over the
vector's environments), the median and range of three rounds.

Run: ``python benchmarks/run.py`` (or this file alone). Needs ``artic[gym]``.
"""

from __future__ import annotations

import importlib.util
import os
import statistics
import time

import numpy as np

ROUNDS = 3
STEPS = 400
SCENARIO = "straight"


def _rate(make, n_envs: int) -> float:
    env = make()
    action = np.array([0.0, -0.6])
    if n_envs > 1:
        action = np.tile(action, (n_envs, 1))
    env.reset(seed=0)
    env.step(action)  # the first step: numba's and MuJoCo's first calls
    t0 = time.perf_counter()
    for _ in range(STEPS):
        out = env.step(action)
        if n_envs == 1 and (out[2] or out[3]):
            env.reset()
    rate = STEPS * n_envs / (time.perf_counter() - t0)
    env.close()
    return rate


def main() -> None:
    if importlib.util.find_spec("gymnasium") is None:
        print("gymnasium is not installed (pip install 'artic[gym]'): skipped")
        return
    import gymnasium as gym

    import artic.gym  # noqa: F401 - registers the environments

    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    print(f"environment steps per second, end to end, median (range) of {ROUNDS} rounds "
          f"of {STEPS} steps; vectorised: {cores} async workers")
    for env_id in artic.gym.ENVIRONMENTS:
        def one(env_id=env_id):
            return gym.make(env_id, scenario=SCENARIO)

        def vec(env_id=env_id):
            return gym.make_vec(env_id, num_envs=cores, vectorization_mode="async",
                                scenario=SCENARIO)

        single = [_rate(one, 1) for _ in range(ROUNDS)]
        vector = [_rate(vec, cores) for _ in range(ROUNDS)]
        for label, xs in (("single", single), (f"async x{cores}", vector)):
            print(f"  {env_id:18s} {label:9s} {statistics.median(xs):6.0f} "
                  f"({min(xs):.0f}-{max(xs):.0f}) steps/s")


if __name__ == "__main__":
    main()
