"""The closed-loop reversing harness: the stability bound of eqs. (6)-(7)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf.steering import Steering
from artic.reduced import KIN, STM
from artic.reduced.kinematic import kin_rhs
from artic.validation.criteria.metrics import run_metrics
from artic.validation.harness.loop import run_closed_loop
from artic.validation.harness.simulate import drive_articulation, simulate
from artic.validation.synthetic.manoeuvres import make_profile
from tests.helpers import as_log, straight_log

U_REV = -3.0 / 3.6
G0 = math.radians(1.0)


def lam6(v, K, u=U_REV):
    """Eq. (6): the eigenvalue of the linearised reversing loop [1/s]."""
    return u * (-v.L1 + K * (v.L2 - v.L1c)) / (v.L1 * v.L2)


def straight_reverse(unloaded, seconds):
    # The log's steering wheel sits at the offset: delta_center = 0.
    s = unloaded.steering_for("kin").delta_h_offset
    return straight_log(n=int(seconds / 0.01), u=U_REV, gamma0=G0, delta_h=s)


def final_gamma(model, log, v, K):
    run = run_closed_loop(model, log, v, gain=K)
    return run.frame["gamma"].to_numpy(), run


def test_kin_linearised_loop_eigenvalue_is_eq6(unloaded):
    v = unloaded
    P = np.array([v.L1, v.L1c, v.L2])
    for K in (0.0, 0.5, 3.0):
        for u in (U_REV, -1.7):
            def g_dot(g, u=u, K=K):
                return kin_rhs(np.array([0, 0, 0, g]), u, 0.0, K * g, P)[3]
            J = (g_dot(1e-7) - g_dot(-1e-7)) / 2e-7
            assert J == pytest.approx(lam6(v, K, u), rel=1e-7)


def test_open_loop_reversing_diverges_and_k3_recovers(unloaded):
    v = unloaded
    log = straight_reverse(v, 30.0)
    for model in (KIN(v, "paper"), STM(v)):
        g_open, _ = final_gamma(model, log, v, 0.0)
        # lambda ~ +0.11 /s: 30 s grows a 1 deg articulation more than 10-fold.
        assert g_open[-1] > 10 * G0, model.name
        g_k3, run = final_gamma(model, log, v, 3.0)
        # lambda ~ -0.49 /s: after 30 s, e^-14 of the start, far below 1e-3.
        assert abs(g_k3[-1]) < 1e-3 * G0, model.name
        assert run.meta["status"] == "ok"


def test_gain_bound_and_growth_rate_match_eq6(unloaded):
    # Eq. (7): the loop is stable for K > L1 / (L2 - L1c). Just below it grows,
    # just above it decays, and at the rate eq. (6) gives (a 1 deg start keeps
    # the loop linear to better than 1e-4).
    v = unloaded
    Kc = v.L1 / (v.L2 - v.L1c)
    assert Kc == pytest.approx(0.5564, abs=1e-4)
    log = straight_reverse(v, 120.0)
    t = log.frame["t"].to_numpy()
    for K in (0.9 * Kc, 1.1 * Kc):
        g, _ = final_gamma(KIN(v, "paper"), log, v, K)
        rate = math.log(g[-1] / g[2000]) / (t[-1] - t[2000])
        assert rate == pytest.approx(lam6(v, K), rel=0.01)
        assert (rate > 0) == (K < Kc)


def test_printed_sign_of_eq5_destabilises(unloaded):
    # delta = delta_center + K (gamma_measured - gamma_model), as printed, is
    # the harness with -K: it must grow for K = 3.
    v = unloaded
    g, _ = final_gamma(KIN(v, "paper"), straight_reverse(v, 10.0), v, -3.0)
    assert abs(g[-1]) > 5 * G0


def test_feedback_only_while_reversing(unloaded):
    v = unloaded
    s = v.steering_for("kin").delta_h_offset
    fwd = straight_log(n=500, u=1.4, gamma0=G0, delta_h=s)
    _, run = final_gamma(KIN(v, "paper"), fwd, v, 3.0)
    assert np.all(run.frame["delta_fb"] == 0.0)
    _, run = final_gamma(KIN(v, "paper"), straight_reverse(v, 5.0), v, 3.0)
    fb = run.frame["delta_fb"].to_numpy()
    g = run.frame["gamma"].to_numpy()
    # Row 0 is the log's own first sample (no error); from row 1 the measured
    # articulation is 0 and the model's is not.
    assert abs(fb[0]) < 1e-15  # the angle wrap rounds at the 1e-16 level
    np.testing.assert_allclose(fb[1:], 3.0 * g[1:], rtol=1e-12)
    assert np.all(np.abs(fb[1:]) > 0)


def test_saturation_is_reported(unloaded):
    v = unloaded
    s = v.steering_for("kin").delta_h_offset
    log = straight_log(n=300, u=U_REV, gamma0=math.radians(20.0), delta_h=s)
    _, run = final_gamma(KIN(v, "paper"), log, v, 3.0)
    # 3 x 20 deg = 60 deg asked at row 1, 43 deg (delta_max) given, and said so.
    assert run.frame["delta_saturated"].iloc[1]
    assert run.frame["delta"].iloc[1] == pytest.approx(v.steering.delta_max)


def test_kin_validated_against_its_own_log_gives_zero(unloaded):
    v = unloaded
    s = v.steering_for("kin")
    prof = make_profile("constant-steer", amplitude_deg=360, speed_kph=5, side="right",
                        duration=40.0, delta_h_offset=s.delta_h_offset, L1=v.L1, i_s=s.i_s)
    log = as_log(simulate(KIN(v, "paper"), v, prof), "kin-fwd")
    m = run_metrics(log.frame, run_closed_loop(KIN(v, "paper"), log, v).frame)
    for key in ("eps_y1", "eps_y2", "eps_r1", "eps_r2", "eps_vy1", "eps_vy2", "J_steer"):
        assert m[key] < 1e-9, (key, m[key])
    # Reverse, from a driver holding 25 deg of articulation: the feedback sees
    # no error, so the model replays the log.
    t = np.arange(0, 40, 0.01)
    gref = math.radians(25) * np.clip(t / 20, 0, 1)
    drv = drive_articulation(KIN(v, "paper"), v, t, np.full_like(t, U_REV), gref,
                             steering=s)
    rev = as_log(drv, "kin-rev")
    m = run_metrics(rev.frame, run_closed_loop(KIN(v, "paper"), rev, v).frame)
    assert abs(rev.frame["gamma"].iloc[-1]) > math.radians(20)
    for key in ("eps_y1", "eps_y2", "eps_r1", "eps_r2", "J_steer"):
        assert m[key] < 1e-6, (key, m[key])


def test_speed_input_corrects_sensor_offset(unloaded):
    # u1 = v_x_1 + r_1 * y_s1: a tractor sensor 5 mm right of the centre line
    # reads r_1 * 0.005 m/s less than the centre line moves.
    from artic.validation.harness.loop import loop_inputs

    log = straight_log(n=10, u=1.0)
    log.frame["r_1"] = 0.2
    linear = Steering(21.0, 0.0, 0.0, delta_max=unloaded.steering.delta_max)
    inputs = loop_inputs(log, unloaded, linear)
    assert inputs.u1[0] == pytest.approx(1.0 + 0.2 * unloaded.sensor1[1])


def test_jackknife_stops_open_loop_reverse(unloaded):
    v = unloaded
    s = v.steering_for("kin")
    prof = make_profile("ramp-steer-reverse", amplitude_deg=90, speed_kph=6,
                        duration=200.0, delta_h_offset=s.delta_h_offset, L1=v.L1, i_s=s.i_s)
    run = simulate(KIN(v, "paper"), v, prof)
    assert run.meta["status"].startswith("stopped at")
    assert "jackknife" in run.meta["status"]
    assert abs(run.frame["gamma"].iloc[-1]) > v.gamma_max
    assert len(run.frame) < prof.t.size


def test_speed_filter_passes_a_quadratic_and_removes_noise():
    from artic.validation.harness.loop import smooth_speed

    t = np.arange(0.0, 20.0, 0.01)
    u = 0.5 + 0.2 * t - 0.01 * t ** 2  # braking and accelerating profiles are quadratic-ish
    np.testing.assert_allclose(smooth_speed(t, u), u, atol=1e-12)
    rng = np.random.default_rng(1)
    noise = rng.normal(0.0, 0.01, t.size)
    # A quadratic fit over 51 samples leaves sqrt(3 (3 m^2 + 3 m - 1) / ((2m - 1)(2m + 1)(2m + 3)))
    # ~ 0.21 of white noise at the centre (m = 25); 0.3 bounds it over the whole log.
    rest = np.std(smooth_speed(t, u + noise) - u)
    assert rest < 0.3 * 0.01
    # The difference quotient, the plant's feed-forward, drops far more.
    assert np.std(np.diff(smooth_speed(t, u + noise) - u)) < 0.05 * np.std(np.diff(noise))


def test_compiled_law_equals_the_python_law_to_the_bit():
    # The truth's drivers and the plant's Python loop call the plain law, the
    # reduced models' numba loop its compiled form: the same arithmetic in the
    # same order, so the same bits, across wraps and both saturations.
    from artic.validation.harness import feedback, reducedloop

    rng = np.random.default_rng(7)
    for i in range(3000):
        weight = (0.0, 1.0, float(rng.uniform(0.0, 1.0)))[i % 3]  # off, on, handing over
        args = (float(rng.uniform(-0.9, 0.9)), float(rng.uniform(-7.0, 7.0)),
                float(rng.uniform(-7.0, 7.0)), weight, float(rng.uniform(0.0, 6.0)), 0.75)
        assert feedback.feedback_law(*args) == reducedloop.feedback_law(*args), args
        assert feedback.wrap(args[1]) == reducedloop.wrap(args[1])


def test_the_law_weighs_its_feedback_term():
    # delta = delta_c + w K wrap(gamma_model - gamma_meas): linear in w, none at w = 0
    # (not even a NaN error's), the wrap before the weight, the limit after it.
    from artic.validation.harness.feedback import feedback_law

    dc, K, dmax = 0.1, 3.0, 0.75
    gm, gs = 0.05, -0.02  # e = 0.07 rad
    full = feedback_law(dc, gm, gs, 1.0, K, dmax)
    assert full[1] == pytest.approx(K * 0.07, rel=1e-12) and not full[2]
    for w in (0.25, 0.5, 0.9):
        d, fb, sat = feedback_law(dc, gm, gs, w, K, dmax)
        assert fb == pytest.approx(w * K * 0.07, rel=1e-12) and d == pytest.approx(dc + fb)
        assert not sat
    assert feedback_law(dc, math.nan, gs, 0.0, K, dmax) == (dc, 0.0, False)
    # An error across the wrap: 2 pi - 0.01 is -0.01, weighted.
    assert feedback_law(0.0, 2 * math.pi - 0.005, 0.005, 0.5, K, dmax)[1] == \
        pytest.approx(0.5 * K * -0.01, rel=1e-9)
    # Saturation applies to the weighted command: half of 0.4 rad of feedback fits.
    big = (0.5, 0.4 / K, 0.0, None, K, dmax)
    assert feedback_law(*big[:3], 1.0, *big[4:]) == (dmax, dmax - 0.5, True)
    d, fb, sat = feedback_law(*big[:3], 0.5, *big[4:])
    assert d == pytest.approx(0.7) and not sat


def test_plant_runs_do_not_import_numba():
    # `artic simulate --model mbd` closes the loop in C; numba's import
    # (about 0.15 s) is for the reduced models only.
    import subprocess
    import sys

    code = ("import sys, artic.validation.cli.commands, artic.validation.harness.loop, "
            "artic.validation.harness.simulate, artic.plant; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] == 'numba'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"
