"""The plant's drawing: its MuJoCo bodies and visual geoms, as the recordings pose them.

The recordings draw the multibody plant from the very model it simulates,
not from a sketch of it. :func:`plant_shape` compiles the vehicle's MJCF
(:func:`artic.mjcf.builder.build_vehicle`) and lists, for every body with visual
geoms, its geoms in the body's frame and how the body is posed from a run's
columns (:meth:`plant.Plant.extras`):

- the tractor, the semitrailer and every axle body take their world pose from
  ``pose.BODY.{x,y,z,qw,qx,qy,qz}``;
- every wheel hangs from its axle at the offset the model gives it, turned
  by ``steer.AXLE.SIDE`` about the axle's z-axis (steered wheels) and then by
  ``spin.AXLE.SIDE`` about its own y-axis;
- the fifth wheel, which the model holds as the hitch joints, is drawn as a
  plate on the tractor at the hitch.

Quaternions here are MuJoCo's (w, x, y, z); :func:`xyzw` turns them into
Rerun's order. Nothing here imports rerun.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from artic.mjcf import naming as nm
from artic.mjcf.builder import build_vehicle
from artic.mjcf.compiling import compile_spec
from artic.mjcf.masses import layout
from artic.mjcf.vehicle import Vehicle

FIFTH_WHEEL_RADIUS = 0.45
"""Radius of the fifth-wheel plate as drawn [m] (a 36-inch plate)."""

FIFTH_WHEEL_THICKNESS = 0.08
"""Thickness of the fifth-wheel plate as drawn [m]."""

_KINDS = {int(mujoco.mjtGeom.mjGEOM_BOX): "box", int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder",
          int(mujoco.mjtGeom.mjGEOM_CAPSULE): "capsule"}


@dataclass(frozen=True)
class Geom:
    """One visual geom in its body's frame.

    Attributes
    ----------
    kind : str
        ``box``, ``cylinder`` or ``capsule``.
    size : ndarray
        MuJoCo's size: half extents (box); radius and half length along z
        (cylinder, capsule) [m].
    pos : ndarray
        Centre in the body frame [m].
    quat : ndarray
        Orientation in the body frame, (w, x, y, z).
    rgba : ndarray
        Colour, 0 to 1.
    """

    kind: str
    size: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    rgba: np.ndarray


@dataclass(frozen=True)
class Part:
    """A drawn body: its geoms and how a run's columns pose it.

    Attributes
    ----------
    name : str
        The MuJoCo body name (``tractor``, ``axle.front``, ``wheel.front.L``),
        or ``fifth-wheel``.
    geoms : tuple of Geom
        In the part's frame.
    parent : str or None
        ``None``: posed in the world by ``pose.NAME.*``. Otherwise the posed
        body it hangs from, at ``offset``.
    offset : ndarray
        Position in the parent's frame at zero joint angles [m].
    steer, spin : str or None
        Columns of the steering and spin angles of a wheel [rad].
    """

    name: str
    geoms: tuple[Geom, ...]
    parent: str | None = None
    offset: np.ndarray | None = None
    steer: str | None = None
    spin: str | None = None


def xyzw(q_wxyz: np.ndarray) -> np.ndarray:
    """MuJoCo's (w, x, y, z) quaternions as Rerun's (x, y, z, w), along the last axis."""
    return np.roll(np.asarray(q_wxyz, dtype=float), -1, axis=-1)


def wheel_quat(steer: np.ndarray, spin: np.ndarray) -> np.ndarray:
    """(w, x, y, z) of a wheel in its axle's frame: steer about z, then spin about y [rad]."""
    cs, ss = np.cos(0.5 * steer), np.sin(0.5 * steer)
    cp, sp = np.cos(0.5 * spin), np.sin(0.5 * spin)
    # (cs + ss k)(cp + sp j) = cs cp + cs sp j + ss cp k + ss sp (k j = -i)
    return np.column_stack([cs * cp, -ss * sp, cs * sp, ss * cp])


def _geoms(m: mujoco.MjModel, body: int) -> tuple[Geom, ...]:
    out = []
    for g in range(m.body_geomadr[body], m.body_geomadr[body] + m.body_geomnum[body]):
        kind = _KINDS.get(int(m.geom_type[g]))
        if kind is None:
            continue
        out.append(Geom(kind, m.geom_size[g].copy(), m.geom_pos[g].copy(), m.geom_quat[g].copy(),
                        m.geom_rgba[g].copy()))
    return tuple(out)


def plant_shape(vehicle: Vehicle) -> list[Part]:
    """The plant's drawn parts, from its compiled MJCF (see the module docstring)."""
    m = compile_spec(build_vehicle(vehicle))
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    parts = [Part(nm.TRACTOR, _geoms(m, m.body(nm.TRACTOR).id)),
             Part(nm.TRAILER, _geoms(m, m.body(nm.TRAILER).id))]
    for a in layout(vehicle).axles:
        axle = m.body(nm.axle(a.axle.name)).id
        parts.append(Part(nm.axle(a.axle.name), _geoms(m, axle)))
        R = d.xmat[axle].reshape(3, 3)
        for side in nm.SIDES:
            w = m.body(nm.wheel(a.axle.name, side)).id
            offset = R.T @ (d.xpos[w] - d.xpos[axle])
            parts.append(Part(nm.wheel(a.axle.name, side), _geoms(m, w), nm.axle(a.axle.name),
                              offset, f"steer.{a.axle.name}.{side}" if a.axle.steered else None,
                              f"spin.{a.axle.name}.{side}"))
    tractor, trailer = m.body(nm.TRACTOR).id, m.body(nm.TRAILER).id
    hitch = d.xpos[trailer] + d.xmat[trailer].reshape(3, 3) @ m.jnt_pos[m.joint(nm.HITCH_YAW).id]
    at = d.xmat[tractor].reshape(3, 3).T @ (hitch - d.xpos[tractor])
    plate = Geom("cylinder", np.array([FIFTH_WHEEL_RADIUS, 0.5 * FIFTH_WHEEL_THICKNESS, 0.0]),
                 np.array([0.0, 0.0, -0.5 * FIFTH_WHEEL_THICKNESS]), np.array([1.0, 0, 0, 0]),
                 np.array([0.2, 0.2, 0.2, 1.0]))
    parts.append(Part("fifth-wheel", (plate,), nm.TRACTOR, at))
    return parts


def has_pose(columns) -> bool:
    """Whether a run's columns pose the plant (a plant run with :meth:`plant.Plant.extras`)."""
    return f"pose.{nm.TRACTOR}.x" in columns


def wheel_names(columns) -> list[str]:
    """``AXLE.SIDE`` of every wheel end with force columns, in column order."""
    return [c[len("force."):-len(".z")] for c in columns
            if c.startswith("force.") and c.endswith(".z")]


def rad2deg(x: np.ndarray) -> np.ndarray:
    """Radians to degrees (for plots, whose titles carry the unit)."""
    return np.asarray(x, dtype=float) * (180.0 / math.pi)
