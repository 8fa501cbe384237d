"""The Warp plant's throughput: plant steps per second against the number of worlds.

Every world drives the bench_plant manoeuvre (a 200 deg constant steer at 5 km/h,
10 ms steps); the commands are set on the device once and the worlds stepped with
:meth:`WarpPlant.step_device`, the path a batched controller takes (on a GPU each
step is a CUDA graph). A plant step is one 10 ms step of one world. The single-core
C plant (:class:`artic.plant.Plant`, compiled) runs the same manoeuvre in the same
run, and the ratio is against it.

Each rate is timed three times (:data:`RUNS`, the worlds reset between runs) and
printed as the median with the range. Runs on a CUDA GPU where Warp finds one, else
on Warp's CPU device (which measures the port, not a GPU's throughput). Needs the
``gpu`` extra; without it, it says so.

Run: ``python benchmarks/bench_warp_plant.py [--device cpu|cuda] [--worlds 1,8,64]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import statistics
import time

from _timing import one_core
from artic.mjcf import load_vehicle
from artic.mjcf.interface import InitialState
from artic.plant import Plant

DT = 0.01
CPU_WORLDS = (1, 4, 16, 64)
GPU_WORLDS = (1, 64, 512, 2048, 8192)
RUNS = 3
"""Timed runs per rate: the median is printed, with the range."""


def _manoeuvre(v) -> tuple[float, float]:
    """``(u [m/s], delta [rad])`` of bench_plant's constant steer."""
    return 5 / 3.6, math.radians(200) / v.steering_for("mbd").i_s


def c_plant_rates(seconds: float) -> list[float]:
    """Plant steps per second of the compiled C plant on one core, :data:`RUNS` runs."""
    v = load_vehicle("gosar2022-unloaded")
    u, delta = _manoeuvre(v)
    rates = []
    with one_core(), Plant(v) as p:
        n = round(seconds / DT)
        for _ in range(RUNS):
            p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
            t0 = time.perf_counter()
            for _ in range(n):
                p.step(DT, delta, u, 0.0)
            rates.append(n / (time.perf_counter() - t0))
    return rates


def warp_rates(n_worlds: int, device: str, seconds: float) -> tuple[list[float], float]:
    """``(plant steps per second of RUNS runs, first-step seconds)`` of ``n_worlds``."""
    import numpy as np
    import warp as wp

    from artic.plant.warp_plant import WarpPlant

    v = load_vehicle("gosar2022-unloaded")
    u, delta = _manoeuvre(v)
    rates = []
    with WarpPlant(v, n_worlds, device=device) as plant:
        plant.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
        plant.ctl.command.assign(np.tile(np.float32([delta, u, 0.0]), (n_worlds, 1)))
        t0 = time.perf_counter()
        plant.step_device(1)  # compilation, graph capture
        wp.synchronize_device(plant.device)
        first = time.perf_counter() - t0
        n = max(1, round(seconds / DT))
        for _ in range(RUNS):
            plant.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
            wp.synchronize_device(plant.device)
            t0 = time.perf_counter()
            for _ in range(n):
                plant.step_device(1)
            wp.synchronize_device(plant.device)
            rates.append(n_worlds * n / (time.perf_counter() - t0))
            if plant.failures():
                raise RuntimeError(f"the benchmark's worlds failed: {plant.failures()}")
    return rates, first


def _spread(rates: list[float]) -> str:
    """``median (min-max)`` of ``rates``."""
    return f"{statistics.median(rates):,.0f} ({min(rates):,.0f}-{max(rates):,.0f})"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--device", default=None, help="cpu or cuda (default: cuda where present)")
    ap.add_argument("--worlds", default=None, help="comma-separated world counts")
    ap.add_argument("--seconds", type=float, default=1.0, help="simulated seconds per count")
    args = ap.parse_args(argv or [])
    missing = [m for m in ("warp", "mujoco_warp") if importlib.util.find_spec(m) is None]
    if missing:
        print(f"skipped: {', '.join(missing)} not installed (pip install 'artic[gpu]')")
        return
    import warp as wp

    wp.config.quiet = True
    device = args.device or ("cuda" if wp.is_cuda_available() else "cpu")
    worlds = ([int(x) for x in args.worlds.split(",")] if args.worlds
              else GPU_WORLDS if device.startswith("cuda") else CPU_WORLDS)
    c_rates = c_plant_rates(max(args.seconds, 2.0))
    c_rate = statistics.median(c_rates)
    name = wp.get_device(device).name
    print(f"device {device} ({name}); C plant, one core: {_spread(c_rates)} plant steps/s "
          f"(median (range) of {RUNS} runs, as below)")
    if not device.startswith("cuda"):
        print("(Warp's CPU device: the port's cost, not a GPU's throughput)")
    print(f"{'worlds':>7} {'plant steps/s, median (range)':>32} {'x C plant':>10} "
          f"{'real-time x':>12} {'first step [s]':>15}")
    for n in worlds:
        rates, first = warp_rates(n, device, args.seconds)
        rate = statistics.median(rates)
        print(f"{n:>7} {_spread(rates):>32} {rate / c_rate:>10.2f} {rate * DT:>12,.0f} "
              f"{first:>15.1f}")


if __name__ == "__main__":
    import sys

    main(sys.argv[1:])
