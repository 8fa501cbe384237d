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

On the Warp plant: ``python benchmarks/bench_gym.py --backend warp --device cuda``
measures ``artic/Dock-v0`` vectorised on the GPU
(:class:`~artic.validation.docking.gym.warpbatch.WarpDockVectorEnv`) at
``--num-envs`` environments (:data:`WARP_ENVS` on a GPU, :data:`WARP_CPU_ENVS` on
Warp's CPU device, a smoke run): rows ``warp xN`` and ``warp xN ends``, the first
step (the kernels' loading and the CUDA graph's capture) not counted. Needs
``artic[gpu]`` as well.

Run: ``python benchmarks/run.py`` (or this file alone; ``python
benchmarks/bench_gym.py artic/Dock-v0`` measures the ids named only). Needs ``artic[gym]``.
"""

from __future__ import annotations

import argparse
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

WARP_ENVS = 8192
"""``--backend warp``'s environments on a GPU: the issue's target is 10^5 steps/s there."""

WARP_CPU_ENVS = 4
"""``--backend warp``'s environments on Warp's CPU device: a smoke run, not a figure."""


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


def _rate(make, n_envs: int, vector: bool, steps: int = STEPS) -> tuple[float, float]:
    """Environment steps per wall second and per CPU second of one round."""
    env = make()
    action = np.array([0.0, -0.6])
    if vector:
        action = np.tile(action, (n_envs, 1))
    env.reset(seed=0)
    env.step(action)  # the first step: numba's and MuJoCo's first calls
    w0, c0 = time.perf_counter(), _cpu()
    for _ in range(steps):
        out = env.step(action)
        if not vector and (out[2] or out[3]):
            env.reset()
    wall, cpu = time.perf_counter() - w0, _cpu() - c0
    env.close()
    return steps * n_envs / wall, steps * n_envs / max(cpu, 1e-9)


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


def warp_main(device: str, n: int | None, steps: int, rounds: int) -> None:
    """Print the rows of ``artic/Dock-v0`` on the Warp plant, ``n`` environments on ``device``."""
    missing = [m for m in ("warp", "mujoco_warp") if importlib.util.find_spec(m) is None]
    if missing:
        print(f"skipped: {', '.join(missing)} not installed (pip install 'artic[gpu]')")
        return
    import gymnasium as gym
    import warp as wp

    wp.config.quiet = True
    n = n or (WARP_ENVS if device.startswith("cuda") else WARP_CPU_ENVS)
    print(f"artic/Dock-v0 on the Warp plant, device {device}: environment steps per second, "
          f"median (range) of {rounds} rounds of {steps} steps, by the wall clock and per CPU "
          "second of this process")
    if not device.startswith("cuda"):
        print("(Warp's CPU device: a smoke run, not a GPU's throughput)")
    print(f"  {'':22s}wall steps/s {'':9s}per core steps/s")
    for label, timeout in ((f"warp x{n}", None), (f"warp x{n} ends", ENDS)):
        extra = {} if timeout is None else {"timeout": timeout}

        def make(extra=extra):
            return gym.make_vec("artic.gym:artic/Dock-v0", num_envs=n,
                                vectorization_mode="vector_entry_point", backend="warp",
                                device=device, scenario=SCENARIO, **extra)

        print(_row(label, [_rate(make, n, True, steps) for _ in range(rounds)]), flush=True)


def main(ids: list[str] | None = None) -> None:
    """Print the rows of every environment id, or of those in ``ids`` (or ``--backend warp``'s)."""
    if importlib.util.find_spec("gymnasium") is None:
        print("gymnasium is not installed (pip install 'artic[gym]'): skipped")
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("ids", nargs="*", help="environment ids (default: all)")
    ap.add_argument("--backend", choices=("cpu", "warp"), default="cpu",
                    help="warp: artic/Dock-v0 vectorised on the Warp plant")
    ap.add_argument("--device", default="cuda", help="the Warp device (--backend warp)")
    ap.add_argument("--num-envs", type=int, default=None,
                    help=f"environments (--backend warp; {WARP_ENVS} on a GPU)")
    ap.add_argument("--steps", type=int, default=STEPS, help="vector steps per round")
    ap.add_argument("--rounds", type=int, default=ROUNDS, help="rounds per row")
    args = ap.parse_args(ids or [])
    if args.backend == "warp":
        warp_main(args.device, args.num_envs, args.steps, args.rounds)
        return
    ids = args.ids
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
