"""The main job: the validation campaign on the embedded default.

1. The synthetic measured campaign (:mod:`validation.synthetic`) is generated
   on first use into ``OUT/synthetic`` and reused afterwards: 58 manoeuvres
   driven on the plant in its truth configuration, exported as OXTS/CAN files.
2. Each export is imported through the same importer as real logs, into
   ``OUT/logs`` (reused when present).
3. Every model runs through the closed-loop harness on every log, with the
   preset of the log's load condition, and is compared by eqs. (8)-(10).
4. Metrics per manoeuvre (``metrics.csv``) and the forward and reverse
   summary tables (``tables.md``) are written atomically.

Not yet here (see the campaign issue): tuning, the efficiency table, the
recordings and the report.
"""

from __future__ import annotations

import os
import platform
import time
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd

from mjcf.vehicle import load_vehicle
from validation.importers import import_source
from validation.logio import atomic_write_text, read_run, write_run
from validation.synthetic import generate_campaign
from validation.validate import (
    markdown_table,
    stderr_progress,
    summary_table,
    validate_runs,
    write_metrics,
)

FORWARD_COLUMNS = ("eps_a", "eps_v", "eps_p", "eps_n")
REVERSE_COLUMNS = ("eps_a", "eps_v", "J_steer", "eps_n")


def load_logs(out_dir: Path, seed: int = 0, jobs: int = 1, only: list[str] | None = None):
    """Generate (or reuse) the synthetic campaign and import it (or reuse the import)."""
    exports = generate_campaign(out_dir / "synthetic", seed=seed, progress=stderr_progress,
                                jobs=jobs, only=only)
    logs = []
    for folder in exports:
        target = out_dir / "logs" / f"{folder.name}.parquet"
        if target.is_file() and target.stat().st_mtime >= (folder / "meta.json").stat().st_mtime:
            logs.append(read_run(target))
            continue
        run, report = import_source(folder)
        for line in report:
            stderr_progress(f"repaired: {line}")
        write_run(run, target)
        logs.append(run)
    return logs


def run_campaign(out_dir: Path, models: tuple[str, ...] = ("kin", "stm"), seed: int = 0,
                 jobs: int | None = None, only: list[str] | None = None) -> dict[str, Path]:
    """Run the campaign; see the module docstring.

    Parameters
    ----------
    out_dir : Path
        Output folder.
    models : tuple of str
        Models to validate.
    seed : int
        Seed of the synthetic campaign.
    jobs : int, optional
        Processes for generation; the number of cores by default.
    only : list of str, optional
        Manoeuvre names or prefixes: a part of the campaign (tests, studies).
    """
    out_dir = Path(out_dir)
    t0 = time.perf_counter()
    jobs = jobs or os.cpu_count() or 1
    stderr_progress(f"artic campaign: models {', '.join(models)}, output {out_dir}")
    logs = load_logs(out_dir, seed, jobs, only)
    t_logs = time.perf_counter() - t0
    stderr_progress(f"{len(logs)} logs ready in {t_logs:.0f} s")
    parts = []
    for load in ("unloaded", "loaded"):
        group = [log for log in logs if log.meta.get("load") == load]
        if group:
            parts.append(validate_runs(group, load_vehicle(f"gosar2022-{load}"), models,
                                       out_dir=out_dir, progress=stderr_progress))
    metrics = pd.concat(parts, ignore_index=True)
    paths = {"metrics": write_metrics(metrics, out_dir / "metrics.csv")}
    fwd = summary_table(metrics[metrics.direction == "forward"], FORWARD_COLUMNS)
    rev = summary_table(metrics[metrics.direction == "reverse"], REVERSE_COLUMNS)
    wall = time.perf_counter() - t0
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    n_f = int((metrics.direction == "forward").sum() / len(models))
    n_r = int((metrics.direction == "reverse").sum() / len(models))
    text = "\n".join([
        f"# artic validation campaign ({stamp}; {platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()})", "",
        f"Synthetic measured campaign, seed {seed}: {n_f} forward and {n_r} reverse "
        "manoeuvres driven on the multibody plant in its truth configuration. Models at "
        "the presets' nominal parameters (no tuning yet), reversing feedback K = 3.", "",
        "## Forward (columns of the seed's Table 2; mean over manoeuvres)", "",
        markdown_table(fwd), "",
        "## Reverse (columns of the seed's Table 3; mean over manoeuvres)", "",
        markdown_table(rev), "",
        f"Wall time {wall:.0f} s, of which {t_logs:.0f} s to generate or load the logs.", "",
    ])
    paths["tables"] = atomic_write_text(out_dir / "tables.md", text)
    print(text)
    stderr_progress(f"done in {wall:.0f} s; results in {out_dir}")
    return paths
