"""``artic/Dock-v0`` and ``artic/DockKIN-v0``: the docking benchmark as a Gymnasium environment.

An episode is one run of ``artic dock`` (:class:`~artic.validation.docking.gym.episode.Episode`):
the scenario's seeded start, the planner, the actuators, the sensors and their
noise, the failure checks and the scores are the benchmark's own, on the
multibody plant (``Dock-v0``) or on KIN (``DockKIN-v0``, for fast prototyping:
the same scenarios, observations and scores, so a policy trained on one is
evaluated on the other).

- **Observation**: ``Box(-inf, inf, (17,), float64)``, the controller's
  observation as ``artic dock`` gives it and the dock errors
  (:data:`~artic.validation.docking.gym.spaces.OBSERVATION_NAMES`, with their
  :data:`~artic.validation.docking.gym.spaces.OBSERVATION_UNITS`).
- **Action**: ``Box(-1, 1, (2,), float64)``: steering wheel and speed as shares
  of their limits (:class:`~artic.validation.docking.gym.spaces.ActionScale`).
  The actuators follow it at their rates, as in ``artic dock``.
- **Step**: the controllers' sample period, 0.1 s; the plant steps at its own
  10 ms within.
- **Reward**: :mod:`artic.validation.docking.gym.reward`.
- **End**: terminated when the run ends docked or failed (collision,
  jackknife, a missed door, a diverged plant); truncated at the scenario's time
  limit. ``info["reason"]`` says which; the last step's ``info["scores"]`` is the
  run's ``dock.csv`` row, so an evaluation with this environment equals
  ``artic dock``'s. Agents built on artic's controllers read
  :attr:`DockEnv.observation` (the :class:`~artic.validation.docking.controllers.Observation`
  a controller gets) and :attr:`DockEnv.task` (its
  :class:`~artic.validation.docking.controllers.Task`, the plan among it).

``reset(seed=s)`` seeds the draw of the start; ``options={"start": k}`` takes
``artic dock``'s start ``k`` (its ``--seeds``) instead, and ``"scenario"`` another
of the environment's scenarios; any other key is refused (:data:`RESET_OPTIONS`).

The environment holds its state in its own copies: the arrays it returns are the
caller's, to scale or overwrite, and change nothing of the episode.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import numbers
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import load_vehicle
from artic.validation.docking.controllers.base import Controller, Observation, Task
from artic.validation.docking.gym.episode import Episode, Step
from artic.validation.docking.gym.reward import outcome_reward, step_reward
from artic.validation.docking.gym.spaces import (
    OBSERVATION_NAMES,
    ActionScale,
    observation_vector,
    stopped_at_dock,
)
from artic.validation.docking.run import run_name
from artic.validation.docking.scenarios import SCENARIOS
from artic.validation.docking.scenarios import scenario as find_scenario
from artic.validation.docking.sensing import sensor_set
from artic.validation.docking.spec import OPTIONS

_TRUNCATIONS = ("timeout",)
_STARTS = 2**31 - 1

RESET_OPTIONS = ("start", "scenario")
"""The keys ``reset(options=...)`` reads."""

_SET_BY_ENV = {"scen": "scenario", "vehicle_name": "vehicle", "controller": None,
               "seed": "reset(options={'start': k})", "yard_model": "the environment's id",
               "record": "render_mode='rerun' with recording_dir",
               "realtime": None, "sensor_set": "sensors"}
# drive()'s parameters the environment sets itself, and the keyword that sets them.

DRIVE_OPTIONS = tuple(p for p in OPTIONS
                      if p not in _SET_BY_ENV and p != "sensors")  # `sensors` is the set here
"""The keywords of :func:`~artic.validation.docking.run.drive` an environment passes on."""


def check_drive_options(options: dict[str, Any]) -> None:
    """Refuse a keyword ``drive`` would not take, or a time limit that is not one.

    Raises
    ------
    UserError
        One line naming the keyword and the accepted ones (or what sets it).
    """
    for key in options:
        if key in _SET_BY_ENV:
            by = _SET_BY_ENV[key]
            raise UserError(f"keyword {key!r}: the environment sets it itself"
                            + (f"; use {by}" if by else ""))
        if key not in DRIVE_OPTIONS:
            raise UserError(f"keyword {key!r}: not an option of the docking environment; "
                            f"expected scenario, vehicle, sensors, render_mode, recording_dir "
                            f"or one of drive()'s: {', '.join(DRIVE_OPTIONS)}")
    timeout = options.get("timeout")
    if timeout is not None:
        try:
            ok = math.isfinite(float(timeout)) and float(timeout) > 0.0
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise UserError(f"timeout {timeout!r}: a run's time limit must be a positive "
                            "number of seconds")


def check_reset_options(options: dict[str, Any]) -> int | None:
    """The start ``options`` asks for (``None``: draw one), the keys checked.

    Raises
    ------
    UserError
        One line for a key not in :data:`RESET_OPTIONS`, or a start that is not an
        integer in [0, 2**31 - 2].
    """
    for key in options:
        if key not in RESET_OPTIONS:
            raise UserError(f"options[{key!r}]: not a reset option; expected "
                            + " or ".join(repr(k) for k in RESET_OPTIONS))
    start = options.get("start")
    if start is None:
        return None
    if isinstance(start, bool) or not isinstance(start, numbers.Integral) \
            or not 0 <= int(start) < _STARTS:
        raise UserError(f"options['start'] {start!r}: expected an integer from 0 to "
                        f"{_STARTS - 1} (artic dock's start, its --seeds)")
    return int(start)


class DockEnv(gym.Env):
    """Reverse a tractor-semitrailer onto a loading dock.

    Parameters
    ----------
    scenario : str
        Comma-separated scenario names (``artic dock --list``), or ``"all"``:
        each reset draws one of them unless ``options["scenario"]`` names it.
    vehicle : str
        Vehicle preset or file.
    yard_model : str
        ``"mbd"``, the multibody plant, or ``"kin"``.
    sensors : str
        ``artic dock --sensors``: ``"full"`` (RTK/INS on both units), ``"tractor"``
        (the tractor's and a hitch encoder) or ``"camera"`` (the tractor's and a
        rear camera); with the last two the observation's semitrailer entries are
        the estimator's (:mod:`artic.validation.docking.estimator`).
    render_mode : str, optional
        ``"rerun"``: write each finished episode's Rerun recording, the one
        ``artic dock`` writes, to ``recording_dir``.
    recording_dir : str or Path
        Where the recordings go (``"recordings"`` by default).
    **drive_options
        More keyword arguments of :func:`artic.validation.docking.run.drive`
        for every episode (for example ``timeout`` [s]).

    Notes
    -----
    Version history (as Gymnasium's environments keep one; a change that alters an
    episode's observations, rewards or ends for the same seed and actions will take a
    new version):

    - v0 (``artic/Dock-v0`` on the plant, ``artic/DockKIN-v0`` on KIN), 2026-11-27:
      an episode is ``artic dock``'s run, one command at a time (its sensors,
      actuators, failure checks and scores); the same day, ``sensors`` reaches the
      run and an environment dropped without ``close()`` stops its run.
    - v0, 2026-11-28: ``timeout`` and the actions are checked, unknown keywords named.
    - v0, 2026-12-06: unknown reset options, a start that is not an integer in range
      and unknown keywords at ``make`` are refused; the environment keeps its own
      copies of what it returns; an abandoned run is neither scored nor recorded;
      the reward's potential takes numpy's ``hypot`` (it differs from
      ``math.hypot`` in the last bit for 0.6 % of pairs, so a reward may differ
      from the release before in its last bit).

    Examples
    --------
    >>> import gymnasium as gym
    >>> import numpy as np
    >>> env = gym.make("artic.gym:artic/DockKIN-v0", scenario="straight")
    >>> observation, info = env.reset(seed=1, options={"start": 0})
    >>> observation.shape, info["reason"]
    ((17,), '')
    >>> observation, reward, terminated, truncated, info = env.step(np.array([0.0, -0.5]))
    >>> bool(reward > -1.0), terminated, truncated
    (True, False, False)
    >>> env.close()
    """

    metadata = {"render_modes": ["rerun"], "render_fps": 10}

    def __init__(self, scenario: str = "alley", vehicle: str = "gosar2022-unloaded",
                 yard_model: str = "mbd", sensors: str = "full",
                 render_mode: str | None = None,
                 recording_dir: str | Path = "recordings", **drive_options: Any) -> None:
        names = list(SCENARIOS) if scenario == "all" else \
            [s.strip() for s in scenario.split(",") if s.strip()]
        self._scenarios = [find_scenario(n, "scenario") for n in names]
        if not self._scenarios:
            raise UserError("scenario: give at least one name (artic dock --list) or 'all'")
        if render_mode not in (None, "rerun"):
            raise UserError(f"render_mode {render_mode!r}: expected None or 'rerun'")
        if yard_model not in ("mbd", "kin"):
            raise UserError(f"yard_model {yard_model!r}: expected 'mbd' or 'kin'")
        self.vehicle_name = vehicle
        self.vehicle = load_vehicle(vehicle)
        self.yard_model = yard_model
        self.render_mode = render_mode
        self.recording_dir = Path(recording_dir)
        check_drive_options(drive_options)
        self._options = {"sensor_set": sensor_set(sensors, "sensors"), **drive_options}
        self.scale = ActionScale.of(self.vehicle)
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (len(OBSERVATION_NAMES),),
                                                np.float64)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float64)
        self._episode: Episode | None = None
        self._helper: Controller | None = None
        self._last: tuple[np.ndarray, Observation] | None = None
        self._task = None

    # ------------------------------------------------------------------ API
    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        """Start an episode at a seeded start; the first observation and ``info``."""
        options = dict(options or {})
        start = check_reset_options(options)
        super().reset(seed=seed)
        self._close_episode()
        if "scenario" in options:
            scen = find_scenario(options["scenario"], "options['scenario']")
        else:
            scen = self._scenarios[int(self.np_random.integers(len(self._scenarios)))]
        for _ in range(100):  # a start the planner finds no path from is drawn again
            k = int(self.np_random.integers(_STARTS)) if start is None else start
            record = None
            if self.render_mode == "rerun":
                name = run_name(scen.name, self.vehicle.name, "gym", k)
                record = self.recording_dir / f"{name}.rrd"
            self._episode = Episode(scen, self.vehicle_name, k, self.yard_model, record=record,
                                    **self._options)
            first = self._episode.start()
            if first.observation is not None:
                break
            reason = first.result.row["failure"]
            if start is not None:
                raise UserError(f"start {k} of {scen.name}: {reason}; choose another start")
        else:
            raise RuntimeError(f"no start of {scen.name} had a plan in 100 draws")
        self._task = self._episode.task
        self._helper = Controller()
        self._helper.reset(self._task)
        vector = observation_vector(first.observation, self._helper)
        self._last = (vector, first.observation)
        info = {"t": first.observation.t, "scenario": scen.name, "start": k, "reason": ""}
        return vector.copy(), info  # the caller's copy: the episode reads its own

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict]:
        """Hold ``action`` for 0.1 s: observation, reward, terminated, truncated, info."""
        self.post(action)
        return self.receive()

    def post(self, action: np.ndarray) -> None:
        """The first half of :meth:`step`: hand ``action`` to the run and return at once.

        The run computes the next 0.1 s on its own thread until :meth:`receive`
        collects it: the vector environment posts to all its episodes, then
        receives from each, so their plants step side by side.

        Raises
        ------
        UserError
            For an action of another shape than ``(2,)`` or not finite; the episode
            goes on, as if the step had not been asked for.
        """
        if self._episode is None or self._last is None:
            raise RuntimeError("call reset() before step()")
        before, _ = self._last
        cmd = self.scale.command(action)
        if stopped_at_dock(cmd, float(before[-3])):
            cmd = type(cmd)(cmd.delta_h, 0.0, done=True)
        self._episode.post(cmd)

    def receive(self) -> tuple[np.ndarray, float, bool, bool, dict]:
        """The second half of :meth:`step`: observation, reward, terminated, truncated, info."""
        if self._episode is None or self._last is None:
            raise RuntimeError("call post() before receive()")
        before, _ = self._last
        got: Step = self._episode.receive()
        if got.observation is not None:
            vector = observation_vector(got.observation, self._helper)
            self._last = (vector, got.observation)
            reward = step_reward(tuple(before[-3:]), tuple(vector[-3:]))
            return vector.copy(), reward, False, False, {"t": got.observation.t, "reason": ""}
        row = got.result.row
        self._episode = None
        reason = "docked" if row["success"] else str(row["failure"]).split(":")[0]
        truncated = reason in _TRUNCATIONS
        reward = outcome_reward(bool(row["success"]), reason)
        info = {"t": self._last[1].t, "reason": reason, "scores": row}
        return before.copy(), reward, not truncated, truncated, info

    @property
    def observation(self) -> Observation:
        """The last :class:`~artic.validation.docking.controllers.Observation` a controller gets.

        A copy: the run keeps its own (its trace scores what the controller saw).
        """
        if self._last is None:
            raise RuntimeError("call reset() first")
        obs = self._last[1]
        return dataclasses.replace(obs, signals=np.array(obs.signals, dtype=float))

    @property
    def task(self) -> Task:
        """The episode's :class:`~artic.validation.docking.controllers.Task` a controller gets."""
        if self._task is None:
            raise RuntimeError("call reset() first")
        return self._task

    def render(self) -> None:
        """Nothing to draw now: with ``render_mode="rerun"`` each episode is recorded whole."""
        return None

    def close(self) -> None:
        """Stop an unfinished episode."""
        self._close_episode()

    def __del__(self) -> None:
        # An environment dropped without close(): its run's thread would wait for
        # a command for ever, holding its plant open.
        with contextlib.suppress(Exception):
            self._close_episode()

    def _close_episode(self) -> None:
        if self._episode is not None:
            self._episode.close()
            self._episode = None

