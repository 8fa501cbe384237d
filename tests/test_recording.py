"""Rerun recordings: written atomically, read back with the rerun SDK."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from artic.mjcf.interface import wrap_angle
from artic.plant import Plant
from artic.reduced import KIN, STM
from artic.validation.harness.loop import run_closed_loop
from artic.validation.harness.simulate import simulate
from artic.validation.review.plantshape import plant_shape, wheel_quat, xyzw
from artic.validation.review.recording import (
    FORCE_SCALE,
    PLOT_RATE,
    YARD_RATE,
    artic_version,
    read_column,
    read_rows,
    read_text,
    read_views,
    record_manoeuvre,
    record_summary,
)
from artic.validation.synthetic.manoeuvres import make_profile
from tests.helpers import as_log


@pytest.fixture(scope="module")
def manoeuvre(unloaded):
    p = make_profile("slalom", amplitude_deg=200.0, speed_kph=5.0, duration=10.0)
    log = as_log(simulate(STM(unloaded), unloaded, p), "ramp")
    log.meta["manoeuvre"] = "docking"  # so that the dock is drawn too
    runs = {cls.name: run_closed_loop(cls(unloaded), log, unloaded)
            for cls in (KIN, STM)}
    with Plant(unloaded) as plant:
        runs["mbd"] = run_closed_loop(plant, log, unloaded)
    return log, runs


@pytest.fixture(scope="module")
def recording(tmp_path_factory, unloaded, manoeuvre):
    log, runs = manoeuvre
    folder = tmp_path_factory.mktemp("rec")
    path = record_manoeuvre(folder / "ramp.rrd", log, runs, unloaded, extra="hello")
    return folder, path


def test_manoeuvre_recording_holds_the_signals(recording, unloaded, manoeuvre):
    folder, path = recording
    log, runs = manoeuvre
    assert [p.name for p in folder.iterdir()] == ["ramp.rrd"]  # no temporary left
    rows = read_rows(path)
    n = len(log.frame)
    every = round(1.0 / (YARD_RATE * 0.01))
    plots = math.ceil(n / round(1.0 / (PLOT_RATE * 0.01)))
    for group in ("articulation", "speed", "yaw_rate/tractor", "lateral_velocity/trailer",
                  "road_wheel", "feedback", "error/lateral_position"):
        assert rows[f"/signals/{group}"] == plots
    for src in ("measured", "kin", "stm"):
        assert rows[f"/yard/{src}/tractor"] == math.ceil(n / every)
        for static in ("path", "tractor/body", "trailer/wheels", "envelope/trailer"):
            assert rows[f"/yard/{src}/{static}"] == 0  # present, static
    assert rows["/yard/dock"] == 0 and rows["/yard/ground"] == 0
    text = read_text(path, "/description")
    assert unloaded.name in text and artic_version() in text and "hello" in text


def test_plots_in_degrees_with_units_in_their_titles(recording, manoeuvre):
    _, path = recording
    log, runs = manoeuvre
    views = read_views(path)
    sources = ["measured", "kin", "stm", "mbd"]
    assert read_column(path, "/signals/articulation", "SeriesLines:names")[0] == sources
    gamma = np.array(read_column(path, "/signals/articulation", "Scalars:scalars"))
    k = round(1.0 / (PLOT_RATE * 0.01))
    # Degrees, not radians: the recorded values are 57.3 times the run's.
    for j, src in enumerate(sources):
        frame = log.frame if src == "measured" else runs[src].frame
        np.testing.assert_allclose(gamma[:, j], np.degrees(frame["gamma"].to_numpy()[::k]),
                                   rtol=1e-9, atol=1e-9)
    assert np.abs(gamma).max() > 50 * np.abs(log.frame["gamma"]).max() > 0  # 57.3 times
    for origin in ("/signals/articulation", "/signals/steering_wheel", "/signals/road_wheel",
                   "/signals/feedback", "/signals/slip_angle"):
        assert "[deg]" in views[origin], views[origin]
    assert "[deg/s]" in views["/signals/yaw_rate/tractor"]
    assert "[km/h]" in views["/signals/speed"]
    assert views["/yard"] == "ramp: yard"  # named by the manoeuvre


def test_speed_plot(recording, manoeuvre):
    _, path = recording
    log, runs = manoeuvre
    speed = np.array(read_column(path, "/signals/speed", "Scalars:scalars"))
    k = round(1.0 / (PLOT_RATE * 0.01))
    np.testing.assert_allclose(speed[:, 0], 3.6 * log.frame["v_x_1"].to_numpy()[::k])
    assert speed[-1, 3] == pytest.approx(5.0, abs=0.2)  # the plant follows at 5 km/h


def test_plant_wheels_steer_and_spin(recording, manoeuvre, unloaded):
    _, path = recording
    _, runs = manoeuvre
    frame = runs["mbd"].frame
    k = round(1.0 / (YARD_RATE * 0.01))
    entity = "/yard/mbd/axle.front/wheel.front.L"
    q = np.array([row[0] for row in read_column(path, entity, "Transform3D:quaternion")])
    assert len(q) == math.ceil(len(frame) / k)
    # Rerun's (x, y, z, w) of steer about z, then spin about y:
    # (w, x, y, z) = (cos s cos p, -sin s sin p, cos s sin p, sin s cos p), halves.
    # With cos(steer / 2) > 0: z / w = tan(steer / 2) and y / w = tan(spin / 2).
    steer_rec = 2 * np.arctan2(q[:, 2], q[:, 3])
    spin_rec = 2 * np.arctan2(q[:, 1], q[:, 3])
    steer_run = frame["steer.front.L"].to_numpy()[::k]
    spin_run = frame["spin.front.L"].to_numpy()[::k]
    # float32 in the run file and in Rerun: a few 1e-7 rad
    # (the quaternion's sign flips with each half turn of spin: compare modulo 2 pi)
    np.testing.assert_allclose(wrap_angle(steer_rec - steer_run), 0.0, atol=1e-5)
    np.testing.assert_allclose(wrap_angle(spin_rec - spin_run), 0.0, atol=1e-5)
    assert np.ptp(frame["steer.front.L"]) > math.radians(5.0)  # the front wheel steers
    # Rolling without much slip: the spin angle is the distance over the radius.
    travelled = float(np.sum(frame["v_x_1"].to_numpy()[:-1]) * 0.01)
    assert spin_run[-1] - spin_run[0] == pytest.approx(travelled / 0.5, rel=0.1)
    # An unsteered wheel only spins: its quaternion has no z part.
    q_drive = np.array([row[0] for row in read_column(path, "/yard/mbd/axle.drive/wheel.drive.L",
                                                      "Transform3D:quaternion")])
    assert np.abs(q_drive[:, 2]).max() < 1e-6 and np.ptp(q_drive[:, 1]) > 0.5
    # Chassis and semitrailer geoms come from the plant's own model.
    names = {p.name for p in plant_shape(unloaded)}
    assert {"tractor", "trailer", "axle.front", "wheel.trailer-3.R", "fifth-wheel"} <= names


def test_tyre_force_arrows(recording, manoeuvre):
    _, path = recording
    _, runs = manoeuvre
    frame = runs["mbd"].frame
    k = round(1.0 / (YARD_RATE * 0.01))
    vectors = read_column(path, "/yard/mbd/tyre_forces", "Arrows3D:vectors")
    origins = read_column(path, "/yard/mbd/tyre_forces", "Arrows3D:origins")
    assert len(vectors) == math.ceil(len(frame) / k) and len(vectors[0]) == 10  # one per wheel
    row = len(vectors) // 2
    fy = frame["force.front.L.y"].to_numpy()[row * k]
    assert vectors[row][0][1] == pytest.approx(fy * FORCE_SCALE, rel=1e-5, abs=1e-6)
    assert origins[row][0][0] == pytest.approx(frame["contact.front.L.x"].to_numpy()[row * k],
                                               abs=1e-3)
    assert max(abs(v[1]) for v in vectors[row]) > 0.05  # lateral forces of hundreds of N


def test_wheel_quaternion_helpers():
    q = wheel_quat(np.array([0.3]), np.array([0.0]))[0]
    assert q == pytest.approx([math.cos(0.15), 0.0, 0.0, math.sin(0.15)])
    assert xyzw(q) == pytest.approx([0.0, 0.0, math.sin(0.15), math.cos(0.15)])


def test_summary_recording_by_manoeuvre_name(tmp_path):
    metrics = pd.DataFrame({"log": ["45-docking-unloaded-left"] * 2 + ["07-constant-steer"] * 2,
                            "model": ["kin", "stm"] * 2,
                            **{c: np.arange(4.0) for c in ("eps_p", "eps_a", "eps_v", "eps_n",
                                                           "J_steer")}})
    path = record_summary(tmp_path / "campaign.rrd", metrics, "# report")
    rows = read_rows(path)
    assert rows["/criteria/eps_n/kin"] == 2 and rows["/criteria/J_steer/stm"] == 2
    assert read_text(path, "/report").startswith("# report")
    # On the manoeuvre timeline at the number that starts each name (07 before 45).
    names = [r[0] for r in read_column(path, "/manoeuvre", "TextLog:text")]
    assert names == ["07-constant-steer", "45-docking-unloaded-left"]
    assert read_column(path, "/manoeuvre", "manoeuvre") == [7, 45]


def test_failed_recording_leaves_nothing(tmp_path, unloaded, manoeuvre):
    log, runs = manoeuvre
    bad = {"kin": runs["kin"], "stm": type(runs["stm"])(runs["stm"].frame.drop(columns="delta"),
                                                        runs["stm"].meta)}
    with pytest.raises(KeyError):
        record_manoeuvre(tmp_path / "bad.rrd", log, bad, unloaded)
    assert list(tmp_path.iterdir()) == []


def test_a_manoeuvre_plot_is_a_png_of_the_figures_size(tmp_path, manoeuvre):
    # The report's static plot (the campaign draws one per docking manoeuvre):
    # 12 x 5.5 in at 100 dpi is 1200 x 550 pixels, read from the PNG's header.
    import struct

    from artic.validation.review.plots import plot_manoeuvre

    log, runs = manoeuvre
    path = plot_manoeuvre(tmp_path / "m.png", log, runs)
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", head[16:24]) == (1200, 550)
    assert [p.name for p in tmp_path.iterdir()] == ["m.png"]  # nothing left beside it


def test_campaign_recordings_draw_on_workers_and_keep_the_newer(tmp_path, unloaded, manoeuvre):
    # The campaign starts its recordings on worker processes before the tables and
    # collects them after (artic.validation.campaign.recordings): what is collected
    # is the recording of each manoeuvre with a run, a recording newer than its runs
    # is kept without starting a worker, and closing leaves no worker behind.
    import multiprocessing

    from artic.validation.campaign.recordings import Recordings
    from artic.validation.logs.runfile import write_run

    log, runs = manoeuvre
    log = type(log)(log.frame, {**log.meta, "name": "m1", "manoeuvre": "slalom"})  # no plot
    for model, run in runs.items():
        write_run(run, tmp_path / "runs" / f"m1.{model}.parquet")
    metrics = pd.DataFrame({"log": ["m1"] * 3, "model": ["kin", "stm", "mbd"],
                            "status": ["ok", "ok", "failed: diverged"]})
    for c in ("eps_p", "eps_a", "eps_v", "eps_n", "J_steer"):  # the description's table
        metrics[c] = [0.25, 0.5, float("nan")]
    with Recordings(tmp_path, metrics, {"m1": log}, {"unloaded": unloaded},
                    ("kin", "stm", "mbd"), jobs=2) as started:
        # the failed plant run is left out; one manoeuvre, one worker
        assert [(set(r), t.name) for _, r, t in started.todo] == [({"kin", "stm"}, "m1.rrd")]
        made = started.collect()
    assert made == {"m1": tmp_path / "recordings" / "m1.rrd"}
    assert read_views(made["m1"])  # a recording Rerun reads, with its blueprint
    # every row of the manoeuvre's metrics went to the worker with it
    text = read_text(made["m1"], "/description")
    assert "| kin | 0.25 | 0.25 | 0.25 | 0.25 | 0.25 |" in text and "| mbd | nan |" in text
    assert not (tmp_path / "plots").exists()  # a slalom: no plot drawn
    again = Recordings(tmp_path, metrics, {"m1": log}, {"unloaded": unloaded},
                       ("kin", "stm", "mbd"), jobs=2)
    assert again.kept == 1 and again.todo == [] and again._pool is None
    assert again.collect() == made
    assert not multiprocessing.active_children()
