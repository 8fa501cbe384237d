"""The plant's PAC2002 tyre, checked by hand formulas on a real truck tyre file."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from artic.mjcf.tir import TirError, read_tir
from artic.plant.tyre import (
    TyreParams,
    TyreRangeWarning,
    check_ranges,
    deflection_rates,
    forces,
    rolling_resistance,
    steady_deflections,
    transient_forces,
)
from tests.shared_data import REFERENCE_TYRE, needs

TIR = REFERENCE_TYRE

# Every test here checks formulas on the real truck tyre file of ../shared.
pytestmark = needs(TIR)


@pytest.fixture(scope="module")
def p():
    return TyreParams.from_tir(TIR)


def test_reader_sections_and_values():
    tir = read_tir(TIR)
    assert tir.text("PROPERTY_FILE_FORMAT") == "PAC2002"
    assert tir.number("FNOMIN") == 35000.0
    assert tir.sections["LATERAL_COEFFICIENTS"]["PKY1"] == -10.289
    assert tir.number("NO_SUCH_KEY", 3.0) == 3.0
    with pytest.raises(TirError, match="NO_SUCH_KEY: missing"):
        tir.number("NO_SUCH_KEY")


@pytest.mark.parametrize("line,words", [
    ("FNOMIN = 35000 kN", "is not a number"),
    ("this is not a line", "line 2 is neither"),
    ("PROPERTY_FILE_FORMAT = 'MF62'", "not PAC2002"),
])
def test_reader_refuses_bad_lines(tmp_path, line, words):
    bad = tmp_path / "bad.tir"
    bad.write_text("[MODEL]\n" + line + "\n")
    with pytest.raises(TirError, match=words) as err:
        read_tir(bad)
    assert str(bad) in str(err.value)


def test_cornering_stiffness_at_nominal_load(p):
    # K_y = PKY1 * FNOMIN * sin(2 atan(1 / PKY2)) at Fz = FNOMIN, in magnitude.
    # The Magic Formula runs in tan(alpha), so the slope of F_y(alpha) is
    # K_y / cos^2(alpha) where the horizontal shift is undone, tan(alpha) = PHY1
    # (ISO sign); evaluated at alpha itself it would be K_y.
    K = abs(-10.289 * 35000.0 * math.sin(2.0 * math.atan(1.0 / 3.3343)))
    assert p.cornering_stiffness(35000.0) == pytest.approx(K, rel=1e-12)
    Fz, a0, h = np.array([35000.0]), math.atan(0.0056509), 1e-6
    slope = (forces(p, Fz, [0.0], [a0 + h])[1] - forces(p, Fz, [0.0], [a0 - h])[1]) / (2 * h)
    assert slope[0] == pytest.approx(K / math.cos(a0) ** 2, rel=1e-8)
    # Normalised: about 5.8 /rad at 30 kN, the paper's f = 6 /rad.
    assert p.cornering_stiffness(30e3) / 30e3 == pytest.approx(5.79, abs=0.01)


def test_peak_friction(p):
    # With shape factor C > 1 the sine reaches 1: the peak of F - S_V is D = mu Fz.
    Fz = np.full(20001, 35000.0)
    a = np.linspace(-0.8, 0.8, Fz.size)
    k = np.linspace(-0.8, 0.8, Fz.size)
    Fy = forces(p, Fz, np.zeros_like(a), a)[1]
    Fx = forces(p, Fz, k, np.zeros_like(k))[0]
    SVy, SVx = 35000.0 * 0.015216, 35000.0 * -5.5714e-7
    assert np.max(np.abs(Fy - SVy)) == pytest.approx(0.73957 * 35000.0, rel=1e-5)
    assert np.max(np.abs(Fx - SVx)) == pytest.approx(0.77751 * 35000.0, rel=1e-5)


def test_positive_slip_angle_pushes_left(p):
    Fz = np.array([10e3, 35e3, 60e3])
    for alpha in (0.02, 0.1, 0.5):
        assert np.all(forces(p, Fz, np.zeros(3), np.full(3, alpha))[1] > 0)
        assert np.all(forces(p, Fz, np.zeros(3), np.full(3, -alpha))[1] < 0)


def test_the_lateral_formula_runs_in_the_tangent(p):
    # At 40 deg, tan(alpha) is 19 % past alpha: evaluated at alpha the force
    # would differ by the Magic Formula's slope over that distance.
    Fz = np.array([35000.0])
    a = math.radians(40.0)
    fy = forces(p, Fz, [0.0], [a])[1][0]
    q = dataclasses.replace(p, PHY1=0.0, PHY2=0.0, PVY1=0.0, PVY2=0.0)
    fy_shiftless = forces(q, Fz, [0.0], [math.atan(math.tan(a))])[1][0]
    assert fy_shiftless != pytest.approx(fy, rel=1e-9)  # the shifts matter here
    # With no shifts, F_y(alpha) is the pure Magic Formula at tan(alpha).
    C, mu = q.PCY1, q.PDY1
    Ky = q.cornering_stiffness(35000.0)
    # The file's slip angle is -alpha: its curvature factor takes PEY3 with sgn = -1.
    B, D, E = Ky / (C * mu * 35000.0), mu * 35000.0, q.PEY1 * (1.0 + q.PEY3)
    x = B * math.tan(a)
    assert fy_shiftless == pytest.approx(D * math.sin(C * math.atan(x - E * (x - math.atan(x)))),
                                         rel=1e-12)


def test_mirror_symmetry_for_reverse_travel(p):
    # Steady-state deflections depend on |V_x|: the same sideways slide
    # gives the same force forward and in reverse.
    Fz = np.full(3, 30e3)
    Vy = np.array([-0.05, 0.02, 0.1])
    for Vx in (0.5, 2.0):
        ss = []
        for sgn in (1.0, -1.0):
            # Solve du/dt = dv/dt = 0 for free rolling (V_sx = 0).
            v = -Vy * p.sigma_alpha(Fz) / Vx
            z = 0 * Vy
            du, dv, _ = deflection_rates(p, Fz, np.full(3, sgn * Vx), z, Vy, z, z, v, z)
            np.testing.assert_allclose(dv, 0.0, atol=1e-15)
            ss.append(transient_forces(p, Fz, np.full(3, sgn * Vx), z, Vy, z, z, v, z))
        np.testing.assert_allclose(ss[0][1], ss[1][1], rtol=1e-12)
        assert np.all(np.sign(ss[0][1]) == -np.sign(Vy))


def test_relaxation_time_constant(p):
    # dv/dt = -V_y - |V_x| v / sigma: after t = sigma / |V_x| the deflection
    # has covered 1 - 1/e of the way to its steady state.
    Fz, Vx, Vy = np.array([30e3]), np.array([1.5]), np.array([0.03])
    sigma = p.sigma_alpha(Fz)
    v, dt = np.zeros(1), 1e-5
    for _ in range(int(round(sigma[0] / Vx[0] / dt))):
        v = v + dt * deflection_rates(p, Fz, Vx, 0 * Vx, Vy, 0 * Vx, 0 * v, v, 0 * v)[1]
    v_ss = -Vy * sigma / Vx
    assert v[0] / v_ss[0] == pytest.approx(1 - math.exp(-1), abs=1e-3)


def test_steady_deflections_zero_every_rate(p):
    # Forward and reverse, turning either way, sliding and twisting: each
    # deflection rate is linear in its deflection (the twist's in |omega_z|
    # and |V_x|), so the steady state zeroes it to rounding.
    rng = np.random.default_rng(3)
    n = 200
    Fz = rng.uniform(5e3, 60e3, n)
    Vx = rng.uniform(-3.0, 3.0, n)
    Vsx, Vy = rng.normal(0.0, 0.05, n), rng.normal(0.0, 0.2, n)
    wz = rng.normal(0.0, 0.3, n)
    u, v, phi = steady_deflections(p, Fz, Vx, Vsx, Vy, wz)
    rates = deflection_rates(p, Fz, Vx, Vsx, Vy, wz, u, v, phi)
    scale = (np.abs(Vsx), np.abs(Vy), np.abs(wz))  # each rate's terms are of this size
    for r, s in zip(rates, scale, strict=True):
        np.testing.assert_allclose(r, 0.0, atol=1e-12 * max(float(s.max()), 1.0))
    # v is the slip angle's: tan(alpha) = -v / sigma_alpha = V_y / |V_x|.
    np.testing.assert_allclose(-v / p.sigma_alpha(Fz), Vy / np.abs(Vx), rtol=1e-12)
    # Standing still, nothing is steady but nothing relaxes either: zero, finite.
    still = steady_deflections(p, Fz[:3], np.zeros(3), Vsx[:3], Vy[:3], np.zeros(3))
    assert all(np.all(x == 0.0) for x in still)


def test_finite_and_smooth_through_zero_speed(p):
    # V_x from +2 to -2 m/s in 4 s while sliding 5 cm/s sideways and
    # spinning 1 cm/s too fast: forces stay finite and change by less than
    # 0.5 % of the wheel load per millisecond, the sign change included.
    dt = 1e-3
    t = np.arange(0.0, 4.0, dt)
    Vx = 2.0 - t
    Fz = np.array([30e3])
    u, v, phi = np.zeros(1), np.zeros(1), np.zeros(1)
    Fx_hist, Fy_hist, Mz_hist = [], [], []
    for vx in Vx:
        # ... and yawing at 0.05 rad/s, as a steered wheel does.
        args = (p, Fz, np.array([vx]), np.array([-0.01]), np.array([0.05]), np.array([0.05]))
        du, dv, dphi = deflection_rates(*args, u, v, phi)
        u, v, phi = u + dt * du, v + dt * dv, phi + dt * dphi
        fx, fy, mz = transient_forces(*args, u, v, phi)
        Fx_hist.append(fx[0])
        Fy_hist.append(fy[0])
        Mz_hist.append(mz[0])
    Fx_hist, Fy_hist = np.array(Fx_hist), np.array(Fy_hist)
    assert np.all(np.isfinite(Fx_hist)) and np.all(np.isfinite(Fy_hist))
    assert np.max(np.abs(np.diff(Fy_hist))) < 0.005 * Fz[0]
    assert np.max(np.abs(np.diff(Fx_hist))) < 0.005 * Fz[0]
    # The moment too: within 0.5 % of its friction bound mu Fz R0 per millisecond.
    Mz_hist = np.array(Mz_hist)
    assert np.all(np.isfinite(Mz_hist))
    assert np.max(np.abs(np.diff(Mz_hist))) < 0.005 * Fz[0] * p.UNLOADED_RADIUS
    # Sliding left throughout: the force pushes right throughout.
    assert np.all(Fy_hist[100:] < 0)


def test_rolling_resistance(p):
    Fz = np.full(3, 30e3)
    M = rolling_resistance(p, Fz, np.array([2.0, -2.0, 0.0]))
    # M_y = -QSY1 R0 Fz, against the rolling; nothing at standstill.
    assert M[0] == pytest.approx(-0.008 * 0.548 * 30e3, rel=1e-6)
    assert M[1] == pytest.approx(-M[0]) and M[2] == 0.0


def test_range_warning_names_wheel(p):
    with pytest.warns(TyreRangeWarning, match="trailer-1 L: Fz = 9e"):
        msgs = check_ranges(p, np.array([30e3, 9e4]), np.zeros(2), np.zeros(2),
                            names=["front L", "trailer-1 L"], where="t = 3.00 s")
    assert len(msgs) == 1
    assert check_ranges(p, np.array([30e3]), np.array([0.1]), np.array([0.2])) == []
