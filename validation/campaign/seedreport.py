"""``report.md`` of a campaign over several trucks (``artic campaign --seeds N``).

The pooled means over trucks and manoeuvres carry their interval over trucks;
the spread between trucks stands beside the spread between manoeuvres; the
model comparisons are paired per manoeuvre and pooled over trucks, and a
ranking is stated only where they resolve it. Each truck's own report, with
its tuning, efficiency and gain sweep, is in its ``seed-K/report.md``.
"""

from __future__ import annotations

import os
import platform
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd

from artic.validation.campaign.rankings import excess_text, ranking_text
from artic.validation.harness.loop import DEFAULT_GAIN
from artic.validation.review.tables import (
    EXTRA_COLUMNS,
    markdown,
    paired_markdown,
    spread_markdown,
)

KEY_CRITERIA = {"forward": ("eps_n", "eps_p"), "reverse": ("eps_n", "J_steer")}
"""The paper's criteria the report ranks by, per direction."""

STATISTICS = (
    "**Statistics over trucks.** Each seed is one truck; its manoeuvres are repeated "
    "measurements of it, so rows of one truck are not independent draws. The pooled mean "
    "is over every seed and manoeuvre; its 95 % interval is over the trucks' own means "
    "(Student's t below 8 trucks, a BCa bootstrap above; see "
    "`validation/criteria/statistics.py`), which holds for another truck drawn alike and "
    "is wide with few trucks. Beside it, the spread between trucks (the standard "
    "deviation of the per-seed means) and between manoeuvres (the pooled standard "
    "deviation within a seed). A paired comparison averages the per-manoeuvre difference "
    "of two models per truck, and its interval and p value are over those per-truck means; "
    "the p values are adjusted by Holm's method over each table, and a ranking is stated "
    "only where it is a finding: resolved after the correction, pooled, on the logs and "
    "on their noise-free twins. Each paired row says on how many trucks alone it is "
    "resolved, and on how many trucks it is a finding of that truck's own campaign.")


@dataclass
class SeedResults:
    """What the pooled report is made from, filled per (reference, direction)."""

    walls: dict[int, float]
    reports: dict[int, Path]
    campaign: dict
    tables: dict[tuple[str, str], pd.DataFrame] = field(default_factory=dict)
    by_seed: dict[tuple[str, str], pd.DataFrame] = field(default_factory=dict)
    paired: dict[tuple[str, str], pd.DataFrame] = field(default_factory=dict)
    excess: dict[str, pd.DataFrame] = field(default_factory=dict)
    stages: dict[int, dict] = field(default_factory=dict)
    noise_share: dict[str, pd.DataFrame] = field(default_factory=dict)
    headline_criteria: dict[str, pd.DataFrame] = field(default_factory=dict)
    extra: list[str] = field(default_factory=list)
    """Sections made elsewhere (per manoeuvre class, docking and parking, form and
    parameters: ``seeds._pooled_classes``, ``seeds._pooled_form``), after the headline."""

    def summed_stages(self) -> tuple[dict[str, float], dict[str, dict]]:
        """Stage wall times and simulated times, each summed over the trucks."""
        times: dict[str, float] = {}
        budget: dict[str, dict] = {}
        for part in self.stages.values():
            for k, v in part.get("stages", {}).items():
                times[k] = times.get(k, 0.0) + float(v)
            for k, kinds in part.get("budget", {}).items():
                into = budget.setdefault(k, {})
                for kind, (runs, sec) in kinds.items():
                    r0, s0 = into.get(kind, (0, 0.0))
                    into[kind] = (r0 + int(runs), s0 + float(sec))
        return times, budget

    def add(self, ref: str, direction: str, table: pd.DataFrame, seeds: pd.DataFrame,
            pairs: pd.DataFrame, excess: pd.DataFrame | None) -> None:
        """Record one (reference, direction): pooled table, per-seed table, pairs, excess."""
        self.tables[ref, direction] = table
        self.by_seed[ref, direction] = seeds
        self.paired[ref, direction] = pairs
        if excess is not None and len(excess):
            self.excess[direction] = excess


def _criteria(pairs: pd.DataFrame, direction: str) -> list[str]:
    have = set(pairs["criterion"]) if len(pairs) else set()
    return [c for c in (*KEY_CRITERIA[direction], *EXTRA_COLUMNS) if c in have]


def render(r: SeedResults, metrics: pd.DataFrame) -> str:
    """The whole pooled report as Markdown: ``seedreport.md.j2`` with the pooled numbers."""
    from artic.validation.campaign.report import budget_table, template

    seeds = sorted(r.walls)
    excess = [{"direction": d, "table": markdown(ex), "spread": spread_markdown(ex),
               "text": "; ".join(f"{c} {excess_text(ex, c, r.paired.get(('logs', d)))}"
                                 for c in KEY_CRITERIA[d] if c in ex)}
              for d, ex in r.excess.items()]
    rankings = [{"ref": ref, "direction": d,
                 "clauses": " ".join(f"By {c}: {ranking_text(pairs, c)}."
                                     for c in _criteria(pairs, d))}
                for (ref, d), pairs in r.paired.items() if len(pairs)]
    paired = []
    for (ref, d), pairs in r.paired.items():
        part = pairs[pairs["criterion"].isin(_criteria(pairs, d))] if len(pairs) else pairs
        if len(part):
            paired.append({"ref": ref, "direction": d, "table": paired_markdown(part)})
    times, budget = r.summed_stages()
    text = template("seedreport.md.j2").render(
        stamp=datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"), machine=platform.machine(),
        cores=os.cpu_count(), python=platform.python_version(), command=_command(r, seeds),
        seeds=seeds, models=[m for m in dict.fromkeys(metrics["model"]) if m != "floor"],
        gain=r.campaign.get("gain", DEFAULT_GAIN), truth=r.campaign.get("truth", "structural"),
        total=sum(r.walls.values()), walls=list(r.walls.items()), excess=excess,
        headline=_headline(r), extra=r.extra, rankings=rankings, statistics=STATISTICS,
        tables=[{"ref": ref, "direction": d, "table": markdown(table),
                 "spread": spread_markdown(table)} for (ref, d), table in r.tables.items()],
        paired=paired,
        by_seed=[{"ref": ref, "direction": d, "table": markdown(table)}
                 for (ref, d), table in r.by_seed.items()],
        reports=list(r.reports.items()),
        budget="\n".join(budget_table(times, budget)) if times else "")
    return text.removesuffix("\n")


def _headline(r: SeedResults) -> list[str]:
    """The pooled findings on the headline criteria, and on how many trucks each holds."""
    from artic.validation.campaign import findings
    from artic.validation.campaign.rankings import label, ranked

    out = ["## Headline, pooled over trucks", "",
           "The criteria that rank models rather than sensors (pooled: a finding between "
           "models, held on the twins), their pooled findings, on how many trucks each is a "
           "finding of that truck's own campaign, and what the noise adds to a model's score "
           "as a ratio of the smallest finding, with its interval.", ""]
    n = len(r.walls)
    for d in ("forward", "reverse"):
        crit, pairs = r.headline_criteria.get(d), r.paired.get(("logs", d))
        if crit is None or pairs is None or crit.empty:
            continue
        for c in crit.index:
            rows = [p for p in pairs[pairs["criterion"] == c].itertuples(index=False)
                    if "floor" not in (p.a, p.b) and ranked(p)]
            if not rows:
                continue
            texts = [f"{label(p.a if p.diff < 0 else p.b)} below "
                     f"{label(p.b if p.diff < 0 else p.a)} by {abs(p.diff):.3g} "
                     f"({p.seeds_findings} of {n} trucks)" for p in rows]
            tag = f"noise ratio {findings.ratio_text(crit.loc[c])}"
            out.append(f"- {d}, {c} ({tag}): " + "; ".join(texts) + ".")
    out += ["", "Which criteria rank models, pooled:", ""]
    for d in ("forward", "reverse"):
        crit = r.headline_criteria.get(d)
        if crit is not None and len(crit):
            out += [f"{d.capitalize()}:", "", findings.criteria_markdown(crit), ""]
    for d in ("forward", "reverse"):
        share = r.noise_share.get(d)
        if share is not None and len(share):
            out += [f"Noise share, {d} (pooled over trucks and manoeuvres):", "",
                    findings.share_markdown(share), ""]
    return out


def _command(r: SeedResults, seeds: list[int]) -> str:
    """The ``artic campaign`` options that chose these results (not the output folder)."""
    c = r.campaign
    parts = ["artic campaign", f"--seeds {len(seeds)}", f"--seed {seeds[0]}"]
    if c.get("models"):
        parts.append(f"--models {','.join(c['models'])}")
    if c.get("only"):
        parts.append(f"--only {','.join(c['only'])}")
    if c.get("gain") is not None and c["gain"] != DEFAULT_GAIN:
        parts.append(f"--gain {c['gain']:g}")
    if c.get("truth", "structural") != "structural":
        parts.append(f"--truth {c['truth']}")
    if c.get("sensors", "default") != "default":
        parts.append(f"--sensors {c['sensors']}")
    if c.get("drift") is False:
        parts.append("--no-drift")
    if c.get("tuning", "default") != "default":
        parts.append(f"--tuning {c['tuning']}")
    if c.get("oracle") is False:
        parts.append("--no-oracle")
    return " ".join(parts)


def closing(r: SeedResults, report: Path) -> str:
    """What the run prints at the end: the pooled tables against the logs and the report."""
    lines = []
    for direction in ("forward", "reverse"):
        table = r.tables.get(("logs", direction))
        if table is not None and len(table):
            lines += [f"{direction.capitalize()}, pooled over {len(r.walls)} trucks (interval "
                      "over trucks)", "", markdown(table), ""]
    lines.append(f"Wall time: {sum(r.walls.values()):.0f} s over {len(r.walls)} trucks.")
    _, budget = r.summed_stages()
    simulated = sum(float(b.get("multibody", (0, 0.0))[1]) for b in budget.values())
    if simulated > 0:
        lines.append(f"Multibody simulated time: {simulated:.0f} s over {len(r.walls)} trucks.")
    lines.append(f"The whole report: {report}")
    return "\n".join(lines)
