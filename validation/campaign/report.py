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

import numpy as np
import pandas as pd

from artic.validation.campaign.tables import PAPER_FORWARD, PAPER_REVERSE, markdown, versus_paper


@dataclass
class CampaignResults:
    """What the report is made from."""

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


FLOOR = "floor"
"""The reference row of the truth itself (see :mod:`artic.validation.campaign.main`)."""


def _rank(table: pd.DataFrame, col: str) -> list[tuple[str, float]]:
    s = table.drop(index=FLOOR, errors="ignore")[col].dropna().sort_values()
    return list(zip(s.index, s.to_numpy(), strict=True))


def _gaps(table: pd.DataFrame, col: str = "eps_n") -> str:
    """Each model's ``col`` above the floor row, as text."""
    if FLOOR not in table.index:
        return ""
    floor = float(table.loc[FLOOR, col])
    return ", ".join(f"{m.upper()} {float(table.loc[m, col]) - floor:+.3g}"
                     for m, _ in _rank(table, col))


def _ranking_text(table: pd.DataFrame, col: str, unit: str) -> str:
    return ", then ".join(f"{m.upper()} ({v:.3g} {unit})" for m, v in _rank(table, col))


def discussion(r: CampaignResults) -> list[str]:
    """The paragraphs that compare models and set the results against the paper's."""
    out = []
    fwd, rev = r.forward, r.reverse
    if len(fwd):
        best = _rank(fwd, "eps_n")[0][0]
        text = (f"**Forward.** By eps_n the ranking is {_ranking_text(fwd, 'eps_n', '%')}; by "
                f"eps_p it is {_ranking_text(fwd, 'eps_p', 'm')}. {best.upper()} is the most "
                "accurate forward model here; the paper found MBD best (4.83 %), then STM "
                "(5.9 %) and KIN (9.26 %).")
        f_fit = [p["fitted"]["stm"]["f"] for p in r.tuned.values() if "stm" in p["fitted"]]
        truth = next((p["truth"] for p in r.tuned.values() if p["truth"]), None)
        if "mbd" in fwd.index and best != "mbd" and f_fit and truth:
            text += (" The multibody model's tyres are not tuned (the paper, too, tuned its "
                     "MBD only a little), while the truth's lateral stiffness is "
                     f"{truth['LKY']:.2f} times the tyre file's; the STM's fitted f ("
                     + " and ".join(f"{f:.3g}" for f in f_fit) + " /rad against the "
                     "presets' 6) absorbs such a difference, the plant's steering ratio only "
                     "partly.")
        out.append(text)
    if len(rev):
        best = _rank(rev, "eps_n")[0][0]
        steer = _rank(rev, "J_steer")
        out.append(
            f"**Reverse.** By eps_n the ranking is {_ranking_text(rev, 'eps_n', '%')}, so "
            f"{best.upper()} is the most accurate reversing model here (the paper: STM, "
            f"27.7 %). The steering-effort ranking J_steer is "
            f"{_ranking_text(rev, 'J_steer', '%')}: {steer[0][0].upper()} needs the least "
            "correction from the harness to follow the measured articulation (the paper: STM "
            "21.15 %, MBD 26.14 %, KIN 26.96 %). A model whose articulation dynamics match "
            "the truck's needs little feedback, so J_steer ranks the models' reversing "
            "dynamics directly, independent of the gain's size as long as the loop is stable.")
    if len(fwd) and set(fwd.index) & set(PAPER_FORWARD.index):
        vs = versus_paper(fwd, PAPER_FORWARD)
        ratio = vs[[c for c in vs.columns if c.endswith("ratio")]]
        out.append(
            "**Against the paper's Table 2.** Our forward errors are "
            f"{np.nanmin(ratio.to_numpy()):.2g} to {np.nanmax(ratio.to_numpy()):.2g} times the "
            "paper's. The measurement here is synthetic: the "
            f"{r.truth} truth (see `validation/synthetic/truth.py`"
            + ("; a model of its own, with TMeasy tyres and a compliant steering column, "
               "not artic's plant" if r.truth == "independent" else "; artic's plant")
            + ") with modelled sensors. What real logs add and these lack: a real tyre's "
            "temperature "
            "dependence, frame compliance, grip variation and GNSS multipath. The "
            "position error eps_p of open-loop forward runs grows with the drift of heading, "
            "which those effects dominate on a real truck; it is therefore the criterion "
            "furthest from the paper's.")
    for name, table in (("forward", fwd), ("reverse", rev)):
        if len(table) and FLOOR in table.index:
            out.append(
                f"**Above the floor, {name}.** The floor row is the truth that made the "
                "logs, without its random processes, through the same harness against the "
                f"same logs: eps_n {float(table.loc[FLOOR, 'eps_n']):.3g} %. It is what "
                "sensor noise, the steering column's drift and the clock skew leave however "
                "good a model is. Each model's eps_n above it, its model-form error "
                f"in percentage points: {_gaps(table)}.")
    for name, table, paper in (("forward", r.forward_vs_plant, "Table 2"),
                               ("reverse", r.reverse_vs_plant, "Table 3")):
        if table is not None and len(table):
            out.append(
                f"**Against the plant as reference, {name}.** With the plant's runs of the "
                "same manoeuvres as the reference (its " + paper + " columns in "
                f"`{'table2' if name == 'forward' else 'table3'}_vs_plant`), the ranking by "
                f"eps_n is {_ranking_text(table, 'eps_n', '%')}" + (
                    f" and by J_steer {_ranking_text(table, 'J_steer', '%')}"
                    if name == "reverse" else "") + ". This reference has no sensor noise "
                "and shares the reduced models' tuned steering map's inputs, so it isolates "
                "the difference of the model equations from the plant's.")
    if len(rev) and set(rev.index) & set(PAPER_REVERSE.index):
        vs = versus_paper(rev, PAPER_REVERSE)
        out.append(
            "**Against the paper's Table 3.** Reverse eps_n here is "
            + ", ".join(f"{m.upper()} {vs.loc[m, 'eps_n']:.3g} % (paper "
                        f"{vs.loc[m, 'eps_n (paper)']:.3g} %)" for m in vs.index)
            + ". The synthetic docking and parking runs come from a driver model that steers "
            "smoothly and stops at the dock; the paper's experienced driver shuffled and "
            "corrected more, and its reverse runs reached 40 to 45 deg of articulation on "
            "average. Reverse yaw rates are small, so eps_n, which divides by them, is large "
            "in both.")
    if r.efficiency is not None and "ratio_to_mbd" in r.efficiency:
        e = r.efficiency
        parts = [f"{m.upper()}/MBD = {e.loc[m, 'ratio_to_mbd']:.3g} "
                 f"(paper {e.loc[m, 'paper_ratio']:.2g})" for m in e.index if m != "mbd"]
        out.append(
            "**Efficiency.** Wall time per simulated second, as ratios to the multibody "
            f"plant: {'; '.join(parts)}. The reduced models are compiled (numba) and the "
            "plant steps MuJoCo with a compiled tyre callback, so the ratios compare "
            "implementations as much as models; the paper's figures (KIN 90 % and STM 60 % "
            "faster) compare its own implementations.")
    return out


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
                    f"{m.upper()} i_s {fit['i_s']:.4g} ({100 * (fit['i_s'] / i_s_true - 1):+.2f} "
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
            "The independent truth is not artic's plant: its tyres are TMeasy, another family "
            "than the plant's PAC2002, fitted to the same tyre files (and its trailer tyres "
            "another construction, 5 /rad against 6), its twin tyres are two tyres, and its "
            "steering is a torsion bar with free play and a lagged hydraulic assist, whose "
            "right wheel follows through a compliant tie rod; its zero drifts, and its "
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


def render(r: CampaignResults) -> str:
    """The whole report as Markdown."""
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    total = sum(r.stages.values())
    lines = [
        "# artic validation campaign", "",
        f"{stamp}; {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}; artic {r.version} (code {r.fingerprint}); seed "
        f"{r.seed}; models {', '.join(r.models)}; reversing feedback K = {r.gain:g}; "
        f"wall time {total:.0f} s.", "",
        "## Discussion", "", *[p + "\n" for p in discussion(r)],
        "## Forward driving (the paper's Table 2)", "",
        "Mean over the forward manoeuvres not used for tuning. Forward, the harness's "
        "feedback is off: the models run open loop from the measured steering and speed.", "",
        markdown(r.forward), "",
        "Beside the paper's values:", "", markdown(versus_paper(r.forward, PAPER_FORWARD)), "",
        "## Reverse driving (the paper's Table 3)", "",
        f"Mean over all reverse manoeuvres, closed loop with K = {r.gain:g}.", "",
        markdown(r.reverse), "",
        "Beside the paper's values:", "", markdown(versus_paper(r.reverse, PAPER_REVERSE)), "",
    ]
    if r.forward_vs_plant is not None:
        lines += ["## Against the plant as reference", "",
                  "KIN and STM against the plant's runs of the same manoeuvres, through the "
                  "same harness: forward open loop, reverse closed loop.", "",
                  "Forward (Table 2 columns):", "", markdown(r.forward_vs_plant), ""]
    if r.reverse_vs_plant is not None:
        lines += ["Reverse (Table 3 columns):", "", markdown(r.reverse_vs_plant), ""]
    for load, table in r.per_load.items():
        lines += [f"### {load}", "", markdown(table), ""]
    lines += ["## Tuning", "",
              "Each load condition fitted on its own 4 forward tuning manoeuvres (8 in "
              "all, as in the paper) by the normalised criteria of eq. (9) (see "
              "`validation/tuning.py`).", "", *_tuning_text(r), ""]
    if r.efficiency is not None:
        lines += ["## Computational efficiency", "",
                  "Each model on the same logs in one process, stepping only (model "
                  "construction apart); the fastest of repeated passes.", "",
                  markdown(r.efficiency), ""]
    if r.sweep is not None and len(r.sweep):
        from artic.validation.campaign.gainsweep import sweep_table

        lines += ["## Feedback gain sweep", "",
                  f"Reverse manoeuvres at each K; the loop is stable only above "
                  f"K_min = L1 / (L2 - L1c) = {r.sweep.attrs['K_min']:.3g} (the row marked "
                  "'bound'). See `plots/gain_sweep.png`.", "",
                  markdown(sweep_table(r.sweep)), ""]
    lines += ["## Wall time by stage", "",
              "| stage | wall [s] |", "|---|---|",
              *[f"| {k} | {v:.1f} |" for k, v in r.stages.items()],
              f"| total | {total:.1f} |", ""]
    if r.files:
        lines += ["## Files", "", *[f"- `{v}`: {k}" for k, v in r.files.items()], ""]
    if "recordings" in r.files:
        lines += ["## Recordings", "",
                  "One Rerun recording per validated manoeuvre, and `campaign.rrd` with "
                  "this report and every criterion per manoeuvre. Open one with "
                  "`rerun recordings/NAME.rrd`; the viewer opens on the yard (the measured "
                  "combination in white, KIN blue, STM green, and the plant in orange, drawn "
                  "from its own MuJoCo bodies with wheels that steer and spin and its tyre "
                  "forces as arrows) beside the steering, speed, yaw-rate, lateral-velocity, "
                  "articulation and running-error plots, angles in degrees, and the plant's "
                  "wheel loads, slip angles and steering torque. The time panel switches "
                  "between time and travelled distance (`distance_cm`).", ""]
    return "\n".join(lines)
