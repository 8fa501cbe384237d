"""The synthetic campaign's truth: what the measured vehicle really is.

A campaign's truth is drawn once from its seed. Three kinds:

- ``"independent"`` (the default): a vehicle that shares neither the tyre
  formula nor the steering model of the plant under validation. It is its own
  MuJoCo model (:class:`artic.validation.synthetic.truthplant.TruthPlant`, whose
  docstring tabulates every difference): TMeasy tyres (another family than the
  plant's PAC2002, :mod:`artic.validation.synthetic.tmeasy`) fitted to the same
  shipped tyre files, twin tyres as two tyres, caster, and a compliant steering
  column with free play and a lagged hydraulic assist, whose right wheel
  follows the left through a compliant tie rod on the exact trapezoid
  (:mod:`artic.validation.synthetic.column`). It takes every draw of the
  structural truth below as well: the play is the column's, the drift of its
  zero stays the random process it was.
- ``"structural"``: the plant itself, differing from the validated presets
  in structure, not only in scale. Each effect below is one that the
  presets leave out, drawn within a stated range:

  ====================================  ==========================================
  effect                                draw
  ====================================  ==========================================
  steering ratio, steering-wheel offset  i_s x N(1, 0.02); 5 deg + N(0, 0.5 deg)
  tyres' stiffness, friction            LKY x N(1, 0.05), LMUY x N(1, 0.03)
  semitrailer tyres                      artic-trailer-385-65R22.5 (another
                                         construction: wide-base, 5 /rad)
  tyre moments                           aligning moment and turn slip on
  fifth-wheel friction                   U(1, 4) kN m (greased to dry plates)
  payload                                CoG N(0, 0.3 m) forward, N(0, 0.04 m)
                                         left (laden; a third of it empty), J2
                                         x N(1, 0.05)
  sensors                                lever arms N(0, 3 cm) per axis, mounting
                                         yaw N(0, 0.2 deg), trailer unit's clock
                                         skew N(0, 10 ms)
  steering column                        free play U(1, 3) deg, offset drift
                                         N(0, 0.5 deg/min)
  driver                                 throttle and brake, reaction U(0.3, 0.6) s,
                                         gain U(0.4, 0.8) /s
  yard                                   per manoeuvre: grade U(-1.5, 1.5) %,
                                         crossfall U(-2, 2) %
  ====================================  ==========================================

  Steering play of a few degrees and yard drainage slopes of 1-2 % are what
  roadworthiness checks and yard design guides allow; the rest are ordinary
  spreads of a surveyed installation and a loaded trailer. Kept for
  regression, as the truth of the release before.
- ``"legacy"``: the first truth artic had, the plant with four scalars changed
  (the steering ratio and offset, and the tractor tyres' LKY and LMUY), driven
  by the plant's own speed controller. Kept for regression: the plant set
  to it replays the logs (see ``tests/test_self_reproduction.py``).

Random processes, which no model of the vehicle can know, are the sensors'
noise, the trailer unit's clock skew and the drift of the column's zero. The
``floor`` (:mod:`artic.validation.models`) is the truth without them.

Each load condition's truth is written as a vehicle file, ``truth-LOAD.toml``,
which every command accepts (the independent truth's tyres and column are
not in it: they are not the plant's; they follow from the file and the
drawn numbers in every log's metadata, ``truth``); the yard's slope changes
per manoeuvre and is in each log's metadata (``slope``), and the measurement
chain's clock skew in its ``sensors``.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import Vehicle, load_vehicle
from artic.mjcf.writer import updated, write_vehicle

TRUTHS = ("independent", "structural", "legacy")
"""The kinds of truth (see the module docstring); the first is the default."""

DEFAULT = TRUTHS[0]

LOADS = ("unloaded", "loaded")
"""The campaign's load conditions."""

TRAILER_TYRE = "artic-trailer-385-65R22.5.tir"
"""The structural truth's semitrailer tyre, shipped with artic."""


def truth_configuration(seed: int, kind: str = DEFAULT, drift: bool = True) -> dict:
    """The truth of a campaign: every drawn number, JSON-serialisable.

    The first four draws are the legacy truth's, in its order, so every kind
    shares the steering and the tyres' scaling; the independent truth's draws
    are the structural one's.

    Parameters
    ----------
    seed : int
        The campaign's seed.
    kind : str
        One of :data:`TRUTHS`.
    drift : bool
        ``False`` stops the column's zero from drifting (``drift_rate`` 0):
        the truth without its one random process of the vehicle, which the
        floor replays (the sensors' noise and clock skew are the sensor model's).
    """
    if kind not in TRUTHS:
        raise UserError(f"truth {kind!r}: expected one of {', '.join(TRUTHS)}")
    rng = np.random.default_rng([seed, 10_000])
    out: dict = {"kind": kind,
                 "i_s_scale": float(1.0 + rng.normal(0.0, 0.02)),
                 "delta_h_offset": float(math.radians(5.0 + rng.normal(0.0, 0.5))),
                 "LKY": float(1.0 + rng.normal(0.0, 0.05)),
                 "LMUY": float(1.0 + rng.normal(0.0, 0.03))}
    if kind == "legacy":
        return out
    payload = {}
    for load, share in (("loaded", 1.0), ("unloaded", 1.0 / 3.0)):
        payload[load] = {"offset": [float(share * rng.normal(0.0, 0.3)),
                                    float(share * rng.normal(0.0, 0.04)), 0.0],
                         "J2_scale": float(1.0 + rng.normal(0.0, 0.05))}
    out.update({
        "trailer_tyre": TRAILER_TYRE,
        "tyre_moments": True,
        "fifth_wheel_friction": float(rng.uniform(1000.0, 4000.0)),
        "payload": payload,
        "sensor1_offset": [float(x) for x in rng.normal(0.0, 0.03, 3)],
        "sensor2_offset": [float(x) for x in rng.normal(0.0, 0.03, 3)],
        "sensor1_yaw": float(math.radians(rng.normal(0.0, 0.2))),
        "sensor2_yaw": float(math.radians(rng.normal(0.0, 0.2))),
        "trailer_clock_skew": float(rng.normal(0.0, 0.01)),
        "backlash": float(math.radians(rng.uniform(1.0, 3.0))),
        "drift_rate": float(math.radians(rng.normal(0.0, 0.5)) / 60.0),
        "driver_delay": float(rng.uniform(0.3, 0.6)),
        "driver_gain": float(rng.uniform(0.4, 0.8)),
    })
    if not drift:
        out["drift_rate"] = 0.0
    return out


def slope(seed: int, index: int, truth: dict) -> dict[str, float]:
    """The yard's grade and crossfall [rad] where manoeuvre ``index`` is driven."""
    if truth["kind"] == "legacy":
        return {"grade": 0.0, "crossfall": 0.0}
    rng = np.random.default_rng([seed, index, 20_000])
    return {"grade": float(math.atan(rng.uniform(-0.015, 0.015))),
            "crossfall": float(math.atan(rng.uniform(-0.02, 0.02)))}


def _changes(v: Vehicle, load: str, truth: dict) -> dict[str, dict]:
    """The truth as vehicle-file sections to change (see :func:`artic.mjcf.writer.updated`)."""
    s = v.steering_for("mbd")
    out: dict[str, dict] = {
        "steering.mbd": {"i_s": s.i_s * truth["i_s_scale"], "q": s.q,
                         "delta_h_offset": truth["delta_h_offset"]},
        "tyre.scaling": {"LKY": truth["LKY"], "LMUY": truth["LMUY"]},
    }
    if truth["kind"] == "legacy":
        return out
    p = truth["payload"][load]
    out["plant"] = {"fifth_wheel_friction": truth["fifth_wheel_friction"],
                    "tyre_moments": truth["tyre_moments"],
                    "payload_offset": p["offset"],
                    "payload_yaw_inertia": v.J2 * (p["J2_scale"] - 1.0)}
    out["tractor"] = {"sensor": [a + b for a, b in zip(v.sensor1, truth["sensor1_offset"],
                                                       strict=True)],
                      "sensor_yaw": truth["sensor1_yaw"]}
    out["trailer"] = {"sensor": [a + b for a, b in zip(v.sensor2, truth["sensor2_offset"],
                                                       strict=True)],
                      "sensor_yaw": truth["sensor2_yaw"]}
    return out


def truth_data(load: str, truth: dict, seed: int) -> dict:
    """The truth of one load condition as vehicle-file data."""
    preset = f"gosar2022-{load}"
    data = updated(preset, _changes(load_vehicle(preset), load, truth),
                   f"The {truth['kind']} truth of artic's synthetic campaign, seed {seed} "
                   "(artic.validation.synthetic.truth)", name=f"truth-{load}")
    if truth["kind"] != "legacy":
        for axle in data["trailer"]["axle"]:
            axle["tyre_file"] = truth["trailer_tyre"]
    return data


def truth_vehicle(load: str, truth: dict, seed: int, slope_: dict | None = None) -> Vehicle:
    """The truth of one load condition, with the yard's slope of one manoeuvre."""
    from artic.mjcf.vehicle import resolve_vehicle_path, vehicle_from_dict

    v = vehicle_from_dict(truth_data(load, truth, seed),
                          resolve_vehicle_path(f"gosar2022-{load}"))
    if slope_:
        v = dataclasses.replace(v, plant=dataclasses.replace(v.plant, **slope_))
    return v


def write_truth_files(out_dir: Path, seed: int, kind: str = DEFAULT) -> dict[str, Path]:
    """Write ``truth-LOAD.toml`` per load condition into ``out_dir``; returns them by load."""
    truth = truth_configuration(seed, kind)
    out = {}
    for load in LOADS:
        path = Path(out_dir) / f"truth-{load}.toml"
        write_vehicle(truth_data(load, truth, seed), path)
        out[load] = path
    return out
