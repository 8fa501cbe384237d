"""``eps_n_fixed``: the normalised error with one fixed scale per direction of travel.

The paper's ``eps_n`` (eq. 9, :mod:`artic.validation.criteria.metrics`) divides each
run's yaw-rate and lateral-velocity errors by that run's own
distance-averaged mean of the measured ``|r|`` and ``|v_y|``:

    eps_n = 100 (eps_a / (mean|r_1| + mean|r_2|) + eps_v / (mean|v_y1| + mean|v_y2|))

In reverse the lateral velocities are small (0.08-0.35 m/s mean), and the
sensors' noise (about 1 cm/s) already gives ``eps_v`` of a perfect model a
size that, divided by them, makes most of ``eps_n``; a run with little
lateral motion then scores badly however good the model, and the score of a
fixed model changes from run to run with the run's own signal size.

``eps_n_fixed`` keeps the numerators and divides by one scale per direction
instead, the same for every run of that direction:

    eps_n_fixed = 100 (eps_a / (R_1 + R_2) + eps_v / (V_1 + V_2))

where ``R_i`` and ``V_i`` are the distance-weighted RMS of the measured
``r_i`` and ``v_yi`` pooled over all the logs of that direction
(``sqrt(sum_logs integral r_i**2 ds / sum_logs s_max)``: eq. (8) applied to
the signal, over the whole set). A run's ``eps_n_fixed`` is then its error
in a unit common to the set, so runs, manoeuvres and models compare on one
scale; it does not change when a run's own signals are larger or smaller.
The scale is computed once per campaign (over the validated logs) and once
per ``artic validate`` call (over its logs), written to
:data:`SCALE_FILE` beside ``metrics.csv``, and used for the references
(the floor, the plant as reference) too.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from artic.validation.criteria.direction import DIRECTIONS, direction_of
from artic.validation.criteria.distance import distance_weights
from artic.validation.criteria.metrics import NOISE_FLOOR
from artic.validation.logs.runfile import Run, atomic_write_text

SCALE_FILE = "eps_n_fixed_scale.json"
"""Where the scale is written, beside ``metrics.csv``."""

SIGNALS = ("r_1", "r_2", "v_y_1", "v_y_2")

Scale = dict[str, dict[str, float]]
"""Per direction: the pooled RMS of each of :data:`SIGNALS` [rad/s, m/s], ``s`` [m] and ``logs``."""


def campaign_scale(logs: Sequence[Run]) -> Scale:
    """The pooled distance-RMS of the measured yaw rates and lateral velocities, per direction.

    Parameters
    ----------
    logs : sequence of Run
        The logs whose runs are scored (each direction from
        :func:`artic.validation.criteria.direction.direction_of`).

    Returns
    -------
    dict
        ``{direction: {"r_1": ..., "r_2": ..., "v_y_1": ..., "v_y_2": ..., "s": metres,
        "logs": count}}`` for each direction with logs.
    """
    sums: dict[str, dict[str, float]] = {}
    for log in logs:
        f = log.frame
        if len(f) < 2:
            continue
        w = distance_weights(f["t"].to_numpy(dtype=float),
                             np.hypot(f["v_x_1"].to_numpy(dtype=float),
                                      f["v_y_1"].to_numpy(dtype=float)))
        acc = sums.setdefault(direction_of(log), dict.fromkeys((*SIGNALS, "s", "logs"), 0.0))
        for c in SIGNALS:
            acc[c] += float(np.sum(w * np.square(f[c].to_numpy(dtype=float))))
        acc["s"] += float(np.sum(w))
        acc["logs"] += 1
    out: Scale = {}
    for d in DIRECTIONS:
        acc = sums.get(d)
        if acc is None or acc["s"] <= 0.0:
            continue
        out[d] = {c: float(np.sqrt(acc[c] / acc["s"])) for c in SIGNALS}
        out[d] |= {"s": acc["s"], "logs": int(acc["logs"])}
    return out


def eps_n_fixed(eps_a: float, eps_v: float, scale: Mapping[str, float] | None) -> float:
    """``100 (eps_a / (R_1 + R_2) + eps_v / (V_1 + V_2))`` [%], or NaN without a usable scale.

    Parameters
    ----------
    eps_a, eps_v : float
        The run's yaw-rate and lateral-velocity errors, eq. (9) [rad/s, m/s].
    scale : mapping, optional
        One direction's entry of :func:`campaign_scale`. Below the
        :data:`artic.validation.criteria.metrics.NOISE_FLOOR` dividing by it means nothing.
    """
    if not scale:
        return float("nan")
    r = scale["r_1"] + scale["r_2"]
    v = scale["v_y_1"] + scale["v_y_2"]
    if not (r > NOISE_FLOOR["r"] and v > NOISE_FLOOR["v_y"]):
        return float("nan")
    return 100.0 * (eps_a / r + eps_v / v)


def write_scale(scale: Scale, path: Path) -> Path:
    """Write the scale as JSON, atomically, with what it is."""
    doc = {"what": "eps_n_fixed = 100 (eps_a / (r_1 + r_2) + eps_v / (v_y_1 + v_y_2)) with "
                   "the distance-weighted RMS of each measured signal pooled over the logs of "
                   "the run's direction [rad/s, m/s]; s is their distance [m]",
           "scale": scale}
    return atomic_write_text(Path(path), json.dumps(doc, indent=1) + "\n")
