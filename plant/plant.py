"""The multibody reference plant behind the harness's model interface.

Every integrator stage (RK4, 10 ms by default: see :data:`artic.mjcf.builder.TIMESTEP`)
the passive-force callback runs for every wheel end at once:

- wheel-centre position and velocity, from the hub site and its body's
  spatial velocity; the heading is the hub's x-axis, flattened onto the
  ground;
- vertical force per tyre, ``k_t (R0 - z) - c_t z_dot``, never pulling;
- slips from the tread deflections held in the ``tread.*`` actuators'
  activations, and their rates written to those actuators' controls, which
  MuJoCo integrates (see :mod:`artic.plant.tyre`);
- PAC2002 forces and rolling resistance, applied at the contact point.

The tractor's speed is either *followed* or *driven* (``speed=``):

- ``"follow"`` (the default, as the harness drives every model): a velocity
  servo at the drive axle's ground contact pushes the tractor along its own
  x-axis so that its speed follows the commanded profile, with feed-forward of
  the profile's acceleration (the combination's mass plus the wheels' spin
  inertia) and of the rolling resistance, and an integral term for what the
  feed-forward misses (cornering drag). The wheels roll free. A log's speed is
  then reproduced within millimetres per second, so a plant replaying a log
  that a plant made does not lag it a second time. What it gives up is the
  drive axle's traction slip, a few tenths of a per cent at yard speeds, and
  its small effect on that axle's side force through combined slip;
- ``"drive"``: a driver's cruise control, a PI controller on drive torque at
  the driven wheels and brake torque at all wheels, with the lag a driver has;
- ``"pedals"``: no controller at all; :attr:`Plant.pedals` sets throttle and
  brake, each in [0, 1], of :data:`DRIVE_FORCE_MAX` and :data:`BRAKE_DECEL_MAX`.
  The synthetic campaign's structural truth has a driver work them.

The steering servo turns the left front wheel to the
commanded road-wheel angle. The right wheel follows through the tie-rod
trapezoid, which gives the left/right asymmetry of eq. (3) by itself, so
the plant's steering map has ``q = 0``.

After every step the plant checks MuJoCo's warning counters and the state.
Anything non-finite raises :class:`PlantError` naming the last sound time
and the wheel with the largest tyre force then; nothing is reset silently.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from collections.abc import Mapping
from pathlib import Path

import mujoco
import numpy as np

from artic.mjcf import naming as nm
from artic.mjcf.builder import build_model, linkage
from artic.mjcf.compiling import compile_spec
from artic.mjcf.errors import PlantError, UserError
from artic.mjcf.interface import InitialState, rotate, wrap_angle
from artic.mjcf.masses import layout
from artic.mjcf.plausible import check_tyre_data
from artic.mjcf.vehicle import G, Vehicle, resolve_tyre_file
from artic.plant import callback, closedloop, ctyre, spinmode
from artic.plant.follower import FOLLOW_KI
from artic.plant.tyre import (
    TyreParams,
    check_ranges,
    deflection_rates,
    longitudinal_tread,
    rolling_resistance,
    steady_deflections,
    transient_forces,
)

SPEED_KP = 2.0
"""Speed controller: proportional gain [1/s] (times the total mass)."""

SPEED_KI = 0.5
"""Speed controller: integral gain [1/s^2] (times the total mass)."""

BRAKE_SPIN_SCALE = 0.5
"""Wheel spin [rad/s] over which brake torque fades to zero at standstill."""

PARKING_BRAKE_GRADE = 0.2
"""Parking brake capacity: it holds the combination on this gradient [-] (20 %;
EU rules ask for 18 % for a laden combination)."""

DRIVE_FORCE_MAX = 0.15
"""Full throttle: drive force at the wheels as a fraction of the combination's
weight [-] (a laden truck in a low gear pulls off at about 1.5 m/s^2)."""

BRAKE_DECEL_MAX = 0.6
"""Full brake: deceleration of the combination [g] (a service brake's reach)."""

SPEED_MODES = ("follow", "drive", "pedals")
"""How the plant's tractor speed is controlled (see the module docstring)."""


SLIP_KNOWN = 0.5
"""Wheel speed above which :meth:`Plant.reset_steady` takes a start's slip as known [m/s].

The slip follows from velocities a log measures with about 1 cm/s of noise:
its angle is uncertain by 45 deg at 1 cm/s and by 1 deg at 0.5 m/s. Below
this speed the steady deflections are scaled by ``|V| / SLIP_KNOWN`` (as the
STM scales its lagged slips), so a start at rest has relaxed tyres."""

BACKENDS = ("auto", "compiled", "python")
"""How the plant runs (see :class:`Plant`): its compiled parts, its Python reference, or the
compiled parts where they were built."""

_FORMER_BACKENDS = {"c": "compiled", "numpy": "python"}

_warned: set[str] = set()


def _warn_once(what: str, message: str) -> None:
    """Warn ``message`` the first time ``what`` happens in this process."""
    if what not in _warned:
        _warned.add(what)
        warnings.warn(message, PlantWarning, stacklevel=4)


def _warn_fallback() -> None:
    _warn_once("tyre", f"the compiled tyre callback is unavailable "
               f"({ctyre.unavailable_reason()}); the plant uses the numpy tyre model, about "
               "16 times slower")


def _warn_loop_fallback() -> None:
    _warn_once("loop", f"the compiled closed loop is unavailable "
               f"({closedloop.unavailable_reason()}); the harness drives the plant in Python, "
               "about a third slower, and plants on threads scale less")


def _actuator_now(m: mujoco.MjModel, d: mujoco.MjData, a: int) -> float:
    """Actuator ``a``'s force as ``mj_fwdActuation`` will compute it from the state now.

    Fixed or affine gain and bias (the motors and servos of the plant); any
    other kind counts zero. The C callback's ``actuator_now``.
    """
    out = m.actuator_outadr[a]
    if m.actuator_dyntype[a] == mujoco.mjtDyn.mjDYN_NONE:
        x = d.ctrl[a]
        clamp = not m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CLAMPCTRL
        if m.actuator_ctrllimited[a] and clamp:
            x = min(max(x, m.actuator_ctrlrange[a, 0]), m.actuator_ctrlrange[a, 1])
    else:
        x = d.act[m.actuator_actadr[a] + m.actuator_actnum[a] - 1]
    gp, bp = m.actuator_gainprm[a], m.actuator_biasprm[a]
    length, speed = d.actuator_length[out], d.actuator_velocity[out]
    if m.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_FIXED:
        gain = gp[0]
    elif m.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_AFFINE:
        gain = gp[0] + gp[1] * length + gp[2] * speed
    else:
        return 0.0
    bias = 0.0
    if m.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_AFFINE:
        bias = bp[0] + bp[1] * length + bp[2] * speed
    elif m.actuator_biastype[a] != mujoco.mjtBias.mjBIAS_NONE:
        return 0.0
    f = gain * x + bias
    if m.actuator_forcelimited[a]:
        f = min(max(f, m.actuator_forcerange[a, 0]), m.actuator_forcerange[a, 1])
    return f


def scaled(p: TyreParams, scaling: tuple[tuple[str, float], ...]) -> TyreParams:
    """``p`` with its Magic Formula scaling factors multiplied by the vehicle file's."""
    if not scaling:
        return p
    return dataclasses.replace(p, **{k: getattr(p, k) * f for k, f in scaling})


def with_tyre_files(vehicle: Vehicle, tyre_files: Mapping[int, str | Path]) -> Vehicle:
    """``vehicle`` with the tyre files of some axles replaced (see :class:`Plant`).

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


class PlantWarning(UserWarning):
    """Something the plant had to limit, such as a steering angle beyond the linkage."""


class Plant:
    """The MuJoCo reference plant, driven like KIN and STM.

    Parameters
    ----------
    vehicle : Vehicle
        Every number of the model comes from here and its tyre file.
    timestep : float, optional
        MuJoCo timestep [s]; the model's default (10 ms, RK4) otherwise.
    backend : str
        How the plant runs; the physics is the same, to rounding:

        - ``"compiled"``: the C tyre callback (:mod:`artic.plant.ctyre`), and
          :meth:`step`, :meth:`observe` and the harness's closed loop in C
          (:mod:`artic.plant.closedloop`) where that extension was built and
          the plant allows it (the loop follows the speed, ``speed="follow"``);
          raises where the tyre callback was not built;
        - ``"python"``: the numpy tyre model (:mod:`artic.plant.tyre`, the
          reference) and the step and loop in Python, about 16 times slower;
          what an install without a C compiler runs;
        - ``"auto"`` (the default): ``"compiled"`` where the tyre callback was
          built, else ``"python"`` with a warning.

        :attr:`backend` is the one chosen.
    speed : str
        ``"follow"`` the commanded speed kinematically, or ``"drive"`` it with
        wheel torques like a driver (see the module docstring).
    tyre_files : mapping of int to str or Path, optional
        Tyre property files per axle, by the axle's index in ``vehicle.axles``
        (front of the tractor first): a path, or the name of a tyre shipped
        with artic. Axles left out keep ``vehicle.tyre_file_for(axle)``, which
        is the vehicle's one tyre file unless its parameter file gives the
        axle its own. The ride height follows each axle's tyre.
    spin_fit : bool
        Integrate each wheel's spin/tread mode fitted to the step
        (:mod:`artic.plant.spinmode`), which keeps RK4 stable and accurate through
        standstill at 10 ms; ``False`` integrates it plainly, which RK4 holds
        only up to about 6 ms (the plain RK4 reference of the convergence study).

    Examples
    --------
    One second at 1 m/s with the road wheels at 0.05 rad, in 10 ms steps:

    >>> import artic
    >>> from artic.mjcf.interface import InitialState
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> with artic.Plant(vehicle) as plant:
    ...     plant.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=1.0))
    ...     for _ in range(100):
    ...         plant.step(0.01, 0.05, 1.0, 0.0)  # dt [s], delta [rad], u1 [m/s], u1_dot
    ...     x_1 = plant.observe(0.05)[0]  # the tractor sensor's x [m]
    >>> bool(0.9 < x_1 < 1.1), bool(plant.gamma > 0.0)  # it moved 1 m and turned left
    (True, True)
    """

    name = "mbd"
    budget_kind = "multibody"
    """What its runs count as in the budget of simulated time, whichever loop runs it."""

    def __init__(self, vehicle: Vehicle, timestep: float | None = None,
                 backend: str = "auto", speed: str = "follow",
                 tyre_files: Mapping[int, str | Path] | None = None,
                 spin_fit: bool = True) -> None:
        if backend not in BACKENDS:
            was = (f" ({backend!r} is now {_FORMER_BACKENDS[backend]!r})"
                   if backend in _FORMER_BACKENDS else "")
            raise UserError(f"backend {backend!r}: expected one of {', '.join(BACKENDS)}{was}")
        if speed not in SPEED_MODES:
            raise UserError(f"speed {speed!r}: expected one of {', '.join(SPEED_MODES)}")
        self.speed_mode = speed
        self.spin_fit = spinmode.FIT_SCALE if spin_fit else 0.0
        """The scale of the spin mode's fit to the step (0: none; :mod:`artic.plant.spinmode`)."""
        self.pedals = (0.0, 0.0)
        """Throttle and brake in [0, 1], applied with ``speed="pedals"``."""
        if backend != "python" and ctyre.library() is None:
            if backend == "compiled":
                raise RuntimeError(f"backend 'compiled': {ctyre.unavailable_reason()}")
            _warn_fallback()
            backend = "python"
        self.backend = "compiled" if backend == "auto" else backend
        """How the plant runs: ``"compiled"`` or ``"python"`` (``"auto"`` resolved)."""
        # The compiled step and loop, where the backend is compiled. The tests
        # and benchmarks switch them off alone, keeping the C tyre callback, for
        # the Python reference they are checked against to the bit.
        self._compiled_step = self._compiled_loop = self.backend == "compiled"
        vehicle = with_tyre_files(vehicle, tyre_files or {})
        # Tyre data that fits the vehicle's wheel loads. The plant is built by commands with
        # and without --models (artic dock drives it whatever): the advice names the model.
        check_tyre_data(vehicle, "mbd", "KIN needs no tyre data (--models kin where a "
                                        "command takes it)")
        self.vehicle = vehicle
        # One coefficient set per tyre file in use; each wheel end names its set.
        files = list(dict.fromkeys(vehicle.tyre_file_for(a) for a in vehicle.axles))
        self._tyres = [scaled(TyreParams.from_tir(f), vehicle.tyre_scaling) for f in files]
        self._tyre_set = np.array([files.index(vehicle.tyre_file_for(a))
                                   for a in vehicle.axles for _ in nm.SIDES])
        spec = self._model_spec(vehicle)  # with vehicle.with_payload(), as _index uses
        self.spec = spec
        """The model's spec, as compiled (:mod:`artic.plant.standalone` writes it out)."""
        n_wheels = 2 * len(vehicle.axles)
        if self.backend == "compiled":
            if spec.numerics:
                raise UserError("the plant's spec must not carry numerics of its own")
            self._add_block(spec, n_wheels, len(files))
        self.model = compile_spec(spec)
        if timestep is not None:
            self.model.opt.timestep = timestep
        self.data = mujoco.MjData(self.model)
        self._index(vehicle)
        if speed != "follow":  # no follower: the wheels drive and brake
            self.model.actuator_gainprm[self._follower, 0] = 0.0
            self.model.actuator_biasprm[self._follower, 2] = 0.0
        self._psi = np.zeros(2)
        self._velocity = np.zeros(6)  # mj_objectVelocity's output, reused
        self._integral = 0.0
        self.steer_limited = 0
        self._last_forces = np.zeros((self.n_wheels, 3))
        self._closed = False
        if self.backend == "compiled":
            self.tyres = self._tyres  # writes the C callback's block and checks it
            callback.install(self.model, callback.NATIVE)
        else:
            callback.install(self.model, self._passive)
        self._stepper = closedloop.Stepper(self) if closedloop.step_available(self) else None
        if self._stepper is not None:  # the unwrapped headings [rad], shared with it
            self._psi = self._stepper.psi

    # ------------------------------------------------------------ model kind
    # A model of another kind (the synthetic truth's, in artic.validation) is a
    # subclass that changes these three: its spec, its numeric block and how
    # the block is written. The compiled callback hands a block of another name
    # to the extension registered for it (artic.plant.ctyre.register_kind).
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

    @property
    def parking_brake(self) -> bool:
        """Whether the parking brake holds every wheel.

        It is dry friction on each wheel's spin joint, solved by MuJoCo's
        constraint solver (implicitly, so a held wheel does not chatter), with
        a torque per wheel end in proportion to its static load: together they
        hold the combination on a :data:`PARKING_BRAKE_GRADE` slope.
        """
        return bool(self.model.dof_frictionloss[self._spin_dof].any())

    @parking_brake.setter
    def parking_brake(self, on: bool) -> None:
        T = PARKING_BRAKE_GRADE * self.mass * G * self.R0 * self._brake_share if on else 0.0
        self.model.dof_frictionloss[self._spin_dof] = T

    @property
    def last_forces(self) -> np.ndarray:
        """Contact force of every wheel end from the last callback, world frame [N]."""
        if self.backend == "compiled":
            return self.data.userdata[:3 * self.n_wheels].reshape(-1, 3)
        return self._last_forces

    # ------------------------------------------------------------ indexing
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
        self._sensor = [m.site(nm.sensor(1)).id, m.site(nm.sensor(2)).id]
        self._index_extras(lay, ends)
        self._s1 = np.array(v.sensor1[:2])
        self._sensor_yaw = (v.sensor1_yaw, v.sensor2_yaw)
        self.mass = v.m1 + v.m2
        self.R0, self.k_t, self.c_t = lay.R0, lay.k_tyre, lay.c_tyre
        self._per_wheel_tyre()

    def _index_extras(self, lay, ends) -> None:
        """Addresses and column names of :meth:`extras`."""
        m = self.model
        names = [nm.TRACTOR, nm.TRAILER, *(nm.axle(a.axle.name) for a in lay.axles)]
        self._pose_bodies = np.array([m.body(b).id for b in names])
        self._spin_qpos = np.array([m.jnt_qposadr[m.joint(nm.spin(a.axle.name, s)).id]
                                    for a, s in ends])
        steered = [(a, s) for a, s in ends if a.axle.steered]
        self._steer_qpos = np.array([m.jnt_qposadr[m.joint(nm.steer(a.axle.name, s)).id]
                                     for a, s in steered], dtype=int)
        wheels = [f"{a.axle.name}.{s}" for a, s in ends]
        cols = [f"pose.{b}.{c}" for b in names for c in ("x", "y", "z", "qw", "qx", "qy", "qz")]
        cols += [f"steer.{a.axle.name}.{s}" for a, s in steered]
        cols += [f"spin.{w}" for w in wheels]
        for what in ("contact", "force"):
            cols += [f"{what}.{w}.{c}" for w in wheels for c in ("x", "y", "z")]
        cols += [f"slip.{w}" for w in wheels]
        cols.append("steer_torque")
        self.extra_columns: tuple[str, ...] = tuple(cols)
        self._gather: np.ndarray | None = None

    def extras(self) -> np.ndarray:
        """Outputs beyond the signal schema, for drawings and plots, in :attr:`extra_columns` order.

        - ``pose.BODY.{x,y,z,qw,qx,qy,qz}``: world position [m] and orientation
          (MuJoCo's w, x, y, z quaternion) of the tractor, the semitrailer and
          every axle body;
        - ``steer.AXLE.SIDE``: steering-hinge angle of each steered wheel [rad];
        - ``spin.AXLE.SIDE``: wheel spin angle [rad];
        - ``contact.AXLE.SIDE.{x,y,z}``: contact point, world frame [m];
        - ``force.AXLE.SIDE.{x,y,z}``: tyre force of the wheel end there from
          the last callback, world frame [N] (``z`` is the wheel load);
        - ``slip.AXLE.SIDE``: transient slip angle alpha of the tyre [rad];
        - ``steer_torque``: the front steering servo's actuator torque [N m].

        It is :meth:`extras_from_raw` of the values :meth:`extras_gather` names,
        read now; the compiled closed loop gathers the same values per sample.
        """
        d = self.data
        g = self.extras_gather()
        arrays = {"qpos": d.qpos, "xpos": d.xpos.ravel(), "xquat": d.xquat.ravel(),
                  "site_xpos": d.site_xpos.ravel(),
                  # the forces: where the compiled callback writes them, or the numpy one's
                  "userdata": (d.userdata if self.backend == "compiled"
                               else self.last_forces.ravel()),
                  "act": d.act,
                  "actuator_force": d.actuator_force, "zero": np.zeros(1)}
        raw = np.empty(len(g))
        for k, name in enumerate(closedloop.SOURCES):
            sel = g[:, 0] == k
            raw[sel] = arrays[name][g[sel, 1]]
        return self.extras_from_raw(raw[None, :])[0]

    def extras_gather(self) -> np.ndarray:
        """Where each raw value behind :meth:`extras` is read, shape (n_columns, 2).

        Row ``j`` is (index into :data:`artic.plant.closedloop.SOURCES`, index into
        that ``MjData`` array, flattened). The ``slip`` columns read the tread's
        lateral deflection, which :meth:`extras_from_raw` turns into a slip angle.
        """
        if self._gather is None:
            src = {n: k for k, n in enumerate(closedloop.SOURCES)}
            rows = []
            for b in self._pose_bodies:
                rows += [(src["xpos"], 3 * b + c) for c in range(3)]
                rows += [(src["xquat"], 4 * b + c) for c in range(4)]
            rows += [(src["qpos"], a) for a in self._steer_qpos]
            rows += [(src["qpos"], a) for a in self._spin_qpos]
            for h in self._hub:
                rows += [(src["site_xpos"], 3 * h), (src["site_xpos"], 3 * h + 1),
                         (src["zero"], 0)]
            rows += [(src["userdata"], j) for j in range(3 * self.n_wheels)]
            rows += [(src["act"], a) for a in self._act_v]
            rows.append((src["actuator_force"], self._servo[0]) if self._servo
                        else (src["zero"], 0))
            self._gather = np.array(rows, dtype=np.int32).reshape(-1, 2)
        return self._gather

    def extras_from_raw(self, raw: np.ndarray) -> np.ndarray:
        """:meth:`extras` rows from rows of the raw values of :meth:`extras_gather`.

        Parameters
        ----------
        raw : ndarray, shape (n_samples, n_columns)

        Returns
        -------
        ndarray, shape (n_samples, n_columns)
            The raw rows with each ``slip`` column's tread deflection [m]
            turned into the slip angle [rad] at that wheel's load.
        """
        out = np.array(raw, dtype=float, copy=True)
        nw = self.n_wheels
        s0 = len(self.extra_columns) - 1 - nw  # the slip columns, before steer_torque
        Fz = out[:, s0 - 3 * nw + 2:s0:3] / self._n_tyres  # force.*.z, per tyre
        v = out[:, s0:s0 + nw].copy()
        slip = out[:, s0:s0 + nw]
        for k, p in enumerate(self._tyres):  # each tyre file on its wheels
            w = self._tyre_set == k
            slip[:, w] = np.arctan(v[:, w] / p.sigma_alpha(np.maximum(Fz[:, w], p.FZMIN)))
        return out

    # ------------------------------------------------------------ tyres
    def _wheel_kinematics(self, d: mujoco.MjData):
        """Per wheel end: hub position, heading, lateral axis, centre velocity, vertical hub.

        A wheel whose hub axis is vertical has no heading on the ground and
        gets no tyre force, as in the C callback.
        """
        pos = d.site_xpos[self._hub]
        R = d.site_xmat[self._hub].reshape(-1, 3, 3)
        hx = R[:, :, 0].copy()
        hx[:, 2] = 0.0
        norm = np.linalg.norm(hx, axis=1)
        flat = norm < 1e-9  # hub axis vertical: no heading, no tyre force (as in C)
        hx /= np.where(flat, 1.0, norm)[:, None]
        hy = np.column_stack([-hx[:, 1], hx[:, 0], np.zeros(len(hx))])
        cvel = d.cvel[self._hub_body]
        r = pos - d.subtree_com[self._root]
        w, v0 = cvel[:, :3], cvel[:, 3:]
        vel = v0 + np.column_stack([w[:, 1] * r[:, 2] - w[:, 2] * r[:, 1],
                                    w[:, 2] * r[:, 0] - w[:, 0] * r[:, 2],
                                    w[:, 0] * r[:, 1] - w[:, 1] * r[:, 0]])
        return pos, hx, hy, vel, flat

    def _passive(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        pos, hx, hy, vel, flat = self._wheel_kinematics(d)
        rho = self.R0_w - pos[:, 2]
        Fz = np.where(rho > 0.0, self.k_t_w * rho - self.c_t_w * vel[:, 2], 0.0)
        Fz = np.maximum(Fz, 0.0)
        Vx = np.einsum("ij,ij->i", vel, hx)
        Vy = np.einsum("ij,ij->i", vel, hy)
        Re = self.R0_w - np.maximum(rho, 0.0) / 3.0
        Vsx = Vx - d.qvel[self._spin_dof] * Re
        u, v, phi = d.act[self._act_u], d.act[self._act_v], d.act[self._act_w]
        omega_z = d.cvel[self._hub_body][:, 2]  # the wheel's yaw rate about the ground normal
        Fx, Fy, Mz, My, du, dv, dphi, k_x, c_x, b_x = (np.empty(self.n_wheels)
                                                      for _ in range(10))
        for k, p in enumerate(self._tyres):  # each tyre file on its wheels
            w = self._tyre_set == k
            du[w], dv[w], dphi[w] = deflection_rates(p, Fz[w], Vx[w], Vsx[w], Vy[w],
                                                     omega_z[w], u[w], v[w], phi[w])
            Fx[w], Fy[w], Mz[w] = transient_forces(p, Fz[w], Vx[w], Vsx[w], Vy[w], omega_z[w],
                                                   u[w], v[w], phi[w],
                                                   self.vehicle.plant.tyre_moments)
            My[w] = rolling_resistance(p, Fz[w], Vx[w], Fx[w])
            k_x[w], c_x[w], b_x[w] = longitudinal_tread(p, Fz[w], Vx[w])
        n = self._n_tyres
        F = (n * Fx)[:, None] * hx + (n * Fy)[:, None] * hy
        F[:, 2] += n * Fz
        torque = (n * My)[:, None] * hy  # about the spin axis
        torque[:, 2] += n * Mz  # aligning and bore torque about the ground normal
        contact = pos.copy()
        contact[:, 2] = 0.0
        if self.spin_fit > 0.0:  # the spin mode, fitted to the step (as in the C callback)
            dFx, ddu = self._fit_spin(m, d, F, torque, contact, hx, Re, k_x, c_x, b_x, du)
            Fx += dFx
            du += ddu
            F += (n * dFx)[:, None] * hx
        d.ctrl[self._tread_u] = np.where(flat, 0.0, du)
        d.ctrl[self._tread_v] = np.where(flat, 0.0, dv)
        d.ctrl[self._tread_w] = np.where(flat, 0.0, dphi)
        F[flat] = 0.0
        torque[flat] = 0.0
        self._last_forces = F
        for i in range(self.n_wheels):
            mujoco.mj_applyFT(m, d, F[i], torque[i], contact[i], int(self._wheel_body[i]),
                              d.qfrc_passive)

    def _fit_spin(self, m: mujoco.MjModel, d: mujoco.MjData, F: np.ndarray,
                  torque: np.ndarray, contact: np.ndarray, hx: np.ndarray, Re: np.ndarray,
                  k_x: np.ndarray, c_x: np.ndarray, b_x: np.ndarray,
                  du: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:func:`artic.plant.spinmode.fit` of every wheel end, before its forces apply.

        The spin's rate counts the tyre's force and torque and everything else
        the passive stage knows on the spin dof: MuJoCo's own passive force, the
        applied force and the actuators on the joint (:meth:`_spin_actuator_forces`).
        A spin held by dry friction (the parking brake) is left to MuJoCo's solver.
        """
        spin = self._spin_dof
        q_x, Q = self._spin_forces(m, d, F, torque, contact, hx)
        inv_I = m.dof_invweight0[spin]
        f_spin = (Q + self._spin_actuator_forces(m, d) + d.qfrc_passive[spin]
                  + d.qfrc_applied[spin]) * inv_I
        dFx, ddu = spinmode.fit(m.opt.timestep, inv_I, q_x, self._n_tyres, Re, k_x, c_x, b_x,
                                f_spin, du, self.spin_fit)
        held = m.dof_frictionloss[spin] != 0.0
        return np.where(held, 0.0, dFx), np.where(held, 0.0, ddu)

    def _spin_forces(self, m: mujoco.MjModel, d: mujoco.MjData, F: np.ndarray,
                     torque: np.ndarray, contact: np.ndarray,
                     hx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Generalized forces on every wheel end's spin, per wheel end.

        Returns ``q_x``, that of one newton along ``hx`` at the contact [m], and
        ``Q``, that of its tyre force ``F`` and ``torque`` [N m].
        """
        spin = self._spin_dof
        jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        q_x, Q = np.empty(self.n_wheels), np.empty(self.n_wheels)
        for i in range(self.n_wheels):
            mujoco.mj_jac(m, d, jacp, jacr, contact[i], int(self._wheel_body[i]))
            q_x[i] = jacp[:, spin[i]] @ hx[i]
            Q[i] = jacp[:, spin[i]] @ F[i] + jacr[:, spin[i]] @ torque[i]
        return q_x, Q

    def spin_modes(self) -> np.ndarray:
        """Eigenvalues of every wheel end's spin/tread mode now [1/s], shape ``(n_wheels, 2)``.

        :func:`artic.plant.spinmode.eigenvalues` of the spin dof's inertia, the
        contact point's lever on it and the tyre's tread at the wheel's load and
        speed now, fastest first: the model's own, whatever the step.
        """
        m, d = self.model, self.data
        pos, hx, _, vel, _ = self._wheel_kinematics(d)
        rho = self.R0_w - pos[:, 2]
        Fz = np.maximum(np.where(rho > 0.0, self.k_t_w * rho - self.c_t_w * vel[:, 2], 0.0), 0.0)
        Vx = np.einsum("ij,ij->i", vel, hx)
        Re = self.R0_w - np.maximum(rho, 0.0) / 3.0
        k_x, c_x, b_x = (np.empty(self.n_wheels) for _ in range(3))
        for k, p in enumerate(self._tyres):
            w = self._tyre_set == k
            k_x[w], c_x[w], b_x[w] = longitudinal_tread(p, Fz[w], Vx[w])
        contact = pos.copy()
        contact[:, 2] = 0.0
        zero = np.zeros_like(hx)
        q_x, _ = self._spin_forces(m, d, zero, zero, contact, hx)
        return spinmode.eigenvalues(m.dof_invweight0[self._spin_dof], q_x, self._n_tyres, Re,
                                    k_x, c_x, b_x)

    def _spin_actuator_forces(self, m: mujoco.MjModel, d: mujoco.MjData) -> np.ndarray:
        """Generalized force on each spin dof from the actuators on its joint.

        The drive and the brakes (the tread states' actuators have no gain),
        each as ``mj_fwdActuation`` will compute it: fixed or affine gain and
        bias, the control clamped to its range, the force to its.
        """
        q = np.zeros(self.n_wheels)
        # As ints: ``x in (enum, ...)`` compares enum == x, which is False for numpy's ints.
        joint_trn = (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))
        for i, j in enumerate(m.dof_jntid[self._spin_dof]):
            for a in range(m.nu):
                if int(m.actuator_trntype[a]) in joint_trn and m.actuator_trnid[a, 0] == j:
                    q[i] += m.actuator_gear[m.actuator_outadr[a], 0] * _actuator_now(m, d, a)
        return q

    # ------------------------------------------------------------ interface
    def reset(self, initial: InitialState) -> None:
        """Place the combination at ``initial``, at rest on its springs, rolling at ``u1``.

        ``initial`` is what the sensors report (a log's first sample): the
        headings, the articulation and the lateral velocity of inertial units
        mounted turned by their yaw (``sensor_yaw``), which :meth:`observe`
        adds. The bodies are placed without it, so that ``observe`` reports
        ``initial`` back.
        """
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        e1, e2 = self._sensor_yaw
        psi = initial.psi_1 - e1
        gamma = initial.gamma - (e1 - e2)
        dx, dy = rotate(psi, self._s1[0], self._s1[1])
        d.qpos[:3] = [initial.x_1 - dx, initial.y_1 - dy, 0.0]
        d.qpos[3:7] = [math.cos(psi / 2), 0.0, 0.0, math.sin(psi / 2)]
        d.qpos[m.jnt_qposadr[self._hitch_yaw]] = -gamma
        v_y = math.sin(e1) * initial.u1 + math.cos(e1) * initial.v_y_1  # in the tractor's axes
        v_origin = v_y - initial.r_1 * self._s1[0]
        d.qvel[:3] = [*rotate(psi, initial.u1, v_origin), 0.0]
        d.qvel[5] = initial.r_1
        d.qvel[m.jnt_dofadr[self._hitch_yaw]] = initial.r_2 - initial.r_1
        d.qvel[self._spin_dof] = initial.u1 / self.R0
        self._integral = 0.0
        self.steer_limited = 0
        mujoco.mj_forward(m, d)
        self._psi[:] = (psi, psi - gamma)

    def reset_steady(self, initial: InitialState) -> None:
        """Place the combination at ``initial`` in the steady state of that motion.

        :meth:`reset`, and then what a vehicle in that motion carries that the
        signals do not show, instead of zero:

        - the steered wheels at ``initial.delta`` (the left one, within the
          linkage's range; the right one through the tie-rod linkage);
        - every wheel spinning at its rolling speed ``V_x / R_e`` (no
          longitudinal slip: the wheels roll free under the speed follower);
        - every tread deflection at its steady state for the wheel's motion
          (:func:`artic.plant.tyre.steady_deflections`: the slip angle and
          turn slip the motion gives, held as if the wheel had rolled there
          for a while), scaled by ``min(1, |V| / SLIP_KNOWN)``
          (:data:`SLIP_KNOWN`).

        The suspension stays at rest on its springs. The open-loop predictions
        start the plant so (:mod:`artic.validation.criteria.prediction`): a
        zeroed start would first build the slip the measured motion already has.
        """
        self.reset(initial)
        m, d = self.model, self.data
        lo, hi = self._servo_range
        delta = min(max(float(initial.delta), lo), hi)
        for name, left, right in zip(self._steered, self._steer_L, self._steer_R, strict=True):
            poly = m.eq_data[m.equality(nm.tie_rod(name)).id, :5]  # right = poly(left)
            d.qpos[left] = delta
            d.qpos[right] = np.polynomial.polynomial.polyval(delta, poly)
        mujoco.mj_forward(m, d)
        pos, hx, hy, vel, flat = self._wheel_kinematics(d)
        rho = self.R0_w - pos[:, 2]
        Fz = np.maximum(np.where(rho > 0.0, self.k_t_w * rho - self.c_t_w * vel[:, 2], 0.0), 0.0)
        Vx = np.einsum("ij,ij->i", vel, hx)
        Vy = np.einsum("ij,ij->i", vel, hy)
        Re = self.R0_w - np.maximum(rho, 0.0) / 3.0
        omega_z = d.cvel[self._hub_body][:, 2]
        d.qvel[self._spin_dof] = Vx / Re
        gate = np.minimum(1.0, np.hypot(Vx, Vy) / SLIP_KNOWN)
        for k, p in enumerate(self._tyres):
            w = (self._tyre_set == k) & ~flat
            u, v, phi = steady_deflections(p, Fz[w], Vx[w], np.zeros(w.sum()), Vy[w],
                                           omega_z[w])
            d.act[self._act_u[w]] = gate[w] * u
            d.act[self._act_v[w]] = gate[w] * v
            d.act[self._act_w[w]] = gate[w] * phi
        mujoco.mj_forward(m, d)

    def _speed(self) -> float:
        """Tractor speed along its x-axis [m/s].

        The tractor is the free root body, so ``qvel[:3]`` is its origin's
        velocity in the world frame; the x-axis is the first column of ``xmat``.
        """
        d = self.data
        R = d.xmat[self._tractor]
        v = d.qvel
        return float(R[0] * v[0] + R[3] * v[1] + R[6] * v[2])

    def _control(self, u_cmd: float, u_dot: float, h: float) -> None:
        d = self.data
        u = self._speed()
        e = u_cmd - u
        self._integral += e * h
        if self.speed_mode == "pedals":
            throttle = min(max(float(self.pedals[0]), 0.0), 1.0)
            brake = min(max(float(self.pedals[1]), 0.0), 1.0)
            direction = 1.0 if u_cmd >= 0.0 else -1.0  # the gear: forward or reverse
            weight = self.mass * G
            d.ctrl[self._drive] = direction * throttle * DRIVE_FORCE_MAX * weight * self.R0 \
                / len(self._drive)
            self._pedal_brake(brake, weight)
            return
        rr = self.tyre.QSY1 * self.mass * G * math.tanh(u_cmd / 0.1)
        if self.speed_mode == "follow":
            ff = self.mass_eff * u_dot + rr
            d.ctrl[self._follower] = u_cmd + ff / self._follower_kv + FOLLOW_KI * self._integral
            return
        F = self.mass * (u_dot + SPEED_KP * e + SPEED_KI * self._integral) + rr
        direction = math.copysign(1.0, u_cmd) if abs(u_cmd) > 0.05 else math.copysign(1.0, F)
        d.ctrl[self._brake] = 0.0
        d.ctrl[self._drive] = 0.0
        if F * direction >= 0.0:
            d.ctrl[self._drive] = F * self.R0 / len(self._drive)
        else:
            spin = d.qvel[self._spin_dof]
            d.ctrl[self._brake] = (-abs(F) * self.R0 * self._brake_share
                                   * np.tanh(spin / BRAKE_SPIN_SCALE))

    def _pedal_brake(self, brake: float, weight: float) -> None:
        """The service brake at pedal ``brake`` [0-1] on a combination of ``weight`` [N]."""
        spin = self.data.qvel[self._spin_dof]
        self.data.ctrl[self._brake] = (-brake * BRAKE_DECEL_MAX * weight * self.R0
                                       * self._brake_share * np.tanh(spin / BRAKE_SPIN_SCALE))

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s]; see :mod:`artic.mjcf.interface`.

        ``delta`` turns the left front wheel (the steering box's wheel); the
        right one follows through the linkage.
        """
        m, d = self.model, self.data
        h = m.opt.timestep
        n = max(1, round(dt / h))
        if self._stepper is not None and self._compiled_step:
            # The same step in C: the speed controls here, the rest there.
            self._control(u1 + u1_dot * 0.5 * (n * h), u1_dot, n * h)
            code = self._stepper.step(delta, n)
            s = self._stepper.struct
            if s.steer_limited:
                first = self.steer_limited == 0
                self.steer_limited += s.steer_limited
                s.steer_limited = 0
                if first:
                    self.warn_steer_limited(s.first_limit_time, s.first_limit_delta)
            if code == closedloop.TYRE_RANGE:
                d.userdata[3 * self.n_wheels] = 0.0
                self.check_tyre_ranges()
            elif code == closedloop.DIVERGED:
                good = np.array(s.good_forces[:3 * self.n_wheels]).reshape(-1, 3)
                self._check(s.good_time, good, s.span)
                raise AssertionError("unreachable: a diverged step that _check accepts")
            elif code != closedloop.DONE:
                raise RuntimeError("the compiled step refused the plant's indices")
            return
        lo, hi = self._servo_range
        if not lo <= delta <= hi:
            self.steer_limited += 1
            if self.steer_limited == 1:
                self.warn_steer_limited(d.time, delta)
        d.ctrl[self._servo] = min(max(delta, lo), hi)
        # The speed controller is sampled once per call (zero-order hold over
        # dt), at the middle of the interval (the commanded ramp's mean, at
        # dt / 2 whatever the step), so MuJoCo runs n steps uninterrupted.
        self._control(u1 + u1_dot * 0.5 * (n * h), u1_dot, n * h)
        # MuJoCo resets a diverged simulation to t = 0 by itself: keep what a report needs.
        good_time, good_forces = d.time, self.last_forces.copy()
        mujoco.mj_step(m, d, nstep=n)
        self._check(good_time, good_forces, n * h)
        if self.backend == "python":
            self.check_tyre_ranges()
        elif d.userdata[3 * self.n_wheels]:  # the C callback counted wheels out of range
            d.userdata[3 * self.n_wheels] = 0.0
            self.check_tyre_ranges()

    def warn_steer_limited(self, time: float, delta: float) -> None:
        """Warn, once per run, that ``delta`` [rad] at ``time`` [s] was beyond the linkage."""
        lo, hi = self._servo_range
        warnings.warn(f"t = {time:.2f} s: left-wheel angle {math.degrees(delta):.1f} "
                      f"deg is beyond the linkage's [{math.degrees(lo):.1f}, "
                      f"{math.degrees(hi):.1f}] deg; limited", PlantWarning, stacklevel=3)

    def _check(self, good_time: float, good_forces: np.ndarray, span: float) -> None:
        """Raise :class:`PlantError` if the step diverged.

        The message gives the last time the state was sound (MuJoCo has reset
        ``d.time`` by now) and the wheel whose tyre force was largest then.
        """
        d = self.data
        if not d.warning.number.any() and np.isfinite(d.qvel).all():
            return
        bad = [mujoco.mjtWarning(i).name for i in range(len(d.warning)) if d.warning[i].number]
        finite = np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))
        if bad or not finite:
            F = np.linalg.norm(good_forces, axis=1)
            F = np.where(np.isfinite(F), F, np.inf)
            k = int(np.argmax(F))
            raise PlantError(f"t = {good_time:.3f} s: the simulation diverged within the next "
                             f"{1e3 * span:.0f} ms ({', '.join(bad) or 'non-finite state'}); "
                             f"largest tyre force then at wheel {self.wheel_names[k]} "
                             f"({F[k]:.3g} N)")

    def observe(self, delta: float | None = None) -> np.ndarray:
        """Signals at the sensor points, in ``OBSERVATION`` order."""
        if self._stepper is not None and self._compiled_step:
            return self._stepper.observe()
        d = self.data
        out = np.empty(13)
        for i, (site, body) in enumerate(zip(self._sensor, (self._tractor, self._trailer),
                                             strict=True)):
            R = d.xmat[body]
            psi = math.atan2(R[3], R[0])
            psi = self._psi[i] + wrap_angle(psi - self._psi[i])
            self._psi[i] = psi
            vx, vy, r = self._sensor_velocity(i)
            xy = d.site_xpos[site]
            out[6 * i:6 * i + 6] = [xy[0], xy[1], psi + self._sensor_yaw[i], vx, vy, r]
        out[12] = wrap_angle(out[2] - out[8])
        return out

    def _sensor_velocity(self, i: int) -> tuple[float, float, float]:
        """``v_x``, ``v_y`` [m/s] and yaw rate [rad/s] at sensor ``i`` (0 tractor, 1 trailer).

        In the unit's axes: turned by the sensor's mounting yaw ``eps`` to the left.
        """
        res = self._velocity  # written whole by MuJoCo
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_SITE,
                                 self._sensor[i], res, 1)
        vx, vy = res[3], res[4]
        eps = self._sensor_yaw[i]
        if eps:
            c, s = math.cos(eps), math.sin(eps)
            vx, vy = c * vx + s * vy, -s * vx + c * vy
        return vx, vy, res[2]

    def sensor_speed(self) -> float:
        """The tractor sensor's longitudinal velocity [m/s]: ``observe()[3]`` alone."""
        return float(self._sensor_velocity(0)[0])

    @property
    def gamma(self) -> float:
        """Articulation angle as the inertial units report it, ``observe()[12]`` [rad].

        The hitch angle plus the units' mounting yaws' difference (zero for units
        mounted straight), so that the harness compares it with a log's like for like.
        """
        e1, e2 = self._sensor_yaw
        return float(wrap_angle(-self.data.qpos[self.model.jnt_qposadr[self._hitch_yaw]]
                                + e1 - e2))

    def wheel_loads(self) -> np.ndarray:
        """Vertical force of every wheel end from the last callback [N]."""
        return self.last_forces[:, 2].copy()

    def check_tyre_ranges(self) -> list[str]:
        """Warn for wheels outside the tyre file's valid ranges now (see :mod:`artic.plant.tyre`).

        Called after every step; a wheel in the air (no load) is not reported.
        """
        out = []
        Fz_all = self.last_forces[:, 2] / self._n_tyres
        for k, p in enumerate(self._tyres):
            idx = np.flatnonzero((self._tyre_set == k) & (Fz_all > 0.0))
            if not idx.size:
                continue
            Fz = Fz_all[idx]
            Fzc = np.maximum(Fz, p.FZMIN)  # as in the force evaluation
            kappa = self.data.act[self._act_u[idx]] / p.sigma_kappa(Fzc)
            alpha = np.arctan(self.data.act[self._act_v[idx]] / p.sigma_alpha(Fzc))
            names = [self.wheel_names[i] for i in idx]
            out += check_ranges(p, Fz, kappa, alpha, names, f"t = {self.data.time:.2f} s")
        return out

    def compiled(self) -> None:
        """The plant has no compiled form for the reduced models' loop: ``None``."""
        return None

    def closed_loop(self):
        """:func:`artic.plant.closedloop.run` for this plant, or ``None`` where it cannot run.

        It cannot with ``backend="python"``, a speed that is not followed, or
        an install without the compiled extension; the harness then drives the
        plant through :meth:`step` and :meth:`observe` in Python.
        """
        if not self._compiled_loop:
            return None
        if closedloop.unavailable_reason():  # not built: say so once, run in Python
            _warn_loop_fallback()
            return None
        if not closedloop.available(self):  # this plant's mode: the Python loop, silently
            return None
        return functools.partial(closedloop.run, self)

    def close(self) -> None:
        """Release the passive-force callback."""
        if not self._closed:
            callback.uninstall(self.model)
            self._closed = True

    def __enter__(self) -> Plant:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass
