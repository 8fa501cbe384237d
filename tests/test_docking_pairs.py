"""``artic dock``'s comparison of every two controllers over the same starts, after Holm."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from artic.validation.criteria.multiplicity import holm
from artic.validation.docking import pairs
from artic.validation.docking.scores import COLUMNS


def _runs() -> pd.DataFrame:
    """Three controllers, two scenarios, 12 seeds each: 24 starts.

    ``b`` ends 2 cm further off the line than ``a`` on every start and 5 s later;
    ``c`` is ``a`` with a little noise of its own and jackknifes on seeds 0-2.
    """
    rng = np.random.default_rng(3)
    rows = []
    for scenario in ("straight", "alley"):
        for seed in range(12):
            base = 0.02 + 0.004 * rng.standard_normal()
            for c, lat, t in (("a", base, 50.0 + seed), ("b", base + 0.02, 55.0 + seed),
                              ("c", base + 0.001 * rng.standard_normal(), 50.0 + seed)):
                failure = "jackknife: 61 deg" if c == "c" and seed < 3 else ""
                rows.append({k: 0.0 for k in COLUMNS} | {
                    "scenario": scenario, "vehicle": "v", "controller": c, "seed": seed,
                    "success": not failure, "failure": failure, "lateral_error_m": -lat,
                    "heading_error_deg": 0.2, "time_s": t})
    return pd.DataFrame(rows)


def test_the_benchmark_pools_every_start_and_corrects_over_the_whole_family():
    found = pairs.compare(_runs(), ["a", "b", "c"], metrics=pairs.ERRORS + (pairs.TIME,))
    # 3 pairs x (success, lateral, heading, time), one Holm family
    assert len(found) == 12 and list(found.columns) == pairs.COLUMNS
    np.testing.assert_array_equal(found["p_holm"], holm(found["p"].to_numpy()))
    ab = found[(found["a"] == "a") & (found["b"] == "b")].set_index("metric")
    # The start is (scenario, vehicle, seed): seed 0 of both scenarios are two starts.
    assert ab.loc["lateral_cm", "pairs"] == 24
    # |lateral| of a less b's: -2 cm on every start, in centimetres (the sign of the
    # magnitudes' difference, not of the signed errors, which are negative).
    assert ab.loc["lateral_cm", "difference"] == pytest.approx(-2.0, abs=1e-9)
    assert ab.loc["time_s", "difference"] == pytest.approx(-5.0)
    assert ab.loc["lateral_cm", "finding"] and ab.loc["time_s", "finding"]
    assert not ab.loc["heading_deg", "finding"]  # equal headings: nothing to find
    ac = found[(found["a"] == "a") & (found["b"] == "c")].set_index("metric")
    # c's jackknifes (seeds 0-2 of both scenarios): 6 starts only a docked, McNemar's
    # p = 2 / 2^6, and the errors over the 18 starts both finished.
    assert (ac.loc["success", "a_only"], ac.loc["success", "b_only"]) == (6, 0)
    assert ac.loc["success", "p"] == pytest.approx(2 * 0.5 ** 6)
    assert ac.loc["lateral_cm", "pairs"] == 18


def test_the_findings_in_words_and_the_markdown():
    found = pairs.compare(_runs(), ["a", "b"], metrics=pairs.ERRORS + (pairs.TIME,))
    text = pairs.markdown(found)
    assert "- a ends less off the line than b over every start: by 2 cm" in text
    assert "- a docks sooner than b over every start: by 5 s" in text
    assert "Holm's correction over the 4 tested." in text  # equal headings: p = 1, tested
    assert "| a | b | success | 24 | 0 vs 0 starts only one docked |" in text


def test_one_controller_has_nothing_to_compare():
    assert pairs.compare(_runs(), ["a"]).empty
