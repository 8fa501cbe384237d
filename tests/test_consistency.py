"""Consistency checks: unit and sign mistakes that pass every structural check are refused.

Each trigger of the reliability review, on measured-looking logs (the
single-track model through the campaign's sensor models): the refusal names
the file, the channel, a time window and the likely cause; ``--accept`` lets
the log through and records it; clean logs pass untouched.
"""

from __future__ import annotations

import re
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.interface import wrap_angle
from artic.validation.cli.commands import main
from artic.validation.logs import consistency
from artic.validation.logs.importers import import_source, read_log
from artic.validation.logs.oxts import export_oxts, import_tables
from artic.validation.logs.runfile import LogError, Run, check_frame, read_run, write_run
from tests.hostile_logs import docking, slalom

WINDOW = r"t = \d+\.\d\d to \d+\.\d\d s"


def refused(frame: pd.DataFrame, **kw) -> str:
    check_frame(frame, "log.parquet")  # structurally sound: only the physics can tell
    with pytest.raises(LogError) as err:
        consistency.check_log(frame, "log.parquet", **kw)
    msg = str(err.value)
    assert msg.startswith("log.parquet: channel ") and "\n" not in msg
    return msg


def export_tables(run: Run) -> dict[str, pd.DataFrame]:
    with tempfile.TemporaryDirectory() as tmp:
        export_oxts(run, Path(tmp))
        return {n: pd.read_csv(Path(tmp) / f"{n}.csv") for n in ("tractor", "trailer", "can")}


def import_refused(tables: dict[str, pd.DataFrame]) -> str:
    with pytest.raises(LogError) as err:
        import_tables(tables["tractor"], tables["trailer"], tables["can"],
                      sources=("tractor.csv", "trailer.csv", "can.csv"))
    return str(err.value)


@pytest.mark.parametrize("make", [slalom, docking])
def test_clean_measured_logs_pass(make):
    run = make()
    assert list(consistency.findings(run.frame, load_vehicle("gosar2022-unloaded"))) == []
    # And through the export and back: the importer runs the same checks.
    t = export_tables(run)
    back, _ = import_tables(t["tractor"], t["trailer"], t["can"], ("a", "b", "c"))
    assert "accepted_checks" not in back.meta


@pytest.mark.parametrize("make", [slalom, docking])
def test_velocity_sign_flip_refused(make):
    f = make().frame
    f[["v_x_1", "v_y_1", "v_x_2", "v_y_2"]] *= -1.0
    msg = refused(f)
    assert "channel v_x_1, v_y_1" in msg and "sign is flipped" in msg
    assert "pointing backwards" in msg and "--accept velocity" in msg


@pytest.mark.parametrize("make", [slalom, docking])
def test_velocity_in_kph_refused(make):
    f = make().frame
    f[["v_x_1", "v_y_1", "v_x_2", "v_y_2"]] *= 3.6
    msg = refused(f)
    assert "velocity looks like km/h" in msg and "3.6 times the track's length" in msg
    # The export's VelForward in km/h: named by its file and column.
    t = export_tables(make())
    t["tractor"][["VelForward", "VelLateral"]] *= 3.6
    assert "channel tractor.csv: VelForward" in import_refused(t)


def test_yaw_rate_sign_flip_on_docking_refused():
    f = docking().frame
    assert np.ptp(f["psi_1"]) < 0.35  # docking turns less than the old check's 0.2 rad...
    f["r_1"] *= -1.0
    msg = refused(f)
    assert "channel r_1" in msg and "r_1 sign is flipped" in msg
    assert re.search(r"integral of r_1 is -(1|0\.99\d) times the change of psi_1", msg)
    t = export_tables(docking())
    t["tractor"]["AngRateZ"] *= -1.0
    assert "AngRateZ sign is flipped (about z down)" in import_refused(t)


def test_yaw_rate_in_rad_per_s_on_docking_refused():
    # The export's AngRateZ in rad/s where deg/s is expected: 1/57.3 of the heading change.
    t = export_tables(docking())
    t["tractor"]["AngRateZ"] = np.radians(t["tractor"]["AngRateZ"])
    msg = import_refused(t)
    assert "tractor.csv: AngRateZ looks like rad/s where deg/s is expected" in msg
    assert "1/57" in msg and "0.0 times" not in msg and "--accept yaw-rate" in msg
    assert "tractor.csv (imported): channel tractor.csv: AngRateZ" in msg


@pytest.mark.parametrize("make", [slalom, docking])
def test_heading_in_radians_refused(make):
    t = export_tables(make())
    t["tractor"]["AngleHeading"] = np.radians(t["tractor"]["AngleHeading"])
    msg = import_refused(t)
    assert "AngleHeading looks like radians where degrees are expected" in msg
    # A canonical log with its heading in degrees (gamma recomputed from it).
    f = make().frame
    f["psi_1"], f["psi_2"] = np.degrees(f["psi_1"]), np.degrees(f["psi_2"])
    f["gamma"] = wrap_angle(f["psi_1"].to_numpy() - f["psi_2"].to_numpy())
    assert "psi_1 looks like degrees where radians are expected" in refused(f)


@pytest.mark.parametrize("make", [slalom, docking])
def test_steering_wheel_in_radians_refused(make):
    t = export_tables(make())
    t["can"]["SteeringWheelAngle"] = np.radians(t["can"]["SteeringWheelAngle"])
    msg = import_refused(t)
    assert "channel can.csv: SteeringWheelAngle" in msg
    assert "SteeringWheelAngle looks like radians where degrees are expected" in msg
    f = make().frame
    f["delta_h"] *= -1.0
    assert "delta_h sign is flipped (left positive)" in refused(f)


@pytest.mark.parametrize("make", [slalom, docking])
def test_swapped_latitude_and_longitude_refused(make):
    t = export_tables(make())
    for unit in ("tractor", "trailer"):
        t[unit][["PosLat", "PosLon"]] = t[unit][["PosLon", "PosLat"]].to_numpy()
    msg = import_refused(t)
    assert "channel tractor.csv: PosLat/PosLon" in msg
    assert "latitude and longitude (or x and y) swapped" in msg


def test_trailer_off_the_hitch_refused():
    # The semitrailer's channels three seconds late: each unit consistent in itself,
    # gamma recomputed, but no single hitch point fits both.
    f = slalom().frame
    trailer = ["x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2"]
    f[trailer] = f[trailer].shift(300).bfill()
    f["gamma"] = wrap_angle(f["psi_1"].to_numpy() - f["psi_2"].to_numpy())
    msg = refused(f)
    assert "channel x_2, y_2, psi_2 against x_1, y_1, psi_1" in msg
    assert "put it" in msg and "--accept hitch" in msg


def test_wrong_vehicle_for_the_log_refused():
    # The six-axle's sensors sit where gosar2022's do, but a log whose tractor sensor
    # is 2 m further back than the vehicle file says does not fit it.
    f = slalom().frame
    f["x_1"] -= 2.0 * np.cos(f["psi_1"])
    f["y_1"] -= 2.0 * np.sin(f["psi_1"])
    v = load_vehicle("gosar2022-unloaded")
    hitch = consistency.check_hitch(f["t"].to_numpy(), f, v, consistency.CANONICAL)
    assert hitch is not None and "not where gosar2022-unloaded's file puts them" in hitch.cause
    # Without a vehicle the hitch is fitted, and a shifted sensor is a different, sound one.
    assert consistency.check_hitch(f["t"].to_numpy(), f, None, consistency.CANONICAL) is None


def test_gap_in_a_canonical_log_refused(tmp_path):
    # 1e5 s without samples: refused by import, validate and tune alike.
    run = slalom()
    run.frame.loc[1500:, "t"] += 1e5
    p = write_run(run, tmp_path / "gap.parquet")
    with pytest.raises(LogError, match=rf"gap.parquet: channel t, {WINDOW}: 1e\+05 s without "
                                       "samples"):
        import_source(p)
    csv = tmp_path / "gap.csv"
    run.frame.to_csv(csv, index=False)
    with pytest.raises(LogError, match="without samples"):
        import_source(csv)
    # tune no longer writes a tuned vehicle file from it (eps_p was 3e26 m).
    out = tmp_path / "tuned.toml"
    assert main(["tune", str(p), "--models", "kin", "--out", str(out)]) == 2
    assert not out.exists()


def test_accept_records_the_override(tmp_path):
    run = docking()
    run.frame["r_1"] *= -1.0
    p = write_run(run, tmp_path / "flipped.parquet")
    with pytest.raises(LogError, match="--accept yaw-rate"):
        read_log(p)
    back = read_log(p, accept=("yaw-rate",))
    assert len(back.meta["accepted_checks"]) == 1
    assert back.meta["accepted_checks"][0].startswith("accepted yaw-rate: ")
    with pytest.raises(ValueError,
                       match="unknown check; the checks are gap, yaw-rate, turning, axes"):
        consistency.parse_accept(["yaw-rate,nonsense"])


def test_cli_refuses_and_accepts_with_the_record(tmp_path, capsys):
    run = slalom()
    run.frame[["v_x_1", "v_y_1", "v_x_2", "v_y_2"]] *= 3.6
    p = write_run(run, tmp_path / "kph.parquet")
    out = tmp_path / "val"
    assert main(["validate", str(p), "--models", "kin", "--out-dir", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "looks like km/h" in err[0] and str(p) in err[0]
    assert not (out / "metrics.csv").exists()
    assert main(["validate", str(p), "--models", "kin", "--out-dir", str(out),
                 "--accept", "velocity"]) == 0, capsys.readouterr().err
    kin = read_run(out / "runs" / "kph.kin.parquet")
    assert kin.meta["accepted_checks"][0].startswith("accepted velocity: ")
    # logs import takes --accept too, and writes the record into the log.
    assert main(["logs", "import", str(p), "--out-dir", str(tmp_path / "imp"),
                 "--accept", "velocity"]) == 0
    assert "accepted velocity" in capsys.readouterr().out
    assert read_run(tmp_path / "imp" / "kph.parquet").meta["accepted_checks"]


def test_a_straight_run_has_no_heading_change_to_judge():
    # Straight driving with sensor noise: the yaw rate's sign cannot be told, and
    # nothing is refused for it (the noise floor), whichever sign it has.
    from artic.validation.synthetic.sensors import measure
    from tests.helpers import straight_log

    f = measure(straight_log(n=3000, u=2.0).frame, np.random.default_rng(3))
    for sign in (1.0, -1.0):
        g = f.assign(r_1=sign * f["r_1"])
        assert list(consistency.findings(g)) == []


def test_explain_names_the_known_mistakes():
    ctx = consistency.CANONICAL
    assert consistency.explain(-1.0, "r_1", ctx) == ("r_1 sign is flipped "
                                                     "(counter-clockwise positive)")
    assert consistency.explain(57.3, "r_1", ctx).endswith("deg/s where rad/s is expected")
    assert consistency.explain(3.6, "v_x_1", ctx).endswith("km/h where m/s is expected")
    assert consistency.explain(2.0, "v_x_1", ctx, known_only=True) == ""
    assert consistency._ratio(1 / 57.3) == "1/57.3" and consistency._ratio(-1.0) == "-1"


def test_an_articulation_offset_is_found_where_both_headings_are_measured():
    # A 10 deg articulation offset was accepted (issue 46, item 6): gamma must be psi_1 - psi_2
    # less the sensors' mounting yaws, to within the sensors' noise.
    import math

    frame = slalom().frame.copy()
    assert consistency.check_articulation_offset(frame["t"].to_numpy(), frame, None,
                                                 consistency.CANONICAL) is None
    rng = np.random.default_rng(0)  # a rear camera's 1.25 deg RMS is no offset
    noisy = frame.assign(gamma=frame["gamma"] + rng.normal(0.0, math.radians(1.25), len(frame)))
    assert consistency.check_articulation_offset(noisy["t"].to_numpy(), noisy, None,
                                                 consistency.CANONICAL) is None
    off = frame.assign(gamma=frame["gamma"] + math.radians(10.0))
    f = consistency.check_articulation_offset(off["t"].to_numpy(), off, None,
                                              consistency.CANONICAL)
    assert f is not None and f.check == "articulation"
    assert "differs from the headings' difference psi_1 - psi_2 by 10 deg" in f.problem
    assert "has an offset" in f.cause
    found = [x.check for x in consistency.findings(off)]
    assert found == ["articulation"], found
