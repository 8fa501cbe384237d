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

The docking benchmark's tractor-only sensor sets add an articulation sensor on
the tractor (:class:`ArticulationModel`): a hitch encoder or a rear-facing
camera, with their resolution, bias, drift, noise, latency and dropouts
(:func:`articulation_noise`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

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


# ---------------------------------------------------------------- articulation sensors
@dataclass(frozen=True)
class ArticulationModel:
    """A tractor-mounted articulation sensor: what it reports of the hitch angle (SI units).

    The reported angle is the hitch angle (the semitrailer's heading against
    the tractor's, mounting yaws of the inertial units apart) as it was
    ``latency`` ago, plus a constant bias per run, a first-order
    Gauss-Markov drift and white noise, rounded to ``step``; during a
    dropout it reports nothing. :meth:`encoder` and :meth:`camera` are the
    docking benchmark's two (``artic dock --sensors tractor|camera``).
    """

    name: str
    white_sigma: float
    """White noise per sample [rad]."""
    bias_sigma: float = 0.0
    """Standard deviation of the constant bias drawn per run [rad]."""
    drift_sigma: float = 0.0
    """Standard deviation of the Gauss-Markov drift [rad]."""
    drift_tau: float = 1.0
    """Its correlation time [s]."""
    step: float = 0.0
    """Resolution [rad]; 0 reports the value as is."""
    latency: float = 0.0
    """Age of a measurement when it arrives [s]: it is of the hitch angle that long ago."""
    dropout_rate: float = 0.0
    """Dropouts starting per second of reporting [1/s]."""
    dropout_mean: float = 0.0
    """Mean length of a dropout [s]."""

    @classmethod
    def encoder(cls) -> ArticulationModel:
        """A 12-bit absolute rotary encoder at the fifth wheel (``--sensors tractor``).

        - resolution 360 deg / 4096 = 0.088 deg: a 12-bit absolute encoder,
          the common single-turn resolution of industrial rotary encoders;
        - white noise 0.05 deg: the play of the driver that turns the encoder
          with the kingpin, about half a step;
        - bias 0.3 deg (standard deviation, drawn per run): the encoder's zero
          is the fifth wheel's, not the semitrailer's centre line; a yard
          tractor couples a different semitrailer every job, whose kingpin
          and build squareness nobody calibrates;
        - no latency (a bus frame's few milliseconds are under the plant's
          10 ms step) and no dropouts.
        """
        return cls("encoder", white_sigma=math.radians(0.05), bias_sigma=math.radians(0.3),
                   step=2.0 * math.pi / 4096)

    @classmethod
    def camera(cls) -> ArticulationModel:
        """A rear-facing camera that tracks the semitrailer's front (``--sensors camera``).

        - accuracy 1.25 deg RMS, the middle of the 1.0-1.5 deg RMS published
          for camera tracking of the articulation on real trucks (de Saxe and
          Cebon), with its occasional 2-3 deg errors as the tails: split
          evenly in variance between white noise (0.88 deg) and a drift of
          2 s correlation time (0.88 deg), the time in which the image's
          scene changes at yard speed (how the published RMS splits is not
          published);
        - latency 0.2 s: a frame's exposure, transfer and the tracking's
          processing, two controller samples;
        - dropouts: one starting every 10 s on average, lasting 1 s on
          average (glare, spray, the tracking losing the semitrailer's
          edge), about 9 % of the time blind.
        """
        part = math.radians(1.25) / math.sqrt(2.0)
        return cls("camera", white_sigma=part, drift_sigma=part, drift_tau=2.0, latency=0.2,
                   dropout_rate=0.1, dropout_mean=1.0)

    def with_noise(self, rms: float) -> ArticulationModel:
        """The same sensor, its noise (white and drift, split as they are) at ``rms`` [rad] RMS."""
        total = math.hypot(self.white_sigma, self.drift_sigma)
        if total == 0.0:
            return replace(self, white_sigma=float(rms))
        k = float(rms) / total
        return replace(self, white_sigma=k * self.white_sigma, drift_sigma=k * self.drift_sigma)

    @property
    def noise_rms(self) -> float:
        """RMS of the white noise and the drift together [rad] (the bias apart)."""
        return math.hypot(self.white_sigma, self.drift_sigma)


def articulation_noise(rng: np.random.Generator, n: int, dt: float,
                       model: ArticulationModel) -> tuple[np.ndarray, np.ndarray]:
    """An articulation sensor's errors and availability at ``n`` samples ``dt`` apart.

    Drawn in a fixed order (bias, drift, white noise, dropouts) from
    ``rng``, so that the same generator gives the same run.

    Returns
    -------
    error : ndarray, shape (n,)
        Bias plus drift plus white noise [rad], before the rounding to ``step``.
    available : ndarray of bool, shape (n,)
        Whether a measurement arrives at the sample (``False`` in a dropout).
    """
    bias = rng.normal(0.0, model.bias_sigma) if model.bias_sigma > 0 else 0.0
    drift = (gauss_markov(rng, n, dt, model.drift_sigma, model.drift_tau)
             if model.drift_sigma > 0 else np.zeros(n))
    white = rng.normal(0.0, model.white_sigma, n) if model.white_sigma > 0 else np.zeros(n)
    available = np.ones(n, dtype=bool)
    if model.dropout_rate > 0 and model.dropout_mean > 0:
        start = 1.0 - math.exp(-model.dropout_rate * dt)  # a two-state Markov chain
        end = 1.0 - math.exp(-dt / model.dropout_mean)
        u = rng.random(n)
        out = False
        for k in range(n):
            out = (u[k] >= end) if out else (u[k] < start)
            available[k] = not out
    return bias + drift + white, available


def quantise_articulation(value, model: ArticulationModel):
    """The articulation in the sensor's steps of ``step`` [rad] (as given if 0)."""
    return np.round(value / model.step) * model.step if model.step > 0 else value
