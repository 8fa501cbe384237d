"""Environment steps per second of artic/Dock-v0 and artic/DockKIN-v0: single, vectorised, model.

A step is 0.1 s of the run (the controllers' sample period): the model's ten
10 ms steps within, the actuators, the sensors, the failure checks, and the
handover to and from the run's thread. Each round runs a fixed action (reverse
at 60 % of the speed limit, straight) on the straight scenario for
:data:`STEPS` vector steps; an episode that ends is reset (the reset's
planning and the end's scoring count). Rows:

- ``single``: one environment in this process;
- ``native xN``: ``make_vec(..., vectorization_mode="vector_entry_point")``,
  ``N`` environments in this process: for ``Dock-v0`` their runs stepping side by
  side on threads (:class:`artic.gym.DockVectorEnv`), for ``DockKIN-v0`` in one
  batched step (:class:`~artic.validation.docking.gym.kinbatch.KinVectorEnv`);
- ``... ends``: the same with a 10 s time limit, so that every environment's
  episode ends and is reset every 100 steps (the planner, the noise's draw and the
  scores count); the other rows' episodes mostly run on;
- ``async xC``: Gymnasium's ``AsyncVectorEnv``, one environment per worker
  process, one per core this process may use;
- ``model``: the environment steps per second the model alone allows (ten
  10 ms steps of the plant, ``Plant.step``, or of KIN, ``step_batch`` over a
  batch of 1 024): the ceiling of an environment that did nothing else.

Each figure is environment steps per second (summed over the vector's
environments), the median and range of :data:`ROUNDS` rounds, by the wall clock
and per CPU second of this process and its workers (``per core``: the rate one
core gives, which is what a loaded or a many-core machine multiplies).

Run: ``python benchmarks/run.py`` (or this file alone; ``python
benchmarks/bench_gym.py artic/Dock-v0`` measures the ids named only). Needs ``artic[gym]``.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import resource
import statistics
import sys
import time
import warnings

import numpy as np

ROUNDS = 3
STEPS = 200
SCENARIO = "straight"
NATIVE = {"artic/Dock-v0": (2, 8), "artic/DockKIN-v0": (16, 1024)}
"""The native vector environment's sizes per environment."""

ENDS = 10.0
"""The time limit of the rows whose episodes end [s]: 100 steps."""


def _cpu() -> float:
    """CPU seconds of this process and its worker processes, running or finished."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    total = own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime
    try:
        import psutil

        for child in psutil.Process().children(recursive=True):
            with contextlib.suppress(psutil.Error):
                times = child.cpu_times()
                total += times.user + times.system
    except ImportError:  # the running workers' time is then left out
        pass
    return total


def _rate(make, n_envs: int, vector: bool) -> tuple[float, float]:
    """Environment steps per wall second and per CPU second of one round."""
    env = make()
    action = np.array([0.0, -0.6])
    if vector:
        action = np.tile(action, (n_envs, 1))
    env.reset(seed=0)
    env.step(action)  # the first step: numba's and MuJoCo's first calls
    w0, c0 = time.perf_counter(), _cpu()
    for _ in range(STEPS):
        out = env.step(action)
        if not vector and (out[2] or out[3]):
            env.reset()
    wall, cpu = time.perf_counter() - w0, _cpu() - c0
    env.close()
    return STEPS * n_envs / wall, STEPS * n_envs / max(cpu, 1e-9)


def _model_rate(env_id: str) -> tuple[float, float]:
    """Environment steps per second the model alone allows (wall, CPU)."""
    import artic
    from artic.mjcf.interface import InitialState

    vehicle = artic.load_vehicle("gosar2022-unloaded")
    if env_id == "artic/Dock-v0":
        from artic.plant import Plant, PlantWarning

        with warnings.catch_warnings(), Plant(vehicle) as plant:
            warnings.simplefilter("ignore", PlantWarning)
            plant.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
            n = 10 * STEPS
            w0, c0 = time.perf_counter(), time.process_time()
            for _ in range(n):
                plant.step(0.01, 0.0, -1.0, 0.0)
            return STEPS / (time.perf_counter() - w0), STEPS / (time.process_time() - c0)
    from artic.reduced.control import step_batch

    kin = artic.KIN(vehicle)
    x = np.tile(kin.initial_state(InitialState(0.0, 0.0, 0.0, 0.0, u1=-1.0)), (1024, 1))
    u = np.tile([0.0, -1.0, 0.0], (1024, 1))
    step_batch(kin.kind, x, u, 0.01, kin.P)  # compiled or loaded
    w0, c0 = time.perf_counter(), time.process_time()
    for _ in range(10 * STEPS):
        x = step_batch(kin.kind, x, u, 0.01, kin.P)
    return 1024 * STEPS / (time.perf_counter() - w0), 1024 * STEPS / (time.process_time() - c0)


def _row(label: str, runs: list[tuple[float, float]]) -> str:
    wall, cpu = [r[0] for r in runs], [r[1] for r in runs]
    return (f"    {label:17s} {statistics.median(wall):9.0f} ({min(wall):.0f}-{max(wall):.0f})"
            f"   {statistics.median(cpu):9.0f} ({min(cpu):.0f}-{max(cpu):.0f})")


def main(ids: list[str] | None = None) -> None:
    """Print the rows of every environment id, or of those in ``ids``."""
    if importlib.util.find_spec("gymnasium") is None:
        print("gymnasium is not installed (pip install 'artic[gym]'): skipped")
        return
    import gymnasium as gym

    import artic.gym  # noqa: F401 - registers the environments

    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    print(f"environment steps per second, median (range) of {ROUNDS} rounds of {STEPS} steps, "
          f"by the wall clock and per CPU second; {cores} cores")
    unknown = sorted(set(ids or ()) - set(artic.gym.ENVIRONMENTS))
    if unknown:
        raise SystemExit(f"{', '.join(unknown)}: not an artic environment; expected "
                         f"{' or '.join(artic.gym.ENVIRONMENTS)}")
    for env_id in artic.gym.ENVIRONMENTS:
        if ids and env_id not in ids:
            continue
        print(f"  {env_id}: {'':5s}wall steps/s {'':9s}per core steps/s")
        rows = [("single", lambda env_id=env_id: gym.make(env_id, scenario=SCENARIO), 1, False)]
        for n in NATIVE[env_id]:
            rows.append((f"native x{n}", lambda env_id=env_id, n=n: gym.make_vec(
                env_id, num_envs=n, vectorization_mode="vector_entry_point",
                scenario=SCENARIO), n, True))
        n = NATIVE[env_id][-1]
        rows += [
            ("single ends", lambda env_id=env_id: gym.make(env_id, scenario=SCENARIO,
                                                           timeout=ENDS), 1, False),
            (f"native x{n} ends", lambda env_id=env_id, n=n: gym.make_vec(
                env_id, num_envs=n, vectorization_mode="vector_entry_point", scenario=SCENARIO,
                timeout=ENDS), n, True),
            (f"async x{cores}", lambda env_id=env_id: gym.make_vec(
                env_id, num_envs=cores, vectorization_mode="async", scenario=SCENARIO),
             cores, True)]
        for label, make, n, vector in rows:
            print(_row(label, [_rate(make, n, vector) for _ in range(ROUNDS)]), flush=True)
        print(_row("model", [_model_rate(env_id) for _ in range(ROUNDS)]), flush=True)

if __name__ == "__main__":
    main(sys.argv[1:])
