"""Batched reduced models: the tuning set integrated in one call.

The 8 forward tuning manoeuvres (constant steers at 200, 360 and 500 deg of
steering wheel, 5 and 10 km/h, 40 s at 100 Hz each), made by the STM itself,
run through ``validation.batch.run_batch`` as one tuning objective
evaluation does. Real-time factor per manoeuvre = simulated time of all
manoeuvres / wall time of the batch call; best of several after a warm-up.
Also the same manoeuvres one call per log, for the ratio.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

from _timing import REPEATS, best_wall
from mjcf import load_vehicle
from reduced import KinematicModel, SingleTrackModel
from validation.batch import run_batch
from validation.harness import loop_inputs, run_inputs
from validation.logs.runfile import Run
from validation.logs.schema import COLUMNS
from validation.simulate import simulate
from validation.steering import SteeringMap
from validation.synthetic.manoeuvres import make_profile

CELLS = [(200, 5), (500, 5), (360, 5), (360, 10)]


def main() -> dict[str, float]:
    v = load_vehicle("gosar2022-unloaded")
    s = v.steering_for("stm")
    logs = []
    for amp, kph in CELLS:
        for side in ("left", "right"):
            p = make_profile("constant-steer", amplitude_deg=amp, speed_kph=kph, side=side,
                             duration=40.0, delta_h_offset=s.delta_h_offset)
            run = simulate(SingleTrackModel(v), v, p)
            logs.append(Run(run.frame[list(COLUMNS)], {"name": f"{amp}-{kph}-{side}"}))
    sim = sum(float(log.frame.t.iloc[-1]) for log in logs)
    out = {}
    for cls in (KinematicModel, SingleTrackModel):
        steering = SteeringMap.from_steering(v.steering_for(cls.name))
        inputs = [loop_inputs(log, v, steering) for log in logs]
        batch = best_wall(lambda cls=cls, inputs=inputs: run_batch(cls, v, inputs))
        single = best_wall(lambda cls=cls, inputs=inputs: [run_inputs(cls(v), i, v)
                                                       for i in inputs])
        out[f"{cls.name}_batch_rtf"] = sim / batch
        out[f"{cls.name}_single_rtf"] = sim / single
    print(f"Tuning set as one batch ({len(logs)} manoeuvres, {sim:.0f} s simulated, best of "
          f"{REPEATS}):")
    for m in ("kin", "stm"):
        print(f"  {m.upper()}: {out[f'{m}_batch_rtf']:8.0f} x real time per manoeuvre as a "
              f"batch, {out[f'{m}_single_rtf']:8.0f} x one call per log "
              f"({out[f'{m}_batch_rtf'] / out[f'{m}_single_rtf']:.2f} times faster)")
    return out


if __name__ == "__main__":
    main()
