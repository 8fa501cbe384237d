"""The main job on parts of the synthetic campaign, on ideal sensors and on two trucks.

The README's own campaign, whole, is ``tests/test_default_campaign.py``.
"""

from __future__ import annotations

import json
import math
import os

import pandas as pd
import pytest

from artic.mjcf import load_vehicle
from artic.validation.campaign.main import run_campaign
from artic.validation.synthetic.testmatrix import TUNING
from tests.helpers import check_recordings

PART = [*[n for n in TUNING if "-unloaded-" in n][:2],
        "02-constant-steer-unloaded-200deg-10kph-left", "27-ramp-steer-reverse", "45-docking"]


@pytest.mark.slow
def test_campaign_part_resumes_and_never_leaves_a_stale_report(tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    paths = run_campaign(out, models=("kin", "stm", "mbd"), only=PART, jobs=2)
    m = pd.read_csv(paths["metrics"])
    assert (m.model == "floor").sum() == 3  # the truth's own plant, one row per validated log
    m = m[m.model != "floor"].reset_index(drop=True)
    validated = ["02-constant-steer-unloaded-200deg-10kph-left",
                 "27-ramp-steer-reverse-unloaded-30deg-6kph-left", "45-docking-unloaded-left"]
    assert sorted(m.log.unique()) == validated  # the tuning logs are not validated
    assert len(m) == 3 * 3 and (m.status == "ok").all()
    assert (m[m.direction == "reverse"].J_steer > 0).all()
    assert (m[m.direction == "forward"].J_steer == 0).all()
    report = (out / "report.md").read_text()
    for heading in ("## Forward driving", "## Reverse driving", "## Tuning",
                    "## Computational efficiency", "## Feedback gain sweep",
                    "## Wall time by stage"):
        assert heading in report
    t2 = pd.read_csv(out / "table2_forward.csv", index_col=0)
    t3 = pd.read_csv(out / "table3_reverse.csv", index_col=0)
    # Each mean with its 95 % interval over the manoeuvres.
    # The paper's columns first, each normalised one with its absolute counterpart
    # beside it (steer_fb [deg] beside J_steer, eps_p [m] beside eps_n), then the
    # criteria beyond them that the runs have (the articulation error and the
    # fixed-scale eps_n in both directions), the runs off their log, the count.
    from artic.validation.criteria.columns import COLUMNS as EXTRA

    for table, paper in ((t2, ("eps_a", "eps_v", "eps_p", "eps_n")),
                         (t3, ("eps_a", "eps_v", "J_steer", "steer_fb", "eps_n", "eps_p"))):
        cols = list(table.columns)
        k = 3 * len(paper)
        assert cols[:k] == [f"{c}{s}" for c in paper for s in ("", "_lo", "_hi")]
        assert cols[-2:] == ["off_run", "n"] and (table["off_run"] == 0).all()
        extra = [c for c in cols[k:-2] if not c.endswith(("_lo", "_hi", "_n"))]
        assert {"eps_gamma", "eps_n_fixed"} <= set(extra) <= set(EXTRA)
        assert all(f"{c}_lo" in cols and f"{c}_hi" in cols for c in extra)
    for c in ("eps_n", "J_steer"):
        assert (t3[f"{c}_lo"] <= t3[c]).all() and (t3[c] <= t3[f"{c}_hi"]).all()
    pairs = pd.read_csv(out / "paired_reverse.csv")
    assert {"a", "b", "diff", "diff_lo", "diff_hi", "resolved", "lower", "p", "p_adj",
            "resolved_adj", "twin_diff", "twin_p_adj", "finding"} <= set(pairs)
    # A finding is resolved after the correction on the logs and on the twins.
    assert not (pairs.finding & ~(pairs.resolved_adj & pairs.twin_resolved_adj)).any()
    has_p = pairs.p.notna()  # a pair with one manoeuvre (a dock error) has no p value
    assert (pairs.p_adj[has_p] >= pairs.p[has_p]).all() and pairs.p_adj[~has_p].isna().all()
    # Every model and the floor on the noise-free twins of the validated logs.
    twins = pd.read_csv(out / "twins" / "metrics.csv")
    assert sorted(twins.log.unique()) == validated and set(twins.model) == {
        "kin", "stm", "mbd", "floor"}
    share = pd.read_csv(out / "noise_share_reverse.csv")
    assert {"eps_n", "J_steer", "pred_p_10m"} <= set(share.criterion)
    assert "## Headline" in report and "## Noise share" in report
    assert not list((out / "recordings").glob("*twin*"))  # the twins have no recordings
    assert "## Model-form error" in report and "nan" not in report.lower().split()
    # Per manoeuvre class, the classes that carry the findings, and docking on its own.
    for heading in ("## Per manoeuvre class", "## Docking and parking on their own",
                    "## Model form and parameters"):
        assert heading in report
    assert "carried_by" in pairs
    answer = (out / "docking_parking.md").read_text()  # the same answer, on its own
    assert answer.count("**docking** (1 manoeuvre,") == 2 and "steer_fb [deg]" in answer
    assert (out / "noise_share_reverse_by_class.md").is_file()
    by_class = pd.read_csv(out / "table3_reverse_by_class.csv", index_col=0)
    assert set(by_class["class"]) == {"ramp-steer-reverse", "docking"}
    oracle = pd.read_csv(paths["metrics_oracle"])
    assert set(oracle.model) == {"kin-oracle", "stm-oracle", "mbd-oracle"}
    assert not (out / "seed-0").exists()  # one truck: today's layout
    assert set(t2.index) == set(t3.index) == {"kin", "stm", "mbd", "floor"}
    eff = pd.read_csv(out / "efficiency.csv", index_col=0)
    assert eff.loc["mbd", "ratio_to_mbd"] == 1.0 and eff.loc["kin", "ratio_to_mbd"] < 1.0
    # The efficiency times the validation runs, one row per model, and runs nothing itself.
    assert list(eff.index) == ["kin", "stm", "mbd"] and (eff["runs"] == 3).all()
    for model, rows in m.groupby("model"):
        assert eff.loc[model, "simulated_s"] == pytest.approx(rows.duration_s.sum(), rel=1e-5)
        assert eff.loc[model, "wall_s"] == pytest.approx(rows.wall_s.sum(), rel=1e-5)
    assert (eff["build_s"] > 0).all()
    budget = json.loads((out / "timings.json").read_text())["budget"]
    assert budget["efficiency"]["multibody"][0] == budget["efficiency"]["reduced"][0] == 0
    # The plant and the floor each ran the 3 logs and their open-loop predictions.
    assert budget["validation"]["multibody"][0] == budget["references"]["multibody"][0] > 3
    assert "| validation |" in report and "multibody simulated [s]" in report
    tuned = load_vehicle(out / "params" / "gosar2022-unloaded.tuned.toml")
    fitted = json.loads((out / "tuning.json").read_text())["loads"]["unloaded"]["fitted"]
    assert tuned.steering_for("stm").i_s == pytest.approx(fitted["stm"]["i_s"])
    assert tuned.f == pytest.approx(fitted["stm"]["f"]) and tuned.m2 == 7100.0
    # No loaded tuning manoeuvre in this part: the loaded preset stays untuned.
    assert not (out / "params" / "gosar2022-loaded.tuned.toml").exists()
    # One recording per validated manoeuvre, holding every sample of each run.
    assert sorted(p.stem for p in (out / "recordings").glob("*.rrd")) == \
        sorted([*validated, "campaign"])
    check_recordings(out)
    assert (out / "plots" / "gain_sweep.png").is_file()

    # Resume: a lost run file is simulated again, the rest reused.
    lost = out / "runs" / f"{validated[1]}.mbd.parquet"
    kept = out / "runs" / f"{validated[0]}.stm.parquet"
    stamp = kept.stat().st_mtime_ns
    lost.unlink()
    capsys.readouterr()
    run_campaign(out, models=("kin", "stm", "mbd"), only=PART, jobs=2)
    captured = capsys.readouterr()
    err = captured.err
    # The stages the lost file does not feed are reused whole, from their cache entries;
    # validation sees its output gone and computes, reusing the runs still there.
    assert "logs reused from" in err and "tuning reused" in err
    assert "gain sweep reused" in err and "8 of 9 runs reused" in err
    assert "validation: output run:" in err and "missing" in err
    assert "efficiency reused" in err and "references reused" in err
    assert lost.is_file() and kept.stat().st_mtime_ns == stamp
    # The run ends with the two tables and where the report is, not the report.
    assert "Table 2 columns" in captured.out and "Table 3 columns" in captured.out
    assert "## Discussion" not in captured.out and str(out / "report.md") in captured.out
    # Same inputs, same numbers: the re-simulated run gives the same criteria.
    again = pd.read_csv(out / "metrics.csv")
    again = again[again.model != "floor"].reset_index(drop=True)
    pd.testing.assert_frame_equal(again.drop(columns="wall_s"), m.drop(columns="wall_s"))
    # Two identical runs give the same report but for its time stamp: a run that
    # reuses everything keeps the stage times and efficiency of the run that computed them.
    first = (out / "report.md").read_text().splitlines()
    run_campaign(out, models=("kin", "stm", "mbd"), only=PART, jobs=2)
    second = (out / "report.md").read_text().splitlines()
    stamp_line = next(i for i, line in enumerate(first) if "UTC" in line)
    assert [x for i, x in enumerate(first) if i != stamp_line] == \
        [x for i, x in enumerate(second) if i != stamp_line]
    assert "reused (" in capsys.readouterr().err

    # A run that fails part way leaves no report behind to be mistaken for its own.
    import artic.validation.campaign.efficiency as eff_module

    def broken(*a, **k):
        raise RuntimeError("interrupted")

    monkeypatch.setattr(eff_module, "from_runs", broken)
    with pytest.raises(RuntimeError, match="interrupted"):  # --remeasure: compute it again
        run_campaign(out, models=("kin", "stm", "mbd"), only=PART, jobs=2, remeasure=True)
    assert not (out / "report.md").exists()


@pytest.mark.slow
def test_parallel_and_serial_campaigns_give_identical_metrics(tmp_path):
    # Each run is a pure function of its inputs, whichever thread runs it and
    # in whichever order: the plant's compiled loops on two threads, the
    # tuning's Jacobian columns at once, and one thread for everything.
    part = PART[:2] + ["27-ramp-steer-reverse"]
    serial = run_campaign(tmp_path / "one", models=("kin", "mbd"), only=part, jobs=1,
                          sweep_models=(), recordings=False, oracle=False)
    parallel = run_campaign(tmp_path / "two", models=("kin", "mbd"), only=part, jobs=2,
                            sweep_models=(), recordings=False, oracle=False)
    a = pd.read_csv(serial["metrics"]).drop(columns="wall_s")
    b = pd.read_csv(parallel["metrics"]).drop(columns="wall_s")
    assert set(a.model) == {"kin", "mbd", "floor"}  # the one validated log, every model
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    ta = json.loads((tmp_path / "one" / "tuning.json").read_text())["loads"]
    tb = json.loads((tmp_path / "two" / "tuning.json").read_text())["loads"]
    assert ta["unloaded"]["fitted"] == tb["unloaded"]["fitted"]


@pytest.mark.slow
def test_two_trucks_pool_and_resume(tmp_path, capsys):
    # --seeds 2 on one tuning and two validation manoeuvres: a campaign per
    # seed in seed-K, pooled tables and report on top, and a rerun that reuses both.
    out = tmp_path / "out"
    part = ["00-", "02-constant-steer-unloaded-200deg-10kph-left", "45-docking-unloaded-left"]
    # No oracle rows: their pooling over trucks is tests/test_tables.py's, their runs
    # test_campaign_classes's.
    paths = run_campaign(out, models=("kin", "mbd"), only=part, jobs=2, seeds=2, seed=3,
                         sweep_models=(), recordings=False, oracle=False)
    for s in (3, 4):
        assert (out / f"seed-{s}" / "report.md").is_file()
    m = pd.read_csv(paths["metrics"])
    assert set(m.seed) == {3, 4} and len(m) == 2 * 2 * 3  # 2 seeds, 2 logs, kin/mbd/floor
    per_seed = [pd.read_csv(out / f"seed-{s}" / "metrics.csv") for s in (3, 4)]
    t3 = pd.read_csv(out / "table3_reverse.csv", index_col=0)
    assert {"eps_n", "eps_n_lo", "eps_n_hi", "eps_n_sd_trucks", "eps_n_sd_manoeuvres",
            "seeds"} <= set(t3)
    rev = [p[(p.model == "kin") & (p.direction == "reverse")].eps_n.mean() for p in per_seed]
    # The CSV holds six significant digits.
    assert t3.loc["kin", "eps_n"] == pytest.approx(sum(rev) / 2, rel=1e-5)
    assert t3.loc["kin", "eps_n_sd_trucks"] == pytest.approx(pd.Series(rev).std(), rel=1e-5)
    # A model counts the trucks on which it has a result: a model may refuse
    # a log on one truck (the plant's tuned eq. (3) folding back before the
    # log's largest steering-wheel angle, say), and that truck then leaves it.
    def has_result(p: pd.DataFrame, model: str) -> bool:
        rows = p[(p.model == model) & (p.direction == "reverse")]
        return bool((~rows.status.astype(str).str.startswith(("failed", "refused"))).any())

    trucks = {m: [s for s, p in zip((3, 4), per_seed, strict=True) if has_result(p, m)]
              for m in ("kin", "mbd", "floor")}
    assert trucks["kin"] == [3, 4] and trucks["floor"] == [3, 4]
    for model, seeds in trucks.items():
        assert t3.loc[model, "seeds"] == len(seeds)
    by_seed = pd.read_csv(out / "table3_reverse_by_seed.csv", index_col=0)
    assert sorted(by_seed.seed) == sorted(s for seeds in trucks.values() for s in seeds)
    pairs = pd.read_csv(out / "paired_reverse.csv")
    assert {"seeds_resolved", "seeds", "seeds_findings", "finding", "p_adj"} <= set(pairs)
    assert (pairs.seeds_findings <= pairs.seeds).all()
    assert (out / "noise_share_reverse.csv").is_file()
    kin_floor = pairs[(pairs.a == "kin") & (pairs.b == "floor")]
    assert (kin_floor.seeds == 2).all() and (pairs.seeds <= 2).all()
    report = (out / "report.md").read_text()
    assert "over 2 trucks" in report and "nan" not in report.lower().split()
    assert "seed-3/report.md" in report
    # The budget summed over the trucks: each truck's simulated seconds, added.
    budgets = [json.loads((out / f"seed-{s}" / "timings.json").read_text())["budget"]
               for s in (3, 4)]
    total = sum(b[k]["multibody"][1] for b in budgets for k in b)
    row = next(line for line in report.splitlines() if line.startswith("| total |"))
    assert total > 0 and row.split("|")[4].strip() == f"{total:.0f}"
    captured = capsys.readouterr()
    assert f"Multibody simulated time: {total:.0f} s over 2 trucks" in captured.out
    assert "[2/2] trucks: seed 4" in captured.err and "pooled over 2 trucks" in captured.out
    # A rerun reuses every seed's work.
    run_campaign(out, models=("kin", "mbd"), only=part, jobs=2, seeds=2, seed=3,
                 sweep_models=(), recordings=False, oracle=False)
    err = capsys.readouterr().err
    assert err.count("tuning reused") == 2 and err.count("4 of 4 runs reused") >= 2
    again = pd.read_csv(out / "table3_reverse.csv", index_col=0)
    pd.testing.assert_frame_equal(again, t3)


# The floor on noise-free logs (ideal sensors, the column's drift stilled):
# the truth replaying itself. Measured on all 54 validated logs of seed 0 with
# the yard truth (per-log maximum / mean): forward eps_a 5.3e-4 / 1.5e-4 rad/s,
# eps_v 1.9e-3 / 5.4e-4 m/s, eps_p 41 / 3.9 mm, eps_n 0.21 / 0.086 %, eps_gamma
# 1.1e-4 / 3.1e-5 rad, eps_n_fixed 0.30 / 0.085 %: the harness's speed input
# takes the sensor's velocity as the axle's, and the yard truth's sensor sits
# 1.2 m up a frame that rolls (the figure-8's 41 mm). Reverse eps_a 1.2e-3 /
# 4.6e-4 rad/s, eps_v 4.7e-3 / 1.6e-3 m/s, J_steer 0.86 / 0.26 %, eps_n 6.7 /
# 2.5 %, eps_gamma 3.3e-4 / 1.0e-4 rad, eps_n_fixed 2.3 / 0.82 %, dock_lat 40 /
# 11 mm, dock_lon 7.3 / 3.7 mm, dock_psi 2.4e-3 / 6.4e-4 rad: the harness's
# replay residual (its speed follows the log's, smoothed, where the truth's came
# from its pedals, and the feedback answers the difference; eps_n divides it by
# the small |v_y| of the slow laden ramps). Against the sensors' share of the
# floor on the default logs (forward eps_n 3.3 of 3.5 %, reverse 22 of 25 %,
# J_steer 6.8 of 7.5 %) these are near zero; the limits are the per-log maxima
# with about 20 % to spare. The open-loop predictions start from the truth's own
# state and replay its own recorded steering and pedals: the 1 cm and
# 0.05 deg, which the floor meets at every start point of every log
# (tests/test_floor_prediction.py; the follower's per-log means were 4.6 mm and
# 8.3e-4 rad).
IDEAL_FLOOR = {"forward": {"eps_a": 6.5e-4, "eps_v": 2.3e-3, "eps_p": 0.05, "eps_n": 0.25,
                           "eps_gamma": 1.3e-4, "eps_n_fixed": 0.36},
               "reverse": {"eps_a": 1.5e-3, "eps_v": 6e-3, "J_steer": 1.05, "eps_n": 8.1,
                           "eps_gamma": 4e-4, "eps_n_fixed": 2.7, "dock_lat": 0.05,
                           "dock_lon": 0.009, "dock_psi": 2.9e-3,
                           "pred_p_10m": 0.01, "pred_gamma_10m": math.radians(0.05)}}
# The means over a whole direction, about twice the measured ones.
IDEAL_FLOOR_MEAN = {"forward": {"eps_n": 0.17}, "reverse": {"eps_n": 5.0, "J_steer": 0.6}}


def check_ideal_floor(out):
    m = pd.read_csv(out / "metrics.csv")
    floor = m[m.model == "floor"]
    assert len(floor) and (floor.status == "ok").all()
    for direction, limits in IDEAL_FLOOR.items():
        rows = floor[floor.direction == direction]
        for c, limit in limits.items():
            assert (rows[c].dropna().abs() <= limit).all(), (direction, c, rows[c].max())
    return m


# A campaign of its own (ideal sensors), so it is not in the fast set; its checks of
# the whole set of logs are test_whole_ideal_campaign_floor_is_near_zero's.
@pytest.mark.slow
def test_ideal_campaign_floor_is_near_zero(tmp_path):
    out = tmp_path / "ideal"
    paths = run_campaign(out, models=("kin",), only=["00-", "02-", "27-"], jobs=2,
                         sweep_models=(), recordings=False, sensors="ideal", drift=False)
    m = check_ideal_floor(out)
    metas = [json.loads(p.read_text()) for p in (out / "synthetic").glob("*/meta.json")]
    assert all(meta["sensors"]["pos_sigma"] == 0.0 and meta["truth"]["drift_rate"] == 0.0
               for meta in metas)
    # KIN is not the truth: it stays clearly above the floor on the same logs.
    kin = m[m.model == "kin"].set_index("log")["eps_n"]
    floor = m[m.model == "floor"].set_index("log")["eps_n"]
    assert (kin > floor + 0.5).all()
    assert not (out / "twins").exists()  # noise-free logs are their own twins
    report = paths["report"].read_text()
    assert "## Headline" in report and "ideal sensors and the column's drift stilled" in report
    with pytest.raises(ValueError, match="--sensors noisy: expected default or ideal"):
        run_campaign(tmp_path / "bad", sensors="noisy")
    assert not (tmp_path / "bad").exists()


@pytest.mark.slow
def test_whole_ideal_campaign_floor_is_near_zero(tmp_path):
    # Every manoeuvre. The open-loop prediction errors are left to
    # tests/test_prediction.py: the floor restarts there from the log's state. The
    # floor is the truth replayed through the harness, whatever models are validated
    # beside it: KIN alone and no oracle rows (the STM's and the plant's tuning and
    # validation on these logs, and the oracle's runs, were time this test checked nothing of).
    out = tmp_path / "ideal"
    run_campaign(out, models=("kin",), jobs=os.cpu_count() or 1, sweep_models=(),
                 recordings=False, sensors="ideal", drift=False, oracle=False)
    m = check_ideal_floor(out)
    floor = m[m.model == "floor"]
    for direction, limits in IDEAL_FLOOR_MEAN.items():
        rows = floor[floor.direction == direction]
        for c, limit in limits.items():
            assert rows[c].mean() <= limit, (direction, c, rows[c].mean())
