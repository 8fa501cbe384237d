"""One docking run: a controller drives the MuJoCo plant onto the dock, and the benchmark.

The loop (:func:`drive`), on the plant built from the vehicle file or, with
``truth``, on the synthetic campaign's truth (:func:`truth_yard`):

1. the start of the scenario's seeded distribution places the plant at rest;
2. the planner makes a path (a failure to plan is a failed run);
3. every :data:`DT` (10 Hz) the controller gets the sensors' signals, with
   the synthetic campaign's noise and, on the truth, its semitrailer unit's
   clock skew (:mod:`artic.validation.docking.sensing`), and returns a
   steering-wheel angle and a speed; with ``sensor_set`` ``"tractor"`` or
   ``"camera"`` the semitrailer's signals are the estimator's, from the
   tractor's sensors and an articulation sensor on the tractor;
4. the plant steps every :data:`PLANT_DT`. Between the controller and the
   plant sit the actuators: the steering wheel turns at most
   :data:`STEER_RATE`; the speed is the yard's, at most :data:`SPEED_MAX`
   either way, and changes at most :data:`ACCEL_MAX` (the docking driver's
   pedal); the plant's steering map (``[steering.mbd]``) turns the wheel
   into the road-wheel angle;
5. after every plant step the run checks the plant's true articulation
   against the vehicle's ``gamma_max`` (jackknife), and after every
   controller period the outlines of those steps against the obstacles
   (collision). Either ends the run as a failure at once, as does a
   timeout, a plant that diverges, or a controller that raises or returns a
   non-finite command;
6. when the controller says it is done, the speed is brought to zero and the
   run is scored where the plant comes to rest.

A failure is a row of the table with its reason, never an exception: a
controller's exception or ``sys.exit`` in ``reset`` or ``command`` fails the
run, and so does a controller slower than the sample period for more than
:data:`REALTIME_LATE` of its commands (the real-time criterion; ``realtime=False``
only counts them). :func:`benchmark` runs scenarios x vehicles x seeds on
supervised worker processes (:mod:`artic.validation.docking.supervise`: a
controller that ends its process or hangs fails its run, and the others go on)
and returns the rows in a fixed order: the same arguments give the same rows,
except the compute times.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import time
import traceback
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from artic.mjcf.errors import UserError, one_line
from artic.mjcf.interface import OBS_INDEX, InitialState
from artic.mjcf.vehicle import load_vehicle
from artic.plant import Plant, PlantWarning, closedloop
from artic.plant.plant import PlantError
from artic.validation.docking.conditions import ActuatorDelay, road
from artic.validation.docking.controllers import Command, Observation, Task, load
from artic.validation.docking.geometry import Frames, box_array
from artic.validation.docking.identify import WheelbaseIdentifier
from artic.validation.docking.planner import HybridAStar, Plan, PlanningError
from artic.validation.docking.scenarios import Scenario, Start, Yard, scenario
from artic.validation.docking.scores import COLUMNS, estimate_scores, score, tiers
from artic.validation.docking.sensing import (
    EstimatedStream,
    SensorStream,
    articulation_model,
    sensor_set,
)
from artic.validation.docking.spec import STEER_RATE, Conditions, DockRun, split_options
from artic.validation.docking.supervise import calling, supervised
from artic.validation.docking.variants import (
    Draw,
    check_trailer,
    draw_semitrailer,
    effective_wheelbase,
)
from artic.validation.logs.runfile import new_frame
from artic.validation.models import build, driven
from artic.validation.plumbing.progress import Counter
from artic.validation.synthetic.sensors import SensorModel

DT = 0.1
"""The controllers' sample period [s]: 10 Hz."""

PLANT_DT = 0.01
"""The plant's step [s], as the synthetic campaign drives it."""

SPEED_MAX = 6.0 / 3.6
"""The yard's speed limit either way [m/s]: 6 km/h."""

SPEED = 4.0 / 3.6
"""Cruising speed in reverse that controllers are told [m/s]: 4 km/h, inside the
3-6 km/h of yard practice."""

ACCEL_MAX = 0.5
"""Largest change of speed [m/s^2]: the docking driver's pedal."""


SETTLE = 3.0
"""Time the run waits for the plant to stop after the controller is done [s]."""

REALTIME_LATE = 0.05
"""Share of a run's commands (its first left out: a first call may compile or warm caches)
that may take longer than the sample period :data:`DT` before the run fails the real-time
criterion. A controller on a real truck that misses its period more often than once in
twenty leaves the actuators holding stale commands for whole periods."""

REALTIME_GRACE = 3
"""Late commands forgiven whatever the share: a loaded machine's scheduling delays are
not the controller's."""

SENSOR_STREAM = 1
"""Third word of a run's random seed ``(seed, scenario number, SENSOR_STREAM)``: the
sensors' noise is drawn apart from the start, and is the same for every controller."""

ARTICULATION_STREAM = 2
"""Third word of the seed of a tractor-only set's articulation sensor (``--sensors tractor``
or ``camera``): drawn apart from :data:`SENSOR_STREAM`, so that ``full``'s draws, and the
tractor's channels of every set, stay the same."""

TRAILER_STREAM = 3
"""Third word of the seed of ``--trailer unknown``'s semitrailer, ``(seed, scenario number,
TRAILER_STREAM)``: drawn apart from the start and the sensors, so that those stay what
they are with the file's semitrailer, and the same for every controller."""


RECORDING_ERROR = "recording_error"
"""Key of a run's row whose recording could not be written (not a column of ``dock.csv``):
where, and why. The run keeps its scores; ``artic dock`` names it and exits 1."""

@dataclass
class Trace:
    """What happened in one run, for the scores and the recording.

    The plant's arrays are per plant step; the controller's per sample.
    """

    t: list[float] = field(default_factory=list)
    true: list[np.ndarray] = field(default_factory=list)
    steering_wheel: list[float] = field(default_factory=list)
    speed: list[float] = field(default_factory=list)
    t_ctrl: list[float] = field(default_factory=list)
    measured: list[np.ndarray] = field(default_factory=list)
    commands: list[tuple[float, float]] = field(default_factory=list)
    solve_ms: list[float] = field(default_factory=list)
    horizons: list[np.ndarray | None] = field(default_factory=list)
    references: list[np.ndarray | None] = field(default_factory=list)
    extras: list[tuple[int, np.ndarray]] = field(default_factory=list)
    """The plant's :meth:`~artic.plant.Plant.extras` at each controller sample, by plant step
    (only when the run is recorded)."""
    extra_columns: tuple[str, ...] = ()
    seen_at: list[int] = field(default_factory=list)
    """The plant step of each controller sample: the truth what the controller saw is
    compared with (:func:`artic.validation.docking.scores.estimate_scores`)."""
    failure: str = ""
    done: bool = False
    late: int = 0
    """Commands (after the first) that took longer than the sample period :data:`DT`."""

    def arrays(self) -> dict[str, np.ndarray]:
        """The plant's and the controller's series as arrays."""
        return {"t": np.asarray(self.t), "true": np.asarray(self.true).reshape(-1, 13),
                "steering_wheel": np.asarray(self.steering_wheel),
                "speed": np.asarray(self.speed), "t_ctrl": np.asarray(self.t_ctrl),
                "measured": np.asarray(self.measured).reshape(-1, 13),
                "commands": np.asarray(self.commands).reshape(-1, 2),
                "solve_ms": np.asarray(self.solve_ms)}


@dataclass
class Result:
    """One run: its scores row, and what the recording draws."""

    row: dict
    trace: Trace
    plan: Plan | None
    yard: Yard
    start: Start


def _fail(trace: Trace, reason: str) -> None:
    if not trace.failure:
        trace.failure = reason


def drive(scen: Scenario, vehicle_name: str, controller: str | type, seed: int,
          **options) -> Result:
    """One docking run on the plant: :func:`dock` with its keywords split into objects.

    ``options`` are :class:`~artic.validation.docking.spec.DockRun`'s and
    :class:`~artic.validation.docking.spec.Conditions`' fields
    (:func:`~artic.validation.docking.spec.split_options`), as below.

    Parameters
    ----------
    scen : Scenario
        The yard and the start distribution.
    vehicle_name : str
        Preset name or vehicle file.
    controller : str or type
        ``--controller``'s value (see :func:`artic.validation.docking.controllers.load`)
        or the class itself.
    seed : int
        Which start of the distribution (and which noise).
    planner : Planner, optional
        :class:`~artic.validation.docking.planner.HybridAStar` by default.
    sensors : SensorModel, optional
        The campaign's measurement chain by default; with ``truth``, as the
        truth carries it (its semitrailer unit's clock skew,
        :func:`artic.validation.synthetic.generate.measurement_chain`).
    timeout : float, optional
        Longest run [s]; the scenario's by default.
    yard_model : str
        What the controller drives: ``"mbd"``, the plant (the benchmark), or
        ``"kin"`` or ``"stm"`` (from :mod:`artic.validation.models`), for a quick
        look while developing a controller.
    record : Path, optional
        Write the run's Rerun recording there (:func:`write_recording`).
    truth : int, optional
        Drive the synthetic campaign's truth of this seed instead of the
        plant built from the vehicle file (:func:`truth_yard`): the
        controller and the planner still know only the vehicle file.
    realtime : bool
        Fail the run as soon as more than :data:`REALTIME_LATE` of its
        commands (and :data:`REALTIME_GRACE`) took longer than :data:`DT`;
        without it the late commands are only counted (``late_commands``).
    sensor_set : str
        What the controller sees (:data:`artic.validation.docking.sensing.SENSOR_SETS`):
        ``"full"``, the RTK/INS of both units (``sensors``' measurement chain);
        ``"tractor"`` or ``"camera"``, the tractor's channels of the same chain
        and a hitch encoder or a camera on the tractor, the semitrailer's
        pose and the articulation from the estimator
        (:class:`artic.validation.docking.sensing.EstimatedStream`).
    articulation_noise_deg : float, optional
        The encoder's or camera's noise RMS [deg] instead of its model's
        (:func:`artic.validation.docking.sensing.articulation_model`); not for ``"full"``.
    trailer : str or Draw
        ``"nominal"``: the plant's semitrailer is the vehicle file's;
        a :class:`~artic.validation.docking.variants.Draw`: that one, for every start
        (a sweep's level, e.g. ``Draw(length_error_m=0.5)``; ``trailer`` is
        ``"given"`` in the row); ``"unknown"``: drawn for this start
        (:func:`artic.validation.docking.variants.draw_semitrailer`, from
        ``(seed, scenario number, TRAILER_STREAM)``) while the planner and the
        controller know the file's. Either way the run identifies the
        semitrailer's effective wheelbase from what the controller observes
        (:class:`~artic.validation.docking.identify.WheelbaseIdentifier`) and
        reports it against the plant's (``l2_identified_m``, ``l2_true_m``).
    delay : float
        The actuators' dead time [s], a whole number of :data:`PLANT_DT`
        (:class:`artic.validation.docking.conditions.ActuatorDelay`); none by default.
    steer_rate : float
        The steering actuator's largest wheel rate [rad/s]; :data:`STEER_RATE` by default.
        The controller is told :data:`STEER_RATE` whatever it is.
    friction : float
        Factor on the tyres' friction [-] (:func:`artic.validation.docking.conditions.road`):
        1.0 dry, about 0.3 packed snow. The plant only (``yard_model="mbd"``, no ``truth``).
    grade : float
        The yard's slope along the dock's approach [%], positive when it falls towards
        the dock (:func:`artic.validation.docking.conditions.road`). The plant only.

    Returns
    -------
    Result
        Its :attr:`Result.row` holds the scores (:func:`artic.validation.docking.scores.score`).
    """
    run, conditions = split_options(options)
    return dock(DockRun(scen, vehicle_name, controller, seed, **run), conditions)


def dock(run: DockRun, conditions: Conditions | None = None) -> Result:
    """One docking run on the plant: ``run`` under ``conditions`` (see :func:`drive`).

    ``conditions`` are the benchmark's (:class:`~artic.validation.docking.spec.Conditions`'
    defaults) if not given.
    """
    scen, vehicle_name, controller, seed = run.scenario, run.vehicle, run.controller, run.seed
    planner, timeout, yard_model = run.planner, run.timeout, run.yard_model
    record = run.record
    c = conditions = conditions or Conditions()
    sensors, sensor_set, articulation_noise_deg = c.sensors, c.sensor_set, \
        c.articulation_noise_deg
    truth, trailer, steer_rate = c.truth, c.trailer, c.steer_rate
    friction, grade = c.friction, c.grade
    sensor_set_ = _sensor_set(sensor_set, articulation_noise_deg)
    vehicle = load_vehicle(vehicle_name)
    cls = load(controller) if isinstance(controller, str) else controller
    cname = controller if isinstance(controller, str) else f"{cls.__module__}:{cls.__name__}"
    yard = scen.yard(vehicle)
    start = scen.start(seed)
    plant_vehicle, actuation = vehicle, None
    sensors = sensors or SensorModel()
    if truth is not None:
        from artic.validation.synthetic.generate import measurement_chain
        from artic.validation.synthetic.truth import truth_configuration

        plant_vehicle, actuation = truth_yard(vehicle, truth, scen.number, seed)
        sensors = measurement_chain(sensors, truth_configuration(truth))
    draw = Draw()
    if isinstance(trailer, Draw) or check_trailer(trailer) == "unknown":
        if truth is not None:
            raise UserError("--trailer unknown: the synthetic truth (--truth) has its own "
                            "semitrailer; leave one of them out")
        if isinstance(trailer, Draw):  # one given semitrailer, e.g. a sweep's level
            draw, plant_vehicle, trailer = trailer, trailer.vary(vehicle), "given"
        else:
            draw, plant_vehicle = draw_semitrailer(
                vehicle, np.random.default_rng([seed, scen.number, TRAILER_STREAM]))
    identifier = WheelbaseIdentifier(vehicle)
    if friction != 1.0 or grade != 0.0:
        if truth is not None or yard_model != "mbd":
            raise UserError("friction and grade act on the plant built from the vehicle file "
                            "only; leave --truth out (and drive yard_model 'mbd')")
        plant_vehicle = road(plant_vehicle, friction, grade)
    if not (math.isfinite(steer_rate) and steer_rate > 0.0):
        raise UserError(f"steer_rate {steer_rate:g} rad/s: the steering actuator's rate limit "
                        "must be positive")
    frames = Frames.of(plant_vehicle)  # the true geometry: placing, collisions, scores
    planner = planner or HybridAStar()
    timeout = scen.timeout if timeout is None else float(timeout)
    if not (math.isfinite(timeout) and timeout > 0.0):
        raise UserError(f"timeout {timeout:g}: a run's time limit must be a positive number "
                        "of seconds")
    trace = Trace()
    t0 = time.perf_counter()
    plan: Plan | None = None
    try:
        plan = planner.plan(yard, vehicle, start)
    except PlanningError as exc:
        _fail(trace, f"no plan: {exc}")
    plan_ms = 1e3 * (time.perf_counter() - t0)
    if plan is not None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlantWarning)  # the lock is the actuator's limit
            _closed_loop(trace, _Loop(vehicle, yard, start, frames, cls, plan, scen.number,
                                      plant_vehicle, actuation, identifier),
                         dataclasses.replace(run, timeout=timeout, record=record),
                         dataclasses.replace(conditions, sensors=sensors,
                                             sensor_set=sensor_set_))
    row = {"scenario": scen.name, "vehicle": vehicle.name, "controller": cname,
           "plant": yard_model if truth is None else f"truth-{truth}", "seed": seed,
           **score(trace, yard, plant_vehicle, frames, start),
           "late_commands": trace.late,
           "plan_ms": plan_ms, "plan_expansions": plan.expansions if plan else 0,
           "plan_direction_changes": plan.direction_changes if plan else 0,
           "plan_length_m": plan.length if plan else math.nan,
           "sensors": sensor_set_, **estimate_scores(trace, Frames.of(vehicle), frames),
           "trailer": trailer, "l2_nominal_m": effective_wheelbase(vehicle),
           "l2_true_m": effective_wheelbase(plant_vehicle),
           "l2_identified_m": identifier.L2 if identifier.updates else math.nan,
           "l2_updates": identifier.updates, **draw.row()}
    result = Result(row, trace, plan, yard, start)
    if record is not None:
        try:
            write_recording(result, plant_vehicle, Path(record), seen_vehicle=vehicle)
        except (MemoryError, RecursionError):
            raise
        except Exception as exc:  # noqa: BLE001 - an output error, not the run's
            # A full disk measures the disk, not the controller: the run keeps its scores,
            # and the command reports the recording (RECORDING_ERROR) and exits non-zero.
            row[RECORDING_ERROR] = f"{record}: {one_line(_named(exc))}"
    return result


@dataclass(frozen=True)
class _Loop:
    """What :func:`dock` prepared for the closed loop: the world the run starts in."""

    vehicle: object
    yard: Yard
    start: Start
    frames: Frames
    cls: type
    plan: Plan
    number: int
    plant_vehicle: object = None
    actuation: Callable | None = None
    identifier: WheelbaseIdentifier | None = None


def _closed_loop(trace: Trace, loop: _Loop, run: DockRun, conditions: Conditions) -> None:
    """The run's loop (steps 3-6 of the module's), ``run``'s timeout and sensors resolved."""
    vehicle, yard, start, frames, cls = loop.vehicle, loop.yard, loop.start, loop.frames, \
        loop.cls
    plan, number, identifier, actuation = loop.plan, loop.number, loop.identifier, \
        loop.actuation
    seed, timeout, yard_model, realtime = run.seed, run.timeout, run.yard_model, run.realtime
    extras = run.record is not None
    sensors, sensor_set = conditions.sensors, conditions.sensor_set
    articulation_noise_deg = conditions.articulation_noise_deg
    delay, steer_rate = conditions.delay, conditions.steer_rate
    plant_vehicle = loop.plant_vehicle or vehicle
    n_sub = round(DT / PLANT_DT)
    n_ctrl = int(round(timeout / DT))
    stream = SensorStream(sensors, np.random.default_rng([seed, number, SENSOR_STREAM]),
                          n_ctrl + 1, DT, PLANT_DT)
    if sensor_set != "full":  # the tractor's channels of the same stream, and an estimator
        stream = EstimatedStream(
            stream, articulation_model(sensor_set, articulation_noise_deg),
            np.random.default_rng([seed, number, ARTICULATION_STREAM]), n_ctrl + 1, DT,
            Frames.of(vehicle), plant_vehicle.sensor1_yaw - plant_vehicle.sensor2_yaw)
    mbd = plant_vehicle.steering_for(yard_model)
    boxes = box_array(yard.obstacles)
    x0 = frames.kin_from_rear(start.x_r, start.y_r, start.psi_2, start.gamma)
    xs, ys = frames.tractor_sensor_of_kin(x0)
    try:
        with calling("reset()"):
            ctrl = cls()
            ctrl.reset(Task(vehicle, yard, plan, DT, SPEED, SPEED_MAX, ACCEL_MAX, STEER_RATE))
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # noqa: BLE001 - a user's controller (sys.exit too): a failed run
        _fail(trace, f"controller error: {one_line(_named(exc))}")
        return
    if actuation is not None:  # the truth behind its steering column and pedals
        plant, yard_plant = actuation()
        mbd = yard_plant.steering
    else:
        plant = (Plant(plant_vehicle) if yard_model == "mbd"
                 else driven(build(yard_model, plant_vehicle)))
        yard_plant = None
    with contextlib.closing(plant):
        (yard_plant or plant).reset(InitialState(xs, ys, float(x0[2]), float(x0[3]), u1=0.0))
        wheel = float(mbd.steering_wheel(0.0))
        u = 0.0
        trace.t.append(0.0)
        trace.true.append(plant.observe())
        trace.steering_wheel.append(wheel)
        trace.speed.append(u)
        settle_until = None
        cmd = Command(wheel, 0.0)
        actuators = ActuatorDelay(delay, PLANT_DT, (wheel, 0.0))
        # Bound once: the plant steps 100 times a second of the run, and Python looks
        # each name up every time.
        wheel_step, u_step, gamma_max = steer_rate * PLANT_DT, ACCEL_MAX * PLANT_DT, \
            plant_vehicle.gamma_max
        observe, road_wheel = plant.observe, mbd.road_wheel
        t_log, true_log, wheel_log, speed_log = trace.t, trace.true, trace.steering_wheel, \
            trace.speed
        # The plant's steps of a sample in one compiled call where the plant allows it
        # (the same arithmetic, to the bit); the loop below in Python otherwise.
        ramp = (closedloop.Ramp(plant, mbd, n_sub, PLANT_DT, (wheel_step, u_step), gamma_max,
                                (wheel, u, 0.0))
                if yard_plant is None and closedloop.ramp_available(plant) else None)
        for k in range(n_ctrl):
            now = k * DT
            if settle_until is None:
                signals, dh = stream.observe(k, trace.true, trace.steering_wheel)
                obs = Observation(now, signals, dh)
                if identifier is not None:
                    identifier.update(now, signals)
                tc = time.perf_counter()
                try:
                    with calling("command()", now):
                        cmd = ctrl.command(obs)
                    solve_ms = 1e3 * (time.perf_counter() - tc)
                    target = (float(cmd.delta_h), float(cmd.u1), bool(cmd.done))
                    intent = (_path(cmd, "horizon"), _path(cmd, "reference"))
                except KeyboardInterrupt:
                    raise
                except BaseException as exc:  # noqa: BLE001 - the user's code (sys.exit too)
                    _fail(trace, f"controller error: {one_line(_named(exc))} "
                                 f"({_where(exc)})")
                    return
                trace.solve_ms.append(solve_ms)
                if k > 0 and solve_ms > 1e3 * DT:
                    trace.late += 1
                    if realtime and trace.late > max(REALTIME_GRACE, REALTIME_LATE * k):
                        late = np.asarray(trace.solve_ms[1:])
                        _fail(trace, f"not real-time: {trace.late} of {k} commands took "
                                     f"longer than the {1e3 * DT:g} ms sample period "
                                     f"(median {np.median(late):.0f} ms) by t = {now:.1f} s; "
                                     "--no-realtime judges the docking alone")
                        return
                if not (math.isfinite(target[0]) and math.isfinite(target[1])):
                    _fail(trace, f"controller error: non-finite command {target[:2]} at "
                                 f"t = {now:.1f} s")
                    return
                trace.t_ctrl.append(now)
                trace.measured.append(signals)
                trace.seen_at.append(len(trace.true) - 1)
                trace.commands.append(target[:2])
                trace.horizons.append(intent[0])
                trace.references.append(intent[1])
                if extras and hasattr(plant, "extras"):
                    trace.extras.append((len(trace.t) - 1, plant.extras()))
                    trace.extra_columns = plant.extra_columns
                if target[2]:
                    trace.done = True
                    settle_until = now + SETTLE
                u_target = 0.0 if settle_until is not None else \
                    min(max(target[1], -SPEED_MAX), SPEED_MAX)
                actuators.command(k * n_sub, (target[0], u_target))
            elif now >= settle_until or (abs(u) < 1e-9 and abs(trace.true[-1][3]) < 0.01):
                return
            if ramp is not None:  # the sample's plant steps in one compiled call
                actuators.fill(k * n_sub, ramp.targets)
                steps = _compiled_steps(trace, ramp, plant, gamma_max)
                if steps is None:
                    return
                u = ramp.u  # the settling reads it
            else:
                for j in range(n_sub):
                    wheel_target, u_target = actuators.at(k * n_sub + j)
                    wheel += min(max(wheel_target - wheel, -wheel_step), wheel_step)
                    u_next = u + min(max(u_target - u, -u_step), u_step)
                    try:
                        if yard_plant is not None:
                            yard_plant.step_steering_wheel(PLANT_DT, wheel, u,
                                                           (u_next - u) / PLANT_DT)
                        else:
                            plant.step(PLANT_DT, float(road_wheel(wheel)), u,
                                       (u_next - u) / PLANT_DT)
                    except (PlantError, FloatingPointError) as exc:  # the plant or the truth
                        _fail(trace, f"plant diverged: {one_line(_named(exc))}")
                        return
                    u = u_next
                    t_log.append(t_log[-1] + PLANT_DT)
                    true_log.append(observe())
                    wheel_log.append(wheel)
                    speed_log.append(u)
                    if abs(plant.gamma) > gamma_max:
                        _jackknife(trace, plant, gamma_max)
                        return
                steps = np.asarray(true_log[-n_sub:])
            i, j, unit = frames.first_hit_of_signals(steps, boxes)
            if i >= 0:
                _fail(trace, f"collision: {('tractor', 'semitrailer')[unit]} hit "
                             f"{yard.obstacles[j].name} at t = {trace.t[-n_sub + i]:.2f} s")
                return
        if settle_until is None:
            _fail(trace, f"timeout: not docked after {timeout:.0f} s")


def _jackknife(trace: Trace, plant, gamma_max: float) -> None:
    """Fail the run: the plant's articulation is past ``gamma_max`` [rad] now."""
    _fail(trace, f"jackknife: |gamma| {math.degrees(abs(plant.gamma)):.1f} deg "
                 f"beyond {math.degrees(gamma_max):.1f} deg at t = {trace.t[-1]:.2f} s")


def _compiled_steps(trace: Trace, ramp: closedloop.Ramp, plant,
                    gamma_max: float) -> np.ndarray | None:
    """One sample's plant steps in one compiled call, logged to ``trace``.

    The steps towards ``ramp.targets``; their signals, rows ``(n, 13)``, or ``None`` when
    the run failed in them (a diverged plant, a jackknife), the steps before logged.
    """
    rows, log, code = ramp.run()
    trace.true.extend(rows)
    trace.steering_wheel.extend(log[:, 0].tolist())
    trace.speed.extend(log[:, 1].tolist())
    trace.t.extend(log[:, 2].tolist())
    if code == closedloop.DIVERGED:
        try:
            ramp.raise_diverged()
        except PlantError as exc:
            _fail(trace, f"plant diverged: {one_line(_named(exc))}")
            return None
    if code == closedloop.STOPPED:
        _jackknife(trace, plant, gamma_max)
        return None
    return rows


def _sensor_set(name: str, articulation_noise_deg: float | None) -> str:
    """``drive``'s sensor set, checked.

    One line for a set it does not know, or for a noise override that has no
    articulation sensor to apply to.
    """
    name = sensor_set(name)
    if articulation_noise_deg is not None:
        if name == "full":
            raise UserError("articulation noise: the full set measures the articulation by "
                            "the two units' headings; give it with the tractor or camera "
                            "sensor set")
        articulation_model(name, articulation_noise_deg)
    return name


def _path(cmd, name: str) -> np.ndarray | None:
    """A command's ``horizon`` or ``reference`` as rows ``(x, y)``; ``None`` if it gave none.

    A command class of the user's own may lack the field. A malformed one
    raises :class:`ValueError` naming the field and what it must be (the run
    fails with it, as for any controller error).
    """
    value = getattr(cmd, name, None)
    if value is None:
        return None
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        a = None
    if a is None or a.ndim != 2 or a.shape[0] < 1 or a.shape[1] < 2 \
            or not np.all(np.isfinite(a[:, :2])):
        what = "not numbers" if a is None else f"shape {a.shape}" + (
            "" if a.ndim != 2 or np.all(np.isfinite(a)) else " with non-finite values")
        raise UserError(f"Command.{name} must be finite rows (x, y) [m], shape (n, 2), or "
                         f"None; got {type(value).__name__}, {what}")
    return a[:, :2]


def truth_yard(vehicle, truth_seed: int, number: int, seed: int) -> tuple:
    """The synthetic campaign's truth for a run, and how to build and drive it.

    The default truth of ``truth_seed``
    (:func:`artic.validation.synthetic.truth.truth_configuration`) for the
    vehicle's load condition, on a yard sloped as one of the campaign's
    manoeuvres is (drawn from ``(truth_seed, number * 1000 + seed)``), built
    and driven as :func:`artic.validation.synthetic.generate.simulate_manoeuvre`
    does: its own model (:func:`artic.validation.synthetic.truthplant.truth_model`),
    the steering wheel through its column and steering map, the speed by a
    driver on the pedals (:mod:`artic.validation.synthetic.actuation`).

    Returns
    -------
    vehicle : Vehicle
        The truth's parameters.
    build : callable
        ``build()`` returns the truth's model (to close after the run) and the
        actuation that drives it (``step_steering_wheel``, ``reset``).

    Raises
    ------
    ValueError
        For a vehicle other than the gosar2022 presets, the only ones with a truth.
    """
    from artic.validation.synthetic.actuation import PedalDriver, SteeringColumn
    from artic.validation.synthetic.truth import slope, truth_configuration, truth_vehicle
    from artic.validation.synthetic.truthplant import truth_actuation, truth_model

    load = {"gosar2022-unloaded": "unloaded", "gosar2022-loaded": "loaded"}.get(vehicle.name)
    if load is None:
        raise UserError(f"--truth: the synthetic truth exists for gosar2022-unloaded and "
                         f"gosar2022-loaded only, not {vehicle.name}; leave --truth out for it")
    truth = truth_configuration(truth_seed)
    vt = truth_vehicle(load, truth, truth_seed, slope(truth_seed, number * 1000 + seed, truth))

    def build():
        steering = vt.steering_for("mbd")
        # The independent truth's play is in its model's column; only the drift is here.
        play = 0.0 if truth["kind"] == "independent" else truth.get("backlash", 0.0)
        column = SteeringColumn(play, truth.get("drift_rate", 0.0))
        pedals = PedalDriver(vt.m1 + vt.m2, delay=truth["driver_delay"],
                             gain=truth["driver_gain"])
        model = truth_model(vt, truth, "pedals")
        return model, truth_actuation(model, steering, column, pedals)

    return vt, build


def write_recording(result: Result, vehicle, path: Path, seen_vehicle=None) -> Path:
    """The run's Rerun recording (:func:`artic.validation.review.recording.record_docking`).

    The yard and its obstacles, the plan, the plant drawn from its bodies at
    every controller sample, its paths and swept envelope, what the
    controller intended at every sample (its predicted horizon and the
    plan's points it tracked, ``Command.horizon`` and ``Command.reference``),
    the steering wheel, speed and articulation, and the scores. What the
    controller saw at every sample (the measured signals with ``--sensors full``,
    the estimator's otherwise) is drawn beside the plant: the articulation and the
    semitrailer's rear where the geometry of ``seen_vehicle`` (the vehicle file the
    controller knows; ``vehicle`` if not given) places it.
    """
    from artic.validation.docking.scores import rear_point
    from artic.validation.review.recording import DockIntent, DockScene, record_docking

    tr = result.trace
    a = tr.arrays()
    frame = new_frame(a["t"], a["steering_wheel"], a["true"])
    if tr.extras:
        rows = np.array([i for i, _ in tr.extras])
        values = np.full((len(frame), len(tr.extras[0][1])), np.nan)
        values[rows] = np.array([v for _, v in tr.extras])
        names = tr.extra_columns
        frame = pd.concat([frame, pd.DataFrame(values, columns=list(names))], axis=1)
    fr = Frames.of(vehicle)
    plan = []
    if result.plan is not None:
        for seg in result.plan.segments:
            plan.append(fr.trailer_axle(seg.states)[:, :2] if seg.direction < 0
                        else seg.states[:, :2])
    horizons = list(zip(tr.t_ctrl, tr.horizons, strict=True))
    references = list(zip(tr.t_ctrl, tr.references, strict=True))
    m = a["measured"]
    seen = None
    if len(m):
        seen = (a["t_ctrl"], m[:, OBS_INDEX["gamma"]],
                rear_point(Frames.of(seen_vehicle or vehicle), m))
    row = result.row
    name = run_name(row["scenario"], row["vehicle"], row["controller"], row["seed"])
    obstacles = [(b.name, b.x_min, b.x_max, b.y_min, b.y_max) for b in result.yard.obstacles]
    scene = DockScene(obstacles, result.yard.doors, (result.yard.x_dock, result.yard.y_dock),
                      plan)
    return record_docking(path, name, frame, vehicle, scene,
                          DockIntent(horizons, references, seen), scores_text(row))


def scores_text(row: dict) -> str:
    """A run's scores as Markdown, for its recording."""
    head = "docked" if row["success"] else f"failed: {row['failure']}"
    lines = [f"# {row['scenario']}, {row['vehicle']}, {row['controller']}, seed {row['seed']}",
             "", head, "", "| score | value |", "|---|---|"]
    for key, unit, scale in (("lateral_error_m", "cm", 100.0),
                             ("longitudinal_error_m", "cm", 100.0),
                             ("heading_error_deg", "deg", 1.0), ("max_gamma_deg", "deg", 1.0),
                             ("direction_changes", "", 1.0), ("time_s", "s", 1.0),
                             ("path_length_m", "m", 1.0), ("swept_width_m", "m", 1.0),
                             ("solve_ms_p50", "ms", 1.0), ("solve_ms_p99", "ms", 1.0)):
        v = row.get(key, math.nan)
        lines.append(f"| {key} | {scale * float(v):.3g} {unit} |")
    return "\n".join(lines)


def _safe(text: str) -> str:
    """``text`` as a file-name part: letters, digits, dot, dash and underscore."""
    return "".join(c if c.isalnum() or c in "._-" else "_" for c in str(text))


def _named(exc: BaseException) -> str:
    """``exc``'s type and message, as a run's failure names a controller's or plant's error."""
    return f"{type(exc).__name__}: {exc}"


def _where(exc: BaseException) -> str:
    tb = traceback.extract_tb(exc.__traceback__)
    if not tb:
        return "?"
    f = tb[-1]
    return f"{f.filename.rsplit('/', 1)[-1]}:{f.lineno}"


def run_name(scen: str, vehicle: str, controller: str, seed: int) -> str:
    """A run's name, fit for a file name: ``SCENARIO-VEHICLE-CONTROLLER-SEED``."""
    return f"{scen}-{_safe(Path(vehicle).stem)}-{_safe(controller)}-{seed}"


def _task(scen_name: str, vehicle: str, controller: str, seed: int, conditions: Conditions,
          recordings: Path | None, realtime: bool = True) -> dict:
    """A worker's job: one run, its scores row only (traces stay in the worker)."""
    record = (None if recordings is None
              else recordings / f"{run_name(scen_name, vehicle, controller, seed)}.rrd")
    return dock(DockRun(scenario(scen_name), vehicle, controller, seed, record=record,
                        realtime=realtime), conditions).row


def failed_row(scen_name: str, vehicle: str, controller: str, seed: int, truth: int | None,
               reason: str, sensor_set: str = "full", trailer: str | Draw = "nominal") -> dict:
    """The row of a run that ended its worker process (see :mod:`.supervise`): failed, why.

    Its start is the scenario's seeded one; the scores of a run that did not finish are
    unknown (NaN).
    """
    start = scenario(scen_name).start(seed)
    yard = scenario(scen_name).yard(load_vehicle(vehicle))
    row = dict.fromkeys(COLUMNS, math.nan)
    row.update({"scenario": scen_name, "vehicle": load_vehicle(vehicle).name,
                "controller": controller, "plant": "mbd" if truth is None else f"truth-{truth}",
                "seed": seed, "success": False, "failure": reason, "direction_changes": 0,
                "late_commands": 0, "plan_expansions": 0, "plan_direction_changes": 0,
                "start_x_m": start.x_r - yard.x_dock, "start_y_m": start.y_r - yard.y_dock,
                "start_heading_deg": math.degrees(start.psi_2),
                "start_gamma_deg": math.degrees(start.gamma), "solve_ms": np.empty(0),
                "sensors": sensor_set,
                "trailer": trailer if isinstance(trailer, str) else "given", "l2_updates": 0,
                **(trailer.row() if isinstance(trailer, Draw) else {})})
    row.update(tiers(row))
    return row


def benchmark(scenarios: Sequence[str], vehicles: Sequence[str], controller: str,
              seeds: Sequence[int], jobs: int = 1,
              progress: Callable[[str], None] | None = None,
              recordings: Path | None = None, deadline: float | None = None,
              realtime: bool = True, **conditions) -> list[dict]:
    """Every scenario x vehicle x seed with one controller; rows in that order.

    The runs go to supervised worker processes
    (:func:`artic.validation.docking.supervise.supervised`): a controller that
    ends its process or hangs fails its run, and the benchmark goes on.

    Parameters
    ----------
    scenarios, vehicles : sequence of str
        Scenario names and vehicle presets or files.
    controller : str
        ``--controller``'s value.
    seeds : sequence of int
        The starts.
    jobs : int
        Worker processes.
    progress : callable, optional
        Receives progress lines.
    sensors : SensorModel, optional
        The measurement chain; the campaign's by default.
    recordings : Path, optional
        Folder for one Rerun recording per run (:func:`run_name`); none without it.
    truth : int, optional
        Drive the synthetic truth of this seed instead of the plant (:func:`truth_yard`).
    realtime : bool
        Hold the controller to the real-time criterion (see :func:`drive`).
    deadline : float, optional
        Longest controller call before its run is ended as hung [s]
        (:data:`artic.validation.docking.supervise.CALL_DEADLINE` by default).
    **conditions
        The :class:`~artic.validation.docking.spec.Conditions` of every run, e.g.
        ``sensor_set`` (what the controllers see, ``artic dock --sensors``) and
        ``trailer`` (``"nominal"``, ``"unknown"`` or a given one; see :func:`drive`).
    """
    run_options, cond = split_options(conditions)
    if run_options:
        raise TypeError(f"benchmark() got an unexpected keyword argument "
                        f"{sorted(run_options)[0]!r}")
    cond = dataclasses.replace(cond, sensor_set=_sensor_set(cond.sensor_set, None))
    tasks = [((s, v, seed), (s, v, controller, seed, cond, recordings, realtime))
             for s in scenarios for v in vehicles for seed in seeds]
    counter = Counter(len(tasks), f"docking ({controller})", progress)
    rows: dict[tuple, dict] = {}

    def failed(key, args, reason):
        s, v, c, seed, co, _, _ = args
        return failed_row(s, v, c, seed, co.truth, reason, co.sensor_set, co.trailer)

    with contextlib.closing(supervised(_task, tasks, jobs, failed, deadline)) as done:
        for key, row in done:
            rows[key] = row
            counter.step(f"{key[0]} {key[1]} seed {key[2]}: "
                         + ("docked" if row["success"] else row["failure"]))
    return [rows[key] for key, _ in tasks]
