"""The truth's records in a log's metadata: its full states and what it was given.

Generation (:mod:`artic.validation.synthetic.generate`) writes them, the floor's
open-loop predictions (:mod:`artic.validation.criteria.prediction`) read them:
the truth's full state at the start-point candidates of a reverse log
(:func:`record_states`, :func:`truth_states`) and its actuation at every step
(:func:`record_actuation`, :func:`recorded_actuation`). Apart from the
predictions, so that making a log imports nothing of the harness it validates.
"""

from __future__ import annotations

import base64
import zlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from artic.mjcf.errors import UserError
from artic.validation.criteria.distance import travelled

SPACING = 10.0
"""Travelled distance between the predictions' start points [m]
(:mod:`artic.validation.criteria.prediction`)."""


def candidates(s: np.ndarray, spacing: float = SPACING) -> np.ndarray:
    """Sample indices of the first sample at or after every ``spacing`` metres of ``s``.

    The start points before the reversing filter of
    :func:`artic.validation.criteria.prediction.start_points`.

    Parameters
    ----------
    s : ndarray
        Travelled distance per sample, non-decreasing [m].
    spacing : float
        Distance between start points [m].
    """
    if s.size == 0:
        return np.zeros(0, dtype=int)
    marks = np.arange(0.0, float(s[-1]) + 0.5 * spacing, spacing)
    idx = np.unique(np.searchsorted(s, marks, side="left"))
    return idx[idx < s.size]


STATE_KEY = "truth_state"
"""The log metadata's key of the truth's recorded states (:func:`record_states`)."""

STATE_MARGIN = 1
"""Samples recorded either side of each candidate [-]. The export rounds the
velocities to 1e-5 m/s, which moves the imported log's travelled distance by
micrometres: a mark that falls that close to a sample moves to its neighbour."""


@dataclass(frozen=True)
class TruthStates:
    """The truth's full states at some samples of a log (:func:`truth_states`)."""

    t: np.ndarray
    """The samples' times [s]."""
    x: np.ndarray
    """One full state per time (``full_state()`` of the truth), float64."""

    def at(self, t: float) -> np.ndarray | None:
        """The state at time ``t`` [s] (within a microsecond), or ``None``."""
        if not self.t.size:
            return None
        i = int(np.argmin(np.abs(self.t - t)))
        return self.x[i] if abs(float(self.t[i]) - t) < 1e-6 else None


def record_states(frame: pd.DataFrame, states: Sequence[np.ndarray],
                  spacing: float = SPACING, margin: int = STATE_MARGIN,
                  also: Sequence[pd.DataFrame] = ()) -> dict:
    """The truth's states at a log's start-point candidates, as JSON-ready metadata.

    Parameters
    ----------
    frame : DataFrame
        The log as measured (its travelled distance places the candidates).
    states : sequence of ndarray
        The truth's full state at every sample of ``frame``.
    spacing : float
        Distance between start points [m].
    margin : int
        Neighbours kept either side of each candidate (:data:`STATE_MARGIN`).
    also : sequence of DataFrame
        Other measurements of the same run on the same samples (its noise-free
        twin): their candidates are kept too, so that the floor finds its
        state at every start point of each (their travelled distances differ
        by the sensors' noise, and so do the samples the marks fall on).

    Returns
    -------
    dict
        ``t`` (the samples' times [s]), ``size`` (numbers per state) and ``x``
        (the states, float64 little-endian, base64): exact, and about a
        kilobyte per sample kept.
    """
    if len(states) != len(frame) or any(len(f) != len(frame) for f in also):
        raise ValueError(f"{len(states)} states and measurements of "
                         f"{[len(f) for f in (frame, *also)]} samples: expected the same")
    k = np.concatenate([candidates(travelled(f), spacing) for f in (frame, *also)])
    keep = np.unique(np.clip((k[:, None] + np.arange(-margin, margin + 1)).ravel(), 0,
                             len(frame) - 1)) if k.size else np.zeros(0, dtype=int)
    x = np.array([states[i] for i in keep], dtype="<f8").reshape(len(keep), -1)
    return {"t": [float(v) for v in frame["t"].to_numpy()[keep]], "size": int(x.shape[1]),
            "x": base64.b64encode(x.tobytes()).decode("ascii")}


def truth_states(meta: dict) -> TruthStates | None:
    """The truth's states a log's metadata holds (:func:`record_states`), or ``None``."""
    rec = meta.get(STATE_KEY)
    if not isinstance(rec, dict):
        return None
    t = np.asarray(rec.get("t", []), dtype=float)
    x = np.frombuffer(base64.b64decode(rec.get("x", "")), dtype="<f8")
    size = int(rec.get("size", 0))
    if size <= 0 or x.size != t.size * size:
        raise UserError(f"{meta.get('name', 'a log')}: metadata {STATE_KEY!r} is damaged "
                         f"({x.size} numbers for {t.size} states of {size}); generate the log "
                         "again")
    return TruthStates(t, x.reshape(t.size, size).astype(float))


ACTUATION_KEY = "truth_actuation"
"""The log metadata's key of the truth's recorded actuation (:func:`record_actuation`)."""

ACTUATION_FIELDS = ("delta", "u1", "u1_dot", "throttle", "brake")
"""What the truth was given at each step: its ``step`` arguments (steering
demand [rad], speed [m/s], speed rate [m/s^2]) and its pedals [-]."""


@dataclass(frozen=True)
class RecordedActuation:
    """The truth's actuation at every step of a log (:func:`recorded_actuation`)."""

    t0: float
    """The time of the sample before the first step [s]."""
    dt: float
    """The step [s]."""
    speed: str
    """The truth's speed mode as it made the log (``"pedals"`` or ``"drive"``)."""
    x: np.ndarray
    """One row of :data:`ACTUATION_FIELDS` per step, float64."""

    def index(self, t: float) -> int | None:
        """The step taken from the sample at time ``t`` [s] (within a microsecond), or ``None``."""
        i = round((t - self.t0) / self.dt)
        ok = 0 <= i < len(self.x) and abs(self.t0 + i * self.dt - t) < 1e-6
        return int(i) if ok else None


def record_actuation(held: Sequence[Sequence[float]], speed: str, dt: float,
                     t0: float = 0.0) -> dict:
    """The truth's actuation at every step, as JSON-ready metadata.

    Parameters
    ----------
    held : sequence
        Per step, the :data:`ACTUATION_FIELDS` the truth was given.
    speed : str
        The truth's speed mode (``"pedals"``, ``"drive"``).
    dt : float
        The step [s].
    t0 : float
        The time of the sample before the first step [s].

    Returns
    -------
    dict
        ``t0``, ``dt``, ``speed``, ``fields`` and ``x`` (the rows, float64
        little-endian, zlib-compressed, base64): exact, so that the floor
        replays them to the bit. About 16 bytes a step (the pedals move in
        ramps and the speed holds, so they compress).
    """
    x = np.asarray(held, dtype="<f8").reshape(-1, len(ACTUATION_FIELDS))
    return {"t0": float(t0), "dt": float(dt), "speed": speed, "fields": list(ACTUATION_FIELDS),
            "x": base64.b64encode(zlib.compress(x.tobytes(), 9)).decode("ascii")}


def recorded_actuation(meta: dict) -> RecordedActuation | None:
    """The truth's actuation a log's metadata holds (:func:`record_actuation`), or ``None``."""
    rec = meta.get(ACTUATION_KEY)
    if not isinstance(rec, dict):
        return None
    try:
        x = np.frombuffer(zlib.decompress(base64.b64decode(rec.get("x", ""))), dtype="<f8")
        ok = list(rec.get("fields", [])) == list(ACTUATION_FIELDS) and float(rec["dt"]) > 0.0
    except (zlib.error, ValueError, TypeError, KeyError):
        ok = False
    if not ok or x.size % len(ACTUATION_FIELDS):
        raise UserError(f"{meta.get('name', 'a log')}: metadata {ACTUATION_KEY!r} is damaged; "
                        "generate the log again")
    return RecordedActuation(float(rec.get("t0", 0.0)), float(rec["dt"]), str(rec["speed"]),
                             x.reshape(-1, len(ACTUATION_FIELDS)).astype(float))
