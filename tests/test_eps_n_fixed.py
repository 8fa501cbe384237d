"""eps_n_fixed: the paper's numerators over one fixed scale per direction."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from artic.validation.criteria.fixedscale import (
    campaign_scale,
    eps_n_fixed,
    write_scale,
)
from artic.validation.criteria.metrics import run_metrics
from artic.validation.logs.runfile import Run
from tests.helpers import straight_log


def swaying(n: int, u: float, amp_r: float, amp_v: float, periods: int = 4) -> Run:
    """A straight log whose yaw rates and semitrailer lateral velocity are whole sine periods.

    The tractor sensor's lateral velocity stays zero: it enters the distance
    ``ds = hypot(v_x_1, v_y_1) dt``, which then is ``|u| dt`` exactly.
    """
    run = straight_log(n=n, u=u)
    f = run.frame
    phase = 2.0 * math.pi * periods * np.arange(n) / (n - 1)
    f["r_1"] = f["r_2"] = amp_r * np.sin(phase)
    f["v_y_2"] = amp_v * np.sin(phase)
    f["gamma"] = 0.0
    f["psi_2"] = 0.0
    return run


def test_scale_is_the_pooled_distance_rms():
    # Constant speed: the distance weights are uniform but for the half end
    # samples, so the RMS of a sine over whole periods is amp / sqrt(2).
    a = swaying(4001, -1.0, 0.02, 0.10)
    b = swaying(2001, -0.5, 0.04, 0.30)
    fwd = swaying(2001, 1.0, 0.5, 0.5)
    scale = campaign_scale([a, b, fwd])
    s_a, s_b = 40.0, 10.0  # metres each reversed
    want_r = math.sqrt((s_a * 0.02**2 / 2 + s_b * 0.04**2 / 2) / (s_a + s_b))
    want_v = math.sqrt((s_a * 0.10**2 / 2 + s_b * 0.30**2 / 2) / (s_a + s_b))
    rev = scale["reverse"]
    assert rev["s"] == pytest.approx(s_a + s_b, rel=1e-12)
    assert rev["logs"] == 2
    for c, want in (("r_1", want_r), ("r_2", want_r), ("v_y_2", want_v)):
        assert rev[c] == pytest.approx(want, rel=1e-3), c  # the end samples' half weights
    assert rev["v_y_1"] == 0.0
    # The forward log has a scale of its own and does not enter the reverse one.
    assert scale["forward"]["r_1"] == pytest.approx(0.5 / math.sqrt(2), rel=1e-3)


def with_error(log: pd.DataFrame, scale_signal: float, e_r: float, e_v: float) -> tuple:
    """The log with its r and v_y scaled, and a model that is off by a constant."""
    meas = log.copy()
    for c in ("r_1", "r_2", "v_y_2"):
        meas[c] = meas[c] * scale_signal
    model = meas.copy()
    model[["r_1", "r_2"]] += e_r
    model["v_y_2"] += e_v
    model["delta"], model["delta_fb"] = 0.0, 0.0
    return meas, model


def test_invariant_to_the_runs_own_signal_size_unlike_eps_n():
    campaign = [swaying(3001, -1.0, 0.03, 0.15), swaying(3001, -0.8, 0.05, 0.2)]
    scale = campaign_scale(campaign)["reverse"]
    log = swaying(3001, -1.0, 0.03, 0.15).frame
    got_n, got_fixed = [], []
    for c in (0.3, 1.0, 3.0):  # a run with little lateral motion, one with much
        meas, model = with_error(log, c, 0.002, 0.01)
        m = run_metrics(meas, model)
        got_n.append(m["eps_n"])
        got_fixed.append(eps_n_fixed(m["eps_a"], m["eps_v"], scale))
    # The same model error: eps_n_fixed is one number; eps_n falls as 1/c.
    assert got_fixed[0] == pytest.approx(got_fixed[1], rel=1e-12)
    assert got_fixed[2] == pytest.approx(got_fixed[1], rel=1e-12)
    assert got_n[0] == pytest.approx(got_n[1] / 0.3, rel=1e-9)
    assert got_n[2] == pytest.approx(got_n[1] / 3.0, rel=1e-9)
    # And it is the formula: both numerators over the summed units' scales.
    m = run_metrics(*with_error(log, 1.0, 0.002, 0.01))
    want = 100 * (m["eps_a"] / (scale["r_1"] + scale["r_2"])
                  + m["eps_v"] / (scale["v_y_1"] + scale["v_y_2"]))
    assert got_fixed[1] == pytest.approx(want, rel=1e-12)
    assert m["eps_a"] == pytest.approx(0.004, rel=1e-9)


def test_no_scale_or_a_scale_in_the_noise_gives_nan():
    assert math.isnan(eps_n_fixed(0.01, 0.01, None))
    flat = campaign_scale([straight_log(n=500, u=-1.0)])["reverse"]  # no yaw, no sway
    assert math.isnan(eps_n_fixed(0.01, 0.01, flat))


def test_scale_file_says_what_it_is(tmp_path):
    scale = campaign_scale([swaying(1001, -1.0, 0.03, 0.15)])
    path = write_scale(scale, tmp_path / "scale.json")
    doc = json.loads(path.read_text())
    assert doc["scale"] == scale
    assert "eps_n_fixed" in doc["what"]


def test_validate_runs_uses_one_scale_for_every_row(unloaded):
    from artic.validation.runs.validate import validate_runs

    logs = [swaying(1500, -0.8, 0.02, 0.05), swaying(1500, -0.8, 0.06, 0.2)]
    logs[1].meta["name"] = "bigger"
    rows = validate_runs(logs, unloaded, ["kin"])
    scale = rows.attrs["scale"]["reverse"]
    assert scale == campaign_scale(logs)["reverse"]
    r, v = scale["r_1"] + scale["r_2"], scale["v_y_1"] + scale["v_y_2"]
    want = 100 * (rows["eps_a"] / r + rows["eps_v"] / v)
    np.testing.assert_allclose(rows["eps_n_fixed"], want, rtol=1e-12)
    given = {"reverse": {**scale, "r_1": 10 * scale["r_1"]}}
    other = validate_runs(logs, unloaded, ["kin"], scale=given)
    assert (other["eps_n_fixed"] < rows["eps_n_fixed"]).all()
