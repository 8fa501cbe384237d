"""The truth's TMeasy tyre: its fit to the shipped tyres, and its equations' properties."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from artic.mjcf.vehicle import resolve_tyre_file
from artic.plant.plant import scaled
from artic.plant.tyre import TyreParams
from artic.validation.synthetic import tmeasy, truthc
from tests.helpers import needs_compiled

pytestmark = needs_compiled("the truth's compiled TMeasy tyres")

TYRES = ("artic-truck-315-80R22.5.tir", "artic-trailer-385-65R22.5.tir")


def path(name: str) -> str:
    return str(resolve_tyre_file(name, "shipped", "test"))


@pytest.fixture(scope="module")
def truck() -> tmeasy.TMeasy:
    return tmeasy.fit(path(TYRES[0]))


@pytest.mark.parametrize("name", TYRES)
@pytest.mark.parametrize("scaling", [(), (("LKY", 1.08), ("LMUY", 0.95))])
def test_the_fit_meets_its_stated_tolerances(name, scaling):
    t = tmeasy.fit(path(name), scaling)
    p = scaled(TyreParams.from_tir(path(name)), scaling)
    err = tmeasy.fit_errors(t, p)
    for what, tol in tmeasy.TOLERANCE.items():
        assert err[what] <= tol, (what, err)
    # Another family: it does not reproduce PAC2002's curves to rounding.
    assert err["Fx"] > 0.005 and err["Mz"] > 0.02, err
    # The scaling reaches the fitted tyre: stiffer and less grippy than unscaled.
    if scaling:
        plain = tmeasy.fit(path(name))
        assert t.dfy0_1 == pytest.approx(1.08 * plain.dfy0_1, rel=1e-6)
        assert t.fym_1 == pytest.approx(0.95 * plain.fym_1, rel=0.01)


def test_the_transient_stiffnesses_keep_the_files_relaxation_length(truck):
    p = TyreParams.from_tir(path(TYRES[0]))
    Fz = p.FNOMIN
    # c_y = Ky / sigma_alpha at the nominal load, so TMeasy's dF0 / c_y is the
    # file's relaxation length there (within the load law's 3 % on dF0).
    assert truck.relaxation_length(Fz) == pytest.approx(float(p.sigma_alpha(np.array(Fz))),
                                                        rel=tmeasy.TOLERANCE["slope"])
    assert truck.dy / truck.cy == pytest.approx(tmeasy.DAMPING_TIME, rel=1e-12)
    assert truck.dx / truck.cx == pytest.approx(tmeasy.DAMPING_TIME, rel=1e-12)


@pytest.mark.parametrize("load", [1, 2])
def test_pure_slip_follows_the_characteristic_through_its_points(truck, load):
    # At Fz_N and 2 Fz_N the load law gives the points themselves; the
    # characteristic starts at slope dF0, peaks at (sM, FM) with zero slope
    # and slides at FS beyond sS.
    Fz = load * truck.fzn
    h = 1e-6
    for axis in ("x", "y"):
        g = {k: getattr(truck, f"{k.replace('?', axis)}_{load}")
             for k in ("df?0", "f?m", "s?m", "f?s", "s?s")}

        def force(s, axis=axis):
            Fx, Fy, _ = truck.steady(Fz, s if axis == "x" else 0.0, s if axis == "y" else 0.0)
            return Fx if axis == "x" else Fy

        slope = (force(h) - force(-h)) / (2 * h)
        assert slope == pytest.approx(g["df?0"], rel=1e-5)
        assert force(g["s?m"]) == pytest.approx(g["f?m"], rel=1e-9)
        peak_slope = (force(g["s?m"] + 1e-5) - force(g["s?m"] - 1e-5)) / 2e-5
        assert abs(peak_slope) < 1e-3 * g["df?0"]
        assert force(np.array([1.0, 2.0, 5.0]) * g["s?s"]) == pytest.approx(g["f?s"], rel=1e-12)
        # Odd in the slip, and continuous where the pieces meet.
        assert force(-0.5 * g["s?m"]) == pytest.approx(-force(0.5 * g["s?m"]), rel=1e-12)
        for s in (g["s?m"], g["s?s"]):
            assert force(s * (1 + 1e-9)) == pytest.approx(force(s * (1 - 1e-9)), rel=1e-6)


def test_the_load_law_is_quadratic_through_zero(truck):
    # Sliding forces at 0.5 and 1.5 Fz_N: X(r) = r (X1 (2 - r) + X2 (r - 1) / 2).
    for r in (0.5, 1.5):
        Fz = r * truck.fzn
        _, Fy, _ = truck.steady(Fz, 0.0, 10.0)
        want = r * (truck.fys_1 * (2 - r) + truck.fys_2 * 0.5 * (r - 1))
        assert float(Fy) == pytest.approx(want, rel=1e-12)
    # No load, no force.
    assert truck.steady(0.0, 0.1, 0.1)[1] == 0.0


def test_combined_slip_shares_one_friction_limit(truck):
    rng = np.random.default_rng(1)
    Fz = truck.fzn
    # Fully sliding, in any direction, the force is the sliding force of that
    # direction, FS(phi) = hypot(FSx cos phi, FSy sin phi): |F|^4 = FSx^2 Fx^2 + FSy^2 Fy^2.
    phi = rng.uniform(0.0, 2 * math.pi, 50)
    sx, sy = 20.0 * np.cos(phi), 20.0 * np.sin(phi)
    Fx, Fy, _ = truck.steady(Fz, sx, sy)
    lhs = (Fx ** 2 + Fy ** 2) ** 2
    rhs = truck.fxs_1 ** 2 * Fx ** 2 + truck.fys_1 ** 2 * Fy ** 2
    np.testing.assert_allclose(lhs, rhs, rtol=1e-9)
    # The force points the way the slip does, quadrant by quadrant.
    assert np.all(np.sign(Fx) == np.sign(sx)) and np.all(np.sign(Fy) == np.sign(sy))
    # Past the lateral peak, braking or driving takes lateral force away.
    _, pure, _ = truck.steady(Fz, 0.0, 0.5)
    _, both, _ = truck.steady(Fz, np.array([-0.1, 0.1]), 0.5)
    assert np.all(both < 0.9 * pure)


def test_the_deflection_is_a_first_order_lag_to_the_steady_force(truck):
    p = truck.vector()
    Fz, v = truck.fzn, 5.0
    # The rate's slope in the deflection at small lateral slip is -1 / tau with
    # tau = d / c + dF0 / (c v*), v* = |v_roll| + v_N: the relaxation length
    # dF0 / c travelled at v*, and the damper's own time. (At exactly zero
    # slip the slip has no direction, and TMeasy takes the characteristic at
    # 45 deg; a micro-slip to the side makes it the lateral one.)
    tau = truck.dy / truck.cy + truck.dfy0_1 / (truck.cy * (v + truck.vn))
    e = 1e-7
    out = truthc.dynamic(p, Fz, v, -1e-5, v, 0.0, 0.0, np.array([-e, e]), 0.0)
    # (1e-4: the characteristic bends by s / sM at the micro-slip)
    assert (out["dye"][1] - out["dye"][0]) / (2 * e) == pytest.approx(-1.0 / tau, rel=1e-4)
    # Integrated at a constant slip, the deflection's force settles on the steady force.
    vy = -0.02 * v
    ye, dt = 0.0, 1e-3
    for _ in range(int(20 * tau / dt)):  # classic RK4, to within exp(-20)
        def f(y):
            return float(truthc.dynamic(p, Fz, v, vy, v, 0.0, 0.0, y, 0.0)["dye"][0])
        k1 = f(ye)
        k2 = f(ye + 0.5 * dt * k1)
        k3 = f(ye + 0.5 * dt * k2)
        k4 = f(ye + dt * k3)
        ye += dt * (k1 + 2 * k2 + 2 * k3 + k4) / 6
    Fy = truthc.dynamic(p, Fz, v, vy, v, 0.0, 0.0, ye, 0.0)["Fy"][0]
    _, steady, _ = truck.steady(Fz, 0.0, -vy / (v + truck.vn))
    assert Fy == pytest.approx(float(steady), rel=1e-6)


def test_standstill_and_reverse_are_sound(truck):
    p = truck.vector()
    Fz = truck.fzn
    rng = np.random.default_rng(2)
    n = 200
    states = [rng.normal(0.0, s, n) for s in (0.01, 0.01, 0.05)]
    # At standstill, with the wheel still, every state gives finite forces and
    # rates, and a held deflection creeps back only at v_N's pace.
    out = truthc.dynamic(p, Fz, 0.0, 0.0, 0.0, 0.0, *states)
    assert all(np.all(np.isfinite(x)) for x in out.values())
    creep = -out["dye"] / states[1]
    assert np.all(creep > 0) and np.all(creep < 0.05)  # [1/s]: v_N c / dF0, about 0.02 /s
    # Reversing: the lateral force is the same, the aligning torque turns
    # round (the trail is ahead now), traction and rolling resistance turn.
    fwd = truthc.dynamic(p, Fz, 2.0, -0.05, 2.05, 0.0, 0.001, 0.002, 0.0)
    rev = truthc.dynamic(p, Fz, -2.0, -0.05, -2.05, 0.0, -0.001, 0.002, 0.0)
    assert rev["Fy"] == pytest.approx(fwd["Fy"], rel=1e-9)
    assert rev["Mz"] == pytest.approx(-fwd["Mz"], rel=1e-6)
    assert rev["Fx"] == pytest.approx(-fwd["Fx"], rel=1e-9) and fwd["Fx"][0] > 0
    assert rev["My"] == pytest.approx(-fwd["My"], rel=1e-9)
    # Rolling resistance: f_r Fz r0 against the rolling, once rolling.
    assert fwd["My"][0] == pytest.approx(-truck.fr * Fz * truck.r0, rel=1e-3)
    # Self-aligning: a leftward force turns the wheel back to the right.
    assert fwd["Fy"][0] > 0 > fwd["Mz"][0]


def test_the_bore_torque_resists_turning_at_standstill_up_to_friction(truck):
    p = truck.vector()
    Fz, w = truck.fzn, 0.3  # the wheel turned on the spot at 0.3 rad/s
    pe, dt, torque = 0.0, 1e-3, []
    for _ in range(2000):
        out = truthc.dynamic(p, Fz, 0.0, 0.0, 0.0, w, 0.0, 0.0, pe)
        torque.append(out["Mz"][0])
        pe += dt * out["dpe"][0]
    torque = np.array(torque)
    L = 2 * math.sqrt(truck.r0 * Fz / truck.cz)
    rb = (0.5 * L + 0.5 * truck.width) / 3
    limit = rb * math.hypot(truck.fxm_1, truck.fym_1)
    assert torque[-1] < 0 and np.all(torque <= 1e-9)  # against the turning
    assert np.max(np.abs(torque)) <= limit
    # It builds up to sliding within the twist it was given (BORE_TWIST at Fz_N).
    assert abs(torque[-1]) > 0.5 * rb * truck.fys_1
    turned = w * np.argmax(np.abs(torque) > 0.5 * abs(torque[-1])) * dt
    assert turned < 2 * tmeasy.BORE_TWIST


def test_the_compiled_order_is_the_dataclass(truck):
    assert set(truthc.tyre_names()) == {f.name for f in dataclasses.fields(truck)}
    v = truck.vector()
    assert v[truthc.tyre_names().index("cy")] == truck.cy
