"""``artic/DockKIN-v0`` vectorised in one batched step: KIN, actuators, sensors, checks, rewards.

:class:`KinVectorEnv` is what ``gymnasium.make_vec("artic.gym:artic/DockKIN-v0",
num_envs=N, vectorization_mode="vector_entry_point")`` gives for the
configurations it covers (:func:`batchable`; any other gets the threaded
:class:`~artic.validation.docking.gym.vector.DockVectorEnv`). It computes what
:func:`artic.validation.docking.run.drive` computes on KIN, for all ``N`` runs
at once:

- the plant steps (:func:`_periods`, compiled): the actuators' rate limits,
  the steering map, KIN's step (:func:`artic.reduced.integrate.rk4_step`,
  the harness's own), its signals and the jackknife check, per 10 ms step;
- per 0.1 s period the collision check
  (:func:`artic.validation.docking.geometry.first_hit`), the sensors (the run's
  noise drawn up front by :class:`~artic.validation.docking.sensing.SensorStream`,
  the CAN bus's sampling and steps), the observation vector and the reward,
  in array operations;
- per episode, in Python, what ``drive`` does once: the seeded start, the
  planner (a start it finds no path from is drawn again), the noise, and at
  the end the scores (:func:`artic.validation.docking.scores.score`, the
  wheelbase identifier over the run's samples) from the run's trace.

Every operation is the single environment's, in the same order, so each
sub-environment gives exactly what ``DockEnv`` gives for the same seed and
actions (``tests/test_gym_vector.py`` compares them bit for bit). The rest of
the contract (autoreset, bad actions, copies) is
:class:`~artic.validation.docking.gym.vector.DockVectorEnv`'s.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numba import njit

from artic.mjcf.errors import UserError
from artic.mjcf.interface import OBS_INDEX, InitialState, wrap_angle
from artic.reduced import integrate
from artic.reduced.control import KIN
from artic.reduced.models import Driven
from artic.validation.docking.geometry import Frames, box_array, first_hit
from artic.validation.docking.gym.env import (
    _STARTS,
    _TRUNCATIONS,
    DockEnv,
    check_drive_options,
    check_reset_options,
)
from artic.validation.docking.gym.reward import outcome_reward, step_rewards
from artic.validation.docking.gym.spaces import STOP_DISTANCE, STOP_SPEED, ActionScale
from artic.validation.docking.identify import WheelbaseIdentifier
from artic.validation.docking.planner import HybridAStar, PlanningError
from artic.validation.docking.run import (
    ACCEL_MAX,
    DT,
    PLANT_DT,
    SENSOR_STREAM,
    SETTLE,
    SPEED_MAX,
    STEER_RATE,
    Trace,
)
from artic.validation.docking.scenarios import scenario as find_scenario
from artic.validation.docking.scores import estimate_scores, score
from artic.validation.docking.sensing import SensorStream
from artic.validation.docking.variants import Draw, effective_wheelbase
from artic.validation.synthetic.sensors import SensorModel

N_SUB = round(DT / PLANT_DT)
"""Plant steps per controller period."""

CONTROLLER = "artic.validation.docking.gym.episode:Caller"
"""The ``controller`` of a row the single environment's run writes."""


def batchable(kwargs: dict[str, Any]) -> bool:
    """Whether :class:`KinVectorEnv` covers the environments of keywords ``kwargs``.

    KIN, the ``full`` sensor set, no recording, and of ``drive``'s options only
    ``timeout``: the others (a delay, a drawn semitrailer, the truth, ...) change
    the loop, and go to the threaded vector environment.
    """
    return (kwargs.get("yard_model") == "kin" and kwargs.get("sensors", "full") == "full"
            and kwargs.get("render_mode") is None
            and set(kwargs) <= {"yard_model", "sensors", "render_mode", "recording_dir",
                                "scenario", "vehicle", "timeout"})


@njit(cache=True)
def _periods(model, live, state, targets, actuators, gamma_max, logs):
    """One controller period of ``N_SUB`` plant steps for the runs ``live``.

    ``model`` is KIN's ``(kind, P, s1, s2)``, ``state`` the runs' ``(x, wheel, u, t)``,
    ``targets`` their ``(wheel_target, u_target)``, ``actuators`` the limits and the
    steering map ``(steer_step, accel_step, dt, i_s, q, offset)``, ``logs`` the arrays
    ``(true, wheels, speeds, times, steps)``.

    The operations of ``drive``'s plant loop, in its order: the actuators' rate
    limits, the steering map (``Steering.road_wheel``), KIN's step and
    signals (``Driven.step``, ``Driven.observe``), the jackknife check on the
    wrapped articulation. ``x, wheel, u, t`` advance in place; ``true, wheels,
    speeds, times`` receive each step's; ``steps`` how many were taken (fewer
    than ``N_SUB`` when the run jackknifed at the last).
    """
    kind, P, s1, s2 = model
    x, wheel, u, t = state
    wheel_target, u_target = targets
    steer_step, accel_step, dt, i_s, q, offset = actuators
    true, wheels, speeds, times, steps = logs
    two_pi = 2.0 * math.pi
    for i in range(live.size):
        if not live[i]:
            continue
        steps[i] = N_SUB
        for j in range(N_SUB):
            dw = wheel_target[i] - wheel[i]
            wheel[i] += min(max(dw, -steer_step), steer_step)
            u_next = u[i] + min(max(u_target[i] - u[i], -accel_step), accel_step)
            d = wheel[i] - offset
            delta = (d - q * d * d) / i_s
            u_dot = (u_next - u[i]) / dt
            x[i] = integrate.rk4_step(kind, x[i], dt, u[i], u_dot, delta, P)
            y = integrate.observe(kind, x[i], u[i] + u_dot * dt, delta, P, s1, s2)
            y[12] = math.pi - (math.pi - y[12]) % two_pi
            u[i] = u_next
            t[i] = t[i] + dt
            true[i, j] = y
            wheels[i, j] = wheel[i]
            speeds[i, j] = u[i]
            times[i, j] = t[i]
            gamma = math.pi - (math.pi - x[i, 3]) % two_pi
            if abs(gamma) > gamma_max:
                steps[i] = j + 1
                break


@njit(cache=True)
def _first_hits(live, tractor, trailer, tractor_box, trailer_box, boxes, n_boxes, hits):
    """:func:`~artic.validation.docking.geometry.first_hit` of each live run over its period.

    ``tractor, trailer`` (n, N_SUB, 3), ``boxes`` (n, m, 4) with ``n_boxes`` of each
    run's used; ``hits`` (n, 3) receives each run's ``(sample, box, unit)``.
    """
    for i in range(live.size):
        hits[i, 0] = hits[i, 1] = hits[i, 2] = -1
        if live[i]:
            k, j, unit = first_hit(tractor[i], trailer[i], tractor_box, trailer_box,
                                   boxes[i, :n_boxes[i]])
            hits[i, 0], hits[i, 1], hits[i, 2] = k, j, unit


class _Run:
    """One sub-environment's episode: its yard, start and plan.

    ``periods`` and ``samples`` are its first entries of the vector environment's
    logs (global counts), where its trace begins.
    """

    def __init__(self, scen, k: int, yard, start, plan, plan_ms: float, timeout: float,
                 true0: np.ndarray, periods: int, samples: int) -> None:
        self.scen, self.k, self.yard, self.start = scen, k, yard, start
        self.plan, self.plan_ms, self.timeout = plan, plan_ms, timeout
        self.true0 = true0
        self.periods, self.samples = periods, samples
        self.failure = ""


class KinVectorEnv(VectorEnv):
    """``num_envs`` ``artic/DockKIN-v0`` environments in one batched step.

    Parameters
    ----------
    num_envs : int
        How many.
    **kwargs
        The keywords of :class:`~artic.validation.docking.gym.env.DockEnv`
        that :func:`batchable` accepts.

    Notes
    -----
    Each run's trace (every 10 ms step, for its scores at the end) is kept in logs
    shared by the runs, a record per period: memory grows with the longest
    running episode, about 1.4 kB per environment and step.

    Version history (as Gymnasium's environments keep one):

    - v0, 2026-12-06: ``gymnasium.make_vec("artic.gym:artic/DockKIN-v0",
      vectorization_mode="vector_entry_point")`` makes this one batched step where
      :func:`batchable` allows, equal to ``SyncVectorEnv`` of single environments
      bit for bit, scores included; the same day it keeps its runs' traces in
      shared logs, and refuses a step before its reset, as the single one does.
    """

    metadata = {"render_modes": ["rerun"], "render_fps": 10,
                "autoreset_mode": AutoresetMode.NEXT_STEP}


    def close(self, **kwargs: Any) -> None:
        """Close every episode (Gymnasium's ``VectorEnv.close``; its docstring is not RST)."""
        super().close(**kwargs)

    @classmethod
    def _check_inputs(cls, num_envs: Any, options: dict[str, Any]) -> None:
        """One line for the first bad input, before anything is built or planned.

        ``options`` are the keywords past ``vehicle`` (``yard_model``, ``sensors``,
        ``render_mode`` and the ``drive()`` options); :meth:`_refuse` says whether
        this batch covers them.
        """
        if isinstance(num_envs, bool) or not isinstance(num_envs, int | np.integer) \
                or num_envs < 1:
            raise UserError(f"num_envs {num_envs!r}: expected a positive integer")
        drive_options = {k: v for k, v in options.items()
                         if k not in ("yard_model", "sensors", "render_mode")}
        check_drive_options(drive_options)
        cls._refuse(options)

    def __init__(self, num_envs: int, scenario: str = "alley",
                 vehicle: str = "gosar2022-unloaded", yard_model: str = "kin",
                 sensors: str = "full", render_mode: str | None = None,
                 recording_dir: Any = "recordings", **drive_options: Any) -> None:
        self._check_inputs(num_envs, {"yard_model": yard_model, "sensors": sensors,
                                      "render_mode": render_mode, **drive_options})
        # One environment checks the keywords and gives the spaces and the scale.
        probe = DockEnv(scenario=scenario, vehicle=vehicle, yard_model=yard_model,
                        sensors=sensors, **drive_options)
        self._scenarios = probe._scenarios
        self.vehicle = probe.vehicle
        self.scale: ActionScale = probe.scale
        self._timeout = drive_options.get("timeout")
        self.num_envs = n = int(num_envs)
        self.render_mode = None
        self.single_observation_space = probe.observation_space
        self.single_action_space = probe.action_space
        self.observation_space = batch_space(probe.observation_space, n)
        self.action_space = batch_space(probe.action_space, n)
        v = self.vehicle
        self._frames = Frames.of(v)
        steering = v.steering_for(self.PLANT)
        self._map = (float(steering.i_s), float(steering.q), float(steering.delta_h_offset))
        self._wheel0 = float(steering.steering_wheel(0.0))
        self._sensors = SensorModel()
        self._rngs: list[np.random.Generator | None] = [None] * n
        self._runs: list[_Run | None] = [None] * n
        # The runs' state, one row each.
        self._x = np.zeros((n, 4))
        self._wheel, self._u, self._t = np.zeros(n), np.zeros(n), np.zeros(n)
        self._wheel_target, self._u_target = np.zeros(n), np.zeros(n)
        self._true = np.zeros((n, 13))  # the plant's signals now
        self._last_wheels = np.zeros((n, N_SUB))  # the last period's steering wheel
        self._signals = np.zeros((n, 13))  # what the sensors reported at the sample
        self._ctrl = np.zeros(n, np.int64)  # the controller's sample
        self._n_ctrl = np.zeros(n, np.int64)
        self._steps = np.zeros(n, np.int64)  # plant steps taken
        self._settle_until = np.full(n, np.nan)  # NaN: not settling
        self._done = np.zeros(n, np.bool_)
        self._late = np.zeros(n, np.int64)
        self._asked = np.zeros(n)  # when the agent got its observation [s, perf_counter]
        self._t_obs = np.zeros(n)
        self._dock = np.zeros((n, 2))
        self._boxes = np.zeros((n, 1, 4))
        self._noise = np.zeros((n, 1, 12))  # each run's sensor noise per sample (padded)
        self._n_boxes = np.zeros(n, np.int64)
        self._last = np.zeros((n, *probe.observation_space.shape))
        self._autoreset = np.zeros(n, np.bool_)
        # The logs: one record per period, one per controller sample, from the
        # oldest running episode's first on (``_base``: the global count of the first).
        self._period_log: list[tuple] = []
        self._sample_log: list[tuple] = []
        self._base = [0, 0]
        self._starts: dict[int, InitialState] = {}  # the runs reset, to be placed
        self._build()

    # ------------------------------------------------------------- the plant
    PLANT = "kin"
    """Whose steering map the actuators use (``Vehicle.steering_for``)."""

    PLANT_NAME = "kin"
    """The ``plant`` of a run's row."""

    @staticmethod
    def _refuse(kwargs: dict[str, Any]) -> None:
        """One line for keywords this batch does not cover (:func:`batchable`)."""
        if not batchable(kwargs):
            raise UserError("KinVectorEnv: KIN with the full sensor set, no recording and "
                            "no drive() option but timeout; use DockVectorEnv for the others")

    def _build(self) -> None:
        """The batch's plant: KIN's model, each run's state a row of ``_x``."""
        self._model = KIN(self.vehicle)

    def _place(self, idx: np.ndarray) -> None:
        """Put runs ``idx`` at their starts (``_starts``): their signals into ``_true``."""
        for i in idx:
            plant = Driven(self._model)
            plant.reset(self._starts.pop(int(i)))
            self._x[i] = plant.x
            self._true[i] = self._runs[i].true0 = plant.observe()

    def _period(self, live: np.ndarray, first: bool) -> tuple:
        """One controller period of runs ``live`` on the plant.

        ``first``: the first period of the step (the later ones are a settling run's).
        Returns the period's logs ``(steps, times, true, wheels, speeds)``, each run's
        rows ``(n, N_SUB, ...)`` and how many steps it took, and the runs that ended in
        it (a jackknife, a diverged plant), their ``failure`` set.
        """
        n = self.num_envs
        m = self._model
        i_s, q, offset = self._map
        true = np.zeros((n, N_SUB, 13))
        wheels, speeds, times = np.zeros((n, N_SUB)), np.zeros((n, N_SUB)), \
            np.zeros((n, N_SUB))
        steps = np.zeros(n, np.int64)
        _periods((m.kind, m.P, m._s1, m._s2), live,
                 (self._x, self._wheel, self._u, self._t),
                 (self._wheel_target, self._u_target),
                 (STEER_RATE * PLANT_DT, ACCEL_MAX * PLANT_DT, PLANT_DT, i_s, q, offset),
                 self.vehicle.gamma_max, (true, wheels, speeds, times, steps))
        jack = live & (steps < N_SUB)
        for i in np.flatnonzero(jack):
            gamma = float(wrap_angle(float(self._x[i, 3])))
            self._runs[i].failure = (
                f"jackknife: |gamma| {math.degrees(abs(gamma)):.1f} deg beyond "
                f"{math.degrees(self.vehicle.gamma_max):.1f} deg at "
                f"t = {float(times[i, steps[i] - 1]):.2f} s")
        return (steps, times, true, wheels, speeds), jack

    # ------------------------------------------------------------- episodes
    def _rng(self, i: int, seed: int | None) -> np.random.Generator:
        if seed is not None or self._rngs[i] is None:
            self._rngs[i], _ = seeding.np_random(seed)
        return self._rngs[i]

    def _reset_one(self, i: int, seed: int | None, options: dict[str, Any]) -> dict:
        """``DockEnv.reset`` for sub-environment ``i``: its info; :meth:`_started` places it."""
        start_k = check_reset_options(options)
        rng = self._rng(i, seed)
        if "scenario" in options:
            scen = find_scenario(options["scenario"], "options['scenario']")
        else:
            scen = self._scenarios[int(rng.integers(len(self._scenarios)))]
        v = self.vehicle
        timeout = scen.timeout if self._timeout is None else float(self._timeout)
        for _ in range(100):  # a start the planner finds no path from is drawn again
            k = int(rng.integers(_STARTS)) if start_k is None else start_k
            yard, start = scen.yard(v), scen.start(k)
            t0 = time.perf_counter()
            try:
                plan = HybridAStar().plan(yard, v, start)  # drive's, anew each run
            except PlanningError as exc:
                if start_k is not None:
                    raise UserError(f"start {k} of {scen.name}: no plan: {exc}; choose another "
                                    "start") from None
                continue
            plan_ms = 1e3 * (time.perf_counter() - t0)
            break
        else:
            raise RuntimeError(f"no start of {scen.name} had a plan in 100 draws")
        n_ctrl = int(round(timeout / DT))
        stream = SensorStream(self._sensors,
                              np.random.default_rng([k, scen.number, SENSOR_STREAM]),
                              n_ctrl + 1, DT, PLANT_DT)
        x0 = self._frames.kin_from_rear(start.x_r, start.y_r, start.psi_2, start.gamma)
        xs, ys = self._frames.tractor_sensor_of_kin(x0)
        self._starts[i] = InitialState(xs, ys, float(x0[2]), float(x0[3]), u1=0.0)
        self._runs[i] = _Run(scen, k, yard, start, plan, plan_ms, timeout,
                             None, self._base[0] + len(self._period_log),
                             self._base[1] + len(self._sample_log))
        if n_ctrl + 1 > self._noise.shape[1]:  # the longest run so far: room for its noise
            grown = np.zeros((self.num_envs, n_ctrl + 1, 12))
            grown[:, :self._noise.shape[1]] = self._noise
            self._noise = grown
        self._noise[i, :n_ctrl + 1] = stream.noise
        boxes = box_array(yard.obstacles)
        if len(boxes) > self._boxes.shape[1]:
            grown = np.zeros((self.num_envs, len(boxes), 4))
            grown[:, :self._boxes.shape[1]] = self._boxes
            self._boxes = grown
        self._boxes[i, :len(boxes)] = boxes
        self._n_boxes[i] = len(boxes)
        self._wheel[i] = self._wheel_target[i] = self._wheel0
        self._u[i] = self._t[i] = self._u_target[i] = 0.0
        self._ctrl[i] = self._steps[i] = self._late[i] = 0
        self._n_ctrl[i] = n_ctrl
        self._settle_until[i] = math.nan
        self._done[i] = False
        self._dock[i] = (yard.x_dock, yard.y_dock)
        return {"t": 0.0, "scenario": scen.name, "start": k, "reason": ""}

    def _started(self, idx: np.ndarray) -> None:
        """Place the runs ``idx`` reset by :meth:`_reset_one`: their first observations."""
        if idx.size:
            self._place(idx)
            self._observe(idx)
            self._asked[idx] = time.perf_counter()

    def _wheel_at(self, i: int, step: int) -> float:
        """Run ``i``'s steering wheel at plant step ``step`` [rad] (last period, or the log)."""
        if step == 0:
            return self._wheel0
        back = int(self._steps[i]) - step
        if 0 <= back < N_SUB:
            return float(self._last_wheels[i, N_SUB - 1 - back])
        run, taken = self._runs[i], 0
        for live, steps, _, _, wheels, _ in self._period_log[run.periods - self._base[0]:]:
            if live[i]:
                if step <= taken + steps[i]:
                    return float(wheels[i, step - taken - 1])
                taken += int(steps[i])
        raise IndexError(step)

    def _observe(self, idx: np.ndarray) -> None:
        """The observation vectors of runs ``idx`` at their sample, into ``_last``.

        ``SensorStream.observe`` (the noise, the articulation from the noisy headings,
        the CAN bus's sample and step) and ``Controller.dock_errors``, as arrays.
        """
        m = self._sensors
        signals = self._true[idx].copy()
        signals[:, :12] += self._noise[idx, self._ctrl[idx]]
        signals[:, OBS_INDEX["gamma"]] = wrap_angle(signals[:, 2] - signals[:, 8])
        j = self._steps[idx]
        every = max(1, round(1.0 / (m.can_rate * PLANT_DT)))
        held_at = np.minimum(np.maximum((j // every) * every - round(m.can_delay / PLANT_DT),
                                        0), j)
        back = j - held_at
        held = np.where(held_at == 0, self._wheel0, self._last_wheels[
            idx, np.clip(N_SUB - 1 - back, 0, N_SUB - 1)])
        for n in np.flatnonzero((held_at > 0) & (back >= N_SUB)):  # not the default bus's
            held[n] = self._wheel_at(int(idx[n]), int(held_at[n]))
        dh = np.round(held / m.can_step) * m.can_step if m.can_step > 0 else held
        _, trailer = self._frames.unit_poses_of_signals(signals)
        rear = self._frames.rear
        out = self._last
        out[idx, :13] = signals
        out[idx, 13] = dh
        out[idx, 14] = trailer[:, 0] - rear * np.cos(trailer[:, 2]) - self._dock[idx, 0]
        out[idx, 15] = trailer[:, 1] - rear * np.sin(trailer[:, 2]) - self._dock[idx, 1]
        out[idx, 16] = wrap_angle(trailer[:, 2])
        self._signals[idx] = signals

    def _finish(self, i: int) -> dict:
        """The scores row ``drive`` writes for run ``i``, from the logs."""
        run = self._runs[i]
        tr = Trace(t=[0.0], true=[run.true0], steering_wheel=[self._wheel0], speed=[0.0])
        for live, steps, times, true, wheels, speeds in \
                self._period_log[run.periods - self._base[0]:]:
            if live[i]:
                k = int(steps[i])
                tr.t.extend(times[i, :k].tolist())
                tr.true.extend(true[i, :k])
                tr.steering_wheel.extend(wheels[i, :k].tolist())
                tr.speed.extend(speeds[i, :k].tolist())
        for mask, t_ctrl, measured, seen_at, commands, solve_ms in \
                self._sample_log[run.samples - self._base[1]:]:
            if mask[i]:
                tr.t_ctrl.append(float(t_ctrl[i]))
                tr.measured.append(measured[i])
                tr.seen_at.append(int(seen_at[i]))
                tr.commands.append((float(commands[i, 0]), float(commands[i, 1])))
                tr.solve_ms.append(float(solve_ms[i]))
                tr.horizons.append(None)
                tr.references.append(None)
        tr.failure, tr.done, tr.late = run.failure, bool(self._done[i]), int(self._late[i])
        v, frames = self.vehicle, self._frames
        identifier = WheelbaseIdentifier(v)
        for now, signals in zip(tr.t_ctrl, tr.measured, strict=True):
            identifier.update(now, signals)
        plan = run.plan
        return {"scenario": run.scen.name, "vehicle": v.name, "controller": CONTROLLER,
                "plant": self.PLANT_NAME, "seed": run.k,
                **score(tr, run.yard, v, frames, run.start),
                "late_commands": tr.late, "plan_ms": run.plan_ms,
                "plan_expansions": plan.expansions,
                "plan_direction_changes": plan.direction_changes,
                "plan_length_m": plan.length, "sensors": "full",
                **estimate_scores(tr, frames, frames), "trailer": "nominal",
                "l2_nominal_m": effective_wheelbase(v), "l2_true_m": effective_wheelbase(v),
                "l2_identified_m": identifier.L2 if identifier.updates else math.nan,
                "l2_updates": identifier.updates, **Draw().row()}

    def _trim(self) -> None:
        """Drop the logs' records older than every running episode's first."""
        runs = [r for r in self._runs if r is not None]
        for which, log, first in ((0, self._period_log, [r.periods for r in runs]),
                                  (1, self._sample_log, [r.samples for r in runs])):
            keep = min(first, default=self._base[which] + len(log))
            del log[:keep - self._base[which]]
            self._base[which] = keep

    # ------------------------------------------------------------------ API
    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        """Reset every sub-environment (or those of ``options["reset_mask"]``).

        ``seed=s`` seeds sub-environment ``i`` with ``s + i``; a list gives each its own.
        """
        n = self.num_envs
        seeds = _seeds(seed, n)
        options = dict(options or {})
        mask = _mask(options.pop("reset_mask", None), n)
        check_reset_options(options)
        infos: dict[str, Any] = {}
        for i in np.flatnonzero(mask):
            infos = self._add_info(infos, self._reset_one(int(i), seeds[i], options), int(i))
        self._started(np.flatnonzero(mask))
        self._autoreset[mask] = False
        self._trim()
        return self._last.copy(), infos

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                 np.ndarray, dict]:
        """Hold each sub-environment's action for 0.1 s (resetting those that ended)."""
        now_wall = time.perf_counter()
        n = self.num_envs
        if self._runs.count(None) > int(np.count_nonzero(self._autoreset)):
            raise RuntimeError("call reset() before step()")
        a = checked_actions(actions, n, self._autoreset)
        rewards = np.zeros(n)
        terminated = np.zeros(n, np.bool_)
        truncated = np.zeros(n, np.bool_)
        stepping = ~self._autoreset
        before = self._last.copy()
        ended = np.zeros(n, np.bool_)
        if stepping.any():
            self._command(stepping, a, before, now_wall)
            ended = self._advance(stepping)
        going = np.flatnonzero(stepping & ~ended)
        if going.size:
            self._observe(going)
            rewards[going] = step_rewards(before[going, -3:], self._last[going, -3:])
            self._asked[going] = time.perf_counter()
        # The infos: the running ones' as arrays, the ended and reset ones' one by one
        # (in the order of the sub-environments, as SyncVectorEnv adds them).
        infos: dict[str, Any] = {}
        if going.size:
            t = np.zeros(n)
            t[going] = self._ctrl[going] * DT
            reason = np.full(n, None, dtype=object)
            reason[going] = ""
            mask = np.zeros(n, np.bool_)
            mask[going] = True
            infos = {"t": t, "_t": mask, "reason": reason, "_reason": mask.copy()}
        for i in np.flatnonzero(~stepping | ended):
            i = int(i)
            if self._autoreset[i]:
                info = self._reset_one(i, None, {})  # observed below, with the others
            else:
                row = self._finish(i)
                reason_ = "docked" if row["success"] else str(row["failure"]).split(":")[0]
                truncated[i] = reason_ in _TRUNCATIONS
                terminated[i] = not truncated[i]
                rewards[i] = outcome_reward(bool(row["success"]), reason_)
                self._last[i] = before[i]
                info = {"t": float(self._t_obs[i]), "reason": reason_, "scores": row}
                self._runs[i] = None
            infos = self._add_info(infos, info, i)
        self._started(np.flatnonzero(~stepping))
        self._autoreset = terminated | truncated
        if len(self._sample_log) > 256:
            self._trim()
        return self._last.copy(), rewards, terminated, truncated, infos

    def _command(self, live: np.ndarray, a: np.ndarray, before: np.ndarray,
                 now_wall: float) -> None:
        """The actions of runs ``live`` as ``drive`` takes a controller's commands."""
        s = self.scale
        a = np.clip(a, -1.0, 1.0)
        delta_h = s.offset + a[:, 0] * np.where(a[:, 0] >= 0.0, s.left, s.right)
        u1 = a[:, 1] * s.speed
        d = before[:, -3]
        done = live & (np.abs(u1) < STOP_SPEED) & (np.abs(d) < STOP_DISTANCE) & np.isfinite(d)
        u1 = np.where(done, 0.0, u1)
        now = self._ctrl * DT
        solve_ms = 1e3 * (now_wall - self._asked)
        self._late += live & (self._ctrl > 0) & (solve_ms > 1e3 * DT)
        self._sample_log.append((live.copy(), now, self._signals.copy(), self._steps.copy(),
                                 np.column_stack([delta_h, u1]), solve_ms))
        self._t_obs = np.where(live, now, self._t_obs)
        self._done |= done
        self._settle_until = np.where(done, now + SETTLE, self._settle_until)
        self._wheel_target = np.where(live, delta_h, self._wheel_target)
        settling = ~np.isnan(self._settle_until)
        self._u_target = np.where(live, np.where(settling, 0.0, np.minimum(
            np.maximum(u1, -SPEED_MAX), SPEED_MAX)), self._u_target)

    def _advance(self, live: np.ndarray) -> np.ndarray:
        """Step runs ``live`` to their next sample, or to their end; the ended ones."""
        n = self.num_envs
        live = live.copy()
        ended = np.zeros(n, np.bool_)
        f = self._frames
        hits = np.empty((n, 3), np.int64)
        first = True
        while live.any():
            (steps, times, true, wheels, speeds), jack = self._period(live, first)
            first = False
            self._period_log.append((live.copy(), steps, times, true, wheels, speeds))
            rows = np.flatnonzero(live & (steps > 0))
            self._steps[rows] += steps[rows]
            self._true[rows] = true[rows, steps[rows] - 1]
            self._last_wheels[rows] = wheels[rows]
            tractor, trailer = f.unit_poses_of_signals(true.reshape(-1, 13))
            _first_hits(live & ~jack, tractor.reshape(n, N_SUB, 3),
                        trailer.reshape(n, N_SUB, 3), f.tractor_box, f.trailer_box,
                        self._boxes, self._n_boxes, hits)
            hit = hits[:, 0] >= 0
            for i in np.flatnonzero(hit):
                run = self._runs[i]
                k, b, unit = hits[i]
                run.failure = (
                    f"collision: {('tractor', 'semitrailer')[unit]} hit "
                    f"{run.yard.obstacles[b].name} at t = {float(times[i, k]):.2f} s")
            on = live & ~jack & ~hit
            self._ctrl[on] += 1
            out_of_time = on & (self._ctrl >= self._n_ctrl)  # drive's loop ends
            settling = ~np.isnan(self._settle_until)
            for i in np.flatnonzero(out_of_time & ~settling):
                run = self._runs[i]
                run.failure = f"timeout: not docked after {run.timeout:.0f} s"
            now = self._ctrl * DT
            with np.errstate(invalid="ignore"):
                rest = (now >= self._settle_until) | ((np.abs(self._u) < 1e-9)
                                                      & (np.abs(self._true[:, 3]) < 0.01))
            stop = on & ~out_of_time & settling & rest
            ended |= jack | hit | out_of_time | stop
            live = on & ~out_of_time & settling & ~rest  # the others: the agent's turn
        return ended

    def render(self) -> None:
        """Nothing to draw: the batched runs are not recorded (``DockVectorEnv`` records)."""
        return None


def _seeds(seed, n: int) -> list[int | None]:
    if seed is None:
        return [None] * n
    if isinstance(seed, int | np.integer) and not isinstance(seed, bool):
        return [int(seed) + i for i in range(n)]
    seeds = list(seed)
    if len(seeds) != n:
        raise UserError(f"seed: a list of {len(seeds)} seeds for {n} environments; "
                        f"give {n}, one int (seeding s, s + 1, ...) or None")
    return seeds


def _mask(mask, n: int) -> np.ndarray:
    if mask is None:
        return np.ones(n, np.bool_)
    mask = np.asarray(mask)
    if mask.shape != (n,) or mask.dtype != np.bool_ or not mask.any():
        raise UserError(f"options['reset_mask']: expected a boolean array of shape ({n},) "
                        f"with at least one True; got shape {mask.shape}, dtype {mask.dtype}")
    return mask


def checked_actions(actions, n: int, skipped: np.ndarray) -> np.ndarray:
    """``actions`` as an ``(n, 2)`` array, or one line naming the first bad row.

    Rows of ``skipped`` (sub-environments resetting this call) are not checked; both
    vector environments refuse a bad call before anything steps.
    """
    a = np.asarray(actions, dtype=float)
    if a.shape != (n, 2):
        raise UserError(f"actions of shape {a.shape}: expected ({n}, 2), a steering wheel "
                        "and a speed in [-1, 1] for each environment; nothing was stepped")
    bad = np.flatnonzero(~np.isfinite(a).all(axis=1) & ~skipped)
    if bad.size:
        i = int(bad[0])
        raise UserError(f"actions[{i}] {a[i].tolist()}: not finite (sub-environment {i}"
                        + (f" and {bad.size - 1} more" if bad.size > 1 else "")
                        + "); expected the steering wheel and the speed, each in [-1, 1]; "
                        "nothing was stepped")
    return a
