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
from artic.validation.docking.controllers.base import Task
from artic.validation.docking.geometry import Frames, box_array, first_hit
from artic.validation.docking.gym.env import (
    _STARTS,
    _TRUNCATIONS,
    DockEnv,
    check_drive_options,
    check_reset_options,
)
from artic.validation.docking.gym.reward import outcome_reward, step_reward
from artic.validation.docking.gym.spaces import STOP_DISTANCE, STOP_SPEED, ActionScale
from artic.validation.docking.identify import WheelbaseIdentifier
from artic.validation.docking.planner import HybridAStar, PlanningError
from artic.validation.docking.run import (
    ACCEL_MAX,
    DT,
    PLANT_DT,
    SENSOR_STREAM,
    SETTLE,
    SPEED,
    SPEED_MAX,
    STEER_RATE,
    Trace,
)
from artic.validation.docking.scenarios import scenario as find_scenario
from artic.validation.docking.scores import estimate_scores, score
from artic.validation.docking.sensing import SensorStream
from artic.validation.docking.variants import Draw, effective_wheelbase
from artic.validation.harness.steering import SteeringMap
from artic.validation.synthetic.sensors import SensorModel, can_quantise, can_sample

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
def _periods(kind, P, s1, s2, live, x, wheel, u, t, wheel_target, u_target, steer_step,
             accel_step, dt, i_s, q, offset, gamma_max, true, wheels, speeds, times, steps):
    """One controller period of ``N_SUB`` plant steps for the runs ``live``.

    The operations of ``drive``'s plant loop, in its order: the actuators' rate
    limits, the steering map (``SteeringMap.road_wheel``), KIN's step and
    signals (``Driven.step``, ``Driven.observe``), the jackknife check on the
    wrapped articulation. ``x, wheel, u, t`` advance in place; ``true, wheels,
    speeds, times`` receive each step's; ``steps`` how many were taken (fewer
    than ``N_SUB`` when the run jackknifed at the last).
    """
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


class _Run:
    """One sub-environment's episode: its yard, start, plan, noise and trace."""

    def __init__(self, scen, k: int, yard, start, plan, plan_ms: float, noise: np.ndarray,
                 n_ctrl: int, timeout: float) -> None:
        self.scen, self.k, self.yard, self.start = scen, k, yard, start
        self.plan, self.plan_ms, self.noise = plan, plan_ms, noise
        self.n_ctrl, self.timeout = n_ctrl, timeout
        self.trace = Trace()
        self.blocks: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self.ctrl = 0  # the controller sample the run is at
        self.settle_until: float | None = None
        self.signals: np.ndarray | None = None  # what the sensors reported at ``ctrl``
        self.wheel0 = 0.0
        self.steps = 0  # plant steps taken
        self.asked = 0.0  # when the agent got the last observation (perf_counter) [s]

    def wheel_at(self, step: int) -> float:
        """The steering wheel at plant step ``step`` [rad]."""
        if step == 0:
            return self.wheel0
        return float(self.blocks[(step - 1) // N_SUB][2][(step - 1) % N_SUB])

    def finish(self, vehicle, frames: Frames, start_frames: Frames) -> dict:
        """The scores row ``drive`` writes for this run."""
        tr = self.trace
        tr.t.append(0.0)  # the start, as drive's trace begins
        tr.true.append(self.true0)
        tr.steering_wheel.append(self.wheel0)
        tr.speed.append(0.0)
        for t0, true, wheel, speed in self.blocks:
            tr.t.extend(t0.tolist())
            tr.true.extend(true)
            tr.steering_wheel.extend(wheel.tolist())
            tr.speed.extend(speed.tolist())
        identifier = WheelbaseIdentifier(vehicle)
        for now, signals in zip(tr.t_ctrl, tr.measured, strict=True):
            identifier.update(now, signals)
        plan = self.plan
        return {"scenario": self.scen.name, "vehicle": vehicle.name, "controller": CONTROLLER,
                "plant": "kin", "seed": self.k,
                **score(tr, self.yard, vehicle, frames, self.start),
                "late_commands": tr.late, "plan_ms": self.plan_ms,
                "plan_expansions": plan.expansions, "plan_direction_changes":
                plan.direction_changes, "plan_length_m": plan.length, "sensors": "full",
                **estimate_scores(tr, start_frames, frames), "trailer": "nominal",
                "l2_nominal_m": effective_wheelbase(vehicle),
                "l2_true_m": effective_wheelbase(vehicle),
                "l2_identified_m": identifier.L2 if identifier.updates else math.nan,
                "l2_updates": identifier.updates, **Draw().row()}


class KinVectorEnv(VectorEnv):
    """``num_envs`` ``artic/DockKIN-v0`` environments in one batched step.

    Parameters
    ----------
    num_envs : int
        How many.
    **kwargs
        The keywords of :class:`~artic.validation.docking.gym.env.DockEnv`
        that :func:`batchable` accepts.
    """

    metadata = {"render_modes": ["rerun"], "render_fps": 10,
                "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int, scenario: str = "alley",
                 vehicle: str = "gosar2022-unloaded", yard_model: str = "kin",
                 sensors: str = "full", render_mode: str | None = None,
                 recording_dir: Any = "recordings", **drive_options: Any) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int | np.integer) \
                or num_envs < 1:
            raise UserError(f"num_envs {num_envs!r}: expected a positive integer")
        check_drive_options(drive_options)
        if not batchable({"yard_model": yard_model, "sensors": sensors,
                          "render_mode": render_mode, **drive_options}):
            raise UserError("KinVectorEnv: KIN with the full sensor set, no recording and "
                            "no drive() option but timeout; use DockVectorEnv for the others")
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
        self._model = KIN(v)
        steering = SteeringMap.from_steering(v.steering_for("kin"))
        self._map = (float(steering.i_s), float(steering.q), float(steering.delta_h_offset))
        self._wheel0 = float(steering.steering_wheel(0.0))
        self._sensors = SensorModel()
        self._rngs: list[np.random.Generator | None] = [None] * n
        self._runs: list[_Run | None] = [None] * n
        self._x = np.zeros((n, 4))
        self._wheel = np.zeros(n)
        self._u = np.zeros(n)
        self._t = np.zeros(n)
        self._wheel_target = np.zeros(n)
        self._u_target = np.zeros(n)
        self._last = np.zeros((n, *probe.observation_space.shape))
        self._autoreset = np.zeros(n, np.bool_)

    # ------------------------------------------------------------- episodes
    def _rng(self, i: int, seed: int | None) -> np.random.Generator:
        if seed is not None or self._rngs[i] is None:
            self._rngs[i], _ = seeding.np_random(seed)
        return self._rngs[i]

    def _reset_one(self, i: int, seed: int | None, options: dict[str, Any]) -> tuple:
        """``DockEnv.reset`` for sub-environment ``i``: its first observation and info."""
        start_k = check_reset_options(options)
        rng = self._rng(i, seed)
        if "scenario" in options:
            scen = find_scenario(options["scenario"], "options['scenario']")
        else:
            scen = self._scenarios[int(rng.integers(len(self._scenarios)))]
        v = self.vehicle
        for _ in range(100):
            k = int(rng.integers(_STARTS)) if start_k is None else start_k
            yard, start = scen.yard(v), scen.start(k)
            timeout = scen.timeout if self._timeout is None else float(self._timeout)
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
        run = _Run(scen, k, yard, start, plan, plan_ms, stream.noise, n_ctrl, timeout)
        run.boxes = box_array(yard.obstacles)
        run.task = Task(v, yard, plan, DT, SPEED, SPEED_MAX, ACCEL_MAX, STEER_RATE)
        x0 = self._frames.kin_from_rear(start.x_r, start.y_r, start.psi_2, start.gamma)
        xs, ys = self._frames.tractor_sensor_of_kin(x0)
        plant = Driven(self._model)
        plant.reset(InitialState(xs, ys, float(x0[2]), float(x0[3]), u1=0.0))
        self._x[i] = plant.x
        self._wheel[i] = run.wheel0 = self._wheel0
        self._u[i] = self._t[i] = 0.0
        self._wheel_target[i], self._u_target[i] = self._wheel0, 0.0
        run.true0 = plant.observe()
        self._runs[i] = run
        obs = self._observe(np.array([i]))[0]
        run.asked = time.perf_counter()
        info = {"t": 0.0, "scenario": scen.name, "start": k, "reason": ""}
        return obs, info

    def _true_last(self, i: int) -> np.ndarray:
        run = self._runs[i]
        if not run.blocks:
            return run.true0
        _, true, _, _ = run.blocks[-1]
        return true[-1]

    def _observe(self, idx: np.ndarray) -> np.ndarray:
        """The observation vectors of runs ``idx`` at their sample (``SensorStream.observe``)."""
        m = self._sensors
        signals = np.array([self._true_last(i) for i in idx], dtype=float)
        noise = np.array([self._runs[i].noise[self._runs[i].ctrl] for i in idx])
        signals[:, :12] += noise
        signals[:, OBS_INDEX["gamma"]] = wrap_angle(signals[:, 2] - signals[:, 8])
        dh = np.empty(len(idx))
        for n, i in enumerate(idx):
            run = self._runs[i]
            j = run.steps
            held = run.wheel_at(min(max(can_sample(j, PLANT_DT, m), 0), j))
            dh[n] = float(can_quantise(held, m))
        _, trailer = self._frames.unit_poses_of_signals(signals)
        rear = self._frames.rear
        x = trailer[:, 0] - rear * np.cos(trailer[:, 2])
        y = trailer[:, 1] - rear * np.sin(trailer[:, 2])
        dock = np.array([[self._runs[i].yard.x_dock, self._runs[i].yard.y_dock] for i in idx])
        out = np.empty((len(idx), 17))
        out[:, :13] = signals
        out[:, 13] = dh
        out[:, 14] = x - dock[:, 0]
        out[:, 15] = y - dock[:, 1]
        out[:, 16] = wrap_angle(trailer[:, 2])
        for n, i in enumerate(idx):
            self._runs[i].signals = signals[n]
        self._last[idx] = out
        return out

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
            _, info = self._reset_one(int(i), seeds[i], options)
            infos = self._add_info(infos, info, int(i))
        self._autoreset[mask] = False
        return self._last.copy(), infos

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                 np.ndarray, dict]:
        """Hold each sub-environment's action for 0.1 s (resetting those that ended)."""
        now_wall = time.perf_counter()
        n = self.num_envs
        a = _checked(actions, n, self._autoreset)
        rewards = np.zeros(n)
        terminated = np.zeros(n, np.bool_)
        truncated = np.zeros(n, np.bool_)
        infos: dict[str, Any] = {}
        stepping = np.flatnonzero(~self._autoreset)
        before = self._last.copy()
        ends: dict[int, None] = {}
        if stepping.size:
            self._command(stepping, a[stepping], before[stepping], now_wall)
            ends = self._advance(stepping)
        going = np.array([i for i in stepping if i not in ends], dtype=int)
        if going.size:
            after = self._observe(going)
            for n_, i in enumerate(going):
                rewards[i] = step_reward(tuple(before[i, -3:]), tuple(after[n_, -3:]))
                self._runs[i].asked = time.perf_counter()
        for i in range(n):
            if self._autoreset[i]:
                _, info = self._reset_one(i, None, {})
            elif i in ends:
                run = self._runs[i]
                row = run.finish(self.vehicle, self._frames, self._frames)
                reason = "docked" if row["success"] else str(row["failure"]).split(":")[0]
                truncated[i] = reason in _TRUNCATIONS
                terminated[i] = not truncated[i]
                rewards[i] = outcome_reward(bool(row["success"]), reason)
                self._last[i] = before[i]
                info = {"t": run.t_obs, "reason": reason, "scores": row}
                self._runs[i] = None
            else:
                info = {"t": self._runs[i].ctrl * DT, "reason": ""}
            infos = self._add_info(infos, info, i)
        self._autoreset = terminated | truncated
        return self._last.copy(), rewards, terminated, truncated, infos

    def _command(self, idx: np.ndarray, a: np.ndarray, before: np.ndarray,
                 now_wall: float) -> None:
        """The actions of runs ``idx`` as ``drive`` takes a controller's commands."""
        s = self.scale
        a = np.clip(a, -1.0, 1.0)
        side = np.where(a[:, 0] >= 0.0, s.left, s.right)
        delta_h = s.offset + a[:, 0] * side
        u1 = a[:, 1] * s.speed
        d = before[:, -3]
        done = (np.abs(u1) < STOP_SPEED) & (np.abs(d) < STOP_DISTANCE) & np.isfinite(d)
        u1 = np.where(done, 0.0, u1)
        for n, i in enumerate(idx):
            run = self._runs[i]
            tr = run.trace
            now = run.ctrl * DT
            solve_ms = 1e3 * (now_wall - run.asked)
            tr.solve_ms.append(solve_ms)
            if run.ctrl > 0 and solve_ms > 1e3 * DT:
                tr.late += 1
            tr.t_ctrl.append(now)
            tr.measured.append(run.signals)
            tr.seen_at.append(run.steps)
            tr.commands.append((float(delta_h[n]), float(u1[n])))
            tr.horizons.append(None)
            tr.references.append(None)
            run.t_obs = now
            if done[n]:
                tr.done = True
                run.settle_until = now + SETTLE
            self._wheel_target[i] = delta_h[n]
            self._u_target[i] = 0.0 if run.settle_until is not None else \
                min(max(float(u1[n]), -SPEED_MAX), SPEED_MAX)

    def _advance(self, idx: np.ndarray) -> dict[int, None]:
        """Step runs ``idx`` to their next sample, or to their end; the ended ones."""
        n = self.num_envs
        live = np.zeros(n, np.bool_)
        live[idx] = True
        ends: dict[int, None] = {}
        true = np.empty((n, N_SUB, 13))
        wheels, speeds, times = np.empty((n, N_SUB)), np.empty((n, N_SUB)), np.empty((n, N_SUB))
        steps = np.zeros(n, np.int64)
        m = self._model
        i_s, q, offset = self._map
        while live.any():
            _periods(m.kind, m.P, m._s1, m._s2, live, self._x, self._wheel, self._u, self._t,
                     self._wheel_target, self._u_target, STEER_RATE * PLANT_DT,
                     ACCEL_MAX * PLANT_DT, PLANT_DT, i_s, q, offset,
                     self.vehicle.gamma_max, true, wheels, speeds, times, steps)
            rows = np.flatnonzero(live)
            tractor, trailer = self._frames.unit_poses_of_signals(
                true[rows].reshape(-1, 13))
            tractor = tractor.reshape(len(rows), N_SUB, 3)
            trailer = trailer.reshape(len(rows), N_SUB, 3)
            for r, i in enumerate(rows):
                run = self._runs[i]
                k = int(steps[i])
                run.blocks.append((times[i, :k].copy(), true[i, :k].copy(),
                                   wheels[i, :k].copy(), speeds[i, :k].copy()))
                run.steps += k
                if k < N_SUB:
                    gamma = float(wrap_angle(float(self._x[i, 3])))
                    run.trace.failure = (
                        f"jackknife: |gamma| {math.degrees(abs(gamma)):.1f} deg beyond "
                        f"{math.degrees(self.vehicle.gamma_max):.1f} deg at "
                        f"t = {float(times[i, k - 1]):.2f} s")
                    ends[i] = None
                    live[i] = False
                    continue
                f = self._frames
                j, b, unit = first_hit(tractor[r], trailer[r], f.tractor_box, f.trailer_box,
                                       run.boxes)
                if j >= 0:
                    run.trace.failure = (
                        f"collision: {('tractor', 'semitrailer')[unit]} hit "
                        f"{run.yard.obstacles[b].name} at t = {float(times[i, j]):.2f} s")
                    ends[i] = None
                    live[i] = False
                    continue
                run.ctrl += 1
                now = run.ctrl * DT
                if run.ctrl >= run.n_ctrl:  # drive's loop ends: a timeout unless settling
                    if run.settle_until is None:
                        run.trace.failure = f"timeout: not docked after {run.timeout:.0f} s"
                    ends[i] = None
                    live[i] = False
                elif run.settle_until is None:
                    live[i] = False  # the agent's turn
                elif now >= run.settle_until or (abs(float(self._u[i])) < 1e-9
                                                 and abs(float(true[i, k - 1, 3])) < 0.01):
                    ends[i] = None
                    live[i] = False
        return ends

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


def _checked(actions, n: int, skipped: np.ndarray) -> np.ndarray:
    """``actions`` as an ``(n, 2)`` array, or one line naming the first bad row."""
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
