"""Importers: OXTS-style CSVs, CAN, .mat; repairs reported, bad input refused."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from artic.mjcf import load_vehicle
from artic.reduced import STM
from artic.validation.cli.commands import main
from artic.validation.harness.simulate import simulate
from artic.validation.logs.importers import import_source
from artic.validation.logs.oxts import export_mat, export_oxts, import_oxts, import_tables
from artic.validation.logs.runfile import LogError, Run, check_frame, read_run
from artic.validation.logs.schema import COLUMNS
from artic.validation.synthetic.manoeuvres import make_profile


@pytest.fixture(scope="module")
def canonical():
    """A 30 s slalom whose steering wheel is already CAN-like: 10 Hz, 0.1 deg steps."""
    v = load_vehicle("gosar2022-unloaded")
    s = v.steering_for("stm")
    prof = make_profile("slalom", amplitude_deg=200, speed_kph=5, duration=30.0,
                        delta_h_offset=s.delta_h_offset, L1=v.L1, i_s=s.i_s)
    held = np.radians(np.round(np.degrees(prof.delta_h[::10]) / 0.1) * 0.1)
    prof = type(prof)(prof.kind, prof.t, np.repeat(held, 10)[:prof.t.size], prof.u1, prof.meta)
    run = simulate(STM(v), v, prof)
    return Run(run.frame[list(COLUMNS)].copy(), {"name": "slalom"})


@pytest.fixture()
def export(canonical, tmp_path):
    export_oxts(canonical, tmp_path)
    return {n: pd.read_csv(tmp_path / f"{n}.csv") for n in ("tractor", "trailer", "can")}


def imported(tables):
    return import_tables(tables["tractor"], tables["trailer"], tables["can"],
                         sources=("tractor.csv", "trailer.csv", "can.csv"))


# Half the export's rounding step, per channel (what a round trip may lose).
PRECISION = {"x": 6e-6, "y": 6e-6, "psi": 9e-8, "v_x": 5.1e-6, "v_y": 5.1e-6, "r": 9e-8}


def test_round_trip_within_export_precision(canonical, tmp_path):
    export_oxts(canonical, tmp_path)
    back, report = import_oxts(tmp_path / "tractor.csv", tmp_path / "trailer.csv",
                               tmp_path / "can.csv")
    assert report == []
    a, b = canonical.frame, back.frame
    assert len(b) == len(a)
    for c in COLUMNS:
        tol = PRECISION.get(c.rsplit("_", 1)[0] if c[-1] in "12" else c, 1e-9)
        if c == "gamma":
            tol = 2 * PRECISION["psi"]
        np.testing.assert_allclose(b[c], a[c], atol=tol, rtol=0, err_msg=c)


def test_mat_round_trip(canonical, tmp_path):
    export_mat(canonical, tmp_path / "run.mat")
    run, _ = import_source(tmp_path / "run.mat")
    np.testing.assert_allclose(run.frame["x_2"], canonical.frame["x_2"], atol=6e-6)
    assert run.name == "run"


def test_missing_channel(export):
    export["trailer"] = export["trailer"].drop(columns=["AngRateZ"])
    with pytest.raises(LogError, match="trailer.csv: missing channel yaw_rate: expected a "
                                       "column named AngRateZ"):
        imported(export)


def test_short_nan_run_is_repaired_and_reported(export):
    export["tractor"].loc[100:104, "VelForward"] = np.nan
    run, report = imported(export)
    assert any("VelForward: interpolated 5 missing value(s) in 1 run(s)" in r for r in report)
    check_frame(run.frame)


def test_long_nan_run_is_refused(export):
    export["tractor"].loc[100:130, "AngleHeading"] = np.nan
    with pytest.raises(LogError, match="AngleHeading: 31 missing value"):
        imported(export)


def test_exact_duplicates_dropped_and_reported(export):
    t = export["trailer"]
    export["trailer"] = pd.concat([t.iloc[:50], t.iloc[49:50], t.iloc[50:]], ignore_index=True)
    run, report = imported(export)
    assert any("dropped 1 exact duplicate" in r for r in report)
    assert len(run.frame) == len(t)


def test_conflicting_duplicates_refused(export):
    t = export["trailer"]
    dup = t.iloc[49:50].copy()
    dup["VelForward"] += 1.0
    export["trailer"] = pd.concat([t.iloc[:50], dup, t.iloc[50:]], ignore_index=True)
    with pytest.raises(LogError, match="repeated time stamp"):
        imported(export)


def test_backward_time_refused(export):
    t = export["tractor"]
    export["tractor"] = pd.concat([t.iloc[:200], t.iloc[150:]], ignore_index=True)
    with pytest.raises(LogError, match="time goes back at row 200"):
        imported(export)


def test_gap_refused(export):
    export["tractor"] = export["tractor"].drop(index=range(300, 320)).reset_index(drop=True)
    with pytest.raises(LogError, match=r"tractor.csv: channel Time: 0\.210 s without samples"):
        imported(export)


def test_gnss_jump_refused(export):
    export["trailer"].loc[1000:, "PosLat"] += 2.0 / 111_000  # 2 m north, from t = 10 s
    with pytest.raises(LogError, match=r"trailer.csv: position jumps 2\.0. m at t = 10"):
        imported(export)


def test_yaw_rate_in_wrong_unit_refused(export):
    # The export's yaw rate in rad/s where deg/s is expected: the slalom's own
    # heading changes judge it; the message gives the ratio, never "0.0 times".
    export["tractor"]["AngRateZ"] = np.radians(export["tractor"]["AngRateZ"])
    with pytest.raises(LogError) as err:
        imported(export)
    msg = str(err.value)
    assert "tractor.csv: AngRateZ looks like rad/s where deg/s is expected" in msg, msg
    assert "1/57.3 times the change of psi_1" in msg and "0.0 times" not in msg
    assert "--accept yaw-rate" in msg


def test_heading_wraps_through_north(canonical, tmp_path):
    # Heading 358 deg -> 2 deg is a 4 deg turn, not -356 deg.
    # The whole run turned about the origin so that it starts heading 1 deg west of north.
    run = Run(canonical.frame.copy(), {})
    turn = math.pi / 2 - run.frame["psi_1"].iloc[0] + math.radians(1.0)
    c, s = math.cos(turn), math.sin(turn)
    for i in (1, 2):
        x, y = run.frame[f"x_{i}"].copy(), run.frame[f"y_{i}"].copy()
        run.frame[f"x_{i}"], run.frame[f"y_{i}"] = c * x - s * y, s * x + c * y
        run.frame[f"psi_{i}"] += turn
    export_oxts(run, tmp_path)
    heading = pd.read_csv(tmp_path / "tractor.csv")["AngleHeading"]
    assert heading.max() > 350 and heading.min() < 10
    back, _ = import_oxts(tmp_path / "tractor.csv", tmp_path / "trailer.csv",
                          tmp_path / "can.csv")
    assert np.max(np.abs(np.diff(back.frame["psi_1"]))) < 0.01


def test_cli_imports_folder_and_mat(canonical, tmp_path, capsys):
    export_oxts(canonical, tmp_path / "run1")
    export_mat(canonical, tmp_path / "run2.mat")
    out = tmp_path / "out"
    assert main(["logs", "import", str(tmp_path / "run1"), str(tmp_path / "run2.mat"),
                 "--out-dir", str(out)]) == 0
    assert read_run(out / "run1.parquet").meta["source"] == "measured"
    assert len(read_run(out / "run2.parquet").frame) == len(canonical.frame)
    assert main(["logs", "import", str(tmp_path / "nothing.txt"), "--out-dir", str(out)]) == 2
    assert "nothing.txt: no such file or folder" in capsys.readouterr().err
    (tmp_path / "notes.txt").write_text("a note, not a log")
    assert main(["logs", "import", str(tmp_path / "notes.txt"), "--out-dir", str(out)]) == 2
    assert "notes.txt: not a log" in capsys.readouterr().err


def test_an_export_given_where_a_canonical_log_is_read_says_import_it(canonical, tmp_path,
                                                                       capsys):
    # validate, tune and artic.read_log read canonical logs; an export folder or
    # CSV is one line naming the import that makes one, for the library and the CLI.
    import artic

    export_oxts(canonical, tmp_path / "run1")
    canonical.frame.to_csv(tmp_path / "rev.csv", index=False)
    for src, name in ((tmp_path / "run1", "run1"), (tmp_path / "rev.csv", "rev")):
        with pytest.raises(LogError) as err:
            artic.read_log(src)
        line = str(err.value)
        assert "\n" not in line and line.startswith(f"{src}: not a canonical log (.parquet)")
        assert f"artic logs import {src} --out-dir DIR" in line
        assert f"DIR/{name}.parquet" in line
        assert main(["validate", str(src), "--models", "kin", "--out-dir",
                     str(tmp_path / "val")]) == 2
        assert f"artic logs import {src} --out-dir DIR" in capsys.readouterr().err
    # What the line says works: the import's file reads back.
    assert main(["logs", "import", str(tmp_path / "run1"), "--out-dir", str(tmp_path)]) == 0
    assert len(artic.read_log(tmp_path / "run1.parquet").frame) == len(canonical.frame)


MUTATIONS = st.lists(st.tuples(
    st.sampled_from(["drop_col", "nan", "dup", "swap", "scale", "gap", "shift", "jump"]),
    st.integers(0, 2), st.integers(1, 2900), st.integers(1, 40),
    st.sampled_from(["Time", "PosLat", "PosLon", "AngleHeading", "VelForward", "VelLateral",
                     "AngRateZ", "SteeringWheelAngle"])), min_size=1, max_size=3)


@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(mutations=MUTATIONS)
def test_importer_never_returns_a_broken_log(canonical, mutations):
    # Random damage to the raw tables: the importer either refuses with a
    # LogError, or returns a log that passes every canonical check.
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        export_oxts(canonical, Path(tmp))
        tables = [pd.read_csv(Path(tmp) / f"{n}.csv") for n in ("tractor", "trailer", "can")]
    for kind, which, row, n, col in mutations:
        df = tables[which]
        cols = [c for c in df.columns if c != col] if kind == "drop_col" else None
        row = min(row, len(df) - 2)
        if kind == "drop_col" and col in df.columns:
            tables[which] = df[cols]
        elif col not in df.columns:
            continue
        elif kind == "nan":
            df.loc[row:row + n, col] = np.nan
        elif kind == "dup":
            tables[which] = pd.concat([df.iloc[:row], df.iloc[row - 1:row], df.iloc[row:]],
                                      ignore_index=True)
        elif kind == "swap":
            df.loc[[row, row + 1], "Time"] = df.loc[[row + 1, row], "Time"].to_numpy()
        elif kind == "scale":
            df[col] = df[col] * 57.3
        elif kind == "gap":
            tables[which] = df.drop(index=range(row, min(row + n, len(df) - 1))).reset_index(
                drop=True)
        elif kind == "shift":
            df["Time"] = df["Time"] + n
        elif kind == "jump":
            df.loc[row:, col] = df.loc[row:, col] + n * 1e-4
    try:
        run, report = import_tables(*tables, sources=("tractor", "trailer", "can"))
    except LogError as exc:
        assert str(exc)
        return
    check_frame(run.frame, "imported")
    assert isinstance(report, list)
