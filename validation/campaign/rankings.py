"""Rankings in words, stated only where they are findings.

The report's sentences about which model is closer come from here. A pair
of models is ranked only where the paired table marks the ranking a finding
(:func:`artic.validation.campaign.findings.mark`: resolved after Holm's
correction over the table, on the logs and on their noise-free twins); a
table without that mark ranks where the correction resolves it, and one
without a correction where the interval excludes zero. Otherwise the text
says why the pair is not ranked, with the difference and its interval, so
that no sentence ranks what the data do not separate.
"""

from __future__ import annotations

import pandas as pd

from artic.validation.criteria.statistics import Interval, format_ci
from artic.validation.review.tables import UNITS

FLOOR = "floor"
"""The reference row: the truth itself, without its random processes."""


ORACLE = "-oracle"
"""The suffix of a model's row run with the truth's own parameters (``kin-oracle``)."""


def label(model: str) -> str:
    """A model's name in prose: its registry label (KIN, STM, MBD, floor, or a registered one's).

    A row with the truth's own parameters is its model's label and ``-oracle`` (``KIN-oracle``).
    """
    from artic.validation import models

    if model.endswith(ORACLE):
        return models.label(model.removesuffix(ORACLE)) + ORACLE
    return models.label(model)


def _unit(criterion: str) -> str:
    unit = UNITS.get(criterion, "")
    return {"%": " points", "": "", "-": ""}.get(unit, f" {unit}")  # "-": a pure number


def _rows(pairs: pd.DataFrame, criterion: str, exclude: tuple[str, ...]) -> pd.DataFrame:
    if pairs is None or pairs.empty:
        return pd.DataFrame()
    keep = (pairs["criterion"] == criterion) & ~pairs["a"].isin(exclude) \
        & ~pairs["b"].isin(exclude)
    return pairs[keep]


def ranked(r) -> bool:
    """Whether a paired table's row states a ranking: a finding where the table marks them."""
    if hasattr(r, "finding"):
        return bool(r.finding)
    if hasattr(r, "resolved_adj"):
        return bool(r.resolved_adj)
    return bool(r.resolved)


def why_not(r) -> str:
    """Why a row that :func:`ranked` refuses is not a ranking, in a few words."""
    if str(getattr(r, "test", "")).startswith("not testable"):
        return r.test  # "not testable at n = ... (why)": its interval stands, no test
    if not r.resolved:
        return "not resolved"
    if hasattr(r, "resolved_adj") and not r.resolved_adj:
        return "not resolved after the correction"
    return "not a finding: the noise-free twins do not hold it"


def verdicts(pairs: pd.DataFrame, criterion: str,
             exclude: tuple[str, ...] = (FLOOR,)) -> list[str]:
    """One phrase per pair of models: who is lower and by how much, or why not ranked."""
    out = []
    unit = _unit(criterion)
    for r in _rows(pairs, criterion, exclude).itertuples(index=False):
        if ranked(r):
            # The difference as higher minus lower, a positive interval.
            low, high = (r.a, r.b) if r.diff < 0 else (r.b, r.a)
            s = -1.0 if r.diff < 0 else 1.0
            lo, hi = sorted((s * r.diff_lo, s * r.diff_hi))
            gap = format_ci(Interval(abs(r.diff), lo, hi, int(r.n), ""))
            out.append(f"{label(low)} below {label(high)} by {gap}{unit}")
        else:
            gap = format_ci(Interval(r.diff, r.diff_lo, r.diff_hi, int(r.n), ""))
            out.append(f"{label(r.a)} and {label(r.b)} {why_not(r)} ({label(r.a)} - "
                       f"{label(r.b)} = {gap}{unit})")
    return out


def lowest(pairs: pd.DataFrame, criterion: str,
           exclude: tuple[str, ...] = (FLOOR,)) -> str | None:
    """The model ranked lower than every other one (:func:`ranked`), if there is one."""
    rows = _rows(pairs, criterion, exclude)
    if rows.empty:
        return None
    models = list(dict.fromkeys([*rows["a"], *rows["b"]]))
    for m in models:
        mine = rows[(rows["a"] == m) | (rows["b"] == m)]
        if len(mine) == len(models) - 1 and all(
                ranked(r) and (r.a if r.diff < 0 else r.b) == m
                for r in mine.itertuples(index=False)):
            return m
    return None


def ranking_text(pairs: pd.DataFrame, criterion: str,
                 exclude: tuple[str, ...] = (FLOOR,)) -> str:
    """The paired verdicts on ``criterion`` as one clause, with the lowest model if resolved."""
    parts = verdicts(pairs, criterion, exclude)
    if not parts:
        return f"no pair of models has {criterion} on the same manoeuvres"
    best = lowest(pairs, criterion, exclude)
    n_models = len(set(_rows(pairs, criterion, exclude)[["a", "b"]].to_numpy().ravel()))
    if best is not None:
        tail = (f"; {label(best)} is the lowest, a finding against every other model"
                if n_models > 2 else "")
    elif n_models > 2:
        tail = "; no model is lowest against every other by findings"
    else:
        tail = ""
    return "; ".join(parts) + tail


def _versus_floor(pairs: pd.DataFrame | None, model: str, criterion: str):
    """The paired table's row of ``model`` against the floor on ``criterion``, if any."""
    if pairs is None or pairs.empty:
        return None
    keep = (pairs["criterion"] == criterion) & (
        ((pairs["a"] == model) & (pairs["b"] == FLOOR))
        | ((pairs["a"] == FLOOR) & (pairs["b"] == model)))
    rows = list(pairs[keep].itertuples(index=False))
    return rows[0] if rows else None


def excess_text(excess: pd.DataFrame, criterion: str, pairs: pd.DataFrame | None = None) -> str:
    """Each model's paired excess over the floor on ``criterion``, and whether it is above zero.

    With ``pairs`` (the paired table, marked), a model counts as above or
    below the floor only where its comparison with the floor is a finding
    (:func:`ranked`); without, where the excess's interval excludes zero.
    """
    if excess is None or excess.empty or criterion not in excess:
        return ""
    unit = _unit(criterion)
    parts: list[str] = []
    groups: dict[str, list[str]] = {"above": [], "unresolved": [], "below": []}
    for m, row in excess.iterrows():
        iv = Interval(float(row[criterion]), float(row[f"{criterion}_lo"]),
                      float(row[f"{criterion}_hi"]), int(row["n"]), "")
        parts.append(f"{label(m)} {format_ci(iv)}{unit}")
        versus = _versus_floor(pairs, m, criterion)
        resolved = ranked(versus) if versus is not None else iv.excludes(0.0)
        side = "unresolved" if not resolved else "above" if iv.mean > 0 else "below"
        groups[side].append(label(m))
    if len(groups["above"]) == len(parts):
        verdict = "each resolved above the floor"
    elif len(groups["unresolved"]) == len(parts):
        verdict = "none resolved from the floor"
    else:
        words = {"above": "resolved above the floor", "unresolved": "not resolved from it",
                 "below": "resolved below it"}
        verdict = "; ".join(f"{' and '.join(g)} {words[k]}" for k, g in groups.items() if g)
    return f"{', '.join(parts)} ({verdict})"
