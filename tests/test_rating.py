"""The ISO/TS 18571 columns ``iso_gap_*`` of a model run against its log."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.validation.criteria import columns
from artic.validation.criteria.rating import COLUMNS, RATE_HZ, gaps
from artic.validation.logs.runfile import Run
from tests.helpers import as_log, straight_log


def _turning_log(n: int = 3000):
    """A 30 s log at 100 Hz whose five rated signals swing (a 10 s period)."""
    log = straight_log(n=n, u=2.0)
    f = log.frame
    phase = 2 * math.pi * f["t"] / 10.0
    f["r_1"], f["r_2"] = 0.1 * np.sin(phase), 0.08 * np.sin(phase - 0.3)
    f["v_y_1"], f["v_y_2"] = 0.05 * np.sin(phase), 0.04 * np.sin(phase - 0.5)
    f["gamma"] = 0.2 * np.sin(phase - 0.2)
    return log


def test_a_run_equal_to_its_log_has_no_gap():
    log = _turning_log()
    out = gaps(log, as_log(log, "run"))
    assert set(out) == set(COLUMNS)
    assert all(out[c] == 0.0 for c in COLUMNS), out


def test_a_scaled_signal_costs_what_the_standard_says():
    # r_1 of the model 1.04 times the log's: every sample inside the inner corridor
    # (Z = 1), no shift (E_P = 1), slope error 0.04 (E_S = 0.98, the derivative is
    # linear); the magnitude error after warping is at most 0.04 (E_M >= 0.92): the
    # gap 1 - R lies in [0.2 * 0.02, 0.2 * 0.02 + 0.2 * 0.08].
    log = _turning_log()
    run = as_log(log, "run")
    run.frame["r_1"] *= 1.04
    out = gaps(log, run)
    assert 0.004 - 1e-9 <= out["iso_gap_r1"] <= 0.02 + 1e-9
    assert out["iso_gap_r2"] == 0.0
    assert out["iso_gap"] == pytest.approx(out["iso_gap_r1"] / 5, rel=1e-12)


def test_the_articulation_is_compared_across_the_cut():
    # a model articulation 2 pi away from the log's is the same angle
    log = _turning_log()
    run = as_log(log, "run")
    run.frame["gamma"] += 2 * math.pi
    assert gaps(log, run)["iso_gap_gamma"] == pytest.approx(0.0, abs=1e-12)


def test_only_the_model_rows_count_and_flat_signals_have_none():
    log = straight_log(n=2000, u=2.0)  # no yaw, no slip: nothing to rate
    out = gaps(log, as_log(log, "run"))
    assert all(math.isnan(out[c]) for c in COLUMNS)
    full = _turning_log()
    short = Run(full.frame.iloc[: int(100 / RATE_HZ)].copy(), full.meta)  # 1 rated sample
    assert all(math.isnan(v) for v in gaps(full, short).values())


def test_the_columns_are_rows_of_the_criteria_table():
    assert set(COLUMNS) <= set(columns.COLUMNS)
    assert {columns.POOL[c] for c in COLUMNS} == {"mean"}
