"""The README's first command's campaign, whole: what it finds and what it writes.

Both read the session's one default campaign (``tests/conftest.py``), the
costliest fixture of the suite; across processes (pytest-xdist) this file runs
in one, first.
"""

from __future__ import annotations

import json
import math
from collections import Counter
from pathlib import Path

import pandas as pd
import pytest

from artic.validation.synthetic.testmatrix import MATRIX
from tests.helpers import check_recordings


@pytest.mark.slow
def test_whole_campaign(default_campaign):
    # The main job on all 63 manoeuvres (the paper's 58, the 4 tuning
    # slaloms and the swept sine of the frequency response), as the README's
    # first command runs it (the session's one, tests/conftest.py, which
    # the test below weighs).
    out = default_campaign
    metas = [json.loads(p.read_text()) for p in (out / "synthetic").glob("*/meta.json")]
    assert Counter(m["direction"] for m in metas) == {"forward": 30, "reverse": 33}
    assert {(m["kind"], m["load"], m["amplitude_deg"], m["speed_kph"], m["side"])
            for m in metas} == {(c.kind, c.load, c.amplitude_deg, c.speed_kph, c.side)
                                for c in MATRIX}
    for m in metas:
        if m["kind"] == "ramp-steer-reverse":
            assert math.radians(30) < m["peak_articulation"] < math.radians(50), m["name"]
        if m["kind"] in ("docking", "parking"):
            assert m["docked"], m["name"]
            assert abs(m["final_lateral_error"]) < 0.5, m["name"]
            assert abs(m["final_heading_error"]) < math.radians(3.0), m["name"]
    # The truth's own driver rarely shuffles (1 of 136 docking and parking drives on seeds
    # 0-7; tests/test_truth_driver.py drives one shuffle against its closed form): none
    # needs more than one, where the harness-law driver it replaced reached its cap of 4.
    assert max(m.get("shuffles", 0) for m in metas) <= 1
    # Tables for all three models and the floor: 22 forward manoeuvres (the
    # paper's 25 less the 4 constant steers for tuning, and the swept sine) and
    # 33 reverse, every run complete.
    t2 = pd.read_csv(out / "table2_forward.csv", index_col=0)
    t3 = pd.read_csv(out / "table3_reverse.csv", index_col=0)
    assert (t2["n"] == 22).all() and (t3["n"] == 33).all()
    assert set(t2.index) == set(t3.index) == {"kin", "stm", "mbd", "floor"}
    assert (pd.read_csv(out / "metrics.csv").status == "ok").all()
    # No model beats the floor, the truth's own plant through the same harness.
    for t in (t2, t3):
        assert (t.drop(index="floor")["eps_n"] > t.loc["floor", "eps_n"]).all()
    # The plant as the second reference, for the reduced models.
    p2 = pd.read_csv(out / "table2_vs_plant.csv", index_col=0)
    p3 = pd.read_csv(out / "table3_vs_plant.csv", index_col=0)
    assert set(p2.index) == set(p3.index) == {"kin", "stm"}
    assert (p2["n"] == 22).all() and (p3["n"] == 33).all()
    # Tuning recovers what it can. The structural truth has understeer no model
    # has (the steering yields to the aligning moment, softer trailer tyres,
    # the tridem's bore torque), which every fit can only put into a larger
    # steering ratio: measured +5.7 % (MBD) to +8.5 % (KIN), so 0 to 12 %. The
    # column's play and drift bias the offset: measured +0.6 to +0.9 deg, so
    # within 1.5 deg.
    for load, part in json.loads((out / "tuning.json").read_text())["loads"].items():
        truth = part["truth"]
        i_s_true = part["nominal"]["i_s"] * truth["i_s_scale"]
        for model, fit in part["fitted"].items():
            assert 1.0 < fit["i_s"] / i_s_true < 1.12, (load, model)
            assert abs(fit["delta_h_offset"] - truth["delta_h_offset"]) < math.radians(1.5), \
                (load, model)
    assert len(list((out / "recordings").glob("*.rrd"))) == 55 + 1
    check_recordings(out)
    assert "## Discussion" in (out / "report.md").read_text()


LIMIT_MB = 150.0
"""What a default campaign may write [MB] (issue 33). It writes 146 MB on seed 0
(2026-11-28): exports 23 + twins 17, runs 41, recordings 61, the twins' and
against-the-plant runs 3. The sizes are the same on any machine (the same
seed gives the same files, but for the recordings' ids and times)."""


@pytest.mark.slow
def test_the_default_campaign_writes_at_most_150_mb(default_campaign):
    # The session's default campaign (tests/conftest.py), which the test above checks.
    out = default_campaign
    files = [p for p in Path(out).rglob("*") if p.is_file()]
    size = sum(p.stat().st_size for p in files) / 1e6
    assert size <= LIMIT_MB, f"{size:.0f} MB"
    # No imported copy of a log is kept: the exports are the campaign's logs.
    assert not (out / "logs").exists() and not (out / "twins" / "logs").exists()
