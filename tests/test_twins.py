"""The noise-free twins: the same truth run as the measured log, measured with ideal sensors."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pandas as pd
import pytest

from artic.validation.logs.importers import import_source
from artic.validation.synthetic.generate import (
    TRUTH_RECORDS,
    exports_as_written,
    generate_campaign,
    simulate_manoeuvre,
)
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX

MOTION = ("x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1", "x_2", "y_2", "psi_2", "gamma")


def test_the_twin_is_the_same_truth_run_measured_without_noise():
    m = next(m for m in MATRIX if m.kind == "ramp-steer-reverse")
    log, twin = simulate_manoeuvre(m, 0, twin=True)
    # The logs are what they were without twins: the twin draws no random number.
    alone = simulate_manoeuvre(m, 0)
    pd.testing.assert_frame_equal(log.frame, alone.frame, check_exact=True)
    # The twin is bit for bit the truth run that ideal sensors measure, the
    # column's drift included (drift on in both): one simulation made both.
    ideal = simulate_manoeuvre(m, 0, SensorModel.ideal())
    pd.testing.assert_frame_equal(twin.frame, ideal.frame, check_exact=True)
    assert twin.meta["truth"] == log.meta["truth"] and twin.meta["truth"]["drift_rate"] != 0
    assert twin.meta["sensors"] == dataclasses.asdict(SensorModel.ideal())
    assert twin.meta["twin_of"] == log.meta["sensors"]
    # Same motion, another measurement: the logs differ from the twin by the
    # sensors' noise (positions 10 mm, velocities 10 mm/s; the trailer's clock
    # skew shifts its signals by a few samples of motion on top), not more.
    assert np.array_equal(twin.frame["t"], log.frame["t"])
    for c in ("x_1", "y_1", "v_y_1"):
        d = (log.frame[c] - twin.frame[c]).to_numpy()
        assert 0.002 < d.std() < 0.05, c  # 10 mm (or mm/s) sigma, within a factor of 5
    assert not np.array_equal(log.frame["delta_h"], twin.frame["delta_h"])  # the CAN bus's


def test_generate_exports_each_twin_and_reuses_both(tmp_path):
    m = next(m for m in MATRIX if m.kind == "constant-steer")
    out, twins = tmp_path / "synthetic", tmp_path / "twins"
    [path] = generate_campaign(out, only=[m.name], twins=twins)
    meta = json.loads((twins / m.name / "meta.json").read_text())
    assert meta["sensors"]["pos_sigma"] == 0.0 and meta["twin_of"]["pos_sigma"] == 0.01
    stamp = (path / "meta.json").stat().st_mtime_ns
    lines = []
    # what is reused is not yielded as written
    assert list(exports_as_written(out, only=[m.name], twins=twins, progress=lines.append)) == []
    assert (path / "meta.json").stat().st_mtime_ns == stamp  # reused, not made again
    assert any("already generated" in line for line in lines)
    # A missing twin makes the manoeuvre again, both exports, yielded together
    # once both are complete (the export, then the twin).
    for f in (twins / m.name).iterdir():
        f.unlink()
    (twins / m.name).rmdir()
    for written in exports_as_written(out, only=[m.name], twins=twins):
        assert written == [path, twins / m.name]
        assert all((f / "meta.json").is_file() for f in written)
    assert (twins / m.name / "meta.json").is_file()


@pytest.fixture(scope="module")
def reverse_exports(tmp_path_factory):
    """A reverse manoeuvre's export and its twin's (reverse logs hold the truth's records)."""
    m = next(m for m in MATRIX if m.kind == "ramp-steer-reverse")
    root = tmp_path_factory.mktemp("twins")
    out, twins = root / "synthetic", root / "twins"
    [path] = generate_campaign(out, only=[m.name], twins=twins)
    return path, twins / m.name


def test_a_twin_export_takes_the_truths_records_from_its_log(reverse_exports):
    # The twin's export leaves the truth's records to its log's meta.json (the same
    # truth run), and the importer reads them from there: the twin imports with them.
    path, twin_path = reverse_exports
    meta = json.loads((twin_path / "meta.json").read_text())
    assert not set(TRUTH_RECORDS) & set(meta)
    assert meta["meta_from"] == f"../../synthetic/{path.name}/meta.json"
    log, _ = import_source(path)
    twin, report = import_source(twin_path)
    assert report == [] and "meta_from" not in twin.meta
    for k in TRUTH_RECORDS:
        assert twin.meta[k] == log.meta[k]
    assert twin.meta["sensors"]["pos_sigma"] == 0.0  # its own metadata wins


def test_a_twin_whose_log_is_gone_imports_without_the_records_and_says_so(reverse_exports,
                                                                          tmp_path):
    import shutil

    twin_path = shutil.copytree(reverse_exports[1], tmp_path / "elsewhere" / "twin")
    twin, report = import_source(twin_path)
    assert not set(TRUTH_RECORDS) & set(twin.meta)
    assert len(report) == 1 and "meta_from" in report[0] and "without" in report[0], report


def test_the_truths_states_cover_every_candidate_of_the_log_and_of_its_twin(reverse_exports):
    # The floor starts from the truth's recorded state at each start-point
    # candidate; the twin's travelled distance differs from the log's by the
    # sensors' noise, so its marks fall on other samples: both sets are recorded.
    from artic.validation.criteria.distance import travelled
    from artic.validation.criteria.prediction import candidates, truth_states

    path, twin_path = reverse_exports
    log, _ = import_source(path)
    twin, _ = import_source(twin_path)
    states = truth_states(log.meta)
    marks = {}
    for run in (log, twin):
        k = candidates(travelled(run.frame))
        t = run.frame["t"].to_numpy()[k]
        marks[run.meta["sensors"]["pos_sigma"]] = set(np.round(t, 6))
        assert len(k) > 3 and all(states.at(float(v)) is not None for v in t), run.name
    assert marks[0.0] != marks[0.01]  # other samples: the test sees the case it is for
