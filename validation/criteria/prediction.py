"""Open-loop prediction errors for reversing: the reversing model itself, not the loop.

Under the harness's feedback (K = 3) the loop pulls a model's articulation
onto the measured one within about 1.5 m of travel, so the paper's reverse
criteria measure steering effort more than the model. Here the model runs
without feedback for a short travelled distance from measured states:

1. **Start points.** Along a reverse log, the first sample at or after every
   :data:`SPACING` metres of the tractor sensor's travelled distance (the
   ``s`` of eq. (8), :func:`artic.validation.criteria.metrics.travelled`) at which the
   harness sees the tractor reversing.
2. **Start.** Every model starts in a state consistent with the motion at
   that sample (see *Consistent starts* below), and is driven by the log's
   steering (through the model's eq. (3) map) and smoothed speed, exactly
   the harness's inputs (:func:`artic.validation.harness.loop.window`), with
   K = 0: the model's own ``step``/``observe`` in the harness's loop, no
   feedback.
3. **Score.** At the first sample at or after ``H`` metres of travel from
   the start, for each horizon ``H`` of :data:`HORIZONS`: the distance
   between the model's and the measured semitrailer axle-group centre
   (``-L2`` behind the kingpin, from each one's semitrailer sensor,
   :mod:`artic.validation.criteria.points`) moved since the start, model
   against measurement [m], and the magnitude of the wrapped articulation
   difference [rad].

The position error compares displacements, ``|(p(H) - p(0))_model -
(p(H) - p(0))_measured|``, not positions: the model's semitrailer is placed at
the start from the tractor's pose and the articulation, as the harness
places it, and its sensor's lever arm and mounting yaw differ from the
measuring rig's by centimetres and a fraction of a degree. That offset is
there before the model has predicted anything (5-7 cm for every model on the
synthetic campaign's noise-free logs, against the preset's geometry) and
would lie under every horizon alike. The articulation starts equal to the
measured one by construction.

``pred_p_<H>m`` and ``pred_gamma_<H>m`` are the means over the start points.
One run to the longest horizon serves all three. A start point with less
than ``H`` metres of log after it does not count for ``H``; when no start
point has (a log shorter than the horizon) the column is NaN, and the run's
``meta["prediction"]["note"]`` says so. A model that passes the jackknife
limit before a horizon scores its error where it stopped, a lower bound.
Forward logs have no prediction errors (NaN).

**Consistent starts.** A model reset with its hidden states zeroed starts
a transient the measured vehicle was not in: at full lock a truth whose
column, assist and tyres are relaxed mispredicted its own 10 m articulation
by degrees. So each model starts from what it would be in at that sample:

- **the floor** (the truth, :func:`truth_states`) from the truth's own full
  state there, which generation records at the start-point candidates
  (:func:`record_states`): ``set_full_state`` of the vector ``full_state()``
  returned while the truth made the log (MuJoCo's ``qpos``, ``qvel``,
  ``act`` and the rest: tyre deflections, column, assist). Where a log holds
  no state for a start point (a log made before states were recorded, or a
  start point that moved on import past the recorded neighbours) the floor
  leaves that start point out. Started, the floor does not take the
  harness's inputs: it replays what the truth was given at every step
  making the log (:class:`Replay`, :func:`recorded_actuation`), its steering
  demand and its driver's pedals, so that it is the reference of what a
  perfect model could predict;
- **a model with** ``reset_steady(initial)`` (the plant, :meth:`artic.plant.Plant.reset_steady`)
  from its steady state matching the measured motion: steering at the
  log's road-wheel angle, wheels spinning at their rolling speed, tyre
  deflections at the slip the motion gives;
- **any other model** (KIN, the STM) from ``reset(initial)``, its state being
  the measured one (the STM's lagged slips already start at their steady state).

Left-out start points are counted in ``meta["prediction"]["left_out"]`` and
named in its note; the means are over the start points used. On the truth's
noise-free logs of seed 0 the floor so started and replaying predicts itself
to within 0.014 mm and 1e-5 deg at every start point and horizon, on the
ramp steers and on docking and parking alike (152 start points, none left out;
``tests/test_floor_prediction.py``): the export's digits.
Driven instead through the harness's speed follower, as the models under
validation are, it missed by up to 6.6 cm at 10 m on one docking shuffle at
full lock: the follower spreads drive and braking over the wheels otherwise
than the truth's pedals did. A log made before the actuation was recorded
has the floor driven by the follower, and its note says so.

**Spacing.** Every start point drives the model up to the longest horizon,
so a spacing ``S`` costs about ``10 m / S`` open-loop runs of the log. Every
10 m, the windows tile the log: a 35-50 m log gives 3-5 start points, the
campaign's 33 reverse logs 163, and the plant simulates 1580 s for them,
0.76 of the logs' own 2090 s: about 12 s of the campaign's wall time for
``mbd`` and ``floor`` on two cores. Every 5 m would cost 23 s and every 2 m
56 s, for start points whose windows overlap and whose errors are
therefore correlated.
KIN and the STM cost next to nothing at any spacing (one compiled call per
start point), but they use the same start points as the plant, so that the
models are compared on the same measured states.
"""

from __future__ import annotations

import hashlib
import json
import math
import pickle
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from artic.mjcf.interface import InitialState, wrap_angle
from artic.mjcf.vehicle import Vehicle
from artic.validation.criteria.direction import direction_of
from artic.validation.criteria.distance import travelled
from artic.validation.criteria.points import axle_x, trailer_point
from artic.validation.criteria.truthrecords import (  # noqa: F401  (their home before)
    ACTUATION_FIELDS,
    ACTUATION_KEY,
    SPACING,
    STATE_KEY,
    STATE_MARGIN,
    RecordedActuation,
    TruthStates,
    candidates,
    record_actuation,
    record_states,
    recorded_actuation,
    truth_states,
)
from artic.validation.harness.loop import loop_inputs, run_inputs, window
from artic.validation.logs.runfile import Run
from artic.validation.models import Model, driven, steering_for

HORIZONS = (2.0, 5.0, 10.0)
"""Travelled distances of the predictions [m]."""


def columns(horizons: tuple[float, ...] = HORIZONS) -> tuple[str, ...]:
    """Column names: ``pred_p_<H>m`` for every horizon, then ``pred_gamma_<H>m``."""
    return (*(f"pred_p_{h:g}m" for h in horizons), *(f"pred_gamma_{h:g}m" for h in horizons))


COLUMNS = columns()
UNITS = {c: ("m" if c.startswith("pred_p") else "rad") for c in COLUMNS}


def start_points(s: np.ndarray, reversing: np.ndarray, spacing: float = SPACING) -> np.ndarray:
    """Sample indices of the start points (see the module docstring).

    Parameters
    ----------
    s : ndarray
        Travelled distance per sample, non-decreasing [m].
    reversing : ndarray of bool
        Whether the harness sees the tractor reversing, per sample.
    spacing : float
        Distance between start points [m].
    """
    idx = candidates(s, spacing)
    return idx[np.asarray(reversing, dtype=bool)[idx]]


class Replay:
    """The truth replaying its own actuation: the floor of the open-loop predictions.

    The harness drives every model with the log's steering and smoothed speed
    (the floor through its speed follower). Replaying, the truth ignores them
    and takes at every step what it was given making the log
    (:func:`recorded_actuation`): its steering demand and its driver's
    pedals. Started from its own full state (:func:`truth_states`) it then
    retraces its log: what a perfect model could predict.

    Parameters
    ----------
    truth : Model
        The truth that made the log, in its speed mode then (``actuation.speed``),
        with ``full_state``/``set_full_state`` and ``pedals``.
    actuation : RecordedActuation
        What it was given.
    """

    def __init__(self, truth, actuation: RecordedActuation) -> None:
        self.truth = truth
        self.actuation = actuation
        self.name = truth.name
        self.budget_kind = getattr(truth, "budget_kind", "multibody")
        self._k = 0

    def start(self, x: np.ndarray, k: int) -> None:
        """Restore the truth's state ``x`` at the sample of step ``k``."""
        self.truth.set_full_state(x)
        self._k = k

    def reset(self, initial: InitialState) -> None:
        """Refused: the replay starts only from the truth's own state (:meth:`start`)."""
        raise ValueError("the replaying truth starts only from its recorded state")

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s] with the recorded step (the arguments are the harness's, unused)."""
        if self._k >= len(self.actuation.x):
            raise ValueError(f"the recorded actuation ends after {len(self.actuation.x)} steps")
        d, u, u_dot, throttle, brake = self.actuation.x[self._k]
        self.truth.pedals = (float(throttle), float(brake))
        self.truth.step(dt, float(d), float(u), float(u_dot))
        self._k += 1

    def observe(self, delta: float | None = None) -> np.ndarray:
        """The truth's signals."""
        return self.truth.observe(delta)

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""
        return self.truth.gamma

    def compiled(self) -> None:
        """No compiled form: the harness's Python loop drives it."""
        return None

    def closed_loop(self) -> Callable | None:
        """The truth's compiled loop replaying its rows from the present one, or ``None``.

        A truth with ``replay_loop`` (the yard truth,
        :mod:`artic.validation.synthetic.yardloop`) runs the harness's loop in C,
        taking each step from the recorded row as :meth:`step` does; the rows
        are the Python loop's to the bit. Other truths: ``None``, the Python loop.
        """
        make = getattr(self.truth, "replay_loop", None)
        if not callable(make):
            return None
        inner = make(lambda: (self.actuation.x, self._k))
        if inner is None:
            return None

        def loop(args, extras: bool = False):
            res = inner(args, extras)
            self._k = res.act_k
            return res

        return loop

    def close(self) -> None:
        """Close the truth."""
        self.truth.close()


Start = Callable[[InitialState], None]
"""How a model is put into its state at a start point, given the log's state there."""


def starter(model: Model, states: TruthStates | None, t: float) -> Start | None:
    """How ``model`` starts at a start point (see *Consistent starts*).

    Parameters
    ----------
    model : Model
        The model to start.
    states : TruthStates, optional
        The truth's states, when ``model`` is the truth (the floor).
    t : float
        The start point's time in the log [s].

    Returns
    -------
    callable or None
        ``start(initial)``: ``set_full_state`` of the truth's state at ``t``,
        the model's ``reset_steady``, or its ``reset``; ``None`` when it
        cannot start there consistently (``states`` hold none at ``t``).
    """
    if states is not None:
        x = states.at(t)
        if x is None:
            return None
        if isinstance(model, Replay):
            k = model.actuation.index(t)
            if k is None:
                return None
            return lambda _initial: model.start(x, k)
        return lambda _initial: model.set_full_state(x)
    steady = getattr(model, "reset_steady", None)
    return steady if callable(steady) else model.reset


REPLAY_MARGIN = 8
"""Samples a floor's replay runs past its longest horizon, for a noise-free twin to reuse.

The replay ignores the harness's inputs (:class:`Replay`), so its run from a start
point is the same whatever the sensors measured; a twin's start points are
mostly the log's samples, and its horizons end within a sample or two of the
log's (its travelled distance is the noise-free one). Eight samples more
(80 ms at the logs' 100 Hz) cover that at under 1 % of the replay's steps.
"""


@dataclass
class ReplayRuns:
    """A floor's replay runs on one truth run, for its other measurement to reuse.

    Attributes
    ----------
    digest : str
        What the runs depend on (:func:`replay_digest`); another log reuses them
        only where its digest is the same.
    runs : dict
        Per start sample: the observations (:func:`run_inputs`'s ``obs``) and
        the rows computed.
    """

    digest: str
    runs: dict[int, tuple[np.ndarray, int]] = field(default_factory=dict)


def replay_digest(replay: Replay, states: TruthStates, log: Run, vehicle: Vehicle,
                  t: np.ndarray) -> str:
    """A digest of everything a floor's replay run depends on: not of the measured signals.

    The truth's vehicle and configuration, its recorded actuation and states,
    and the samples' times ``t`` [s] (the harness steps between them).
    """
    h = hashlib.sha256()
    h.update(pickle.dumps(vehicle, protocol=5))
    h.update(json.dumps(log.meta.get("truth") or {}, sort_keys=True, default=str).encode())
    act = replay.actuation
    h.update(repr((act.speed, float(act.dt), float(act.t0))).encode())
    for a in (act.x, states.t, states.x, t):
        a = np.ascontiguousarray(a, dtype=float)
        h.update(repr(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def horizon_ends(s: np.ndarray, starts: np.ndarray, horizons=HORIZONS) -> np.ndarray:
    """Per start point and horizon, the first sample ``H`` metres on, or -1 past the log's end."""
    target = s[starts][:, None] + np.asarray(horizons, dtype=float)[None, :]
    ends = np.searchsorted(s, target, side="left")
    return np.where(ends < s.size, ends, -1)


def prediction_errors(model: Model, log: Run, vehicle: Vehicle, spacing: float = SPACING,
                      horizons: tuple[float, ...] = HORIZONS,
                      states: TruthStates | None = None, per_start: bool = False,
                      share: ReplayRuns | bool | None = None) -> dict:
    """The open-loop prediction errors of a model on one log.

    Parameters
    ----------
    model : Model
        Built from ``vehicle``; it is started again at every start point
        (:func:`starter`).
    log : Run
        The measured log.
    vehicle : Vehicle
        The parameters the model was built from: its steering map for
        ``model.name``, the semitrailer's ``L2`` and sensor lever arm.
    spacing : float
        Distance between start points [m].
    horizons : tuple of float
        Travelled distances [m].
    states : TruthStates, optional
        The truth's states, for the floor: ``model`` (the truth) starts from
        them (``set_full_state``), and a start point without one is left out.
    per_start : bool
        Also return ``per_start``: the start points' times [s] (``t``) and
        their errors per horizon (``p`` [m], ``gamma`` [rad], NaN where not
        scored), arrays.
    share : ReplayRuns or bool, optional
        For the floor's replay (``model`` a :class:`Replay`) only: ``True``
        returns its runs as ``replays`` (a :class:`ReplayRuns`), each
        :data:`REPLAY_MARGIN` samples longer where the log and the actuation
        allow; a :class:`ReplayRuns` of the same truth run (the measured log's,
        for its noise-free twin) is reused where its digest, start sample and
        length fit, the rest run and returned too. The errors are the same to
        the bit either way: the replay's run does not depend on the measured
        signals, and a longer run's rows are the shorter one's.

    Returns
    -------
    dict
        The :func:`columns` [m, rad]; ``starts`` (start points used for the
        shortest horizon), ``left_out`` (start points the model could not
        start at consistently), ``stopped`` (predictions that passed the
        jackknife limit or stopped being finite), ``note`` (why a column is
        NaN or start points were left out, or ``""``) and ``wall_s`` [s].
    """
    model = driven(model)  # KIN and the STM with a state the harness keeps
    t0 = time.perf_counter()
    names = columns(horizons)
    out: dict = dict.fromkeys(names, float("nan")) | {"starts": 0, "left_out": 0,
                                                       "stopped": 0, "note": ""}
    if direction_of(log) != "reverse":
        return out | {"note": "not a reverse log", "wall_s": time.perf_counter() - t0}
    frame = log.frame
    steering = steering_for(vehicle, model)
    inputs = loop_inputs(log, vehicle, steering)
    s = travelled(frame)
    starts = start_points(s, inputs.reversing, spacing)
    ends = horizon_ends(s, starts, horizons)
    xa = axle_x(vehicle)
    ax, ay = trailer_point(vehicle, xa, frame["x_2"].to_numpy(dtype=float),
                           frame["y_2"].to_numpy(dtype=float),
                           frame["psi_2"].to_numpy(dtype=float))
    err_p = np.full(ends.shape, np.nan)
    err_g = np.full(ends.shape, np.nan)
    stopped = left_out = 0
    kept = reuse = None
    if share is not None and share is not False and isinstance(model, Replay) \
            and states is not None:
        kept = ReplayRuns(replay_digest(model, states, log, vehicle, inputs.t))
        if isinstance(share, ReplayRuns) and share.digest == kept.digest:
            reuse = share
    for i, k in enumerate(starts):
        fits = ends[i] >= 0
        if not fits.any():
            continue
        start = starter(model, states, float(inputs.t[k]))
        if start is None:
            left_out += 1
            continue
        stop = int(ends[i][fits].max()) + 1
        if kept is None:
            obs, _, _, _, n = run_inputs(model, window(inputs, frame, int(k), stop), vehicle,
                                         gain=0.0, start=start)
        else:
            obs, n = _replayed(model, inputs, frame, vehicle, int(k), stop, start, kept,
                               reuse)
        stopped += int(n < stop - k)
        for j in np.flatnonzero(fits):
            m = min(int(ends[i, j]) - int(k), n - 1)  # where it stopped: a lower bound
            if not np.all(np.isfinite(obs[m])):
                continue
            px, py = trailer_point(vehicle, xa, obs[[0, m], 6], obs[[0, m], 7],
                                   obs[[0, m], 8])
            err_p[i, j] = math.hypot(float(px[1] - px[0]) - (ax[k + m] - ax[k]),
                                     float(py[1] - py[0]) - (ay[k + m] - ay[k]))
            err_g[i, j] = abs(float(wrap_angle(float(obs[m, 12] - inputs.gamma_meas[k + m]))))
    short = []
    for j, h in enumerate(horizons):
        ok = np.isfinite(err_p[:, j])
        if ok.any():
            out[names[j]] = float(np.mean(err_p[ok, j]))
            out[names[len(horizons) + j]] = float(np.mean(err_g[ok, j]))
        elif not (ends[:, j] >= 0).any():
            short.append(f"{h:g} m")
    notes = []
    if left_out:
        usable = int((ends >= 0).any(axis=1).sum())
        notes.append(f"{left_out} of {usable} start points left out: the log holds no "
                     "state of the truth there (generate it again)")
    if short:
        notes.append(f"no start point has {' or '.join(short)} of reverse travel after it "
                     f"(the log reverses {s[-1]:.1f} m)" if s.size else "an empty log")
    out["note"] = "; ".join(notes)
    out["starts"] = int(np.isfinite(err_p[:, 0]).sum()) if len(starts) else 0
    out["left_out"] = left_out
    out["stopped"] = stopped
    if kept is not None:
        out["replays"] = kept
    if per_start:
        out["per_start"] = {"t": inputs.t[starts], "p": err_p, "gamma": err_g}
    out["wall_s"] = time.perf_counter() - t0
    return out


def _replayed(model: Replay, inputs, frame, vehicle: Vehicle, k: int, stop: int, start: Start,
              kept: ReplayRuns, reuse: ReplayRuns | None) -> tuple[np.ndarray, int]:
    """The replay's run from sample ``k`` to ``stop``: reused, or run :data:`REPLAY_MARGIN` longer.

    Returns ``run_inputs``'s ``obs`` and ``n_done`` of the run to ``stop``
    exactly; the longer run is kept in ``kept`` for the twin.
    """
    got = reuse.runs.get(k) if reuse is not None else None
    if got is not None and len(got[0]) >= stop - k:
        kept.runs[k] = got
        return got[0][:stop - k], min(got[1], stop - k)
    act = model.actuation
    first = act.index(float(inputs.t[k]))
    room = k + 1 + len(act.x) - first if first is not None else stop
    longer = max(stop, min(stop + REPLAY_MARGIN, len(frame), room))
    try:
        obs, _, _, _, n = run_inputs(model, window(inputs, frame, k, longer), vehicle,
                                     gain=0.0, start=start)
    except Exception:  # noqa: BLE001 - failing in the margin: run as asked, as it would
        obs, _, _, _, n = run_inputs(model, window(inputs, frame, k, stop), vehicle,
                                     gain=0.0, start=start)
        return obs, n
    kept.runs[k] = (obs, n)
    return obs[:stop - k], min(n, stop - k)
