"""The independent truth's multibody model: its own tyres and steering in MuJoCo.

:class:`TruthPlant` is the measured vehicle of the synthetic campaign's
``independent`` truth. It keeps what a vehicle is and MuJoCo does (the bodies,
masses, suspension, fifth wheel, payload, sensors and slopes of the truth's
vehicle file, and the plant's drive, brakes and speed follower), and replaces
what the plant under validation models:

==================  ================================  ===============================
                    the plant (:class:`.Plant`)       the truth (this)
==================  ================================  ===============================
tyre formula        PAC2002 Magic Formula             TMeasy (:mod:`.tmeasy`), fitted
                                                      to the same ``.tir`` curves
combined slip       PAC2002 weighting functions       TMeasy's generalised slip
tyre transients     tread deflections over            spring and damper of each
                    relaxation lengths                deflection (first order)
aligning, bore      PAC2002 trail; artic's twist      TMeasy's trail law; its bore
torque              model                             slip, with a twist state
twin tyres          one tyre, forces doubled          two tyres 350 mm apart, each
                                                      with its own load and slip
steering            position servo on the left        torsion bar, free play, lagged
                    wheel                             and saturating hydraulic assist
                                                      (:mod:`.column`)
right wheel         fitted quartic joint equality     compliant tie rod on the exact
                                                      trapezoid
caster              none: the kingpin through the     4 deg: the kingpin leads it
                    contact
brakes               torque fading with the wheel's    dry friction: they hold a
                    spin: a stopped truck creeps      stopped truck on the slope
                    down the slope
speed follower      pushes the drive axle             drives the driven wheels and
(the floor's)                                         brakes all, as the truth's
                                                      driver does
==================  ================================  ===============================

Both are evaluated in C at every integrator stage: the plant's compiled
callback hands this model (numeric 0 ``artic.truth``) to the truth's
(``_truth_c.c``, see :mod:`.truthc`). The model's steering-servo actuator is
kept as a slot with no gain: what :meth:`step` sets there, the left-wheel
angle the steering wheel stands for, is the column's input.
"""

from __future__ import annotations

from collections.abc import Mapping

import mujoco
import numpy as np

from artic.mjcf import naming as nm
from artic.mjcf.builder import build_model
from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import G, Vehicle
from artic.plant import Plant
from artic.plant.closedloop import SOURCES
from artic.plant.plant import BRAKE_DECEL_MAX, PARKING_BRAKE_GRADE
from artic.validation.synthetic import tmeasy, truthc
from artic.validation.synthetic.column import Column
from artic.validation.synthetic.truthmodel import (  # noqa: F401  (their home before)
    FORWARD_KINDS,
    FORWARD_TIMESTEP,
    PLANT_TRUTH_TIMESTEP,
    TIMESTEP,
    timestep_for,
    truth_actuation,
    truth_model,
)

DUAL_SPACING = 0.35
"""Centre distance of twin tyres [m]: 22.5-inch twin wheels on a drive axle."""

ASSIST = "column.assist"
"""The integrator actuator whose activation is the assist torque [N m]."""

STATE = int(mujoco.mjtState.mjSTATE_FULLPHYSICS | mujoco.mjtState.mjSTATE_WARMSTART)
"""The parts of MuJoCo's state :meth:`TruthPlant.full_state` holds (``mj_getState``)."""


def second_tread(axle: str, side: str, direction: str) -> str:
    """The tread actuators of a twin's second tyre."""
    return f"tread2.{axle}.{side}.{direction}"


class TruthPlant(Plant):
    """The independent truth (see the module docstring), with the plant's interface.

    Parameters
    ----------
    vehicle : Vehicle
        The truth's vehicle (:func:`artic.validation.synthetic.truth.truth_vehicle`);
        its tyre files and scaling give the TMeasy tyres (:func:`tmeasy.fit`).
    column : Column, optional
        The steering; :meth:`Column.of` the vehicle, without play, by default.
    speed : str
        As :class:`artic.plant.Plant`: ``"pedals"`` for the truth's driver,
        ``"follow"`` for the harness (the floor).
    timestep : float, optional
        MuJoCo timestep [s]; :data:`TIMESTEP` by default.

    Raises
    ------
    truthc.TruthUnavailable
        Without the compiled truth.
    """

    def __init__(self, vehicle: Vehicle, column: Column | None = None, speed: str = "follow",
                 timestep: float | None = None) -> None:
        truthc.library()  # registered with the plant's callback before any step
        self.column = column or Column.of(vehicle)
        files = list(dict.fromkeys(vehicle.tyre_file_for(a) for a in vehicle.axles))
        self.tmeasy = [tmeasy.fit(f, vehicle.tyre_scaling) for f in files]
        """The TMeasy tyre of each tyre file in use (the ``tyre_set`` of each wheel)."""
        self._parked = False
        self._friction_decel: float | None = None  # the brakes' friction as last written
        super().__init__(vehicle, timestep=TIMESTEP if timestep is None else timestep,
                         backend="compiled", speed=speed)

    # ------------------------------------------------------------ brakes
    # The truth's brakes are dry friction on the wheels' spin joints, which
    # MuJoCo's constraint solver holds at standstill: a driver who stops on the
    # yard's slope stays stopped. (The plant's service brake fades with the
    # wheel's spin, so a braked plant creeps; its parking brake is dry friction.)
    def _control(self, u_cmd: float, u_dot: float, h: float) -> None:
        super()._control(u_cmd, u_dot, h)
        brake = 0.0
        if self.speed_mode == "pedals":
            brake = min(max(float(self.pedals[1]), 0.0), 1.0)
        self._set_friction(brake)

    def _pedal_brake(self, brake: float, weight: float) -> None:
        self.data.ctrl[self._brake] = 0.0  # no fading brake torque: dry friction instead

    def _set_friction(self, brake: float) -> None:
        decel = max(brake * BRAKE_DECEL_MAX, PARKING_BRAKE_GRADE if self._parked else 0.0)
        if decel != self._friction_decel:  # written when it changes, not at every step
            self.model.dof_frictionloss[self._spin_dof] = (decel * self.mass * G * self.R0
                                                           * self._brake_share)
            self._friction_decel = decel

    @property
    def parking_brake(self) -> bool:
        """Whether the parking brake holds every wheel (see :class:`artic.plant.Plant`)."""
        return self._parked

    @parking_brake.setter
    def parking_brake(self, on: bool) -> None:
        self._parked = bool(on)
        self._set_friction(0.0)

    # ------------------------------------------------------------ model kind
    def _model_spec(self, vehicle: Vehicle) -> mujoco.MjSpec:
        spec = build_model(vehicle)
        # The speed follower keeps its gain, which the plant's controller reads,
        # and loses its transmission: the compiled truth applies its force
        # through the drive and the brakes.
        spec.actuator(nm.SPEED_SERVO).gear = np.zeros(6)
        v = vehicle.with_payload()
        for a in v.axles:
            if a.steered:
                slot = spec.actuator(nm.servo(a.name))
                slot.gaintype = mujoco.mjtGain.mjGAIN_FIXED
                slot.gainprm = np.zeros(len(slot.gainprm))
                slot.biastype = mujoco.mjtBias.mjBIAS_NONE
                slot.biasprm = np.zeros(len(slot.biasprm))
                spec.delete(spec.equality(nm.tie_rod(a.name)))
                assist = spec.add_actuator(name=ASSIST, target=nm.steer(a.name, "L"),
                                           trntype=mujoco.mjtTrn.mjTRN_JOINT)
                _integrator(assist)
            if a.dual:  # the twin's second tyre: its own deflection states
                for side in nm.SIDES:
                    for direction in ("u", "v", "w"):
                        t = spec.add_actuator(name=second_tread(a.name, side, direction),
                                              target=nm.spin(a.name, side),
                                              trntype=mujoco.mjtTrn.mjTRN_JOINT)
                        _integrator(t)
        return spec

    def _add_block(self, spec: mujoco.MjSpec, n_wheels: int, n_sets: int) -> None:
        steered = sum(a.steered for a in self.vehicle.axles)
        if steered > 1:
            raise UserError(f"{self.vehicle.name}: the independent truth steers one axle, "
                             f"this vehicle has {steered}")
        spec.add_numeric(name=truthc.BLOCK, size=truthc.block_size(n_wheels, n_sets, steered))
        spec.nuserdata = 3 * n_wheels + 1 + truthc.diagnostics()

    def _write_block(self) -> None:
        m = self.model
        driven = np.array([float(a.driven) for a in self.vehicle.with_payload().axles
                           for _ in nm.SIDES])
        ends = np.zeros((self.n_wheels, len(truthc.end_names())))
        col = {n: i for i, n in enumerate(truthc.end_names())}
        steered = {a.name for a in self.vehicle.axles if a.steered}
        axle_of = [a.name for a in self.vehicle.with_payload().axles for _ in nm.SIDES]
        sides = [s for _ in self.vehicle.axles for s in nm.SIDES]
        for i in range(self.n_wheels):
            row = {"hub_site": self._hub[i], "hub_body": self._hub_body[i],
                   "root_body": self._root[i], "wheel_body": self._wheel_body[i],
                   "spin_dof": self._spin_dof[i], "n_tyres": self._n_tyres[i],
                   "tyre_set": self._tyre_set[i], "half_spacing": 0.5 * DUAL_SPACING,
                   "trail": self.column.trail if axle_of[i] in steered else 0.0,
                   "steer_dof": (m.jnt_dofadr[m.joint(nm.steer(axle_of[i], sides[i])).id]
                                 if axle_of[i] in steered else 0),
                   "drive_share": driven[i] / driven.sum(),
                   "brake_share": self._brake_share[i],
                   "act_x1": self._act_u[i], "act_y1": self._act_v[i],
                   "act_p1": self._act_w[i], "ctrl_x1": self._tread_u[i],
                   "ctrl_y1": self._tread_v[i], "ctrl_p1": self._tread_w[i]}
            if self._n_tyres[i] == 2:
                for d, key in (("u", "x2"), ("v", "y2"), ("w", "p2")):
                    a = m.actuator(second_tread(axle_of[i], sides[i], d)).id
                    row[f"act_{key}"] = m.actuator_actadr[a]
                    row[f"ctrl_{key}"] = a
            for k, x in row.items():
                ends[i, col[k]] = x
        column = None
        if steered:
            front = next(iter(steered))
            assist = m.actuator(ASSIST).id
            jl, jr = m.joint(nm.steer(front, "L")).id, m.joint(nm.steer(front, "R")).id
            column = self.column.vector({
                "slot": self._servo[0], "steer_l_qpos": m.jnt_qposadr[jl],
                "steer_l_dof": m.jnt_dofadr[jl], "steer_r_qpos": m.jnt_qposadr[jr],
                "steer_r_dof": m.jnt_dofadr[jr], "assist_act": m.actuator_actadr[assist],
                "assist_ctrl": assist})
        follower = (self.speed_mode == "follow", self._follower_kv, self._follower,
                    m.actuator_trnid[self._follower, 0])
        m.numeric_data[:] = truthc.seal(follower, [t.vector() for t in self.tmeasy], column,
                                        ends)
        if not truthc.block_ok(m):
            raise UserError(f"{self.vehicle.name}: the compiled truth refuses the block "
                             "written for it (a coefficient out of range?)")

    # ------------------------------------------------------------ state
    reset_steady = None
    """None: the plant's steady start (:meth:`artic.plant.Plant.reset_steady`) knows
    PAC2002's treads and the plant's tie rod, not this truth's; the truth starts
    from its own recorded state (:meth:`set_full_state`) instead."""

    def full_state(self) -> np.ndarray:
        """Everything the truth's motion from now on depends on, as one float64 vector.

        MuJoCo's :data:`STATE` (time, ``qpos``, ``qvel``, ``act`` and the
        solver's warm start): the bodies, the steered wheels, the column's
        torsion bar (the steering joints' angles; its play is a dead zone of
        them, without memory), the assist (an activation), and every tyre's
        deflections, the twin's second tyres' too (activations). Then the two
        unwrapped headings [rad] and the speed follower's integral [m]
        (0 unless the speed is followed: the truth's driver on the pedals has
        no follower). The column's drift is the driver's side
        (:class:`artic.validation.synthetic.actuation.SteeringColumn`), not the
        vehicle's. :meth:`set_full_state` restores it, and stepping on from it
        continues the run to rounding (1e-10 m and rad over a second: MuJoCo's
        data after a step hold what its last integrator stage computed, which
        a restored state has computed afresh).
        """
        m, d = self.model, self.data
        x = np.empty(mujoco.mj_stateSize(m, STATE) + 3)
        mujoco.mj_getState(m, d, x[:-3], STATE)
        x[-3:-1] = self._psi
        x[-1] = self._integral if self.speed_mode == "follow" else 0.0
        return x

    def set_full_state(self, x: np.ndarray) -> None:
        """Put the truth in the state :meth:`full_state` returned (of a truth of this vehicle).

        Raises
        ------
        ValueError
            For a vector of another length (another vehicle's state).
        """
        m, d = self.model, self.data
        x = np.asarray(x, dtype=float)
        n = mujoco.mj_stateSize(m, STATE) + 3
        if x.shape != (n,):
            raise ValueError(f"{self.vehicle.name}: a full state has {n} numbers, got "
                             f"{x.size}: it is another vehicle's")
        mujoco.mj_setState(m, d, x[:-3], STATE)
        self._psi[:] = x[-3:-1]
        self._integral = float(x[-1])
        self.steer_limited = 0
        mujoco.mj_forward(m, d)

    # ------------------------------------------------------------ outputs
    @property
    def column_torques(self) -> Mapping[str, float]:
        """The steering's torques from the last callback [N m].

        ``box``: the gear and the assist on the left knuckle; ``torsion_bar``:
        at the steering wheel; ``tie_rod``: on the right knuckle.
        """
        d = self.data.userdata[3 * self.n_wheels + 1:]
        return {"box": float(d[0]), "torsion_bar": float(d[1]), "tie_rod": float(d[2])}

    def extras_gather(self) -> np.ndarray:
        """As the plant's, with ``steer_torque`` the column's torque on the left knuckle."""
        if self._gather is None:
            g = super().extras_gather().copy()
            src = {n: k for k, n in enumerate(_sources())}
            g[-1] = (src["userdata"], 3 * self.n_wheels + 1)
            self._gather = g
        return self._gather

    def extras_from_raw(self, raw: np.ndarray) -> np.ndarray:
        """As the plant's, with the ``slip`` columns from the truth's tyres.

        Each is the slip angle of the first tyre's lateral deflection,
        ``atan(c_y y_e / dF0_y)``: the slip that would hold it steadily.
        """
        out = np.array(raw, dtype=float, copy=True)
        nw = self.n_wheels
        s0 = len(self.extra_columns) - 1 - nw
        Fz = out[:, s0 - 3 * nw + 2:s0:3] / self._n_tyres
        ye = out[:, s0:s0 + nw].copy()
        for k, t in enumerate(self.tmeasy):
            w = self._tyre_set == k
            r = np.minimum(np.maximum(Fz[:, w], 0.0), t.fzmax) / t.fzn
            slope = np.maximum(r * (t.dfy0_1 * (2.0 - r) + t.dfy0_2 * 0.5 * (r - 1.0)), 1.0)
            out[:, s0:s0 + nw][:, w] = np.arctan(t.cy * ye[:, w] / slope)
        return out

    def check_tyre_ranges(self) -> list[str]:
        """Nothing to check: TMeasy has no fitted range (its load law is capped)."""
        return []


def _sources() -> tuple[str, ...]:
    return SOURCES


def _integrator(a) -> None:
    """An actuator that only holds a state: its activation integrates its ctrl, no force."""
    a.dyntype = mujoco.mjtDyn.mjDYN_INTEGRATOR
    a.gaintype = mujoco.mjtGain.mjGAIN_FIXED
    a.gainprm = np.zeros(len(a.gainprm))
    a.biastype = mujoco.mjtBias.mjBIAS_NONE
    a.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
    a.actlimited = mujoco.mjtLimited.mjLIMITED_FALSE
