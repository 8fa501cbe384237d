"""What a controller sees: the synthetic campaign's sensors, sample by sample.

The campaign measures a whole run at once (:func:`artic.validation.synthetic.sensors.measure`).
A controller needs the same signals as they arrive, at its own rate, with
the same measurement chain, whose pieces are
:mod:`artic.validation.synthetic.sensors`' own:

- the noise of the position, heading, velocity and yaw-rate channels is
  additive, so :class:`SensorStream` draws it for the whole run up front by
  measuring a run of zeros with ``measure`` itself (the same processes,
  correlation times and bias), sampled at the controller's rate: a
  Gauss-Markov process sampled every ``dt`` is the same process whatever
  rate it was generated at, and the white channels have the same variance
  per sample;
- the semitrailer unit's clock skew (``trailer_skew``, the truth's
  ``trailer_clock_skew``): a controller that pairs the two units' samples
  by their stamps, as the logs are paired, gets the semitrailer as it was
  at :func:`~artic.validation.synthetic.sensors.trailer_taken` of now, that
  is ``trailer_skew`` ago, interpolated between the plant's steps. A
  negative skew stamps the semitrailer's samples early, so the pair for
  now is complete only ``|trailer_skew|`` later: both units arrive that late;
- the steering wheel from the CAN bus, sampled at its rate, late by its
  delay and quantised in its steps
  (:func:`~artic.validation.synthetic.sensors.can_sample`,
  :func:`~artic.validation.synthetic.sensors.can_quantise`).

That is the ``full`` sensor set (``artic dock --sensors full``, the default):
RTK/INS on both units. A yard tractor couples a different semitrailer every
job, and semitrailers carry no GNSS; :data:`SENSOR_SETS` ``tractor`` and
``camera`` keep the tractor's channels of the same stream (the same noise,
sample for sample) and measure the articulation from the tractor, with a
hitch encoder or a rear-facing camera
(:class:`~artic.validation.synthetic.sensors.ArticulationModel`, its errors
drawn up front like the rest, from a random stream of their own).
:class:`EstimatedStream` gives the controller the semitrailer's channels and
the articulation from the estimator
(:mod:`artic.validation.docking.estimator`), never the plant's.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.interface import OBS_INDEX, wrap_angle
from artic.validation.docking.estimator import (
    ArticulationEKF,
    estimated_signals,
    hitch_velocity,
)
from artic.validation.docking.geometry import Frames
from artic.validation.logs.runfile import new_frame
from artic.validation.synthetic.sensors import (
    TRAILER_CHANNELS,
    ArticulationModel,
    SensorModel,
    articulation_noise,
    can_quantise,
    can_sample,
    measure,
    quantise_articulation,
    trailer_taken,
)

_CHANNELS = ("x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1", *TRAILER_CHANNELS)
_TRAILER = np.array([OBS_INDEX[c] for c in TRAILER_CHANNELS])
_ANGLES = np.array([OBS_INDEX[c] for c in ("psi_1", "psi_2", "gamma")])
_GAMMA = OBS_INDEX["gamma"]


class SensorStream:
    """The measurement chain of one run, at the controller's samples.

    Parameters
    ----------
    model : SensorModel
        Noise, clock and sampling figures (:class:`SensorModel` ``()`` for
        the campaign's, ``SensorModel.ideal()`` for none).
    rng : Generator
        This run's random numbers.
    n : int
        Samples the run may take.
    dt : float
        The controller's sample period [s].
    plant_dt : float
        The plant's step [s]: the resolution of the histories it is given.
    """

    def __init__(self, model: SensorModel, rng: np.random.Generator, n: int, dt: float,
                 plant_dt: float) -> None:
        self.model = model
        t = np.arange(n) * dt
        zero = new_frame(t, np.zeros(n), np.zeros((n, 13)))
        # The noise alone: the skew moves the signals, and the noise is the
        # same process either way, so a run's noise is the same with or without it.
        noise = measure(zero, rng, dataclasses.replace(model, trailer_skew=0.0))
        self.noise = noise[list(_CHANNELS)].to_numpy()
        self.plant_dt = plant_dt
        self._ideal = model.is_ideal  # a frozen model: asked once, not every sample

    def _at(self, true: Sequence[np.ndarray], when: float) -> np.ndarray:
        """The plant's signals at time ``when`` [s], linear between its steps (angles wrapped)."""
        f = min(max(when / self.plant_dt, 0.0), len(true) - 1.0)
        i = min(int(f), len(true) - 2) if len(true) > 1 else 0
        w = f - i
        a = np.asarray(true[i], dtype=float)
        if w <= 0.0:
            return a.copy()
        b = np.asarray(true[i + 1], dtype=float)
        out = a + w * (b - a)
        out[_ANGLES] = a[_ANGLES] + w * wrap_angle(b[_ANGLES] - a[_ANGLES])
        return out

    def observe(self, k: int, true: Sequence[np.ndarray],
                steering_wheel: Sequence[float]) -> tuple:
        """Measured signals and steering-wheel angle at sample ``k``.

        Parameters
        ----------
        k : int
            The controller's sample.
        true : sequence of ndarray, shape (13,) each
            The plant's signals at every plant step so far (``OBSERVATION``
            order), now last.
        steering_wheel : sequence of float
            The steering-wheel angle at every plant step so far [rad], now last.

        Returns
        -------
        signals : ndarray, shape (13,)
            As the sensors report them now, with the noise of sample ``k``;
            ``gamma`` from the measured headings.
        delta_h : float
            The steering wheel as the CAN bus reports it now [rad].
        """
        m = self.model
        i = len(true) - 1
        if m.trailer_skew:
            late = max(0.0, -m.trailer_skew)  # a negative skew: wait for the semitrailer
            now = i * self.plant_dt - late
            out = self._at(true, now)
            out[_TRAILER] = self._at(true, trailer_taken(now, m))[_TRAILER]
        else:
            out = np.array(true[i], dtype=float, copy=True)
        out[:12] += self.noise[k]
        out[_GAMMA] = wrap_angle(float(out[2] - out[8]))
        j = len(steering_wheel) - 1
        if self._ideal:
            return out, float(steering_wheel[j])
        held = float(steering_wheel[min(max(can_sample(j, self.plant_dt, m), 0), j)])
        return out, float(can_quantise(held, m))


SENSOR_SETS = {
    "full": "RTK/INS on both units (the campaign's; the articulation from the two headings)",
    "tractor": "the tractor's RTK/INS and a 12-bit hitch encoder; nothing on the semitrailer",
    "camera": "the tractor's RTK/INS and a rear-facing camera's articulation "
              "(1.25 deg RMS, 0.2 s late, dropouts); nothing on the semitrailer",
}
"""``artic dock --sensors``: what each set puts on the combination."""


def sensor_set(name: str, given: str = "--sensors") -> str:
    """``name`` if it is one of :data:`SENSOR_SETS`; else one line naming the choices.

    ``given`` names what gave it (the option, or a keyword), for the message.

    Raises
    ------
    UserError
        For any other name.
    """
    if name not in SENSOR_SETS:
        raise UserError(f"{given} {name}: no such sensor set; choose one of "
                        f"{', '.join(SENSOR_SETS)}")
    return name


def articulation_model(name: str, noise_deg: float | None = None) -> ArticulationModel:
    """The articulation sensor of sensor set ``name`` (``tractor`` or ``camera``).

    Parameters
    ----------
    name : str
        ``"tractor"`` (:meth:`ArticulationModel.encoder`) or ``"camera"``
        (:meth:`ArticulationModel.camera`).
    noise_deg : float, optional
        Its noise RMS [deg] instead of the model's (white and drift together,
        :meth:`ArticulationModel.with_noise`).
    """
    model = {"tractor": ArticulationModel.encoder,
             "camera": ArticulationModel.camera}[sensor_set(name)]()
    if noise_deg is not None:
        if not (math.isfinite(noise_deg) and noise_deg >= 0.0):
            raise UserError(f"articulation noise {noise_deg} deg: give a finite RMS >= 0")
        model = model.with_noise(math.radians(noise_deg))
    return model


class EstimatedStream:
    """Tractor-only sensing: the tractor's channels, an articulation sensor, the estimator.

    The controller gets :class:`SensorStream`'s tractor channels as they are
    (the same noise as ``full``'s, sample for sample), and the semitrailer's
    channels and the articulation from :class:`~artic.validation.docking.estimator.ArticulationEKF`
    (:func:`~artic.validation.docking.estimator.estimated_signals`): never
    the plant's semitrailer.

    Parameters
    ----------
    stream : SensorStream
        The run's measurement chain (its semitrailer channels are not used).
    model : ArticulationModel
        The articulation sensor.
    rng : Generator
        Its random numbers (a stream of their own, so that ``full``'s draws
        stay as they are).
    n : int
        Samples the run may take.
    dt : float
        The controller's sample period [s].
    frames : Frames
        The vehicle file's geometry: what the estimator knows.
    hitch_offset : float
        The plant's signals' articulation less its hitch angle [rad]: its units'
        mounting yaws' difference (zero when mounted straight). The sensor
        measures the hitch angle.
    """

    def __init__(self, stream: SensorStream, model: ArticulationModel,
                 rng: np.random.Generator, n: int, dt: float, frames: Frames,
                 hitch_offset: float = 0.0) -> None:
        self.stream = stream
        self.model = model
        self.dt = dt
        self.frames = frames
        self.hitch_offset = float(hitch_offset)
        self.error, self.available = articulation_noise(rng, n, dt, model)
        self.ekf = ArticulationEKF(frames.kin.params.L2, model)
        self.reported: list[float] = []
        """What the articulation sensor reported at each sample [rad] (NaN: nothing)."""

    def observe(self, k: int, true: Sequence[np.ndarray],
                steering_wheel: Sequence[float]) -> tuple:
        """Signals and steering-wheel angle at sample ``k`` (as :meth:`SensorStream.observe`)."""
        measured, dh = self.stream.observe(k, true, steering_wheel)
        now = (len(true) - 1) * self.stream.plant_dt
        t = k * self.dt
        y = None
        if self.available[k]:
            seen = self.stream._at(true, now - self.model.latency)
            y = float(quantise_articulation(
                wrap_angle(float(seen[OBS_INDEX["gamma"]]) - self.hitch_offset) + self.error[k],
                self.model))
        self.reported.append(math.nan if y is None else y)
        self.ekf.step(t, hitch_velocity(measured, self.frames), y, t - self.model.latency)
        return (estimated_signals(measured, self.ekf.gamma, self.ekf.gamma_dot, self.frames),
                dh)
