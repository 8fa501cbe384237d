"""The harness's steering law, in plain Python that numba also compiles.

The law is eq. (5) of the seed paper with the stabilising sign of its
eqs. (6)-(7) (see :mod:`artic.validation.harness.loop`), its feedback term
weighted by ``w`` in [0, 1]: 1 while the log reverses, 0 otherwise, ramping
between the two where a reversing stretch starts or ends
(:func:`artic.validation.harness.reversing.feedback_weight`). The plant's C
loop (``plant/_loop_c.c``) writes the same arithmetic in the same order. It
lives apart from the numba kernels (:mod:`artic.validation.harness.reducedloop`)
so that the plant's runs, which close the loop in C or in Python, never import
numba.
"""

from __future__ import annotations

import math


def wrap(a: float) -> float:
    """Wrap an angle to [-pi, pi) [rad]."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


def feedback_law(delta_c: float, gamma_model: float, gamma_meas: float, weight: float,
                 gain: float, delta_max: float) -> tuple[float, float, bool]:
    """The harness's steering law.

    Parameters
    ----------
    delta_c : float
        Road-wheel angle from the measured steering wheel, eq. (3) [rad].
    gamma_model, gamma_meas : float
        Articulation of the model and of the log [rad].
    weight : float
        The feedback's weight ``w`` at this sample, in [0, 1]: 0 (no feedback
        at all) forward, 1 reversing [-].
    gain : float
        K [rad/rad].
    delta_max : float
        Largest road-wheel angle [rad].

    Returns
    -------
    delta : float
        Road-wheel angle to apply [rad].
    delta_fb : float
        ``delta - delta_c`` [rad].
    saturated : bool
        Whether ``delta_max`` limited it.
    """
    fb = 0.0
    if weight != 0.0:
        e = gamma_model - gamma_meas
        # wrap(e), written out: numba compiles this function's own source,
        # where a call to the plain-Python wrap above would not compile
        fb = weight * gain * (e - 2.0 * math.pi * math.floor((e + math.pi) / (2.0 * math.pi)))
    delta = delta_c + fb
    saturated = False
    if delta > delta_max:
        delta, saturated = delta_max, True
    elif delta < -delta_max:
        delta, saturated = -delta_max, True
    return delta, delta - delta_c, saturated
