"""``artic tyre curves``: the steady-state sweeps a user checks a .tir file with."""

from __future__ import annotations

import numpy as np
import pandas as pd

from artic.plant.curves import ALPHA_RANGE_DEG, COLUMNS, KAPPA_RANGE
from artic.validation.cli.commands import main


def test_curves_are_written_as_csv_and_png(tmp_path, capsys):
    assert main(["tyre", "curves", "--fz", "10e3,30e3", "--out", str(tmp_path)]) == 0
    csv = tmp_path / "artic-truck-315-80R22.5.curves.csv"
    assert (tmp_path / "artic-truck-315-80R22.5.curves.png").stat().st_size > 10_000
    t = pd.read_csv(csv)
    assert tuple(t.columns) == COLUMNS
    assert set(t.fz) == {10e3, 30e3}
    pure_k = t[(t.alpha_deg == 0.0) & (t.fz == 30e3)]
    pure_a = t[(t.kappa == 0.0) & (t.fz == 30e3)]
    assert pure_k.kappa.min() <= -KAPPA_RANGE and pure_k.kappa.max() >= KAPPA_RANGE
    assert pure_a.alpha_deg.min() <= -ALPHA_RANGE_DEG and pure_a.alpha_deg.max() >= 20.0
    # Physics a user would check: driving slip pushes forward, a positive slip
    # angle pushes left and aligns (negative Mz), and the friction peak is
    # below the load times the file's friction.
    assert pure_k[pure_k.kappa > 0.05].fx.min() > 0
    small = pure_a[(pure_a.alpha_deg > 0.5) & (pure_a.alpha_deg < 3.0)]
    assert (small.fy > 0).all() and (small.mz < 0).all()
    assert np.abs(pure_k.fx).max() < 0.9 * 30e3
    assert "wrote" in capsys.readouterr().out


def test_bad_loads_and_missing_files_are_one_line(tmp_path, capsys):
    assert main(["tyre", "curves", "--fz", "ten", "--out", str(tmp_path)]) == 2
    assert "--fz 'ten'" in capsys.readouterr().err
    assert main(["tyre", "curves", "--fz", "1e4,-5", "--out", str(tmp_path)]) == 2
    assert main(["tyre", "curves", "--tyre", "nope.tir", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    # A bare name: neither here nor shipped; the line names the shipped ones, and no
    # made-up path (the tyre is looked for beside the current folder).
    assert len(err) == 2 and err[-1].startswith("artic: error: --tyre nope.tir: no such file")
    assert "artic-truck-315-80R22.5.tir" in err[-1] and "command-line" not in err[-1]
    missing = str(tmp_path / "gone" / "x.tir")
    assert main(["tyre", "curves", "--tyre", missing, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"artic: error: --tyre {missing}: no such file, nor a tyre shipped with "
                   "artic (artic-trailer-385-65R22.5.tir, artic-truck-315-80R22.5.tir); give a "
                   ".tir file or one of those names"]
    # An output that is a file: named, with the fix, and left as it was.
    a_file = tmp_path / "afile"
    a_file.write_text("x")
    assert main(["tyre", "curves", "--out", str(a_file)]) == 2
    assert capsys.readouterr().err.strip() == (f"artic: error: --out {a_file}: exists and is "
                                               "not a folder; choose a folder")
    assert a_file.read_text() == "x"
