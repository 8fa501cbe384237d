"""The multibody plant's speed: real-time factor and cost over a bare MuJoCo step.

Measured in one run on one machine:

- real-time factor of the plant at its default timestep (RK4, 5 ms), driving
  a 200 deg constant steer at 5 km/h through ``Plant.step``;
- plant step time / bare ``mj_step`` time of the same model and timestep with
  no passive callback (so no tyre forces: the model falls, which costs
  MuJoCo nothing extra without contacts).

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import math
import time

import mujoco

from mjcf import load_vehicle
from plant import Plant
from reduced import InitialState

SIM_SECONDS = 10.0


def main() -> dict[str, float]:
    v = load_vehicle("gosar2022-unloaded")
    u, delta = 5 / 3.6, math.radians(200) / v.steering_for("mbd").i_s
    with Plant(v) as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
        n = int(SIM_SECONDS / 0.01)
        t0 = time.perf_counter()
        for _ in range(n):
            p.step(0.01, delta, u, 0.0)
        wall = time.perf_counter() - t0
        steps = round(SIM_SECONDS / p.model.opt.timestep)
        model = p.model
    data = mujoco.MjData(model)
    saved = mujoco.get_mjcb_passive()
    mujoco.set_mjcb_passive(None)
    try:
        t0 = time.perf_counter()
        for _ in range(steps):
            mujoco.mj_step(model, data)
        bare = time.perf_counter() - t0
    finally:
        mujoco.set_mjcb_passive(saved)
    out = {"plant_rtf": SIM_SECONDS / wall, "plant_over_bare": wall / bare,
           "timestep_ms": model.opt.timestep * 1e3,
           "bare_step_us": bare / steps * 1e6, "plant_step_us": wall / steps * 1e6}
    print(f"Plant, {SIM_SECONDS:.0f} s of constant steer, RK4 at {out['timestep_ms']:.0f} ms:")
    print(f"  real-time factor: {out['plant_rtf']:.1f} x")
    print(f"  plant step / bare mj_step: {out['plant_over_bare']:.1f} "
          f"({out['plant_step_us']:.0f} us / {out['bare_step_us']:.0f} us per step)")
    return out


if __name__ == "__main__":
    main()
