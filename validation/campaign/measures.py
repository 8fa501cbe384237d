"""The report's sections on what heavy-vehicle engineers measure, per truck and over trucks.

Three families beside the paper's criteria, each read from the tables the
campaign already wrote (nothing is computed again here):

- the **low-speed performance measures** of the PBS low-speed turn
  (:mod:`artic.validation.pbs.trucks`: ``pbs_truck.csv`` per truck,
  ``pbs_trucks.md`` over trucks with intervals and Holm's correction);
- **ISO/TS 18571's rating** of each model's signals against the log (the
  ``iso_gap*`` columns, :mod:`artic.validation.criteria.rating`), whose paired
  comparisons form a Holm family of their own
  (:func:`artic.validation.review.tables.corrected`);
- the swept sine's **frequency response** (:mod:`artic.validation.campaign.frequency`:
  ``frequency_departure.csv``).

One truck gives no interval over trucks: its section says so and points at
``--seeds``; the pooled report carries the intervals.
"""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from artic.validation.campaign.rankings import ranking_text
from artic.validation.criteria.iso18571 import GRADES
from artic.validation.review.frequency import GAIN_BOUND, PHASE_BOUND
from artic.validation.review.tables import markdown

RATING = "iso_gap"
"""The rating of a run as a whole: the mean of its signals' ``1 - R``."""

_GRADES = ", ".join(f"{name} above {bound:g}" for bound, name in GRADES if math.isfinite(bound))

_PBS_INTRO = (
    "The PBS low-speed turn (`docs/guide/pbs.md`) driven by each model built from the "
    "loaded preset and by this truck's truth, as the campaign's `pbs_truck.csv` holds it: "
    "each measure's value and, in brackets, its error against the truth, to the "
    "centimetre [m]. One truck gives no interval; `artic campaign --seeds N` pools the "
    "trucks, with each model's mean error, its 95 % interval over trucks and the paired "
    "comparisons after Holm's correction (`pbs_trucks.md`).")

_RATING_INTRO = (
    "ISO/TS 18571's objective rating of each model's yaw rates, lateral velocities and "
    "articulation against the log's, as the shortfall `1 - R` per signal (`iso_gap_*`) "
    "and its mean over the five (`iso_gap`), with their intervals in the tables above; "
    f"the standard grades `R` {_GRADES}, poor below (`docs/guide/rating.md`). Their "
    "paired comparisons are a Holm family of their own, so adding them leaves the "
    "distance criteria's findings as they were.")

_FREQUENCY_INTRO = (
    "The swept sine (forward, open loop: reversing is open-loop unstable, so it has no "
    "frequency response of its own here): per signal, the lowest band [Hz] where each "
    f"model's gain departs from the truth's by more than {GAIN_BOUND:.0%} or its phase by "
    f"more than {PHASE_BOUND:g} deg (-: within both over the whole sweep; "
    "`frequency_response.csv` has every band; `docs/guide/rating.md`).")


def pbs_table(trucks: pd.DataFrame) -> str:
    """One truck's measures as Markdown: a row per model, ``value (error)`` per measure.

    Parameters
    ----------
    trucks : DataFrame
        ``pbs_truck.csv``'s rows (:func:`artic.validation.pbs.trucks.truck_table`).

    Returns
    -------
    str
        The table, the truth's values in a row of their own; with more than
        one load, each row names its load.
    """
    cells: dict[str, dict[str, str]] = {}
    loads = set(trucks["load"]) if "load" in trucks else set()
    for row in trucks.itertuples(index=False):
        head = f"{row.measure} [{row.unit}]"
        of = f", {row.load}" if len(loads) > 1 else ""
        cells.setdefault(f"{row.model}{of}", {})[head] = f"{row.value:.2f} ({row.error:+.2f})"
        cells.setdefault(f"truth{of}", {})[head] = f"{row.truth:.2f}"
    table = pd.DataFrame.from_dict(cells, orient="index")
    table.index.name = "model"
    return markdown(table)


def truck_lines(pbs: pd.DataFrame | None, paired: dict[str, pd.DataFrame],
                departure: pd.DataFrame | None) -> list[str]:
    """The per-truck report's section: the measures, the rating's findings, the departure.

    Parameters
    ----------
    pbs : DataFrame or None
        ``pbs_truck.csv``, or None where the campaign did not drive the turn.
    paired : dict of str to DataFrame
        The paired comparisons by direction (``forward``, ``reverse``), with
        the rating's rows among them.
    departure : DataFrame or None
        ``frequency_departure.csv`` (index model, a column per signal), or None
        without a swept sine.

    Returns
    -------
    list of str
        Markdown lines; empty when there is nothing of the three.
    """
    out: list[str] = []
    if pbs is not None and len(pbs):
        out += ["## Low-speed performance measures", "", _PBS_INTRO, "", pbs_table(pbs), ""]
    rated = _rating_clauses(paired)
    if rated:
        out += ["## ISO/TS 18571 rating", "", _RATING_INTRO, "", *rated, ""]
    if departure is not None and len(departure):
        out += ["## Frequency response", "", _FREQUENCY_INTRO, "",
                markdown(departure.map(_band).rename_axis("model")), ""]
    return out


def pooled_lines(out_dir: Path, paired: dict[tuple[str, str], pd.DataFrame]) -> list[str]:
    """The pooled report's section: the measures, the rating and the departure over trucks.

    Parameters
    ----------
    out_dir : Path
        The pooled campaign's folder, where ``pbs_trucks.md`` and
        ``frequency_departure.csv`` were written.
    paired : dict of (str, str) to DataFrame
        The pooled paired comparisons by (reference, direction).

    Returns
    -------
    list of str
        Markdown lines; empty when there is nothing of the three.
    """
    out: list[str] = []
    pbs = Path(out_dir) / "pbs_trucks.md"
    if pbs.is_file():
        body = pbs.read_text(encoding="utf-8").split("\n", 1)[1].strip()
        out += ["## Low-speed performance measures, over trucks", "", body, ""]
    rated = _rating_clauses({d: p for (ref, d), p in paired.items() if ref == "logs"})
    if rated:
        out += ["## ISO/TS 18571 rating, over trucks", "", _RATING_INTRO, "", *rated, ""]
    dep = Path(out_dir) / "frequency_departure.csv"
    if dep.is_file():
        table = pd.read_csv(dep, index_col=0)
        out += ["## Frequency response, over trucks", "",
                _FREQUENCY_INTRO.replace("model's gain", "model's mean gain"), "",
                markdown(table.map(_band).rename_axis("model")), ""]
    return out


def _rating_clauses(paired: dict[str, pd.DataFrame]) -> list[str]:
    """Per direction, the rating's paired verdicts (its findings after its own correction)."""
    out = []
    for d in ("forward", "reverse"):
        pairs = paired.get(d)
        if pairs is None or not len(pairs) or RATING not in set(pairs["criterion"]):
            continue
        out.append(f"- **{d.capitalize()}, {RATING}**: {ranking_text(pairs, RATING)}.")
    return out


def _band(f: float) -> str:
    """A band's centre to three significant digits, or "-" within the bound over the sweep."""
    return "-" if not math.isfinite(f) else f"{f:.3g}"
