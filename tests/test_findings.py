"""Findings: corrected on the logs and held on their noise-free twins; the noise share."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from artic.validation.campaign import findings
from artic.validation.campaign.rankings import lowest, ranking_text
from artic.validation.review.tables import paired_markdown, paired_table


def metrics(values: dict[str, np.ndarray], criterion: str = "eps_n") -> pd.DataFrame:
    """Reverse metrics rows: one per (manoeuvre, model)."""
    rows = []
    for model, v in values.items():
        for i, x in enumerate(v):
            rows.append({"log": f"{i:02d}", "model": model, "direction": "reverse",
                         "status": "ok", criterion: x, "eps_a": 0.0, "eps_v": 0.0,
                         "J_steer": 0.0})
    return pd.DataFrame(rows)


N = 20
RNG = np.random.default_rng(4)
BASE = RNG.normal(30.0, 5.0, N)  # the manoeuvres' own difficulty
NOISE = RNG.normal(6.0, 1.0, N)  # what the sensors add, alike for every model


def logs_and_twins(gap_logs: float, gap_twins: float):
    """KIN above STM by ``gap_*`` on the logs and on the twins, per manoeuvre."""
    jitter = RNG.normal(0.0, 0.5, N)
    twins = {"kin": BASE + gap_twins + jitter, "stm": BASE.copy(), "floor": BASE - 10.0}
    logs = {"kin": BASE + gap_logs + jitter + NOISE, "stm": BASE + NOISE,
            "floor": BASE - 10.0 + NOISE}
    return metrics(logs), metrics(twins)


def test_a_ranking_that_holds_on_the_twins_is_a_finding():
    logs, twins = logs_and_twins(3.0, 3.0)
    pairs = findings.mark(paired_table(logs, "reverse"), paired_table(twins, "reverse"))
    row = pairs.set_index(["criterion", "a", "b"]).loc[("eps_n", "kin", "stm")]
    assert row["resolved_adj"] and row["twin_resolved_adj"] and row["finding"]
    assert row["p_adj"] >= row["p"]  # Holm never lowers a p value
    assert ranking_text(pairs, "eps_n").startswith("STM below KIN")
    assert lowest(pairs, "eps_n") == "stm"
    text = paired_markdown(pairs)
    assert "p (Holm)" in text and "**yes**" in text and "on the twins" in text


def test_a_ranking_the_noise_makes_is_not_a_finding():
    # KIN worse only on the logs: on the twins the two are equal.
    logs, twins = logs_and_twins(3.0, 0.0)
    pairs = findings.mark(paired_table(logs, "reverse"), paired_table(twins, "reverse"))
    row = pairs.set_index(["criterion", "a", "b"]).loc[("eps_n", "kin", "stm")]
    assert row["resolved_adj"] and not row["finding"]
    assert "noise-free twins do not hold it" in ranking_text(pairs, "eps_n")
    assert lowest(pairs, "eps_n") is None
    crit = findings.headline_criteria(pairs, findings.noise_share(logs, twins, "reverse"))
    assert crit.loc["eps_n", "noise_made"] == 1 and not crit.loc["eps_n", "headline"]


def test_a_ranking_of_the_opposite_sign_on_the_twins_is_not_a_finding():
    logs, twins = logs_and_twins(3.0, -3.0)
    pairs = findings.mark(paired_table(logs, "reverse"), paired_table(twins, "reverse"))
    row = pairs.set_index(["criterion", "a", "b"]).loc[("eps_n", "kin", "stm")]
    assert row["resolved_adj"] and row["twin_resolved_adj"] and not row["finding"]


def test_without_twins_a_finding_is_a_corrected_ranking():
    logs, _ = logs_and_twins(3.0, 3.0)
    pairs = findings.mark(paired_table(logs, "reverse"), None)
    assert (pairs["finding"] == pairs["resolved_adj"]).all()


def test_noise_share_is_the_paired_difference_and_its_share():
    logs, twins = logs_and_twins(3.0, 3.0)
    share = findings.noise_share(logs, twins, "reverse").set_index(["model", "criterion"])
    for model in ("kin", "stm", "floor"):
        r = share.loc[(model, "eps_n")]
        assert r["noise"] == pytest.approx(NOISE.mean(), abs=1e-9)
        assert r["noise_lo"] < NOISE.mean() < r["noise_hi"]
        assert r["share"] == pytest.approx(100.0 * r["noise"] / r["noisy"])
        assert r["n"] == N
    assert "kin: logs / twins / noise (share)" in findings.share_markdown(share.reset_index())


def test_the_noise_ratio_is_stated_with_its_interval_not_cut():
    # The noise adds 6 points to every model: against a 3-point finding that is
    # 2 times the difference, against a 30-point one 0.2 times. Both criteria
    # carry their finding; the ratio is stated with the interval that the two
    # differences' intervals give, never compared with a fixed cut.
    for gap in (3.0, 30.0):
        logs, twins = logs_and_twins(gap, gap)
        pairs = findings.mark(paired_table(logs, "reverse"), paired_table(twins, "reverse"))
        share = findings.noise_share(logs, twins, "reverse")
        crit = findings.headline_criteria(pairs, share)
        r = crit.loc["eps_n"]
        assert r["findings"] == 1 and r["noise_made"] == 0 and r["headline"]
        assert r["ratio"] == pytest.approx(NOISE.mean() / gap, rel=0.05)
        # the ends: the noise's interval over the finding's
        row = pairs.set_index(["criterion", "a", "b"]).loc[("eps_n", "kin", "stm")]
        noisiest = share[share["criterion"] == "eps_n"]
        noisiest = noisiest.loc[noisiest["noise"].abs().idxmax()]
        assert r["ratio_lo"] == pytest.approx(noisiest["noise_lo"] / row["diff_hi"])
        assert r["ratio_hi"] == pytest.approx(noisiest["noise_hi"] / row["diff_lo"])
        assert r["ratio_lo"] < r["ratio"] < r["ratio_hi"]
        text = findings.criteria_markdown(crit)
        assert findings.ratio_text(r) in text and "headline" not in text
        assert np.isnan(r["trucks"])  # one truck: no count over trucks


def test_pooled_over_trucks_the_criteria_say_on_how_many_a_finding_holds():
    logs, twins = logs_and_twins(3.0, 3.0)
    pairs = findings.mark(paired_table(logs, "reverse"), paired_table(twins, "reverse"))
    pairs["seeds"] = 5
    pairs["seeds_findings"] = np.where(pairs["a"] == "kin", 3, 0)
    crit = findings.headline_criteria(pairs, findings.noise_share(logs, twins, "reverse"))
    assert findings.trucks_text(crit.loc["eps_n"]) == "3 of 5 trucks"
    assert "3 of 5 trucks" in findings.criteria_markdown(crit)


def test_a_row_not_testable_is_never_a_finding():
    # One manoeuvre far out: the differences are too skewed to test at n = 20,
    # however large the mean difference; the row keeps its interval.
    logs, twins = logs_and_twins(0.0, 0.0)
    for frame in (logs, twins):
        kin = (frame["model"] == "kin") & (frame["log"] == "00")
        frame.loc[kin, "eps_n"] += 400.0
    pairs = findings.mark(paired_table(logs, "reverse"), paired_table(twins, "reverse"))
    row = pairs.set_index(["criterion", "a", "b"]).loc[("eps_n", "kin", "stm")]
    assert row["test"].startswith("not testable at n = 20") and np.isnan(row["p"])
    assert np.isnan(row["p_adj"]) and not row["resolved_adj"] and not row["finding"]
    assert np.isfinite(row["diff_lo"])
    assert "not testable at n = 20" in paired_markdown(pairs)
    assert "not testable at n = 20" in ranking_text(pairs, "eps_n")


def test_the_rating_columns_are_a_family_of_their_own():
    """Adding ISO/TS 18571's columns leaves the distance criteria's Holm family as it was."""
    from statsmodels.stats.multitest import multipletests

    from artic.validation.review.tables import corrected

    p = [0.001, 0.004, 0.02, 0.03, 0.01, 0.2]
    crit = ["eps_p", "eps_n", "J_steer", "steer_fb", "iso_gap", "iso_gap_r1"]
    rows = pd.DataFrame({"criterion": crit, "p": p, "resolved": True})
    out = corrected(rows)
    dist, rate = np.array(p[:4]), np.array(p[4:])
    # Holm written out (statsmodels' own), per family: the same p values alone.
    assert np.allclose(out["p_adj"][:4], multipletests(dist, method="holm")[1])
    assert np.allclose(out["p_adj"][4:], multipletests(rate, method="holm")[1])
    # One family of six would have made eps_n's 0.004 into 0.02, J_steer's 0.02 into 0.06.
    assert out["p_adj"][2] == pytest.approx(0.04) and bool(out["resolved_adj"][2])
