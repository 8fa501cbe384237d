"""``artic pbs`` and the measures ``artic validate`` writes: outputs and one-line errors."""

from __future__ import annotations

import numpy as np
import pandas as pd

from artic.validation.cli.commands import main
from artic.validation.pbs.run import MEASURES


def test_pbs_writes_the_tables_and_the_figure(tmp_path, capsys):
    out = tmp_path / "pbs"
    assert main(["pbs", "--models", "kin", "--no-recording", "--out-dir", str(out)]) == 0
    df = pd.read_csv(out / "pbs.csv")
    assert list(df["measure"]) == list(MEASURES)
    values = df.set_index("measure")["value"]
    # KIN has no tyre forces; everything else is a length, and a 16.5 m
    # combination turning at 12.5 m sweeps more than its 2.55 m body's width.
    assert np.isnan(values["steer_friction"])
    assert values["swept_width"] > 2.55
    assert (values.drop("steer_friction") >= 0).all()
    assert (out / "swept-path.png").stat().st_size > 0
    assert (out / "pbs.md").read_text().count("\n| ") == len(MEASURES) + 1
    assert not (out / "pbs-turn.rrd").exists()


def test_pbs_bad_input_is_one_line(tmp_path, capsys):
    assert main(["pbs", "--models", "kin,abc", "--out-dir", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--models" in err[0]
    assert main(["pbs", "--vehicle", "no-such-truck", "--models", "kin",
                 "--out-dir", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no-such-truck" in err[0]
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def test_validate_writes_the_measures_of_each_log_and_model(tmp_path):
    log = tmp_path / "turn.parquet"
    assert main(["simulate", "--model", "stm", "--manoeuvre", "constant-steer",
                 "--duration", "20", "--out", str(log)]) == 0
    out = tmp_path / "val"
    assert main(["validate", str(log), "--models", "kin", "--no-recordings",
                 "--out-dir", str(out)]) == 0
    df = pd.read_csv(out / "pbs_measures.csv")
    assert list(df[["log", "model"]].itertuples(index=False, name=None)) == [("turn", "kin")]
    for c in ("swept_width", "max_offtracking"):
        assert np.isfinite(df[c]).all() and np.isfinite(df[f"{c}_log"]).all()
        assert (df[f"{c}_err"] == (df[c] - df[f"{c}_log"]).abs()).all()
