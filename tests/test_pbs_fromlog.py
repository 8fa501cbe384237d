"""The low-speed measures of a run with the motion (artic validate's pbs_measures.csv)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from artic.mjcf.vehicle import load_vehicle
from artic.validation.logs.runfile import Run
from artic.validation.pbs import fromlog, standards
from tests.test_pbs_measures import _kinematic_circle


def _frame(t, x1, y1, psi1, psi2) -> pd.DataFrame:
    return pd.DataFrame({"t": t, "x_1": x1, "y_1": y1, "psi_1": psi1, "psi_2": psi2})


def test_polyline_offsets_of_a_circle_are_radial():
    R = 12.0
    a = np.linspace(0.0, 2.0, 401)  # 5 mrad: a chord's sagitta R (5e-3)^2 / 8 = 4e-5 m
    path = fromlog.PolylinePath(np.c_[R * np.sin(a), R * (1 - np.cos(a))])
    b = np.linspace(0.2, 1.8, 37)
    for off in (-2.0, 0.5):
        r = R - off  # off to the left of a left turn is towards the centre
        s, n = path.frenet(r * np.sin(b), R - r * np.cos(b))
        assert n == pytest.approx(np.full(b.size, off), abs=1e-4)  # the sagitta, twice over
        # Along a chord the station of a point off the path moves by up to
        # |off| / R of half the chord (the chords are 6 cm): 5 mm at 2 m off.
        assert s == pytest.approx(R * b, abs=5e-3)


def test_a_steady_circle_offtracks_by_j695s_formula():
    # The log's own steer-axle path is the circle; the semitrailer's axle runs
    # the steady off-tracking inside it once the start's transient is gone.
    v = load_vehicle("gosar2022-loaded")
    L1 = max(a.x for a in v.tractor_axles)
    R = standards.J695_RADIUS
    expected = R - math.sqrt(R * R - L1 * L1 + v.L1c ** 2 - v.L2 ** 2)
    t, x1, y1, psi1, psi2 = _kinematic_circle(v, R, 150.0)
    run = Run(_frame(t, x1, y1, psi1, psi2), {"name": "circle"})
    m = fromlog.measures(fromlog.motion_of(run.frame, v), fromlog.reference_of(run, v))
    # The off-tracking grows towards the steady value and is largest at the end.
    # The start's transient decays by R_2 / (R_k L2), 0.1 per metre of the
    # kingpin's travel: after 150 m it is e**-15 of 3 m. The polyline's chords
    # (5 cm of travel) lie inside the circle by their sagitta, 2.5e-5 m.
    assert m["max_offtracking"] == pytest.approx(expected, abs=1e-4)


def test_a_model_that_runs_the_log_has_no_error_and_an_offset_one_has_the_offset():
    v = load_vehicle("gosar2022-loaded")
    t, x1, y1, psi1, psi2 = _kinematic_circle(v, 15.0, 30.0)
    log = Run(_frame(t, x1, y1, psi1, psi2), {"name": "turn"})
    # Shifted 0.3 m as a whole: the swept path moves with it, its width does not,
    # and the semitrailer's axle sits 0.3 m further from (or nearer to) the log's path.
    shifted = Run(_frame(t, x1 + 0.3, y1, psi1, psi2), {"name": "turn"})
    df = fromlog.validate_table([log], v, {("turn", "same"): log, ("turn", "moved"): shifted})
    same = df[df["model"] == "same"].iloc[0]
    assert same["swept_width_err"] == 0.0 and same["max_offtracking_err"] == 0.0
    moved = df[df["model"] == "moved"].iloc[0]
    assert 0.0 < moved["max_offtracking_err"] <= 0.3 + 1e-9
    assert np.isfinite(moved["swept_width_err"])
