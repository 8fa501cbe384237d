"""The multibody plant: statics, straight and steady driving, reversing, numerics."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.linkage import centre_angle
from artic.plant import Plant, PlantError, callback
from artic.plant.tyre import TyreParams, TyreRangeWarning
from artic.reduced import STM, Driven, InitialState
from artic.validation.harness.loop import run_closed_loop
from artic.validation.harness.simulate import drive_articulation
from tests.helpers import PRESETS, needs_compiled, straight_log


@pytest.fixture(scope="module")
def unloaded_plant(unloaded):
    p = Plant(unloaded)
    yield p
    p.close()


def run(plant, seconds, delta=0.0, u=0.0, initial=None):
    plant.reset(initial or InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
    out = []
    for _ in range(int(round(seconds / 0.01))):
        plant.step(0.01, delta, u, 0.0)
        out.append(plant.observe())
    return np.array(out)


@pytest.mark.parametrize("name", PRESETS)
def test_static_axle_loads_match_the_file(name):
    # The model stands in equilibrium on the loads derived from the file: the
    # tyres' vertical forces, summed per axle, after 1 s at rest.
    v = load_vehicle(name)
    with Plant(v) as p:
        run(p, 1.0)
        loads = p.wheel_loads().reshape(-1, 2).sum(axis=1)
    np.testing.assert_allclose(loads, v.static_loads, rtol=0.02)
    # In fact far closer: the model is built to start in that equilibrium.
    np.testing.assert_allclose(loads, v.static_loads, rtol=1e-6)


def test_ten_seconds_at_rest(unloaded_plant):
    p = unloaded_plant
    obs = run(p, 10.0)
    assert all(w.number == 0 for w in p.data.warning)
    drift = np.hypot(obs[:, 0] - obs[0, 0], obs[:, 1] - obs[0, 1])
    assert drift.max() < 1e-3
    assert abs(p.data.qpos[2]) < 1e-3


def test_deterministic(unloaded_plant):
    a = run(unloaded_plant, 2.0, delta=0.1, u=1.5)
    b = run(unloaded_plant, 2.0, delta=0.1, u=1.5)
    assert np.array_equal(a, b)


def test_two_plants_do_not_disturb_each_other(unloaded, loaded):
    # Stepped in turns, each plant gives what it gives alone; closing them
    # restores whatever passive callback was there before.
    before = mujoco.get_mjcb_passive()
    n0 = callback.active()  # plants of other tests may be open
    with Plant(unloaded) as a:
        alone = run(a, 1.0, delta=0.2, u=2.0)
    with Plant(unloaded) as a, Plant(loaded) as b:
        assert callback.active() == n0 + 2
        init = InitialState(0.0, 0.0, 0.0, 0.0, u1=2.0)
        a.reset(init)
        b.reset(init)
        both = []
        for _ in range(100):
            a.step(0.01, 0.2, 2.0, 0.0)
            b.step(0.01, -0.1, 2.0, 0.0)
            both.append(a.observe())
    assert np.array_equal(np.array(both), alone)
    assert callback.active() == n0
    assert mujoco.get_mjcb_passive() is before


def test_steering_asymmetry_emerges_from_the_linkage(unloaded_plant):
    # The servo turns the left wheel; the right follows the trapezoid, so the
    # centre angle is smaller for a left turn than for a right one.
    p = unloaded_plant
    c = []
    for d in (0.3, -0.3):
        run(p, 1.0, delta=d, u=0.0)
        qL = p.data.qpos[p._steer_L[0]]
        qR = p.data.qpos[p._steer_R[0]]
        assert qL == pytest.approx(d, abs=2e-3)
        c.append(float(centre_angle(np.array(qL), np.array(qR))))
    assert 0 < c[0] < 0.3 < -c[1]


def stm_with_tyre_file_stiffness(v):
    tyre = TyreParams.from_tir(v.tyre_file)
    n = np.array([2.0 * (2 if a.dual else 1) for a in v.axles])
    C = n * tyre.cornering_stiffness(v.static_loads / n)
    m = STM(v)
    m.params = m.params._replace(C=C)  # the tyre file's cornering stiffnesses
    return m


@pytest.mark.slow
def test_constant_steer_yaw_rate_matches_stm(unloaded, unloaded_plant):
    # 200 deg of steering wheel at 5 km/h. At the plant's own centre angle,
    # with the tyre file's cornering stiffness at the static loads, the STM's
    # steady yaw rate is within 5 %: the two differ by roll, load transfer,
    # tyre non-linearity and the tyres' longitudinal forces, all small here.
    v, p, u = unloaded, unloaded_plant, 5 / 3.6
    delta_left = math.radians(200.0) / v.steering_for("mbd").i_s
    y = run(p, 40.0, delta=delta_left, u=u)[-1]
    qL, qR = p.data.qpos[p._steer_L[0]], p.data.qpos[p._steer_R[0]]
    dc = float(centre_angle(np.array(qL), np.array(qR)))
    m = Driven(stm_with_tyre_file_stiffness(v))  # the STM with the state the harness keeps
    m.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
    for _ in range(4000):
        m.step(0.01, dc, u, 0.0)
    assert y[5] == pytest.approx(m.observe()[5], rel=0.05)


@pytest.mark.slow
def test_straight_100_m(unloaded_plant):
    u = 10 / 3.6
    obs = run(unloaded_plant, 100.0 / u, u=u)
    assert obs[-1, 0] - obs[0, 0] == pytest.approx(100.0, abs=0.5)
    assert np.max(np.abs(obs[:, 1] - obs[0, 1])) < 0.05
    # The speed controller holds 10 km/h to within 0.1 %.
    assert obs[-1, 3] == pytest.approx(u, rel=1e-3)


@pytest.mark.slow
def test_reverse_open_loop_diverges_and_harness_holds_it(unloaded):
    v = unloaded
    s = v.steering_for("mbd").delta_h_offset
    log = straight_log(n=3000, u=-3 / 3.6, gamma0=math.radians(2.0), delta_h=s)
    with Plant(v) as p:
        g_open = run_closed_loop(p, log, v, gain=0.0).frame["gamma"].to_numpy()
    with Plant(v) as p:
        g_k3 = run_closed_loop(p, log, v, gain=3.0).frame["gamma"].to_numpy()
    # Eq. (6) with K = 0 at -3 km/h: growth near 0.1 /s, about 20-fold in 30 s.
    assert abs(g_open[-1]) > 5 * math.radians(2.0)
    assert abs(g_k3[-1]) < 0.05 * math.radians(2.0)


@pytest.mark.slow
def test_forward_stop_reverse_without_warnings(unloaded_plant):
    p = unloaded_plant
    t = np.arange(0.0, 30.0, 0.01)
    u = np.interp(t, [0, 8, 11, 14, 17, 30], [1.4, 1.4, 0.0, 0.0, -0.8, -0.8])
    p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u[0]))
    obs = []
    for k in range(t.size - 1):
        p.step(0.01, 0.15, u[k], (u[k + 1] - u[k]) / 0.01)
        obs.append(p.observe())
    obs = np.array(obs)
    assert all(w.number == 0 for w in p.data.warning)
    assert np.all(np.isfinite(obs))
    # The speed followed the profile, through zero and into reverse.
    assert obs[-1, 3] == pytest.approx(-0.8, abs=0.02)
    assert abs(obs[int(12.5 / 0.01), 3]) < 0.02


def stop_and_reverse(plant, seconds: float = 12.0) -> np.ndarray:
    """Forward at 2 m/s, braking at 0.6 m/s^2 through a stop into 1 m/s reverse, steering."""
    plant.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=2.0))
    out = []
    for k in range(int(round(seconds / 0.01))):
        t = k * 0.01
        u = 2.0 if t < 3.0 else max(2.0 - 0.6 * (t - 3.0), -1.0)
        u_dot = -0.6 if 3.0 <= t and u > -1.0 else 0.0
        plant.step(0.01, 0.15 * math.sin(0.5 * t), u, u_dot)
        out.append(plant.observe())
    return np.array(out)


@pytest.mark.long_on_numpy
@pytest.mark.parametrize("name", ["gosar2022-unloaded", "six-axle"])
def test_the_default_step_and_10_ms_are_converged_through_a_stop(name):
    # The default step and the logs' 10 ms against plain RK4 at 1 ms (the
    # model's own rates), through a stop and a change of direction, where the
    # wheel-spin mode is stiffest: within the convergence study's targets
    # (1 cm, 0.05 deg, 1e-3 rad/s), in fact within a millimetre.
    from artic.mjcf.builder import TIMESTEP

    v = load_vehicle(name)
    with Plant(v, timestep=1e-3, spin_fit=False) as p:
        ref = stop_and_reverse(p)
    assert ref[:, 3].min() < -0.9 and ref[:, 3].max() > 1.9  # through the stop
    for h in sorted({TIMESTEP, 0.01}):
        with Plant(v, timestep=None if h == TIMESTEP else h) as p:
            assert p.model.opt.timestep == h
            got = stop_and_reverse(p)
        assert np.abs(np.hypot(got[:, 6] - ref[:, 6], got[:, 7] - ref[:, 7])).max() < 1e-3
        assert np.degrees(np.abs(got[:, 12] - ref[:, 12]).max()) < 0.05
        assert np.abs(got[:, [5, 11]] - ref[:, [5, 11]]).max() < 1e-3


@pytest.mark.long_on_numpy
def test_the_speed_set_point_is_the_middle_of_the_step_whatever_the_timestep(unloaded):
    # A ramp of the commanded speed is held for each 10 ms at its value at the
    # middle of the interval (its mean), so the followed speed does not depend
    # on how many MuJoCo steps the interval takes. At 0.5 m/s^2, a set-point at
    # the middle of the steps' starts (4.5 ms into the interval at 1 ms, 0 at
    # 10 ms) puts the two 2.2e-3 m/s apart; at the middle they agree within
    # RK4's own error at 10 ms (1.4e-4 m/s, 1e-5 at 5 ms): 5e-4 m/s.
    out = []
    for h in (0.01, 0.001):
        with Plant(unloaded, timestep=h) as p:
            p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
            v = []
            for k in range(400):
                p.step(0.01, 0.0, 0.5 * k * 0.01, 0.5)
                v.append(p.observe()[3])
            out.append(np.array(v))
    assert out[0][-1] == pytest.approx(2.0, abs=0.01)
    assert np.abs(out[0][50:] - out[1][50:]).max() < 5e-4


def test_divergence_names_time_and_wheel(unloaded_plant):
    p = unloaded_plant
    p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=1.0))
    p.step(0.01, 0.0, 1.0, 0.0)
    p.data.qvel[p._spin_dof[3]] = np.nan
    with pytest.raises(PlantError, match=r"t = 0\.0[0-9]+ s: the simulation diverged.*wheel"):
        p.step(0.01, 0.0, 1.0, 0.0)


@pytest.mark.parametrize("backend", [pytest.param("compiled", marks=needs_compiled(
    "the compiled tyre callback's range count")), "python"])
def test_tyre_range_warning_names_the_wheel(unloaded, backend):
    import dataclasses

    with Plant(unloaded, backend=backend) as p:
        # A tyre file whose valid load range ends below the front tyres' load.
        p.tyre = dataclasses.replace(p.tyre, FZMAX=20e3)
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
        with pytest.warns(TyreRangeWarning, match=r"front L: Fz = .* outside \[500, 20000\]"):
            p.step(0.01, 0.0, 0.0, 0.0)


@pytest.mark.slow
def test_reverse_ramp_steer_is_held_by_the_harness(unloaded):
    # A reverse ramp steer as a driver does it: at 3 km/h the articulation is
    # steered up to 30 deg, the log coming from the STM. The plant, driven by
    # the log's steering wheel and the harness with K = 3, follows it without
    # jackknifing: its articulation stays within a few degrees of the log's.
    v = unloaded
    t = np.arange(0.0, 35.0, 0.01)
    gref = math.radians(30.0) * np.clip((t - 3.0) / 20.0, 0.0, 1.0)
    s = v.steering_for("mbd")
    log = drive_articulation(STM(v), v, t, np.full_like(t, -3 / 3.6), gref,
                             steering=s)
    log.meta["name"] = "ramp"
    from tests.helpers import as_log

    log = as_log(log, "ramp")
    with Plant(v) as p:
        run_ = run_closed_loop(p, log, v, gain=3.0)
    assert run_.meta["status"] == "ok"
    g_meas, g_plant = log.frame["gamma"].to_numpy(), run_.frame["gamma"].to_numpy()
    assert abs(g_meas[-1]) > math.radians(25.0)
    assert np.max(np.abs(g_plant - g_meas)) < math.radians(5.0)
