"""What a controller sees: the synthetic campaign's sensors, sample by sample.

The campaign measures a whole run at once (:func:`artic.validation.synthetic.sensors.measure`).
A controller needs the same signals as they arrive, at its own rate. The
noise of the position, heading, velocity and yaw-rate channels is additive,
so :class:`SensorStream` draws it for the whole run up front by measuring a
run of zeros with ``measure`` itself (the same processes, correlation times
and bias), sampled at the controller's rate: a Gauss-Markov process sampled
every ``dt`` is the same process whatever rate it was generated at, and the
white channels have the same variance per sample. The steering wheel
arrives as ``measure`` delivers it: from the CAN bus, sampled at its rate,
late by its delay and quantised in its steps.
"""

from __future__ import annotations

import numpy as np

from artic.mjcf.interface import OBS_INDEX, wrap_angle
from artic.validation.logs.runfile import new_frame
from artic.validation.synthetic.sensors import SensorModel, measure

_CHANNELS = ("x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1",
             "x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2")


class SensorStream:
    """The measurement chain of one run, at the controller's samples.

    Parameters
    ----------
    model : SensorModel
        Noise and sampling figures (:class:`SensorModel` ``()`` for the
        campaign's, ``SensorModel.ideal()`` for none).
    rng : Generator
        This run's random numbers.
    n : int
        Samples the run may take.
    dt : float
        The controller's sample period [s].
    plant_dt : float
        The plant's step [s]: the resolution of the steering-wheel history.
    """

    def __init__(self, model: SensorModel, rng: np.random.Generator, n: int, dt: float,
                 plant_dt: float) -> None:
        self.model = model
        t = np.arange(n) * dt
        zero = new_frame(t, np.zeros(n), np.zeros((n, 13)))
        noise = measure(zero, rng, model)
        self.noise = noise[list(_CHANNELS)].to_numpy()
        self.plant_dt = plant_dt

    def observe(self, k: int, true: np.ndarray, steering_wheel: list[float]) -> tuple:
        """Measured signals and steering-wheel angle at sample ``k``.

        Parameters
        ----------
        k : int
            The controller's sample.
        true : ndarray, shape (13,)
            The plant's signals now (``OBSERVATION`` order).
        steering_wheel : list of float
            The steering-wheel angle at every plant step so far [rad], now last.

        Returns
        -------
        signals : ndarray, shape (13,)
            With the noise of sample ``k``; ``gamma`` from the measured headings.
        delta_h : float
            The steering wheel as the CAN bus reports it now [rad].
        """
        out = np.array(true, dtype=float, copy=True)
        out[:12] += self.noise[k]
        out[OBS_INDEX["gamma"]] = wrap_angle(float(out[2] - out[8]))
        m = self.model
        i = len(steering_wheel) - 1
        if m.is_ideal:
            return out, float(steering_wheel[i])
        step = max(1, round(1.0 / (m.can_rate * self.plant_dt)))
        lag = round(m.can_delay / self.plant_dt)
        held = float(steering_wheel[min(max((i // step) * step - lag, 0), i)])
        if m.can_step > 0:
            held = round(held / m.can_step) * m.can_step
        return out, held
