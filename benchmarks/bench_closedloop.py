"""The plant in the harness: compiled closed loop, Python loop, bare MuJoCo, threads, the CLI.

Every figure is a ratio of times measured in the same round; three rounds
alternate the variants, and each figure is given as the median and range of
the three. The log is the default forward manoeuvre of ``artic simulate``
(a 200 deg constant steer at 5 km/h, 60 s), driven through
:func:`artic.validation.harness.loop.run_inputs` with the reversing feedback on (K = 3):

- **per step**, the compiled closed loop (:mod:`artic.plant.closedloop`) against
  the Python loop it replaces, and against bare ``mj_step`` loops over the
  same states: with the plant's tyre callback (MuJoCo's whole step of the
  model, as a standalone MJCF with its callback runs it) and without any
  callback. The bare loops replay the states the compiled run passed
  through (every 10 ms, two 5 ms steps each from there);
- **threads**: four runs of the log on one thread, and on two;
- **end to end**, as a user runs it: ``artic simulate --model mbd`` for the
  default 60 s and for 600 s, process start to exit, as real-time factors.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import mujoco
import numpy as np

from _timing import bare_steps
from artic.mjcf import load_vehicle
from artic.plant import Plant
from artic.validation.harness.loop import LoopInputs, run_inputs
from artic.validation.synthetic.manoeuvres import make_profile

ROUNDS = 3
VEHICLE = "gosar2022-unloaded"


def _inputs(vehicle) -> LoopInputs:
    from artic.mjcf.interface import InitialState

    prof = make_profile("constant-steer", amplitude_deg=200.0, speed_kph=5.0, side="left")
    steering = vehicle.steering_for("mbd")
    n = prof.t.size
    u1_dot = np.zeros(n)
    u1_dot[:-1] = np.diff(prof.u1) / np.diff(prof.t)
    return LoopInputs(t=prof.t, delta_h=prof.delta_h,
                      delta_c=np.asarray(steering.road_wheel(prof.delta_h)), u1=prof.u1,
                      u1_dot=u1_dot, gamma_meas=np.zeros(n), weight=np.zeros(n),
                      initial=InitialState(0.0, 0.0, 0.0, 0.0, u1=float(prof.u1[0])))


def _loop(vehicle, inp, compiled: bool, extras: bool = False, step: bool | None = None) -> float:
    """One run; ``step``: whether Plant.step is compiled in the Python loop (as ``compiled``)."""
    with Plant(vehicle) as p:
        p._compiled_loop = compiled
        p._compiled_step = compiled if step is None else step
        t0 = time.perf_counter()
        run_inputs(p, inp, vehicle, 3.0, {} if extras else None)
        return time.perf_counter() - t0


def _states(vehicle, inp) -> tuple[Plant, list[np.ndarray]]:
    """The states of the compiled run, every 10 ms (its own stepping, without timing)."""
    p = Plant(vehicle)
    p.reset(inp.initial)
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    out = []
    for k in range(inp.t.size - 1):
        s = np.empty(mujoco.mj_stateSize(p.model, spec))
        mujoco.mj_getState(p.model, p.data, s, spec)
        out.append(s)
        p.step(float(inp.t[k + 1] - inp.t[k]), float(inp.delta_c[k]), float(inp.u1[k]),
               float(inp.u1_dot[k]))
    return p, out


def _bare(p: Plant, states, callback: bool) -> float:
    return bare_steps(p.model, states, 2, callback)


def _threads(vehicle, inp, jobs: int, runs: int = 4) -> float:
    def one(_):
        with Plant(vehicle) as p:
            run_inputs(p, inp, vehicle, 3.0)

    t0 = time.perf_counter()
    with ThreadPoolExecutor(jobs) as pool:
        list(pool.map(one, range(runs)))
    return time.perf_counter() - t0


def _cli(duration: float) -> float:
    artic = Path(sys.executable).with_name("artic")
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [str(artic), "simulate", "--model", "mbd", "--manoeuvre", "constant-steer",
               "--out", str(Path(tmp) / "run.parquet")]
        if duration != 60.0:
            cmd += ["--duration", str(duration)]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        return time.perf_counter() - t0


def _fmt(xs: list[float], unit: str = "") -> str:
    return f"{statistics.median(xs):.2f}{unit} ({min(xs):.2f}-{max(xs):.2f})"


def main() -> dict[str, list[float]]:
    vehicle = load_vehicle(VEHICLE)
    inp = _inputs(vehicle)
    seconds = float(inp.t[-1] - inp.t[0])
    p, states = _states(vehicle, inp)
    _loop(vehicle, inp, True)  # warm-up: loading the library, numba's cached feedback law
    _loop(vehicle, inp, False)
    fig: dict[str, list[float]] = {k: [] for k in (
        "compiled_rtf", "compiled_over_python", "compiled_over_bare_cb", "compiled_over_bare",
        "extras_over_compiled", "python_rtf", "python_c_step_rtf", "threads_speedup",
        "cli_rtf_60", "cli_rtf_600")}
    for _ in range(ROUNDS):
        c = _loop(vehicle, inp, True)
        py = _loop(vehicle, inp, False)
        ce = _loop(vehicle, inp, True, extras=True)
        pc = _loop(vehicle, inp, False, step=True)
        b_cb = _bare(p, states, True)
        b = _bare(p, states, False)
        one, two = _threads(vehicle, inp, 1), _threads(vehicle, inp, 2)
        fig["compiled_rtf"].append(seconds / c)
        fig["python_rtf"].append(seconds / py)
        fig["python_c_step_rtf"].append(seconds / pc)
        fig["compiled_over_python"].append(c / py)
        fig["compiled_over_bare_cb"].append(c / b_cb)
        fig["compiled_over_bare"].append(c / b)
        fig["extras_over_compiled"].append(ce / c)
        fig["threads_speedup"].append(one / two)
        fig["cli_rtf_60"].append(60.0 / _cli(60.0))
        fig["cli_rtf_600"].append(600.0 / _cli(600.0))
    p.close()
    print(f"Plant in the harness, {seconds:.0f} s constant steer, RK4 at "
          f"{p.model.opt.timestep * 1e3:.0f} ms; median (range) of {ROUNDS} rounds:")
    print(f"  compiled closed loop: {_fmt(fig['compiled_rtf'], 'x')} real time, per step")
    print(f"  Python loop:          {_fmt(fig['python_rtf'], 'x')} real time, per step")
    print(f"  Python loop, Plant.step and observe in C (as the truth's drivers run): "
          f"{_fmt(fig['python_c_step_rtf'], 'x')} real time, per step")
    print(f"  compiled / Python loop time: {_fmt(fig['compiled_over_python'])}")
    print(f"  compiled / bare mj_step with the tyre callback: {_fmt(fig['compiled_over_bare_cb'])}")
    print(f"  compiled / bare mj_step without any callback:   {_fmt(fig['compiled_over_bare'])}")
    print(f"  with the extras gathered / without: {_fmt(fig['extras_over_compiled'])}")
    print(f"  four runs, one thread / two threads: {_fmt(fig['threads_speedup'])}")
    print(f"  artic simulate --model mbd, end to end: 60 s {_fmt(fig['cli_rtf_60'], 'x')}, "
          f"600 s {_fmt(fig['cli_rtf_600'], 'x')} real time")
    return fig


if __name__ == "__main__":
    from artic.validation.plumbing import runtime

    runtime.configure()
    main()
