"""The campaign report's sections on the low-speed measures, the rating and the frequency response.

Small frames of the campaign's own table shapes (``pbs_truck.csv``,
``paired_*.csv``, ``frequency_departure.csv``): what the sections print must
follow the numbers, the findings and the missing values.
"""

from __future__ import annotations

import math
import re

import pandas as pd

from artic.validation.campaign import measures


def _pbs(loads=("loaded",)) -> pd.DataFrame:
    rows = []
    for load in loads:
        for model, value in (("kin", 5.73), ("mbd", 5.78)):
            rows.append(dict(seed=0, load=load, model=model, measure="swept_width", unit="m",
                             value=value, truth=5.776, error=value - 5.776))
    return pd.DataFrame(rows)


def _pairs(p_adj: float) -> pd.DataFrame:
    # kin against mbd on the rating: kin lower by 0.01, resolved where p_adj < 0.05.
    return pd.DataFrame([dict(criterion="iso_gap", a="kin", b="mbd", n=22, diff=-0.01,
                              diff_lo=-0.02, diff_hi=-0.004, resolved=True, lower="kin",
                              test="tested", p=p_adj / 2, p_adj=p_adj,
                              resolved_adj=p_adj < 0.05, finding=p_adj < 0.05, carried_by="")])


def test_the_measures_table_shows_value_error_and_truth_to_the_centimetre():
    text = measures.pbs_table(_pbs())
    assert "| kin " in text and "| truth " in text
    assert "5.73 (-0.05)" in text  # 5.73 - 5.776 = -0.046: to the centimetre
    assert "5.78 (+0.00)" in text and "5.78 " in text
    # Two loads: each row names its load, so no load's value overwrites the other's.
    both = measures.pbs_table(_pbs(("loaded", "unloaded")))
    assert "kin, loaded" in both and "truth, unloaded" in both


def test_the_rating_clause_follows_the_corrected_finding():
    found = "\n".join(measures.truck_lines(None, {"forward": _pairs(0.001)}, None))
    open_ = "\n".join(measures.truck_lines(None, {"forward": _pairs(0.4)}, None))
    assert "## ISO/TS 18571 rating" in found and "**Forward, iso_gap**" in found
    assert found != open_
    # The rating is a pure number (unit "-"): no unit, and no stray dash, after a figure.
    bullets = [line for line in (found + open_).splitlines() if line.startswith("- **")]
    assert "by 0.010" in found and not any(re.search(r"[\d\]] -", b) for b in bullets)
    assert "not resolved" in open_ or "no finding" in open_ or "unresolved" in open_
    # Without the rating's rows there is no section; with nothing at all, no lines.
    other = _pairs(0.001).assign(criterion="eps_n")
    assert measures.truck_lines(None, {"forward": other}, None) == []


def test_the_departure_band_shows_a_dash_within_the_bound():
    dep = pd.DataFrame({"r_1": [0.635, math.nan], "gamma": [0.063, 0.25198]},
                       index=pd.Index(["kin", "mbd"], name="model"))
    text = "\n".join(measures.truck_lines(None, {}, dep))
    assert "## Frequency response" in text
    assert "0.635" in text and "0.063" in text and "0.252" in text
    assert "| model " in text and "| - " in text  # mbd's r_1 stays within both bounds


def test_the_pooled_section_reads_the_files_the_pooled_campaign_wrote(tmp_path):
    assert measures.pooled_lines(tmp_path, {}) == []
    (tmp_path / "pbs_trucks.md").write_text("# PBS over trucks\n\n| model | swept |\n")
    pd.DataFrame({"r_1": [0.5]}, index=["kin"]).to_csv(tmp_path / "frequency_departure.csv")
    lines = measures.pooled_lines(tmp_path, {("logs", "reverse"): _pairs(0.001),
                                             ("plant", "reverse"): _pairs(0.001)})
    text = "\n".join(lines)
    assert "| model | swept |" in text and "# PBS over trucks" not in text
    assert "mean gain" in text and "0.5" in text
    # The rating over trucks is the one against the logs, not the plant's.
    assert text.count("**Reverse, iso_gap**") == 1
