"""The table of the criteria beyond the paper's (criteria/columns.py), and the walk it makes short.

``docs/contributing.md`` promises that a new criterion of a log and a model run
is one module in ``criteria/``, one row of :data:`TABLE` and a test. The last
test here takes that walk in a copy of artic and checks that ``artic validate``
then writes the criterion into ``metrics.csv`` and the tables, and that a log
split at its gaps pools it as its row says.
"""

from __future__ import annotations

import importlib
import math
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from artic.mjcf import load_vehicle
from artic.validation.criteria import columns, dock, pooled, prediction
from artic.validation.criteria.columns import TABLE, Criterion
from artic.validation.criteria.metrics import CRITERIA
from artic.validation.logs.runfile import Run
from artic.validation.logs.schema import COLUMNS as SCHEMA
from tests.helpers import straight_log

ROOT = Path(__file__).resolve().parents[1]


def test_the_table_is_the_one_list_of_the_added_columns():
    # Read off the table, not a copy of it: a new row adds its columns here. No
    # column twice, none a paper criterion's or a log's; the ones the docs name
    # are there, each from its module's own list.
    assert len(set(columns.COLUMNS)) == len(columns.COLUMNS), columns.COLUMNS
    assert not set(columns.COLUMNS) & (set(CRITERIA) | set(SCHEMA)), columns.COLUMNS
    assert {"eps_gamma", "eps_n_fixed", *prediction.COLUMNS, *dock.COLUMNS} <= set(columns.COLUMNS)
    assert set(columns.UNITS) == set(columns.POOL) == set(columns.COMPUTE) == set(columns.COLUMNS)
    assert all(row.units and all(row.units.values()) for row in TABLE)  # every column a unit
    assert columns.POOL["eps_gamma"] == "rms" and "eps_gamma" in pooled.RMS
    assert columns.POOL["dock_psi"] == "last" and columns.POOL["pred_p_5m"] == "mean"


def test_each_row_computed_from_a_run_gives_exactly_its_columns():
    log = straight_log(n=400, u=-1.0)
    run = Run(log.frame.copy(), {"name": "straight.kin"})
    run.frame.loc[:, "psi_2"] += 0.01  # the model's semitrailer 0.01 rad off
    run.frame.loc[:, "gamma"] -= 0.01
    vehicle = load_vehicle("gosar2022-unloaded")
    for row in TABLE:
        if ":" not in row.compute:
            continue
        module, _, name = row.compute.partition(":")
        out = getattr(importlib.import_module(module), name)(log, run, vehicle)
        assert set(out) == set(row.units), row
    got = columns.of_run(log, run, vehicle)
    assert got["eps_gamma"] == pytest.approx(0.01, rel=1e-9)  # a constant error is itself
    assert math.isnan(got["dock_lat"])  # not a docking log


def test_a_malformed_row_is_refused():
    with pytest.raises(ValueError, match="pool 'median'; choose from rms, mean, last, set"):
        Criterion({"x": "m"}, "artic.validation.criteria.articulation:of_run", "median")
    with pytest.raises(ValueError, match="give 'package.module:function'"):
        Criterion({"x": "m"}, "articulation.of_run", "rms")


def test_pooling_follows_the_row():
    # Two segments of 10 m and 30 m: an RMS criterion pools as sqrt of the
    # distance-weighted mean square, a "last" one is the last segment's.
    base = {c: 0.0 for c in pooled.POOLED} | {"r": 0.1, "v_y": 0.1, "delta_c": 0.1}
    parts = [base | {"s_max": 10.0, "eps_gamma": 0.3, "dock_lat": 1.0},
             base | {"s_max": 30.0, "eps_gamma": 0.1, "dock_lat": 2.0}]
    out = pooled.pool(parts)
    assert out["eps_gamma"] == pytest.approx(math.sqrt((10 * 0.09 + 30 * 0.01) / 40))
    assert out["dock_lat"] == 2.0


NEW_CRITERION = '''
"""The semitrailer's heading error ``eps_psi2``: eq. (8) applied to ``psi_2``."""

from __future__ import annotations

import numpy as np

from artic.mjcf.interface import wrap_angle
from artic.validation.criteria.metrics import distance_rms, distance_weights


def of_run(log, run, vehicle) -> dict[str, float]:
    """``eps_psi2`` of a model run against its log [rad]."""
    meas = log.frame.iloc[:len(run.frame)]
    w = distance_weights(meas["t"].to_numpy(float), np.hypot(meas["v_x_1"], meas["v_y_1"]))
    e = wrap_angle(run.frame["psi_2"].to_numpy(float) - meas["psi_2"].to_numpy(float))
    return {"eps_psi2": distance_rms(np.atleast_1d(e), w)}
'''


@pytest.mark.slow
def test_adding_a_criterion_is_one_module_and_one_row(tmp_path):
    # The walk, in a copy of artic: (1) the module, (2) the row; (3) is this test.
    copy = tmp_path / "src" / "artic"
    copy.mkdir(parents=True)
    shutil.copy(ROOT / "artic" / "__init__.py", copy / "__init__.py")
    for pkg in ("mjcf", "plant", "reduced", "validation"):
        shutil.copytree(ROOT / pkg, copy / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    crit = copy / "validation" / "criteria"
    (crit / "heading.py").write_text(NEW_CRITERION)
    table = (crit / "columns.py").read_text()
    # The row goes last in TABLE: before the first line that closes a tuple after it opens.
    end = table.index("\n)\n", table.index("\nTABLE: tuple"))
    (crit / "columns.py").write_text(table[:end] + '\n    Criterion({"eps_psi2": "rad"}, '
                                     '"artic.validation.criteria.heading:of_run", "rms"),'
                                     + table[end:])

    out = tmp_path / "val"
    code = textwrap.dedent(f"""
        import artic
        assert artic.__file__.startswith({str(tmp_path)!r}), artic.__file__
        from artic.validation.cli.entry import main
        logs = []
        for side in ("left", "right"):
            p = {str(tmp_path)!r} + f"/{{side}}.parquet"
            assert main(["simulate", "--model", "stm", "--manoeuvre", "constant-steer",
                         "--side", side, "--duration", "15", "--out", p]) == 0
            logs.append(p)
        assert main(["validate", *logs, "--models", "kin,stm", "--no-recordings",
                     "--out-dir", {str(out)!r}]) == 0
        from artic.validation.criteria import pooled
        assert "eps_psi2" in pooled.RMS and "eps_psi2" in pooled.POOLED
    """)
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "src"),
           "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=900, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    metrics = pd.read_csv(out / "metrics.csv")
    assert "eps_psi2" in metrics.columns and metrics["eps_psi2"].notna().all()
    # The STM replays its own logs; KIN, without tyre slip, heads its semitrailer off.
    by = metrics.groupby("model")["eps_psi2"].max()
    assert by["stm"] < 1e-6 < by["kin"]
    table2 = pd.read_csv(out / "table2_forward.csv")
    assert {"eps_psi2", "eps_psi2_lo", "eps_psi2_hi"} <= set(table2.columns)
    assert np.isfinite(table2["eps_psi2"]).all()
    assert "eps_psi2" in (out / "table2_forward.md").read_text()
