"""Tables and findings per manoeuvre class, the classes carrying a finding, docking and parking.

A direction's pooled table mixes manoeuvres of different kinds: forward,
constant steers, the slalom and the figure-8; reverse, ramp steers, docking
and parking. A normalised criterion (``J_steer``, ``eps_n``) divides by a mean
of the manoeuvre's own signals, so a class steered gently weighs more than its
correction does; and a pooled finding may come from one class alone. Here:

- :func:`by_class`: the summary table (:func:`artic.validation.review.tables.summary`)
  of each class on its own, stacked with a ``class`` column; the classes the
  tuning fitted on are named so (``constant-steer (tuning class)``): their
  validated logs are of the tuning logs' family. The pooled mean of a
  criterion is the mean of the class means weighted by the class counts;
- :func:`paired_by_class`: the paired table and its findings
  (:func:`artic.validation.campaign.findings.mark`) of each class, Holm's
  correction over the class's own table;
- :func:`carried_by`: for each pooled finding, the classes whose removal
  loses it (the paired table and its findings computed again without the
  class, logs and twins alike);
- :func:`answer`: the paper's question, "which model for planning and
  control", for docking and for parking on their own, in absolute units
  (:data:`ANSWER_CRITERIA`), from the class's own findings, in sentences
  made from a template fed with the computed numbers.

A p value that is NaN ("not testable at this n") never makes a finding: the
correction leaves it NaN, and a NaN is not below the level.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterable
from string import Template

import pandas as pd

from artic.validation.campaign import findings
from artic.validation.campaign.rankings import label, ranking_text
from artic.validation.criteria.statistics import format_ci
from artic.validation.review.tables import UNITS, markdown, paired_table, summary

CLASSES = ("constant-steer", "slalom", "figure-8", "swept-sine", "ramp-steer-reverse", "docking",
           "parking")
"""The manoeuvre classes of the test matrix, in table order."""

CLASS = "class"
"""The column that names a row's class."""

CARRIED = "carried_by"
"""The column of a pooled paired table naming the classes that carry each finding."""

LARGE_ARTICULATION = ("docking", "parking")
"""The classes the paper's question is about: reversing at large articulation."""

ANSWER_CRITERIA = {
    "steer_fb": "the steering correction the feedback added (road-wheel angle, RMS)",
    "eps_p": "the lateral position error of the two sensor points",
    "eps_gamma": "the articulation error",
}
"""The absolute criteria the answer for docking and parking is stated in: control
needs the correction small, planning the path and the articulation close. (The
dock errors ``dock_*`` are signed, so their means are biases, not errors to rank:
they stay in the tables.)"""


def tuning_classes(tuning_logs: Iterable[str]) -> tuple[str, ...]:
    """The classes of the tuning manoeuvres (by their names in the test matrix)."""
    from artic.validation.synthetic.testmatrix import MATRIX

    names = set(tuning_logs)
    return tuple(dict.fromkeys(m.kind for m in MATRIX if m.name in names))


def class_name(kind: str, tuning: Iterable[str] = ()) -> str:
    """A class as the tables name it: ``KIND (tuning class)`` where tuning fitted on it."""
    return f"{kind} (tuning class)" if kind in set(tuning) else kind


def classes_of(metrics: pd.DataFrame, direction: str) -> list[str]:
    """The classes of ``direction`` that ``metrics`` has, in :data:`CLASSES` order, then others."""
    if "manoeuvre" not in metrics:
        return []
    present = list(dict.fromkeys(metrics.loc[metrics["direction"] == direction, "manoeuvre"]))
    return [k for k in CLASSES if k in present] + [k for k in present if k not in CLASSES]


def _of(metrics: pd.DataFrame | None, kind: str) -> pd.DataFrame | None:
    return None if metrics is None else metrics[metrics["manoeuvre"] == kind]


def by_class(metrics: pd.DataFrame, direction: str, tuning: Iterable[str] = (),
             summarise: Callable[[pd.DataFrame, str], pd.DataFrame] = summary) -> pd.DataFrame:
    """:func:`~artic.validation.review.tables.summary` of each class, stacked.

    ``summarise`` makes each class's table: ``summary`` for one truck, or
    :func:`~artic.validation.review.tables.pooled` over several (``metrics``
    with a ``seed`` column).

    Returns
    -------
    DataFrame
        Indexed by model, with ``class`` first (named by :func:`class_name`), then
        the summary's columns; a criterion a class lacks is NaN there.
    """
    parts = []
    for kind in classes_of(metrics, direction):
        t = summarise(_of(metrics, kind), direction)
        if len(t):
            t.insert(0, CLASS, class_name(kind, tuning))
            parts.append(t)
    return pd.concat(parts) if parts else pd.DataFrame()


def class_markdown(table: pd.DataFrame, level: int = 2) -> str:
    """A :func:`by_class` table in Markdown: one section per class, headed at ``level``."""
    if table.empty:
        return "(no class has results)"
    out = []
    for name, g in table.groupby(CLASS, sort=False):
        g = g.drop(columns=CLASS).dropna(axis=1, how="all")
        out += [f"{'#' * level} {name}", "", markdown(g), ""]
    return "\n".join(out)


Pairing = Callable[[pd.DataFrame, str], pd.DataFrame]
"""A paired table of a direction: ``paired_table`` (one truck) or ``pooled_paired`` (several)."""


def paired_by_class(metrics: pd.DataFrame, twins: pd.DataFrame | None, direction: str,
                    tuning: Iterable[str] = (), pair: Pairing = paired_table
                    ) -> dict[str, pd.DataFrame]:
    """Each class's paired table, Holm over its own rows, marked for findings; by class name."""
    out = {}
    for kind in classes_of(metrics, direction):
        twin = _of(twins, kind)
        pairs = findings.mark(pair(_of(metrics, kind), direction),
                              pair(twin, direction) if twin is not None else None)
        if len(pairs):
            out[class_name(kind, tuning)] = pairs
    return out


def carried_by(pairs: pd.DataFrame, metrics: pd.DataFrame, twins: pd.DataFrame | None,
               direction: str, tuning: Iterable[str] = (), pair: Pairing = paired_table
               ) -> pd.DataFrame:
    """``pairs`` (a pooled paired table, marked) with ``carried_by``: leave one class out.

    For every class of the direction, the paired table and its findings are
    computed again on the other classes' manoeuvres (logs and twins alike,
    Holm over the smaller table); a finding of ``pairs`` that is no longer one
    is carried by that class. ``carried_by`` names those classes (``;``
    between them), ``none alone`` where no single class's removal loses the
    finding, and is empty for rows that are not findings. With one class only,
    that class carries every finding.
    """
    out = pairs.copy()
    out[CARRIED] = ""
    if out.empty or "finding" not in out or not out["finding"].astype(bool).any():
        return out
    kinds = classes_of(metrics, direction)
    keys = ["criterion", "a", "b"]
    if pair is paired_table:  # read for their findings alone: no interval that cannot resolve
        pair = functools.partial(paired_table, intervals=False)
    found = out["finding"].astype(bool)
    carriers: dict[int, list[str]] = {i: [] for i in out.index[found]}
    for kind in kinds:
        rest = metrics[metrics["manoeuvre"] != kind]
        rest_twins = None if twins is None else twins[twins["manoeuvre"] != kind]
        again = findings.mark(pair(rest, direction),
                              pair(rest_twins, direction)
                              if rest_twins is not None else None) if len(kinds) > 1 else None
        held = set() if again is None or again.empty else {
            tuple(r) for r in again.loc[again["finding"].astype(bool), keys].itertuples(
                index=False)}
        for i in carriers:
            if tuple(out.loc[i, keys]) not in held:
                carriers[i].append(class_name(kind, tuning))
    for i, names in carriers.items():
        out.loc[i, CARRIED] = "; ".join(names) if names else "none alone"
    return out


_CLASS_SENTENCE = Template(
    "**$kind** ($n $manoeuvres, reverse under the feedback): $criteria.")
_CRITERION_CLAUSE = Template("$what, $criterion [$unit]: $values; $ranking")


def _values(table: pd.DataFrame, criterion: str) -> str:
    parts = []
    for model, row in table.iterrows():
        if criterion not in row or not math.isfinite(float(row[criterion])):
            continue
        count = row.get(f"{criterion}_n")
        n = int(count) if count is not None and pd.notna(count) else int(row["n"])
        mean, lo, hi = (float(row[k]) for k in (criterion, f"{criterion}_lo",
                                                 f"{criterion}_hi"))
        parts.append(f"{label(str(model))} {format_ci(mean, lo, hi, n)}")
    return ", ".join(parts)


def answer(table: pd.DataFrame, pairs: dict[str, pd.DataFrame],
           kinds: tuple[str, ...] = LARGE_ARTICULATION, tuning: Iterable[str] = (),
           exclude: tuple[str, ...] = (findings.FLOOR,)) -> list[str]:
    """The paper's question for each class of ``kinds`` on its own, one paragraph each.

    Parameters
    ----------
    table : DataFrame
        :func:`by_class` of the reverse direction.
    pairs : dict
        :func:`paired_by_class` of the reverse direction.
    kinds : tuple of str
        The classes to answer for.
    tuning : iterable of str
        The tuning classes (for the class names).
    exclude : tuple of str
        Rows the rankings leave out (the floor; its values are still listed).

    Returns
    -------
    list of str
        One sentence per class that has results: each criterion of
        :data:`ANSWER_CRITERIA` it has, every row's mean with its interval, and
        the ranking the class's own findings state (or why none).
    """
    out = []
    for kind in kinds:
        name = class_name(kind, tuning)
        if table.empty or name not in set(table[CLASS]):
            continue
        t = table[table[CLASS] == name]
        p = pairs.get(name)
        clauses = []
        for c, what in ANSWER_CRITERIA.items():
            if c not in t or not t[c].notna().any():
                continue
            ranking = ranking_text(p, c, exclude) if p is not None and len(p) else "no pairs"
            clauses.append(_CRITERION_CLAUSE.substitute(
                what=what, criterion=c, unit=UNITS.get(c, ""), values=_values(t, c),
                ranking=ranking))
        if clauses:
            n = int(t["n"].max())
            out.append(_CLASS_SENTENCE.substitute(
                kind=kind, n=n, manoeuvres="manoeuvre" if n == 1 else "manoeuvres",
                criteria="; ".join(clauses)))
    return out
