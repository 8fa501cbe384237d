"""What the campaign writes: small files that keep what the criteria and a reviewer need.

Logs are stored losslessly (zstd over the byte-split floats, the metadata
once), and the campaign keeps none: it imports its exports in memory. Model
runs, the plant's too, in single precision but the time, after their criteria
were computed in double; the floor's, the noise-free twins' and the runs
against the plant as their metadata only; the exports' tables
gzip-compressed, a twin's export without the truth's records its log holds.
A default campaign wrote 804 MB, then 245 MB, and now 146 MB (seed 0).
"""

from __future__ import annotations

import math
import os

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from artic.validation.criteria.metrics import run_metrics
from artic.validation.logs.importers import import_source
from artic.validation.logs.oxts import export_oxts
from artic.validation.logs.runfile import Run, read_run, write_run
from artic.validation.runs.validate import SINGLE, validate_runs
from tests.hostile_logs import docking, slalom

# The campaign's tables print three significant digits; the criteria are
# means of squared or absolute differences of signals that float32 holds to
# 6e-8 relative (3e-5 m on a 300 m yard). Recomputed from a run read back that
# differs from its log as a model's does (centimetres, per cent), they agree to
# 1e-5 relative, a hundred times finer than the last printed digit.
CRITERIA_RTOL = 1e-5


def test_a_log_is_stored_losslessly_and_its_metadata_once(tmp_path):
    log = docking()
    log.meta["truth_state"] = {"x": "A" * 200_000}  # a log holding the truth's states
    path = write_run(log, tmp_path / "log.parquet")
    back = read_run(path)
    pd.testing.assert_frame_equal(back.frame, log.frame, check_exact=True)
    assert back.meta["truth_state"] == log.meta["truth_state"]
    # The metadata once: no Arrow schema copy beside Parquet's own key-value pair.
    keys = pq.read_metadata(path).metadata
    assert b"ARROW:schema" not in keys and len(keys[b"artic"]) > 200_000
    assert os.path.getsize(path) < 200_000 + 8 * log.frame.size  # below plain float64 + meta


def test_a_model_run_read_back_gives_the_criteria_to_the_printed_digits(tmp_path):
    log = slalom()
    run = Run(log.frame.copy(), {"name": "run"})
    f = run.frame
    f[["x_1", "x_2"]] += 250.0  # across a yard: float32's coarsest positions here
    f["psi_1"] += 6.0 * math.pi  # an unwrapped heading three turns on
    f["psi_2"] += 6.0 * math.pi
    # A model's run: centimetres and a few per cent off the log, as the models are.
    wave = np.sin(0.7 * f["t"].to_numpy())
    for c in ("x_1", "y_1", "x_2", "y_2"):
        f[c] += 0.03 * wave
    for c in ("psi_1", "psi_2", "gamma"):
        f[c] += 0.005 * wave
    for c in ("v_x_1", "v_y_1", "r_1", "v_x_2", "v_y_2", "r_2"):
        f[c] *= 1.0 + 0.03 * wave
    rng = np.random.default_rng(1)
    f["delta"] = rng.normal(0.0, 0.1, len(f))
    f["delta_fb"] = rng.normal(0.0, 0.01, len(f))
    f["delta_saturated"] = False
    path = write_run(run, tmp_path / "run.parquet", single=SINGLE)
    back = read_run(path, check=False)
    assert (back.frame.dtypes[list(SINGLE)] == np.float64).all()  # double again on reading
    np.testing.assert_array_equal(back.frame["t"], f["t"])  # the time is kept exactly
    # Each signal to float32's half step: 0.03 mm at 250 m, 2e-6 rad at 19 rad.
    for c in SINGLE:
        ulp = np.spacing(np.abs(f[c].to_numpy()).astype(np.float32)).astype(float)
        assert np.all(np.abs(back.frame[c].to_numpy() - f[c].to_numpy()) <= 0.5 * ulp), c
    assert np.abs(back.frame["x_1"] - f["x_1"]).max() < 3e-5  # [m]
    ref = Run(log.frame.copy())
    ref.frame[["x_1", "x_2"]] += 250.0
    ref.frame[["psi_1", "psi_2"]] += 6.0 * math.pi
    want = run_metrics(ref.frame, f)
    got = run_metrics(ref.frame, back.frame)
    for k, v in want.items():
        assert v != 0.0 and got[k] == pytest.approx(v, rel=CRITERIA_RTOL), k
    # Single precision halves the file at least (the time and the flags stay).
    plain = write_run(run, tmp_path / "plain.parquet")
    assert os.path.getsize(path) < 0.6 * os.path.getsize(plain)


def test_an_export_is_gzipped_and_imports_as_the_plain_one(tmp_path):
    log = slalom()
    plain = export_oxts(log, tmp_path / "plain")
    packed = export_oxts(log, tmp_path / "packed", compress=True)
    assert sorted(p.name for p in packed.values()) == [
        "can.csv.gz", "tractor.csv.gz", "trailer.csv.gz"]
    assert sum(p.stat().st_size for p in packed.values()) < 0.5 * sum(
        p.stat().st_size for p in plain.values())
    again = export_oxts(log, tmp_path / "again", compress=True)  # the same bytes
    assert all(again[k].read_bytes() == packed[k].read_bytes() for k in packed)
    a, _ = import_source(tmp_path / "plain")
    b, _ = import_source(tmp_path / "packed")
    pd.testing.assert_frame_equal(a.frame, b.frame, check_exact=True)


def test_runs_without_samples_keep_their_criteria_and_are_reused(tmp_path):
    import artic

    vehicle = artic.load_vehicle("gosar2022-unloaded")
    log = slalom()
    first = validate_runs([log], vehicle, ["kin"], out_dir=tmp_path, reuse_key="k",
                          samples=False)
    path = tmp_path / "runs" / f"{log.name}.kin.parquet"
    stored = read_run(path, check=False)
    assert len(stored.frame) == 0 and stored.meta["samples"] == len(log.frame)
    assert stored.meta["criteria"]["eps_n"] == first.iloc[0]["eps_n"]
    again = validate_runs([log], vehicle, ["kin"], out_dir=tmp_path, reuse_key="k",
                          samples=False)
    assert again.attrs.get("reused") == 1
    pd.testing.assert_frame_equal(again.drop(columns="wall_s"), first.drop(columns="wall_s"))
