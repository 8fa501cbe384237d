"""Docking runs on the plant: failures are rows, controllers see only the sensors, scores."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.interface import OBS_INDEX
from artic.plant import closedloop
from artic.validation.criteria.statistics import format_ci
from artic.validation.docking.controllers import BUILTIN, Command, Controller, load
from artic.validation.docking.planner import steady_delta
from artic.validation.docking.run import DT, PLANT_DT, drive
from artic.validation.docking.scenarios import SCENARIOS, scenario
from artic.validation.docking.scores import COLUMNS, markdown, rate_ci, table
from artic.validation.docking.sensing import SensorStream
from artic.validation.synthetic.sensors import SensorModel

VEHICLE = "gosar2022-unloaded"

USER_CONTROLLER = (Path(__file__).resolve().parents[1] / "docs" / "guide" / "docking.md"
                   ).read_text().split("```python\n", 1)[1].split("```", 1)[0]
"""The docking guide's controller of your own, run here as a user would run it."""


class HoldStraight(Controller):
    """Reverse at 5 km/h keeping the articulation at zero, and never stop."""

    def command(self, obs):
        delta = steady_delta(0.0, self.frames.P) + 3.0 * obs["gamma"]
        return Command(self.steering_wheel(delta), -5.0 / 3.6)


class FullLock(Controller):
    """Reverse with the wheel at full lock: a jackknife."""

    def command(self, obs):
        return Command(self.steering_wheel(self.vehicle.steering.delta_max), -1.0)


class Raises(Controller):
    def command(self, obs):
        if obs.t > 0.5:
            raise ZeroDivisionError("user bug")
        return Command(self.steering_wheel(0.0), -1.0)


class NotANumber(Controller):
    def command(self, obs):
        return Command(float("nan"), -1.0)


class StandStill(Controller):
    def command(self, obs):
        return Command(self.steering_wheel(0.0), 0.0)


class DoneAtOnce(Controller):
    def command(self, obs):
        return Command(self.steering_wheel(0.0), 0.0, done=True)


# ---------------------------------------------------------------- failures are rows
def test_a_collision_with_the_dock_is_a_failed_run_not_a_crash():
    r = drive(scenario("straight"), VEHICLE, HoldStraight, 1)
    row = r.row
    assert row["success"] is False
    assert row["failure"].startswith("collision: semitrailer hit dock at t = ")
    # It stopped at once: the rear just past the bumpers, long before the timeout.
    assert -0.2 < row["longitudinal_error_m"] < 0.0
    assert row["time_s"] < 60.0


def test_a_jackknife_is_a_failed_run_not_a_crash():
    v = load_vehicle(VEHICLE)
    r = drive(scenario("straight"), VEHICLE, FullLock, 0)
    assert r.row["failure"].startswith("jackknife: |gamma|")
    assert r.row["success"] is False
    # Stopped on the step that passed the limit.
    assert math.degrees(v.gamma_max) < r.row["max_gamma_deg"] < math.degrees(v.gamma_max) + 0.5
    assert r.row["gamma_margin_deg"] < 0.0


def test_a_controller_that_raises_or_returns_nan_is_a_failed_run():
    r = drive(scenario("straight"), VEHICLE, Raises, 0)
    assert r.row["failure"].startswith("controller error: ZeroDivisionError: user bug (")
    assert "test_docking_run.py" in r.row["failure"]
    r = drive(scenario("straight"), VEHICLE, NotANumber, 0)
    assert r.row["failure"].startswith("controller error: non-finite command")


def test_a_timeout_and_a_stop_short_of_the_door_are_failures():
    r = drive(scenario("straight"), VEHICLE, StandStill, 0, timeout=1.0)
    assert r.row["failure"] == "timeout: not docked after 1 s"
    r = drive(scenario("straight"), VEHICLE, DoneAtOnce, 0)
    assert r.row["failure"].startswith("missed the door: rear ")
    assert r.row["longitudinal_error_m"] == pytest.approx(r.row["start_x_m"], abs=0.01)


@pytest.mark.parametrize("controller, options", [
    (HoldStraight, {}),  # into the dock: a collision
    (FullLock, {}),  # a jackknife within a sample's steps
    (StandStill, {"timeout": 2.0}),
    (DoneAtOnce, {"delay": 0.05, "steer_rate": 2.0}),  # delayed, slower wheel, settling
])
def test_the_compiled_steps_run_as_the_python_loop_to_the_bit(controller, options, monkeypatch):
    # drive steps the plant a sample at a time in C (closedloop.Ramp) where it can; its
    # Python loop is the reference: the traces and the scores agree to the bit.
    calls = []
    run = closedloop.Ramp.run

    def counted(self):
        calls.append(1)
        return run(self)

    monkeypatch.setattr(closedloop.Ramp, "run", counted)
    a = drive(scenario("straight"), VEHICLE, controller, 1, realtime=False, **options)
    assert calls  # it ran compiled
    compiled = len(calls)
    monkeypatch.setattr(closedloop, "ramp_available", lambda plant: False)
    b = drive(scenario("straight"), VEHICLE, controller, 1, realtime=False, **options)
    assert len(calls) == compiled  # and this one in Python
    ta, tb = a.trace.arrays(), b.trace.arrays()
    for key in ("t", "true", "steering_wheel", "speed", "measured", "commands"):
        np.testing.assert_array_equal(ta[key], tb[key], err_msg=key)
    timed = ("plan_ms", "solve_ms", "solve_ms_p50", "solve_ms_p99")
    assert a.row.keys() == b.row.keys()
    for key in a.row.keys() - set(timed):
        x, y = a.row[key], b.row[key]
        assert x == y or (x != x and y != y), key  # NaN where a score is unknown
    assert a.trace.seen_at == b.trace.seen_at and a.row["failure"] == b.row["failure"]


# ---------------------------------------------------------------- what a controller sees
class Spy(Controller):
    seen: list = []

    def reset(self, task):
        super().reset(task)
        assert not hasattr(task, "plant")
        Spy.seen = []

    def command(self, obs):
        Spy.seen.append((obs.t, obs.signals.copy(), obs.delta_h))
        return Command(self.steering_wheel(0.02), -1.0, done=obs.t >= 2.0)


def test_the_controller_sees_the_campaigns_noisy_sensors_not_the_plant():
    r = drive(scenario("straight"), VEHICLE, Spy, 0)
    true = np.asarray(r.trace.true)
    t = np.array([s[0] for s in Spy.seen])
    assert t == pytest.approx(np.arange(len(t)) * DT)
    seen = np.array([s[1] for s in Spy.seen])
    at = true[np.round(t / PLANT_DT).astype(int)]
    err = seen - at
    # RTK noise of about a centimetre on positions, not zero and not metres.
    pos = err[:, [OBS_INDEX["x_1"], OBS_INDEX["y_1"], OBS_INDEX["x_2"], OBS_INDEX["y_2"]]]
    assert 1e-4 < np.abs(pos).max() < 0.06
    # The articulation is the difference of the measured headings.
    assert seen[:, 12] == pytest.approx(seen[:, 2] - seen[:, 8], abs=1e-12)
    # The steering wheel arrives late and quantised, as the CAN bus delivers it.
    dh = np.array([s[2] for s in Spy.seen])
    assert np.allclose(dh / math.radians(0.1), np.round(dh / math.radians(0.1)), atol=1e-6)


def test_ideal_sensors_report_the_plant():
    r = drive(scenario("straight"), VEHICLE, Spy, 0, sensors=SensorModel.ideal())
    true = np.asarray(r.trace.true)
    t = np.array([s[0] for s in Spy.seen])
    seen = np.array([s[1] for s in Spy.seen])
    assert seen == pytest.approx(true[np.round(t / PLANT_DT).astype(int)], abs=1e-12)


def test_the_sensor_stream_reports_the_wheel_50_ms_late_at_10_hz():
    stream = SensorStream(SensorModel(), np.random.default_rng(0), 10, DT, PLANT_DT)
    wheel = [math.radians(k) for k in range(31)]  # 1 deg per 10 ms
    _, dh = stream.observe(3, [np.zeros(13)] * len(wheel), wheel)
    # Now is sample 30; the bus sampled at 30 the value of 50 ms before: 25 deg.
    assert math.degrees(dh) == pytest.approx(25.0)
    # Its noise is the campaign's: a Gauss-Markov position error of about 1 cm.
    big = SensorStream(SensorModel(), np.random.default_rng(1), 20000, DT, PLANT_DT)
    assert np.std(big.noise[:, 0]) == pytest.approx(0.01, rel=0.3)


def _ramp(n: int) -> list[np.ndarray]:
    """Plant signals at ``n`` steps whose every channel reads the time [s] (headings small)."""
    return [np.full(13, i * PLANT_DT) for i in range(n)]


@pytest.mark.parametrize("skew", [0.0118, 0.05, -0.03])
def test_a_skewed_semitrailer_unit_lags_the_plant_by_its_skew(skew):
    """Paired by their stamps: the semitrailer as it was ``skew`` ago (early stamps: both late)."""
    import dataclasses

    model = dataclasses.replace(SensorModel.ideal(), trailer_skew=skew)
    stream = SensorStream(model, np.random.default_rng(0), 10, DT, PLANT_DT)
    true = _ramp(301)  # now is 3.0 s
    seen, _ = stream.observe(3, true, [0.0] * 301)
    tractor = seen[[OBS_INDEX[c] for c in ("x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1")]]
    trailer = seen[[OBS_INDEX[c] for c in ("x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2")]]
    late = max(0.0, -skew)  # early stamps: the pair for now is whole only |skew| later
    assert tractor == pytest.approx(3.0 - late, abs=1e-12)
    assert trailer == pytest.approx(3.0 - late - skew, abs=1e-12)
    # The articulation is the measured headings' difference: the skew times the yaw rate.
    assert seen[OBS_INDEX["gamma"]] == pytest.approx(skew, abs=1e-12)


def test_the_stream_skews_as_the_campaigns_logs_are_skewed():
    """The sensor model's own resampling (``measure``) and the stream's agree."""
    import dataclasses

    from artic.validation.logs.runfile import new_frame
    from artic.validation.synthetic.sensors import measure

    model = dataclasses.replace(SensorModel.ideal(), trailer_skew=0.0237)
    t = np.arange(400) * PLANT_DT
    signals = np.column_stack([np.sin(0.7 * t + j) for j in range(13)])
    logged = measure(new_frame(t, np.zeros(t.size), signals), np.random.default_rng(0), model)
    stream = SensorStream(model, np.random.default_rng(0), 40, DT, PLANT_DT)
    for k in (5, 17, 39):
        i = round(k * DT / PLANT_DT)
        seen, _ = stream.observe(k, list(signals[:i + 1]), [0.0] * (i + 1))
        for c in ("x_2", "psi_2", "r_2", "x_1", "gamma"):
            assert seen[OBS_INDEX[c]] == pytest.approx(logged[c].iloc[i], abs=1e-12), (k, c)


def test_on_the_truth_the_controller_sees_its_semitrailer_units_clock_skew():
    import dataclasses

    from artic.validation.synthetic.truth import truth_configuration

    skew = truth_configuration(0)["trailer_clock_skew"]
    assert abs(skew) > 0.005  # the default truth's is 11.8 ms: worth checking
    quiet = dataclasses.replace(SensorModel.ideal(), can_rate=10.0)  # noiseless, not ideal
    r = drive(scenario("straight"), VEHICLE, Spy, 0, sensors=quiet, truth=0)
    true = np.asarray(r.trace.true)
    t_plant = np.asarray(r.trace.t)
    seen = np.array([s[1] for s in Spy.seen])
    t = np.array([s[0] for s in Spy.seen])
    i_x2, i_x1 = OBS_INDEX["x_2"], OBS_INDEX["x_1"]
    assert seen[:, i_x1] == pytest.approx(np.interp(t, t_plant, true[:, i_x1]), abs=1e-9)
    assert seen[:, i_x2] == pytest.approx(np.interp(t - skew, t_plant, true[:, i_x2]), abs=1e-9)
    # Moving at about a metre a second, the lag is a centimetre: not the plant's now.
    assert np.abs(seen[:, i_x2] - true[np.round(t / PLANT_DT).astype(int), i_x2]).max() > 0.005


# ---------------------------------------------------------------- controllers by name
def test_controllers_load_by_name_or_module_and_class():
    from artic.validation.docking.controllers.reference import ReferenceController

    assert load("reference") is ReferenceController
    assert set(BUILTIN) >= {"reference"}
    with pytest.raises(ValueError, match="not a built-in controller"):
        load("nope")
    with pytest.raises(ValueError, match="cannot import 'no_such_module'"):
        load("no_such_module:X")
    with pytest.raises(ValueError, match="no class 'Missing'"):
        load("artic.validation.docking.run:Missing")


def test_a_user_controller_runs_through_the_command_line_and_is_scored(tmp_path, monkeypatch,
                                                                        capsys):
    from artic.validation.cli.commands import main

    (tmp_path / "my_docking.py").write_text(textwrap.dedent(USER_CONTROLLER))
    monkeypatch.syspath_prepend(str(tmp_path))
    out = tmp_path / "out"
    assert main(["dock", "--scenario", "straight", "--vehicle", VEHICLE, "--controller",
                 "my_docking:Proportional", "--seeds", "1", "--jobs", "1",
                 "--out-dir", str(out)]) == 0
    rows = pd.read_csv(out / "dock.csv")
    assert list(rows.columns) == list(COLUMNS)
    assert rows.loc[0, "controller"] == "my_docking:Proportional"
    assert bool(rows.loc[0, "success"])
    assert abs(rows.loc[0, "lateral_error_m"]) < 0.1
    md = (out / "dock_table.md").read_text()
    assert md.count("my_docking:Proportional") == 2  # the table and the compute times
    assert "Compute time per command, every run's commands pooled, in 1 process on " in md
    assert "1 of 1 runs docked" in capsys.readouterr().out
    assert (out / "dock_errors.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rrd = out / "recordings" / "straight-gosar2022-unloaded-my_docking_Proportional-0.rrd"
    assert rrd.is_file()


def test_a_docking_recording_holds_the_yard_the_plan_the_plant_and_the_scores(tmp_path):
    from artic.validation.review.recording import read_rows, read_text, read_views

    path = tmp_path / "run.rrd"
    r = drive(scenario("bay"), VEHICLE, Spy, 0, record=path)
    rows = read_rows(path)
    # The plant from its bodies at every controller sample, the signals, the yard.
    assert rows["/yard/mbd/tractor"] == len(r.trace.t_ctrl)
    assert rows["/signals/articulation"] > 0
    for static in ("/yard/dock", "/yard/neighbour-left-1", "/yard/neighbour-right-1",
                   "/yard/plan", "/yard/doors"):
        assert rows[static] == 0
    text = read_text(path, "/description")
    assert text.startswith("# bay, gosar2022-unloaded, ") and "failed: missed the door" in text
    assert "/yard" in read_views(path)
    # Spy intends nothing: it still records, without a horizon or a tracked plan.
    assert "/yard/horizon" not in rows and "/yard/plan/tracked" not in rows
    # What it saw, at every sample: the articulation and the rear point, and the path.
    assert rows["/signals/articulation/seen"] == rows["/yard/seen/rear"] == len(r.trace.t_ctrl)
    assert rows["/yard/seen/rear_path"] == 0


def test_a_docking_recording_draws_the_estimate_where_the_estimator_put_it(tmp_path):
    """With tractor-only sensing the recording's rear point is the estimate, not the plant."""
    from artic.validation.docking.geometry import Frames
    from artic.validation.docking.scores import rear_point
    from artic.validation.review.recording import read_column, read_times

    path = tmp_path / "run.rrd"
    r = drive(scenario("straight"), VEHICLE, "reference", 0, record=path, sensor_set="camera")
    points = np.array([p[0][:2] for p in read_column(path, "/yard/seen/rear",
                                                     "Points3D:positions")])
    assert read_times(path, "/yard/seen/rear") == pytest.approx(r.trace.t_ctrl, abs=1e-6)
    fr = Frames.of(load_vehicle(VEHICLE))
    seen = rear_point(fr, np.asarray(r.trace.measured))
    true = rear_point(fr, np.asarray(r.trace.true)[r.trace.seen_at])
    # Float32 in the file: millimetres at yard coordinates of tens of metres.
    assert points == pytest.approx(seen, abs=1e-3)
    # It is the estimate: off the plant's rear by the estimator's error, which
    # the run's row reports (RMS over the same samples).
    err = np.hypot(*(points - true).T)
    assert np.sqrt(np.mean(err ** 2)) == pytest.approx(r.row["rear_est_rms_m"], rel=1e-3)
    assert r.row["rear_est_rms_m"] > 0.01


def test_a_docking_recording_holds_what_the_controller_intended_at_every_sample(tmp_path):
    """The reference's horizon and the plan's points it tracks, one row per control step."""
    from artic.validation.review.recording import read_column, read_rows, read_times

    path = tmp_path / "run.rrd"
    r = drive(scenario("straight"), VEHICLE, "reference", 0, record=path)
    assert r.row["success"], r.row["failure"]
    t_ctrl = np.asarray(r.trace.t_ctrl)
    rows = read_rows(path)
    for entity in ("/yard/horizon", "/yard/plan/tracked", "/yard/plan/point"):
        assert rows[entity] == len(t_ctrl), entity
        # On the controller's clock: the recording's rows are its samples.
        assert read_times(path, entity) == pytest.approx(t_ctrl, abs=1e-6), entity
    # Moving, it gave both; standing at the end (done), no horizon, and the row is empty.
    strips = read_column(path, "/yard/horizon", "LineStrips3D:strips")
    given = [h is not None for h in r.trace.horizons]
    assert [len(x) > 0 for x in strips] == given
    assert sum(given) > 0.9 * len(given) and not given[-1]
    # The horizon starts at the tracked point (the semitrailer axle by its sensor)
    # and the tracked point sits on the plan: within the noise and the path's spacing.
    from artic.validation.docking.geometry import Frames

    fr = Frames.of(load_vehicle(VEHICLE))
    plan = np.concatenate([fr.trailer_axle(seg.states)[:, :2] for seg in r.plan.segments])
    for k in np.flatnonzero(given)[::25]:
        axle = fr.trailer_axle_of_signals(r.trace.measured[k])[:2]
        h, ref = r.trace.horizons[k], r.trace.references[k]
        assert h.shape == (ref.shape[0], 2) == (26, 2)
        # The start lies off the path by the tracked offset, along the path's normal.
        assert np.hypot(*(h[0] - axle)) < 0.02
        assert np.min(np.hypot(*(plan - ref[0]).T)) < 0.13


def test_the_reference_predicts_its_closed_loop_on_the_design_model():
    """``Ad - Bd K`` of the schedule: stable, exact at the table's speeds, laid off the path."""
    from artic.validation.docking.controllers import Task
    from artic.validation.docking.controllers.reference import ReferenceController
    from artic.validation.docking.linear import (
        discretise,
        trailer_error_model,
        with_steering_state,
    )
    from artic.validation.docking.planner import HybridAStar

    v = load_vehicle(VEHICLE)
    s = scenario("straight")
    yard = s.yard(v)
    c = ReferenceController()
    c.reset(Task(v, yard, HybridAStar().plan(yard, v, s.start(0)), DT, 1.1, 1.67, 0.5, 6.3))
    sched = c.schedule[-1]
    # At a table speed the interpolation is exact: the LQR's closed loop itself.
    speed = float(sched.speeds[10])
    Ad, Bd = discretise(*with_steering_state(*trailer_error_model(c.frames.kin, -1.0)),
                        speed * DT)
    assert sched.closed_loop(speed) == pytest.approx(Ad - Bd @ sched(speed)[None, :], abs=1e-12)
    # The designed loop is stable reversing and forward at every yard speed, and as
    # the design works in distance, its slowest mode decays by the same factor per
    # metre at every speed. Without the feedback, reversing is unstable (the
    # semitrailer jackknifes).
    for d in (-1, 1):
        per_metre = [np.log(max(abs(np.linalg.eigvals(c.schedule[d].closed_loop(u))))) / (u * DT)
                     for u in (0.3, 0.7, 1.1, 1.6)]
        assert max(per_metre) < 0.0
        assert per_metre == pytest.approx([per_metre[0]] * 4, rel=0.02)
    assert max(abs(np.linalg.eigvals(Ad))) > 1.0
    # An offset to the left of the path, errors otherwise zero: the horizon starts
    # that far to the left of the path's heading, and comes back towards it.
    d, p, _, _, s_ = c.refs[-1]
    here = float(s_[10])
    h = c._prediction(d, p, s_, here, np.array([0.3, 0.0, 0.0, 0.0]), 1.1)
    foot = np.array([np.interp(here, s_, p[:, 0]), np.interp(here, s_, p[:, 1])])
    psi = float(np.interp(here, s_, p[:, 2]))
    assert h[0] - foot == pytest.approx(0.3 * np.array([-np.sin(psi), np.cos(psi)]), abs=1e-9)
    ref = c._preview(p, s_, here, 1.1)
    off = np.hypot(*(h - ref).T)
    # It decays at the slowest mode's rate, about 5 m of travel, without
    # overshoot; reversing is non-minimum-phase, so it first moves the wrong way,
    # by less than a millimetre.
    assert off[0] == pytest.approx(0.3)
    assert off.max() - off[0] < 1e-3 and off[-1] < 0.6 * off[0]
    assert np.all(np.diff(off[np.argmax(off):]) <= 1e-9)
    # Standing, it predicts nothing and tracks one point.
    assert c._prediction(d, p, s_, here, np.zeros(4), 0.0) is None
    assert c._preview(p, s_, here, 0.0).shape == (1, 2)


def _projection(p: np.ndarray, s: np.ndarray, point: np.ndarray) -> float:
    """Arc length ``s`` of ``point``'s foot on the polyline ``p`` (its nearest point)."""
    a, b = p[:-1, :2], p[1:, :2]
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", point[:2] - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
    dist = np.hypot(*(a + t[:, None] * ab - point[:2]).T)
    j = int(np.argmin(dist))
    return float(s[j] + t[j] * (s[j + 1] - s[j]))


def test_the_reference_knows_how_far_along_the_path_it_is():
    """Its arc length along the segment is the foot of the tracked point, either direction."""
    from artic.validation.docking.controllers.reference import ReferenceController

    seen = []

    class Probe(ReferenceController):
        def _follow(self, obs):
            cmd = super()._follow(obs)
            if self.now is not None:
                d, p, s, here, _ = self.now
                seen.append((d, here, _projection(p, s, self._point(obs, d))))
            return cmd

    r = drive(scenario("alley"), VEHICLE, Probe, 0, sensors=SensorModel.ideal())
    assert r.row["success"], r.row["failure"]
    a = np.array(seen)
    assert set(a[:, 0]) == {-1.0, 1.0}
    # The path's samples are 0.25 m of tractor travel apart; the nearest one's
    # offset along the heading is added with the travel's sign. The foot and the
    # offset differ only by the path's curvature over half a sample: millimetres.
    assert np.abs(a[:, 1] - a[:, 2]).max() < 0.01


class BadHorizon(Controller):
    def command(self, obs):
        return Command(self.steering_wheel(0.0), -1.0, horizon=[[1.0, float("nan")]])


def test_a_malformed_horizon_is_a_failed_run_naming_the_field():
    r = drive(scenario("straight"), VEHICLE, BadHorizon, 0)
    assert r.row["failure"].startswith("controller error: UserError: Command.horizon must be "
                                       "finite rows (x, y)")


def test_dock_list_names_the_scenarios_and_controllers(capsys):
    from artic.validation.cli.commands import main

    assert main(["dock", "--list"]) == 0
    text = capsys.readouterr().out
    for name in [*SCENARIOS, *BUILTIN, "six-axle"]:
        assert name in text
    assert main(["dock", "--scenario", "parallel", "--out-dir", "x"]) == 2
    assert "no such scenario" in capsys.readouterr().err


def test_dock_list_aligns_a_long_controller_name(monkeypatch):
    from artic.validation.docking import command

    monkeypatch.setitem(BUILTIN, "proportional-long", ("m:C", "a controller with a long name"))
    lines = command.list_all().splitlines()
    i = lines.index("controllers (or package.module:Class):")
    rows = lines[i + 1:lines.index("vehicles (or a vehicle file):")]
    starts = {len(r) - len(r.split(None, 1)[1].lstrip()) for r in rows}
    assert len(rows) == len(BUILTIN) and len(starts) == 1, rows  # one column of descriptions
    for row, (name, (_, text)) in zip(rows, BUILTIN.items(), strict=True):
        assert row.split()[0] == name and row.endswith(f"  {text}"), row


# ---------------------------------------------------------------- the reference controller
def test_the_reference_controller_docks_a_straight_start():
    r = drive(scenario("straight"), VEHICLE, "reference", 0)
    row = r.row
    assert row["success"], row["failure"]
    assert abs(row["lateral_error_m"]) <= 0.10
    assert abs(row["heading_error_deg"]) <= 1.0
    assert abs(row["longitudinal_error_m"]) <= 0.05
    assert row["direction_changes"] == 0
    # Reversing nearly straight, the semitrailer sweeps little more than its own width.
    assert 2.55 <= row["swept_width_m"] < 3.2


def _docks(name: str, vehicle: str, seeds: range) -> None:
    for seed in seeds:
        row = drive(scenario(name), vehicle, "reference", seed).row
        assert row["success"], (name, vehicle, seed, row["failure"])
        assert abs(row["lateral_error_m"]) <= 0.10
        assert abs(row["heading_error_deg"]) <= 1.0
        assert row["gamma_margin_deg"] > 0.0


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_each_scenario_docks_with_the_reference_controller(name):
    """A short start distribution per scenario: the issue's bar on each start."""
    _docks(name, VEHICLE, range(2))


@pytest.mark.slow
@pytest.mark.parametrize("vehicle", ["gosar2022-loaded", "six-axle"])
@pytest.mark.parametrize("name", list(SCENARIOS))
def test_each_scenario_docks_the_other_presets(name, vehicle):
    _docks(name, vehicle, range(2, 5))


# ---------------------------------------------------------------- statistics
def test_the_success_interval_is_wilsons():
    iv = rate_ci(9, 10)
    assert iv.mean == 0.9 and iv.n == 10
    # Wilson's 95 % interval for 9 of 10: 0.596 to 0.982.
    assert (iv.lo, iv.hi) == pytest.approx((0.596, 0.982), abs=1e-3)
    # Ten of ten still has an interval below one.
    assert rate_ci(10, 10).lo == pytest.approx(0.722, abs=1e-3)
    assert format_ci(rate_ci(10, 10)) == "1.0 [0.7, 1.0]"


def test_compute_times_pool_every_runs_commands():
    """The pooled 99th percentile is over all commands, not the worst run's own."""
    from artic.validation.docking.scores import compute_times

    rows = [{"controller": "a", "solve_ms": np.r_[np.ones(99), 50.0]},
            {"controller": "a", "solve_ms": np.full(100, 2.0)},
            {"controller": "b", "solve_ms": np.array([3.0])}]
    t = compute_times(rows)
    assert list(t["controller"]) == ["a", "b"] and list(t["commands"]) == [200, 1]
    a = t.iloc[0]
    # 200 commands: 99 of 1 ms, 100 of 2 ms and one of 50: the median and the 99th
    # percentile are 2 ms (the one slow command in 200 lies beyond the 99th; in the
    # first run's 100 alone it would pull its 99th percentile to 1.5 ms), the largest 50.
    assert (a["p50 [ms]"], a["p99 [ms]"], a["max [ms]"]) == ("2", "2", "50")
    assert np.percentile(rows[0]["solve_ms"], 99) == pytest.approx(1.49)


def test_the_table_has_a_row_per_scenario_vehicle_and_controller():
    rows = pd.DataFrame([{c: 0.0 for c in COLUMNS} | {
        "scenario": s, "vehicle": "v", "controller": "c", "seed": k, "success": k != 0,
        "failure": "jackknife: x" if k == 0 else "", "lateral_error_m": 0.01 * k}
        for s in ("straight", "alley") for k in range(4)])
    t = table(rows)
    assert list(t["scenario"]) == ["straight", "alley"]
    assert list(t["docked"]) == [3, 3] and list(t["jackknifes"]) == [1, 1]
    assert "| straight | v | c | 4 | 3 |" in markdown(t)


def test_with_truth_the_controller_drives_the_synthetic_truth():
    from artic.validation.docking.run import truth_yard

    nominal = load_vehicle(VEHICLE)
    vt, _ = truth_yard(nominal, 0, 1, 0)
    # The truth is another vehicle: its steering map differs from the file's.
    assert vt.steering_for("mbd") != nominal.steering_for("mbd")
    r = drive(scenario("straight"), VEHICLE, Spy, 0, truth=0)
    assert r.row["plant"] == "truth-0"
    assert r.row["failure"].startswith("missed the door")  # Spy stops after 2 s
    # It moved: the pedal driver followed the speed asked for.
    assert np.abs(np.asarray(r.trace.true)[:, OBS_INDEX["v_x_1"]]).max() > 0.3
    with pytest.raises(ValueError, match="gosar2022-unloaded and gosar2022-loaded only"):
        truth_yard(load_vehicle("six-axle"), 0, 1, 0)
