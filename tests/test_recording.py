"""Rerun recordings: written atomically, read back with the rerun SDK."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from conftest import as_log
from reduced import KinematicModel, SingleTrackModel
from validation.campaign.recording import (
    YARD_RATE,
    artic_version,
    read_rows,
    read_text,
    record_manoeuvre,
    record_summary,
)
from validation.harness import run_closed_loop
from validation.simulate import simulate
from validation.synthetic.manoeuvres import make_profile


@pytest.fixture(scope="module")
def manoeuvre(unloaded):
    p = make_profile("ramp-steer-reverse", amplitude_deg=30.0, speed_kph=3.0, duration=12.0)
    log = as_log(simulate(SingleTrackModel(unloaded), unloaded, p), "ramp")
    log.meta["manoeuvre"] = "docking"  # so that the dock is drawn too
    runs = {cls.name: run_closed_loop(cls(unloaded), log, unloaded)
            for cls in (KinematicModel, SingleTrackModel)}
    return log, runs


def test_manoeuvre_recording_holds_every_sample(tmp_path, unloaded, manoeuvre):
    log, runs = manoeuvre
    path = record_manoeuvre(tmp_path / "ramp.rrd", log, runs, unloaded, extra="hello")
    assert [p.name for p in tmp_path.iterdir()] == ["ramp.rrd"]  # no temporary left
    rows = read_rows(path)
    n = len(log.frame)
    for src in ("measured", "kin", "stm"):
        assert rows[f"/signals/yaw_rate/tractor/{src}"] == len(runs.get(src, log).frame)
        assert rows[f"/signals/articulation/{src}"] == n
        # The yard at YARD_RATE: every k-th sample.
        every = round(1.0 / (YARD_RATE * 0.01))
        assert rows[f"/yard/{src}/tractor"] == math.ceil(n / every)
        for static in ("path", "tractor/body", "trailer/wheels", "envelope/trailer"):
            assert rows[f"/yard/{src}/{static}"] == 0  # present, static
    for model in ("kin", "stm"):
        assert rows[f"/signals/steering/delta_fb/{model}"] == n
        assert rows[f"/signals/error/lateral_position/{model}"] == n
    assert rows["/yard/dock"] == 0 and rows["/yard/ground"] == 0
    text = read_text(path, "/description")
    assert unloaded.name in text and artic_version() in text and "hello" in text


def test_summary_recording(tmp_path):
    metrics = pd.DataFrame({"log": ["a", "a", "b", "b"], "model": ["kin", "stm"] * 2,
                            **{c: np.arange(4.0) for c in ("eps_p", "eps_a", "eps_v", "eps_n",
                                                           "J_steer")}})
    path = record_summary(tmp_path / "campaign.rrd", metrics, "# report")
    rows = read_rows(path)
    assert rows["/criteria/eps_n/kin"] == 2 and rows["/criteria/J_steer/stm"] == 2
    assert read_text(path, "/report").startswith("# report")


def test_failed_recording_leaves_nothing(tmp_path, unloaded, manoeuvre):
    log, runs = manoeuvre
    bad = {"kin": runs["kin"], "stm": type(runs["stm"])(runs["stm"].frame.drop(columns="delta"),
                                                        runs["stm"].meta)}
    with pytest.raises(KeyError):
        record_manoeuvre(tmp_path / "bad.rrd", log, bad, unloaded)
    assert list(tmp_path.iterdir()) == []
