"""The tables with intervals, paired comparisons, pooling over trucks, and the report's words.

Small hand-made metrics frames, so that every number has a known answer.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from artic.validation.campaign.rankings import lowest, ranking_text
from artic.validation.campaign.report import CampaignResults, render
from artic.validation.review import tables as T

N = 20


@pytest.fixture(autouse=True)
def fewer_resamples(monkeypatch):
    """1999 bootstrap resamples instead of 9999: the intervals' ends move by a few per cent
    of their width, far inside what these tests tell apart, and the tests run 5 times faster."""
    from artic.validation.criteria import statistics

    monkeypatch.setattr(statistics, "RESAMPLES", 1999)


def frame(values: dict[str, np.ndarray], direction: str = "reverse", seed: int | None = None,
          **extra: dict[str, np.ndarray]) -> pd.DataFrame:
    """Metrics rows: ``values[model]`` as eps_n per manoeuvre, the other criteria derived."""
    rows = []
    for model, v in values.items():
        for i, x in enumerate(v):
            row = {"log": f"m{i:02d}", "model": model, "direction": direction,
                   "eps_a": 1e-4 * x, "eps_v": 1e-3 * x, "eps_p": 0.1 * x, "J_steer": 0.5 * x,
                   "eps_n": x, "status": "ok"}
            for name, by_model in extra.items():
                row[name] = by_model[model][i]
            rows.append(row)
    df = pd.DataFrame(rows)
    return df if seed is None else df.assign(seed=seed)


@pytest.fixture()
def manoeuvres():
    """Per-manoeuvre eps_n: a spread of 10 between manoeuvres; KIN and STM alike, MBD 3 higher."""
    rng = np.random.default_rng(42)
    base = rng.normal(40.0, 10.0, N)
    return {"kin": base + rng.normal(0, 0.5, N), "stm": base + rng.normal(0, 0.5, N),
            "mbd": base + 3.0 + rng.normal(0, 0.5, N), "floor": base - 10.0}


def test_summary_carries_an_interval_per_mean(manoeuvres):
    m = frame(manoeuvres)
    m.loc[(m.model == "kin") & (m.log == "m00"), "status"] = "failed: diverged"
    t = T.summary(m, "reverse")
    assert list(t.columns[:3]) == ["eps_a", "eps_a_lo", "eps_a_hi"] and t.columns[-1] == "n"
    assert t.loc["kin", "n"] == N - 1 and t.loc["stm", "n"] == N  # the failed pair left out
    assert t.loc["stm", "eps_n"] == pytest.approx(manoeuvres["stm"].mean())
    for model in t.index:
        assert t.loc[model, "eps_n_lo"] < t.loc[model, "eps_n"] < t.loc[model, "eps_n_hi"]
    # About the t interval's width for 20 values of SD 10 (the bootstrap follows the data).
    half = stats.t.ppf(0.975, N - 1) * np.std(manoeuvres["stm"], ddof=1) / math.sqrt(N)
    width = t.loc["stm", "eps_n_hi"] - t.loc["stm", "eps_n_lo"]
    assert 0.7 * 2 * half < width < 1.3 * 2 * half
    # The reverse table's columns: eps_p [m] joins beside eps_n as its absolute counterpart.
    cols = [c for c in t.columns if c in T.UNITS]
    assert "J_steer" in t and cols.index("eps_p") == cols.index("eps_n") + 1


def test_extra_criteria_join_when_present_and_only_then(manoeuvres):
    dock = {m: np.where(np.arange(N) < 6, 0.2, np.nan) for m in manoeuvres}
    gamma = {m: np.full(N, 0.01) for m in manoeuvres}
    m = frame(manoeuvres, eps_gamma=gamma, dock_lat=dock,
              pred_p_5m={k: np.full(N, np.nan) for k in manoeuvres})
    t = T.summary(m, "reverse")
    assert {"eps_gamma", "eps_gamma_lo", "dock_lat", "dock_lat_n"} <= set(t)
    assert "pred_p_5m" not in t and "dock_psi" not in t  # no values: not fabricated
    assert (t["dock_lat_n"] == 6).all() and "eps_gamma_n" not in t
    text = T.markdown(t)
    assert "dock_lat [m]" in text and "eps_gamma [rad]" in text and "(n = 6)" in text
    assert "0.01 ± 0" in text  # every value equal: the interval is the value


def test_markdown_prints_digits_the_interval_supports_and_never_nan(tmp_path, manoeuvres):
    m = frame(manoeuvres)
    m.loc[m.model == "floor", "eps_a"] = np.nan
    t = T.summary(m, "reverse")
    text = T.markdown(t)
    assert "nan" not in text.lower() and "| - |" in text.replace("| - | -", "| - |")
    assert re.search(r"\| \d+ ± \d+ \|", text)  # eps_n of about 40 ± 5: no decimals
    csv, md = T.write_table(t, tmp_path / "table3_reverse", "Reverse")
    back = pd.read_csv(csv, index_col=0)
    assert {"eps_n", "eps_n_lo", "eps_n_hi", "n"} <= set(back)
    assert "±" in md.read_text()
    vs = T.versus_paper(t, T.PAPER_REVERSE)
    assert math.isnan(vs.loc["floor", "eps_n (paper)"])
    assert "nan" not in T.markdown(vs).lower()


def test_paired_table_resolves_a_real_difference_only(manoeuvres):
    pairs = T.paired_table(frame(manoeuvres), "reverse", ["eps_n"])
    assert len(pairs) == 6  # every pair of kin, stm, mbd, floor
    row = pairs.set_index(["a", "b"])
    assert not row.loc[("kin", "stm"), "resolved"]
    assert row.loc[("kin", "stm"), "lower"] == "not resolved"
    assert row.loc[("stm", "mbd"), "resolved"] and row.loc[("stm", "mbd"), "lower"] == "stm"
    assert row.loc[("stm", "mbd"), "diff_lo"] < -3.0 < row.loc[("stm", "mbd"), "diff_hi"]
    assert lowest(pairs, "eps_n") is None
    text = ranking_text(pairs, "eps_n")
    assert "KIN and STM not resolved" in text and "no model is lowest against every other" in text
    assert "STM below MBD" in text and "KIN below STM" not in text and "STM below KIN" not in text
    assert "not resolved" in T.paired_markdown(pairs)


def test_a_paired_table_without_intervals_has_the_same_findings(manoeuvres):
    # intervals=False bootstraps only the rows whose adjusted p is below the
    # level: every other row cannot resolve after the correction, whatever its
    # interval. What it gives must equal the full table where it is computed.
    m = frame(manoeuvres)
    full = T.paired_table(m, "reverse")
    quick = T.paired_table(m, "reverse", intervals=False)
    same = ["criterion", "a", "b", "n", "diff", "test", "p", "p_adj", "resolved_adj"]
    pd.testing.assert_frame_equal(quick[same], full[same])
    below = quick["p_adj"] < 0.05
    assert below.any() and (~below).any()  # both kinds of row in this table
    pd.testing.assert_frame_equal(quick.loc[below], full.loc[below])
    assert quick.loc[~below, ["diff_lo", "diff_hi"]].isna().all().all()
    assert not quick.loc[~below, "resolved"].any()


def test_excess_over_the_floor_is_paired(manoeuvres):
    m = frame(manoeuvres)
    ex = T.excess(m, "reverse")
    assert list(ex.index) == ["kin", "stm", "mbd"]
    d = manoeuvres["mbd"] - manoeuvres["floor"]
    assert ex.loc["mbd", "eps_n"] == pytest.approx(d.mean())
    # Paired, the interval is that of the differences (SD 0.5), not of the manoeuvres (SD 10).
    assert ex.loc["mbd", "eps_n_hi"] - ex.loc["mbd", "eps_n_lo"] < 1.0
    assert T.excess(m[m.model != "floor"], "reverse").empty


def test_pooled_over_trucks(manoeuvres):
    # Three trucks: the same manoeuvres, each truck's models shifted by its own offset,
    # and each run with its own noise.
    offsets = {0: 0.0, 1: 4.0, 2: -2.0}
    rng = np.random.default_rng(5)
    per_truck = {s: {k: v + off + rng.normal(0, 0.5, N) for k, v in manoeuvres.items()}
                 for s, off in offsets.items()}
    m = pd.concat([frame(v, seed=s) for s, v in per_truck.items()], ignore_index=True)
    p = T.pooled(m, "reverse")
    per_seed = np.array([v["kin"].mean() for v in per_truck.values()])
    assert p.loc["kin", "eps_n"] == pytest.approx(per_seed.mean())
    assert p.loc["kin", "eps_n_sd_trucks"] == pytest.approx(np.std(per_seed, ddof=1))
    within = np.mean([np.var(v["kin"], ddof=1) for v in per_truck.values()])
    assert p.loc["kin", "eps_n_sd_manoeuvres"] == pytest.approx(math.sqrt(within))
    lo, hi = stats.t.interval(0.95, 2, per_seed.mean(), stats.sem(per_seed))
    assert (p.loc["kin", "eps_n_lo"], p.loc["kin", "eps_n_hi"]) == pytest.approx((lo, hi))
    assert p.loc["kin", "n"] == 3 * N and p.loc["kin", "seeds"] == 3
    seeds = T.by_seed(m, "reverse")
    assert len(seeds) == 3 * 4 and set(seeds["seed"]) == {0, 1, 2}
    # The offset is the truck's, shared by its models: the paired differences pool tightly.
    pairs = T.pooled_paired(m, "reverse", ["eps_n"]).set_index(["a", "b"])
    assert pairs.loc[("stm", "mbd"), "resolved"]
    assert pairs.loc[("stm", "mbd"), "seeds_resolved"] == 3
    assert not pairs.loc[("kin", "stm"), "resolved"]
    assert "trucks / manoeuvres" in T.spread_markdown(p)


def report_of(metrics: pd.DataFrame) -> str:
    forward, reverse = T.summary(metrics, "forward"), T.summary(metrics, "reverse")
    sweep = pd.DataFrame({"model": ["kin", "kin"], "K": [0.504, 3.0], "J_steer": [9.0, 20.0],
                          "J_steer_lo": [8.0, 18.0], "J_steer_hi": [10.0, 22.0],
                          "eps_n": [40.0, 30.0], "eps_n_lo": [35.0, 27.0],
                          "eps_n_hi": [45.0, 33.0], "stopped": [0, 0], "n": [20, 20]})
    sweep.attrs["K_min"] = {"kin": 0.504}
    r = CampaignResults(seed=0, models=("kin", "stm", "mbd"), gain=3.0, metrics=metrics,
                        forward=forward, reverse=reverse, tuned={}, efficiency=None,
                        sweep=sweep, stages={"validation": 1.0}, fingerprint="0", version="0")
    return render(r)


def test_report_states_no_unresolved_ranking_and_no_nan(manoeuvres):
    # KIN and STM cannot be told apart; MBD is resolved above both; the floor is not in
    # the paper.
    fwd = {k: v / 8 for k, v in manoeuvres.items()}
    metrics = pd.concat([frame(manoeuvres), frame(fwd, "forward")], ignore_index=True)
    text = report_of(metrics)
    assert not re.search(r"(?i)\bnan\b", text)
    assert "KIN and STM not resolved" in text
    for claim in ("KIN below STM", "STM below KIN", "KIN is the lowest", "STM is the lowest",
                  "most accurate"):
        assert claim not in text
    assert "STM below MBD" in text and "KIN below MBD" in text
    assert "floor" in text and "(not in the paper)" in text
    assert "## Model-form error: the excess over the floor" in text
    assert "## Paired comparisons" in text and "KIN 0.504" in text
    # No mean printed with more digits than its interval carries: eps_n means of about
    # 40 with intervals of a few points print as whole numbers.
    assert not re.search(r"\b4\d\.\d\d ", text)


def test_pooled_files_and_report_over_three_trucks(tmp_path, manoeuvres, capsys):
    # The files --seeds N writes on top of the per-seed campaigns, from hand-made trucks:
    # KIN and STM alike on every truck, MBD 3 points above them.
    from artic.validation.campaign.seeds import write_pooled

    rng = np.random.default_rng(9)
    trucks, plant = [], []
    for s in range(3):
        per = {k: v + 2.0 * s + rng.normal(0, 0.5, N) for k, v in manoeuvres.items()}
        trucks.append(pd.concat([frame(per, seed=s), frame(per, "forward", seed=s)]))
        plant.append(frame({k: per[k] for k in ("kin", "stm")}, seed=s))
    paths = write_pooled(tmp_path, trucks, plant, {0: 90.0, 1: 91.0, 2: 92.0},
                         {s: tmp_path / f"seed-{s}" / "report.md" for s in range(3)},
                         {"gain": 3.0, "only": ["45-"]})
    for stem in ("table2_forward", "table3_reverse", "table3_vs_plant", "paired_reverse",
                 "paired_reverse_vs_plant", "table3_reverse_by_seed"):
        assert (tmp_path / f"{stem}.csv").is_file() and (tmp_path / f"{stem}.md").is_file()
    assert set(pd.read_csv(paths["metrics"]).seed) == {0, 1, 2}
    text = (tmp_path / "report.md").read_text()
    assert not re.search(r"(?i)\bnan\b", text)
    assert "over 3 trucks" in text and "--only 45-" in text
    assert "KIN and STM not resolved" in text and "STM below MBD" in text
    assert "KIN below STM" not in text and "STM below KIN" not in text
    assert "trucks / manoeuvres" in text and "seed-1/report.md" in text
    assert "pooled over 3 trucks" in capsys.readouterr().out


def test_pooled_files_per_class_and_with_oracle_rows(tmp_path, manoeuvres, capsys):
    # Three trucks whose reverse manoeuvres are 10 ramp steers and 10 dockings, with
    # oracle rows: the pooled per-class tables and the form split are written, and
    # the report answers for docking on its own.
    from artic.validation.campaign.seeds import write_pooled

    rng = np.random.default_rng(5)
    kinds = np.array(["ramp-steer-reverse"] * 10 + ["docking"] * 10)
    trucks, oracles = [], []
    for s in range(3):
        per = {k: v + rng.normal(0, 0.5, N) for k, v in manoeuvres.items() if k != "mbd"}
        per["floor"] = manoeuvres["kin"] - 5.0
        t = frame(per, seed=s).assign(manoeuvre=np.tile(kinds, len(per)),
                                     steer_fb=lambda d: 0.02 * d["eps_n"])
        trucks.append(t)
        o = t[t["model"] != "floor"].assign(model=lambda d: d["model"] + "-oracle",
                                            eps_n=lambda d: d["eps_n"] + 1.0)
        oracles.append(o)
    paths = write_pooled(tmp_path, trucks, [], {0: 1.0, 1: 1.0, 2: 1.0},
                         {s: tmp_path / f"seed-{s}" / "report.md" for s in range(3)},
                         {"gain": 3.0}, oracles=oracles)
    for stem in ("table3_reverse_by_class", "paired_reverse_by_class", "form_reverse",
                 "paired_reverse_oracle"):
        assert stem in paths and (tmp_path / f"{stem}.md").is_file()
    by_class = pd.read_csv(paths["table3_reverse_by_class"], index_col="model")
    pooled_table = pd.read_csv(paths["table3_reverse"], index_col="model")
    for m in ("kin", "stm", "floor"):  # the pooled mean weighs the class means by their counts
        rows = by_class.loc[[m]]
        # rel 1e-5: the CSV files keep 6 significant digits
        assert float((rows["eps_n"] * rows["n"]).sum() / rows["n"].sum()) == pytest.approx(
            pooled_table.loc[m, "eps_n"], rel=1e-5)
    form = pd.read_csv(paths["form_reverse"], index_col="model")
    # The oracle rows are one point above the tuned ones; form and parameters add up
    # to the tuned row's excess over the floor.
    assert form.loc["kin parameters", "eps_n"] == pytest.approx(-1.0, rel=1e-5)
    excess = pooled_table.loc["kin", "eps_n"] - pooled_table.loc["floor", "eps_n"]
    assert form.loc["kin form", "eps_n"] + form.loc["kin parameters", "eps_n"] == pytest.approx(
        excess, rel=1e-4)
    text = (tmp_path / "report.md").read_text()
    assert "## Docking and parking on their own" in text and "**docking** (30 manoeuvres" in text
    answer = (tmp_path / "docking_parking.md").read_text()
    assert answer.count("**docking**") == 2  # the tuned rows, then the oracle rows
    assert not re.search(r"(?i)\bnan\b", text)


def _pivot_alone(metrics: pd.DataFrame, direction: str, criterion: str,
                 by: tuple[str, ...]) -> pd.DataFrame:
    """One criterion pivoted on its own, as the tables did before :func:`T._pivots`."""
    part = T._ok(metrics)
    part = part[part["direction"] == direction]
    values = pd.to_numeric(part[criterion], errors="coerce")
    return part.assign(_v=values).pivot_table(index=list(by), columns="model", values="_v",
                                              aggfunc="first", sort=False, dropna=False)


def test_one_pivot_of_all_criteria_gives_each_criterion_alone():
    # Two trucks (seed, log rows), duplicated rows (the first non-NaN value
    # counts), NaN and non-numeric values, a failed run, cells missing (a
    # model without some manoeuvres, a seed without some models), an integer
    # and an all-NaN criterion, rows of the other direction, and the logs and
    # models in an order that is not sorted.
    rng = np.random.default_rng(3)
    rows = []
    for seed in (7, 2):
        for log in ("m09", "m01", "m05", "m03"):
            for model in ("stm", "kin", "mbd"):
                if (seed == 2 and model == "mbd") or (log == "m05" and model == "kin"):
                    continue
                for direction in ("reverse", "forward"):
                    rows.append({"seed": seed, "log": log, "model": model,
                                 "direction": direction, "status": "ok",
                                 "eps_n": rng.normal(40, 10), "eps_a": rng.normal(1e-3, 1e-4),
                                 "eps_v": "n/a" if log == "m03" else rng.normal(0.1, 0.01),
                                 "n_hit": int(rng.integers(0, 5)), "empty": math.nan})
    m = pd.DataFrame(rows)
    m.loc[0, "eps_n"] = math.nan
    dup = m.iloc[[0, 3, 8]].copy()
    dup["eps_n"] = [1.0, 2.0, math.nan]
    m = pd.concat([m, dup], ignore_index=True)  # duplicate (seed, log, model) rows
    m.loc[5, "status"] = "failed: diverged"
    crit = ["eps_n", "eps_a", "eps_v", "n_hit", "empty"]
    for by in (("log",), ("seed", "log")):
        for direction in ("reverse", "forward"):
            got = T._pivots(m, direction, crit, by)
            assert list(got) == crit
            for c in crit:
                pd.testing.assert_frame_equal(got[c], _pivot_alone(m, direction, c, by),
                                              check_exact=True, check_index_type=True,
                                              check_column_type=True)
    table = T._pivots(m, "reverse", crit, ("seed", "log"))["eps_n"]
    assert table.loc[(7, "m09"), "stm"] == 1.0  # the duplicate's value where the first is NaN
    assert math.isnan(table.loc[(2, "m01"), "mbd"])  # a missing cell
    assert T._pivots(m, "reverse", [], ("log",)) == {}
    for c, table in T._pivots(m, "sideways", crit, ("log",)).items():  # no rows: empty frames
        pd.testing.assert_frame_equal(table, _pivot_alone(m, "sideways", c, ("log",)))
