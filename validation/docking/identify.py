"""Online identification of the semitrailer's effective wheelbase from the tractor's motion.

The semitrailer turns about its no-slip point, its effective wheelbase ``L2``
behind the kingpin (:func:`artic.validation.docking.variants.effective_wheelbase`):
that point moves along the semitrailer's heading, so the kingpin's velocity
across the semitrailer is the semitrailer's yaw rate times ``L2``.

The kingpin's velocity follows from the tractor's sensor alone. The sensor
at ``(x_s1, y_s1)`` from the drive axle reports the velocity ``(v_x_1, v_y_1)``
in tractor axes and the yaw rate ``r_1``; the kingpin at ``(L1c, 0)`` moves
at ``(v_x_1 + r_1 y_s1, v_y_1 + r_1 (L1c - x_s1))``. Turned into the
semitrailer's axes (its heading is ``psi_1 - gamma``), its component across
the semitrailer is::

    w = (v_x_1 + r_1 y_s1) sin(gamma) + (v_y_1 + r_1 (L1c - x_s1)) cos(gamma)

and ``psi_2_dot = r_1 - gamma_dot = w / L2``. Split ``w = w_a + L1c r_1 cos(gamma)``
(``w_a`` without the fifth wheel's position, which the tractor's operator may
have moved, :mod:`~artic.validation.docking.variants`)::

    r_1 - gamma_dot = theta_1 w_a + theta_2 r_1 cos(gamma),
    theta = (1 / L2, L1c / L2)

linear in ``theta``. The articulation's rate is the noisy part, so it goes
into the measured side, not the regressor (noise in a regressor biases least
squares towards zero): integrated over a window of :attr:`window` samples
instead of differentiated, ``y = int r_1 dt - (gamma(t) - gamma(t - T))`` against
``phi = (int w_a dt, int r_1 cos(gamma) dt)`` (trapezoids), every sample.

Recursive least squares with a forgetting factor :attr:`forgetting` per
update estimates ``theta``, starting from the vehicle file's values with a
prior spread (:data:`PRIOR_L2`, :data:`PRIOR_L1C`) against the window's noise
(:data:`NOISE`): a Bayesian start, so that what the motion cannot tell apart
stays near the file's. **Excitation check**: a window updates only when the
semitrailer's heading changed by at least :attr:`excitation` over it by the
current estimate (``|theta . phi|``): when the semitrailer runs straight behind
the tractor, ``gamma`` and its rate carry no information on ``L2`` and the
estimate is held. The covariance is held to its prior size (its trace), so
that long stretches of one kind of motion cannot wind it up.

Every signal used is the tractor's (its GNSS/INS) and the articulation: the
identification works from any sensor set that gives the controller ``gamma``.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from artic.mjcf.interface import OBS_INDEX
from artic.mjcf.vehicle import Vehicle
from artic.reduced.kinematic import kin_params

WINDOW = 10
"""Samples the articulation is integrated over [-]: 1 s at 10 Hz."""

FORGETTING = 0.995
"""Forgetting factor per update [-]: data about 200 updates (20 s of turning) old weigh
a third."""

EXCITATION = 0.01
"""Least change of the semitrailer's heading over a window for an update [rad]
(0.6 deg): several times the window's articulation noise of RTK/INS headings
(0.05 deg each, so about 0.1 deg in a difference of two articulations)."""

NOISE = 0.003
"""Standard deviation of a window's residual [rad] the prior is weighed against: the
articulation's noise and what the plant's tyre slip adds to the kinematics."""

PRIOR_L2 = 0.15
"""Prior spread of ``L2`` [-], relative: a bogie within about a metre of the file's."""

PRIOR_L1C = 0.2
"""Prior spread of the fifth wheel's position ``L1c`` [m]."""

MIN_SPEED = 0.1
"""Least tractor speed over the window for an update [m/s]."""

_VX, _VY, _R1, _GAMMA = (OBS_INDEX[c] for c in ("v_x_1", "v_y_1", "r_1", "gamma"))


class WheelbaseIdentifier:
    """Recursive least squares on the semitrailer's kinematics (see the module docstring).

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle file: the tractor sensor's position, the file's ``L1c``
        and effective wheelbase (the prior).
    window : int
        Samples per window.
    forgetting : float
        Forgetting factor per update, in (0, 1].
    excitation : float
        Least heading change of the semitrailer per window for an update [rad].

    Examples
    --------
    >>> import artic
    >>> from artic.validation.docking.identify import WheelbaseIdentifier
    >>> ident = WheelbaseIdentifier(artic.load_vehicle("gosar2022-loaded"))
    >>> round(ident.L2, 3) == round(ident.L2_prior, 3), ident.updates  # nothing seen yet
    (True, 0)
    """

    def __init__(self, vehicle: Vehicle, window: int = WINDOW, forgetting: float = FORGETTING,
                 excitation: float = EXCITATION) -> None:
        if not (window >= 1 and 0.0 < forgetting <= 1.0 and excitation >= 0.0):
            raise ValueError("WheelbaseIdentifier: window >= 1, 0 < forgetting <= 1 and "
                             "excitation >= 0")
        self.window = int(window)
        self.forgetting = float(forgetting)
        self.excitation = float(excitation)
        self.s1 = np.asarray(vehicle.sensor1[:2], dtype=float)
        self.gamma_bias = float(vehicle.sensor1_yaw - vehicle.sensor2_yaw)
        self.L2_prior = float(kin_params(vehicle).L2)
        self.L1c_prior = float(vehicle.L1c)
        self.theta = np.array([1.0 / self.L2_prior, self.L1c_prior / self.L2_prior])
        sd = np.array([PRIOR_L2 / self.L2_prior, PRIOR_L1C / self.L2_prior]) / NOISE
        self.P0 = np.diag(sd ** 2)
        self.P = self.P0.copy()
        self.updates = 0
        self._s1x, self._s1y = float(self.s1[0]), float(self.s1[1])
        self._last: tuple[float, float, float, float] | None = None
        # The window's last ``window`` trapezoids of r_1, w_a and r_1 cos(gamma) (one
        # tuple per interval), and its ``window + 1`` articulations and speeds.
        self._areas: deque[tuple[float, float, float]] = deque(maxlen=self.window)
        self._gamma: deque[float] = deque(maxlen=self.window + 1)
        self._u: deque[float] = deque(maxlen=self.window + 1)

    @property
    def L2(self) -> float:
        """Identified effective wheelbase [m]."""
        return float(1.0 / self.theta[0])

    @property
    def L1c(self) -> float:
        """Identified fifth-wheel position ahead of the drive axle [m]."""
        return float(self.theta[1] / self.theta[0])

    def update(self, t: float, signals: np.ndarray) -> bool:
        """Take one sample; update the estimate if the window is exciting enough.

        Parameters
        ----------
        t : float
            Its time [s].
        signals : ndarray, shape (13,)
            The signals as the controller gets them (``OBSERVATION`` order); only
            the tractor's velocity and yaw rate and ``gamma`` are read.

        Returns
        -------
        bool
            Whether the estimate was updated.
        """
        vx, vy, r1 = float(signals[_VX]), float(signals[_VY]), float(signals[_R1])
        gamma = float(signals[_GAMMA]) - self.gamma_bias
        t = float(t)
        if not (math.isfinite(vx) and math.isfinite(vy) and math.isfinite(r1)
                and math.isfinite(gamma) and math.isfinite(t)):
            return False  # a dropout: skipped, the window spans it
        sg, cg = math.sin(gamma), math.cos(gamma)
        wa = (vx + r1 * self._s1y) * sg + (vy - r1 * self._s1x) * cg
        rc = r1 * cg
        last, self._last = self._last, (t, r1, wa, rc)
        if last is not None:  # the interval's trapezoids, as numpy's would compute them
            dt = t - last[0]
            self._areas.append((0.5 * (r1 + last[1]) * dt, 0.5 * (wa + last[2]) * dt,
                                0.5 * (rc + last[3]) * dt))
        self._gamma.append(gamma)
        self._u.append(abs(vx))
        if len(self._areas) < self.window or min(self._u) < MIN_SPEED:
            return False
        r1_dt, wa_dt, rc_dt = zip(*self._areas, strict=True)
        y = numpy_sum(r1_dt) - (self._gamma[-1] - self._gamma[0])
        phi = np.array([numpy_sum(wa_dt), numpy_sum(rc_dt)])
        if abs(float(phi @ self.theta)) < self.excitation:
            return False
        lam = self.forgetting
        Pphi = self.P @ phi
        k = Pphi / (lam + float(phi @ Pphi))
        self.theta = self.theta + k * (y - float(phi @ self.theta))
        P = (self.P - np.outer(k, Pphi)) / lam
        P = 0.5 * (P + P.T)
        tr0, tr = float(np.trace(self.P0)), float(np.trace(P))
        self.P = P * (tr0 / tr) if tr > tr0 else P
        if self.theta[0] <= 0.0:  # never on data the check let through; kept finite anyway
            self.theta[0] = 1.0 / self.L2_prior
        self.updates += 1
        return True


def numpy_sum(values) -> float:
    """``float(np.sum(np.array(values)))`` to the bit, without making the array.

    numpy adds a float64 array pairwise: blocks of up to 128 in eight running
    sums combined as ``((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))`` and
    the rest added in order, larger arrays split in two at a multiple of eight,
    all added to the sum's start, 0.0. The identifier's window is ten samples:
    the array would cost more than the sum.
    """
    return 0.0 + _pairwise(values, 0, len(values))


def _pairwise(a, lo: int, n: int) -> float:
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    if n < 16:  # one block, no running sums (the identifier's windows of ten)
        r0, r1, r2, r3, r4, r5, r6, r7 = a[lo:lo + 8]
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        for k in range(lo + 8, lo + n):
            res += a[k]
        return res
    if n <= 128:
        r = [a[lo + j] for j in range(8)]
        i = 8
        while i < n - n % 8:
            for j in range(8):
                r[j] += a[lo + i + j]
            i += 8
        res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
        for k in range(lo + i, lo + n):
            res += a[k]
        return res
    half = n // 2
    half -= half % 8
    return _pairwise(a, lo, half) + _pairwise(a, lo + half, n - half)
