"""Frequency response: gain and phase of the yaw rates and the articulation against the steering.

The classic validation of a handling model beside its time histories: the
transfer function from the steering-wheel angle ``delta_h`` [rad] to the
tractor's and the semitrailer's yaw rates ``r_1``, ``r_2`` [rad/s] and the
articulation ``gamma`` [rad], per frequency band, of each model against the
truth's, from the test matrix's swept sine
(:func:`artic.validation.synthetic.manoeuvres.swept_sine`: 90 deg of steering
wheel at 10 km/h, 0.05 to 0.8 Hz).

**The estimator.** ``H(f) = sum Y U* / sum |U|^2`` over the Fourier bins of
each third-octave band (:data:`CENTRES`; the record is zero-padded
:data:`PAD` times, so the lowest band holds several bins), ``U`` and ``Y``
the transforms of input and output less their means: the band-averaged
cross-spectral (H1) estimate. It is unbiased by noise on the output (the log's
sensors) and needs only the input each system actually received, not how it
was chosen.

**The bound.** A model's response departs from the truth's in a band where its
gain differs by more than :data:`GAIN_BOUND` (10 %, 0.8 dB) or its phase by more
than :data:`PHASE_BOUND` (10 deg). No standard sets them for an articulated
vehicle; they are the corridor a practitioner reads off a Bode plot at a
glance, and 10 % is where ISO/TS 18571's corridor score of a sine starts to
fall below 0.9 (its inner corridor is 5 % of the peak either side).
:func:`departure` gives the lowest band centre where the bound is first
exceeded, NaN where never within the sweep.

**Forward only, open loop.** The models are driven open loop by the log's own
steering and speed (:func:`artic.validation.harness.simulate.simulate`), which
is sound forward: every model is stable there. Reversing, the semitrailer's
articulation is open-loop unstable (a steady steer jackknifes), so an open-loop
sweep diverges, and a closed-loop one measures the driver's loop as much as the
vehicle (the input is then correlated with the output's noise, which biases H1);
artic leaves the reversing frequency response out rather than report either.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from artic.validation.synthetic.manoeuvres import SWEEP_F0

if TYPE_CHECKING:
    from artic.validation.logs.runfile import Run

SIGNALS = ("r_1", "r_2", "gamma")
"""The outputs, against ``delta_h``."""

CENTRES = tuple(SWEEP_F0 * 2.0 ** (k / 3.0) for k in range(1, 12))
"""The band centres [Hz]: third octaves from one above the sweep's first frequency
to one below its last (the bands at the ends are half outside the sweep)."""

PAD = 8
"""Zero-padding factor of the transforms [-]."""

GAIN_BOUND = 0.10
"""The largest relative gain error inside the bound [-]."""

PHASE_BOUND = 10.0
"""The largest phase error inside the bound [deg]."""


def response(t: np.ndarray, u: np.ndarray, y: np.ndarray,
             centres: Iterable[float] = CENTRES) -> np.ndarray:
    """The band-averaged transfer function from ``u`` to ``y`` at each band centre.

    Parameters
    ----------
    t : ndarray
        Uniform sample times [s].
    u, y : ndarray
        Input and output, as many samples [their units].
    centres : iterable of float
        Third-octave band centres [Hz].

    Returns
    -------
    ndarray of complex
        ``H`` per band [unit of y / unit of u]; NaN for a band without input.
    """
    t = np.asarray(t, dtype=float)
    dt = float(np.median(np.diff(t)))
    n = PAD * t.size
    big_u = np.fft.rfft(np.asarray(u, float) - np.mean(u), n)
    big_y = np.fft.rfft(np.asarray(y, float) - np.mean(y), n)
    f = np.fft.rfftfreq(n, dt)
    out = []
    for c in centres:
        band = (f >= c * 2.0 ** (-1 / 6)) & (f < c * 2.0 ** (1 / 6))
        suu = float(np.sum(np.abs(big_u[band]) ** 2))
        out.append(np.sum(big_y[band] * np.conj(big_u[band])) / suu if suu > 0 else np.nan)
    return np.asarray(out, dtype=complex)


def bode(run: Run, centres: Iterable[float] = CENTRES) -> pd.DataFrame:
    """Gain and phase of :data:`SIGNALS` against ``delta_h`` of one run or log.

    Returns
    -------
    DataFrame
        One row per (signal, band): ``signal``, ``f`` [Hz], ``gain`` [unit per rad of
        steering wheel], ``phase`` [deg], unwrapped along the bands.
    """
    frame = run.frame
    centres = tuple(centres)
    rows = []
    for s in SIGNALS:
        h = response(frame["t"].to_numpy(), frame["delta_h"].to_numpy(), frame[s].to_numpy(),
                     centres)
        phase = np.degrees(np.unwrap(np.angle(h)))
        rows += [{"signal": s, "f": c, "gain": abs(x), "phase": p}
                 for c, x, p in zip(centres, h, phase, strict=True)]
    return pd.DataFrame(rows)


def compare(truth: Run, runs: dict[str, Run]) -> pd.DataFrame:
    """Each model's gain and phase against the truth's, per signal and band.

    Parameters
    ----------
    truth : Run
        The measured log of the swept sine.
    runs : dict of str to Run
        Per model, its run driven by the log's steering.

    Returns
    -------
    DataFrame
        ``model``, ``signal``, ``f`` [Hz], ``gain``, ``gain_truth``, ``gain_error`` [-]
        (relative), ``phase``, ``phase_truth``, ``phase_error`` [deg].
    """
    ref = bode(truth).rename(columns={"gain": "gain_truth", "phase": "phase_truth"})
    parts = []
    for name, run in runs.items():
        b = bode(run).merge(ref, on=["signal", "f"])
        b.insert(0, "model", name)
        b["gain_error"] = b["gain"] / b["gain_truth"] - 1.0
        # the model's phase less the truth's, wrapped to [-180, 180)
        b["phase_error"] = (b["phase"] - b["phase_truth"] + 180.0) % 360.0 - 180.0
        parts.append(b)
    cols = ["model", "signal", "f", "gain", "gain_truth", "gain_error", "phase", "phase_truth",
            "phase_error"]
    return pd.concat(parts, ignore_index=True)[cols]


def departure(table: pd.DataFrame, gain_bound: float = GAIN_BOUND,
              phase_bound: float = PHASE_BOUND) -> pd.DataFrame:
    """The lowest band centre where each model's error on each signal exceeds the bound [Hz].

    Returns
    -------
    DataFrame
        Index the models, columns :data:`SIGNALS`; NaN where no band exceeds it.
    """
    out: dict[str, dict[str, float]] = {}
    for (model, signal), g in table.groupby(["model", "signal"], sort=False):
        over = g[(g["gain_error"].abs() > gain_bound) | (g["phase_error"].abs() > phase_bound)]
        out.setdefault(model, {})[signal] = float(over["f"].min()) if len(over) else math.nan
    return pd.DataFrame.from_dict(out, orient="index")[list(SIGNALS)]
