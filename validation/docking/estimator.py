"""The articulation from tractor-only sensors: an extended Kalman filter.

``artic dock --sensors tractor|camera`` puts no sensor on the semitrailer.
The tractor's RTK/INS reports its pose, velocity and yaw rate as with
``full``; an articulation sensor on the tractor
(:class:`artic.validation.synthetic.sensors.ArticulationModel`: a hitch
encoder, or a rear-facing camera with its latency and dropouts) reports the
hitch angle. :class:`ArticulationEKF` estimates the hitch angle ``gamma`` from
both, and the semitrailer's pose follows from it by the vehicle file's
geometry: the kingpin ``L1c`` ahead of the tractor's drive axle, the
semitrailer's heading ``psi_2 = psi_1 - gamma``.

**Why a filter on the articulation alone.** The filter the brief of the
benchmark suggests, an EKF on KIN's states ``(X, Y, psi_1, gamma)``, splits
exactly in two with this process model: the tractor's pose is driven by its
own measured velocities and yaw rate, which do not depend on ``gamma``, and
its measurements (GNSS/INS) do not see ``gamma``; ``gamma``'s rate depends
on the tractor's motion but not on its pose, and the articulation sensor
sees ``gamma`` alone. Both the transition and the measurement matrices are
block-diagonal, so the four-state filter's covariance stays block-diagonal
and its ``gamma`` is this filter's. Its tractor block would filter the RTK/INS
pose, whose errors are correlated over 5-10 s (a Gauss-Markov process,
:class:`~artic.validation.synthetic.sensors.SensorModel`): no filter
averages them away, so the controller gets the tractor's pose as measured,
as with ``full``. A UKF buys nothing here: ``gamma_dot`` is a sinusoid in
``gamma``, and across the estimate's spread (a standard deviation of a degree
at most, 0.017 rad) its slope changes by a few per cent at most, so the
linearisation's error is far below the sensor's. A moving-horizon estimator
would bound the state (``|gamma| < gamma_max``), which an estimate this
close to the truth never reaches.

**The state** is ``(gamma, b, d)``: the hitch angle, the sensor's constant
bias per run and its Gauss-Markov drift, all in [rad]; the sensor reports
``gamma + b + d`` plus white noise. The encoder's bias (the semitrailer's
centre line is not the fifth wheel's zero) and the camera's slow error are
thus estimated where the motion makes them observable: the articulation's
own kinematics predict how ``gamma`` must change with the tractor's motion,
so a steady offset between prediction and measurement is the sensor's.

**Process model (derived).** The tractor is rigid: its inertial unit at
``s1`` (from the drive axle, turned by its mounting yaw ``eps_1``) reports
``(v_x, v_y)`` and the yaw rate ``r_1``; the kingpin, ``L1c`` ahead of the
drive axle, moves at

    v_h = (v_x + r_1 s1_y,  v_y + r_1 (L1c - s1_x))     in tractor axes.

The semitrailer turns about the kingpin; its (equivalent) axle, ``L2``
behind it (:func:`artic.reduced.kinematic.wheelbases`, Fancher's effective
wheelbase), does not slip sideways, so its yaw rate is the kingpin's
velocity across the semitrailer over ``L2``; turned into the semitrailer's
axes by ``gamma``,

    r_2 = (v_hx sin(gamma) + v_hy cos(gamma)) / L2,   gamma_dot = r_1 - r_2.

With KIN's tractor (no slip at its reference point, so ``v_hy = r_1 L1c``
and ``v_hx = u_1``) this is KIN's eq. (1) exactly
(``tests/test_docking_estimator.py`` checks it against
:meth:`artic.reduced.control.KIN.rhs`, and against the plant). Unlike KIN's
``gamma_dot = f(u_1, delta, gamma)``, it needs neither the steering map nor
the tractor's equivalent wheelbase, nor the CAN bus's late steering wheel:
the tractor's slip is in its measured ``v_y``. Its one model error is the
semitrailer's ``L2`` (the tridem's scrub, the tyres' relaxation), held as
:data:`Q_RELATIVE` of the semitrailer's yaw rate.

**Latency and dropouts.** The filter keeps its posteriors and inputs of the
last :data:`HISTORY` seconds. A measurement stamped ``latency`` ago is
fused where it belongs: the filter goes back to the posterior at or before
its stamp, predicts to the stamp, updates, and predicts forward again over
the stored inputs to now (buffer and re-filter; exact for a linear filter,
and for this one as exact as the linearisation). A sample without a
measurement (a dropout) is a prediction only.
"""

from __future__ import annotations

import bisect
import math

import numpy as np

from artic.mjcf.interface import OBS_INDEX, wrap_angle
from artic.validation.docking.geometry import Frames
from artic.validation.synthetic.sensors import ArticulationModel

Q_RELATIVE = 0.05
"""The process model's error in the semitrailer's yaw rate, as a share of it (white over a
sample): the equivalent wheelbase is a low-speed steady-turn figure, and the plant's
tridem scrubs and its tyres relax. ``tests/test_docking_estimator.py`` measures the
plant's departure from the model."""

Q_FLOOR = math.radians(0.05)
"""The process model's error at rest or straight [rad/sqrt(s)]: the measured lateral
velocity's noise (10 mm/s over an 8 m wheelbase) and the hitch's play."""

HISTORY = 2.0
"""How long the filter keeps its posteriors to fuse late measurements [s]; longer than any
sensor's latency."""

SUBSTEP = 0.02
"""Longest integration step of the prediction [s]."""

GAMMA_PRIOR = math.radians(30.0)
"""Standard deviation of the hitch angle before any measurement [rad]."""


def hitch_velocity(signals: np.ndarray, frames: Frames) -> np.ndarray:
    """The kingpin's velocity in tractor axes and the tractor's yaw rate from its sensor.

    Parameters
    ----------
    signals : ndarray, shape (13,) or (n, 13)
        Signals in ``OBSERVATION`` order; the tractor's ``v_x_1, v_y_1, r_1`` are used.
    frames : Frames
        The vehicle's geometry: the kingpin ``L1c`` ahead of the drive axle, the
        sensor's position ``s1`` and mounting yaw.

    Returns
    -------
    ndarray, shape (3,) or (n, 3)
        ``(v_hx, v_hy, r_1)`` [m/s, m/s, rad/s].
    """
    s = np.asarray(signals, dtype=float)
    vx, vy, r = (s[..., OBS_INDEX[c]] for c in ("v_x_1", "v_y_1", "r_1"))
    eps = frames.sensor_yaw[0]
    c, sn = math.cos(eps), math.sin(eps)
    vxt, vyt = c * vx - sn * vy, sn * vx + c * vy  # the sensor's axes turned back by eps
    s1x, s1y = frames.s1
    return np.stack([vxt + r * s1y, vyt + r * (frames.L1c - s1x), r], axis=-1)


def gamma_rate(gamma: float, u: np.ndarray, L2: float) -> float:
    """``gamma_dot`` [rad/s] of hitch angle ``gamma`` [rad] under ``u = (v_hx, v_hy, r_1)``."""
    return float(u[2] - (u[0] * math.sin(gamma) + u[1] * math.cos(gamma)) / L2)


def _rate_jacobian(gamma: float, u: np.ndarray, L2: float) -> float:
    """``d gamma_dot / d gamma`` [1/s]."""
    return float(-(u[0] * math.cos(gamma) - u[1] * math.sin(gamma)) / L2)


class ArticulationEKF:
    """Extended Kalman filter on ``(gamma, b, d)``: the hitch angle and the sensor's errors.

    Parameters
    ----------
    L2 : float
        The semitrailer's (equivalent) wheelbase the filter assumes [m].
    model : ArticulationModel
        The articulation sensor, as characterised: its white noise, step,
        bias and drift figures are the filter's measurement model.
    q_relative, q_floor : float
        Process noise: :data:`Q_RELATIVE`, :data:`Q_FLOOR`.

    Examples
    --------
    Standing still with a perfect encoder, the estimate is the measurement:

    >>> import math
    >>> import numpy as np
    >>> from artic.validation.synthetic.sensors import ArticulationModel
    >>> ekf = ArticulationEKF(8.0, ArticulationModel("ideal", white_sigma=1e-6))
    >>> ekf.step(0.0, np.zeros(3), math.radians(2.0), 0.0)
    >>> round(math.degrees(ekf.gamma), 6)
    2.0
    """

    def __init__(self, L2: float, model: ArticulationModel, q_relative: float = Q_RELATIVE,
                 q_floor: float = Q_FLOOR) -> None:
        self.L2 = float(L2)
        self.model = model
        self.q_relative = float(q_relative)
        self.q_floor = float(q_floor)
        self.R = model.white_sigma ** 2 + model.step ** 2 / 12.0
        # A sensor with no error at all still needs a positive innovation variance.
        self.R = max(self.R, 1e-12)
        self._t: list[float] = []
        self._u: list[np.ndarray] = []
        self._x: list[np.ndarray] = []
        self._P: list[np.ndarray] = []

    # ------------------------------------------------------------ the estimate
    @property
    def gamma(self) -> float:
        """The hitch angle now [rad]."""
        return float(self._x[-1][0])

    @property
    def sigma(self) -> float:
        """The filter's standard deviation of :attr:`gamma` [rad]."""
        return float(math.sqrt(max(self._P[-1][0, 0], 0.0)))

    @property
    def gamma_dot(self) -> float:
        """The hitch angle's rate now by the process model [rad/s]."""
        return gamma_rate(self.gamma, self._u[-1], self.L2)

    @property
    def sensor_error(self) -> float:
        """The sensor's estimated bias plus drift now [rad]."""
        return float(self._x[-1][1] + self._x[-1][2])

    # ------------------------------------------------------------ the filter
    def _predict(self, x: np.ndarray, P: np.ndarray, t0: float, t1: float,
                 u0: np.ndarray, u1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """From ``t0`` to ``t1`` [s], the inputs linear between ``u0`` and ``u1``."""
        span = t1 - t0
        if span <= 0.0:
            return x.copy(), P.copy()
        n = max(1, math.ceil(span / SUBSTEP - 1e-9))
        h = span / n
        g, F, r2 = float(x[0]), 1.0, 0.0
        for i in range(n):  # the midpoint rule, and its derivative with respect to gamma
            ua = u0 + (u1 - u0) * (i / n)
            um = u0 + (u1 - u0) * ((i + 0.5) / n)
            ja = _rate_jacobian(g, ua, self.L2)
            half = g + 0.5 * h * gamma_rate(g, ua, self.L2)
            jm = _rate_jacobian(half, um, self.L2)
            r2 += abs(um[2] - gamma_rate(half, um, self.L2)) * h
            g = g + h * gamma_rate(half, um, self.L2)
            F *= 1.0 + h * jm * (1.0 + 0.5 * h * ja)
        m = self.model
        a = math.exp(-span / m.drift_tau) if m.drift_sigma > 0 else 1.0
        Phi = np.diag([F, 1.0, a])
        q_gamma = (self.q_relative * r2) ** 2 + self.q_floor ** 2 * span
        Q = np.diag([q_gamma, 0.0, m.drift_sigma ** 2 * (1.0 - a * a)])
        xn = np.array([g, x[1], a * x[2]])
        return xn, Phi @ P @ Phi.T + Q

    def _update(self, x: np.ndarray, P: np.ndarray, y: float) -> tuple[np.ndarray, np.ndarray]:
        H = np.ones(3)
        S = float(H @ P @ H) + self.R
        K = P @ H / S
        xn = x + K * float(wrap_angle(float(y - H @ x)))
        A = np.eye(3) - np.outer(K, H)
        return xn, A @ P @ A.T + self.R * np.outer(K, K)  # Joseph's form: stays symmetric

    def _start(self, t: float, u: np.ndarray, y: float | None) -> None:
        m = self.model
        b2, d2 = m.bias_sigma ** 2, m.drift_sigma ** 2
        if y is None:
            x = np.zeros(3)
            P = np.diag([GAMMA_PRIOR ** 2, b2, d2])
        else:  # gamma = y - b - d - noise: its covariances with b and d follow
            x = np.array([float(y), 0.0, 0.0])
            P = np.array([[self.R + b2 + d2, -b2, -d2], [-b2, b2, 0.0], [-d2, 0.0, d2]])
        self._t, self._u, self._x, self._P = [t], [u], [x], [P]

    def _input_at(self, i: int, t: float) -> np.ndarray:
        """The inputs at ``t`` [s], between stored entries ``i`` and ``i + 1``."""
        if i + 1 >= len(self._t):
            return self._u[i]
        t0, t1 = self._t[i], self._t[i + 1]
        w = 0.0 if t1 <= t0 else (t - t0) / (t1 - t0)
        return self._u[i] + w * (self._u[i + 1] - self._u[i])

    def step(self, t: float, u: np.ndarray, y: float | None = None,
             stamp: float | None = None) -> None:
        """Advance to time ``t`` and fuse a measurement, if one arrived.

        Parameters
        ----------
        t : float
            Now [s]; later than the previous call's.
        u : ndarray, shape (3,)
            ``(v_hx, v_hy, r_1)`` now (:func:`hitch_velocity`) [m/s, m/s, rad/s].
        y : float, optional
            The articulation sensor's report [rad]; ``None`` in a dropout.
        stamp : float, optional
            When it was measured [s] (``t`` by default). Measurements must
            arrive in the order of their stamps (a constant latency ensures it).
        """
        u = np.asarray(u, dtype=float)
        if not self._t:
            self._start(t, u, y)
            return
        x, P = self._predict(self._x[-1], self._P[-1], self._t[-1], t, self._u[-1], u)
        self._t.append(t)
        self._u.append(u)
        self._x.append(x)
        self._P.append(P)
        if y is not None:
            when = min(max(t if stamp is None else float(stamp), self._t[0]), t)
            i = bisect.bisect_right(self._t, when) - 1
            um = self._input_at(i, when)
            xm, Pm = self._predict(self._x[i], self._P[i], self._t[i], when, self._u[i], um)
            xm, Pm = self._update(xm, Pm, y)
            if when - self._t[i] <= 1e-9:
                self._u[i], self._x[i], self._P[i] = um, xm, Pm
            else:
                i += 1
                self._t.insert(i, when)
                self._u.insert(i, um)
                self._x.insert(i, xm)
                self._P.insert(i, Pm)
            for j in range(i + 1, len(self._t)):  # forward again over the stored inputs
                self._x[j], self._P[j] = self._predict(self._x[j - 1], self._P[j - 1],
                                                       self._t[j - 1], self._t[j],
                                                       self._u[j - 1], self._u[j])
        old = bisect.bisect_left(self._t, t - HISTORY)
        if old > 0:
            del self._t[:old], self._u[:old], self._x[:old], self._P[:old]


def estimated_signals(tractor: np.ndarray, gamma: float, gamma_dot: float,
                      frames: Frames) -> np.ndarray:
    """The 13 signals of a tractor-only estimate, as a semitrailer unit would report them.

    The tractor's channels as measured; the semitrailer's unit at ``s2`` from
    the kingpin (turned by its mounting yaw) on the semitrailer placed by the
    hitch angle ``gamma``; ``gamma`` as the signals carry it (the hitch angle
    plus the units' mounting yaws' difference), so that a controller reads
    them as it reads ``full``'s.

    Parameters
    ----------
    tractor : ndarray, shape (13,)
        Measured signals; the first six (the tractor's) are used.
    gamma, gamma_dot : float
        The estimated hitch angle [rad] and its rate [rad/s].
    frames : Frames
        The vehicle file's geometry (what the controller knows).
    """
    out = np.array(tractor, dtype=float, copy=True)
    t, _ = frames.unit_poses_of_signals(out)
    xa, ya, psi_1 = t[0]
    xk, yk = xa + frames.L1c * math.cos(psi_1), ya + frames.L1c * math.sin(psi_1)
    psi_2 = psi_1 - gamma
    c2, s2 = math.cos(psi_2), math.sin(psi_2)
    e1, e2 = frames.sensor_yaw
    v_hx, v_hy, r_1 = hitch_velocity(out, frames)
    r_2 = r_1 - gamma_dot
    cg, sg = math.cos(gamma), math.sin(gamma)
    vx = cg * v_hx - sg * v_hy - r_2 * frames.s2[1]  # the kingpin's velocity in the
    vy = sg * v_hx + cg * v_hy + r_2 * frames.s2[0]  # semitrailer's axes, plus r_2 x s2
    ce, se = math.cos(e2), math.sin(e2)
    out[OBS_INDEX["x_2"]] = xk + c2 * frames.s2[0] - s2 * frames.s2[1]
    out[OBS_INDEX["y_2"]] = yk + s2 * frames.s2[0] + c2 * frames.s2[1]
    out[OBS_INDEX["psi_2"]] = psi_2 + e2
    out[OBS_INDEX["v_x_2"]] = ce * vx + se * vy
    out[OBS_INDEX["v_y_2"]] = -se * vx + ce * vy
    out[OBS_INDEX["r_2"]] = r_2
    out[OBS_INDEX["gamma"]] = wrap_angle(float(gamma + e1 - e2))
    return out
