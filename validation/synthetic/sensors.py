"""Sensor models of a measured run: RTK GNSS, the inertial unit, the CAN bus.

Figures typical of an RTK-corrected automotive INS (such as the paper's OXTS
RT3000) and of a truck CAN bus:

- position: RTK noise as a first-order Gauss-Markov process, 10 mm standard
  deviation, 5 s correlation time;
- heading: Gauss-Markov, 0.05 deg, 10 s;
- velocities: white, 10 mm/s;
- yaw rate: white, 0.005 deg/s per sample at 100 Hz, plus a constant bias
  per run of standard deviation 0.01 deg/s;
- steering-wheel angle: sampled at 10 Hz, 50 ms late, in 0.1 deg steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from artic.mjcf.interface import wrap_angle


@dataclass(frozen=True)
class SensorModel:
    """Noise and sampling of the measurement chain (SI units)."""

    pos_sigma: float = 0.01
    pos_tau: float = 5.0
    heading_sigma: float = math.radians(0.05)
    heading_tau: float = 10.0
    vel_sigma: float = 0.01
    rate_sigma: float = math.radians(0.005)
    rate_bias_sigma: float = math.radians(0.01)
    can_rate: float = 10.0
    can_delay: float = 0.05
    can_step: float = math.radians(0.1)
    trailer_skew: float = 0.0
    """Clock offset of the semitrailer's unit [s]: it stamps its samples this late."""

    @classmethod
    def ideal(cls) -> SensorModel:
        """Sensors that report the truth: no noise, the steering wheel at 100 Hz, unquantised."""
        return cls(pos_sigma=0.0, heading_sigma=0.0, vel_sigma=0.0, rate_sigma=0.0,
                   rate_bias_sigma=0.0, can_rate=100.0, can_delay=0.0, can_step=0.0)

    @property
    def is_ideal(self) -> bool:
        """Whether :func:`measure` returns the true signals unchanged."""
        return self == SensorModel.ideal()


TRAILER_CHANNELS = ("x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2")
"""The semitrailer unit's signals: those its clock's skew shifts."""


def trailer_taken(t, model: SensorModel):
    """When the semitrailer unit took the sample it stamps ``t`` [s]: ``t - trailer_skew``.

    Its clock runs ``trailer_skew`` ahead, so a stream aligned by the stamps
    holds, at ``t``, the semitrailer as it was ``trailer_skew`` earlier.
    """
    return t - model.trailer_skew


def can_sample(i, dt: float, model: SensorModel):
    """The step whose steering-wheel angle the CAN bus reports at step ``i`` (may be < 0).

    The bus samples every ``1 / can_rate`` [s] and delivers ``can_delay``
    [s] late, on a grid of ``dt`` [s]; the caller clips at the first step.
    """
    step = max(1, round(1.0 / (model.can_rate * dt)))
    return (i // step) * step - round(model.can_delay / dt)


def can_quantise(delta_h, model: SensorModel):
    """The steering-wheel angle in the bus's steps of ``can_step`` [rad] (as given if 0)."""
    return np.round(delta_h / model.can_step) * model.can_step if model.can_step > 0 else delta_h


def gauss_markov(rng: np.random.Generator, n: int, dt: float, sigma: float,
                 tau: float) -> np.ndarray:
    """A stationary first-order Gauss-Markov sequence."""
    a = math.exp(-dt / tau)
    w = rng.normal(0.0, sigma * math.sqrt(1 - a * a), n)
    x = np.empty(n)
    x[0] = rng.normal(0.0, sigma)
    for k in range(1, n):
        x[k] = a * x[k - 1] + w[k]
    return x


def measure(frame: pd.DataFrame, rng: np.random.Generator,
            model: SensorModel = SensorModel()) -> pd.DataFrame:
    """What the sensors report of a true run in the signal schema.

    Parameters
    ----------
    frame : DataFrame
        True signals, 100 Hz.
    rng : Generator
        Random numbers for this run.
    model : SensorModel
        Noise figures.

    Returns
    -------
    DataFrame
        Measured signals, same schema; ``delta_h`` as the CAN bus delivers it
        (10 Hz, held, late, quantised).
    """
    out = frame.copy()
    if model.is_ideal:
        return out
    t = frame["t"].to_numpy()
    n, dt = len(t), float(np.median(np.diff(t)))
    for i in (1, 2):
        for c in ("x", "y"):
            out[f"{c}_{i}"] = frame[f"{c}_{i}"] + gauss_markov(rng, n, dt, model.pos_sigma,
                                                              model.pos_tau)
        out[f"psi_{i}"] = frame[f"psi_{i}"] + gauss_markov(rng, n, dt, model.heading_sigma,
                                                          model.heading_tau)
        for c in ("v_x", "v_y"):
            out[f"{c}_{i}"] = frame[f"{c}_{i}"] + rng.normal(0.0, model.vel_sigma, n)
        out[f"r_{i}"] = (frame[f"r_{i}"] + rng.normal(0.0, model.rate_sigma, n)
                         + rng.normal(0.0, model.rate_bias_sigma))
    if model.trailer_skew:
        # A sample stamped t was taken at t - skew: resample the trailer's signals.
        for c in TRAILER_CHANNELS:
            out[c] = np.interp(trailer_taken(t, model), t, out[c].to_numpy())
    out["gamma"] = wrap_angle(out["psi_1"].to_numpy() - out["psi_2"].to_numpy())
    true = frame["delta_h"].to_numpy()
    held = true[np.clip(can_sample(np.arange(n), dt, model), 0, n - 1)]
    out["delta_h"] = can_quantise(held, model)
    return out
