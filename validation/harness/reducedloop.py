"""The harness loop for KIN and the STM, compiled by numba: a whole log in one call.

It runs the steering law of :mod:`artic.validation.harness.feedback` exactly as the other
loops of :mod:`artic.validation.harness.loop` do, and releases the GIL, so that
:mod:`artic.validation.harness.batch` spreads logs over threads.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from artic.reduced.integrate import observe, rk4_step_into
from artic.validation.harness import feedback

wrap = njit(cache=True)(feedback.wrap)
feedback_law = njit(cache=True)(feedback.feedback_law)


@njit(cache=True, nogil=True)
def compiled_loop(form, args):
    """The harness loop for a reduced model, compiled: a whole log in one call.

    Parameters
    ----------
    form : tuple
        The model's ``compiled()``: ``kind`` (``artic.reduced.integrate.KIN`` or
        ``STM``), then the initial state, parameters and sensors (ndarrays).
    args : tuple
        A :class:`artic.mjcf.interface.LoopArgs` as a plain tuple: the per-sample
        inputs, then K [rad/rad], the road-wheel limit and the jackknife limit [rad].

    Returns
    -------
    obs, delta, delta_fb, saturated : ndarray
    n_done : int
        Rows filled; fewer when the articulation passed ``gamma_max`` or the
        state stopped being finite.
    """
    kind, x0, P, s1, s2 = form
    dt, delta_c, u1, u1_dot, gamma_meas, weight, gain, delta_max, gamma_max = args
    n = delta_c.size
    obs = np.full((n, 13), np.nan)
    delta = np.full(n, np.nan)
    delta_fb = np.full(n, np.nan)
    sat = np.zeros(n, dtype=np.bool_)
    x = x0.copy()
    work = np.empty((5, x.size))  # the step's scratch, once: it steps x in place
    for k in range(n):
        d, f, s = feedback_law(delta_c[k], wrap(x[3]), gamma_meas[k], weight[k],
                               gain, delta_max)
        o = observe(kind, x, u1[k], d, P, s1, s2)
        o[12] = wrap(o[12])
        finite = True
        for j in range(o.size):
            obs[k, j] = o[j]
            finite = finite and math.isfinite(o[j])
        delta[k], delta_fb[k], sat[k] = d, f, s
        if abs(o[12]) > gamma_max or not finite:
            return obs, delta, delta_fb, sat, k + 1
        if k + 1 < n:
            rk4_step_into(kind, x, dt[k], u1[k], u1_dot[k], d, P, work, x)
    return obs, delta, delta_fb, sat, n
