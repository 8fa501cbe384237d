"""The wheel-spin/tread mode, and its integration at a finite step.

Each wheel end's spin ``Omega`` [rad/s] and longitudinal tread deflection
``u`` [m] (:mod:`artic.plant.tyre`) form a small linear system of their own.
With the chassis' speed ``V_x`` held (a wheel's spin inertia is a few per
cent of the mass it carries), per wheel end of ``n`` tyres:

    dOmega/dt = (Q + Q_o) / I,   Q = q_x n F_x,   F_x = k u + c (Omega R_e - V_x)
    du/dt     = Omega R_e - V_x - b u

with ``I`` the spin dof's inertia, ``q_x`` the generalized force on the spin
per newton of longitudinal force at the contact point (minus the hub's height
[m]), ``k = K_x / sigma_kappa`` the tread's stiffness [N/m], ``c`` the low-speed
damper [N s/m] (:func:`artic.plant.tyre.longitudinal_tread`), ``b = |V_x| /
sigma_kappa`` [1/s] and ``Q_o`` the spin's other torques (drive, brakes).
So ``d(Omega, u)/dt = J (Omega, u) + inputs`` with

    J = [[q_x n c R_e / I, q_x n k / I],
         [R_e,             -b         ]].

At standstill (``b = 0``, the damper fully in) the eigenvalues of ``J`` are
real, about -44 and -430 1/s for artic's tyres; rolling above ``VXLOW`` (no
damper) they are ``-b/2 +- i 137`` 1/s. RK4 is stable for real ``h lambda``
down to -2.785: the fast standstill root limits its step to about 6 ms
(``docs/design/timestep.md``). Nothing else in the plant is that fast.

**The fit.** At a step ``h`` the tyre callback does not hand the integrator
the rate ``f = (dOmega/dt, du/dt)`` but ``g(h J) f``, with the matrix function
of

    g(z) = 1 / (1 + (z / z_0)^4),   z_0 = FIT_SCALE.

It does so by adding to the tyre's force ``F_x`` and to ``du/dt`` the terms
of a state correction ``y = (g(h J) - 1) J^-1 f``: ``dF_x = (c R_e, k) . y``
and ``d(du/dt) = (J y)_u``; the force on the contact point gives the spin
exactly ``(J y)_Omega`` and gives the chassis what the fitted mode's lag
does, so momentum balances. Then:

- every eigenvalue ``lambda`` of the mode becomes ``g(h lambda) lambda``: the
  slow root (-44 1/s at standstill) keeps its rate within ``(h lambda / z_0)^4``
  (4e-4 at 10 ms), the fast root leaves RK4's unstable range: on the real
  axis ``z g(z)`` is never below ``-0.57 z_0``;
- equilibria are those of the model (``f = 0`` gives ``y = 0``): a wheel held
  by its brake or its drive torque does not creep;
- the correction is ``O(h^4)``: as the step shrinks the plant converges to the
  model's own solution, at RK4's order. At 1 ms it changes the fast root by
  2e-4 of itself.

``g`` has poles where ``(z / z_0)^4 = -1``, at ``|z| = z_0`` and 45 degrees
off either axis. The mode's eigenvalues stay away from them: on both axes
``(z / z_0)^4 >= 0``, and a pair 45 degrees off the negative axis (damping
ratio 0.71, ``a + b = sqrt(2) |lambda|``, ``|lambda|^2 = omega_0^2 + a b``
with ``a b <= (a + b)^2 / 4``) has ``|lambda| <= sqrt(2) omega_0``: at most
200 1/s for artic's tyres, ``|z / z_0| <= 0.5`` at 10 ms.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

FIT_SCALE = 4.0
"""``z_0`` of the fit ``g(z) = 1 / (1 + (z / z_0)^4)`` [-] (see the module docstring).

Large enough that the rolling mode (``|h lambda| = 1.4`` at 10 ms) keeps its
rate within 1.5 % and that ``g``'s poles stay far from the mode's eigenvalues,
small enough that the fitted fast root, at most ``0.57 z_0 = 2.28`` on the real
axis, stays within RK4's stability interval (2.785)."""

RK4_REAL_LIMIT = 2.785293563
"""RK4 is stable for real ``h lambda`` in ``[-RK4_REAL_LIMIT, 0]`` [-]."""


def rk4_amplification(z):
    """RK4's factor per step on ``dx/dt = lambda x``, ``z = h lambda`` [-]."""
    return 1.0 + z + z * z / 2.0 + z ** 3 / 6.0 + z ** 4 / 24.0


def fit_factor(z, scale: float = FIT_SCALE):
    """The fit's ``g(z) = 1 / (1 + (z / z_0)^4)`` of a mode at ``z = h lambda`` [-]."""
    return 1.0 / (1.0 + (np.asarray(z) / scale) ** 4)


def jacobian(inv_inertia, q_x, n, Re, k, c, b) -> np.ndarray:
    """The mode's ``J``, shape ``(..., 2, 2)`` (module docstring).

    Rows: ``dOmega/dt`` [rad/s^2] and ``du/dt`` [m/s]; columns: ``Omega``
    [rad/s] and ``u`` [m].

    Parameters
    ----------
    inv_inertia : array_like
        Inverse inertia of the spin dof [1/(kg m^2)].
    q_x : array_like
        Generalized force on the spin per newton of ``F_x`` at the contact [m].
    n : array_like
        Tyres on the wheel end.
    Re : array_like
        Effective rolling radius [m].
    k, c : array_like
        Tread stiffness [N/m] and low-speed damper [N s/m], per tyre.
    b : array_like
        Rolling relaxation rate ``|V_x| / sigma_kappa`` [1/s].
    """
    g = np.asarray(q_x) * n * inv_inertia
    Re, k, c, b = np.broadcast_arrays(Re, k, c, b)
    J = np.empty(np.broadcast_shapes(np.shape(g), Re.shape) + (2, 2))
    J[..., 0, 0] = g * c * Re
    J[..., 0, 1] = g * k
    J[..., 1, 0] = Re
    J[..., 1, 1] = -b
    return J


def eigenvalues(inv_inertia, q_x, n, Re, k, c, b) -> np.ndarray:
    """The mode's two eigenvalues [1/s], fastest first (real ones sorted by magnitude)."""
    lam = np.linalg.eigvals(jacobian(inv_inertia, q_x, n, Re, k, c, b))
    order = np.argsort(-np.abs(lam), axis=-1)
    return np.take_along_axis(lam, order, axis=-1)


DET_MIN = 0.5
"""Smallest ``det(1 + P^4)`` the fit divides by [-]; below it (never reached by a
mode of a tyre with the module docstring's bounds) the wheel end is integrated plainly."""


@dataclasses.dataclass(frozen=True)
class Mode:
    """The coefficients of wheel ends' spin/tread modes, as :func:`jacobian` takes them.

    Each is a float or an array over wheel ends; see :func:`jacobian` for their units.
    """

    inv_inertia: Any
    q_x: Any
    n: Any
    Re: Any
    k: Any
    c: Any
    b: Any


def fit(h: float, mode: Mode, f_spin, f_u,
        scale: float = FIT_SCALE) -> tuple[np.ndarray, np.ndarray]:
    """The fit's additions to a wheel end's ``F_x`` [N per tyre] and ``du/dt`` [m/s].

    The C callback's ``artic_spin_fit``, term by term.

    Parameters
    ----------
    h : float
        The integrator's step [s]; 0 (or ``scale`` 0) adds nothing.
    mode : Mode
        The wheel ends' ``inv_inertia, q_x, n, Re, k, c, b``, as in :func:`jacobian`.
    f_spin : array_like
        ``dOmega/dt`` of the spin now, from everything acting on it [rad/s^2].
    f_u : array_like
        The tyre's ``du/dt`` now [m/s].
    scale : float
        ``z_0`` (:data:`FIT_SCALE`).

    Returns
    -------
    dFx, ddu : ndarray
        ``(c R_e, k) . y`` and ``(J y)_u``, with ``y = -(1 + P^4)^-1 P^3 (s f)``,
        ``s = h / z_0`` and ``P = s J``.
    """
    inv_inertia, q_x, n = mode.inv_inertia, mode.q_x, mode.n
    f_spin, f_u, k, c, b, Re = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in
                                                     (f_spin, f_u, mode.k, mode.c, mode.b,
                                                      mode.Re)))
    if not (scale > 0.0 and h > 0.0):
        return np.zeros_like(f_spin), np.zeros_like(f_spin)
    g = np.asarray(q_x) * n * inv_inertia
    s = h / scale
    p0, p1, p2, p3 = s * g * c * Re, s * g * k, s * Re, -s * b
    w0, w1 = s * f_spin, s * f_u
    for _ in range(3):
        w0, w1 = p0 * w0 + p1 * w1, p2 * w0 + p3 * w1
    q0, q1 = p0 * p0 + p1 * p2, p0 * p1 + p1 * p3
    q2, q3 = p2 * p0 + p3 * p2, p2 * p1 + p3 * p3
    n0, n1 = 1.0 + q0 * q0 + q1 * q2, q0 * q1 + q1 * q3
    n2, n3 = q2 * q0 + q3 * q2, 1.0 + q2 * q1 + q3 * q3
    det = n0 * n3 - n1 * n2
    ok = det > DET_MIN
    det = np.where(ok, det, 1.0)
    y0 = np.where(ok, -(n3 * w0 - n1 * w1) / det, 0.0)
    y1 = np.where(ok, -(-n2 * w0 + n0 * w1) / det, 0.0)
    return c * Re * y0 + k * y1, Re * y0 - b * y1

