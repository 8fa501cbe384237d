"""Several trucks: ``artic campaign --seeds N``.

One seed of the synthetic campaign is one truck (its truth draw); its
manoeuvres are repeated measurements of that truck. ``--seeds N`` runs N truth
draws, seeds ``S`` to ``S + N - 1`` (``--seed S``, 0 by default), each a whole
campaign of its own in ``OUT/seed-K/`` with its own report, resumable as any
campaign (a rerun reuses what each seed folder holds). Then, in ``OUT/``:

- ``metrics.csv``, ``metrics_vs_plant.csv``: every seed's rows, with a ``seed`` column;
- ``table2_forward``, ``table3_reverse``, ``table2_vs_plant``, ``table3_vs_plant``
  (``.csv``, ``.md``): the pooled tables, the mean over seeds and manoeuvres
  with its interval over trucks, and the spread between trucks (SD of the
  per-seed means) beside the spread between manoeuvres (within a seed);
- the same with ``_by_seed``: one row per (seed, model), each with its
  interval over that seed's manoeuvres;
- ``paired_forward``, ``paired_reverse`` and their ``_vs_plant``
  counterparts: the paired comparisons pooled over trucks;
- ``report.md``: the pooled results (:mod:`artic.validation.campaign.seedreport`).

``--seeds 1`` (the default) is the single campaign, written into ``OUT/``
itself as before. Its measured time per seed is in ``docs/design/speed.md``.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from artic.validation.campaign.config import CampaignConfig
from artic.validation.criteria.statistics import format_ci, mean_ci
from artic.validation.logs.runfile import atomic_write_text
from artic.validation.plumbing.outputs import OutDirLock, clean_stale
from artic.validation.plumbing.progress import Counter, stderr
from artic.validation.review.tables import (
    by_seed,
    differences,
    markdown,
    paired_markdown,
    pooled,
    pooled_paired,
    spread_markdown,
    write_table,
)

TABLES = {("logs", "forward"): "table2_forward", ("logs", "reverse"): "table3_reverse",
          ("plant", "forward"): "table2_vs_plant", ("plant", "reverse"): "table3_vs_plant"}
"""File stem of each (reference, direction) table, as a single campaign names them."""

TITLES = {"forward": "Forward driving (the paper's Table 2 columns)",
          "reverse": "Reverse driving (the paper's Table 3 columns)"}


def seed_dir(out_dir: Path, seed: int) -> Path:
    """The folder of one truck's campaign."""
    return Path(out_dir) / f"seed-{seed}"


def run_seeds(config: CampaignConfig, run_campaign: Callable[[CampaignConfig], dict[str, Path]],
              progress: Callable[[str], None] = stderr) -> dict[str, Path]:
    """Run ``config.seeds`` campaigns (seeds ``config.seed`` on) and write the pooled results.

    Parameters
    ----------
    config : CampaignConfig
        The campaign; each truck's goes to ``config.out_dir/seed-K``
        (:meth:`~artic.validation.campaign.config.CampaignConfig.for_seed`).
    run_campaign : callable
        Runs one truck's campaign from its configuration and returns its result
        files (:func:`artic.validation.campaign.main.run_campaign`, which calls
        this function: passed in, so that this module does not import it).
    progress : callable
        Receives one line per finished truck, with its reverse eps_n and the time left.

    Returns
    -------
    dict
        Result files by name.
    """
    out_dir, seeds, seed = config.out_dir, config.seeds, config.seed
    campaign = {k: v for k, v in config.options().items() if k not in ("seed", "seeds")}
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with OutDirLock(out_dir, "campaign"):
        stale = clean_stale(out_dir)
        if stale:
            progress(f"removed {len(stale)} temporary file(s) left by an interrupted run")
        (out_dir / "report.md").unlink(missing_ok=True)
        counter = Counter(seeds, "trucks", progress, every=0.0)
        metrics, vs_plant, walls, reports, stages, twins = [], [], {}, {}, {}, []
        oracles: list[pd.DataFrame] = []
        pbs: list[Path] = []
        marked: dict[str, list[pd.DataFrame]] = {}
        for k in range(seeds):
            s = seed + k
            where = seed_dir(out_dir, s)
            progress(f"=== truck {k + 1} of {seeds}: seed {s}, {where}")
            t0 = time.perf_counter()
            paths = run_campaign(config.for_seed(s, where))
            m = pd.read_csv(paths["metrics"]).assign(seed=s)
            metrics.append(m)
            if "metrics_vs_plant" in paths:
                vs_plant.append(pd.read_csv(paths["metrics_vs_plant"]).assign(seed=s))
            if "metrics_twins" in paths:
                twins.append(pd.read_csv(paths["metrics_twins"]).assign(seed=s))
            if "metrics_oracle" in paths:
                oracles.append(pd.read_csv(paths["metrics_oracle"]).assign(seed=s))
            for d in ("forward", "reverse"):
                if f"paired_{d}" in paths:
                    marked.setdefault(d, []).append(
                        pd.read_csv(paths[f"paired_{d}"]).assign(seed=s))
            if "pbs_truck" in paths:
                pbs.append(paths["pbs_truck"])
            walls[s] = _wall(where, time.perf_counter() - t0)
            stages[s] = _stages(where)
            reports[s] = paths["report"].relative_to(out_dir)
            counter.step(f"seed {s} in {walls[s]:.0f} s; reverse eps_n {_eps_n_line(m)}",
                         always=True)
        if pbs:  # the low-speed measures over trucks (artic.validation.pbs.trucks)
            from artic.validation.pbs.trucks import write_pooled as write_pbs

            write_pbs(out_dir, pbs)
        return write_pooled(out_dir, metrics, vs_plant, walls, reports, campaign, stages,
                            twins, marked, oracles)


def _wall(where: Path, measured: float) -> float:
    """A truck's campaign wall time [s]: its stages as first computed (``timings.json``)."""
    try:
        saved = json.loads((where / "timings.json").read_text())
        return float(sum(saved["stages"].values()))
    except (OSError, ValueError, KeyError, TypeError):
        return measured


def _stages(where: Path) -> dict:
    """A truck's stage times and simulated time by stage (``timings.json``; empty if unreadable)."""
    try:
        saved = json.loads((where / "timings.json").read_text())
        return {"stages": dict(saved["stages"]), "budget": dict(saved.get("budget") or {})}
    except (OSError, ValueError, KeyError, TypeError):
        return {}


def _eps_n_line(m: pd.DataFrame) -> str:
    """``KIN 47 ± 8, ... %``: a truck's reverse eps_n per model, for its progress line."""
    part = m[(m["direction"] == "reverse") & (m["status"] == "ok")]
    return ", ".join(f"{model} {format_ci(mean_ci(g['eps_n']))}"
                     for model, g in part.groupby("model", sort=False)) + " %"


def seeds_findings(pooled_pairs: pd.DataFrame, per_seed: list[pd.DataFrame]) -> pd.DataFrame:
    """``pooled_pairs`` with ``seeds_findings``: the trucks whose own table marks it a finding.

    A truck counts where its own paired table (``seed-K/paired_*.csv``, corrected
    and checked on its twins) marks the pair a finding with the pooled sign.
    """
    out = pooled_pairs.copy()
    if out.empty or not per_seed:
        out["seeds_findings"] = 0
        return out
    each = pd.concat(per_seed, ignore_index=True)
    each = each[each["finding"].astype(str).str.lower().isin(("true", "1"))]
    counts = []
    for r in out.itertuples(index=False):
        mine = each[(each["criterion"] == r.criterion) & (each["a"] == r.a)
                    & (each["b"] == r.b)]
        counts.append(int((np.sign(mine["diff"].to_numpy(dtype=float))
                           == np.sign(r.diff)).sum()))
    out["seeds_findings"] = counts
    return out


def write_pooled(out_dir: Path, metrics: list[pd.DataFrame], vs_plant: list[pd.DataFrame],
                 walls: dict[int, float], reports: dict[int, Path],
                 campaign: dict, stages: dict[int, dict] | None = None,
                 twins: list[pd.DataFrame] | None = None,
                 marked: dict[str, list[pd.DataFrame]] | None = None,
                 oracles: list[pd.DataFrame] | None = None) -> dict[str, Path]:
    """The pooled files and ``report.md`` from every truck's metrics (see the module docstring).

    With the trucks' twin metrics (``twins``) the pooled paired tables mark the
    findings (resolved after Holm's correction pooled, on the logs and on the
    twins) and count the trucks whose own table marks each (``marked``, their
    ``paired_*.csv``); the noise share is pooled over trucks and manoeuvres.
    """
    from artic.validation.campaign import findings, seedreport
    from artic.validation.runs.validate import write_metrics

    paths: dict[str, Path] = {}
    logs = _first_columns(pd.concat(metrics, ignore_index=True))
    paths["metrics"] = write_metrics(logs, out_dir / "metrics.csv")
    twin_frame = None
    if twins:
        twin_frame = _first_columns(pd.concat(twins, ignore_index=True))
        (out_dir / "twins").mkdir(parents=True, exist_ok=True)
        paths["metrics_twins"] = write_metrics(twin_frame, out_dir / "twins" / "metrics.csv")
    plant = None
    if vs_plant:
        plant = _first_columns(pd.concat(vs_plant, ignore_index=True))
        paths["metrics_vs_plant"] = write_metrics(plant, out_dir / "metrics_vs_plant.csv")
    results = seedreport.SeedResults(walls=walls, reports=reports, campaign=campaign,
                                     stages=stages or {})
    for ref, frame in (("logs", logs), ("plant", plant)):
        if frame is None:
            continue
        suffix = "" if ref == "logs" else "_vs_plant"
        for direction in ("forward", "reverse"):
            if not (frame["direction"] == direction).any():
                continue
            stem, title, where = TABLES[ref, direction], TITLES[direction], f", against the {ref}"
            table, seeds = pooled(frame, direction), by_seed(frame, direction)
            pairs = pooled_paired(frame, direction)
            if ref == "logs":
                twin_pairs = pooled_paired(twin_frame, direction) \
                    if twin_frame is not None else None
                pairs = seeds_findings(findings.mark(pairs, twin_pairs),
                                       (marked or {}).get(direction, []))
                if twin_frame is not None:
                    share = findings.noise_share(frame, twin_frame, direction)
                    results.noise_share[direction] = share
                    results.headline_criteria[direction] = findings.headline_criteria(
                        pairs, share)
                    if len(share):
                        paths[f"noise_share_{direction}"], _ = write_table(
                            share.set_index("model"), out_dir / f"noise_share_{direction}",
                            f"Noise share, {direction}, pooled over {len(walls)} trucks",
                            findings.share_markdown(share))
            else:
                pairs = findings.mark(pairs, None)
            text = (f"{markdown(table)}\n\nSpread between trucks / between manoeuvres (standard "
                    f"deviations):\n\n{spread_markdown(table)}")
            paths[stem], _ = write_table(table, out_dir / stem, f"{title}{where}, pooled over "
                                         f"{len(walls)} trucks", text)
            paths[f"{stem}_by_seed"], _ = write_table(seeds, out_dir / f"{stem}_by_seed",
                                                      f"{title}{where}, per truck")
            name = f"paired_{direction}{suffix}"
            if len(pairs):
                paths[name], _ = write_table(pairs.set_index("criterion"), out_dir / name,
                                             f"Paired comparisons, {direction}{where}, pooled "
                                             "over trucks", paired_markdown(pairs))
            excess = pooled(differences(frame, direction), direction) if ref == "logs" \
                else None
            results.add(ref, direction, table, seeds, pairs, excess)
    results.extra = _pooled_classes(out_dir, logs, twin_frame, results, campaign, paths)
    if oracles:
        frame = _first_columns(pd.concat(oracles, ignore_index=True))
        paths["metrics_oracle"] = write_metrics(frame, out_dir / "metrics_oracle.csv")
        results.extra += _pooled_form(out_dir, logs, frame, paths, len(walls))
    answer = _sections(results.extra, "## Docking and parking on their own")
    if answer:
        paths["docking_parking"] = atomic_write_text(
            out_dir / "docking_parking.md", f"# Docking and parking on their own, pooled over "
            f"{len(walls)} trucks\n\n" + "\n".join(answer) + "\n")
    from artic.validation.campaign import frequency, measures

    paths |= frequency.write_pooled(out_dir, [out_dir / Path(r).parent for r in reports.values()])
    results.extra += measures.pooled_lines(out_dir, results.paired)
    text = seedreport.render(results, logs)
    paths["report"] = atomic_write_text(out_dir / "report.md", text)
    print(seedreport.closing(results, paths["report"]))
    return paths


def _pooled_classes(out_dir: Path, logs: pd.DataFrame, twins: pd.DataFrame | None,
                    results, campaign: dict, paths: dict[str, Path]) -> list[str]:
    """The pooled tables per manoeuvre class, ``carried_by``, and the report's lines on them.

    As one truck's (:mod:`artic.validation.campaign.classes`), with the pooled
    tables and paired comparisons (intervals over trucks).
    """
    from artic.validation.campaign import classes
    from artic.validation.campaign.report import articulation_lines, class_lines
    from artic.validation.synthetic.testmatrix import tuning_set

    tuning = classes.tuning_classes(tuning_set(str(campaign.get("tuning", "default"))))
    found: dict[str, Any] = {"tuning": tuning}
    paired: dict[str, pd.DataFrame] = {}
    for d in ("forward", "reverse"):
        table = classes.by_class(logs, d, tuning, summarise=pooled)
        if table.empty:
            continue
        stem = TABLES["logs", d]
        paths[f"{stem}_by_class"], _ = write_table(
            table, out_dir / f"{stem}_by_class", f"{TITLES[d]} per manoeuvre class, pooled "
            "over trucks", classes.class_markdown(table))
        per = classes.paired_by_class(logs, twins, d, tuning, pair=pooled_paired)
        if per:
            both = pd.concat([p.assign(**{classes.CLASS: k}) for k, p in per.items()])
            paths[f"paired_{d}_by_class"], _ = write_table(
                both.set_index("criterion"), out_dir / f"paired_{d}_by_class",
                f"Paired comparisons per manoeuvre class, {d}, pooled over trucks",
                "\n\n".join(f"## {k}\n\n{paired_markdown(p)}" for k, p in per.items()))
        pairs = results.paired.get(("logs", d))
        if pairs is not None and len(pairs):
            pairs = classes.carried_by(pairs, logs, twins, d, tuning, pair=pooled_paired)
            results.paired[("logs", d)] = paired[d] = pairs
            paths[f"paired_{d}"], _ = write_table(
                pairs.set_index("criterion"), out_dir / f"paired_{d}",
                f"Paired comparisons, {d}, against the logs, pooled over trucks; the classes "
                "that carry each finding (leave one class out)", paired_markdown(pairs))
        found[d] = {"table": table, "paired": per,
                    "answer": classes.answer(table, per, tuning=tuning) if d == "reverse"
                    else []}
    return [*articulation_lines(found, {}), *class_lines(found, paired)]


def _pooled_form(out_dir: Path, logs: pd.DataFrame, oracle_rows: pd.DataFrame,
                 paths: dict[str, Path], trucks: int) -> list[str]:
    """The oracle rows pooled over trucks: form and parameters, the form's findings."""
    from artic.validation.campaign import classes, oracle
    from artic.validation.campaign.report import articulation_lines, form_lines

    both = oracle.oracle_metrics(logs, oracle_rows)
    forms: dict[str, Any] = {}
    for d in ("forward", "reverse"):
        split = oracle.split(both, d, summarise=pooled)
        if split.empty:
            continue
        pairs = oracle.form_pairs(both, d, pair=pooled_paired)
        paths[f"form_{d}"], _ = write_table(
            split, out_dir / f"form_{d}", f"{TITLES[d]}: form (oracle row minus floor) and "
            f"parameters (tuned row minus oracle row), pooled over {trucks} trucks")
        if len(pairs):
            paths[f"paired_{d}_oracle"], _ = write_table(
                pairs.set_index("criterion"), out_dir / f"paired_{d}_oracle",
                f"Paired comparisons of the oracle rows, {d}, pooled over trucks",
                paired_markdown(pairs))
        forms[d] = {"split": split, "pairs": pairs}
        if d == "reverse":
            rows = both[both["model"].str.endswith(oracle.ORACLE) | (both["model"] == "floor")]
            table = classes.by_class(rows, d, summarise=pooled)
            forms[d]["answer"] = classes.answer(
                table, classes.paired_by_class(rows, None, d, pair=pooled_paired))
    return [*articulation_lines({}, forms), *form_lines(forms)]


def _sections(lines: list[str], heading: str) -> list[str]:
    """The body lines of every section of ``lines`` headed ``heading``, in order."""
    out, inside = [], False
    for line in lines:
        if line.startswith("## "):
            inside = line == heading
            continue
        if inside:
            out.append(line)
    return out


def _first_columns(df: pd.DataFrame) -> pd.DataFrame:
    """``seed`` as the first column."""
    return df[["seed", *[c for c in df.columns if c != "seed"]]]
