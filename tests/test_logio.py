"""Logs: lossless round trip, atomic writes and clear errors on bad input."""

from __future__ import annotations

import numpy as np
import pytest

from artic.validation.logs.runfile import (
    LogError,
    Run,
    atomic_write,
    check_frame,
    read_run,
    write_run,
)
from tests.helpers import straight_log


def good_log() -> Run:
    run = straight_log(n=300, u=1.2)
    run.frame["r_1"] = run.frame["r_2"] = 0.01 * np.sin(np.arange(300) / 30)
    run.meta.update(manoeuvre="constant-steer", load="unloaded", sensors=[[1, 2, 3]])
    return run


def test_round_trip_is_lossless(tmp_path):
    run = good_log()
    p = write_run(run, tmp_path / "a" / "run.parquet")
    back = read_run(p)
    assert back.frame.equals(run.frame)
    assert back.meta == {**run.meta, "sensors": [[1, 2, 3]], "name": "run"}
    assert not list((tmp_path / "a").glob("*.part"))


def test_metadata_only_run_files_are_the_same_bytes_from_the_kept_schema(tmp_path):
    # write_run keeps the Arrow schema of each empty frame's columns and dtypes; a
    # file written from the kept schema must be the file a fresh conversion writes,
    # and a frame whose dtypes differ must not take another frame's schema.
    from artic.validation.logs import runfile

    run = good_log()
    run.frame["flag"] = run.frame["t"] > 1.0  # a bool column beside the floats
    empty = Run(run.frame.iloc[:0], run.meta)
    runfile._EMPTY_SCHEMAS.clear()
    fresh = write_run(empty, tmp_path / "fresh.parquet", single=("x_1", "psi_1")).read_bytes()
    assert len(runfile._EMPTY_SCHEMAS) == 1
    kept = write_run(empty, tmp_path / "kept.parquet", single=("x_1", "psi_1")).read_bytes()
    assert kept == fresh
    back = read_run(tmp_path / "kept.parquet", check=False).frame
    assert list(back.columns) == list(run.frame.columns) and len(back) == 0
    assert back["flag"].dtype == bool
    # Another single set is another schema: x_1 stays float64 there.
    other = write_run(empty, tmp_path / "other.parquet", single=("psi_1",))
    assert len(runfile._EMPTY_SCHEMAS) == 2 and other.read_bytes() != fresh
    import pyarrow.parquet as pq

    assert str(pq.read_schema(other).field("x_1").type) == "double"
    assert str(pq.read_schema(tmp_path / "kept.parquet").field("x_1").type) == "float"


def test_truncated_file(tmp_path):
    p = write_run(good_log(), tmp_path / "run.parquet")
    p.write_bytes(p.read_bytes()[: p.stat().st_size // 2])
    with pytest.raises(LogError, match="truncated") as err:
        read_run(p)
    assert str(p) in str(err.value)


@pytest.mark.parametrize("edit,words", [
    (lambda df: df.drop(columns=["r_2"]), "missing column(s) r_2"),
    (lambda df: df.assign(v_y_1=df.v_y_1.where(df.index != 40)), "column v_y_1: 1 NaN"),
    (lambda df: df.assign(t=df.t.where(df.index != 50, 0.2)), "column t: time does not increase"),
    (lambda df: df.assign(r_1=np.degrees(df.r_1 + 0.1)), "column r_1"),
    (lambda df: df.assign(gamma=-df.gamma + 0.2), "column gamma"),
    (lambda df: df.iloc[:1], "1 sample(s)"),
    (lambda df: df.assign(v_x_1=df.v_x_1 * 3.6 * 5), "km/h read as m/s"),
])
def test_bad_input_names_column(tmp_path, edit, words):
    run = good_log()
    run.frame = edit(run.frame)
    p = write_run(run, tmp_path / "bad.parquet")
    with pytest.raises(LogError) as err:
        read_run(p)
    assert words in str(err.value) and str(p) in str(err.value), str(err.value)
    # Nothing was lost: the file is as written, readable unchecked.
    assert len(read_run(p, check=False).frame) == len(run.frame)


def test_degrees_per_second_named():
    run = good_log()
    run.frame["r_1"] = np.degrees(run.frame["r_1"] + 0.1)
    with pytest.raises(LogError, match="deg/s read as rad/s"):
        check_frame(run.frame, "x")


def test_atomic_write_keeps_old_file_on_failure(tmp_path):
    p = tmp_path / "out.txt"
    p.write_text("old")

    def broken(tmp):
        tmp.write_text("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        atomic_write(p, broken)
    assert p.read_text() == "old"
    assert list(tmp_path.iterdir()) == [p]
