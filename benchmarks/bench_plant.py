"""The multibody plant's speed: real-time factor and cost over a bare MuJoCo step.

Measured in one run on one machine, driving a 200 deg constant steer at
5 km/h through ``Plant.step`` at the harness's 100 Hz:

- real-time factor of the plant at its default timestep (RK4, 10 ms), with
  the compiled tyre callback and with the numpy reference;
- plant step time / bare ``mj_step`` time of the same model and timestep.
  "Bare" is ``mj_step`` with no passive callback, from the plant's own states:
  every 10 ms of the compiled run the state is recorded, and the bare step
  is timed on two steps from each recorded state (without tyre forces the
  combination would otherwise fall through the ground, a different and
  cheaper computation).

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import math
import time

import mujoco
import numpy as np

from _timing import bare_steps
from artic.mjcf import load_vehicle
from artic.mjcf.interface import InitialState
from artic.plant import Plant

SIM_SECONDS = 10.0
DT = 0.01


def _run(backend: str, seconds: float, states: list | None = None,
         moments: bool = False) -> tuple[float, Plant]:
    import dataclasses

    v = load_vehicle("gosar2022-unloaded")
    v = dataclasses.replace(v, plant=dataclasses.replace(v.plant, tyre_moments=moments))
    u, delta = 5 / 3.6, math.radians(200) / v.steering_for("mbd").i_s
    p = Plant(v, backend=backend)
    p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    wall = 0.0
    for _ in range(int(seconds / DT)):
        if states is not None:
            s = np.empty(mujoco.mj_stateSize(p.model, spec))
            mujoco.mj_getState(p.model, p.data, s, spec)
            states.append(s)
        t0 = time.perf_counter()
        p.step(DT, delta, u, 0.0)
        wall += time.perf_counter() - t0
    return wall, p


def _bare(p: Plant, states: list) -> float:
    return bare_steps(p.model, states, round(DT / p.model.opt.timestep))


def _tyre_ns() -> tuple[float, float, float]:
    """Per wheel evaluation [ns]: compiled, numpy, and compiled with the tyre moments.

    The first two as the default plant runs (``tyre_moments`` off: forces,
    deflection rates, rolling resistance), the third with the aligning and
    bore torques too.
    """
    from artic.plant import ctyre
    from artic.plant.tyre import TyreParams, deflection_rates, rolling_resistance, transient_forces

    p = TyreParams.from_tir(load_vehicle("gosar2022-unloaded").tyre_file)
    rng = np.random.default_rng(0)
    n = 100_000
    # Fz, Vx, Vsx, Vy, omega_z, u, v, phi
    a = (rng.uniform(1e4, 4e4, n), rng.uniform(-3, 3, n), rng.normal(0, 0.3, n),
         rng.normal(0, 0.3, n), rng.normal(0, 0.1, n), rng.normal(0, 0.01, n),
         rng.normal(0, 0.05, n), rng.normal(0, 0.02, n))

    def numpy_eval():
        Fx = transient_forces(p, *a, moments=False)[0]
        deflection_rates(p, *a)
        rolling_resistance(p, a[0], a[1], Fx)

    times = []
    for fn in (lambda: ctyre.evaluate(p, *a, moments=False), numpy_eval,
               lambda: ctyre.evaluate(p, *a, moments=True)):
        fn()
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) / n * 1e9)
    return times[0], times[1], times[2]


def main() -> dict[str, float]:
    c_ns, np_ns, cm_ns = _tyre_ns()
    states: list = []
    wall_c, p = _run("compiled", SIM_SECONDS, states)
    bare = _bare(p, states)
    steps = round(SIM_SECONDS / p.model.opt.timestep)
    p.close()
    wall_m, pm = _run("compiled", SIM_SECONDS, moments=True)
    pm.close()
    wall_np, q = _run("python", SIM_SECONDS / 5)
    q.close()
    wall_np *= 5
    out = {"plant_rtf": SIM_SECONDS / wall_c, "numpy_rtf": SIM_SECONDS / wall_np,
           "moments_rtf": SIM_SECONDS / wall_m, "moments_over_bare": wall_m / bare,
           "plant_over_bare": wall_c / bare, "numpy_over_c": wall_np / wall_c,
           "timestep_ms": p.model.opt.timestep * 1e3,
           "bare_step_us": bare / steps * 1e6, "plant_step_us": wall_c / steps * 1e6}
    out["tyre_c_ns"], out["tyre_numpy_ns"], out["tyre_c_moments_ns"] = c_ns, np_ns, cm_ns
    print(f"Tyre model per wheel evaluation: compiled {c_ns:.0f} ns, numpy (vectorised over "
          f"100 000 wheels) {np_ns:.0f} ns; compiled with the tyre moments {cm_ns:.0f} ns")
    print(f"Plant, {SIM_SECONDS:.0f} s of constant steer, RK4 at {out['timestep_ms']:.0f} ms, "
          "stepped at 100 Hz:")
    print(f"  real-time factor, compiled tyre callback: {out['plant_rtf']:.1f} x")
    print(f"  real-time factor, numpy tyre callback:    {out['numpy_rtf']:.1f} x "
          f"({out['numpy_over_c']:.1f} times slower)")
    print(f"  plant step / bare mj_step: {out['plant_over_bare']:.2f} "
          f"({out['plant_step_us']:.1f} us / {out['bare_step_us']:.1f} us per step)")
    print(f"  with the tyre moments: {out['moments_rtf']:.1f} x real time, "
          f"plant step / bare {out['moments_over_bare']:.2f}")
    return out


if __name__ == "__main__":
    from artic.validation.plumbing import runtime

    runtime.configure()  # as the artic command does: MuJoCo's step timers quiet
    main()
