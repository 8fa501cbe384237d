"""What a log lacks, derived: rates from poses, either unit from the other, steering from the
yaw rate, and criteria pooled over gap-free segments."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from artic.mjcf.interface import wrap_angle
from artic.reduced import KIN
from artic.validation.criteria.metrics import (
    CRITERIA,
    distance_mean_abs,
    distance_rms,
    distance_weights,
)
from artic.validation.criteria.pooled import pool, pool_segments, whole_logs
from artic.validation.harness.loop import run_closed_loop
from artic.validation.harness.simulate import simulate
from artic.validation.logs.derive import derive_tractor, derive_trailer
from artic.validation.logs.differentiate import derivative, rates_from_pose, sinusoid_gain
from artic.validation.logs.runfile import Run, read_run
from artic.validation.logs.yawsteer import road_wheel_from_yaw_rate, speed_floor
from artic.validation.runs.validate import validate_runs
from artic.validation.synthetic.manoeuvres import make_profile
from tests.hostile_logs import docking


# ------------------------------------------------------------------ the differentiator
def test_differentiator_is_exact_on_a_quadratic_and_has_its_stated_gain():
    t = np.arange(0.0, 5.0, 0.01)
    x = 0.3 + 1.2 * t - 0.7 * t ** 2
    np.testing.assert_allclose(derivative(t, x, 0.5), 1.2 - 1.4 * t, atol=1e-9)  # ends too
    for period in (2.0, 5.0):
        w = 0.5
        dx = derivative(t, np.sin(2 * math.pi * t / period), w)
        mid = slice(100, -100)
        gain = np.max(np.abs(dx[mid])) / (2 * math.pi / period)
        # the continuous formula against the discrete filter: 0.3 % apart at 51 samples
        assert gain == pytest.approx(sinusoid_gain(w, period), rel=5e-3)
    assert sinusoid_gain(0.5, 5.0) < 1.0 - 0.9 * (math.pi * 0.1) ** 2 / 10


def test_rates_from_a_steady_turn_pose():
    """A unit on a circle of radius R at speed u, sensor on its centre line: v_x = u, v_y = 0,
    r = u / R, whatever the heading."""
    u, R = 1.5, 12.0
    t = np.arange(0.0, 10.0, 0.01)
    psi = u / R * t + 2.0
    x, y = R * np.sin(psi), -R * np.cos(psi)
    rates = rates_from_pose(t, x, y, psi, 0.5)
    # A circle is not a quadratic. Inside, the centred fit loses the sinusoid gain's
    # (u/R W/2)**2 / 10 = 1e-4; at the ends the edge window's quadratic is extrapolated
    # by up to W/2, an error of about R (u/R)**3 (W/2)**2 = 6e-4 m/s.
    mid = slice(25, -25)
    gain = sinusoid_gain(0.5, 2 * math.pi * R / u)
    assert 1 - gain == pytest.approx((u / R * 0.25) ** 2 / 10, rel=0.01)
    np.testing.assert_allclose(rates["v_x"][mid], u * gain, rtol=1e-5)  # the loss within 5 %
    np.testing.assert_allclose(rates["v_y"][mid], 0.0, atol=1e-6)
    np.testing.assert_allclose(rates["v_x"], u, atol=1e-3)
    np.testing.assert_allclose(rates["r"], u / R, rtol=1e-9)  # psi is linear: exact


def test_differentiator_noise_follows_the_stated_figure():
    rng = np.random.default_rng(0)
    t = np.arange(0.0, 60.0, 0.01)
    sigma = 0.01
    d = derivative(t, rng.normal(0.0, sigma, t.size), 0.5)
    n = 51
    expected = sigma * math.sqrt(12.0 / (n * (n * n - 1))) / 0.01
    assert np.std(d[100:-100]) == pytest.approx(expected, rel=0.05)


# ------------------------------------------------------------------ either unit
def test_derive_tractor_inverts_derive_trailer(unloaded):
    truth = docking().frame  # reversing, turning: every term of the kinematics in play
    tractor_only = truth.drop(columns=["x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2"])
    rate = (truth["r_1"] - truth["r_2"]).to_numpy()
    trailer, _ = derive_trailer(tractor_only, unloaded, rate)
    back, note = derive_tractor(trailer.drop(columns=["x_1", "y_1", "psi_1", "v_x_1", "v_y_1",
                                                      "r_1"]), unloaded, rate)
    for c in ("x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1"):
        np.testing.assert_allclose(back[c], truth[c], atol=1e-9, err_msg=c)
    assert "tractor channels" in note and unloaded.name in note


def test_derive_tractor_on_a_rigid_turn(unloaded):
    """Both units turn at r about one centre: the tractor sensor's speed is r times its
    distance from the centre, and its heading psi_2 + gamma."""
    v = unloaded
    r, gamma = 0.15, -0.25
    t = np.linspace(0.0, 4.0, 401)
    psi2 = r * t
    # semitrailer sensor on a circle about the origin
    s2 = np.array(v.sensor2[:2])
    R2 = 25.0
    p2 = np.column_stack([R2 * np.sin(psi2), -R2 * np.cos(psi2)])
    # its velocity: r x p2 (about the origin), in semitrailer axes
    ve, vn = -r * p2[:, 1], r * p2[:, 0]
    c, s = np.cos(psi2), np.sin(psi2)
    frame = pd.DataFrame({"t": t, "x_2": p2[:, 0], "y_2": p2[:, 1], "psi_2": psi2,
                          "v_x_2": c * ve + s * vn, "v_y_2": -s * ve + c * vn, "r_2": r,
                          "gamma": gamma})
    out, _ = derive_tractor(frame, v)
    np.testing.assert_allclose(out["psi_1"], psi2 + gamma, atol=1e-12)
    np.testing.assert_allclose(out["r_1"], r, atol=1e-9)
    dist = np.hypot(out["x_1"], out["y_1"])
    np.testing.assert_allclose(np.hypot(out["v_x_1"], out["v_y_1"]), r * dist, rtol=1e-9)
    # the kingpin both units agree on
    k2 = p2 - np.column_stack([c * s2[0] - s * s2[1], s * s2[0] + c * s2[1]])
    c1, s1 = np.cos(out["psi_1"]), np.sin(out["psi_1"])
    k1 = np.column_stack([out["x_1"] + c1 * (v.L1c - v.sensor1[0]) + s1 * v.sensor1[1],
                          out["y_1"] + s1 * (v.L1c - v.sensor1[0]) - c1 * v.sensor1[1]])
    np.testing.assert_allclose(k1, k2, atol=1e-9)


# ------------------------------------------------------------------ steering from the yaw rate
def test_yaw_rate_steering_is_kins_inverse_and_calm_at_standstill(unloaded):
    from artic.validation.logs.yawsteer import equivalent_wheelbase

    L1 = equivalent_wheelbase(unloaded)
    u = np.array([2.0, -1.5, 1.0])
    delta = np.array([0.1, -0.2, 0.3])
    r = u * np.tan(delta) / L1
    got = road_wheel_from_yaw_rate(u, r, L1, u_eps=1e-6)
    np.testing.assert_allclose(got, delta, rtol=1e-9)  # sign right forward and in reverse
    # standing still with yaw-rate noise: the plain inverse is any angle, this one is zero
    rng = np.random.default_rng(1)
    r_noise = rng.normal(0.0, 0.01, 1000)
    u0 = np.zeros(1000)
    assert np.all(road_wheel_from_yaw_rate(u0, r_noise, L1, u_eps=0.05) == 0.0)
    # and its largest angle from noise anywhere is L1 |r| / (2 u_eps)
    u_scan = np.linspace(-0.5, 0.5, 1001)
    worst = np.max(np.abs(road_wheel_from_yaw_rate(u_scan, 0.01, L1, u_eps=0.05)))
    assert worst == pytest.approx(math.atan(L1 * 0.01 / 0.1), rel=1e-3)
    assert speed_floor(np.full(10, 2.0)) == pytest.approx(0.1)


def test_kin_steered_from_its_own_yaw_rate_tracks_its_log(unloaded):
    """A KIN run steered by its yaw rate instead of its steering wheel: the same run."""
    p = make_profile("slalom", amplitude_deg=200.0, speed_kph=6.0, duration=20.0)
    log = simulate(KIN(unloaded), unloaded, p)
    log = Run(log.frame[log.frame.columns[:15]].copy(), {"name": "kin", "steer_from": "yaw-rate"})
    run = run_closed_loop(KIN(unloaded), log, unloaded).frame
    # the smoothing of r_1 and u_1 (0.5 s quadratic) is all that differs
    assert float(np.max(np.abs(run["r_1"] - log.frame["r_1"]))) < 2e-3
    assert float(np.max(np.abs(wrap_angle(run["gamma"] - log.frame["gamma"])))) < 2e-3
    plain = run_closed_loop(KIN(unloaded), Run(log.frame, {"name": "kin"}), unloaded)
    assert not np.allclose(plain.frame["delta_h"], run["delta_h"], atol=0.0)


# ------------------------------------------------------------------ pooling
def _segments(log: Run, cut: int) -> list[Run]:
    out = []
    for k, part in enumerate((log.frame.iloc[:cut], log.frame.iloc[cut + 150:]), start=1):
        f = part.reset_index(drop=True).copy()
        f["t"] = f["t"] - f["t"].iloc[0]
        out.append(Run(f, {"name": f"dock.seg{k}", "direction": "reverse",
                           "segment": {"log": "dock", "index": k, "of": 2}}))
    return out


def test_pooled_criteria_are_the_integrals_over_both_segments(unloaded, tmp_path):
    segs = _segments(docking(), 1500)
    metrics = validate_runs(segs, unloaded, ["kin"], out_dir=tmp_path)
    pooled = pool_segments(metrics, segs, tmp_path / "runs")
    row = pooled[pooled["segment"] == "pooled 2"].iloc[0]
    assert row["log"] == "dock" and row["status"] == "ok"
    # the integrals of eq. (8) over both segments' samples, each with its own weights
    w, err, meas, dfb, dc = [], {c: [] for c in ("r_1", "v_y_2")}, {"r": [], "v_y": []}, [], []
    for s in segs:
        run = read_run(tmp_path / "runs" / f"{s.name}.kin.parquet").frame
        f = s.frame.iloc[: len(run)]
        wk = distance_weights(f["t"].to_numpy(), np.hypot(f["v_x_1"], f["v_y_1"]).to_numpy())
        w.append(wk)
        for c in err:
            err[c].append((run[c] - f[c]).to_numpy())
        meas["r"].append(np.abs(f["r_1"]).to_numpy() + np.abs(f["r_2"]).to_numpy())
        meas["v_y"].append(np.abs(f["v_y_1"]).to_numpy() + np.abs(f["v_y_2"]).to_numpy())
        dfb.append(run["delta_fb"].to_numpy())
        dc.append((run["delta"] - run["delta_fb"]).to_numpy())
    W = np.concatenate(w)
    assert row["s_max"] == pytest.approx(W.sum(), rel=1e-12)
    # The run files hold the model's signals in single precision (6e-8 relative,
    # artic.validation.runs.validate.SINGLE); the pooled row is computed from the
    # runs in double: recomputed from the files, a criterion agrees to 1e-6.
    assert row["eps_r1"] == pytest.approx(distance_rms(np.concatenate(err["r_1"]), W), rel=1e-6)
    assert row["eps_vy2"] == pytest.approx(distance_rms(np.concatenate(err["v_y_2"]), W),
                                           rel=1e-6)
    r_mean = distance_mean_abs(np.concatenate(meas["r"]), W)
    vy_mean = distance_mean_abs(np.concatenate(meas["v_y"]), W)
    assert row["eps_n"] == pytest.approx(100 * (row["eps_a"] / r_mean + row["eps_v"] / vy_mean),
                                         rel=1e-9)
    J = 100 * distance_rms(np.concatenate(dfb), W) / distance_mean_abs(np.concatenate(dc), W)
    assert row["J_steer"] == pytest.approx(J, rel=1e-6) and J > 1.0  # reversing: feedback
    assert list(whole_logs(pooled)["log"]) == ["dock"]


def test_pool_of_one_segment_is_that_segment():
    part = {**dict.fromkeys(CRITERIA, 0.0), "eps_y1": 0.2, "eps_y2": 0.1, "eps_r1": 0.01,
            "eps_r2": 0.02, "eps_vy1": 0.03, "eps_vy2": 0.04, "J_steer": 12.0,
            "s_max": 30.0, "r": 0.1, "v_y": 0.2, "delta_c": 0.05}
    got = pool([part])
    assert got["eps_p"] == pytest.approx(0.3) and got["J_steer"] == pytest.approx(12.0)
    assert got["eps_n"] == pytest.approx(100 * (0.03 / 0.1 + 0.07 / 0.2))
    # two equal segments pool to the same; a segment twice as long weighs twice
    assert pool([part, part])["eps_y1"] == pytest.approx(0.2)
    other = {**part, "eps_y1": 0.5, "s_max": 60.0}
    assert pool([part, other])["eps_y1"] == pytest.approx(math.sqrt((0.04 + 2 * 0.25) / 3))


# ------------------------------------------------------------------ the command line
def test_steer_from_yaw_rate_and_tune_refusal(tmp_path, unloaded):
    import io
    from contextlib import redirect_stderr, redirect_stdout

    from artic.validation.cli.commands import main
    from artic.validation.logs.runfile import write_run
    from tests.hostile_logs import slalom

    log = tmp_path / "slalom.parquet"
    write_run(slalom(), log)

    def artic(*argv):
        out, err = io.StringIO(), io.StringIO()
        with redirect_stdout(out), redirect_stderr(err):
            code = main([str(a) for a in argv])
        return code, out.getvalue(), err.getvalue()

    code, out, err = artic("validate", log, "--models", "kin", "--no-recordings",
                           "--steer-from", "yaw-rate", "--out-dir", tmp_path / "yaw")
    assert code == 0, err
    assert "comparison is about the semitrailer" in out
    yaw = read_run(tmp_path / "yaw" / "runs" / "slalom.kin.parquet")
    code, _, err = artic("validate", log, "--models", "kin", "--no-recordings",
                         "--out-dir", tmp_path / "wheel")
    wheel = read_run(tmp_path / "wheel" / "runs" / "slalom.kin.parquet")
    assert yaw.meta["steer_from"] == "yaw-rate" and wheel.meta["steer_from"] == "delta_h"
    # KIN's tractor follows the measured yaw rate far closer when steered from it
    e_yaw = distance_rms(yaw.frame["r_1"] - slalom().frame["r_1"], np.ones(len(yaw.frame)))
    e_wheel = distance_rms(wheel.frame["r_1"] - slalom().frame["r_1"], np.ones(len(yaw.frame)))
    assert e_yaw < 0.5 * e_wheel
    # a log whose delta_h was derived cannot tune the steering map
    derived = Run(slalom().frame, {"derived": {"channels": ["delta_h"], "note": "x"}})
    write_run(derived, tmp_path / "derived.parquet")
    code, _, err = artic("tune", tmp_path / "derived.parquet", "--models", "kin", "--out",
                         tmp_path / "t.toml")
    assert code == 2 and "no steering channel" in err and "derived" in err


def test_a_segment_that_starts_in_a_turn_starts_without_a_transient(unloaded):
    """A segment after a gap starts mid-manoeuvre: the STM must start with its steered tyres at
    the first road-wheel angle's slip, or its yaw rate jumps by the angle's worth."""
    from artic.reduced import STM

    p = make_profile("constant-steer", amplitude_deg=200.0, speed_kph=8.0, duration=30.0)
    log = simulate(STM(unloaded), unloaded, p)
    f = log.frame[log.frame.columns[:15]].iloc[2000:].reset_index(drop=True)  # in the turn
    f["t"] -= f["t"].iloc[0]
    run = run_closed_loop(STM(unloaded), Run(f, {"name": "seg"}), unloaded).frame
    # The STM replays its own steady turn: what is left is the harness's speed smoothing.
    first = slice(0, 100)
    assert abs(f["r_1"].iloc[0]) > 0.05  # it is a turn
    assert float(np.max(np.abs(run["r_1"][first] - f["r_1"][first]))) < 1e-3
