"""Fixed-step fourth-order Runge-Kutta for sampled-and-held inputs.

Logs hold their inputs over each sample, so every sample is a discontinuity.
An adaptive solver would shrink its step at each one; a fixed step at the log
rate is both faster and exactly aligned with the samples.

``rhs(x, u1, u1_dot, delta, P)`` returns the state derivative. Within a step
the speed rises linearly, ``u1(t) = u1 + u1_dot * t``.
"""

from __future__ import annotations

from numba import njit


def make_rk4(rhs):
    """Build a compiled RK4 step ``step(x, dt, u1, u1_dot, delta, P)`` for ``rhs``.

    Parameters
    ----------
    rhs : numba dispatcher
        ``rhs(x, u1, u1_dot, delta, P) -> x_dot``.
    """

    @njit(cache=True)
    def step(x, dt, u1, u1_dot, delta, P):
        h2 = 0.5 * dt
        k1 = rhs(x, u1, u1_dot, delta, P)
        k2 = rhs(x + h2 * k1, u1 + h2 * u1_dot, u1_dot, delta, P)
        k3 = rhs(x + h2 * k2, u1 + h2 * u1_dot, u1_dot, delta, P)
        k4 = rhs(x + dt * k3, u1 + dt * u1_dot, u1_dot, delta, P)
        return x + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)

    return step
