"""The wheel-spin/tread mode: its eigenvalues, and the plant's fit of it to the step.

The fit (:mod:`artic.plant.spinmode`) must leave the model's solution alone as
the step shrinks, keep its equilibria, move the fast standstill root into
RK4's stable range, and be what the plant (C and numpy) integrates.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import G
from artic.plant import Plant, PlantError, ctyre, spinmode
from artic.plant.tyre import TyreParams, longitudinal_tread
from tests.helpers import needs_compiled, rates_jacobian

TYRES = ("artic-truck-315-80R22.5.tir", "artic-trailer-385-65R22.5.tir")


def tyre(name: str) -> TyreParams:
    from importlib import resources

    return TyreParams.from_tir(resources.files("artic.mjcf") / "tyres" / name)


def wheel(p: TyreParams, Fz, Vx, inertia=12.0, n=1.0):
    """The mode's parameters of a wheel end on tyre ``p``: hub height as the lever."""
    k, c, b = longitudinal_tread(p, np.asarray(Fz, dtype=float), np.asarray(Vx, dtype=float))
    rho = np.asarray(Fz) / p.VERTICAL_STIFFNESS
    return dict(inv_inertia=1.0 / inertia, q_x=-(p.UNLOADED_RADIUS - rho), n=n,
                Re=p.UNLOADED_RADIUS - rho / 3.0, k=k, c=c, b=b)


def fitted_jacobian(h, w, scale=spinmode.FIT_SCALE):
    """The Jacobian of the rate the plant integrates, column by column from spinmode.fit.

    The fit adds ``dFx`` to the contact force, which turns the spin by
    ``inv_inertia q_x n dFx``, and ``ddu`` to the tread rate.
    """
    J = spinmode.jacobian(**w)
    out = np.empty_like(J)
    for j in range(2):
        f = J[..., :, j]
        dFx, ddu = spinmode.fit(h, spinmode.Mode(**w), f[..., 0], f[..., 1], scale)
        out[..., 0, j] = f[..., 0] + w["inv_inertia"] * w["q_x"] * w["n"] * dFx
        out[..., 1, j] = f[..., 1] + ddu
    return out


@needs_compiled("the compiled spin fit")
def test_compiled_fit_equals_the_numpy_reference():
    # The same arithmetic in the same order: they agree to rounding, 1e-12
    # relative on a floor of 1e-9 N (m/s) for terms that vanish.
    rng = np.random.default_rng(3)
    for _ in range(400):
        a = dict(h=rng.choice([0.0, 1e-3, 5e-3, 1e-2, 2e-2]), scale=rng.choice([0.0, 2.0, 4.0]),
                 inv_inertia=1.0 / rng.uniform(5.0, 30.0), q_x=-rng.uniform(0.4, 0.55),
                 n=rng.choice([1.0, 2.0]), Re=rng.uniform(0.45, 0.54),
                 k=rng.uniform(0.0, 2e6), c=rng.uniform(0.0, 5e4), b=rng.uniform(0.0, 300.0),
                 f_spin=rng.normal(0.0, 300.0), f_u=rng.normal(0.0, 0.5))
        mode = spinmode.Mode(*(a[x] for x in ("inv_inertia", "q_x", "n", "Re", "k", "c", "b")))
        got = ctyre.spin_fit(a["h"], a["scale"], mode, a["f_spin"], a["f_u"])
        ref = spinmode.fit(a["h"], mode, a["f_spin"], a["f_u"], a["scale"])
        for x, y in zip(got, ref, strict=True):
            assert abs(x - float(y)) <= 1e-12 * abs(float(y)) + 1e-9, (a, got, ref)


@pytest.mark.parametrize("name", TYRES)
def test_eigenvalues_at_standstill_and_rolling_match_the_closed_form(name):
    # At standstill (b = 0, full damper) the characteristic polynomial is
    # s^2 + a s + w0^2 with a = -q_x n c Re / I and w0^2 = -q_x n k Re / I:
    # both roots real and negative (overdamped, a > 2 w0). Rolling above VXLOW
    # (c = 0): s^2 + b s + w0^2, a lightly damped pair at +-i w0.
    p = tyre(name)
    for Vx, real in ((0.0, True), (1.5 * p.VXLOW, False)):
        w = wheel(p, 30e3, Vx)
        a = -w["q_x"] * w["n"] * w["c"] * w["Re"] * w["inv_inertia"]
        w0 = math.sqrt(-w["q_x"] * w["n"] * w["k"] * w["Re"] * w["inv_inertia"])
        roots = np.roots([1.0, a + w["b"], a * w["b"] + w0 ** 2])
        lam = spinmode.eigenvalues(**w)
        np.testing.assert_allclose(np.sort_complex(lam), np.sort_complex(roots), rtol=1e-9)
        if real:
            assert a > 2.0 * w0 and np.all(lam.real < 0.0) and np.all(lam.imag == 0.0)
        else:
            assert np.all(lam.imag != 0.0) and abs(lam[0]) == pytest.approx(w0, rel=0.01)


def test_rk4_real_stability_limit():
    # On the negative real axis RK4's factor falls to 0.27 at z = -1.596 and
    # rises back to 1 at the limit: inside it a mode decays (without changing
    # sign), beyond it it grows.
    z = -spinmode.RK4_REAL_LIMIT
    assert spinmode.rk4_amplification(z) == pytest.approx(1.0, abs=1e-8)
    inside = np.linspace(z + 1e-6, -1e-6, 1000)
    R = spinmode.rk4_amplification(inside)
    assert np.all((R > 0.27) & (R < 1.0))
    assert spinmode.rk4_amplification(z - 1e-3) > 1.0


def test_plain_rk4_is_unstable_at_standstill_at_10_ms_and_the_fit_is_stable():
    # Every load and speed of both tyres, single and twin wheel ends: plain
    # RK4's factor exceeds 1 somewhere at 10 ms (the standstill root near
    # -430 1/s, beyond -2.785 / h), and never with the fit (a wheel in the
    # air has a zero root: a factor of 1, to rounding).
    h = 0.01
    Fz = np.linspace(0.0, 90e3, 181)[:, None]
    for name in TYRES:
        p = tyre(name)
        Vx = np.linspace(0.0, 1.5 * p.VXLOW, 61)[None, :]
        for inertia, n in ((12.0, 1.0), (24.0, 2.0)):
            w = wheel(p, Fz, Vx, inertia, n)
            lam = spinmode.eigenvalues(**w)
            plain = np.abs(spinmode.rk4_amplification(h * lam)).max()
            fitted = np.linalg.eigvals(fitted_jacobian(h, w))
            assert plain > 5.0 and (h * lam.real).min() < -spinmode.RK4_REAL_LIMIT
            assert (h * fitted.real).min() > -0.57 * spinmode.FIT_SCALE
            assert np.abs(spinmode.rk4_amplification(h * fitted)).max() <= 1.0 + 1e-12


@pytest.mark.parametrize("Vx", [0.0, 0.3, 0.8, 3.0])
def test_the_fit_moves_each_eigenvalue_by_g(Vx):
    # The rate the plant integrates is g(h J) J: its eigenvalues are
    # g(h lambda) lambda with g(z) = 1 / (1 + (z / z0)^4), for both roots.
    p = tyre(TYRES[0])
    w = wheel(p, 25e3, Vx)
    lam = spinmode.eigenvalues(**w)
    for h in (0.005, 0.01):
        got = np.linalg.eigvals(fitted_jacobian(h, w))
        want = spinmode.fit_factor(h * lam) * lam
        np.testing.assert_allclose(np.sort_complex(got), np.sort_complex(want), rtol=1e-9)


def test_the_fit_vanishes_as_h_to_the_fourth():
    # The correction is -(1 + P^4)^-1 P^4 f: halving h divides it by 16 as
    # h -> 0, so the plant converges to the model's own rates at RK4's order.
    p = tyre(TYRES[0])
    w = wheel(p, 30e3, 0.0)
    f = (35.0, -0.02)
    dF = [spinmode.fit(h, spinmode.Mode(**w), *f)[0] for h in (1e-4, 5e-5)]
    assert float(dF[0] / dF[1]) == pytest.approx(16.0, rel=1e-3)
    J = spinmode.jacobian(**w)
    # At 1 ms the fast root (-430 1/s) keeps 99.98 % of its rate.
    lam = spinmode.eigenvalues(**w)
    assert spinmode.fit_factor(1e-3 * lam[0]) == pytest.approx(1.0, abs=3e-4)
    # At 0.1 ms the whole rate is the model's within (h |lambda| / z0)^4, 2e-8.
    assert np.abs(fitted_jacobian(1e-4, w) - J).max() < 1e-7 * np.abs(J).max()


def test_equilibria_are_kept():
    # A wheel whose rates are zero (held by its torque, the tread spring
    # taking it) gets no correction at any step.
    p = tyre(TYRES[0])
    w = wheel(p, 30e3, 0.0)
    for h in (0.005, 0.01, 0.02):
        dF, du = spinmode.fit(h, spinmode.Mode(**w), 0.0, 0.0)
        assert float(dF) == 0.0 and float(du) == 0.0


# ---------------------------------------------------------------- the plant




def at_rest(vehicle, **kw) -> Plant:
    p = Plant(vehicle, **kw)
    p.reset(InitialState(0.0, 0.0, 0.0, 0.0))
    for _ in range(100):
        p.step(0.01, 0.0, 0.0, 0.0)
    return p


@pytest.mark.parametrize("name", ["gosar2022-unloaded", "six-axle"])
def test_the_plant_spin_modes_are_the_derived_eigenvalues(name):
    # The whole model linearised at rest: its fastest eigenvalues are the
    # wheel ends' standstill spin roots that Plant.spin_modes derives from
    # the local two-state system. The chassis' share of the mode (the wheel's
    # spin inertia over its rolling radius squared, about 45 kg against a
    # tonne and more per wheel) moves them by a few per cent: 4 %.
    # Settled at 5 ms: plain RK4 (no fit, the model's own rates) is stable at
    # rest only below about 6 ms, and the linearisation needs a true rest state.
    with at_rest(load_vehicle(name), spin_fit=False, timestep=5e-3) as p:
        local = np.sort(p.spin_modes()[:, 0].real)
        lam = np.linalg.eigvals(rates_jacobian(p))
        fast = np.sort(lam[np.abs(lam) > 200.0].real)
        assert fast.size == p.n_wheels and np.all(np.abs(lam[np.abs(lam) > 200.0].imag) < 1e-6)
        np.testing.assert_allclose(fast, local, rtol=0.04)
        # Nothing else in the plant is faster than 100 1/s (suspension, steering).
        rest = np.abs(lam[np.abs(lam) <= 200.0])
        assert rest.max() < 100.0


def test_the_plant_integrates_the_fitted_mode():
    # At 10 ms the C callback hands MuJoCo the fitted rates: the fast roots of
    # the linearised plant become g(h lambda) lambda (about -190 1/s instead of
    # -430), within the chassis' few per cent.
    v = load_vehicle("gosar2022-unloaded")
    with at_rest(v, timestep=0.01) as p:
        lam0 = p.spin_modes()[:, 0].real
        want = np.sort(spinmode.fit_factor(0.01 * lam0) * lam0)
        lam = np.linalg.eigvals(rates_jacobian(p))
        spin = lam[(np.abs(lam) > 150.0) & (np.abs(lam) < 250.0)]
        np.testing.assert_allclose(np.sort(spin.real), want, rtol=0.05)
        # and RK4 at 10 ms is stable on every mode (the pose's zero roots: 1).
        assert np.abs(spinmode.rk4_amplification(0.01 * lam)).max() <= 1.0 + 1e-9


def nudge_spin_and_watch(p: Plant, seconds: float) -> np.ndarray:
    """At rest, one wheel's spin nudged by 0.1 rad/s: its spin over ``seconds`` of rest.

    Ends early, with the spin last seen, if the plant diverges.
    """
    p.data.qvel[p._spin_dof[0]] += 0.1
    out = []
    for _ in range(int(round(seconds / 0.01))):
        try:
            p.step(0.01, 0.0, 0.0, 0.0)
        except PlantError:
            out.append(np.inf)
            break
        out.append(p.data.qvel[p._spin_dof[0]])
    return np.array(out)


@pytest.mark.filterwarnings("ignore::artic.plant.tyre.TyreRangeWarning")
def test_a_nudged_wheel_at_rest_settles_at_10_ms_with_the_fit_and_not_without():
    # The nudge rings through the chassis' slow modes too; a second later the
    # spin is down by more than 1e4 (1e-5 rad/s; 1 ms RK4: 7e-9) with the fit.
    v = load_vehicle("gosar2022-unloaded")
    with at_rest(v, timestep=0.01) as p:
        spin = nudge_spin_and_watch(p, 1.0)
        assert np.abs(spin[-10:]).max() < 1e-5
    with at_rest(v, timestep=0.01, spin_fit=False) as p:
        # Plain RK4 at 10 ms: the standstill root is beyond its reach; the
        # spin grows (about 9 times per step) until the tread slides.
        spin = nudge_spin_and_watch(p, 1.0)
        assert np.abs(spin).max() > 1.0


def held_by_the_drive(vehicle, timestep: float, spin_fit: bool) -> tuple[float, np.ndarray]:
    """On a 4 % slope, the drive wheels' torques set to hold the combination's weight.

    Settled on the parking brake, released with the drive torque that balances
    the grade through the contact's lever; then 10 s with every other actuator
    at zero. Returns the distance moved then [m] and the final spins [rad/s].
    """
    theta = 0.04
    v = dataclasses.replace(vehicle, plant=dataclasses.replace(vehicle.plant, grade=theta))
    with Plant(v, speed="drive", timestep=timestep, spin_fit=spin_fit) as p:
        m, d = p.model, p.data
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0))
        p.parking_brake = True
        mujoco.mj_step(m, d, nstep=int(round(2.0 / timestep)))
        p.parking_brake = False
        pos, hx, _, _, _ = p._wheel_kinematics(d)
        contact = pos.copy()
        contact[:, 2] = 0.0
        q_x, _ = p._spin_forces(m, d, np.zeros_like(hx), np.zeros_like(hx), contact, hx)
        drive = [i for i, n in enumerate(p.wheel_names) if n.startswith("drive")]
        weight = m.body_subtreemass[p._tractor] * G * math.sin(theta)
        d.ctrl[p._drive] = -q_x[drive] * weight / len(drive)
        mujoco.mj_step(m, d, nstep=int(round(2.0 / timestep)))
        x0 = p.observe()[0]
        mujoco.mj_step(m, d, nstep=int(round(10.0 / timestep)))
        return p.observe()[0] - x0, d.qvel[p._spin_dof].copy()


@pytest.mark.long_on_numpy
def test_held_by_the_drive_on_a_slope_at_10_ms_as_at_1_ms(unloaded):
    # A wheel held by a torque: its spin's rate is zero only counting that
    # torque, which the fit does (left out, the held drive wheels creep at
    # 0.26 rad/s at 10 ms). The combination moves 2 mm in 10 s (the lever
    # changes a little once the brake lets go): at 10 ms as plain RK4 at 1 ms,
    # within 1e-5 m, and its wheels stand within 1e-5 rad/s of the same spins.
    x_ref, spin_ref = held_by_the_drive(unloaded, 0.001, spin_fit=False)
    x, spin = held_by_the_drive(unloaded, 0.01, spin_fit=True)
    assert abs(x - x_ref) < 1e-5 and abs(x_ref) < 5e-3
    assert np.abs(spin - spin_ref).max() < 1e-5


def parked(vehicle, timestep: float, spin_fit: bool) -> float:
    """Parked on a 15 % slope: the distance moved in 10 s after a settling second [m]."""
    v = dataclasses.replace(vehicle, plant=dataclasses.replace(vehicle.plant, grade=0.15))
    with Plant(v, speed="drive", timestep=timestep, spin_fit=spin_fit) as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0))
        p.parking_brake = True
        mujoco.mj_step(p.model, p.data, nstep=int(round(1.0 / timestep)))
        x0 = p.observe()[0]
        mujoco.mj_step(p.model, p.data, nstep=int(round(10.0 / timestep)))
        return p.observe()[0] - x0


@pytest.mark.long_on_numpy
def test_parked_on_a_slope_at_10_ms_as_at_1_ms(unloaded):
    # The parking brake is MuJoCo's soft friction constraint on the spins
    # (a parked truck creeps, 0.4 mm/s on 15 %), which the fit leaves to the
    # solver: at 10 ms it creeps as plain RK4 at 1 ms does, within 0.5 mm in 10 s.
    ref = parked(unloaded, 0.001, spin_fit=False)
    assert abs(parked(unloaded, 0.01, spin_fit=True) - ref) < 5e-4 and abs(ref) < 5e-3


def test_the_numpy_fit_counts_the_torques_of_the_actuators_on_the_spins(unloaded):
    # The fit holds a wheel that a torque holds only counting that torque
    # (held_by_the_drive). The numpy reference once tested the actuators'
    # transmission against MuJoCo's enum with `in`, which is never true for
    # numpy's ints, and counted none: its held drive wheels crept at 0.26 rad/s.
    with Plant(unloaded, backend="python", speed="drive") as p:
        m, d = p.model, p.data
        d.ctrl[p._drive] = 1000.0  # [N m] at each driven wheel
        q = p._spin_actuator_forces(m, d)
        driven = np.isin(p._spin_dof, m.jnt_dofadr[m.actuator_trnid[p._drive, 0]])
        np.testing.assert_array_equal(q[driven], 1000.0 * m.actuator_gear[p._drive, 0])
        assert driven.sum() == len(p._drive) and np.all(q[~driven] == 0.0)
