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

import functools
import warnings
from collections.abc import Mapping
from pathlib import Path

import mujoco
import numpy as np

from artic.mjcf import naming as nm
from artic.mjcf.compiling import compile_spec
from artic.mjcf.errors import PlantError, UserError
from artic.mjcf.plausible import check_tyre_data
from artic.mjcf.vehicle import Vehicle
from artic.plant import callback, closedloop, ctyre, spinmode
from artic.plant.building import Building, scaled, with_tyre_files
from artic.plant.observing import Observing
from artic.plant.recording import Recording
from artic.plant.stepping import (
    BRAKE_DECEL_MAX,
    BRAKE_SPIN_SCALE,
    DRIVE_FORCE_MAX,
    FOLLOW_KI,
    PARKING_BRAKE_GRADE,
    SLIP_KNOWN,
    SPEED_KI,
    SPEED_KP,
    PlantWarning,
    Stepping,
)
from artic.plant.tyre import TyreParams
from artic.plant.tyreforces import TyreForces

__all__ = ["BACKENDS", "BRAKE_DECEL_MAX", "BRAKE_SPIN_SCALE", "DRIVE_FORCE_MAX", "FOLLOW_KI",
           "PARKING_BRAKE_GRADE", "SLIP_KNOWN", "SPEED_KI", "SPEED_KP", "SPEED_MODES", "Plant",
           "PlantError", "PlantWarning", "scaled", "with_tyre_files"]

SPEED_MODES = ("follow", "drive", "pedals")
"""How the plant's tractor speed is controlled (see the module docstring)."""


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


class Plant(Building, TyreForces, Stepping, Observing, Recording):
    """The MuJoCo reference plant, driven like KIN and STM.

    Made of one part per job, each in its module: :class:`~artic.plant.building.Building`
    (the model, its indices, its tyre sets), :class:`~artic.plant.tyreforces.TyreForces`
    (the tyre forces in Python), :class:`~artic.plant.stepping.Stepping` (resets, speed
    control, the step), :class:`~artic.plant.observing.Observing` (the signals) and
    :class:`~artic.plant.recording.Recording` (the outputs for drawings).

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

    See Also
    --------
    artic.KIN : the kinematic model.
    artic.STM : the single-track model.
    artic.build_model : any model of the harness by name.

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
