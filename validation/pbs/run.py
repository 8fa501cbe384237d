"""The low-speed manoeuvres on one model, and their measures.

Three manoeuvres (:data:`MANOEUVRES`), each a prescribed path for the steer
axle's centre (:mod:`artic.validation.pbs.standards`):

- ``pbs``: the PBS low-speed 90-degree turn, left, the steer tyre's outer
  edge on 12.5 m (the axle's centre on 12.5 m less the edge's offset), 30 m
  straight before and 40 m after, at 5 km/h: swept path, frontal swings, tail
  swing, steer-tyre friction demand;
- ``fhwa``: the FHWA turn, right, 41 ft, 60 ft before and 105 ft after, at
  5 mph: the largest off-tracking;
- ``j695``: a turn and a quarter of 41 ft radius after 20 m straight, at 5 km/h: the
  steady off-tracking over the circle's last tenth (the transient off-tracking
  decays over about a semitrailer wheelbase, and the arc is thirteen).

:func:`run_model` drives one model through all three with
:class:`artic.validation.pbs.driver.PathDriver`; the models are KIN, the STM
and the plant built from the vehicle file, and ``truth``, the synthetic
campaign's yard truth of a seed (for the gosar2022 presets only: the truth is
drawn around them), on a flat yard and without its column's drift.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import Vehicle, load_vehicle
from artic.validation.pbs import friction, offtracking, swing
from artic.validation.pbs.driver import PathDriver, drive_path
from artic.validation.pbs.motion import Geometry, Motion
from artic.validation.pbs.paths import TurnPath
from artic.validation.pbs.standards import (
    FHWA_ENTRY,
    FHWA_EXIT,
    FHWA_RADIUS,
    FHWA_SPEED,
    J695_RADIUS,
    PBS_ANGLE,
    PBS_RADIUS,
    PBS_SPEED,
)
from artic.validation.pbs.sweep import swept_width

MANOEUVRES = ("pbs", "fhwa", "j695")

MEASURES = {
    # column: (unit, manoeuvre, what)
    "swept_width": ("m", "pbs", "low-speed swept path: widest cross-section of the swept path"),
    "frontal_swing": ("m", "pbs", "tractor's front outside corner beyond the steer tyre's path"),
    "trailer_frontal_swing": ("m", "pbs", "semitrailer's front outside corner outside the "
                              "tractor's side"),
    "tail_swing": ("m", "pbs", "semitrailer's rear outside corner outwards of its entry line"),
    "steer_friction": ("%", "pbs", "steer-axle friction demand, share of a 0.8 road's peak"),
    "fhwa_offtracking": ("m", "fhwa", "largest off-tracking of the semitrailer axle group"),
    "j695_offtracking": ("m", "j695", "steady off-tracking on the circle (SAE J695)"),
    "path_error": ("m", "pbs", "largest distance of the steer axle from its path (driver)"),
}
"""Every measure: its unit, the manoeuvre it is taken in, and one line of what it is."""

J695_ANGLE = 2.5 * math.pi
"""Angle of J695's circle [rad]: a turn and a quarter, 98 m of arc, thirteen
semitrailer wheelbases: the off-tracking's transient, which decays over about
one wheelbase of travel, is gone to e**-10 of itself by the last tenth."""

MODELS = ("kin", "stm", "mbd", "truth")

TRUTH_LOADS = {"gosar2022-unloaded": "unloaded", "gosar2022-loaded": "loaded"}


def paths(g: Geometry) -> dict[str, tuple[TurnPath, float]]:
    """Each manoeuvre's steer-axle path and speed [m/s] for geometry ``g``."""
    return {"pbs": (TurnPath(30.0, PBS_RADIUS - g.steer_edge, PBS_ANGLE, 40.0, 1.0), PBS_SPEED),
            "fhwa": (TurnPath(FHWA_ENTRY, FHWA_RADIUS, math.pi / 2, FHWA_EXIT, -1.0),
                     FHWA_SPEED),
            "j695": (TurnPath(20.0, J695_RADIUS, J695_ANGLE, 10.0, 1.0), PBS_SPEED)}


@dataclass
class ModelRun:
    """One model's drives and measures.

    Attributes
    ----------
    name : str
        The model.
    vehicle : Vehicle
        The parameters it ran with (the truth's own for the truth).
    drives : dict
        Per manoeuvre: ``(t, obs, delta)``.
    measures : dict
        Per measure of :data:`MEASURES`: its value (NaN where not available).
    """

    name: str
    vehicle: Vehicle
    drives: dict = field(default_factory=dict)
    measures: dict = field(default_factory=dict)


def truth_seat(vehicle: Vehicle, seed: int, kind: str | None = None):
    """The truth of ``seed`` (of ``kind``, the default's) for ``vehicle``'s load, flat, no drift.

    Returns its vehicle, its model (to close) and the driver's seat.
    """
    from artic.validation.synthetic.actuation import SteeringColumn
    from artic.validation.synthetic.truth import truth_configuration, truth_vehicle
    from artic.validation.synthetic.truthmodel import truth_actuation, truth_model

    load = TRUTH_LOADS.get(vehicle.name)
    if load is None:
        raise UserError(f"--models truth: the synthetic truth exists for "
                        f"{' and '.join(TRUTH_LOADS)} only, not {vehicle.name}; leave "
                        "truth out of --models")
    truth = (truth_configuration(seed, drift=False) if kind is None
             else truth_configuration(seed, kind, drift=False))
    vt = truth_vehicle(load, truth, seed)
    model = truth_model(vt, truth, "follow")
    return vt, model, truth_actuation(model, vt.steering_for("mbd"), SteeringColumn(0.0, 0.0))


def _build(name: str, vehicle: Vehicle, seed: int, kind: str | None = None):
    """(vehicle, model to drive, forces callable or None, closer)."""
    from artic.validation.models import build, close, driven

    if name == "truth":
        vt, model, seat = truth_seat(vehicle, seed, kind)
        return vt, seat, None, model.close
    m = build(name, vehicle)
    if name == "mbd":
        steer = [a.name for a in vehicle.tractor_axles if a.steered]
        cols = [m.extra_columns.index(f"force.{steer[0]}.{side}.{c}")
                for side in ("L", "R") for c in ("x", "y", "z")]

        def forces():
            return np.asarray(m.extras(), dtype=float)[cols].reshape(2, 3)

        return vehicle, m, forces, lambda: close(m)
    return vehicle, driven(m), None, lambda: close(m)


def measure(name: str, v: Vehicle, drives: dict, f_pbs) -> dict[str, float]:
    """Every measure of one model's drives (:data:`MEASURES`); NaN for a manoeuvre not driven."""
    g = Geometry.of(v)
    p = paths(g)
    out: dict[str, float] = dict.fromkeys(MEASURES, math.nan)
    if "pbs" not in drives:
        return out
    t, obs, _ = drives["pbs"]
    m = Motion.from_observations(v, t, obs)
    path = p["pbs"][0]
    out["swept_width"] = swept_width(path, m.body_points())
    out["frontal_swing"] = swing.frontal_swing(path, m)
    out["trailer_frontal_swing"] = swing.trailer_frontal_swing(path, m)
    out["tail_swing"] = swing.tail_swing(path, m)
    out["steer_friction"] = (friction.friction_demand(f_pbs) if f_pbs is not None
                             else float("nan"))
    out["path_error"] = offtracking.path_error(path, m)
    if "fhwa" not in drives:
        return out
    t, obs, _ = drives["fhwa"]
    out["fhwa_offtracking"] = offtracking.max_offtracking(
        p["fhwa"][0], Motion.from_observations(v, t, obs))
    if "j695" not in drives:
        return out
    t, obs, _ = drives["j695"]
    c = p["j695"][0]
    m = Motion.from_observations(v, t, obs)
    front, rear = m.steer_axle, m.trailer_axle
    cx, cy = c.centre
    turned = np.unwrap(np.arctan2(front[:, 0] - cx, cy - front[:, 1]))  # left turn
    last = (turned >= (1.0 - offtracking.STEADY_SHARE) * c.angle) & (turned <= c.angle)
    out["j695_offtracking"] = offtracking.steady_offtracking(c.centre, front[last], rear[last]) \
        if last.sum() >= 2 else float("nan")
    return out


def run_model(name: str, vehicle: Vehicle, seed: int = 0,
              manoeuvres: tuple[str, ...] = MANOEUVRES, truth: str | None = None) -> ModelRun:
    """Drive model ``name`` (of :data:`MODELS`) through ``manoeuvres`` and measure it.

    ``seed`` and ``truth`` (a kind of :data:`artic.validation.synthetic.truth.TRUTHS`,
    the default's if None) pick the truth.
    """
    v, model, forces, closer = _build(name, vehicle, seed, truth)
    out = ModelRun(name, v)
    g = Geometry.of(v)
    f_pbs = None
    try:
        for man, (path, speed) in paths(g).items():
            if man not in manoeuvres:
                continue
            t, obs, delta, f = drive_path(model, PathDriver(v, path, speed),
                                          forces if man == "pbs" else None)
            out.drives[man] = (t, obs, delta)
            if man == "pbs":
                f_pbs = f
    finally:
        closer()
    out.measures = measure(name, v, out.drives, f_pbs)
    return out


LOAD = "loaded"
"""The preset whose load the campaign's PBS turn drives (:mod:`artic.validation.pbs.trucks`)."""


def truck_measures(name: str, seed: int, truth: str | None = None,
                   load: str = LOAD) -> dict[str, float]:
    """The PBS turn's measures of model ``name`` (or ``"truth"``) built from the ``load`` preset.

    Parameters
    ----------
    name : str
        A model of :data:`MODELS`, or ``"truth"``.
    seed : int
        The truck (the campaign's seed), which draws the truth.
    truth : str, optional
        The kind of truth; the default's if None.
    load : str
        ``"loaded"`` or ``"unloaded"``: the ``gosar2022-`` preset built.

    Returns
    -------
    dict
        Each measure of :data:`MEASURES` by name, in its unit.
    """
    return run_model(name, load_vehicle(f"gosar2022-{load}"), seed, ("pbs",), truth).measures
