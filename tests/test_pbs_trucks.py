"""The low-speed measures over trucks: intervals and pairwise comparisons, by hand."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from artic.validation.pbs import trucks


def _rows(errors: dict[str, list[float]]) -> pd.DataFrame:
    rows = []
    for model, es in errors.items():
        for seed, e in enumerate(es):
            rows.append({"seed": seed, "load": "loaded", "model": model,
                         "measure": "swept_width", "unit": "m", "value": 5.0 + e,
                         "truth": 5.0, "error": e, "plant": math.nan,
                         "error_vs_plant": math.nan})
    return pd.DataFrame(rows)


def test_mean_error_over_trucks_is_students_interval():
    e = [0.01, 0.04, 0.02, 0.05, 0.03]
    errors, _ = trucks.pooled(_rows({"kin": e}))
    r = errors.iloc[0]
    # Five trucks: Student's t with four degrees of freedom, by hand.
    half = stats.t.ppf(0.975, 4) * np.std(e, ddof=1) / math.sqrt(5)
    assert r["mean_error"] == pytest.approx(0.03, abs=1e-15)
    assert (r["lo"], r["hi"]) == pytest.approx((0.03 - half, 0.03 + half), abs=1e-12)
    assert r["reference"] == "truth" and r["trucks"] == 5  # no plant values: no plant row


def test_pairs_are_students_test_on_the_trucks_differences_with_holm():
    kin = [0.05, -0.06, 0.07, 0.05, -0.06]
    stm = [0.01, 0.02, -0.015, 0.012, 0.018]
    mbd = [0.03, -0.02, 0.01, 0.05, 0.04]
    _, pairs = trucks.pooled(_rows({"kin": kin, "stm": stm, "mbd": mbd}))
    ps = []
    for a, b in (("kin", "stm"), ("kin", "mbd"), ("stm", "mbd")):
        d = np.abs({"kin": kin, "stm": stm, "mbd": mbd}[a]) - np.abs(
            {"kin": kin, "stm": stm, "mbd": mbd}[b])
        ps.append(stats.ttest_1samp(d, 0.0).pvalue)
    assert list(pairs["p"]) == pytest.approx(ps, rel=1e-12)
    # Holm by hand: sorted p times (3, 2, 1), running maximum, capped at 1.
    order = np.argsort(ps)
    adj = np.empty(3)
    running = 0.0
    for k, i in enumerate(order):
        running = max(running, min(1.0, (3 - k) * ps[i]))
        adj[i] = running
    assert list(pairs["p_holm"]) == pytest.approx(list(adj), rel=1e-12)
    assert list(pairs["resolved"]) == [p < 0.05 for p in adj]
    assert "kin" in trucks.markdown(*trucks.pooled(_rows({"kin": kin, "stm": stm})))


def test_one_truck_has_no_interval_and_no_test():
    errors, pairs = trucks.pooled(_rows({"kin": [0.02], "stm": [0.01]}))
    assert errors["lo"].isna().all() and pairs["p"].isna().all()
    assert not pairs["resolved"].any()


@pytest.mark.slow  # drives the truth and KIN through the PBS turn twice (about 10 s)
def test_a_truck_on_fresh_processes_is_the_same_truck():
    here = trucks.truck_table(0, models=("kin",))
    there = trucks.truck_table(0, models=("kin",), jobs=2, fresh=True)
    pd.testing.assert_frame_equal(here, there, check_exact=True)
