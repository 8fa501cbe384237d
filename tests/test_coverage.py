"""The progress term eps_cover: a model that does not follow the run along its length scores badly.

On a straight log the coverage has closed forms (a constant offset, standing
still, stopping part-way); a model that never moves passes the paper's
position error but fails the plugin's assertions and ranks last on
``eps_cover`` and, marked off the run, on the path criteria in the campaign's
tables, built here from ``validate_runs`` on two short synthetic logs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf.vehicle import load_vehicle
from artic.reduced import KIN, Driven
from artic.validation.criteria import columns
from artic.validation.criteria.coverage import FOLLOW_BOUND, eps_cover
from artic.validation.criteria.metrics import run_metrics
from artic.validation.criteria.pooled import RMS
from artic.validation.models import register_model, unregister_model
from artic.validation.review.tables import OFF_RUN, markdown, paired_table, summary
from artic.validation.runs.validate import validate_runs
from artic.validation.synthetic.generate import simulate_manoeuvre
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX
from artic.validation.testing import COVER_LIMIT, assert_tracks, default_limits
from tests.helpers import straight_log


class Still:
    """A model that never moves: KIN held at its start, whatever the log's speed."""

    name = "still"

    def __init__(self, vehicle):
        self._kin = Driven(KIN(vehicle))  # KIN with the state the harness keeps

    def reset(self, initial):
        self._kin.reset(initial)

    def step(self, dt, delta, u1, u1_dot):
        self._kin.step(dt, delta, 0.0, 0.0)

    def observe(self, delta=None):
        return self._kin.observe(delta)

    def compiled(self):
        return None

    def closed_loop(self):
        return None

    def close(self):
        pass

    @property
    def gamma(self):
        return self._kin.gamma


@pytest.fixture(scope="module")
def still():
    spec = register_model("still", Still)
    yield spec.name
    unregister_model(spec.name)


@pytest.fixture(scope="module")
def synthetic_logs():
    """Logs of the truth through the default sensors: the plugin's two (a forward constant
    steer, a reverse ramp steer), and two more constant steers for a paired comparison."""
    names = ("00-constant-steer-unloaded-200deg-5kph-left",
             "28-ramp-steer-reverse-unloaded-30deg-6kph-right",
             "01-constant-steer-unloaded-200deg-5kph-right",
             "04-constant-steer-unloaded-360deg-5kph-left")
    return [simulate_manoeuvre(next(m for m in MATRIX if m.name == n), 0, SensorModel())
            for n in names]


def test_a_constant_offset_is_covered_at_its_offset():
    # A model running parallel, e metres to the side, covers every measured
    # point at e for each unit: eps_cover = 2 e, as eps_p.
    log = straight_log(2000, u=1.0)
    run = log.frame.copy()
    run[["y_1", "y_2"]] += 0.3
    assert eps_cover(log.frame, run) == pytest.approx(0.6, rel=1e-12)
    assert run_metrics(log.frame, run)["eps_p"] == pytest.approx(0.6, rel=1e-12)


@pytest.mark.parametrize("q", [0.0, 0.5, 0.9])
def test_stopping_part_way_leaves_the_rest_uncovered(q):
    # A straight log of L = 19.99 m; the model stops after q L. Each unit's
    # measured point at s is s - q L from the model's path beyond q L, so
    # eps_cover^2 = (1/L) int_qL^L (2 (s - q L))^2 ds = 4 L^2 (1 - q)^3 / 3. The
    # trapezoidal rule errs by h^2 / (2 L^2) ~ 1e-7 relative on s^2 (h = L / 1999),
    # and the kink at q L by about h / L; the model's paths lie on the log's.
    log = straight_log(2000, u=1.0)
    f = log.frame
    L = float(f["x_1"].iloc[-1] - f["x_1"].iloc[0])
    k = int(round(q * (len(f) - 1)))
    run = f.copy()
    for c in ("x_1", "x_2"):
        run[c] = np.minimum(f[c].to_numpy(), f[c].iloc[k])
    expected = 2.0 * L * math.sqrt((1.0 - q) ** 3 / 3.0)
    assert eps_cover(f, run) == pytest.approx(expected, rel=2e-3)
    # The paper's position error does not see it: every model point is on the path.
    assert run_metrics(f, run)["eps_p"] < 1e-12


def test_a_model_that_never_moves_fails_assert_tracks_and_kin_passes(still, synthetic_logs):
    forward = synthetic_logs[0]
    v = load_vehicle(forward.meta["vehicle"])
    # eps_p alone: standing still at the start passes (the 0.079 m),
    # where KIN, which drives the 56 m, has about 3 m.
    with pytest.raises(AssertionError, match=r"eps_cover .* 7 m \(default\)\s+FAIL"):
        assert_tracks(still, forward, within={"eps_p": 4.0}, vehicle=v)
    got = assert_tracks("kin", synthetic_logs[:2], within={"eps_p": 4.0}, vehicle=v)
    for crit in got.values():
        # A following model's coverage is about its lateral error (equal for a
        # constant offset): within 15 % here, where KIN's errors vary along the run.
        assert crit["eps_cover"] == pytest.approx(crit["eps_p"], rel=0.15)
    # The model that never moves is on the measured path at its start: its
    # eps_p is below KIN's, its eps_cover the RMS distance of the run from its
    # start, metres to tens of metres.
    with pytest.raises(AssertionError) as failed:
        assert_tracks(still, forward, within={"eps_p": 0.5}, vehicle=v)
    assert "eps_p" in str(failed.value) and " pass" in str(failed.value)


def test_the_default_limit_is_a_lane_per_unit_whatever_the_position_limit():
    assert default_limits({"eps_n": 40.0}) == {"eps_cover": COVER_LIMIT} == {"eps_cover": 7.0}
    # A loose position limit does not loosen the progress bound.
    assert default_limits({"eps_p": 12.0}) == {"eps_cover": COVER_LIMIT}
    assert default_limits({"eps_cover": 1.0}) == {}
    # The plugin's number (kept a literal so the plugin loads no pandas) is the tables' bound.
    assert COVER_LIMIT == FOLLOW_BOUND


def test_a_loose_position_limit_still_fails_a_model_that_never_moves(still, synthetic_logs):
    forward = synthetic_logs[0]
    v = load_vehicle(forward.meta["vehicle"])
    # 1 km of eps_p would once have made the progress limit 1 km too.
    with pytest.raises(AssertionError, match=r"eps_cover .* 7 m \(default\)\s+FAIL"):
        assert_tracks(still, forward, within={"eps_p": 1000.0}, vehicle=v)


def test_the_model_that_never_moves_ranks_last_in_the_tables(still, synthetic_logs):
    v = load_vehicle(synthetic_logs[0].meta["vehicle"])
    metrics = validate_runs(synthetic_logs, v, ["kin", "stm", still])
    assert (metrics["status"] == "ok").all()
    assert "eps_cover" in metrics and "eps_cover" in columns.COLUMNS and "eps_cover" in RMS
    for direction in ("forward", "reverse"):
        table = summary(metrics, direction)
        assert "eps_cover" in table
        # Last on the progress term, by a wide margin.
        assert table["eps_cover"].idxmax() == still
        others = table.drop(index=still)["eps_cover"]
        assert table.loc[still, "eps_cover"] > 10.0 * others.max()
    # Its own eps_p is the smallest forward (it sits on the measured path at the
    # start), but its runs are off the run: marked, and last on the path criteria.
    assert metrics[metrics["model"] == still].groupby("direction")["eps_p"].mean()["forward"] \
        < metrics[metrics["model"] != still].groupby("direction")["eps_p"].mean()["forward"]
    for direction in ("forward", "reverse"):
        table = summary(metrics, direction)
        n_still = int(((metrics["model"] == still) & (metrics["direction"] == direction)).sum())
        assert table.loc[still, OFF_RUN] == n_still
        assert (table.drop(index=still)[OFF_RUN] == 0).all()
        assert table["eps_p"].idxmax() == still
        # Its path error is at least the bound, where every model that follows is within it.
        assert table.loc[still, "eps_p"] > FOLLOW_BOUND > table.drop(index=still)["eps_p"].max()
        assert f"{still} (**off the run** on {n_still} of {n_still})" in markdown(table)
    eps_p = paired_table(metrics, "forward", ["eps_p"])
    mine = eps_p[(eps_p["a"] == still) | (eps_p["b"] == still)]
    assert len(mine) == 2 and (mine["lower"] != still).all()
    # On the three forward manoeuvres the paired comparison resolves the model
    # that never moves above each other model on eps_cover.
    pairs = paired_table(metrics, "forward", ["eps_cover"])
    mine = pairs[(pairs["a"] == still) | (pairs["b"] == still)]
    assert len(mine) == 2 and mine["resolved"].all() and (mine["lower"] != still).all()
