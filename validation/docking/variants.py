"""The unknown semitrailer: the plant's semitrailer drawn from a yard's range of them.

A yard tractor couples a different semitrailer for every job, and nobody tells
it the semitrailer's geometry, load or tyres. ``artic dock --trailer unknown``
builds each run's plant from :func:`vary_semitrailer` of the vehicle file with
the figures :func:`draw_semitrailer` draws for that start, while the planner and
the controllers get the vehicle file as it is.

What varies, and over what range (:data:`RANGES`):

- **the bogie** (``length_error_m``): the whole axle group slides back
  (positive) or forward along the semitrailer, so the kingpin-to-axle length
  ``L2`` changes by that much and the axle spacing ``j`` does not. Sliding
  tandem and tridem bogies travel about 1-1.5 m in steps of 6 in (152 mm),
  set per load to share the weight between the fifth wheel and the bogie;
  semitrailers of one 13.6 m body from different makers and fleets place
  their axle groups within about a metre of each other. Drawn uniformly
  within +-1 m. The bogie's unsprung masses move with it, so the unit's
  centre of gravity and yaw inertia change (parallel-axis theorem);
- **the kingpin setting** (``kingpin_error_m``): where the fifth wheel sits
  on the tractor, ahead of the drive axle (positive forward). Sliding fifth
  wheels are set per semitrailer to bring the drive axle to its load; drawn
  within +-0.15 m of the file's ``L1c`` (the tractor's mass layout is kept:
  the fifth wheel's own mass of a few hundred kilograms is not moved);
- **the payload** (``payload_kg``, ``payload_x_m``): a box of pallets on the
  deck, added to the file's semitrailer, of 0 up to the mass that brings the
  combination to the 40 t gross of an articulated vehicle of five or more
  axles (EU Directive 96/53/EC, Annex I 2.2.2), stacked
  :data:`PAYLOAD_HEIGHT` high on the deck (:data:`DECK_HEIGHT`), as long as
  that mass at the density of a full legal load spread over the 13.6 m deck
  (:data:`PAYLOAD_DENSITY`, at least one pallet row) and
  :data:`PAYLOAD_WIDTH` wide; its centre anywhere on the deck that it fits,
  uniformly. A draw whose load would lift the kingpin or unload an axle is
  drawn again: no one couples such a load;
- **the tyres** (``tyre_scale``): the Magic Formula's cornering-stiffness
  factor ``LKY`` (and KIN's and the STM's ``f``) times 0.8-1.2, the spread of
  truck tyres of one size between makes, tread wear and inflation pressure.
  The plant's scaling factors are one set per vehicle file, so the tractor's
  tyres vary with the semitrailer's; the semitrailer's effective wheelbase
  does not depend on them (below).

The semitrailer's **effective wheelbase** (:func:`effective_wheelbase`) is
what matters for docking: the distance behind the kingpin of the point of the
semitrailer that moves along its own heading, about which it turns at low
speed. For one axle it is the axle; for a tandem or tridem of unsteered axles,
whose tyres scrub, it is where the tyres' side forces have no moment about the
kingpin: with side forces ``C_i alpha_i`` and slip ``alpha_i`` growing
linearly with the distance ``l_i`` behind that point,
``l_0 = sum C_i l_i^2 / sum C_i l_i`` (the equivalent wheelbase of Winkler's
"Simplified analysis of the steady-state turning of complex vehicles",
Vehicle System Dynamics 29, 1998; for equal axle loads of a tridem of spacing
``j`` about ``l``, ``l + 2 j^2 / (3 l)``). ``C_i`` is proportional to the
axle's load, and a load-equalising bogie loads its axles alike, so ``l_0``
depends on the bogie's position only, not on the payload or the tyres'
stiffness: :func:`artic.reduced.kinematic.kin_params` computes it, and the
tests compare it with the plant's steady turning.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.masses import layout
from artic.mjcf.outline import outline
from artic.mjcf.schema import VehicleFileError
from artic.mjcf.vehicle import Vehicle, check_geometry
from artic.reduced.kinematic import kin_params

TRAILERS = ("nominal", "unknown")
"""``--trailer`` choices: the vehicle file's semitrailer, or one drawn per start."""

GROSS_MAX = 40000.0
"""Largest gross mass of the combination [kg]: EU Directive 96/53/EC, Annex I 2.2.2
(articulated vehicles of five or six axles)."""

DECK_HEIGHT = 1.2
"""Height of the semitrailer's deck above the ground [m]: a dock's loading height."""

PAYLOAD_HEIGHT = 1.2
"""Height of the payload's box [m]: one layer of loaded pallets."""

PAYLOAD_WIDTH = 2.4
"""Width of the payload's box [m]: three Euro pallets (0.8 m) across the deck."""

DECK_LENGTH = 13.6
"""Deck length a full legal load spreads over [m] (EU 13.6 m box)."""

PAYLOAD_DENSITY = 24000.0 / DECK_LENGTH
"""Mass per metre of deck of the payload's box [kg/m]: a full legal load of about 24 t
(40 t gross less a tractor and an empty semitrailer) spread over the deck."""

PAYLOAD_MIN_LENGTH = 1.2
"""Shortest payload box [m]: one row of pallets, lengthwise."""

REDRAWS = 50
"""Draws tried before giving up on a vehicle whose ranges give no valid semitrailer."""


@dataclass(frozen=True)
class Range:
    """A uniform range of one semitrailer figure.

    Parameters
    ----------
    low, high : float
        Its bounds, in the figure's unit.
    why : str
        Where the range comes from.
    """

    low: float
    high: float
    why: str


RANGES = {
    "length_error_m": Range(-1.0, 1.0, "sliding tandem/tridem bogies travel about 1-1.5 m "
                                       "in 152 mm steps; makers place the axle group of a "
                                       "13.6 m semitrailer within about a metre of another's"),
    "kingpin_error_m": Range(-0.15, 0.15, "sliding fifth wheels are set per semitrailer "
                                          "for the drive axle's load"),
    "tyre_scale": Range(0.8, 1.2, "cornering stiffness of truck tyres of one size between "
                                  "makes, wear and inflation"),
}
"""The ranges :func:`draw_semitrailer` draws from; the payload's depend on the vehicle
(:func:`payload_range`)."""


@dataclass(frozen=True)
class Draw:
    """One drawn semitrailer, the arguments of :func:`vary_semitrailer`.

    Attributes
    ----------
    length_error_m : float
        Bogie moved back [m].
    kingpin_error_m : float
        Fifth wheel moved forward on the tractor [m].
    payload_kg : float
        Payload added [kg].
    payload_x_m : float
        Its box's centre in the semitrailer's frame, from the kingpin [m] (negative behind).
    tyre_scale : float
        Cornering-stiffness factor [-].
    """

    length_error_m: float = 0.0
    kingpin_error_m: float = 0.0
    payload_kg: float = 0.0
    payload_x_m: float = math.nan
    tyre_scale: float = 1.0

    def vary(self, vehicle: Vehicle) -> Vehicle:
        """The vehicle with this semitrailer (:func:`vary_semitrailer`)."""
        return vary_semitrailer(vehicle, length_error_m=self.length_error_m,
                                payload_kg=self.payload_kg or None,
                                payload_x_m=None if math.isnan(self.payload_x_m)
                                else self.payload_x_m,
                                kingpin_error_m=self.kingpin_error_m,
                                tyre_scale=self.tyre_scale)

    def row(self) -> dict[str, float]:
        """The draw as ``dock.csv`` columns."""
        return {"trailer_length_error_m": self.length_error_m,
                "trailer_kingpin_error_m": self.kingpin_error_m,
                "trailer_payload_kg": self.payload_kg,
                "trailer_payload_x_m": self.payload_x_m,
                "trailer_tyre_scale": self.tyre_scale}


def check_trailer(name: str) -> str:
    """``name`` if it is a ``--trailer`` choice.

    Raises
    ------
    UserError
        One line naming the choices.
    """
    if name not in TRAILERS:
        raise UserError(f"--trailer {name!r}: not a semitrailer choice; use one of "
                        f"{', '.join(TRAILERS)}")
    return name


def effective_wheelbase(vehicle: Vehicle) -> float:
    """The semitrailer's effective wheelbase ``l_0`` behind the kingpin [m].

    See the module docstring: ``sum C_i l_i^2 / sum C_i l_i`` over its axles,
    ``C_i`` proportional to their static loads.
    """
    return float(kin_params(vehicle).L2)


def payload_box(vehicle: Vehicle, payload_kg: float) -> tuple[float, float, float]:
    """The payload's box: its length [m], and where its centre may lie on the deck [m].

    Returns
    -------
    length, x_min, x_max : float
        Its length, and the range of its centre's x in the semitrailer's frame
        (from the kingpin, negative behind) that keeps it on the deck.
    """
    o = outline(vehicle)
    deck = o.trailer_front - o.trailer_rear
    length = min(max(payload_kg / PAYLOAD_DENSITY, PAYLOAD_MIN_LENGTH), deck)
    return length, o.trailer_rear + 0.5 * length, o.trailer_front - 0.5 * length


def payload_range(vehicle: Vehicle) -> tuple[float, float]:
    """Payload that may be added to the vehicle file's semitrailer [kg]: ``(0, max)``.

    Up to :data:`GROSS_MAX` for the combination, none if the file is already there.
    """
    return 0.0, max(0.0, GROSS_MAX - vehicle.m1 - vehicle.m2)


def _combine(parts: list[tuple[float, float, float]]) -> tuple[float, float, float]:
    """Mass [kg], centre x [m] and yaw inertia about it [kg m^2] of point-like parts.

    Each part is ``(mass, x, own yaw inertia)``; the parallel-axis theorem adds
    ``mass (x - x_g)^2`` for each.
    """
    m = sum(p[0] for p in parts)
    x_g = sum(p[0] * p[1] for p in parts) / m
    J = sum(p[2] + p[0] * (p[1] - x_g) ** 2 for p in parts)
    return m, x_g, J


def vary_semitrailer(vehicle: Vehicle, *, length_error_m: float = 0.0,
                     payload_kg: float | None = None, payload_x_m: float | None = None,
                     kingpin_error_m: float = 0.0, tyre_scale: float = 1.0) -> Vehicle:
    """The vehicle with another semitrailer: its bogie moved, a payload, the fifth wheel, tyres.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle file's combination (its ``[plant]`` payload offset is folded
        in first, :meth:`~artic.mjcf.vehicle.Vehicle.with_payload`).
    length_error_m : float
        The semitrailer's axle group moved back by this much (forward if
        negative), with its unsprung masses [m]: ``L2`` grows by it.
    payload_kg : float, optional
        Mass added as a box on the deck [kg] (:func:`payload_box`), none by default.
    payload_x_m : float, optional
        The box's centre, semitrailer frame from the kingpin [m] (negative
        behind); the middle of where it fits on the deck by default.
    kingpin_error_m : float
        The fifth wheel moved forward on the tractor [m]: ``L1c`` grows by it.
    tyre_scale : float
        Factor on the tyres' cornering stiffness (``LKY`` and ``f``) [-].

    Returns
    -------
    Vehicle
        Checked as a vehicle file is (its geometry and static loads).

    Raises
    ------
    UserError
        For a payload or tyre factor out of range, a box off the deck, or a
        semitrailer that the vehicle checks reject (the kingpin would lift, an
        axle would carry nothing), naming which.
    """
    v = vehicle.with_payload()
    if not (math.isfinite(length_error_m) and math.isfinite(kingpin_error_m)):
        raise UserError("vary_semitrailer: length_error_m and kingpin_error_m must be finite [m]")
    if not (math.isfinite(tyre_scale) and tyre_scale > 0.0):
        raise UserError(f"vary_semitrailer: tyre_scale {tyre_scale}: must be a positive factor")
    m2, x_g, J2 = v.m2, -v.a2, v.J2
    if length_error_m:
        trailer = v.trailer_axles
        m_u = sum(a.unsprung_mass for a in trailer)
        x_u = sum(a.unsprung_mass * a.x for a in trailer) / m_u
        # The rest of the unit, about its own centre, then the bogie moved back.
        m_r = m2 - m_u
        x_r = (m2 * x_g - m_u * x_u) / m_r
        J_r = J2 - m_r * (x_r - x_g) ** 2 - m_u * (x_u - x_g) ** 2  # own inertias, lumped
        m2, x_g, J2 = _combine([(m_r, x_r, J_r), (m_u, x_u - length_error_m, 0.0)])
        axles = tuple(replace(a, x=a.x - length_error_m) if a.unit == 2 else a for a in v.axles)
        v = replace(v, axles=axles, L2=v.L2 + length_error_m)
    h2 = v.h2
    if payload_kg:
        if not (math.isfinite(payload_kg) and payload_kg > 0.0):
            raise UserError(f"vary_semitrailer: payload_kg {payload_kg}: must be a positive "
                            "mass [kg]")
        length, lo, hi = payload_box(v, payload_kg)
        x_p = 0.5 * (lo + hi) if payload_x_m is None else float(payload_x_m)
        if not lo - 1e-9 <= x_p <= hi + 1e-9:
            raise UserError(f"vary_semitrailer: payload_x_m {x_p:.3f}: a {length:.2f} m "
                            f"payload lies on the deck with its centre at {lo:.2f} to "
                            f"{hi:.2f} m from the kingpin")
        J_p = payload_kg * (length ** 2 + PAYLOAD_WIDTH ** 2) / 12.0  # a box about its centre
        h_p = DECK_HEIGHT + 0.5 * PAYLOAD_HEIGHT
        h2 = (m2 * h2 + payload_kg * h_p) / (m2 + payload_kg)
        m2, x_g, J2 = _combine([(m2, x_g, J2), (payload_kg, x_p, J_p)])
    v = replace(v, m2=m2, a2=-x_g, J2=J2, h2=h2, L1c=v.L1c + kingpin_error_m)
    if tyre_scale != 1.0:
        scaling = dict(v.tyre_scaling)
        scaling["LKY"] = scaling.get("LKY", 1.0) * tyre_scale
        v = replace(v, tyre_scaling=tuple(sorted(scaling.items())), f=v.f * tyre_scale)
    try:
        check_geometry(v, f"{vehicle.name} with another semitrailer")
        if v.tyre_file:
            layout(v)  # the plant's bodies: chassis mass and yaw inertia left positive
    except VehicleFileError as exc:
        raise UserError(f"vary_semitrailer: {exc}") from None
    return v


def draw_semitrailer(vehicle: Vehicle, rng: np.random.Generator) -> tuple[Draw, Vehicle]:
    """A semitrailer from the yard's range (:data:`RANGES`, :func:`payload_range`).

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle file's combination.
    rng : Generator
        This start's own stream (apart from the start's and the sensors').

    Returns
    -------
    draw : Draw
        The figures drawn.
    plant_vehicle : Vehicle
        The vehicle with that semitrailer.

    Raises
    ------
    UserError
        For a vehicle that is not full-size, or when no draw of :data:`REDRAWS`
        gives a valid semitrailer (a vehicle file far from the ranges).
    """
    if vehicle.vehicle_class != "full-size":
        raise UserError(f"--trailer unknown: the semitrailer ranges are a full-size one's; "
                        f"{vehicle.name} is of class {vehicle.vehicle_class}: use "
                        "--trailer nominal")
    r = RANGES
    p_lo, p_hi = payload_range(vehicle)
    last = ""
    for _ in range(REDRAWS):
        length = float(rng.uniform(r["length_error_m"].low, r["length_error_m"].high))
        kingpin = float(rng.uniform(r["kingpin_error_m"].low, r["kingpin_error_m"].high))
        tyres = float(rng.uniform(r["tyre_scale"].low, r["tyre_scale"].high))
        payload = float(rng.uniform(p_lo, p_hi))
        u = float(rng.uniform())  # where on the deck, drawn whatever the payload
        x_p = math.nan
        if payload > 0.0:
            moved = replace(vehicle, axles=tuple(
                replace(a, x=a.x - length) if a.unit == 2 else a for a in vehicle.axles))
            _, lo, hi = payload_box(moved, payload)
            x_p = lo + u * (hi - lo)
        draw = Draw(length, kingpin, payload, x_p, tyres)
        try:
            return draw, draw.vary(vehicle)
        except UserError as exc:
            last = str(exc)
    raise UserError(f"--trailer unknown: {REDRAWS} semitrailers drawn for {vehicle.name} were "
                    f"all invalid (last: {last}); the ranges are a full-size semitrailer's")
