"""``report.md``: the campaign's results, discussed as the paper discusses its own.

Every statement about a ranking or a size is computed from the results
passed in; the fixed prose gives only the reasons that hold for any run of
the synthetic campaign (what the measurement is, where the sensor noise
floors lie).
"""

from __future__ import annotations

import math
import os
import platform
from dataclasses import dataclass, field
from datetime import UTC, datetime
from importlib import resources
from string import Template
from typing import Any

import jinja2
import numpy as np
import pandas as pd

from artic.validation.campaign import findings, measures
from artic.validation.campaign.rankings import (
    excess_text,
    label,
    lowest,
    ranked,
    ranking_text,
    verdicts,
)
from artic.validation.criteria.statistics import Interval, format_ci
from artic.validation.review.tables import (
    EXTRA_COLUMNS,
    PAPER_FORWARD,
    PAPER_REVERSE,
    excess,
    markdown,
    paired_markdown,
    paired_table,
    pipe_table,
    versus_paper,
)


@dataclass
class CampaignResults:
    """What the report is made from.

    ``paired`` holds the paired comparisons by ``forward``, ``reverse``,
    ``forward_vs_plant`` and ``reverse_vs_plant``, and ``excess`` the excess
    over the floor by direction; what is missing is computed from
    ``metrics`` and ``metrics_vs_plant``.
    """

    seed: int
    models: tuple[str, ...]
    gain: float
    metrics: pd.DataFrame
    forward: pd.DataFrame
    reverse: pd.DataFrame
    tuned: dict[str, dict]
    efficiency: pd.DataFrame | None
    sweep: pd.DataFrame | None
    stages: dict[str, float]
    fingerprint: str
    version: str
    files: dict[str, str] = field(default_factory=dict)
    per_load: dict[str, pd.DataFrame] = field(default_factory=dict)
    forward_vs_plant: pd.DataFrame | None = None
    reverse_vs_plant: pd.DataFrame | None = None
    truth: str = "independent"
    metrics_vs_plant: pd.DataFrame | None = None
    paired: dict[str, pd.DataFrame] = field(default_factory=dict)
    excess: dict[str, pd.DataFrame] = field(default_factory=dict)
    budget: dict[str, dict] = field(default_factory=dict)
    twins: pd.DataFrame | None = None
    noise_share: dict[str, pd.DataFrame | None] = field(default_factory=dict)
    headline_criteria: dict[str, pd.DataFrame] = field(default_factory=dict)
    sensors: str = "default"
    drift: bool = True
    classes: dict[str, Any] = field(default_factory=dict)
    """Per direction, the tables per manoeuvre class (see ``campaign/main.py``'s ``_by_class``)."""
    form: dict[str, Any] = field(default_factory=dict)
    """Per direction, the oracle rows' split into form and parameters (``_form``)."""
    pbs: pd.DataFrame | None = None
    """The truck's low-speed measures (``pbs_truck.csv``), if the campaign drove the turn."""
    departure: pd.DataFrame | None = None
    """The swept sine's departure bands (``frequency_departure.csv``), if it was validated."""

    def __post_init__(self) -> None:
        for d in ("forward", "reverse"):
            if d not in self.paired and len(self.metrics):
                twin = paired_table(self.twins, d) if self.twins is not None else None
                self.paired[d] = findings.mark(paired_table(self.metrics, d), twin)
            if d not in self.noise_share and self.twins is not None and len(self.metrics):
                self.noise_share[d] = findings.noise_share(self.metrics, self.twins, d)
            if d not in self.headline_criteria and d in self.paired:
                self.headline_criteria[d] = findings.headline_criteria(
                    self.paired[d], self.noise_share.get(d))
            if d not in self.excess and len(self.metrics):
                self.excess[d] = excess(self.metrics, d)
            key = f"{d}_vs_plant"
            if key not in self.paired and self.metrics_vs_plant is not None:
                self.paired[key] = paired_table(self.metrics_vs_plant, d)


KEY_CRITERIA = {"forward": ("eps_n", "eps_p"), "reverse": ("eps_n", "J_steer")}
"""The paper's criteria the discussion ranks by, per direction."""

STATISTICS = (
    "**Statistics.** One seed of the synthetic campaign is one truck, and its "
    "manoeuvres are repeated measurements of it. Every mean carries its 95 % confidence "
    "interval over manoeuvres: a seeded BCa bootstrap at Hesterberg's expanded level "
    "(Student's t below 8 values; see `validation/criteria/statistics.py`), printed as "
    "value ± half-width, or [lo, hi] where the interval is skewed, with only the digits "
    "the interval supports. Two models are compared paired per manoeuvre: the mean of "
    "their differences on the same logs, with its interval and the p value of a test "
    "calibrated at the levels the correction uses (the exact sign-flip test and Student's "
    "t with Hall's skewness correction, both required; a row too skewed for any test at "
    "its number of manoeuvres is \"not testable\", shown with its interval, never a "
    "finding). "
    "A paired table holds some 40 (forward) to 90 (reverse) comparisons, so a few would "
    "resolve by chance: the p values are adjusted by Holm's method over each table (the "
    "family-wise error rate 5 % under any dependence; "
    "`validation/criteria/multiplicity.py`), and a ranking is stated only where it is a "
    "**finding**: resolved after the correction on the logs and, with the same sign, on "
    "their noise-free twins. The `_lo` and `_hi` columns of the CSV tables hold the exact "
    "bounds; `paired_*.csv` every pair and criterion with `p`, `p_adj` and `finding`.")


def headline_section(r: CampaignResults) -> list[str]:
    """The headline: the criteria that rank models, their findings, and the noise beside them.

    Generated from the results alone, so that it can be copied as it stands.
    """
    out = ["## Headline", ""]
    if r.twins is None:
        chain = ("ideal sensors" + ("" if r.drift else " and the column's drift stilled"))
        out += [f"The logs were made with {chain}: they are noise-free, so they are their "
                "own twins and every criterion ranks models; the findings are the rankings "
                "resolved after the correction.", ""]
    else:
        out += [
            "The criteria that rank models rather than sensors: a finding between the models "
            "(resolved after the correction on the logs and, with the same sign, on the "
            "noise-free twins). Beside each, what the sensor noise adds to a model's score at "
            "most, as a ratio of the smallest difference its findings state, with the "
            "interval of that ratio (\"Which criteria rank models\" below): near or above 1 "
            "the measurement chain moves the scores as much as the models differ. Their "
            "findings:", ""]
    any_line = False
    for d in ("forward", "reverse"):
        crit = r.headline_criteria.get(d)
        pairs = r.paired.get(d)
        if crit is None or pairs is None or crit.empty:
            continue
        heads = [c for c in crit.index if crit.loc[c, "headline"]]
        if not heads:
            out += [f"- **{d.capitalize()}**: no criterion has a finding between models.",
                    ""]
            continue
        for c in heads:
            found = [v for v, row in zip(verdicts(pairs, c), _model_rows(pairs, c), strict=True)
                     if ranked(row)]
            share = r.noise_share.get(d)
            noise = ""
            if share is not None and len(share):
                noise = (f"; the noise adds at most {crit.loc[c, 'noise']:.2g} to a model's "
                         f"score, {findings.ratio_text(crit.loc[c])} times the smallest "
                         "finding")
            made = int(crit.loc[c, "noise_made"])
            if made:
                noise += (f"; the noise also makes {made} ranking(s) that the twins do not "
                          "hold, not stated (\"Discussion\" below)")
            out.append(f"- **{d.capitalize()}, {c}**: " + "; ".join(found) + noise + ".")
            any_line = True
        out.append("")
    if not any_line:
        out += ["No ranking between models is a finding.", ""]
    paper = []
    for d, cols in (("forward", PAPER_FORWARD.columns), ("reverse", PAPER_REVERSE.columns)):
        share = r.noise_share.get(d)
        if share is None or share.empty:
            continue
        for c in cols:
            part = share[share["criterion"] == c]
            if len(part):
                paper.append(f"{d} {c}: " + ", ".join(
                    f"{label(m)} {v:.0f} %" for m, v in zip(part["model"], part["share"],
                                                           strict=True) if math.isfinite(v)))
    if paper:
        out += ["The paper's criteria, kept for comparison with the paper, with the share of "
                "each score that the sensor noise makes (\"Noise share\" below): "
                + "; ".join(paper) + ".", ""]
    return out


def _model_rows(pairs: pd.DataFrame, criterion: str) -> list:
    """The rows :func:`verdicts` speaks of, in its order."""
    keep = (pairs["criterion"] == criterion) & ~pairs["a"].isin(("floor",)) \
        & ~pairs["b"].isin(("floor",))
    return list(pairs[keep].itertuples(index=False))


def noise_sections(r: CampaignResults) -> list[str]:
    """Which criteria rank models, and every criterion's noise share."""
    out = ["## Which criteria rank models", "",
           "Per criterion: the findings between models, the rankings resolved after the "
           "correction on the logs that do not hold on the noise-free twins (made by the "
           "noise), the smallest difference a finding states, the largest noise addition to "
           "a model's score (each the magnitude with its bounds over the 95 % interval), "
           "and their ratio with the interval those bounds give (the noise's over the "
           "finding's: both hold at least 90 % of the time). The ratio is stated, not cut: "
           "a criterion with a finding carries it, and the ratio says how much the sensors "
           "move the scores beside it.", ""]
    for d in ("forward", "reverse"):
        crit = r.headline_criteria.get(d)
        if crit is not None and len(crit):
            out += [f"{d.capitalize()}:", "", findings.criteria_markdown(crit), ""]
    if r.twins is None:
        return out
    out += ["## Noise share", "",
            "Every criterion on the logs, on their noise-free twins (the same truth runs, the "
            "column's drift included, measured with ideal sensors: no noise, no clock skew, "
            "the steering wheel every sample) and the difference, paired per manoeuvre with "
            "its 95 % interval: what the measurement chain adds to the floor's and to each "
            "model's score, and its share of the score on the logs (`noise_share_*.csv`; the "
            "dock errors as magnitudes).", ""]
    for d in ("forward", "reverse"):
        share = r.noise_share.get(d)
        if share is not None and len(share):
            out += [f"{d.capitalize()}:", "", findings.share_markdown(share), ""]
    return out


def _extras(pairs: pd.DataFrame | None) -> list[str]:
    """The criteria beyond the paper's that a paired table has."""
    if pairs is None or pairs.empty:
        return []
    return [c for c in EXTRA_COLUMNS if c in set(pairs["criterion"])]


def _value(table: pd.DataFrame, model: str, col: str) -> str:
    """One table entry with its interval, as text."""
    row = table.loc[model]
    n = int(row[f"{col}_n"]) if f"{col}_n" in row and pd.notna(row[f"{col}_n"]) \
        else int(row["n"])
    return format_ci(Interval(float(row[col]), float(row[f"{col}_lo"]), float(row[f"{col}_hi"]),
                              n, ""))


def headline(r: CampaignResults) -> list[str]:
    """The excess over the floor, paired per manoeuvre: the model-form error."""
    out = []
    for name in ("forward", "reverse"):
        ex = r.excess.get(name)
        if ex is None or ex.empty:
            continue
        crit = KEY_CRITERIA[name]
        text = "; ".join(f"{c} {excess_text(ex, c, r.paired.get(name))}" for c in crit
                         if c in ex)
        out += [f"**{name.capitalize()}**, above the floor: {text}.", "", markdown(ex), ""]
    if not out:
        return []
    return [
        "## Model-form error: the excess over the floor", "",
        "The floor is the truth that made the logs, without its random processes (sensor "
        "noise, the steering column's drift, clock skew), through the same harness against "
        "the same logs: what those processes and the harness cost however good a model "
        "is. Each model's criteria "
        "minus the floor's on the same manoeuvre, averaged over the manoeuvres, with the "
        "95 % interval of that mean: the headline figure of model-form error. A model is "
        "said to be above the floor where its paired comparison with the floor is a finding "
        "(resolved after the correction, on the logs and on the twins).", "", *out]


def discussion(r: CampaignResults) -> list[str]:
    """The paragraphs that compare models and set the results against the paper's."""
    out = []
    fwd, rev = r.forward, r.reverse
    pf, pr = r.paired.get("forward"), r.paired.get("reverse")
    if len(fwd) and pf is not None:
        text = (f"**Forward.** By eps_n: {ranking_text(pf, 'eps_n')}. By eps_p: "
                f"{ranking_text(pf, 'eps_p')}. The paper found MBD best (4.83 %), then STM "
                "(5.9 %) and KIN (9.26 %), as means without intervals.")
        f_fit = [p["fitted"]["stm"]["f"] for p in r.tuned.values() if "stm" in p["fitted"]]
        truth = next((p["truth"] for p in r.tuned.values() if p["truth"]), None)
        if "mbd" in fwd.index and lowest(pf, "eps_n") != "mbd" and f_fit and truth:
            tyres = (f"lateral stiffness is {truth['LKY']:.2f} times the tyre file's"
                     if truth.get("kind") != "independent" else
                     "tyres are another make (a published TMeasy truck-tyre set, their "
                     "cornering stiffness about 1.25 times the tyre file's at its nominal "
                     "load; docs/design/truth.md)")
            text += (" The multibody model's tyres are not tuned (the paper, too, tuned its "
                     f"MBD only a little), while the truth's {tyres}; the STM's fitted f ("
                     + " and ".join(f"{f:.3g}" for f in f_fit) + " /rad against the "
                     "presets' 6) absorbs such a difference, the plant's steering ratio only "
                     "partly.")
        out.append(text)
    if len(rev) and pr is not None:
        out.append(
            f"**Reverse.** By eps_n: {ranking_text(pr, 'eps_n')} (the paper: STM lowest, "
            f"27.7 %). By the steering effort J_steer: {ranking_text(pr, 'J_steer')} (the "
            "paper: STM 21.15 %, MBD 26.14 %, KIN 26.96 %). A model whose articulation "
            "dynamics match the truck's needs little feedback, so J_steer ranks the models' "
            "reversing dynamics directly, independent of the gain's size as long as the loop "
            "is stable.")
    for name, pairs in (("forward", pf), ("reverse", pr)):
        extras = _extras(pairs)
        if extras:
            out.append(f"**Beyond the paper's criteria, {name}.** "
                       + " ".join(f"By {c}: {ranking_text(pairs, c)}." for c in extras))
    if len(fwd) and set(fwd.index) & set(PAPER_FORWARD.index):
        out.append(
            "**Against the paper's Table 2.** Our forward means over the paper's, "
            f"{_ratio_range(versus_paper(fwd, PAPER_FORWARD))}. The measurement here is "
            f"synthetic: the {r.truth} truth (see `validation/synthetic/truth.py`"
            + ("; a vehicle of its own, sharing no code with artic's plant: its own "
               "skeleton with frame torsion, a cab on mounts, fifth-wheel lash and roll "
               "steer, TMeasy tyres from a published set and a compliant steering column"
               if r.truth == "independent" else "; artic's plant")
            + ") with modelled sensors. What real logs add and these lack: a real tyre's "
            "temperature dependence, frame compliance, grip variation and GNSS multipath. The "
            "position error eps_p of open-loop forward runs grows with the drift of heading, "
            "which those effects dominate on a real truck; it is therefore the criterion "
            "furthest from the paper's.")
    for name, table, paper in (("forward", r.forward_vs_plant, "Table 2"),
                               ("reverse", r.reverse_vs_plant, "Table 3")):
        pairs = r.paired.get(f"{name}_vs_plant")
        if table is not None and len(table) and pairs is not None:
            second = "J_steer" if name == "reverse" else "eps_p"
            out.append(
                f"**Against the plant as reference, {name}.** With the plant's runs of the "
                "same manoeuvres as the reference (its " + paper + " columns in "
                f"`{'table2' if name == 'forward' else 'table3'}_vs_plant`), by eps_n: "
                f"{ranking_text(pairs, 'eps_n')}; by {second}: {ranking_text(pairs, second)}. "
                "This reference has no sensor noise and shares the reduced models' tuned "
                "steering map's inputs, so it isolates the difference of the model equations "
                "from the plant's.")
    if len(rev) and set(rev.index) & set(PAPER_REVERSE.index):
        vs = versus_paper(rev, PAPER_REVERSE)
        out.append(
            "**Against the paper's Table 3.** Reverse eps_n here is "
            + ", ".join(f"{label(m)} {_value(rev, m, 'eps_n')} % " + (
                f"(paper {vs.loc[m, 'eps_n (paper)']:.4g} %)" if m in PAPER_REVERSE.index
                else "(not in the paper)") for m in vs.index)
            + ". The synthetic docking and parking runs come from a driver model that steers "
            "smoothly and stops at the dock; the paper's experienced driver shuffled and "
            "corrected more, and its reverse runs reached 40 to 45 deg of articulation on "
            "average. Reverse yaw rates are small, so eps_n, which divides by them, is large "
            "in both.")
    if r.efficiency is not None and "ratio_to_mbd" in r.efficiency:
        e = r.efficiency
        parts = [f"{label(m)}/MBD = {e.loc[m, 'ratio_to_mbd']:.2g} "
                 f"(paper {e.loc[m, 'paper_ratio']:.2g})" for m in e.index if m != "mbd"]
        out.append(
            "**Efficiency.** Wall time per simulated second, as ratios to the multibody "
            f"plant: {'; '.join(parts)}. The reduced models are compiled (numba) and the "
            "plant steps MuJoCo with a compiled tyre callback, so the ratios compare "
            "implementations as much as models; the paper's figures (KIN 90 % and STM 60 % "
            "faster) compare its own implementations.")
    out.append(STATISTICS)
    return out


def _ratio_range(vs: pd.DataFrame) -> str:
    """The smallest and largest of our-over-paper ratios, each with its interval and source."""
    found = []
    for m in vs.index:
        for c in [c for c in vs.columns if c.endswith(" ratio")]:
            v = float(vs.loc[m, c])
            if np.isfinite(v):
                iv = Interval(v, float(vs.loc[m, f"{c}_lo"]), float(vs.loc[m, f"{c}_hi"]),
                              int(vs.loc[m, "n"]) if "n" in vs else 0, "")
                found.append((v, f"{format_ci(iv)} ({label(m)} {c.removesuffix(' ratio')})"))
    if not found:
        return "not available"
    found.sort()
    return f"from {found[0][1]} to {found[-1][1]}"


def paired_sections(r: CampaignResults) -> list[str]:
    """The paired comparison tables of the key criteria, per reference and direction."""
    lines = ["## Paired comparisons", "",
             "Every two models on the same manoeuvres: the mean of a - b with its 95 % "
             "interval, whether the interval excludes zero (resolved), the p value adjusted "
             "by Holm's method over the table and whether the ranking is resolved after it, "
             "the same on the noise-free twins, and whether it is a finding. The key criteria "
             "here; every criterion in `paired_forward.csv`, `paired_reverse.csv` and their "
             "`_vs_plant` counterparts (against the plant, which has no sensor noise, the "
             "findings are the rankings resolved after the correction).", ""]
    any_table = False
    for key, title in (("forward", "Forward, against the logs"),
                       ("reverse", "Reverse, against the logs"),
                       ("forward_vs_plant", "Forward, against the plant"),
                       ("reverse_vs_plant", "Reverse, against the plant")):
        pairs = r.paired.get(key)
        if pairs is None or pairs.empty:
            continue
        crit = [*KEY_CRITERIA[key.split("_")[0]], *_extras(pairs)]
        part = pairs[pairs["criterion"].isin(crit)]
        lines += [f"{title}:", "", paired_markdown(part), ""]
        any_table = True
    return lines if any_table else []


def _tuning_text(r: CampaignResults) -> list[str]:
    lines = []
    for load, part in r.tuned.items():
        lines += [f"### {load}", "", f"Tuning logs: {', '.join(part['logs'])}.", "",
                  markdown(pd.DataFrame(part["rows"]).drop(columns="load").set_index("model"),
                           digits=5), "",
                  markdown(pd.DataFrame(part["summary"]).drop(columns="load")
                           .set_index("model"), digits=4), ""]
        truth = part["truth"]
        if not truth:
            continue
        i_s_true = part["nominal"]["i_s"] * truth["i_s_scale"]
        off_true = truth["delta_h_offset"]
        recovered = []
        for m, fit in part["fitted"].items():
            if "i_s" in fit and "delta_h_offset" in fit:
                recovered.append(
                    f"{label(m)} i_s {fit['i_s']:.4g} ({100 * (fit['i_s'] / i_s_true - 1):+.2f} "
                    f"%), offset {math.degrees(fit['delta_h_offset']):.3g} deg "
                    f"({math.degrees(fit['delta_h_offset'] - off_true):+.2f} deg)")
        lines += [
            f"Truth of the synthetic campaign (seed {r.seed}): steering ratio {i_s_true:.4g}, "
            f"steering-wheel offset {math.degrees(off_true):.3g} deg, tyre LKY x "
            f"{truth['LKY']:.3f}, LMUY x {truth['LMUY']:.3f}. Recovered: "
            + "; ".join(recovered) + ".", ""]
    if r.truth == "legacy":
        lines.append(
            "The multibody model shares the legacy truth's structure, so its fit is the test "
            "of recovery; the reduced models absorb their structural differences (no tyre "
            "slip in KIN, linear tyres in STM) into i_s and the offset.")
    elif r.truth == "independent":
        lines.append(
            "The independent truth is not artic's plant and shares no code with it: its "
            "skeleton is its own (the tractor's frame twists, the cab sits on mounts, the "
            "fifth wheel has lash, every axle steers with its roll), its tyres are TMeasy "
            "with a published truck-tyre set, not the plant's PAC2002 files, its twin tyres "
            "are two tyres, its masses and centres of gravity are off the presets by stated "
            "amounts, and its steering is a torsion bar with free play and a lagged "
            "hydraulic assist, whose right wheel follows through a compliant tie rod on its "
            "own trapezoid; its zero drifts, and its "
            "driver works the pedals on a sloped yard. The fits absorb what they can into "
            "i_s and the offset: the column's compliance and play show as a larger "
            "effective ratio, its drift as an offset bias. These are the biases of the "
            "recovered values above.")
    else:
        lines.append(
            "The structural truth differs from every model: its trailer tyres are another "
            "construction (5 /rad against 6), its tyres have aligning moment and turn slip, "
            "its steering column has free play and a drifting offset, and its driver works "
            "the pedals on a sloped yard. The fits absorb what they can into i_s and the "
            "offset: the column's play shows as a smaller effective ratio near centre and "
            "its drift as an offset bias, the softer trailer tyres as a lower fitted f of "
            "the STM. These are the biases of the recovered values above.")
    return lines


def budget_table(stages: dict[str, float], budget: dict[str, dict]) -> list[str]:
    """The stages' wall times and simulated times as Markdown table lines.

    Beside each stage's wall time, the multibody runs (the plant and the
    truth, MuJoCo) and reduced-model runs it made and the seconds they
    simulated (:class:`artic.validation.plumbing.budget.Budget`), and the stage's
    share of the multibody seconds: the campaign's cost in numbers that do not
    depend on the machine.
    """
    def cell(stage: str, kind: str) -> tuple[int, float]:
        runs, seconds = (budget.get(stage) or {}).get(kind, (0, 0.0))
        return int(runs), float(seconds)

    total_mb = sum(cell(k, "multibody")[1] for k in stages)
    head = ["stage", "wall [s]", "multibody runs", "multibody simulated [s]", "share [%]",
            "reduced runs", "reduced simulated [s]"]
    rows = []
    for k, v in stages.items():
        (mr, ms), (rr, rs) = cell(k, "multibody"), cell(k, "reduced")
        share = f"{100.0 * ms / total_mb:.0f}" if total_mb > 0 else "-"
        rows.append([k, f"{v:.1f}", str(mr), f"{ms:.0f}", share, str(rr), f"{rs:.0f}"])
    sums = [sum(cell(k, kind)[i] for k in stages) for kind in ("multibody", "reduced")
            for i in (0, 1)]
    rows.append(["total", f"{sum(stages.values()):.1f}", str(sums[0]), f"{sums[1]:.0f}",
                 str(100 if total_mb > 0 else "-"), str(sums[2]), f"{sums[3]:.0f}"])
    return pipe_table(head, rows).splitlines()


_LARGE = Template(
    "The paper's question, which model for planning and control in reverse, asked of "
    "docking and parking on their own (reversing at large articulation), in absolute "
    "units, each class's findings from its own paired table ($correction over it, on the "
    "logs and their noise-free twins). With the tuned parameters:")
_FORM = Template(
    "With the truth's own parameters (the oracle rows, untuned: what each model's form "
    "allows; findings resolved after $correction on the logs):")


def large_articulation(r: CampaignResults) -> list[str]:
    """The answer for docking and parking on their own: tuned rows, then the oracle rows."""
    return articulation_lines(r.classes, r.form)


def articulation_lines(classes: dict[str, Any], forms: dict[str, Any]) -> list[str]:
    """:func:`large_articulation` from the tables' dicts (one truck or pooled)."""
    from artic.validation.criteria.multiplicity import CORRECTION

    tuned = (classes.get("reverse") or {}).get("answer") or []
    form = (forms.get("reverse") or {}).get("answer") or []
    if not tuned and not form:
        return []
    out = ["## Docking and parking on their own", ""]
    if tuned:
        out += [_LARGE.substitute(correction=CORRECTION), "", *[f"- {t}" for t in tuned], ""]
    if form:
        out += [_FORM.substitute(correction=CORRECTION), "", *[f"- {t}" for t in form], ""]
    return out


def class_sections(r: CampaignResults) -> list[str]:
    """The tables per manoeuvre class, and which classes carry the pooled findings."""
    return class_lines(r.classes, r.paired)


def class_lines(classes: dict[str, Any], paired: dict[str, pd.DataFrame]) -> list[str]:
    """:func:`class_sections` from the tables' dicts (one truck or pooled)."""
    from artic.validation.campaign.classes import CARRIED, class_markdown

    out: list[str] = []
    for d in ("forward", "reverse"):
        part = classes.get(d)
        if not part or part["table"].empty:
            continue
        if not out:
            tuning = ", ".join(classes.get("tuning", ())) or "none"
            out += ["## Per manoeuvre class", "",
                    "Each table of the direction again, one class at a time (a class the "
                    f"tuning fitted on is named so; tuning classes: {tuning}). A normalised "
                    "criterion divides by the class's own signals, so the absolute columns "
                    "beside it (steer_fb [deg], eps_p [m]) are the ones to compare across "
                    "classes. `table2_forward_by_class.md`, `table3_reverse_by_class.md`, "
                    "`paired_*_by_class.md`.", ""]
        pairs = paired.get(d)
        if pairs is not None and CARRIED in pairs:
            found = pairs[pairs["finding"].astype(bool)]
            lines = [f"- {rk.criterion}: {label(rk.a)} against {label(rk.b)}, carried by "
                     f"{getattr(rk, CARRIED)}" for rk in found.itertuples(index=False)]
            if lines:
                out += [f"The classes whose removal loses each pooled {d} finding:", "",
                        *lines, ""]
        out += [f"### {d.capitalize()}", "",
                class_markdown(part["table"], level=4), ""]
    return out


def form_sections(r: CampaignResults) -> list[str]:
    """Each model's error split into form (oracle row) and parameters (tuned row)."""
    return form_lines(r.form)


def form_lines(forms: dict[str, Any]) -> list[str]:
    """:func:`form_sections` from the tables' dict (one truck or pooled)."""
    out: list[str] = []
    for d in ("forward", "reverse"):
        part = forms.get(d)
        if not part:
            continue
        if not out:
            out += ["## Model form and parameters", "",
                    "Every model again, untuned, with the truth's own parameters (the "
                    "oracle rows: geometry, masses, centres of gravity, steering gear, and "
                    "the cornering stiffness equivalent to the truth's tyres; "
                    "`validation/campaign/oracle.py`). `MODEL form` is the oracle row minus "
                    "the floor, `MODEL parameters` the tuned row minus the oracle row, "
                    "paired per manoeuvre; the two add up to the tuned row's excess over "
                    "the floor.", ""]
        out += [f"### {d.capitalize()}", "", markdown(part["split"]), ""]
        pairs = part.get("pairs")
        crits = KEY_CRITERIA[d] + (("steer_fb",) if d == "reverse" else ("eps_gamma",))
        if pairs is not None and len(pairs):
            for c in crits:
                if c in set(pairs["criterion"]):
                    out.append(f"- {c}, the oracle rows: {ranking_text(pairs, c)}.")
            out.append("")
    return out


def template(name: str) -> jinja2.Template:
    """The Jinja2 template ``name`` beside this module: a report's prose, its numbers as data.

    Lines of blocks are trimmed (``trim_blocks``, ``lstrip_blocks``), so a ``{% if %}``
    on a line of its own leaves no blank line; ``fmt`` formats a number with a
    format spec (``{{ x | fmt(".0f") }}``), as an f-string does; a missing name
    is an error, not an empty string.
    """
    env = jinja2.Environment(trim_blocks=True, lstrip_blocks=True, autoescape=False,
                             undefined=jinja2.StrictUndefined, keep_trailing_newline=True)
    env.filters["fmt"] = format
    return env.from_string(resources.files(__package__).joinpath(name).read_text("utf-8"))


def render(r: CampaignResults) -> str:
    """The whole report as Markdown: ``report.md.j2`` with the results' numbers and tables."""
    sweep = None
    bounds = ""
    if r.sweep is not None and len(r.sweep):
        from artic.validation.runs.gainsweep import bounds_text, sweep_table

        sweep, bounds = markdown(sweep_table(r.sweep)), bounds_text(r.sweep.attrs["K_min"])
    tables = {
        "forward": markdown(r.forward),
        "forward_paper": markdown(versus_paper(r.forward, PAPER_FORWARD)),
        "reverse": markdown(r.reverse),
        "reverse_paper": markdown(versus_paper(r.reverse, PAPER_REVERSE)),
        "forward_vs_plant": (markdown(r.forward_vs_plant) if r.forward_vs_plant is not None
                             else None),
        "reverse_vs_plant": (markdown(r.reverse_vs_plant) if r.reverse_vs_plant is not None
                             else None),
        "efficiency": markdown(r.efficiency) if r.efficiency is not None else None,
        "sweep": sweep,
        "budget": "\n".join(budget_table(r.stages, r.budget)),
    }
    text = template("report.md.j2").render(
        r=r, stamp=datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        machine=platform.machine(), cores=os.cpu_count(), python=platform.python_version(),
        total=sum(r.stages.values()), headline_section=headline_section(r),
        headline=headline(r), discussion=discussion(r), tables=tables,
        sections=[*large_articulation(r), *class_sections(r), *form_sections(r),
                  *paired_sections(r), *noise_sections(r),
                  *measures.truck_lines(r.pbs, r.paired, r.departure)],
        per_load=[(load, markdown(table)) for load, table in r.per_load.items()],
        tuning_n=sum(len(part.get("logs", [])) for part in r.tuned.values()),
        tuning_logs="; ".join(f"{load}: {', '.join(part.get('logs', []))}"
                              for load, part in r.tuned.items()) or "none",
        tuning=_tuning_text(r), sweep_bounds=bounds, files=list(r.files.items()),
        recordings="recordings" in r.files)
    return text.removesuffix("\n")
