"""Docking runs on the plant: failures are rows, controllers see only the sensors, scores."""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pandas as pd
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.interface import OBS_INDEX
from artic.validation.criteria.statistics import format_ci
from artic.validation.docking.controllers import BUILTIN, Command, Controller, load
from artic.validation.docking.planner import steady_delta
from artic.validation.docking.run import DT, PLANT_DT, drive
from artic.validation.docking.scenarios import SCENARIOS, scenario
from artic.validation.docking.scores import COLUMNS, markdown, paired, rate_ci, table
from artic.validation.docking.sensing import SensorStream
from artic.validation.synthetic.sensors import SensorModel

VEHICLE = "gosar2022-unloaded"

USER_CONTROLLER = '''
from artic.validation.docking.controllers import Command, Controller
from artic.validation.docking.planner import steady_delta


class Proportional(Controller):
    """Reverse onto the door's line: offset -> semitrailer heading -> articulation -> steering."""

    def command(self, obs):
        dist, e_y, e_psi = self.dock_errors(obs)
        if dist < 0.05:
            return Command(self.steering_wheel(0.0), 0.0, done=True)
        psi_ref = max(-0.4, min(0.4, 0.15 * e_y))                 # aim at the line
        gamma_ref = max(-0.6, min(0.6, 1.5 * (e_psi - psi_ref)))  # swing the semitrailer
        delta = steady_delta(gamma_ref, self.frames.P) + 3.0 * (obs["gamma"] - gamma_ref)
        return Command(self.steering_wheel(delta), -min(1.1, 0.15 + 0.3 * dist))
'''


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
    _, dh = stream.observe(3, np.zeros(13), wheel)
    # Now is sample 30; the bus sampled at 30 the value of 50 ms before: 25 deg.
    assert math.degrees(dh) == pytest.approx(25.0)
    # Its noise is the campaign's: a Gauss-Markov position error of about 1 cm.
    big = SensorStream(SensorModel(), np.random.default_rng(1), 20000, DT, PLANT_DT)
    assert np.std(big.noise[:, 0]) == pytest.approx(0.01, rel=0.3)


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
    assert (out / "dock_table.md").read_text().count("my_docking:Proportional") == 1
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


def test_dock_list_names_the_scenarios_and_controllers(capsys):
    from artic.validation.cli.commands import main

    assert main(["dock", "--list"]) == 0
    text = capsys.readouterr().out
    for name in [*SCENARIOS, *BUILTIN, "six-axle"]:
        assert name in text
    assert main(["dock", "--scenario", "parallel", "--out-dir", "x"]) == 2
    assert "no such scenario" in capsys.readouterr().err


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


def test_paired_differences_resolve_only_when_the_interval_excludes_zero():
    rows = []
    for seed in range(10):
        for c, err in (("a", 0.05 + 0.001 * seed), ("b", 0.02 + 0.001 * seed)):
            rows.append({"scenario": "s", "vehicle": "v", "controller": c, "seed": seed,
                         "success": True, "lateral_error_m": err})
    df = pd.DataFrame(rows)
    p = paired(df, "a", "b", "lateral_error_m")
    assert p["pairs"] == 10 and p["resolved"]
    assert p["mean_difference"] == pytest.approx(0.03)
    same = paired(df, "a", "a", "lateral_error_m")
    assert not same["resolved"]


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
