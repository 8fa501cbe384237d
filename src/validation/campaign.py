"""The main job: a validation campaign on the embedded default.

Until the multibody plant and the synthetic measured campaign exist, the
"measured" logs come from the single-track model in a *truth configuration*.
That configuration differs from the nominal preset by stated amounts (steering
ratio, steering-wheel offset, cornering stiffness), so the models have real
errors to show. There is one forward and one reversing run:

- forward: constant steer, 360 deg of steering wheel at 5 km/h, to the left;
- reverse: at 3 km/h, a driver steers the articulation up a ramp to 35 deg.

KIN and STM at their nominal parameters are then validated through the
closed-loop harness, and the metrics and tables are written.
"""

from __future__ import annotations

import math
import platform
import time
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from mjcf.vehicle import Vehicle, load_vehicle
from reduced import SingleTrackModel
from validation.logio import Run, atomic_write_text, write_run
from validation.manoeuvres import make_profile
from validation.simulate import drive_articulation, simulate
from validation.steering import SteeringMap
from validation.validate import (
    markdown_table,
    stderr_progress,
    summary_table,
    validate_runs,
    write_metrics,
)

DEFAULT_VEHICLE = "gosar2022-unloaded"

TRUTH = {"i_s_scale": 1.03, "delta_h_offset_add": math.radians(1.0), "f_scale": 0.85}
"""How the truth configuration differs from the nominal preset."""

FORWARD_COLUMNS = ("eps_a", "eps_v", "eps_p", "eps_n")
REVERSE_COLUMNS = ("eps_a", "eps_v", "J_steer", "eps_n")


def truth_vehicle(v: Vehicle) -> Vehicle:
    """The nominal vehicle changed by :data:`TRUTH`."""
    s = v.steering_for("stm")
    steering = replace(s, i_s=s.i_s * TRUTH["i_s_scale"],
                       delta_h_offset=s.delta_h_offset + TRUTH["delta_h_offset_add"])
    return replace(v, f=v.f * TRUTH["f_scale"], steering=steering, steering_overrides={},
                   name=f"{v.name}+truth")


def synthetic_logs(v: Vehicle) -> list[Run]:
    """The forward and the reversing "measured" run, from the truth STM."""
    truth = truth_vehicle(v)
    s = truth.steering
    fwd = make_profile("constant-steer", amplitude_deg=360.0, speed_kph=5.0, side="left",
                       duration=60.0, delta_h_offset=s.delta_h_offset, L1=v.L1, i_s=s.i_s)
    f_run = simulate(SingleTrackModel(truth), truth, fwd)
    f_run.frame = f_run.frame[[c for c in f_run.frame.columns
                               if c not in ("delta", "delta_saturated")]]
    f_run.meta.update(name="constant-steer-360-5kph-left", source="synthetic")
    t = np.arange(0.0, 60.0 + 0.005, 0.01)
    u1 = np.full_like(t, -3.0 / 3.6)
    gamma_ref = math.radians(35.0) * np.clip((t - 5.0) / 30.0, 0.0, 1.0)
    r_run = drive_articulation(SingleTrackModel(truth), truth, t, u1, gamma_ref, gain=2.0,
                               steering=SteeringMap.from_steering(s))
    r_run.meta.update(name="reverse-articulation-35-3kph-left", manoeuvre="reverse-articulation",
                      direction="reverse", speed_kph=3.0, amplitude_deg=35.0)
    truth_meta = {"truth": {**TRUTH, "model": "stm"}, "vehicle": v.name}
    for run in (f_run, r_run):
        run.meta.update(truth_meta)
        run.meta.setdefault("direction", "forward")
    return [f_run, r_run]


def run_campaign(out_dir: Path, vehicle: str = DEFAULT_VEHICLE,
                 models: tuple[str, ...] = ("kin", "stm")) -> dict[str, Path]:
    """Generate the logs, validate the models, write tables.

    Parameters
    ----------
    out_dir : Path
        Output folder: ``logs/``, ``runs/``, ``metrics.csv``, ``tables.md``.
    vehicle : str
        Preset name or parameter file.
    models : tuple of str
        Models to validate.

    Returns
    -------
    dict
        Paths of what was written.
    """
    out_dir = Path(out_dir)
    t0 = time.perf_counter()
    v = load_vehicle(vehicle)
    stderr_progress(f"artic campaign: vehicle {v.name}, models {', '.join(models)}, "
                    f"output {out_dir}")
    logs = synthetic_logs(v)
    for run in logs:
        write_run(run, out_dir / "logs" / f"{run.name}.parquet")
    stderr_progress(f"generated {len(logs)} logs in {time.perf_counter() - t0:.1f} s")
    metrics = validate_runs(logs, v, models, out_dir=out_dir, progress=stderr_progress)
    paths = {"metrics": write_metrics(metrics, out_dir / "metrics.csv")}
    fwd = summary_table(metrics[metrics.direction == "forward"], FORWARD_COLUMNS)
    rev = summary_table(metrics[metrics.direction == "reverse"], REVERSE_COLUMNS)
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    text = "\n".join([
        f"# artic validation ({stamp}, {platform.node() or 'host'}, "
        f"{platform.machine()}, Python {platform.python_version()})", "",
        f"Vehicle `{v.name}`; logs from the STM in the truth configuration {TRUTH}.", "",
        "## Forward (seed Table 2 columns)", "", markdown_table(fwd), "",
        "## Reverse, K = 3 (seed Table 3 columns)", "", markdown_table(rev), "",
    ])
    paths["tables"] = atomic_write_text(out_dir / "tables.md", text)
    print(text)
    stderr_progress(f"done in {time.perf_counter() - t0:.1f} s; results in {out_dir}")
    return paths
