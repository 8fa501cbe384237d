"""artic's PAC2002 against an independent evaluation written from the book's equations.

``tests/reference/pac2002_book.py`` was written from Pacejka (2006) and the
MF-Tyre 5.2 equations without reading artic's tyre code. Both evaluate the
same closed forms in double precision, so they agree to rounding: 1e-6
relative is a bound that a wrong sign, a lost factor or a term evaluated at
the angle instead of its tangent fails by orders of magnitude. Forces that
vanish (at zero slip or load) are compared on a floor of 1 N or 1 N m.

Conventions mapped here, once: artic's slip angle is the negative of the
file's (artic's positive angle gives a leftward force); both report Fx, Fy
and Mz in ISO axes. The reference forms cos(alpha') = V_cx / (V_c + eps) from
a speed, with the Magic Formula's eps = 1e-6 m/s; artic takes it from the
tread state, cos(alpha), with no eps. At 10 m/s that eps alone moves Mz by
up to 6e-6 where trail and residual torque nearly cancel, so the reference is
evaluated at V_CX, where eps is 1e-10 of V_c.
"""

from __future__ import annotations

import dataclasses
from importlib import resources

import numpy as np
import pytest

from artic.plant.tyre import TyreParams, steady_state
from tests.reference import pac2002_book as book
from tests.shared_data import REFERENCE_TYRE, needs

SHIPPED = [str(resources.files("artic.mjcf") / "tyres" / n)
           for n in ("artic-truck-315-80R22.5.tir", "artic-trailer-385-65R22.5.tir")]
V_CX = 1e4
"""Forward speed given to the reference [m/s] (see the module docstring)."""

FILES = [*SHIPPED, pytest.param(str(REFERENCE_TYRE), marks=needs(REFERENCE_TYRE))]


def grid():
    fz = np.array([5e3, 20e3, 35e3, 60e3])[:, None, None]
    kappa = np.array([-0.3, -0.05, 0.0, 0.02, 0.1, 0.3])[None, :, None]
    alpha = np.radians([-20.0, -8.0, -2.0, 0.0, 1.0, 5.0, 12.0, 20.0])[None, None, :]
    return np.broadcast_arrays(fz, kappa, alpha)


def compare(ours, ref, what):
    for name, a, b in zip(("Fx", "Fy", "Mz"), ours, ref, strict=True):
        err = np.abs(a - b) / np.maximum(np.abs(b), 1.0)
        assert err.max() < 1e-6, f"{what} {name}: worst relative error {err.max():.2e}"


@pytest.mark.parametrize("path", FILES)
@pytest.mark.parametrize("lfzo", [1.0, 1.2])
def test_combined_slip_forces_and_moment_agree_with_the_book(path, lfzo):
    p = dataclasses.replace(TyreParams.from_tir(path), LFZO=lfzo)
    c = book.read_tir(path)
    c["LFZO"] = lfzo
    fz, kappa, alpha = grid()
    ours = steady_state(p, fz, kappa, alpha)
    ref = book.steady_state(c, fz, kappa, -alpha, 0.0, V_CX)  # the file's slip angle
    compare(ours, ref, f"{path} LFZO={lfzo}")


@pytest.mark.parametrize("path", FILES)
def test_pure_slip_agrees_with_the_book(path):
    p = TyreParams.from_tir(path)
    c = book.read_tir(path)
    fz = np.linspace(2e3, 70e3, 9)[:, None]
    a = np.radians(np.linspace(-25.0, 25.0, 21))[None, :]
    compare(steady_state(p, fz, 0.0 * a, a), book.steady_state(c, fz, 0.0 * a, -a, 0.0, V_CX),
            "pure alpha")
    k = np.linspace(-0.4, 0.4, 21)[None, :]
    compare(steady_state(p, fz, k, 0.0 * k), book.steady_state(c, fz, k, 0.0 * k, 0.0, V_CX),
            "pure kappa")


def test_lfzo_scales_the_cornering_stiffness_once():
    # Ky = PKY1 Fz0' sin(2 atan(Fz / (PKY2 Fz0'))) LKY with Fz0' = LFZO FNOMIN: at a
    # load of Fz0' the stiffness is PKY1 Fz0' sin(2 atan(1/PKY2)), proportional to
    # LFZO exactly once.
    p = TyreParams.from_tir(SHIPPED[0])
    q = dataclasses.replace(p, LFZO=1.2)
    expect = abs(p.PKY1) * q.Fz0 * np.sin(2 * np.arctan(1 / p.PKY2))
    assert q.cornering_stiffness(q.Fz0) == pytest.approx(expect, rel=1e-12)


def test_aligning_moment_restores_and_turns_with_travel():
    p = TyreParams.from_tir(SHIPPED[1])
    a = np.radians([2.0])
    _, fy, mz = steady_state(p, 40e3, 0.0, a)
    # Slip to the right (positive alpha): leftward force behind the centre, so a
    # clockwise moment that turns the wheel toward its travel.
    assert fy > 0 and mz < 0
    # The pneumatic trail is Mz / Fy near zero slip: QDZ1 R0 at the nominal load.
    small = np.radians(0.05)
    fy0, mz0 = steady_state(p, 40e3, 0.0, small)[1:]
    fy1, mz1 = steady_state(p, 40e3, 0.0, -small)[1:]
    assert -(mz0 - mz1) / (fy0 - fy1) == pytest.approx(p.QDZ1 * p.UNLOADED_RADIUS, rel=1e-3)
    # Reversing, the contact patch's leading edge is behind: the trail turns over.
    assert steady_state(p, 40e3, 0.0, a, -1.0)[2] == pytest.approx(-mz)
