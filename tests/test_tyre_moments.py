"""The tyres' aligning moment and bore torque in the plant, and a block that cannot crash it."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.interface import InitialState
from artic.plant import Plant
from artic.plant.tyre import (
    TWIST_LIMIT,
    TWIST_STIFFNESS,
    TyreParams,
    bore_torque,
    deflection_rates,
    steady_state,
    transient_forces,
)
from tests.helpers import needs_compiled


def with_moments(v, on=True):
    return dataclasses.replace(v, plant=dataclasses.replace(v.plant, tyre_moments=on))


@pytest.fixture(scope="module")
def loaded_moments():
    return with_moments(load_vehicle("gosar2022-loaded"))


def test_a_parked_steered_truck_twists_its_tyres_to_the_friction_bound(loaded_moments):
    v = loaded_moments
    with Plant(v) as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0))
        p.parking_brake = True
        effort = []
        for k in range(500):  # steer to 10 deg at 0.2 rad/s, then hold, parked
            p.step(0.01, min(0.002 * k, math.radians(10.0)), 0.0, 0.0)
            effort.append(p.data.actuator_force[p._servo[0]])
        n = p._n_tyres
        Fz = p.last_forces[:2, 2] / n[:2]  # the steered tyres
        phi = p.data.act[p._act_w[:2]]
        t = p.tyre
        back = []
        for k in range(200):  # steer back to straight ahead at 0.2 rad/s, then hold
            p.step(0.01, max(math.radians(10.0) - 0.002 * k, 0.0), 0.0, 0.0)
            back.append(p.data.actuator_force[p._servo[0]])
    # The bound from the book's contact patch, written out here: mu Fz a 2/3 for
    # a circular patch of radius a = sqrt(R0 Fz / k_t) under uniform pressure.
    mu = (t.PDY1 + t.PDY2 * (Fz - t.Fz0) / t.Fz0) * t.LMUY
    bound = 2.0 / 3.0 * mu * Fz * np.sqrt(t.UNLOADED_RADIUS * Fz / t.VERTICAL_STIFFNESS)
    torque = np.abs(bore_torque(t, Fz, phi))
    assert np.all(torque <= bound * (1 + 1e-12))  # bounded by friction
    assert np.all(torque >= 0.8 * bound)  # and reached: within 20 % of it
    assert 1.5e3 < bound.min() < 3e3  # about 2 kN m per steer tyre, as expected
    # The servo feels both tyres (through the linkage) and holds steady, parked:
    # no chatter, no creep of the torque over the last second.
    held = np.array(effort[-100:])
    assert held.mean() > 1.5 * torque.min()
    assert held.std() < 1e-3 * held.mean()
    # Friction, not a spring: steered back, the tyres resist the return (the
    # servo pushes the other way, two tyres' worth) instead of pulling the
    # wheels back to where they stood (measured: +4.1 kN m out, -3.3 kN m back).
    back = np.array(back[-50:])
    assert back.max() < -bound.min() and back.std() < 1e-3 * abs(back.mean())


def test_bore_torque_is_friction_through_standstill_and_reversal():
    # One tyre at 30 kN, integrated in 1 ms steps: turned at standstill, held,
    # turned back, then rolled round a 10 m turn, through a stop into reverse.
    from importlib import resources

    p = TyreParams.from_tir(resources.files("artic.mjcf") / "tyres" / "artic-truck-315-80R22.5.tir")
    Fz, dt, R = np.array([30e3]), 1e-3, 10.0
    a, phi_s = p.patch_half_length(Fz)[0], p.twist_scale(Fz)[0]
    phi_lim = TWIST_LIMIT * phi_s
    m_max = 2.0 / 3.0 * p.PDY1 * p.LMUY * Fz[0] * a  # the friction bound, at the nominal load
    z = np.zeros(1)
    state = [np.zeros(1)] * 3  # u, v, phi

    def run(n, Vx, omega_z):
        out = []
        for k in range(n):
            vx, wz = np.array([Vx(k)]), np.array([omega_z(k)])
            rates = deflection_rates(p, Fz, vx, z, z, wz, *state)
            state[:] = [x + dt * r for x, r in zip(state, rates, strict=True)]
            out.append((transient_forces(p, Fz, vx, z, z, wz, *state)[2][0],
                        bore_torque(p, Fz, state[2])[0]))
        return np.array(out)

    w, turn = 0.5, 0.35  # 0.5 rad/s, a truck's fastest steering at standstill; 20 deg
    out = run(int(turn / w / dt), lambda k: 0.0, lambda k: w)
    # Bounded by friction while turning, the damper included, and reached.
    assert np.abs(out[:, 0]).max() <= m_max * (1 + 1e-9)
    assert out[-1, 1] < -0.95 * m_max  # resisting the turn
    held = run(100, lambda k: 0.0, lambda k: 0.0)  # parked: held, not a hair of chatter
    assert np.ptp(held[:, 0]) == 0.0 and held[0, 0] == pytest.approx(out[-1, 1], rel=1e-12)
    # Turned back, the twist unwinds and the torque reverses after the angle
    # Dahl's equation gives, phi_lim ln(2 - exp(-turn / phi_lim)), and ends
    # resisting the return: friction re-anchored, not a spring.
    back = run(int(turn / w / dt), lambda k: 0.0, lambda k: -w)
    crossing = w * dt * (np.flatnonzero(back[:, 1] > 0.0)[0] + 0.5)
    assert crossing == pytest.approx(phi_lim * math.log(2.0 - math.exp(-turn / phi_lim)),
                                     rel=0.01)
    assert back[-1, 1] > 0.95 * m_max and np.abs(back[:, 0]).max() <= m_max * (1 + 1e-9)
    # Rolling round the turn at 1 m/s: the twist settles at -a / (R + a / phi_lim).
    run(1500, lambda k: 1.0, lambda k: 1.0 / R)  # 1.5 m: twelve a
    assert state[2][0] == pytest.approx(-a / (R + a / phi_lim), rel=1e-3)
    # Through a stop into reverse in the same turn (the yaw reverses with the
    # travel): continuous, within 0.5 % of the bound per millisecond, and it
    # settles at the mirror image.
    ramp = run(2000, lambda k: 1.0 - k / 1000.0, lambda k: (1.0 - k / 1000.0) / R)
    rev = run(1500, lambda k: -1.0, lambda k: -1.0 / R)
    series = np.concatenate([ramp[:, 0], rev[:, 0]])
    assert np.all(np.isfinite(series)) and np.abs(np.diff(series)).max() < 5e-3 * m_max
    assert state[2][0] == pytest.approx(a / (R + a / phi_lim), rel=1e-3)


def test_twist_is_continuous_through_standstill_and_relaxes_when_rolling():
    from importlib import resources

    p = TyreParams.from_tir(resources.files("artic.mjcf") / "tyres" / "artic-truck-315-80R22.5.tir")
    Fz = np.array([30e3])
    phi = np.array([-0.1])
    z = np.zeros(1)
    # Parked, no yaw: the twist is held.
    assert deflection_rates(p, Fz, z, z, z, z, z, z, phi)[2][0] == 0.0
    # Rolling at V: it relaxes over the patch half-length a, time constant a / V.
    a = p.patch_half_length(Fz)[0]
    rate = deflection_rates(p, Fz, np.array([2.0]), z, z, z, z, z, phi)[2][0]
    assert rate == pytest.approx(-2.0 * phi[0] / a, rel=1e-12)
    # Small twists: the torque is the torsional stiffness times the twist.
    small = np.array([1e-5])
    assert bore_torque(p, Fz, small)[0] == pytest.approx(TWIST_STIFFNESS * 30e3 * 1e-5,
                                                         rel=1e-6)


@pytest.mark.slow
def test_the_tridem_resists_yaw_in_a_tight_slow_turn(loaded_moments):
    # At R = 10 m and 5 km/h the tridem scrubs; its bore torques resist the
    # trailer's yaw on top of the side forces, so the trailer swings out less
    # (measured: 44.1 -> 42.8 deg), and the steering feels the aligning moment.
    U = 5 / 3.6
    out = {}
    for on in (False, True):
        v = with_moments(loaded_moments, on)
        with Plant(v) as p:
            p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=U))
            g, eff = [], []
            for _ in range(6000):
                p.step(0.01, math.atan(v.L1 / 10.0), U, 0.0)
                g.append(p.gamma)
                eff.append(p.data.actuator_force[p._servo[0]])
        out[on] = (math.degrees(np.mean(g[-300:])), np.mean(eff[-300:]))
    assert out[True][0] < out[False][0] - 0.5
    assert abs(out[True][1]) > 100 * max(abs(out[False][1]), 1.0)


MALFORMED = {
    "negative wheel count": "blk[3] = -5",
    "short block": "m.numeric_data[-3:] = 1e9",  # changes the seal: refused
    "bad body id": "blk[HDR + NS * NP + 1] = 1e6",
    "foreign key": "blk[1] = 12345",
    "zero relaxation length": "blk[HDR + NAMES.index('PTY1')] = 0.0",
    "negative spin fit": "blk[ctyre.HEADER_FIELDS.index('spin_fit')] = -1.0",
}


@needs_compiled("the compiled tyre callback's checks of its block")
@pytest.mark.parametrize("case", list(MALFORMED))
def test_a_malformed_tyre_block_raises_and_never_crashes(case):
    # In a subprocess: a segmentation fault would end it with a signal.
    code = textwrap.dedent(f"""
        import mujoco, numpy as np
        from artic.mjcf import load_vehicle
        from artic.plant import Plant, ctyre
        with Plant(load_vehicle("gosar2022-unloaded"), backend="compiled") as p:
            m, d = p.model, p.data
            blk = m.numeric_data
            HDR, NS, NP = len(ctyre.HEADER_FIELDS), int(blk[5]), len(ctyre.param_names())
            NAMES = ctyre.param_names()
            {MALFORMED[case]}
            try:
                ctyre.check_block(m, d)
                print("ACCEPTED")
            except ctyre.TyreBlockError as e:
                print("REFUSED", e)
            for _ in range(20):  # the callback must skip it, not crash
                mujoco.mj_step(m, d)
            print("STEPPED", int(np.isfinite(d.qpos).all()))
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "REFUSED" in out.stdout and "STEPPED 1" in out.stdout, out.stdout


@needs_compiled("the compiled tyre callback's checks of its block")
def test_a_block_refuses_a_zero_relaxation_length():
    from importlib import resources

    from artic.plant import ctyre

    p = TyreParams.from_tir(resources.files("artic.mjcf") / "tyres" / "artic-truck-315-80R22.5.tir")
    bad = dataclasses.replace(p, PTY1=0.0)
    with pytest.raises(ctyre.TyreBlockError, match="PTY1 = 0.0 must be positive"):
        ctyre.check_set(bad)
    with pytest.raises(ctyre.TyreBlockError, match="not finite"):
        ctyre.check_set(dataclasses.replace(p, QDZ1=float("nan")))


MIRROR_ODD = ("PHY1", "PHY2", "PVY1", "PVY2", "PEY3", "RBY3", "RVY1", "RVY2", "RHX1", "QHZ1",
              "QHZ2", "QDZ6", "QDZ7", "QEZ4", "SSZ1")
"""The coefficients that change sign when a PAC2002 characteristic is mirrored
(zero camber): Fy_m(alpha) = -Fy(-alpha), Mz_m(alpha) = -Mz(-alpha), Fx_m(alpha) = Fx(-alpha)."""


def _zero_force_slip_angle(t, Fz):
    """Slip angle [rad] at which the tyre's lateral force vanishes, by bisection."""
    lo, hi = np.full_like(Fz, -0.05), np.full_like(Fz, 0.05)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        pos = steady_state(t, Fz, 0.0 * Fz, mid)[1] > 0.0  # Fy rises with alpha
        hi, lo = np.where(pos, mid, hi), np.where(pos, lo, mid)
    return 0.5 * (lo + hi)


def _straight_run(v, tyre=None):
    U = 5 / 3.6
    with Plant(v) as p:
        if tyre is not None:
            p.tyre = tyre
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=U))
        ys = []
        for k in range(6000):  # 60 s, 83 m, steering wheel held straight
            p.step(0.01, 0.0, U, 0.0)
            if k % 1000 == 999:
                ys.append(p.observe()[1])
        Fz = p.last_forces[:, 2] / p._n_tyres
        alpha = np.arctan(p.data.act[p._act_v] / p.tyre.sigma_alpha(np.maximum(Fz, 1.0)))
        return np.array(ys), Fz, alpha, p.tyre


@pytest.mark.slow
def test_ply_steer_is_not_mirrored_so_a_real_tyre_drifts_with_it():
    # The real file pushes at zero slip angle (its offsets); artic takes that as
    # ply steer, alike on both sides (see artic.plant.tyre, "Mounting side"). Driven
    # straight, the combination must then crab until every tyre runs near the
    # slip angle at which its force vanishes, and drift to the side the tyres
    # push. Mirrored per side (MF-Tyre's TYRESIDE), the offsets would cancel on
    # every axle and nothing would drift.
    from tests.shared_data import REFERENCE_TYRE

    if not REFERENCE_TYRE.is_file():
        pytest.skip(f"reference data {REFERENCE_TYRE} is absent (it is in ../shared)")
    v = dataclasses.replace(load_vehicle("gosar2022-unloaded"), tyre_file=str(REFERENCE_TYRE))
    y, Fz, alpha, t = _straight_run(v)
    push = steady_state(t, Fz, 0.0 * Fz, 0.0 * Fz)[1]  # every tyre's force at zero slip
    assert np.all(push < -100.0)  # this file: 180-520 N to the right per tyre
    assert y[0] < -0.02  # so it crabs right: 4 cm in the first 14 m
    assert np.abs(y).max() > 0.05
    # Every tyre runs at its zero-force slip angle (0.18-0.20 deg here), to
    # within the small slip that the yaw balance between axles asks for
    # (measured: 5 %; the drive and trailer axles' zero-force angles differ by
    # 0.02 deg from the front's, which sets the scale).
    alpha0 = _zero_force_slip_angle(t, Fz)
    assert np.all(alpha0 > math.radians(0.1))
    np.testing.assert_allclose(alpha, alpha0, rtol=0.1)
    # The tyre built the other way round (its characteristic mirrored) drives the
    # mirror image: the drift comes from the offsets and from nothing else.
    mirrored = dataclasses.replace(t, **{k: -getattr(t, k) for k in MIRROR_ODD})
    y_m, *_ = _straight_run(v, mirrored)
    np.testing.assert_allclose(y_m, -y, rtol=1e-4, atol=1e-6)


FOREIGN = textwrap.dedent('''
    import mujoco, numpy as np
    from importlib import resources
    from artic.mjcf import load_vehicle
    from artic.plant import Plant, ctyre
    from artic.plant.tyre import TyreParams

    P = TyreParams.from_tir(resources.files("artic.mjcf") / "tyres" / "artic-truck-315-80R22.5.tir")
    WHEEL = {"hub_site": 0, "hub_body": 1, "root_body": 1, "wheel_body": 2, "spin_dof": 6,
             "act_u": 0, "act_v": 1, "act_w": 2, "ctrl_u": 0, "ctrl_v": 1, "ctrl_w": 2,
             "n_tyres": 1, "tyre_set": 0}

    def foreign(key, nuserdata=4, **change):
        # One wheel on a free body, with three tread actuators: a look-alike of
        # an artic model, its block built (and checksummed) like artic's.
        row = [{**WHEEL, **change}[f] for f in ctyre.WHEEL_FIELDS]
        body = np.concatenate([ctyre.param_vector(P), row])
        head = [ctyre.ABI, *key, 1, len(ctyre.param_names()), 1, 1, 0.0, ctyre.checksum(body)]
        data = " ".join(repr(float(x)) for x in np.concatenate([head, body]))
        act = '<general joint="spin" dyntype="integrator" gainprm="0" biasprm="0 0 0"/>' * 3
        return (f'<mujoco><size nuserdata="{nuserdata}"/>'
                f'<custom><numeric name="artic.tyre" data="{data}"/></custom>'
                '<worldbody><body pos="0 0 0.5"><freejoint/><geom size="0.3" mass="3000"/>'
                '<site name="hub"/><body><joint name="spin" type="hinge" axis="0 1 0"/>'
                '<geom size="0.2" mass="50"/></body></body></worldbody>'
                f'<actuator>{act}</actuator></mujoco>')

    CASES = {"sealed and fitting": dict(key=ctyre.KEY),
             "unsealed": dict(key=(0, 0)),
             "another process's key": dict(key=(12345, 678)),
             "sealed, site beyond the model": dict(key=ctyre.KEY, hub_site=5),
             "sealed, dof beyond the model": dict(key=ctyre.KEY, spin_dof=7),
             "sealed, too little userdata": dict(key=ctyre.KEY, nuserdata=2)}
    with Plant(load_vehicle("gosar2022-unloaded"), backend="compiled"):  # the C callback is global
        for name, kw in CASES.items():
            m = mujoco.MjModel.from_xml_string(foreign(**kw))  # compiled while a plant is open
            d = mujoco.MjData(m)
            try:
                ctyre.check_block(m, d)
                verdict = "ACCEPTED"
            except ctyre.TyreBlockError as e:
                verdict = f"REFUSED {e}"
            mujoco.mj_step(m, d, nstep=20)
            force = np.abs(d.qfrc_passive).max()
            print(f"{name}|{verdict}|{force:.6g}|{int(np.isfinite(d.qpos).all())}")
''')


@needs_compiled("the compiled tyre callback's checks of its block")
def test_a_foreign_model_with_a_look_alike_block_is_never_touched():
    # A model artic did not attach carries an 'artic.tyre' numeric laid out like
    # artic's, and is compiled and stepped while a plant has the C callback
    # installed process-wide. Only a block sealed with this process's key and
    # fitting its model gets tyre forces (the first case shows that the
    # look-alike is good enough to be followed); any other is refused in Python
    # with its reason, and left alone by the callback. In a subprocess: a
    # segmentation fault would end it with a signal.
    out = subprocess.run([sys.executable, "-c", FOREIGN], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    rows = {r.split("|")[0]: r.split("|")[1:] for r in out.stdout.splitlines() if "|" in r}
    assert len(rows) == 6, out.stdout
    verdict, force, finite = rows.pop("sealed and fitting")
    assert verdict == "ACCEPTED" and float(force) > 1e4  # the tyre carries the body
    reasons = {"unsealed": "not sealed by this process",
               "another process's key": "not sealed by this process",
               "sealed, site beyond the model": "hub_site = 5 is outside",
               "sealed, dof beyond the model": "spin_dof = 7 is outside",
               "sealed, too little userdata": "nuserdata = 2"}
    for name, (verdict, force, finite) in rows.items():
        assert verdict.startswith("REFUSED") and reasons[name] in verdict, (name, verdict)
        assert float(force) == 0.0 and finite == "1", name
