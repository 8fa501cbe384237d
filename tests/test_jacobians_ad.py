"""KIN's hand-derived Jacobians against CasADi's automatic differentiation.

The reference is eq. (1) of "Model Validation of a Low-Speed and Reverse
Driving Articulated Vehicle" written here in CasADi's symbols (no code of
artic's), differentiated by CasADi; :meth:`artic.KIN.jacobians` is derived by
hand (:mod:`artic.reduced.jacobians`). The STM's Jacobians are checked against
finite differences in ``tests/test_control.py``; its right-hand side is
compiled numba code that CasADi cannot trace.
"""

from __future__ import annotations

import numpy as np
import pytest

import artic

casadi = pytest.importorskip("casadi", reason="CasADi (the optional [control] extra) is not "
                                              "installed: no automatic differentiation to "
                                              "compare with")


def kin_reference(L1: float, L1c: float, L2: float):
    """Eq. (1) in CasADi: the functions ``A(x, u)`` and ``B(x, u)``, ``u = (delta, u1)``."""
    x = casadi.SX.sym("x", 4)
    u = casadi.SX.sym("u", 2)
    psi, gamma = x[2], x[3]
    delta, u1 = u[0], u[1]
    r1 = u1 * casadi.tan(delta) / L1
    f = casadi.vertcat(u1 * casadi.cos(psi), u1 * casadi.sin(psi), r1,
                       -u1 * casadi.sin(gamma) / L2 + (1.0 - L1c * casadi.cos(gamma) / L2) * r1)
    return (casadi.Function("A", [x, u], [casadi.jacobian(f, x)]),
            casadi.Function("B", [x, u], [casadi.jacobian(f, u)]))


@pytest.mark.parametrize("preset", ["gosar2022-unloaded", "scale-model-1to14"])
def test_kin_jacobians_equal_casadis(preset):
    # Both are exact derivatives of the same closed form, so they agree to
    # rounding: 1e-12 relative to the largest entry (a few ulps of sums of
    # products of order-one terms), over headings, articulations, steering
    # angles and speeds in either direction.
    model = artic.KIN(artic.load_vehicle(preset))
    p = model.params
    A_ad, B_ad = kin_reference(p.L1, p.L1c, p.L2)
    rng = np.random.default_rng(45)
    for _ in range(200):
        x = np.array([*rng.uniform(-50.0, 50.0, 2), rng.uniform(-np.pi, np.pi),
                      rng.uniform(-1.2, 1.2)])
        u = np.array([rng.uniform(-0.6, 0.6), rng.uniform(-3.0, 3.0)])
        A, B = model.jacobians(x, u)
        A_ref, B_ref = np.array(A_ad(x, u)), np.array(B_ad(x, u))
        scale = max(np.abs(A_ref).max(), np.abs(B_ref).max(), 1.0)
        np.testing.assert_allclose(A, A_ref, rtol=0.0, atol=1e-12 * scale)
        np.testing.assert_allclose(B, B_ref, rtol=0.0, atol=1e-12 * scale)

