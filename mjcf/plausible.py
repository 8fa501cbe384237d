"""Plausibility ranges of the vehicle's parameters: refuse the impossible, warn on the odd.

The parameter file's schema (:mod:`artic.mjcf.schema`) checks types, signs and
finiteness, and :func:`artic.mjcf.vehicle.check_geometry` that the symbols and the
axle list describe one geometry. What they let through can still be no
tractor-semitrailer at all: a trailer centre of gravity 100 m up, a steering
ratio of 0.001, a 2 kg tractor. Every number here has two ranges:

- outside the *possible* range the file is refused (:class:`VehicleFileError`
  naming the file and the key): no road vehicle has such a value, and the
  models would run into nonsense or divergence;
- outside the *plausible* range a :class:`PlausibilityWarning` names the key
  and the usual range: a special vehicle may have such a value, a typing
  mistake more often does.

The plausible ranges span European and North American tractors and
semitrailers (EU and FMVSS dimension rules, published inertia and tyre data),
with margin; the possible ranges are ten times wider or physical limits.
Inertias are judged by their radius of gyration ``sqrt(J / m)``.

These are the ranges of the ``full-size`` class. A file that declares
``[vehicle] class = "scale-model"`` is judged by :data:`SCALE_MODEL_RANGES`,
the same ranges carried to model scale by similitude: a quantity of length
dimension ``e`` (1 for lengths, 3 for masses, 2 for spring rates ``m g / sag``,
2.5 for damping ``sqrt(k m)``, 5 for spin inertias ``m r^2``, 0 for angles and
ratios) scales by ``s^e``. The plausible range spans hobby kits and laboratory
robots, ``s`` from 1:32 to 1:4; the possible range ``s`` from 1:100 to 1:2. A value
outside its class's possible range is refused; the message names the class option
when another class would take it, and a value outside every class's is refused
whatever the class.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

# The warning is named here too: users filter artic.mjcf.plausible.PlausibilityWarning.
from artic.mjcf.ranges import PlausibilityWarning, Range  # noqa: F401
from artic.mjcf.schema import VehicleFileError
from artic.mjcf.tir import TirError, read_tir

if TYPE_CHECKING:  # pragma: no cover
    from artic.mjcf.vehicle import Vehicle


INF = math.inf

VEHICLE_RANGES: dict[str, Range] = {
    "tractor.m1": Range(500.0, 3000.0, 25000.0, 60000.0, "kg"),
    "tractor.J1 (radius of gyration)": Range(0.2, 0.6, 3.0, 10.0, "m"),
    "tractor.a1 + tractor.b1 (wheelbase L1)": Range(1.0, 2.5, 7.0, 15.0, "m"),
    "tractor.L1c": Range(-5.0, -1.0, 2.0, 5.0, "m"),
    "tractor.h1": Range(0.1, 0.5, 2.0, 5.0, "m"),
    "tractor.h5": Range(0.2, 0.8, 1.6, 5.0, "m"),
    "trailer.m2": Range(300.0, 1500.0, 50000.0, 150000.0, "kg"),
    "trailer.J2 (radius of gyration)": Range(0.2, 1.0, 6.0, 20.0, "m"),
    "trailer.a2": Range(0.1, 1.0, 12.0, 30.0, "m"),
    "trailer.L2": Range(1.0, 3.0, 15.0, 30.0, "m"),
    "trailer.j": Range(0.0, 0.0, 2.5, 5.0, "m"),
    "trailer.h2": Range(0.1, 0.5, 2.6, 5.0, "m"),
    # Axles per unit: a road tractor has 2 to 3 (4x2, 6x4; 8x4 heavy haul 4), a semitrailer
    # 1 to 4 (EU 96/53/EC sets the weights of up to 3; four-axle ones run in Scandinavia);
    # heavy-haul low-bed semitrailers reach 8. Beyond that it is a modular trailer (its own
    # steering, no fifth wheel), not a tractor-semitrailer that KIN, the STM and the plant
    # describe.
    "tractor.axle (number)": Range(1.0, 2.0, 3.0, 5.0, "axles"),
    "trailer.axle (number)": Range(1.0, 1.0, 4.0, 8.0, "axles"),
    "axle.track": Range(0.5, 1.5, 2.6, 5.0, "m"),
    "axle.unsprung_mass": Range(1.0, 100.0, 3000.0, 10000.0, "kg"),
    "axle.suspension_stiffness": Range(1e3, 5e4, 1e7, 1e9, "N/m"),
    "axle.suspension_damping": Range(10.0, 1e3, 3e5, 1e8, "N s/m"),
    "axle.wheel_inertia": Range(0.01, 2.0, 80.0, 1000.0, "kg m^2"),
    "steering.i_s": Range(1.0, 10.0, 40.0, 200.0, ""),
    "steering.q": Range(0.0, 0.0, 0.05, 1.0, "1/rad"),
    "steering.delta_h_offset": Range(-math.pi, -0.35, 0.35, math.pi, "rad"),
    "steering.delta_max": Range(0.05, 0.4, 0.95, 1.5, "rad"),
    "steering.steering_arm": Range(0.02, 0.1, 0.5, 2.0, "m"),
    "tyre.f": Range(0.1, 2.0, 20.0, 100.0, "1/rad"),
    "tyre.sigma_alpha": Range(0.01, 0.1, 2.0, 20.0, "m"),
    "limits.gamma_max": Range(0.1, 0.8, 1.6, math.pi, "rad"),
    "limits.hitch_pitch": Range(0.0, 0.02, 0.4, 1.5, "rad"),
    "sensor.x": Range(-40.0, -20.0, 10.0, 40.0, "m"),
    "sensor.y": Range(-5.0, -2.0, 2.0, 5.0, "m"),
    "sensor.z": Range(-2.0, 0.0, 4.5, 10.0, "m"),
}
"""Keys (or derived quantities) and their ranges: the ``full-size`` class."""

MODEL_SCALES = (1 / 100, 1 / 32, 1 / 4, 1 / 2)
"""Length scales of the ``scale-model`` class: possible and plausible, smallest to largest."""

DIMENSION: dict[str, float] = {
    "tractor.m1": 3.0, "trailer.m2": 3.0, "axle.unsprung_mass": 3.0,
    "axle.suspension_stiffness": 2.0, "axle.suspension_damping": 2.5,
    "axle.wheel_inertia": 5.0,
    **{k: 1.0 for k in ("tractor.J1 (radius of gyration)",
                        "tractor.a1 + tractor.b1 (wheelbase L1)", "tractor.L1c", "tractor.h1",
                        "tractor.h5", "trailer.J2 (radius of gyration)", "trailer.a2",
                        "trailer.L2", "trailer.j", "trailer.h2", "axle.track",
                        "steering.steering_arm", "tyre.sigma_alpha", "sensor.x", "sensor.y",
                        "sensor.z")},
}
"""Length dimension of each judged number (absent: 0, an angle or a ratio)."""


def _scaled(r: Range, e: float) -> Range:
    """``r`` carried to model scale (see the module docstring)."""
    slo, plo, phi, shi = (s ** e for s in MODEL_SCALES)
    return Range(r.lo * (shi if r.lo < 0 else slo), r.plo * (phi if r.plo < 0 else plo),
                 r.phi * (phi if r.phi > 0 else plo), r.hi * (shi if r.hi > 0 else slo), r.unit)


SCALE_MODEL_RANGES: dict[str, Range] = {
    **{k: _scaled(r, DIMENSION.get(k, 0.0)) for k, r in VEHICLE_RANGES.items()},
    # A model's steering channel is mostly its road-wheel angle or a servo command.
    "steering.i_s": Range(0.1, 1.0, 40.0, 200.0, ""),
}
"""The ranges of the ``scale-model`` class."""

CLASS_RANGES: dict[str, dict[str, Range]] = {"full-size": VEHICLE_RANGES,
                                             "scale-model": SCALE_MODEL_RANGES}
"""Every vehicle class's ranges, by the name ``[vehicle] class`` takes."""


def _values(v: Vehicle) -> list[tuple[str, str, float]]:
    """``(range key, key as the file names it, value)`` for every judged number."""
    out = [
        ("tractor.m1", "tractor.m1", v.m1),
        ("tractor.J1 (radius of gyration)", "tractor.J1", math.sqrt(v.J1 / v.m1)),
        ("tractor.a1 + tractor.b1 (wheelbase L1)", "tractor.a1 + tractor.b1", v.L1),
        ("tractor.L1c", "tractor.L1c", v.L1c),
        ("tractor.h1", "tractor.h1", v.h1),
        ("tractor.h5", "tractor.h5", v.h5),
        ("trailer.m2", "trailer.m2", v.m2),
        ("trailer.J2 (radius of gyration)", "trailer.J2", math.sqrt(v.J2 / v.m2)),
        ("trailer.a2", "trailer.a2", v.a2),
        ("trailer.L2", "trailer.L2", v.L2),
        ("trailer.j", "trailer.j", v.j),
        ("trailer.h2", "trailer.h2", v.h2),
        ("tractor.axle (number)", "tractor.axle",
         sum(a.unit == 1 for a in v.axles)),
        ("trailer.axle (number)", "trailer.axle",
         sum(a.unit == 2 for a in v.axles)),
        ("tyre.f", "tyre.f", v.f),
        ("tyre.sigma_alpha", "tyre.sigma_alpha", v.sigma_alpha),
        ("limits.gamma_max", "limits.gamma_max", v.gamma_max),
        ("limits.hitch_pitch", "limits.hitch_pitch", v.hitch_pitch),
        ("steering.delta_max", "steering.delta_max", v.steering.delta_max),
        ("steering.steering_arm", "steering.steering_arm", v.steering.steering_arm),
    ]
    for unit, sensor in (("tractor", v.sensor1), ("trailer", v.sensor2)):
        for axis, x in zip("xyz", sensor, strict=True):
            out.append((f"sensor.{axis}", f"{unit}.sensor ({axis})", x))
    for model in ("", *v.steering_overrides):
        s = v.steering if not model else v.steering_for(model)
        prefix = "steering" if not model else f"steering.{model}"
        if model and not v.steering_overrides.get(model):
            continue
        for key in ("i_s", "q", "delta_h_offset"):
            if model and key not in v.steering_overrides[model]:
                continue
            out.append((f"steering.{key}", f"{prefix}.{key}", getattr(s, key)))
    for a in v.axles:
        unit = "tractor" if a.unit == 1 else "trailer"
        for key in ("track", "unsprung_mass", "suspension_stiffness", "suspension_damping",
                    "wheel_inertia"):
            out.append((f"axle.{key}", f"{unit}.axle '{a.name}'.{key}", getattr(a, key)))
    return out


def check_plausible(v: Vehicle, path: str | Path) -> None:
    """Judge every number of a vehicle against the ranges of its class (:data:`CLASS_RANGES`).

    Raises
    ------
    VehicleFileError
        For an impossible value, naming the file and the key, and the class
        option when another class takes the value.
    """
    cls = v.vehicle_class
    for rng, key, value in _values(v):
        where, value = f"{path}: key '{key}'", float(value)
        if key.startswith("tyre.") and not v.has_tyre_data and not math.isfinite(value):
            continue  # a scale model without tyre data: the STM and the plant refuse it
        r = CLASS_RANGES[cls][rng]
        if not math.isfinite(value):
            raise VehicleFileError(f"{where}: {value!r} is not a finite number")
        if r.possible(value):
            r.warn(value, where)
            continue
        others = [c for c, table in CLASS_RANGES.items() if c != cls and table[rng].possible(value)]
        if others:
            raise VehicleFileError(
                f"{where}: {value:g}{r._u} is impossible for a tractor-semitrailer of class "
                f"{cls} (possible: {r.span}); check the value and its unit, or, for a "
                f"vehicle of class {others[0]} (possible: {CLASS_RANGES[others[0]][rng].span}), "
                f"declare [vehicle] class = \"{others[0]}\"")
        spans = "; ".join(f"{c}: {t[rng].span}" for c, t in CLASS_RANGES.items())
        raise VehicleFileError(f"{where}: {value:g}{r._u} is impossible for a tractor-semitrailer "
                               f"of any class ({spans}); check the value and its unit")


def check_tir_file(path: Path, context: str) -> Path:
    """Read a tyre property file and judge its coefficients (see :mod:`artic.mjcf.tir`).

    Returns
    -------
    Path
        ``path``, once it passed.

    Raises
    ------
    VehicleFileError
        ``context`` (the vehicle file and key) followed by the tyre file's error.
    """
    try:
        read_tir(path)
    except TirError as exc:
        raise VehicleFileError(f"{context}: {exc}") from None
    return path


def check_tyre_data(v: Vehicle, model: str,
                    instead: str = "KIN needs none: use --models kin") -> None:
    """Refuse to build ``model`` on tyre data that the vehicle lacks or that does not fit it.

    KIN needs no tyre data and works at any scale. The STM needs ``[tyre] f`` and
    ``sigma_alpha``; a ``scale-model`` file may leave them out (a full-size truck's
    do not fit a model's tyres), and the STM then refuses it. The plant needs a
    tyre file for every axle whose load range ``[FZMIN, FZMAX]`` holds the axle's
    static load per tyre: outside it the Magic Formula extrapolates its load
    dependence, as a truck tyre's data would on a 1:14 model (its 500 N floor is
    fifty times a model's wheel load).

    Parameters
    ----------
    v : Vehicle
        The vehicle.
    model : str
        ``"stm"`` or ``"mbd"`` (anything else needs no tyre data).
    instead : str
        What the caller can do instead, ending the message (the commands that take
        ``--models`` name KIN; ``artic dock``, which drives the plant, asks for tyre data).

    Raises
    ------
    VehicleFileError
        Naming the vehicle file, the key and what fits.
    """
    where = f"{v.path or v.name}: key"
    if model == "stm" and not (math.isfinite(v.f) and math.isfinite(v.sigma_alpha)):
        raise VehicleFileError(
            f"{where} 'tyre.f': vehicle {v.name} (class {v.vehicle_class}) has no tyre data; "
            "the STM needs [tyre] f [1/rad] and sigma_alpha [m] measured on its own tyres (a "
            f"full-size truck's do not fit a scale model); {instead}")
    if model != "mbd":
        return
    if not v.tyre_file:
        raise VehicleFileError(
            f"{where} 'tyre.file': vehicle {v.name} (class {v.vehicle_class}) has no tyre "
            "file; the plant needs a PAC2002 .tir of its own tyres whose load range FZMIN to "
            f"FZMAX holds its wheel loads; {instead}")
    for axle, fz in zip(v.axles, v.static_loads, strict=True):
        path = v.tyre_file_for(axle)
        tir = read_tir(path)
        lo, hi = tir.number("FZMIN", 0.0), tir.number("FZMAX", math.inf)
        per_tyre = float(fz) / (2 * (2 if axle.dual else 1))
        if not lo <= per_tyre <= hi:
            key = "tyre_file" if axle.tyre_file else "tyre.file"
            raise VehicleFileError(
                f"{where} '{key}': the static load of a tyre on axle '{axle.name}' of vehicle "
                f"{v.name} (class {v.vehicle_class}) is {per_tyre:.4g} N, outside the load "
                f"range FZMIN = {lo:g} N to FZMAX = {hi:g} N of {path}: that tyre data does "
                f"not fit this vehicle; give a .tir of its own tyres ({instead})")
