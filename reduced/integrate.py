"""Fixed-step fourth-order Runge-Kutta for sampled-and-held inputs.

Logs hold their inputs over each sample, so every sample is a discontinuity.
An adaptive solver would shrink its step at each one; a fixed step at the log
rate is both faster and exactly aligned with the samples.

Within a step the road-wheel angle is held and the speed rises linearly,
``u1(t) = u1 + u1_dot * t``.

Both reduced models are reached through one compiled entry point per
operation, chosen by an integer model kind (:data:`KIN`, :data:`STM`). Their
parameters are flat float arrays. That keeps every compiled function at
module level, where numba can cache it between processes; closures over other
compiled functions cannot be cached.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from artic.reduced.kinematic import kin_observe, kin_rhs
from artic.reduced.single_track import stm_observe, stm_rhs

KIN = 0
STM = 1


@njit(cache=True)
def rhs(kind, x, u1, u1_dot, delta, P):
    """State derivative of model ``kind`` (equations in the model modules)."""
    if kind == KIN:
        return kin_rhs(x, u1, u1_dot, delta, P)
    return stm_rhs(x, u1, u1_dot, delta, P)


@njit(cache=True)
def rk4_step(kind, x, dt, u1, u1_dot, delta, P):
    """One RK4 step of ``dt`` [s] of model ``kind``."""
    # Element loops instead of array expressions: the same operations in the
    # same order (so the same bits), without a temporary array per operation.
    h2 = 0.5 * dt
    n = x.size
    xt = np.empty(n)
    k1 = rhs(kind, x, u1, u1_dot, delta, P)
    for i in range(n):
        xt[i] = x[i] + h2 * k1[i]
    k2 = rhs(kind, xt, u1 + h2 * u1_dot, u1_dot, delta, P)
    for i in range(n):
        xt[i] = x[i] + h2 * k2[i]
    k3 = rhs(kind, xt, u1 + h2 * u1_dot, u1_dot, delta, P)
    for i in range(n):
        xt[i] = x[i] + dt * k3[i]
    k4 = rhs(kind, xt, u1 + dt * u1_dot, u1_dot, delta, P)
    w = dt / 6.0
    for i in range(n):
        xt[i] = x[i] + w * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    return xt


@njit(cache=True)
def observe(kind, x, u1, delta, P, s1, s2):
    """Signals at the sensor points of model ``kind``, in ``OBSERVATION`` order."""
    if kind == KIN:
        return kin_observe(x, u1, delta, P, s1, s2)
    return stm_observe(x, u1, delta, P, s1, s2)
