"""The plant's building: its model, the indices into it and its tyre sets.

:class:`Building` is one of the parts :class:`artic.plant.plant.Plant` is made of
(building, the tyre forces in Python, stepping, observing, recording); the
plant's constructor calls its methods. A model of another kind (the synthetic
truth's, in :mod:`artic.validation.synthetic.truthplant`) is a subclass of the
plant that changes three of them: its spec, its numeric block and how the block
is written. The compiled callback hands a block of another name to the
extension registered for it (:func:`artic.plant.ctyre.register_kind`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path

import mujoco
import numpy as np

from artic.mjcf import naming as nm
from artic.mjcf.builder import build_model, linkage
from artic.mjcf.errors import UserError
from artic.mjcf.masses import layout
from artic.mjcf.vehicle import Vehicle, resolve_tyre_file
from artic.plant import ctyre
from artic.plant.tyre import TyreParams


def scaled(p: TyreParams, scaling: tuple[tuple[str, float], ...]) -> TyreParams:
    """``p`` with its Magic Formula scaling factors multiplied by the vehicle file's."""
    if not scaling:
        return p
    return dataclasses.replace(p, **{k: getattr(p, k) * f for k, f in scaling})


def with_tyre_files(vehicle: Vehicle, tyre_files: Mapping[int, str | Path]) -> Vehicle:
    """``vehicle`` with the tyre files of some axles replaced (see :class:`artic.plant.Plant`).

    Raises
    ------
    ValueError
        For an axle index that the vehicle does not have.
    artic.mjcf.vehicle.VehicleFileError
        For a file that is neither there nor shipped, or is not a ``.tir``.
    """
    if not tyre_files:
        return vehicle
    axles = list(vehicle.axles)
    for i, name in tyre_files.items():
        if not (isinstance(i, (int, np.integer)) and 0 <= i < len(axles)):
            raise UserError(f"tyre_files: axle {i!r} does not exist; {vehicle.name} has axles "
                             f"0 to {len(axles) - 1} ({', '.join(a.name for a in axles)})")
        path = Path(name)
        if not path.is_file():
            path = resolve_tyre_file(str(name), vehicle.path or Path.cwd() / "tyre_files",
                                     f"tyre_files[{i}]")
        axles[i] = dataclasses.replace(axles[i], tyre_file=str(path))
    return dataclasses.replace(vehicle, axles=tuple(axles))


class Building:
    """The plant's model spec, numeric block, indices and tyre sets (a part of ``Plant``)."""

    def _model_spec(self, vehicle: Vehicle) -> mujoco.MjSpec:
        """The model's spec before its numeric block: :func:`artic.mjcf.builder.build_model`."""
        return build_model(vehicle)

    def _add_block(self, spec: mujoco.MjSpec, n_wheels: int, n_sets: int) -> None:
        """Add the compiled callback's numeric 0 and the ``userdata`` it writes."""
        spec.add_numeric(name=ctyre.BLOCK, size=ctyre.block_size(n_wheels, n_sets))
        spec.nuserdata = 3 * n_wheels + 1  # forces, then the out-of-range count

    def _write_block(self) -> None:
        """Write the numeric block from :attr:`tyres` and check it against the model."""
        self.model.numeric_data[:] = ctyre.block(self._tyres, self._wheel_table(),
                                                 self.vehicle.plant.tyre_moments, self.spin_fit)
        ctyre.check_block(self.model, self.data)

    def _wheel_table(self) -> np.ndarray:
        cols = {"hub_site": self._hub, "hub_body": self._hub_body, "root_body": self._root,
                "wheel_body": self._wheel_body, "spin_dof": self._spin_dof,
                "act_u": self._act_u, "act_v": self._act_v, "act_w": self._act_w,
                "ctrl_u": self._tread_u, "ctrl_v": self._tread_v, "ctrl_w": self._tread_w,
                "n_tyres": self._n_tyres, "tyre_set": self._tyre_set}
        return np.column_stack([cols[f] for f in ctyre.WHEEL_FIELDS])

    @property
    def tyres(self) -> list[TyreParams]:
        """The tyre coefficient sets in use, one per tyre file (``tyre_set`` of each wheel)."""
        return list(self._tyres)

    @tyres.setter
    def tyres(self, sets: list[TyreParams]) -> None:
        if len(sets) != len(self._tyres):
            raise UserError(f"the plant has {len(self._tyres)} tyre sets, got {len(sets)}")
        self._tyres = list(sets)
        self._per_wheel_tyre()
        if self.backend == "compiled":
            self._write_block()

    @property
    def wheel_tyres(self) -> list[TyreParams]:
        """The tyre of every wheel end, in :attr:`wheel_names` order."""
        return [self._tyres[i] for i in self._tyre_set]

    @property
    def tyre(self) -> TyreParams:
        """The vehicle's own tyre (``[tyre] file``); assigning one puts it on every axle."""
        return self._tyres[0]

    @tyre.setter
    def tyre(self, p: TyreParams) -> None:
        self.tyres = [p] * len(self._tyres)

    def _per_wheel_tyre(self) -> None:
        """Radius, vertical stiffness and damping of every wheel end's tyre."""
        s = self._tyre_set
        self.R0_w = np.array([self._tyres[i].UNLOADED_RADIUS for i in s])
        self.k_t_w = np.array([self._tyres[i].VERTICAL_STIFFNESS for i in s])
        self.c_t_w = np.array([self._tyres[i].VERTICAL_DAMPING for i in s])

    def _index(self, v: Vehicle) -> None:
        m = self.model
        v = v.with_payload()
        lay = layout(v)
        ends = [(a, side) for a in lay.axles for side in nm.SIDES]
        self.n_wheels = len(ends)
        self.wheel_names = [f"{a.axle.name} {side}" for a, side in ends]
        self._hub = np.array([m.site(nm.hub(a.axle.name, s)).id for a, s in ends])
        self._hub_body = m.site_bodyid[self._hub]
        self._root = m.body_rootid[self._hub_body]
        self._wheel_body = np.array([m.body(nm.wheel(a.axle.name, s)).id for a, s in ends])
        self._spin_dof = np.array([m.jnt_dofadr[m.joint(nm.spin(a.axle.name, s)).id]
                                   for a, s in ends])
        self._n_tyres = np.array([float(a.n_tyres) for a, _ in ends])
        self._tread_u = np.array([m.actuator(nm.tread(a.axle.name, s, "u")).id for a, s in ends])
        self._tread_v = np.array([m.actuator(nm.tread(a.axle.name, s, "v")).id for a, s in ends])
        self._tread_w = np.array([m.actuator(nm.tread(a.axle.name, s, "w")).id for a, s in ends])
        self._act_u = m.actuator_actadr[self._tread_u]
        self._act_v = m.actuator_actadr[self._tread_v]
        self._act_w = m.actuator_actadr[self._tread_w]
        self._drive = [m.actuator(nm.drive(a.axle.name, s)).id for a, s in ends if a.axle.driven]
        self._brake = np.array([m.actuator(nm.brake(a.axle.name, s)).id for a, s in ends])
        static = np.array([a.static_load / 2.0 for a, _ in ends])
        self._brake_share = static / static.sum()
        steered = [a.axle.name for a in lay.axles if a.axle.steered]
        self._steered = steered
        self._servo = [m.actuator(nm.servo(n)).id for n in steered]
        self._servo_range = linkage(v)[2]
        self._steer_L = [m.jnt_qposadr[m.joint(nm.steer(n, "L")).id] for n in steered]
        self._steer_R = [m.jnt_qposadr[m.joint(nm.steer(n, "R")).id] for n in steered]
        self._follower = m.actuator(nm.SPEED_SERVO).id
        self._follower_kv = float(m.actuator_gainprm[self._follower, 0])
        spin_inertia = sum(2.0 * a.wheel_inertia for a in v.axles)
        self.mass_eff = v.m1 + v.m2 + spin_inertia / lay.R0 ** 2
        self._tractor = m.body(nm.TRACTOR).id
        self._trailer = m.body(nm.TRAILER).id
        self._hitch_yaw = m.joint(nm.HITCH_YAW).id
        self._hitch_qpos = int(m.jnt_qposadr[self._hitch_yaw])  # gamma reads it every step
        self._sensor = [m.site(nm.sensor(1)).id, m.site(nm.sensor(2)).id]
        self._index_extras(lay, ends)
        self._s1 = np.array(v.sensor1[:2])
        self._sensor_yaw = (v.sensor1_yaw, v.sensor2_yaw)
        self.mass = v.m1 + v.m2
        self.R0, self.k_t, self.c_t = lay.R0, lay.k_tyre, lay.c_tyre
        self._per_wheel_tyre()
