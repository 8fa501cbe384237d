"""Mass, inertia and ride height of every body of the multibody model.

The parameter file gives each unit's total mass ``m``, centre of gravity and
yaw inertia ``J`` about it. It also gives each axle's unsprung mass and
each wheel end's spin inertia. This module splits them into bodies whose
composite matches the file exactly:

- each axle: half its unsprung mass in the axle body, a quarter in each wheel
  end (of which a tenth sits in the steering knuckle of a steered end);
- the chassis: what is left, placed and shaped so that the unit's mass,
  centre of gravity (``x``, and height ``h``) and yaw inertia are the file's.

The chassis' yaw inertia ``J_c = A + B`` is split into a length part ``A``
and a width part ``B = m_c W^2 / 12`` (``W`` the widest track). Its roll and
pitch inertias are ``B + C`` and ``A + C``, with the height part
``C = m_c (2 h_c)^2 / 12``. If ``J_c`` is smaller than the width part, ``B``
gives way, to keep ``A`` at a tenth of ``J_c``.

Ride height at rest: every axle centre stands at the tyre's loaded radius
``R0 - Fz_tyre / k_t`` under its static load, and each suspension spring
is preloaded to carry the sprung part of it. So the model starts in
equilibrium.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from artic.mjcf.schema import VehicleFileError
from artic.mjcf.tir import read_tir
from artic.mjcf.vehicle import Axle, G, Vehicle

AXLE_SHARE = 0.5
"""Share of an axle's unsprung mass in the axle body; the rest is in its two wheel ends."""

KNUCKLE_SHARE = 0.1
"""Share of a steered wheel end's mass in its knuckle."""


@dataclass(frozen=True)
class Body:
    """Mass properties of one body, in its unit's frame.

    Parameters
    ----------
    mass : float
        [kg].
    pos : ndarray, shape (3,)
        Centre of mass in the unit frame [m].
    inertia : ndarray, shape (3,)
        Principal moments about the centre of mass, unit axes [kg m^2].
    """

    mass: float
    pos: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True)
class AxleLayout:
    """An axle of the model.

    Parameters
    ----------
    axle : Axle
        From the parameter file.
    centre : ndarray, shape (3,)
        Axle centre at rest, unit frame [m].
    body, wheel, knuckle : Body
        The axle body, one wheel end (wheel body), one knuckle (steered only).
    n_tyres : int
        Tyres per wheel end (2 for duals).
    static_load : float
        Static vertical load of the axle [N].
    springref : float
        Suspension spring reference position [m]: the spring carries the sprung
        load at zero travel.
    """

    axle: Axle
    centre: np.ndarray
    body: Body
    wheel: Body
    knuckle: Body | None
    n_tyres: int
    static_load: float
    springref: float


@dataclass(frozen=True)
class Layout:
    """Everything the MJCF generator needs beyond the parameter file."""

    chassis: dict[int, Body]
    axles: tuple[AxleLayout, ...]
    R0: float
    k_tyre: float
    c_tyre: float

    def unit_axles(self, unit: int) -> tuple[AxleLayout, ...]:
        """Axles of unit 1 (tractor) or 2 (semitrailer)."""
        return tuple(a for a in self.axles if a.axle.unit == unit)


def layout(v: Vehicle) -> Layout:
    """Split the vehicle into bodies (see the module docstring).

    Raises
    ------
    VehicleFileError
        If the unsprung masses leave no chassis mass or yaw inertia.
    """
    if not v.tyre_file:  # a scale model may have no tyre data; its wheels need a radius
        raise VehicleFileError(f"{v.path or v.name}: key 'tyre.file': vehicle {v.name} (class "
                               f"{v.vehicle_class}) has no tyre file; the multibody model's "
                               "wheels take their size from a PAC2002 .tir of its own tyres")
    tyre = read_tir(v.tyre_file)
    R0 = tyre.number("UNLOADED_RADIUS")
    k_t = tyre.number("VERTICAL_STIFFNESS")
    c_t = tyre.number("VERTICAL_DAMPING")
    loads = v.static_loads
    axles = []
    for a, fz in zip(v.axles, loads, strict=True):
        n_t = 2 if a.dual else 1
        own = read_tir(v.tyre_file_for(a)) if a.tyre_file else tyre
        r_static = (own.number("UNLOADED_RADIUS")
                    - fz / (2 * n_t) / own.number("VERTICAL_STIFFNESS"))
        z = r_static if a.unit == 1 else r_static - v.h5
        centre = np.array([a.x, 0.0, z])
        m_axle = AXLE_SHARE * a.unsprung_mass
        m_end = 0.5 * (1 - AXLE_SHARE) * a.unsprung_mass
        knuckle = None
        if a.steered:
            mk = KNUCKLE_SHARE * m_end
            knuckle = Body(mk, np.zeros(3), np.full(3, mk * 0.15 ** 2))
            m_end -= mk
        I_w = a.wheel_inertia
        wheel = Body(m_end, np.zeros(3), np.array([0.5 * I_w, I_w, 0.5 * I_w]))
        rod = m_axle * a.track ** 2 / 12
        body = Body(m_axle, centre, np.array([rod, 0.01 * rod, rod]))
        sprung = fz - a.unsprung_mass * G
        axles.append(AxleLayout(a, centre, body, wheel, knuckle, n_t, float(fz),
                                -sprung / a.suspension_stiffness))
    out = Layout({}, tuple(axles), R0, k_t, c_t)
    chassis = {}
    for unit, m, x_g, h, J in ((1, v.m1, v.b1, v.h1, v.J1),
                               (2, v.m2, -v.a2, v.h2 - v.h5, v.J2)):
        y_g = v.plant.payload_offset[1] if unit == 2 else 0.0
        chassis[unit] = _chassis(v, unit, m, np.array([x_g, y_g, h]), J, out.unit_axles(unit))
    return Layout(chassis, tuple(axles), R0, k_t, c_t)


def unsprung_bodies(a: AxleLayout) -> list[tuple[float, np.ndarray, float]]:
    """``(mass, position, yaw inertia)`` of an axle's bodies, unit frame."""
    out = [(a.body.mass, a.body.pos, a.body.inertia[2])]
    for sign in (1.0, -1.0):
        p = a.centre + np.array([0.0, sign * 0.5 * a.axle.track, 0.0])
        out.append((a.wheel.mass, p, a.wheel.inertia[2]))
        if a.knuckle is not None:
            out.append((a.knuckle.mass, p, a.knuckle.inertia[2]))
    return out


def _chassis(v: Vehicle, unit: int, m: float, g: np.ndarray, J: float,
             axles: tuple[AxleLayout, ...]) -> Body:
    parts = [b for a in axles for b in unsprung_bodies(a)]
    m_u = sum(p[0] for p in parts)
    m_c = m - m_u
    name = "tractor.m1" if unit == 1 else "trailer.m2"
    if m_c <= 0:
        raise VehicleFileError(f"{v.path}: key '{name}': the unsprung masses ({m_u:.0f} kg) "
                               f"leave no chassis mass")
    pos = (m * g - sum(p[0] * p[1] for p in parts)) / m_c
    J_u = sum(p[2] + p[0] * ((p[1][0] - g[0]) ** 2 + p[1][1] ** 2) for p in parts)
    J_c = J - J_u - m_c * (pos[0] - g[0]) ** 2
    if J_c <= 0:
        name = "tractor.J1" if unit == 1 else "trailer.J2"
        J_off = m_c * (pos[0] - g[0]) ** 2  # the chassis's own mass off the unit's CoG
        raise VehicleFileError(f"{v.path}: key '{name}': the axles ({J_u:.0f} kg m^2) and the "
                               f"chassis's offset from the centre of gravity ({J_off:.0f}) "
                               f"need {J_u + J_off:.0f} kg m^2 of yaw inertia, more than the "
                               f"unit's {J:.0f}")
    width = max(a.axle.track for a in axles)
    height = g[2] + (v.h5 if unit == 2 else 0.0)
    B = m_c * width ** 2 / 12
    A = max(J_c - B, 0.1 * J_c)
    B = J_c - A
    C = m_c * (2 * height) ** 2 / 12
    return Body(m_c, pos, np.array([B + C, A + C, A + B]))
