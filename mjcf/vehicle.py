"""Vehicle parameters: loading, consistency checks and derived quantities.

This module is the single source of truth for every physical number of the
combination. The MJCF generator, the plant's tyres and the reduced models all
read a :class:`Vehicle`; none of them hard-codes a mass, a length or a stiffness.

Frames and symbols (the paper's, ISO 8855: x forward, y left, z up):

- The tractor frame has its origin at the drive-axle centre. The front axle
  is at ``x = L1 = a1 + b1``, the centre of gravity at ``x = b1`` and the
  fifth wheel at ``x = L1c``.
- The semitrailer frame has its origin at the kingpin. Its centre of gravity
  is at ``x = -a2`` and its axles are at ``x = -L2i``, centred on ``-L2``.
- ``Lc = b1 - L1c`` is the distance from the tractor centre of gravity back
  to the hitch.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from artic.mjcf import schema
from artic.mjcf.errors import UserError
from artic.mjcf.plausible import check_plausible, check_tir_file
from artic.mjcf.schema import VehicleFileError
from artic.mjcf.steering import Steering

G = 9.81
"""Gravitational acceleration [m/s^2], as used for the paper's axle loads."""

GEOMETRY_TOL = 1e-3
"""Tolerance on geometric consistency checks [m]: one millimetre."""

REFERENCE_LENGTH = 11.3
"""``L1 + L2`` of the full-size reference, the ``gosar2022`` presets' combination [m]: the
length that :attr:`Vehicle.length_ratio` relates a scale model to."""


@dataclass(frozen=True)
class Axle:
    """One axle of a unit.

    Parameters
    ----------
    name : str
        Unique axle name.
    unit : int
        1 for the tractor, 2 for the semitrailer.
    x : float
        Position along the unit frame [m], forward positive.
    track : float
        Track width [m].
    steered, driven, dual : bool
        Steered by the steering wheel; carries drive torque; twin tyres.
    load_share : float
        Share of its load group's static load [-].
    unsprung_mass : float
        Axle, hubs, brakes and wheels [kg].
    suspension_stiffness, suspension_damping : float
        Vertical rate [N/m] and damping [N s/m], both sides together.
    wheel_inertia : float
        Spin inertia of one wheel end (a wheel or a dual pair) [kg m^2].
    tyre_file : str
        This axle's tyre property file (resolved path), or ``""`` for the
        vehicle's :attr:`Vehicle.tyre_file`.
    """

    name: str
    unit: int
    x: float
    track: float
    steered: bool
    driven: bool
    dual: bool
    load_share: float
    unsprung_mass: float
    suspension_stiffness: float
    suspension_damping: float
    wheel_inertia: float
    tyre_file: str = ""


@dataclass(frozen=True)
class PlantOptions:
    """Effects only the multibody plant has (``[plant]``), each off by default.

    Parameters
    ----------
    fifth_wheel_friction : float
        Dry friction torque of the fifth wheel about its vertical axis [N m].
    hitch_damping : float
        Viscous yaw damping of the fifth wheel [N m s/rad].
    grade, crossfall : float
        Ground slope along and across the yard's axes [rad], positive when
        +x (+y) runs uphill.
    payload_offset : tuple of float
        Shift of the semitrailer's centre of gravity [m], semitrailer axes.
    payload_yaw_inertia : float
        Change of the semitrailer's yaw inertia [kg m^2].
    tyre_moments : bool
        Whether the tyres' aligning moment and turn-slip torque act.
    """

    fifth_wheel_friction: float = 0.0
    hitch_damping: float = 0.0
    grade: float = 0.0
    crossfall: float = 0.0
    payload_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    payload_yaw_inertia: float = 0.0
    tyre_moments: bool = False


@dataclass(frozen=True)
class Vehicle:
    """A tractor-semitrailer combination, as read from a parameter file.

    Use :func:`load_vehicle` to build one; the attributes carry the paper's
    symbols and SI units. Derived quantities are properties.

    See Also
    --------
    artic.load_vehicle : read one from a file or a preset.
    artic.KIN : the kinematic model of it.
    artic.STM : the single-track model of it.
    artic.Plant : the multibody plant of it.

    Examples
    --------
    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-loaded")
    >>> round(vehicle.m2) > round(artic.load_vehicle("gosar2022-unloaded").m2)  # payload [kg]
    True
    """

    name: str
    description: str
    sources: tuple[str, ...]
    m1: float
    J1: float
    a1: float
    b1: float
    L1c: float
    h1: float
    h5: float
    sensor1: tuple[float, float, float]
    m2: float
    J2: float
    a2: float
    L2: float
    j: float
    h2: float
    sensor2: tuple[float, float, float]
    axles: tuple[Axle, ...]
    steering: Steering
    # Compared, but left out of the hash (a dict has none): equal vehicles
    # still hash equal, and a Vehicle can key a cache.
    steering_overrides: dict[str, dict[str, float]] = field(default_factory=dict, hash=False)
    f: float = 6.0
    sigma_alpha: float = 0.45
    gamma_max: float = 1.4
    hitch_pitch: float = 0.2
    tyre_file: str = ""
    path: str = ""
    sensor1_yaw: float = 0.0
    sensor2_yaw: float = 0.0
    plant: PlantOptions = PlantOptions()
    tyre_scaling: tuple[tuple[str, float], ...] = ()
    vehicle_class: str = "full-size"

    # ----------------------------------------------------------- derived
    @property
    def length_ratio(self) -> float:
        """The vehicle's size over the full-size reference's [-].

        1 for the ``full-size`` class, whose thresholds were set for the whole
        class; ``(L1 + L2) / REFERENCE_LENGTH`` for a ``scale-model``.
        """
        if self.vehicle_class == "full-size":
            return 1.0
        return (self.L1 + self.L2) / REFERENCE_LENGTH

    @property
    def speed_ratio(self) -> float:
        """The vehicle's speeds over the full-size reference's [-]: ``sqrt(length_ratio)``.

        Froude similitude: a geometrically similar model with the same ratio of
        lateral acceleration to gravity (the same manoeuvre, scaled) drives at
        ``sqrt(length_ratio)`` times the speed, and its times and yaw rates scale
        by ``sqrt(length_ratio)`` and its inverse.
        """
        return float(np.sqrt(self.length_ratio))

    @property
    def has_tyre_data(self) -> bool:
        """Whether the file gives ``[tyre]`` data (a scale model may leave it out)."""
        return bool(np.isfinite(self.f) and np.isfinite(self.sigma_alpha) and self.tyre_file)

    @property
    def L1(self) -> float:
        """Tractor wheelbase, front axle to drive axle [m]."""
        return self.a1 + self.b1

    @property
    def Lc(self) -> float:
        """Tractor centre of gravity to hitch [m]."""
        return self.b1 - self.L1c

    @property
    def b2(self) -> float:
        """Semitrailer centre of gravity to the centre of its axle group [m]."""
        return self.L2 - self.a2

    @property
    def tractor_axles(self) -> tuple[Axle, ...]:
        """Tractor axles, front to rear."""
        return tuple(a for a in self.axles if a.unit == 1)

    @property
    def trailer_axles(self) -> tuple[Axle, ...]:
        """Semitrailer axles, front to rear."""
        return tuple(a for a in self.axles if a.unit == 2)

    @property
    def trailer_axle_distances(self) -> np.ndarray:
        """Distances ``L2i`` from the kingpin back to each trailer axle [m]."""
        return np.array([-a.x for a in self.trailer_axles])

    @property
    def sensor2_from_drive_axle(self) -> tuple[float, float, float]:
        """Semitrailer sensor from the tractor drive axle at ``gamma = 0`` [m] (Table 1)."""
        x, y, z = self.sensor2
        return (x + self.L1c, y, z)

    def tyre_file_for(self, axle: Axle) -> str:
        """The tyre property file of ``axle``: its own, or the vehicle's."""
        return axle.tyre_file or self.tyre_file

    def with_payload(self) -> Vehicle:
        """The vehicle with ``[plant]``'s payload offset folded into a2, h2 and J2.

        The plant is built from this; KIN and STM use the file's a2, h2 and J2.
        The lateral offset stays in ``plant.payload_offset`` for the plant's
        mass layout; the rest is zeroed there, so folding twice changes nothing.
        """
        dx, dy, dz = self.plant.payload_offset
        if dx == 0.0 and dz == 0.0 and self.plant.payload_yaw_inertia == 0.0:
            return self
        rest = replace(self.plant, payload_offset=(0.0, dy, 0.0), payload_yaw_inertia=0.0)
        return replace(self, a2=self.a2 - dx, h2=self.h2 + dz,
                       J2=self.J2 + self.plant.payload_yaw_inertia, plant=rest)

    def steering_for(self, model: str) -> Steering:
        """Steering-map parameters for one model, with its overrides applied.

        Parameters
        ----------
        model : str
            ``"kin"``, ``"stm"``, ``"mbd"``, or the name of a model from outside
            artic; a model without a ``[steering.NAME]`` table gets ``[steering]``.
        """
        if not isinstance(model, str) or not re.fullmatch(schema.MODEL_NAME, model):
            raise UserError(f"model name {model!r}: expected one of {schema.MODELS} or a "
                             "registered model's name (lower-case letters, digits, _)")
        return replace(self.steering, **self.steering_overrides.get(model, {}))

    @property
    def static_loads(self) -> np.ndarray:
        """Static vertical load of every axle, in file order [N].

        The combination stands level. Each unit is a rigid body resting on
        its load groups: on the tractor the steered axles and the other axles,
        on the semitrailer all its axles. A group's resultant sits at the
        ``load_share``-weighted mean position of its axles, and the group's
        load divides by ``load_share``. This is what load-equalising
        suspensions do, and it makes every unit statically determinate.
        """
        return _static_loads(self)[0]

    @property
    def kingpin_load(self) -> float:
        """Static vertical load on the fifth wheel [N]."""
        return _static_loads(self)[1]

    @property
    def cornering_stiffness(self) -> np.ndarray:
        """Axle cornering stiffness ``C_i = f * Fz_i``, in file order [N/rad]."""
        return self.f * self.static_loads

    def flat(self) -> dict[str, Any]:
        """Resolved parameters, derived values and axle loads, keyed by the paper's symbols.

        Axles are numbered over the combination from the front, as the
        paper's ``Fz1 ... Fz5``.
        """
        out: dict[str, Any] = {"name": self.name, "path": self.path,
                               "class": self.vehicle_class}
        for key in ("m1", "J1", "a1", "b1", "L1c", "L1", "Lc", "h1", "h5",
                    "m2", "J2", "a2", "b2", "L2", "j", "h2", "f", "sigma_alpha", "gamma_max"):
            out[key] = float(getattr(self, key))
        for i, d in enumerate(self.trailer_axle_distances, start=1):
            out[f"L2{i}"] = float(d)
        out["x_s1"], out["y_s1"], out["z_s1"] = self.sensor1
        out["x_s2"], out["y_s2"], out["z_s2"] = self.sensor2
        for model in schema.MODELS:
            s = self.steering_for(model)
            for key in ("i_s", "q", "delta_h_offset"):
                out[f"{key}_{model}"] = float(getattr(s, key))
        for key in ("i_s", "q", "delta_h_offset", "delta_max", "steering_arm"):
            out[key] = float(getattr(self.steering, key))
        out["hitch_pitch"] = self.hitch_pitch
        out["tyre_file"] = self.tyre_file
        loads = self.static_loads
        for i, (axle, fz) in enumerate(zip(self.axles, loads, strict=True), start=1):
            out[f"Fz{i}"] = float(fz)
            out[f"axle{i}.name"] = axle.name
            out[f"axle{i}.unit"] = axle.unit
            out[f"axle{i}.x"] = axle.x
            out[f"axle{i}.track"] = axle.track
            out[f"axle{i}.steered"] = axle.steered
            out[f"axle{i}.driven"] = axle.driven
            out[f"axle{i}.dual"] = axle.dual
            out[f"axle{i}.load_share"] = axle.load_share
            for key in ("unsprung_mass", "suspension_stiffness", "suspension_damping",
                        "wheel_inertia"):
                out[f"axle{i}.{key}"] = getattr(axle, key)
        out["Fz_k"] = float(self.kingpin_load)
        return out


def _group_resultant(axles: tuple[Axle, ...]) -> float:
    """Position of a load group's resultant [m]."""
    return sum(a.load_share * a.x for a in axles)


def _static_loads(v: Vehicle) -> tuple[np.ndarray, float]:
    W1, W2 = v.m1 * G, v.m2 * G
    trailer = v.trailer_axles
    x_r2 = _group_resultant(trailer)
    # Moments about the kingpin: the trailer group carries W2 * a2 / |x_r2|.
    R2 = W2 * v.a2 / -x_r2
    Fk = W2 - R2
    front = tuple(a for a in v.tractor_axles if a.steered)
    rear = tuple(a for a in v.tractor_axles if not a.steered)
    x_f, x_r = _group_resultant(front), _group_resultant(rear)
    # Moments about the rear group's resultant: W1 at b1 and Fk at L1c push down.
    R_front = (W1 * (v.b1 - x_r) + Fk * (v.L1c - x_r)) / (x_f - x_r)
    R_rear = W1 + Fk - R_front
    group_load = {1: R_front, 2: R_rear, 3: R2}
    loads = []
    for a in v.axles:
        g = 3 if a.unit == 2 else (1 if a.steered else 2)
        loads.append(group_load[g] * a.load_share)
    return np.array(loads), Fk


# ------------------------------------------------------------------ loading
def preset_names() -> list[str]:
    """Names of the presets shipped with artic.

    See Also
    --------
    artic.load_vehicle : load one of them.

    Examples
    --------
    >>> import artic
    >>> "gosar2022-loaded" in artic.preset_names()
    True
    """
    files = resources.files("artic.mjcf") / "presets"
    return sorted(p.name[:-5] for p in files.iterdir() if p.name.endswith(".toml"))


def resolve_vehicle_path(name_or_path: str | Path) -> Path:
    """Turn a preset name or a file path into a file path.

    Raises
    ------
    VehicleFileError
        If it is neither a preset nor an existing file.
    """
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists():
        if not p.is_file():
            raise VehicleFileError(f"{p}: no such vehicle parameter file")
        return p
    names = preset_names()
    if str(name_or_path) in names:
        return Path(str(resources.files("artic.mjcf") / "presets" / f"{name_or_path}.toml"))
    raise VehicleFileError(
        f"{name_or_path!r} is neither a preset nor a file; presets are: {', '.join(names)}")


def resolve_tyre_file(name: str, vehicle_path: str | Path, key: str = "tyre.file") -> Path:
    """Find a tyre property file: beside the vehicle file, or shipped with artic.

    Raises
    ------
    VehicleFileError
        Naming the vehicle file and the key ``tyre.file``.
    """
    if not name.lower().endswith(".tir") or "\0" in name:
        raise VehicleFileError(f"{vehicle_path}: key 'tyre.file': {name!r} is not a .tir "
                               "file; name a PAC2002 tyre property file (.tir)")
    here = Path(vehicle_path).parent / name
    if here.is_file():
        return check_tir_file(here, f"{vehicle_path}: key 'tyre.file'")
    shipped = Path(str(resources.files("artic.mjcf") / "tyres" / name))
    if shipped.is_file():
        return check_tir_file(shipped, f"{vehicle_path}: key 'tyre.file'")
    raise VehicleFileError(
        f"{vehicle_path}: key '{key}': {name!r} is neither beside the vehicle file nor "
        f"shipped with artic (shipped: {', '.join(tyre_names())})")


def tyre_names() -> list[str]:
    """Tyre property files shipped with artic."""
    files = resources.files("artic.mjcf") / "tyres"
    return sorted(p.name for p in files.iterdir() if p.name.endswith(".tir"))


def load_vehicle(name_or_path: str | Path) -> Vehicle:
    """Load and check a vehicle parameter file.

    Parameters
    ----------
    name_or_path : str or Path
        A preset name (``gosar2022-unloaded``, ``gosar2022-loaded``,
        ``six-axle``) or a path to a TOML file.

    Returns
    -------
    Vehicle

    Raises
    ------
    VehicleFileError
        For a missing file, invalid TOML, an unknown or missing key, a value
        out of range, or inconsistent geometry. The message names the file and
        the key.

    See Also
    --------
    artic.preset_names : the presets' names.
    artic.Vehicle : what it returns.
    artic.Plant : the multibody plant built from it.

    Examples
    --------
    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> vehicle.L1, vehicle.m1  # tractor wheelbase [m], tractor mass [kg]
    (3.8, 8060.0)
    """
    path = resolve_vehicle_path(name_or_path)
    return vehicle_from_dict(read_vehicle_toml(path), path)


MAX_FILE_BYTES = 1 << 20
"""Largest vehicle or tyre file read [B]; real ones are a few kilobytes."""


def read_vehicle_toml(path: Path) -> dict[str, Any]:
    """Parse a vehicle file; every failure is a :class:`VehicleFileError` naming it.

    Raises
    ------
    VehicleFileError
        For an unreadable, oversized, non-UTF-8, malformed or too deeply nested file.
    """
    try:
        if path.stat().st_size > MAX_FILE_BYTES:
            raise VehicleFileError(f"{path}: {path.stat().st_size} bytes; a vehicle file is "
                                   f"at most {MAX_FILE_BYTES} bytes")
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise VehicleFileError(f"{path}: not valid TOML: {exc}") from exc
    except UnicodeDecodeError as exc:
        raise VehicleFileError(f"{path}: not UTF-8 text (byte {exc.start}); save it as "
                               "UTF-8") from exc
    except RecursionError as exc:
        raise VehicleFileError(f"{path}: not valid TOML: nested too deeply") from exc
    except OSError as exc:
        raise VehicleFileError(f"{path}: cannot read ({exc.strerror or exc})") from exc


def _override_names(steering: Any) -> tuple[str, ...]:
    """The ``[steering.NAME]`` tables a ``[steering]`` section may have.

    The built-in models' and any other table named like a model (one
    registered from outside artic, :mod:`artic.validation.models`).
    """
    if not isinstance(steering, dict):
        return schema.MODELS
    return (*schema.MODELS, *(k for k, v in steering.items() if isinstance(v, dict)
                              and k not in schema.MODELS and re.fullmatch(schema.MODEL_NAME, k)))


def vehicle_from_dict(data: dict[str, Any], path: str | Path = "<dict>") -> Vehicle:
    """Check parsed TOML and build a :class:`Vehicle` (see :func:`load_vehicle`)."""
    for key in data:
        if key not in schema.SECTIONS and key not in schema.OPTIONAL_SECTIONS:
            raise VehicleFileError(
                f"{path}: key '{key}': unknown section; sections are: "
                f"{', '.join([*schema.SECTIONS, *schema.OPTIONAL_SECTIONS])}")
    vclass = vehicle_class(data, path)
    sec = {}
    if vclass == "scale-model":  # tyre data is optional: KIN needs none
        data = {"tyre": {}, **data}
    for name, fields in schema.SECTIONS.items():
        if name not in data:
            raise VehicleFileError(f"{path}: key '{name}': section missing")
        if name == "tyre" and vclass == "scale-model":
            fields = schema.TYRE_SCALE_MODEL
        allow = ("axle",) if name in ("tractor", "trailer") else (
            _override_names(data["steering"]) if name == "steering" else ())
        allow = (*allow, "scaling") if name == "tyre" else allow
        sec[name] = schema.check_table(path, name, data[name], fields, allow)
    for name, fields in schema.OPTIONAL_SECTIONS.items():
        sec[name] = schema.check_table(path, name, data.get(name, {}), fields)
    scaling = data["tyre"].get("scaling", {})
    if not isinstance(scaling, dict):
        raise VehicleFileError(f"{path}: key 'tyre.scaling': expected a table of factors")
    for k, val in scaling.items():
        if k not in schema.TYRE_SCALING:
            raise VehicleFileError(f"{path}: key 'tyre.scaling.{k}': unknown scaling factor; "
                                   f"known: {', '.join(schema.TYRE_SCALING)}")
        schema.check_value(path, f"tyre.scaling.{k}", schema.Field("", "factor"), val)
    overrides = {}
    for model in _override_names(data["steering"]):
        if model in data["steering"]:
            o = schema.check_table(path, f"steering.{model}", data["steering"][model],
                                   schema.STEERING_OVERRIDE)
            overrides[model] = {k: v for k, v in o.items() if v is not None}
    axles = []
    for unit, uname in ((1, "tractor"), (2, "trailer")):
        raw = data[uname].get("axle")
        if not isinstance(raw, list) or not raw:
            raise VehicleFileError(
                f"{path}: key '{uname}.axle': no axles; add [[{uname}.axle]] tables")
        for i, table in enumerate(raw):
            a = schema.check_table(path, f"{uname}.axle[{i}]", table, schema.AXLE)
            if a["tyre_file"]:
                a["tyre_file"] = str(resolve_tyre_file(a["tyre_file"], path,
                                                       f"{uname}.axle[{i}].tyre_file"))
            axles.append(Axle(unit=unit, **{**a, "load_share": a["load_share"] or 0.0}))
    axles = _fill_load_shares(path, axles)
    t, tr = sec["tractor"], sec["trailer"]
    v = Vehicle(
        name=sec["vehicle"]["name"], description=sec["vehicle"]["description"],
        sources=sec["vehicle"]["sources"],
        m1=t["m1"], J1=t["J1"], a1=t["a1"], b1=t["b1"], L1c=t["L1c"], h1=t["h1"], h5=t["h5"],
        sensor1=t["sensor"], m2=tr["m2"], J2=tr["J2"], a2=tr["a2"], L2=tr["L2"], j=tr["j"],
        h2=tr["h2"], sensor2=tr["sensor"], axles=tuple(axles),
        steering=Steering(**sec["steering"]), steering_overrides=overrides,
        f=_or_nan(sec["tyre"]["f"]), sigma_alpha=_or_nan(sec["tyre"]["sigma_alpha"]),
        gamma_max=sec["limits"]["gamma_max"], hitch_pitch=sec["limits"]["hitch_pitch"],
        tyre_file=(str(resolve_tyre_file(sec["tyre"]["file"], path))
                   if sec["tyre"]["file"] is not None else ""), path=str(path),
        sensor1_yaw=t["sensor_yaw"], sensor2_yaw=tr["sensor_yaw"],
        plant=PlantOptions(**sec["plant"]),
        tyre_scaling=tuple(sorted((k, float(val)) for k, val in scaling.items())),
        vehicle_class=vclass,
    )
    check_geometry(v, path)
    check_plausible(v, path)
    return v


def vehicle_class(data: dict[str, Any], path: str | Path = "<dict>") -> str:
    """The ``[vehicle] class`` of parsed TOML, checked (``full-size`` when absent).

    Raises
    ------
    VehicleFileError
        For a class artic does not know, naming the file, the key and the classes.
    """
    table = data.get("vehicle", {})
    value = table.get("class", schema.CLASSES[0]) if isinstance(table, dict) else schema.CLASSES[0]
    if value not in schema.CLASSES:
        raise VehicleFileError(f"{path}: key 'vehicle.class': {value!r} is not a vehicle class; "
                               f"use one of {', '.join(schema.CLASSES)}")
    return str(value)


def _or_nan(x: float | None) -> float:
    return math.nan if x is None else float(x)


def _fill_load_shares(path: str | Path, axles: list[Axle]) -> list[Axle]:
    groups: dict[tuple[int, bool], list[int]] = {}
    for i, a in enumerate(axles):
        groups.setdefault((a.unit, a.steered and a.unit == 1), []).append(i)
    out = list(axles)
    for idx in groups.values():
        given = [axles[i].load_share for i in idx]
        if all(s == 0.0 for s in given):
            for i in idx:
                out[i] = replace(axles[i], load_share=1.0 / len(idx))
        elif any(s == 0.0 for s in given) or abs(sum(given) - 1.0) > 1e-6:
            names = ", ".join(axles[i].name for i in idx)
            raise VehicleFileError(
                f"{path}: key 'load_share': the shares of axles {names} must all be given "
                f"and sum to 1, got {given}")
    return out


def check_geometry(v: Vehicle, path: str | Path) -> None:
    """Check that the symbols and the axle list describe one geometry.

    Raises
    ------
    VehicleFileError
        Naming the key that disagrees.
    """
    def fail(key: str, msg: str) -> VehicleFileError:
        return VehicleFileError(f"{path}: key '{key}': {msg}")

    names = [a.name for a in v.axles]
    for n in names:
        if names.count(n) > 1:
            raise fail("axle.name", f"axle name {n!r} is used twice")
    tractor, trailer = v.tractor_axles, v.trailer_axles
    steered = [a for a in tractor if a.steered]
    if not steered:
        raise fail("tractor.axle.steered", "the tractor needs at least one steered axle")
    if any(a.steered for a in trailer):
        raise fail("trailer.axle.steered", "semitrailer axles are not steered in artic")
    if not any(a.driven for a in tractor):
        raise fail("tractor.axle.driven", "the tractor needs at least one driven axle")
    if not any(abs(a.x) < GEOMETRY_TOL and not a.steered for a in tractor):
        raise fail("tractor.axle.x", "no axle at x = 0: the tractor frame's origin is the "
                                     "drive axle, so the drive axle has x = 0")
    front = max(steered, key=lambda a: a.x)
    if abs(front.x - v.L1) > GEOMETRY_TOL:
        raise fail("tractor.a1", f"a1 + b1 = {v.L1:.4f} m but the front axle "
                                 f"{front.name!r} is at x = {front.x:.4f} m; they must agree")
    xs = [a.x for a in tractor]
    if xs != sorted(xs, reverse=True) or [a.x for a in trailer] != sorted(
            (a.x for a in trailer), reverse=True):
        raise fail("axle.x", "list each unit's axles from front to rear")
    if v.Lc <= 0:
        raise fail("tractor.L1c", f"L1c = {v.L1c} m puts the fifth wheel ahead of the "
                                  f"tractor's centre of gravity (b1 = {v.b1} m): need L1c < b1")
    if any(a.x >= 0 for a in trailer):
        raise fail("trailer.axle.x", "semitrailer axles lie behind the kingpin: x < 0")
    centre = -float(np.mean([a.x for a in trailer]))
    if abs(centre - v.L2) > GEOMETRY_TOL:
        raise fail("trailer.L2", f"L2 = {v.L2} m but the trailer axles are centred "
                                 f"{centre:.4f} m behind the kingpin")
    gaps = -np.diff([a.x for a in trailer])
    if gaps.size and np.any(np.abs(gaps - v.j) > GEOMETRY_TOL):
        raise fail("trailer.j", f"j = {v.j} m but the trailer axle spacings are "
                                f"{np.round(gaps, 4).tolist()} m")
    if v.a2 >= -_group_resultant(trailer):
        raise fail("trailer.a2", f"a2 = {v.a2} m puts the centre of gravity behind the axle "
                                 "group: the kingpin would lift")
    loads, fk = _static_loads(v)
    for a, fz in zip(v.axles, loads, strict=True):
        if fz <= 0:
            raise fail(f"axle {a.name}", f"static load {fz:.0f} N is not positive: check the "
                                         "centre-of-gravity position")
    if v.h5 >= v.h2 + 2.0 or v.h5 <= 0:
        raise fail("tractor.h5", f"fifth-wheel height {v.h5} m is implausible")
    if not 0 < v.steering.delta_max < math.pi / 2:
        raise fail("steering.delta_max", "must lie in (0, pi/2) rad")
    if not 0 < v.gamma_max < math.pi:
        raise fail("limits.gamma_max", "must lie in (0, pi) rad")
