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

from artic.reduced.kinematic import kin_observe, kin_rates, kin_rhs, kin_rhs_into
from artic.reduced.single_track import stm_observe, stm_rhs, stm_rhs_into

KIN = 0
STM = 1


@njit(cache=True)
def rhs(kind, x, u1, u1_dot, delta, P):
    """State derivative of model ``kind`` (equations in the model modules)."""
    if kind == KIN:
        return kin_rhs(x, u1, u1_dot, delta, P)
    return stm_rhs(x, u1, u1_dot, delta, P)


@njit(cache=True)
def rhs_into(kind, x, u1, u1_dot, delta, P, out):
    """:func:`rhs` written into ``out``, allocating nothing for KIN."""
    if kind == KIN:
        kin_rhs_into(x, u1, u1_dot, delta, P, out)
    else:
        stm_rhs_into(x, u1, u1_dot, delta, P, out)


@njit(cache=True)
def rk4_step(kind, x, dt, u1, u1_dot, delta, P):
    """One RK4 step of ``dt`` [s] of model ``kind``."""
    n = x.size
    out = np.empty(n)
    rk4_step_into(kind, x, dt, u1, u1_dot, delta, P, np.empty((5, n)), out)
    return out


@njit(cache=True)
def rk4_step_into(kind, x, dt, u1, u1_dot, delta, P, work, out):
    """:func:`rk4_step` written into ``out`` (n,), with ``work`` (5, n) as scratch.

    The one copy of the step: :func:`rk4_step` and the batched steps
    (:mod:`artic.reduced.control`) call it, so they agree to the bit. ``out``
    may be ``x`` itself (every stage reads ``x`` before the last loop writes).
    """
    if kind == KIN:
        kin_rk4_into(x, dt, u1, u1_dot, delta, P, out)
        return
    # Element loops instead of array expressions: the same operations in the
    # same order (so the same bits), without a temporary array per operation.
    h2 = 0.5 * dt
    n = x.size
    k1, k2, k3, k4, xt = work[0], work[1], work[2], work[3], work[4]
    rhs_into(kind, x, u1, u1_dot, delta, P, k1)
    for i in range(n):
        xt[i] = x[i] + h2 * k1[i]
    rhs_into(kind, xt, u1 + h2 * u1_dot, u1_dot, delta, P, k2)
    for i in range(n):
        xt[i] = x[i] + h2 * k2[i]
    rhs_into(kind, xt, u1 + h2 * u1_dot, u1_dot, delta, P, k3)
    for i in range(n):
        xt[i] = x[i] + dt * k3[i]
    rhs_into(kind, xt, u1 + dt * u1_dot, u1_dot, delta, P, k4)
    w = dt / 6.0
    for i in range(n):
        out[i] = x[i] + w * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@njit(cache=True)
def kin_rk4_into(x, dt, u1, u1_dot, delta, P, out):
    """:func:`rk4_step_into` for KIN, through :func:`kin_rk4`."""
    out[0], out[1], out[2], out[3] = kin_rk4((x[0], x[1], x[2], x[3]), dt, u1, u1_dot, delta,
                                             (P[0], P[1], P[2]))


@njit(cache=True)
def kin_rk4(state, dt, u1, u1_dot, delta, lengths):
    """KIN's :func:`rk4_step` in scalars: the same operations in the same order.

    KIN's rates depend on ``psi_1`` and ``gamma`` alone, so only their stage
    values are formed; every other operation is the generic step's, so the
    bits are its bits, at a fraction of its cost in a batch (no array views
    or temporaries). ``state`` is ``(X_1, Y_1, psi_1, gamma)`` [m, m, rad, rad] and
    ``lengths`` ``(L1, L1c, L2)`` [m]; returns the state ``dt`` [s] later.
    """
    X, Y, psi, gamma = state
    L1, L1c, L2 = lengths
    h2 = 0.5 * dt
    a0, a1, a2, a3 = kin_rates(psi, gamma, u1, delta, L1, L1c, L2)
    b0, b1, b2, b3 = kin_rates(psi + h2 * a2, gamma + h2 * a3, u1 + h2 * u1_dot, delta,
                               L1, L1c, L2)
    c0, c1, c2, c3 = kin_rates(psi + h2 * b2, gamma + h2 * b3, u1 + h2 * u1_dot, delta,
                               L1, L1c, L2)
    d0, d1, d2, d3 = kin_rates(psi + dt * c2, gamma + dt * c3, u1 + dt * u1_dot, delta,
                               L1, L1c, L2)
    w = dt / 6.0
    return (X + w * (a0 + 2.0 * b0 + 2.0 * c0 + d0), Y + w * (a1 + 2.0 * b1 + 2.0 * c1 + d1),
            psi + w * (a2 + 2.0 * b2 + 2.0 * c2 + d2),
            gamma + w * (a3 + 2.0 * b3 + 2.0 * c3 + d3))


@njit(cache=True)
def observe(kind, x, u1, delta, P, s1, s2):
    """Signals at the sensor points of model ``kind``, in ``OBSERVATION`` order."""
    if kind == KIN:
        return kin_observe(x, u1, delta, P, s1, s2)
    return stm_observe(x, u1, delta, P, s1, s2)
