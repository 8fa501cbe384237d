"""The campaign's budget: simulated seconds and runs counted where runs are made.

The counts replace wall time as the measure of what a campaign costs, so
they must be exact: every run the harness makes counted once, with the
simulated time it actually covered (a run stopped early counts its samples
up to the stop), and the efficiency figures must come from the validation's
own runs without making any.
"""

from __future__ import annotations

import threading

import numpy as np
import pandas as pd
import pytest

from artic.plant import Plant
from artic.reduced import KIN
from artic.validation.campaign.efficiency import from_runs
from artic.validation.campaign.report import budget_table
from artic.validation.harness.batch import run_batch
from artic.validation.harness.loop import loop_inputs, run_inputs
from artic.validation.plumbing.budget import BUDGET, Budget, budget_text
from artic.validation.runs.validate import validate_runs
from tests.helpers import straight_log


def inputs(vehicle, name, log):
    return loop_inputs(log, vehicle, vehicle.steering_for(name))


def test_the_harness_counts_each_run_with_the_time_it_simulated(unloaded):
    logs = [straight_log(n=400, u=-0.8), straight_log(n=251, u=1.5, delta_h=2.0)]
    before = BUDGET.snapshot()
    # Two reduced runs in one batch, one through run_inputs, one plant run.
    run_batch(KIN, unloaded, [inputs(unloaded, "kin", log) for log in logs], 3.0, 2)
    run_inputs(KIN(unloaded), inputs(unloaded, "kin", logs[1]), unloaded)
    with Plant(unloaded) as plant:
        run_inputs(plant, inputs(unloaded, "mbd", logs[1]), unloaded)
    got = BUDGET.since(before)
    # 400 samples at 10 ms span 3.99 s, 251 span 2.50 s.
    assert got["reduced"][0] == 3
    assert got["reduced"][1] == pytest.approx(3.99 + 2 * 2.50, abs=1e-9)
    assert got["multibody"] == (1, pytest.approx(2.50, abs=1e-9))
    assert got["other"] == (0, 0.0)


def test_a_run_stopped_early_counts_only_what_it_simulated(unloaded):
    # Open loop, a 0.3 rad start jackknifes before the end of the log (test_batch).
    inp = inputs(unloaded, "kin", straight_log(n=2000, u=-1.0, gamma0=0.3))
    before = BUDGET.snapshot()
    *_, n = run_inputs(KIN(unloaded), inp, unloaded, gain=0.0)
    assert 1 < n < inp.t.size
    assert BUDGET.since(before)["reduced"] == (1, pytest.approx(inp.t[n - 1] - inp.t[0]))


def test_a_scope_collects_only_its_own_threads_runs():
    budget = Budget()
    outside = threading.Thread(target=budget.add, args=("multibody", 40.0))
    with budget.scope() as mine:
        budget.add("multibody", 10.0)
        budget.add("reduced", 2.0, runs=3)
        outside.start()
        outside.join()
        with budget.scope() as inner:
            budget.add("multibody", 5.0)
    budget.add("multibody", 7.0)
    assert mine == {"multibody": [2, 15.0], "reduced": [3, 2.0]}
    assert inner == {"multibody": [1, 5.0]}
    assert budget.snapshot()["multibody"] == (4, 62.0)
    # What a worker collected joins the count of the process that merges it.
    other = Budget()
    other.merge(mine)
    assert other.snapshot()["multibody"] == (2, 15.0)
    assert budget_text(other.snapshot()) == ("multibody 2 runs, 15 s simulated; reduced 3 runs, "
                                             "2 s simulated")


def test_the_efficiency_times_the_validation_runs_and_makes_none(unloaded, tmp_path):
    logs = [straight_log(n=n, u=u) for n, u in ((600, -0.8), (300, 1.2))]
    for i, log in enumerate(logs):
        log.meta["name"] = f"log{i}"
    metrics = validate_runs(logs, unloaded, ["kin", "mbd"], out_dir=tmp_path, jobs=2)
    # A failed pair has no time to add: it must not count.
    failed = metrics.iloc[[0]].assign(model="mbd", log="gone", status="failed: diverged",
                                      wall_s=99.0, duration_s=0.0)
    before = BUDGET.snapshot()
    eff = from_runs(pd.concat([metrics, failed]), ["kin", "mbd"], tmp_path / "runs")
    assert BUDGET.since(before)["multibody"][0] == BUDGET.since(before)["reduced"][0] == 0
    assert list(eff.index) == ["kin", "mbd"]  # one row per model
    for model, rows in metrics.groupby("model"):
        assert eff.loc[model, "runs"] == 2
        assert eff.loc[model, "simulated_s"] == pytest.approx(5.99 + 2.99)
        assert eff.loc[model, "wall_s"] == pytest.approx(rows.wall_s.sum())
        assert eff.loc[model, "wall_per_sim_s"] == pytest.approx(rows.wall_s.sum() / 8.98)
    assert (eff["build_s"] > 0).all() and np.isfinite(eff["build_s"]).all()
    assert eff.loc["mbd", "ratio_to_mbd"] == 1.0 and eff.loc["kin", "paper_ratio"] == 0.1
    # Without run files there are no construction times, and the rest stands.
    bare = from_runs(metrics, ["kin", "mbd"])
    assert bare["build_s"].isna().all() and (bare["simulated_s"] == eff["simulated_s"]).all()


def test_the_budget_table_gives_each_stage_its_share():
    lines = budget_table({"logs": 30.0, "tables": 1.0, "validation": 20.0},
                         {"logs": {"multibody": (58, 3000.0)}, "tables": {},
                          "validation": {"multibody": [150, 1000.0], "reduced": [100, 500.0]}})
    assert lines[2] == "| logs | 30.0 | 58 | 3000 | 75 | 0 | 0 |"
    assert lines[3] == "| tables | 1.0 | 0 | 0 | 0 | 0 | 0 |"
    assert lines[4] == "| validation | 20.0 | 150 | 1000 | 25 | 100 | 500 |"
    assert lines[5] == "| total | 51.0 | 208 | 4000 | 100 | 100 | 500 |"


def test_the_campaign_benchmark_reads_the_reports_stage_table(tmp_path):
    # benchmarks/bench_campaign.py and bench_commands.py read each stage's wall
    # time from report.md; the table grew columns once and the reader broke
    # unnoticed, so it is read here from the table the report writes.
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_campaign.py"
    spec = importlib.util.spec_from_file_location("bench_campaign", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    lines = budget_table({"logs": 30.5, "tables": 1.25},
                         {"logs": {"multibody": (58, 3173.0)}})
    report = tmp_path / "report.md"
    report.write_text("\n".join(["# Report", "", "## Wall time by stage", "", *lines, "",
                                 "## Files"]) + "\n")
    stages = bench._stages(report)
    assert stages["logs"] == 30.5 and stages["tables"] == 1.2  # as printed, one decimal
    assert "total" in stages


def test_the_campaign_benchmark_finds_each_stage_where_it_opens_and_closes():
    # bench_campaign.py reads each stage's CPU between the progress lines the
    # campaign's stage timer prints: read here from the timer itself.
    import importlib.util
    from pathlib import Path

    from artic.validation.campaign.main import Stages

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_campaign.py"
    spec = importlib.util.spec_from_file_location("bench_campaign", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    lines = []
    timer = Stages(lines.append)
    for name in ("logs", "gain sweep"):
        with timer(name):
            lines.append(f"[1/1] generated: {name}")
    assert [bench.stage_of(x + "\n") for x in lines] == [
        "logs", None, "logs", "gain sweep", None, "gain sweep"]
