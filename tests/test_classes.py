"""Tables and findings per manoeuvre class, and the classes that carry a pooled finding."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from artic.validation.campaign import classes, findings
from artic.validation.review.tables import paired_table, summary

COUNTS = {"ramp-steer-reverse": 16, "docking": 9, "parking": 8}  # the reverse test matrix


def reverse_metrics(gap: dict[str, float], seed: int = 3,
                    counts: dict[str, int] | None = None) -> pd.DataFrame:
    """Reverse rows of KIN, STM and the floor; KIN's J_steer above STM's by ``gap[class]``."""
    rng = np.random.default_rng(seed)
    rows = []
    i = 0
    for kind, n in (counts or COUNTS).items():
        base = rng.normal(20.0, 4.0, n)
        jitter = rng.normal(0.0, 0.3, n)
        steer = rng.normal(0.8, 0.2, n)
        for j in range(n):
            for model, j_steer in (("kin", base[j] + gap[kind] + jitter[j]),
                                   ("stm", base[j]), ("floor", base[j] - 5.0)):
                rows.append({"log": f"{i:02d}-{kind}", "model": model, "direction": "reverse",
                             "manoeuvre": kind, "status": "ok", "eps_a": 0.01, "eps_v": 0.05,
                             "J_steer": j_steer, "steer_fb": steer[j], "eps_n": base[j]})
            i += 1
    return pd.DataFrame(rows)


def test_the_class_tables_split_the_pooled_rows_and_the_pooled_mean_weighs_them():
    m = reverse_metrics({k: 1.0 for k in COUNTS})
    pooled = summary(m, "reverse")
    table = classes.by_class(m, "reverse", tuning=("docking",))
    assert list(dict.fromkeys(table[classes.CLASS])) == [
        "ramp-steer-reverse", "docking (tuning class)", "parking"]
    for model in pooled.index:
        rows = table.loc[[model]]
        assert rows["n"].sum() == pooled.loc[model, "n"]  # every pooled row in one class
        for c in ("J_steer", "steer_fb", "eps_n"):
            weighted = float((rows[c] * rows["n"]).sum() / rows["n"].sum())
            assert weighted == pytest.approx(pooled.loc[model, c], rel=1e-12)
    # Each class's row is the summary of that class's rows alone.
    dock = summary(m[m["manoeuvre"] == "docking"], "reverse")
    got = table[table[classes.CLASS] == "docking (tuning class)"]
    assert got.loc["kin", "J_steer"] == pytest.approx(dock.loc["kin", "J_steer"], rel=1e-12)
    assert "## docking (tuning class)" in classes.class_markdown(table)


def test_leaving_one_class_out_names_the_class_that_carries_a_finding():
    # KIN needs 6 points more J_steer than STM on the ramp steers, the same on the rest.
    m = reverse_metrics({"ramp-steer-reverse": 6.0, "docking": 0.0, "parking": 0.0})
    pairs = findings.mark(paired_table(m, "reverse"), paired_table(m, "reverse"))
    row = pairs.set_index(["criterion", "a", "b"]).loc[("J_steer", "kin", "stm")]
    assert row["finding"]  # pooled over the 33, a finding
    marked = classes.carried_by(pairs, m, m, "reverse").set_index(["criterion", "a", "b"])
    assert marked.loc[("J_steer", "kin", "stm"), classes.CARRIED] == "ramp-steer-reverse"
    # KIN above the floor by 5 points on every class: no one class carries it.
    assert marked.loc[("J_steer", "kin", "floor"), classes.CARRIED] == "none alone"
    # Rows that are not findings name no class.
    assert (marked.loc[~marked["finding"].astype(bool), classes.CARRIED] == "").all()
    # Per class: the finding is the ramp steers' alone.
    per = classes.paired_by_class(m, m, "reverse")
    found = {k: bool(p.set_index(["criterion", "a", "b"]).loc[("J_steer", "kin", "stm"),
                                                               "finding"])
             for k, p in per.items()}
    assert found == {"ramp-steer-reverse": True, "docking": False, "parking": False}


def test_the_answer_for_docking_and_parking_is_in_absolute_units_from_their_own_findings():
    def answer(parking: int) -> list[str]:
        m = reverse_metrics({"ramp-steer-reverse": 6.0, "docking": 0.0, "parking": 0.0},
                            counts={**COUNTS, "parking": parking})
        m.loc[(m["model"] == "kin") & (m["manoeuvre"] == "parking"), "steer_fb"] += 1.0
        table = classes.by_class(m, "reverse")
        return classes.answer(table, classes.paired_by_class(m, m, "reverse"))

    text = answer(16)
    assert len(text) == 2 and text[0].startswith("**docking** (9 manoeuvres")
    assert "steer_fb [deg]" in text[0] and "STM below KIN" not in text[0].split("steer_fb")[1]
    # Parking on 16 manoeuvres: KIN 1 deg more correction on every one, a finding there
    # (the exact sign-flip test's smallest p, 2/2^16, passes Holm's first step).
    assert "STM below KIN by 1 ± 0 deg" in text[1]
    # On the test matrix's 8 parking manoeuvres the same gap cannot be a finding: the
    # exact test's smallest p is 2/2^8 = 0.0078, above 0.05/m for the class's family, so
    # the answer states the difference with its interval and says it is not resolved.
    text = answer(8)
    assert "STM below KIN" not in text[1]
    assert "KIN and STM not resolved after the correction (KIN - STM = 1 ± 0 deg)" in text[1]
