"""Every two docking controllers over the same starts, after Holm's correction.

Two controllers driven from the same start (scenario, vehicle, seed: the same
initial pose and the same sensor noise) are a pair. For each two controllers:

- **success** by McNemar's exact test (:func:`mcnemar_p`): only the discordant
  starts (one docked, the other did not) carry evidence;
- **the final |lateral| [cm] and |heading| [deg] errors**, and with
  ``artic dock`` the **time** [s], over the starts both *finished* (came to rest
  at the dock: docked, or stopped outside the gates; a jackknife has no final
  error) by the mean paired difference ``a - b`` with its 95 % interval and the
  p value of the campaign's calibrated paired test
  (:func:`artic.validation.criteria.multiplicity.paired_test`: the sign-flip test
  and Hall's t; NaN, and ``test`` says why, where the differences are too skewed
  for any test at their number).

Holm's correction runs over the whole family the call makes (every group,
pair and metric; the rows not testable left out) and gives ``p_holm``; a
comparison is a ``finding`` only where ``p_holm < 0.05`` (:data:`ALPHA`). The
benchmark (``artic dock``, :func:`compare` without ``by``) pools every
scenario and vehicle; a sweep compares at each level, scenario and vehicle
(:mod:`artic.validation.docking.sweep`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd
from scipy import stats

from artic.validation.criteria.multiplicity import ALPHA, holm, paired_test
from artic.validation.criteria.statistics import paired

ERRORS = (("lateral_cm", "lateral_error_m", 100.0), ("heading_deg", "heading_error_deg", 1.0))
"""The final errors compared: name, ``dock.csv``'s column, scale of the magnitude."""

TIME = ("time_s", "time_s", 1.0)
"""The time to dock [s], compared by ``artic dock`` beside :data:`ERRORS`."""

KEY = ("scenario", "vehicle", "seed")
"""What makes two runs the same start."""

COLUMNS = ["a", "b", "metric", "pairs", "a_only", "b_only", "difference", "low", "high",
           "test", "p", "p_holm", "finding"]
"""The comparison's columns, after the group's (:func:`compare`'s ``by``)."""

_WORDS = {"lateral_cm": ("cm", "ends less off the line than"),
          "heading_deg": ("deg", "ends less askew than"),
          "time_s": ("s", "docks sooner than")}


def mcnemar_p(a_only: int, b_only: int) -> float:
    """McNemar's exact two-sided p value from the discordant pairs [-].

    Under "both dock equally often" each discordant start is ``a``'s with
    probability 1/2: the binomial test of ``a_only`` of ``a_only + b_only``.
    Without discordant pairs there is no evidence either way: 1.
    """
    n = int(a_only) + int(b_only)
    if n == 0:
        return 1.0
    return float(stats.binomtest(int(a_only), n, 0.5).pvalue)


def finished(rows: pd.DataFrame) -> pd.Series:
    """Runs that came to rest at the dock: docked, or stopped outside the gates."""
    from artic.validation.docking.scores import MISSED

    f = rows["failure"].fillna("").astype(str)
    return (f == "") | f.str.startswith(MISSED)


def _two(ra: pd.DataFrame, rb: pd.DataFrame, head: dict,
         metrics: Sequence[tuple[str, str, float]]) -> list[dict]:
    """The rows comparing controller ``a``'s runs ``ra`` with ``b``'s ``rb`` (indexed by start)."""
    starts = ra.index.intersection(rb.index)
    sa = ra.loc[starts, "success"].astype(bool).to_numpy()
    sb = rb.loc[starts, "success"].astype(bool).to_numpy()
    a_only, b_only = int(np.sum(sa & ~sb)), int(np.sum(~sa & sb))
    out = [head | {"metric": "success", "pairs": len(starts), "a_only": a_only,
                   "b_only": b_only,
                   "difference": float(np.mean(sa) - np.mean(sb)) if len(starts) else math.nan,
                   "low": math.nan, "high": math.nan, "test": "McNemar exact",
                   "p": mcnemar_p(a_only, b_only)}]
    both = ra.loc[starts, "_finished"].to_numpy(bool) & rb.loc[starts, "_finished"].to_numpy(bool)
    common = starts[both]
    for name, col, scale in metrics:
        xa = scale * np.abs(ra.loc[common, col].to_numpy(dtype=float))
        xb = scale * np.abs(rb.loc[common, col].to_numpy(dtype=float))
        p = paired(xa, xb, (head["a"], head["b"]))
        test = paired_test(xa - xb)
        out.append(head | {
            "metric": name, "pairs": len(common), "a_only": math.nan, "b_only": math.nan,
            "difference": p.diff.mean, "low": p.diff.lo, "high": p.diff.hi,
            "test": f"paired mean ({p.diff.method})"
            + ("" if test.testable else f": {test.status}"), "p": test.p})
    return out


def compare(rows: pd.DataFrame, controllers: Sequence[str], by: Sequence[str] = (),
            metrics: Sequence[tuple[str, str, float]] = ERRORS) -> pd.DataFrame:
    """Every two ``controllers`` over the same starts, in each group of ``by``, after Holm.

    Parameters
    ----------
    rows : pandas.DataFrame
        One row per run: ``dock.csv``'s columns (at least :data:`KEY`,
        ``controller``, ``success``, ``failure`` and the metrics' columns), and
        the ``by`` columns.
    controllers : sequence of str
        The controllers, in the order the pairs are formed (``a`` before ``b``).
    by : sequence of str
        Columns whose groups are compared apart (a sweep's axis, level,
        scenario and vehicle); none pools every run: the pairs are the starts
        (:data:`KEY`).
    metrics : sequence of (str, str, float)
        The magnitudes compared besides success (:data:`ERRORS`, :data:`TIME`).

    Returns
    -------
    pandas.DataFrame
        ``by``'s columns, then :data:`COLUMNS`; one Holm family over all rows.
    """
    out = []
    rows = rows.assign(_finished=finished(rows))
    groups = rows.groupby(list(by), sort=False) if by else [((), rows)]
    for values, g in groups:
        head0 = dict(zip(by, values if isinstance(values, tuple) else (values,), strict=True))
        start = [k for k in KEY if k not in by]
        of = {c: x.set_index(start) for c, x in g.groupby("controller", sort=False)}
        for i, a in enumerate(controllers):
            for b in controllers[i + 1:]:
                if a in of and b in of:
                    out += _two(of[a], of[b], head0 | {"a": a, "b": b}, metrics)
    cols = list(by) + COLUMNS
    if not out:
        return pd.DataFrame(columns=cols)
    t = pd.DataFrame(out)
    t["p_holm"] = holm(t["p"].to_numpy(dtype=float))
    t["finding"] = t["p_holm"] < ALPHA  # NaN (not testable): never a finding
    return t[cols]


def finding_words(r, where: str) -> str:
    """One finding (a row of :func:`compare` with ``finding``) in words, ``where`` it holds."""
    if r.metric == "success":
        better, worse = (r.a, r.b) if r.difference > 0 else (r.b, r.a)
        n_better, n_worse = (r.a_only, r.b_only) if r.difference > 0 else (r.b_only, r.a_only)
        return (f"{better} docks more often than {worse} {where}: {int(n_better)} starts only "
                f"it docked against {int(n_worse)} of {r.pairs} (McNemar, Holm p = "
                f"{r.p_holm:.2g})")
    # the difference of magnitudes a - b: positive, b is the smaller
    flip = r.difference > 0
    less, more = (r.b, r.a) if flip else (r.a, r.b)
    d, lo, hi = (r.difference, r.low, r.high) if flip else (-r.difference, -r.high, -r.low)
    unit, verb = _WORDS[r.metric]
    return (f"{less} {verb} {more} {where}: by {d:.2g} {unit} [95 % CI {lo:.2g} to {hi:.2g}] "
            f"over {r.pairs} starts (Holm p = {r.p_holm:.2g})")


def summary(pairs: pd.DataFrame, findings: list[str], family: str) -> str:
    """The paragraph that ends a table: how many comparisons, Holm's family, the findings."""
    n = len(pairs)
    tested = int(np.isfinite(pairs["p"].to_numpy(dtype=float)).sum())
    untested = (f" ({n - tested} not testable at their number of starts: `test` in "
                f"{family} says why; their intervals stand, no finding)") if tested < n else ""
    return (f"\nPaired comparisons: {n} (success by McNemar's exact test, errors by the "
            "paired mean difference over the starts both finished); Holm's correction over "
            f"the {tested} tested{untested}. Findings (Holm p < 0.05): "
            + ("none." if not findings else "\n\n" + "\n".join(f"- {f}" for f in findings))
            + "\n")


def markdown(found: pd.DataFrame) -> str:
    """``artic dock``'s comparisons (:func:`compare` pooled): a table, then the findings."""
    from artic.validation.criteria.statistics import format_ci
    from artic.validation.docking.scores import markdown as md_table

    recs = []
    for r in found.itertuples(index=False):
        if r.metric == "success":
            diff = f"{int(r.a_only)} vs {int(r.b_only)} starts only one docked"
        else:
            unit = _WORDS[r.metric][0]
            diff = f"{format_ci(r.difference, r.low, r.high)} {unit}"
        recs.append({"a": r.a, "b": r.b, "metric": r.metric, "starts": r.pairs,
                     "a - b [95 % CI]": diff,
                     "Holm p": "-" if not np.isfinite(r.p_holm) else f"{r.p_holm:.2g}",
                     "finding": "yes" if r.finding else "no"})
    words = [finding_words(r, "over every start")
             for r in found[found["finding"].astype(bool)].itertuples(index=False)]
    return ("\nEvery two controllers over the same starts (scenario, vehicle, seed), the "
            "magnitudes of the final errors and the time over the starts both finished "
            "(dock_pairs.csv):\n\n" + md_table(pd.DataFrame(recs))
            + summary(found, words, "dock_pairs.csv"))
