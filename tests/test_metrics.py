"""Error criteria, eqs. (8)-(10), on constructed runs with known answers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from artic.validation.criteria.metrics import distance_rms, distance_weights, run_metrics
from artic.validation.criteria.pathdist import distance_to_polyline
from tests.helpers import straight_log


def brute_force(points, path):
    """Every point against every segment, in complex numbers (independent of pathdist)."""
    z = points[:, 0] + 1j * points[:, 1]
    p = path[:, 0] + 1j * path[:, 1]
    a, b = p[:-1][None, :], p[1:][None, :]
    e = b - a
    safe = np.where(e == 0, 1.0, e)
    s = np.clip(np.real((z[:, None] - a) / safe), 0.0, 1.0)
    s = np.where(e == 0, 0.0, s)
    return np.abs(z[:, None] - (a + s * e)).min(axis=1)


@pytest.mark.parametrize("seed", range(5))
def test_polyline_distance_is_exact(seed):
    rng = np.random.default_rng(seed)
    # A wiggly path with a few repeated vertices (standstill) and one long
    # straight segment, and points near it and far from it.
    path = np.cumsum(rng.normal(0, 0.05, (400, 2)), axis=0)
    path[100:110] = path[100]
    path = np.vstack([path, path[-1] + [30.0, 0.0]])
    pts = np.vstack([path[rng.integers(0, len(path), 300)] + rng.normal(0, 0.3, (300, 2)),
                     rng.uniform(-40, 40, (50, 2))])
    np.testing.assert_allclose(distance_to_polyline(pts, path), brute_force(pts, path),
                               rtol=0, atol=1e-12)


def test_polyline_distance_degenerate_paths():
    pts = np.array([[3.0, 4.0]])
    assert distance_to_polyline(pts, np.zeros((1, 2)))[0] == pytest.approx(5.0)
    assert distance_to_polyline(pts, np.zeros((5, 2)))[0] == pytest.approx(5.0)
    with pytest.raises(ValueError, match="shape"):
        distance_to_polyline(pts, np.zeros((0, 2)))


def offset_run(log: pd.DataFrame, dy: float) -> pd.DataFrame:
    run = log.copy()
    run["y_1"] += dy
    run["y_2"] += dy
    run["delta"] = 0.0
    run["delta_fb"] = 0.0
    return run


def test_constant_offset_gives_that_offset():
    log = straight_log(n=1000, u=1.2).frame
    m = run_metrics(log, offset_run(log, 0.37))
    assert m["eps_y1"] == pytest.approx(0.37, rel=1e-12)
    assert m["eps_y2"] == pytest.approx(0.37, rel=1e-12)
    assert m["eps_p"] == pytest.approx(0.74, rel=1e-12)


def test_offset_on_a_circle_is_radial():
    # A model circle of radius 21 m against a measured circle of 20 m.
    t = np.linspace(0, 30, 3001)
    th = 0.06 * t
    log = straight_log(n=t.size, u=1.2).frame
    log["t"] = t
    for i in (1, 2):
        log[f"x_{i}"], log[f"y_{i}"] = 20 * np.cos(th), 20 * np.sin(th)
    run = log.copy()
    for i in (1, 2):
        run[f"x_{i}"], run[f"y_{i}"] = 21 * np.cos(th), 21 * np.sin(th)
    m = run_metrics(log, run)
    # The chords of the measured polyline sit inside the circle by at most
    # R (1 - cos(dth/2)) ~ 1.6e-6 m here.
    assert m["eps_y1"] == pytest.approx(1.0, abs=2e-6)


def test_reversing_counts_distance_positively():
    fwd = straight_log(n=1001, u=1.5).frame
    rev = straight_log(n=1001, u=-1.5).frame
    # 10 s at 1.5 m/s is 15 m, whichever way.
    assert run_metrics(rev, offset_run(rev, 0.1))["s_max"] == pytest.approx(15.0)
    assert run_metrics(fwd, offset_run(fwd, 0.1))["s_max"] == pytest.approx(15.0)
    # Speed changing sign mid-run: distance still adds up.
    w = distance_weights(np.array([0.0, 1.0, 2.0]), np.array([1.0, -1.0, -1.0]))
    assert w.sum() == pytest.approx(0.5 * (1 + 1) + 0.5 * (1 + 1))


def test_identical_run_gives_zero():
    log = straight_log(n=500, u=-1.0).frame
    log["r_1"] = log["r_2"] = 0.05
    log["v_y_1"] = log["v_y_2"] = 0.02
    m = run_metrics(log, offset_run(log, 0.0))
    for k in ("eps_y1", "eps_y2", "eps_r1", "eps_r2", "eps_vy1", "eps_vy2", "eps_n"):
        assert m[k] == 0.0, k


def test_rates_normalised_and_summed():
    # Measured r_1 = r_2 = 0.1 rad/s, v_y = 0.05 m/s; model 10 % high in r_1
    # and 0.01 m/s off in v_y_2. eps_n = 100 (0.01 / 0.2 + 0.01 / 0.1) = 15 %.
    log = straight_log(n=500, u=1.0).frame
    log["r_1"] = log["r_2"] = 0.1
    log["v_y_1"] = log["v_y_2"] = 0.05
    run = offset_run(log, 0.0)
    run["r_1"] = 0.11
    run["v_y_2"] = 0.06
    m = run_metrics(log, run)
    assert m["eps_r1"] == pytest.approx(0.01) and m["eps_r2"] == 0.0
    assert m["eps_a"] == pytest.approx(0.01) and m["eps_v"] == pytest.approx(0.01)
    assert m["eps_n"] == pytest.approx(15.0)


def test_eps_n_is_nan_without_motion():
    log = straight_log(n=200, u=1.0).frame
    assert np.isnan(run_metrics(log, offset_run(log, 0.1))["eps_n"])


def test_j_steer_by_hand():
    # delta_center = 0.1 rad throughout, the harness adds 0.02 rad: J = 20 %.
    log = straight_log(n=300, u=-1.0).frame
    run = offset_run(log, 0.0)
    run["delta"] = 0.12
    run["delta_fb"] = 0.02
    assert run_metrics(log, run)["J_steer"] == pytest.approx(20.0)


def test_distance_rms_weights_distance_not_time():
    # Error 1 while crawling at 0.1 m/s for 10 s, error 0 at 1 m/s for 10 s:
    # by distance the error covers 1 m of 11 m.
    t = np.arange(0, 20.001, 0.01)
    v = np.where(t < 10, 0.1, 1.0)
    eps = np.where(t < 10, 1.0, 0.0)
    w = distance_weights(t, v)
    assert distance_rms(eps, w) == pytest.approx(np.sqrt(1.0 / 11.0), rel=2e-3)


def test_travelled_ends_at_s_max():
    from artic.validation.criteria.distance import distance_weights, travelled

    t = np.linspace(0.0, 10.0, 101)
    f = pd.DataFrame({"t": t, "v_x_1": -np.sin(t), "v_y_1": 0.1 * np.cos(t)})
    s = travelled(f)
    assert s[-1] == pytest.approx(distance_weights(t, np.hypot(f.v_x_1, f.v_y_1)).sum(),
                                  rel=1e-12)
    assert np.all(np.diff(s) >= 0)  # reversing counts as distance too
