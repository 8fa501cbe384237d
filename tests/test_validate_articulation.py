"""`artic validate` reports the articulation error of every run, and writes the new criteria."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd

from artic.mjcf import load_vehicle
from artic.reduced import KIN
from artic.validation.cli.commands import main
from artic.validation.criteria.columns import COLUMNS
from artic.validation.criteria.fixedscale import SCALE_FILE
from artic.validation.harness.simulate import drive_articulation
from artic.validation.logs.runfile import Run, write_run


def test_validate_prints_eps_gamma_for_every_run(tmp_path, capsys):
    v = load_vehicle("gosar2022-unloaded")
    t = np.arange(0.0, 30.0, 0.01)
    run = drive_articulation(KIN(v), v, t, np.full(t.size, -1.0),
                             math.radians(8.0) * np.sin(2 * math.pi * t / 20.0))
    path = write_run(Run(run.frame, {"name": "swing"}), tmp_path / "swing.parquet")
    out = tmp_path / "val"
    assert main(["validate", str(path), "--models", "kin,stm", "--no-recordings",
                 "--out-dir", str(out)]) == 0
    printed = capsys.readouterr().out
    m = pd.read_csv(out / "metrics.csv")
    assert set(COLUMNS) <= set(m.columns)
    for row in m.itertuples():
        line = next(ln for ln in printed.splitlines() if f"swing / {row.model}" in ln)
        assert f"eps_gamma {math.degrees(row.eps_gamma):6.2f} deg" in line, line
    # KIN replays its own log; the STM's articulation differs by its tyre slip.
    assert m.set_index("model").loc["kin", "eps_gamma"] < 1e-9
    assert m.set_index("model").loc["stm", "eps_gamma"] > 1e-5
    # No direction in the log's metadata: most samples reverse, so it is a
    # reverse log, with predictions and a reverse scale.
    assert m["pred_gamma_10m"].notna().all()
    scale = json.loads((out / SCALE_FILE).read_text())["scale"]
    assert list(scale) == ["reverse"] and scale["reverse"]["logs"] == 1
    assert m["eps_n_fixed"].notna().all()
