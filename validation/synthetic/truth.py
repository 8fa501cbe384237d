"""The synthetic campaign's truth: what the measured vehicle really is.

A campaign's truth is drawn once from its seed. Three kinds:

- ``"independent"`` (the default): a vehicle with its own skeleton, sharing no
  code with the plant under validation
  (:class:`artic.validation.synthetic.yardtruth.YardTruth`, whose docstring
  tabulates every difference): its own MuJoCo model with frame torsion, a cab
  on mounts, a fifth wheel with roll lash and roll steer, TMeasy tyres from a
  published truck-tyre set, a compliant column with play and assist, its own
  loop. It takes every draw of the structural truth below, and then its own
  masses, inertias, centres of gravity, fifth-wheel setting and tyres, drawn
  around values offset from the presets (:data:`OFFSETS`): the presets are a
  specification sheet, not the truck's mean.
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
  spreads of a surveyed installation and a loaded trailer. Kept as the
  positive control of the excess over the floor: known structural effects
  switched on from the plant itself (``docs/design/truth.md``, "What the
  structural and legacy truths still guard").
- ``"legacy"``: the first truth artic had, the plant with four scalars changed
  (the steering ratio and offset, and the tractor tyres' LKY and LMUY), driven
  by the plant's own speed controller. Kept because the plant set to it is
  the truth exactly, so replaying its logs shows whatever the harness adds
  (``tests/test_self_reproduction.py``; ``docs/design/truth.md``).

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
from artic.mjcf.vehicle import Vehicle, load_vehicle, resolve_vehicle_path, vehicle_from_dict
from artic.mjcf.writer import updated, write_vehicle

TRUTHS = ("independent", "structural", "legacy")
"""The kinds of truth (see the module docstring); the first is the default."""

DEFAULT = TRUTHS[0]

LOADS = ("unloaded", "loaded")
"""The campaign's load conditions."""

TRAILER_TYRE = "artic-trailer-385-65R22.5.tir"
"""The structural truth's semitrailer tyre, shipped with artic."""

OFFSETS = {
    # name: (offset of the truth's mean from the preset, spread (sd), why)
    "m1": (0.035, 0.01, "relative: fuel, AdBlue, driver and tools over the spec sheet's "
           "kerb weight (90 % fuel, no driver): about 280 kg on 8 t"),
    "J1": (0.08, 0.04, "relative: a spec sheet's yaw inertia is an estimate from masses "
           "and lengths; measured ones differ by 5-15 %"),
    "a1": (-0.05, 0.03, "[m]: full tanks and the driver sit ahead of the centre of "
           "gravity and move it forward"),
    "h1": (0.06, 0.03, "[m]: the kerb-weight height is quoted at nominal ride height, "
           "without the cab's equipment"),
    "L1c": (0.04, 0.02, "[m]: the fifth wheel set a notch forward on its slide for the "
            "axle loads (the kingpin setting)"),
    "m2.loaded": (0.04, 0.02, "relative: pallets weigh more than the waybill says, "
                  "and the tautliner carries its equipment"),
    "m2.unloaded": (0.03, 0.01, "relative: spare wheel, pallet box and straps"),
    "J2.loaded": (0.06, 0.04, "relative: the load spread longer than the model's"),
    "J2.unloaded": (0.04, 0.03, "relative: as J1"),
    "a2.loaded": (-0.20, 0.10, "[m]: the pallets pushed against the headboard"),
    "a2.unloaded": (0.05, 0.03, "[m]: the spare wheel and pallet box under the rear"),
    "h2.loaded": (0.08, 0.05, "[m]: the pallets stacked higher than the model's"),
    "h2.unloaded": (0.02, 0.02, "[m]: ride height"),
    "pressure": (-0.10, 0.04, "relative to the rated inflation: fleet surveys find "
                 "truck tyres about 10 % under-inflated on average"),
    "friction": (-0.05, 0.04, "relative to the tyre pattern's road (0.8): a dusty "
                 "yard's asphalt"),
    "cornering": (-0.05, 0.04, "relative to the pattern's cornering slope: mixed wear "
                  "and retreads"),
}
"""How the independent truth differs from the presets on average, and how much it
spreads: every drawn quantity is ``preset x (1 + offset + N(0, sd))`` (relative)
or ``preset + offset + N(0, sd)`` ([m]). The presets stay what a specification
sheet says; real trucks differ from it, by these stated amounts."""


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
    if kind == "independent":  # after the structural draws, which stay as they were
        body = {k: float(o + rng.normal(0.0, sd)) for k, (o, sd, _) in OFFSETS.items()}
        out["body"] = {k: body[k] for k in OFFSETS if k not in ("pressure", "friction",
                                                                 "cornering")}
        out["tyres"] = {k: 1.0 + body[k] for k in ("pressure", "friction", "cornering")}
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
    if "body" in truth:  # the independent truth: its own masses and positions, in the file
        out["tractor"].update(body_values(v, load, truth))
        out["trailer"].update({k: out["tractor"].pop(k) for k in ("m2", "J2", "a2", "h2")})
        # the payload's lateral offset stays; its length and yaw are in a2 and J2
        out["plant"]["payload_offset"] = [0.0, p["offset"][1], 0.0]
        out["plant"]["payload_yaw_inertia"] = 0.0
    return out


def body_values(v: Vehicle, load: str, truth: dict) -> dict[str, float]:
    """The independent truth's masses, inertias and positions of one load (see :data:`OFFSETS`).

    Parameters
    ----------
    v : Vehicle
        The preset of the load condition.
    load : str
        One of :data:`LOADS`.
    truth : dict
        The configuration (its ``body`` draws).
    """
    b = truth["body"]
    a1 = v.a1 + b["a1"]
    return {"m1": v.m1 * (1.0 + b["m1"]), "J1": v.J1 * (1.0 + b["J1"]), "a1": a1,
            "b1": v.a1 + v.b1 - a1, "h1": v.h1 + b["h1"], "L1c": v.L1c + b["L1c"],
            "m2": v.m2 * (1.0 + b[f"m2.{load}"]), "J2": v.J2 * (1.0 + b[f"J2.{load}"]),
            "a2": v.a2 + b[f"a2.{load}"], "h2": v.h2 + b[f"h2.{load}"]}


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
