"""The harness's closed loop around the plant, compiled: a whole log in one call.

``_loop_c.c`` does per sample what :func:`artic.validation.harness.loop.run_inputs` does
with :class:`plant.Plant` in Python (the reference, kept and tested against
this within 1e-9): the reversing feedback law, the signals at the sensor
points, the raw rows behind :meth:`plant.Plant.extras`, the stop at the
jackknife limit, the steering servos, the speed follower and MuJoCo's steps.
ctypes releases the GIL for the call, so plants on threads run in parallel.

The C loop hands control back to Python, and resumes after it, where Python
must see the state of that moment: a wheel outside its tyre file's ranges
(Python names it, as after every :meth:`plant.Plant.step`) and a diverged
step (Python raises :class:`plant.PlantError`). A steering angle beyond the
linkage is counted in C and warned about once, as ``Plant.step`` does.

:class:`Stepper` is one :meth:`plant.Plant.step` (after Python has set the
speed controls) and one ``observe`` from the same C: ``Plant`` uses it for
the plants Python drives step by step, such as the synthetic truth's, whose
drivers decide in Python every 10 ms. It computes what Python's ``step``
and ``observe`` compute, to the bit (``tests/test_plant_step.py``).

:class:`Ramp` is a docking run's plant steps between two controller samples
(:func:`artic.validation.docking.run.drive`): the actuators' rate-limited ramps,
the steering map, ``step``, ``observe`` and the jackknife check, ten steps in
one call without the GIL, to the bit of ``drive``'s Python loop.

The extension is built by ``pip install`` beside the tyre callback; without
it, or for a plant whose speed is not followed or whose backend is
``"python"``, :func:`available` says why and the harness uses its Python loop.
"""

from __future__ import annotations

import ctypes
import functools
import math
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from artic.mjcf import extensions
from artic.mjcf.vehicle import G
from artic.plant import ctyre
from artic.plant.follower import FOLLOW_KI

if TYPE_CHECKING:
    from artic.mjcf.interface import LoopArgs
    from artic.plant.plant import Plant

ABI = 4
MAX_SERVOS = 4
MAX_WHEELS = 64
N_OBS = 13

SOURCES = ("qpos", "xpos", "xquat", "site_xpos", "userdata", "act", "actuator_force", "zero")
"""What a gathered raw value can be read from: an ``MjData`` array, or a constant 0."""

DONE, STOPPED, TYRE_RANGE, DIVERGED, BAD = 0, 1, 3, 4, 5


class _Loop(ctypes.Structure):
    _fields_ = [
        ("tractor_body", ctypes.c_int), ("trailer_body", ctypes.c_int),
        ("sensor_site", ctypes.c_int * 2), ("hitch_qpos", ctypes.c_int),
        ("n_servo", ctypes.c_int), ("servo", ctypes.c_int * MAX_SERVOS),
        ("servo_lo", ctypes.c_double), ("servo_hi", ctypes.c_double),
        ("follower", ctypes.c_int),
        ("follower_kv", ctypes.c_double), ("mass_eff", ctypes.c_double),
        ("rr_coef", ctypes.c_double), ("follow_ki", ctypes.c_double),
        ("sensor_yaw", ctypes.c_double * 2),
        ("n_wheels", ctypes.c_int),
        ("gain", ctypes.c_double), ("delta_max", ctypes.c_double),
        ("gamma_max", ctypes.c_double),
        ("n_gather", ctypes.c_int), ("gather", ctypes.POINTER(ctypes.c_int)),
        ("k", ctypes.c_int), ("psi", ctypes.c_double * 2), ("integral", ctypes.c_double),
        ("steer_limited", ctypes.c_int),
        ("first_limit_time", ctypes.c_double), ("first_limit_delta", ctypes.c_double),
        ("good_time", ctypes.c_double), ("span", ctypes.c_double),
        ("good_forces", ctypes.c_double * (3 * MAX_WHEELS)),
    ]


class _Ramp(ctypes.Structure):
    _fields_ = [
        ("wheel", ctypes.c_double), ("u", ctypes.c_double), ("t", ctypes.c_double),
        ("wheel_step", ctypes.c_double), ("u_step", ctypes.c_double),
        ("offset", ctypes.c_double), ("q", ctypes.c_double), ("i_s", ctypes.c_double),
        ("dt", ctypes.c_double), ("gamma_max", ctypes.c_double),
        ("n", ctypes.c_int), ("j", ctypes.c_int), ("tyre_range", ctypes.c_int),
    ]


def _load() -> tuple[ctypes.CDLL | None, str]:
    if ctyre.library() is None:  # the loop calls the tyre callback's models
        return None, ctyre.unavailable_reason()
    lib, why = extensions.load("artic.plant._loop_c", "artic_loop", ABI,
                               "the compiled closed loop")
    if lib is None:
        return None, why
    if lib.artic_loop_size() != ctypes.sizeof(_Loop):
        return None, ("the compiled closed loop was built from another version of artic; "
                      "reinstall artic")
    d, b = ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_ubyte)
    lib.artic_run_loop.restype = ctypes.c_int
    lib.artic_run_loop.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.POINTER(_Loop),
                                   ctypes.c_int, d, d, d, d, d, d, d, d, d, b, d,
                                   ctypes.POINTER(ctypes.c_int)]
    lib.artic_step.restype = ctypes.c_int
    lib.artic_step.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.POINTER(_Loop),
                               ctypes.c_double, ctypes.c_int]
    # observe is called through a handle that keeps the GIL: it takes a microsecond, and
    # releasing the GIL for it would let every other thread's plant in (Dock-v0's vector
    # environment steps its plants on threads) before this one goes on.
    lib.artic_observe = ctypes.PyDLL(lib._name).artic_observe
    lib.artic_observe.restype = ctypes.c_int
    lib.artic_observe.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.POINTER(_Loop),
                                  ctypes.c_void_p]
    lib.artic_ramp_steps.restype = ctypes.c_int
    lib.artic_ramp_steps.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.POINTER(_Loop),
                                     ctypes.POINTER(_Ramp), ctypes.c_void_p, ctypes.c_void_p,
                                     ctypes.c_void_p]
    if lib.artic_ramp_size() != ctypes.sizeof(_Ramp):
        return None, ("the compiled closed loop was built from another version of artic; "
                      "reinstall artic")
    return lib, ""


@functools.cache
def _loaded() -> tuple[ctypes.CDLL | None, str]:
    return _load()


def unavailable_reason() -> str:
    """Why the compiled loop cannot run at all (not built, wrong version); empty when it can."""
    return _loaded()[1]


def step_available(plant: Plant) -> bool:
    """Whether ``plant`` can take its single steps in compiled code (:func:`why_no_step`)."""
    return not why_no_step(plant)


def why_no_step(plant: Plant) -> str:
    """Why ``plant`` cannot take its single steps in compiled code; empty when it can."""
    lib, why = _loaded()
    if lib is None:
        return why
    if plant.backend != "compiled":
        return f"the plant's backend is {plant.backend!r} (the numpy tyre callback)"
    if len(plant._servo) > MAX_SERVOS or plant.n_wheels > MAX_WHEELS:
        return (f"the compiled plant takes at most {MAX_SERVOS} steered axles and "
                f"{MAX_WHEELS} wheels")
    return ""


def available(plant: Plant) -> bool:
    """Whether ``plant`` can use the compiled loop (:func:`why_no_loop` says why not)."""
    return not why_no_loop(plant)


def why_no_loop(plant: Plant) -> str:
    """Why ``plant`` cannot use the compiled loop; empty when it can.

    The loop needs what the single step needs, and a followed speed.
    """
    why = why_no_step(plant)
    if why:
        return why
    if plant.speed_mode != "follow":
        return (f"the plant's speed mode is {plant.speed_mode!r}; the compiled loop only "
                "follows the log's speed")
    return ""


class Stepper:
    """:meth:`plant.Plant.step` (after the speed controls) and ``observe`` in compiled code.

    For a plant that Python drives one step at a time, as the synthetic
    truth's drivers do. The struct holds the plant's unwrapped headings
    (``Plant._psi`` is a view of them) and counts the steering demands
    beyond the linkage since the plant last took the count.

    Parameters
    ----------
    plant : Plant
        :func:`step_available` must be true of it.
    """

    def __init__(self, plant: Plant) -> None:
        self._lib = _loaded()[0]
        self._gather = np.zeros((0, 2), dtype=np.int32)
        self.struct = _struct(plant, 0.0, math.inf, math.inf, self._gather)
        self._s = ctypes.pointer(self.struct)
        self._m, self._d = plant.model._address, plant.data._address
        self._out = np.empty(N_OBS)
        self._out_at = self._out.ctypes.data
        # observe's arguments converted once: the harness calls it every plant step.
        self._observe_args = (ctypes.c_void_p(self._m), ctypes.c_void_p(self._d), self._s,
                              ctypes.c_void_p(self._out_at))
        self.psi = np.ctypeslib.as_array(self.struct.psi)
        """The unwrapped headings [rad], a view of the struct's."""

    def step(self, delta: float, n: int) -> int:
        """Servos at ``delta`` [rad], ``n`` MuJoCo steps and the check; a ``closedloop`` code."""
        return self._lib.artic_step(self._m, self._d, self._s, delta, n)

    def observe(self) -> np.ndarray:
        """The signals at the sensor points (``OBSERVATION`` order), a new array."""
        if self._lib.artic_observe(*self._observe_args) != DONE:
            raise RuntimeError("the compiled step refused the plant's indices")
        return self._out.copy()


class Ramp:
    """A docking run's plant steps between two controller samples, in compiled code.

    :func:`artic.validation.docking.run.drive` steps the plant ``n`` times per
    controller sample. Each step the steering wheel and the speed move one
    rate-limited step towards their targets (``min(max(target - now, -step),
    step)``), the steering map turns the wheel into the road-wheel angle, the
    plant steps (:meth:`plant.Plant.step`, the speed's ramp as its derivative) and is
    observed (:meth:`plant.Plant.observe`), and its articulation is checked against
    ``gamma_max``. :meth:`run` does the ``n`` steps in one call without the GIL,
    with the arithmetic of ``drive``'s Python loop in its order, so the signals,
    the wheel, the speed and the times are that loop's to the bit
    (``tests/test_plant_step.py``); a wheel outside its tyre file's ranges is
    named and a diverged step raises as :meth:`plant.Plant.step` does.

    Parameters
    ----------
    plant : Plant
        :func:`ramp_available` must be true of it.
    steering : Steering
        The steering map (:class:`artic.mjcf.steering.Steering`) from wheel to road wheel.
    n : int
        Plant steps per call.
    dt : float
        The plant's step [s].
    limits : tuple of float
        The largest change per plant step of the steering wheel [rad] and of the speed [m/s].
    gamma_max : float
        The articulation that stops the steps [rad].
    start : tuple of float
        The steering wheel [rad], the speed [m/s] and the time [s] now.
    """

    def __init__(self, plant: Plant, steering, n: int, dt: float,
                 limits: tuple[float, float], gamma_max: float,
                 start: tuple[float, float, float]) -> None:
        self._lib = _loaded()[0]
        self._plant = plant
        stepper = plant._stepper
        self._stepper = stepper
        r = self.struct = _Ramp()
        r.wheel, r.u, r.t = start
        r.wheel_step, r.u_step = limits
        r.offset, r.q, r.i_s = steering.delta_h_offset, steering.q, steering.i_s
        r.dt, r.gamma_max, r.n = dt, gamma_max, n
        self.targets = np.zeros((n, 2))
        """The steering wheel's [rad] and the speed's [m/s] target at each step of a call."""
        self._obs = np.zeros((n, N_OBS))
        self._log = np.zeros((n, 3))
        self._args = (ctypes.c_void_p(plant.model._address), ctypes.c_void_p(plant.data._address),
                      stepper._s, ctypes.pointer(r),
                      *(ctypes.c_void_p(a.ctypes.data) for a in (self.targets, self._obs,
                                                                 self._log)))

    @property
    def wheel(self) -> float:
        """The steering wheel now [rad]."""
        return self.struct.wheel

    @property
    def u(self) -> float:
        """The speed now [m/s]."""
        return self.struct.u

    def run(self) -> tuple[np.ndarray, np.ndarray, int]:
        """The ``n`` steps towards :attr:`targets`, or up to the one that ends the run.

        Returns
        -------
        obs : ndarray, shape (k, 13)
            The signals after each step taken (new arrays, the caller's).
        log : ndarray, shape (k, 3)
            The steering wheel [rad], the speed [m/s] and the time [s] after each.
        code : int
            :data:`DONE`; :data:`STOPPED` when the last step passed ``gamma_max``;
            :data:`DIVERGED` when the step after the last one diverged
            (:meth:`raise_diverged` raises what ``Plant.step`` raises).
        """
        plant, s, r = self._plant, self._stepper.struct, self.struct
        r.j = 0
        while True:
            s.integral = plant._integral
            code = self._lib.artic_ramp_steps(*self._args)
            plant._integral = s.integral
            if s.steer_limited:  # as Plant.step counts and warns
                first = plant.steer_limited == 0
                plant.steer_limited += s.steer_limited
                s.steer_limited = 0
                if first:
                    plant.warn_steer_limited(s.first_limit_time, s.first_limit_delta)
            if r.tyre_range:
                plant.data.userdata[3 * plant.n_wheels] = 0.0
                plant.check_tyre_ranges()
            if code == TYRE_RANGE:
                continue
            if code == BAD:
                raise RuntimeError("the compiled step refused the plant's indices")
            k = r.j
            return self._obs[:k].copy(), self._log[:k].copy(), code

    def raise_diverged(self) -> None:
        """Raise the :class:`plant.PlantError` of the diverged step :meth:`run` reported."""
        s, plant = self._stepper.struct, self._plant
        good = np.array(s.good_forces[:3 * plant.n_wheels]).reshape(-1, 3)
        plant._check(s.good_time, good, s.span)
        raise AssertionError("unreachable: a diverged step that _check accepts")


def ramp_available(plant) -> bool:
    """Whether ``plant`` can take a docking run's steps in compiled code (:class:`Ramp`).

    It needs the compiled single step switched on and a followed speed, as the
    docking runs' plant has; the runs step any other plant in Python.
    """
    return (getattr(plant, "_stepper", None) is not None and plant._compiled_step
            and plant.speed_mode == "follow")


class LoopResult(NamedTuple):
    """What one log gives: as :func:`artic.validation.harness.loop.run_inputs`, and raw extras."""

    obs: np.ndarray
    delta: np.ndarray
    delta_fb: np.ndarray
    saturated: np.ndarray
    n_done: int
    raw: np.ndarray | None


def _ptr(a: np.ndarray, kind):
    return a.ctypes.data_as(ctypes.POINTER(kind))


def run(plant: Plant, args: LoopArgs, extras: bool = False) -> LoopResult:
    """Drive ``plant`` (already reset) through a log's inputs in compiled code.

    Parameters
    ----------
    plant : Plant
        Reset to the log's first sample; :func:`available` must be empty.
    args : LoopArgs
        The log's steps [s], per-sample inputs (the feedback's weight from
        :func:`artic.validation.harness.reversing.feedback_weight`), the feedback
        gain K [rad/rad], the road-wheel limit and the jackknife limit [rad].
    extras : bool
        Gather the raw rows of :meth:`plant.Plant.extras` per sample.

    Returns
    -------
    LoopResult
        Rows after ``n_done`` stay NaN.

    Raises
    ------
    plant.PlantError
        When the simulation diverged, naming the time and the wheel.
    """
    why = why_no_loop(plant)
    if why:
        raise RuntimeError(f"the compiled closed loop is unavailable: {why}")
    lib = _loaded()[0]
    dt, delta_c, u1, u1_dot, gamma_meas, weight, gain, delta_max, gamma_max = args
    n = int(np.asarray(delta_c).size)
    f64 = [np.ascontiguousarray(a, dtype=float)
           for a in (delta_c, u1, u1_dot, gamma_meas, weight)]
    dt_full = np.zeros(n)
    dt_full[:min(n, np.size(dt))] = np.asarray(dt, dtype=float)[:n]
    obs = np.full((n, N_OBS), np.nan)
    delta, delta_fb = np.full(n, np.nan), np.full(n, np.nan)
    sat = np.zeros(n, dtype=np.uint8)
    gather = plant.extras_gather() if extras else np.zeros((0, 2), dtype=np.int32)
    gather = np.ascontiguousarray(gather, dtype=np.int32)
    raw = np.full((n, len(gather)), np.nan) if extras else np.zeros((1, 1))
    s = _struct(plant, gain, delta_max, gamma_max, gather)
    done = ctypes.c_int(0)
    limited_before = plant.steer_limited
    m, d = plant.model, plant.data
    while True:
        code = lib.artic_run_loop(
            m._address, d._address, ctypes.byref(s), n, _ptr(dt_full, ctypes.c_double),
            *(_ptr(a, ctypes.c_double) for a in f64),
            _ptr(obs, ctypes.c_double), _ptr(delta, ctypes.c_double),
            _ptr(delta_fb, ctypes.c_double), _ptr(sat, ctypes.c_ubyte),
            _ptr(raw, ctypes.c_double), ctypes.byref(done))
        plant._psi[:] = s.psi[:]
        plant._integral = s.integral
        plant.steer_limited = s.steer_limited
        if limited_before == 0 and s.steer_limited > 0:
            limited_before = s.steer_limited
            plant.warn_steer_limited(s.first_limit_time, s.first_limit_delta)
        if code == TYRE_RANGE:
            d.userdata[3 * plant.n_wheels] = 0.0
            plant.check_tyre_ranges()
            continue
        if code == DIVERGED:
            good = np.array(s.good_forces[:3 * plant.n_wheels]).reshape(-1, 3)
            plant._check(s.good_time, good, s.span)
            raise AssertionError("unreachable: a diverged step that _check accepts")
        if code == BAD:
            raise RuntimeError("the compiled closed loop refused the plant's indices")
        break
    return LoopResult(obs, delta, delta_fb, sat.astype(bool), int(done.value),
                      raw if extras else None)


def _struct(plant: Plant, gain: float, delta_max: float, gamma_max: float,
            gather: np.ndarray) -> _Loop:
    m = plant.model
    s = _Loop()
    s.tractor_body, s.trailer_body = plant._tractor, plant._trailer
    s.sensor_site[:] = [int(x) for x in plant._sensor]
    s.hitch_qpos = int(m.jnt_qposadr[plant._hitch_yaw])
    s.n_servo = len(plant._servo)
    for i, a in enumerate(plant._servo):
        s.servo[i] = int(a)
    s.servo_lo, s.servo_hi = (float(x) for x in plant._servo_range)
    s.follower = int(plant._follower)
    s.follower_kv = plant._follower_kv
    s.mass_eff = plant.mass_eff
    s.rr_coef = plant.tyre.QSY1 * plant.mass * G  # as Plant._control groups it
    s.follow_ki = FOLLOW_KI
    s.sensor_yaw[:] = [float(x) for x in plant._sensor_yaw]
    s.n_wheels = plant.n_wheels
    s.gain, s.delta_max, s.gamma_max = float(gain), float(delta_max), float(gamma_max)
    s.n_gather = len(gather)
    s.gather = gather.ctypes.data_as(ctypes.POINTER(ctypes.c_int))
    s._keep = gather  # the array must outlive the struct's pointer
    s.k = 0
    s.psi[:] = [float(x) for x in plant._psi]
    s.integral = plant._integral
    s.steer_limited = plant.steer_limited
    s.first_limit_time = s.first_limit_delta = math.nan
    return s

