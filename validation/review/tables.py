"""The summary tables: the paper's Table 2 (forward) and Table 3 (reverse), with intervals.

Each table is the mean of the criteria per model over the manoeuvres of one
direction, as the paper reports them, and beside each mean its 95 %
confidence interval over manoeuvres
(:func:`artic.validation.criteria.statistics.mean_ci`): in CSV the columns
``col``, ``col_lo`` and ``col_hi``; in Markdown ``value ± half-width`` with
only the digits the interval supports. The criteria beyond the paper's
(:data:`EXTRA_COLUMNS`) join the tables whenever ``metrics.csv`` has them; a
criterion defined only on some runs (the dock errors, on docking and parking)
carries its own count ``col_n``.

The paired tables compare every two models on the same manoeuvres: the mean
per-manoeuvre difference with its interval, and whether it resolves the
ranking (the interval excludes zero). With several trucks (``artic campaign
--seeds N``) the pooled tables give the mean over seeds and manoeuvres with
its interval over trucks, and the spread between trucks beside the spread
between manoeuvres.

The paper's own values are kept here for comparison; they come from its
Tables 2 and 3 (a Scania tractor with a tri-axle semitrailer on a test track,
17 forward and 33 reverse manoeuvres).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from artic.validation.criteria import columns as extra
from artic.validation.criteria.coverage import FOLLOW_BOUND, PATH_CRITERIA
from artic.validation.criteria.multiplicity import (
    ALPHA,
    CORRECTION,
    NOT_TESTABLE,
    holm,
    paired_test,
    truck_p,
)
from artic.validation.criteria.statistics import (
    Interval,
    format_ci,
    mean_ci,
    paired,
)
from artic.validation.logs.runfile import atomic_write, atomic_write_text

FORWARD_COLUMNS = ("eps_a", "eps_v", "eps_p", "eps_n")
REVERSE_COLUMNS = ("eps_a", "eps_v", "J_steer", "eps_n")
EXTRA_COLUMNS = extra.COLUMNS
"""Criteria beyond the paper's, in the tables whenever a metrics table has values of them."""

UNITS = {"eps_a": "rad/s", "eps_v": "m/s", "eps_p": "m", "eps_n": "%", "J_steer": "%",
         **extra.UNITS}

PAPER_FORWARD = pd.DataFrame(
    {"eps_a": [0.0064, 0.0049, 0.0037], "eps_v": [0.0431, 0.0211, 0.0159],
     "eps_p": [3.06, 2.51, 1.72], "eps_n": [9.26, 5.9, 4.83]},
    index=pd.Index(["kin", "stm", "mbd"], name="model"))
"""The paper's Table 2 (forward driving)."""

PAPER_REVERSE = pd.DataFrame(
    {"eps_a": [0.0072, 0.0069, 0.0080], "eps_v": [0.039, 0.032, 0.034],
     "J_steer": [26.96, 21.15, 26.14], "eps_n": [32.36, 27.7, 30.78]},
    index=pd.Index(["kin", "stm", "mbd"], name="model"))
"""The paper's Table 3 (reverse driving)."""

SPREADS = ("sd_trucks", "sd_manoeuvres")
"""Suffixes of the pooled table's spread columns."""


def _ok(metrics: pd.DataFrame) -> pd.DataFrame:
    """The rows with results (status not ``failed`` or ``refused``), with :func:`progress`."""
    if "status" in metrics:
        metrics = metrics[~metrics["status"].astype(str).str.startswith(("failed", "refused"))]
    return progress(metrics)


OFF_RUN = "off_run"
"""The column that counts a model's runs that did not follow their log."""


def progress(metrics: pd.DataFrame) -> pd.DataFrame:
    """Runs that do not follow their log, marked and put last on the path criteria.

    A run whose ``eps_cover`` exceeds
    :data:`artic.validation.criteria.coverage.FOLLOW_BOUND` (a lane per sensor
    point) left places of the run farther than a lane from anything it drove.
    Its position errors (:data:`~artic.validation.criteria.coverage.PATH_CRITERIA`)
    measure only the model's points against the measured path, so a model
    that never leaves the start scores near zero there. Such a run's path
    criteria become at least its ``eps_cover`` (``eps_y1``, ``eps_y2`` and
    ``eps_p`` each ``max(own, eps_cover)``): more than the bound, more than a
    run that follows scores. The column ``off_run`` is 1 for such a run, 0
    otherwise; ``metrics.csv`` keeps the values as computed.
    """
    if "eps_cover" not in metrics or OFF_RUN in metrics:
        return metrics
    cover = pd.to_numeric(metrics["eps_cover"], errors="coerce")
    off = cover > FOLLOW_BOUND
    out = metrics.copy()
    out[OFF_RUN] = off.astype(int)
    if off.any():
        for c in PATH_CRITERIA:
            if c in out:
                v = pd.to_numeric(out[c], errors="coerce")
                out[c] = v.where(~off, np.fmax(v, cover))
    return out


def columns(metrics: pd.DataFrame, direction: str) -> list[str]:
    """The criteria of one direction's table: the paper's, then the extras with values.

    Each normalised criterion of the table is followed by its absolute
    counterpart (:data:`artic.validation.criteria.columns.COUNTERPARTS`), which
    joins the table only beside it: ``steer_fb`` [deg] beside ``J_steer``,
    ``eps_p`` [m] beside ``eps_n``.
    """
    paper = list(FORWARD_COLUMNS if direction == "forward" else REVERSE_COLUMNS)
    part = metrics[metrics["direction"] == direction] if "direction" in metrics else metrics

    def has(c: str) -> bool:
        return c in part and bool(pd.to_numeric(part[c], errors="coerce").notna().any())

    absolute = {k: v for k, v in extra.COUNTERPARTS.items() if k in paper and has(v)}
    cols: list[str] = []
    for c in paper:
        if c in cols:
            continue
        cols.append(c)
        if c in absolute and absolute[c] not in cols:
            cols.append(absolute[c])
    for c in EXTRA_COLUMNS:
        if c not in cols and c not in extra.COUNTERPARTS.values() and has(c):
            cols.append(c)
    return cols


def _interval_columns(out: dict, c: str, iv: Interval, n: int) -> None:
    out[c], out[f"{c}_lo"], out[f"{c}_hi"] = iv.mean, iv.lo, iv.hi
    if iv.n != n:
        out[f"{c}_n"] = iv.n


def summary(metrics: pd.DataFrame, direction: str) -> pd.DataFrame:
    """Mean criteria per model over one direction's manoeuvres, with intervals and count ``n``.

    Pairs without a result (status ``failed: ...`` or ``refused: ...``) are left out
    of the means and of ``n``; ``metrics.csv`` lists them.

    Returns
    -------
    DataFrame
        Indexed by model: per criterion ``col``, ``col_lo``, ``col_hi`` (95 %
        interval over manoeuvres) and, where fewer runs have it than ``n``,
        ``col_n``; then ``off_run``, the runs that did not follow their log
        (:func:`progress`: their path criteria count as their ``eps_cover``,
        which puts the model last on them), and ``n``.
    """
    def row_of(g: pd.DataFrame, cols: list[str]) -> dict:
        row: dict = {}
        for c in cols:
            _interval_columns(row, c, mean_ci(pd.to_numeric(g[c], errors="coerce")), len(g))
        if OFF_RUN in g:
            row[OFF_RUN] = int(g[OFF_RUN].sum())
        row["n"] = len(g)
        return row

    return _per_model(metrics, direction, row_of, (OFF_RUN, "n"))


def _per_model(metrics: pd.DataFrame, direction: str, row_of, tail: tuple[str, ...]
               ) -> pd.DataFrame:
    """One row per model of one direction's results, ``row_of(rows, criteria)`` each.

    The rows with results of ``direction``, grouped by model in order of
    appearance; columns grouped per criterion, then ``tail``; indexed by model.
    """
    cols = columns(metrics, direction)
    part = _ok(metrics)
    part = part[part["direction"] == direction]
    rows = {model: row_of(g, cols) for model, g in part.groupby("model", sort=False)}
    out = pd.DataFrame.from_dict(rows, orient="index")
    out = out[_ordered(out.columns, cols, tail)] if len(out) else out
    out.index.name = "model"
    return out


def _ordered(present, cols: list[str], tail: tuple[str, ...] = ("n",)) -> list[str]:
    """``present`` columns grouped per criterion in ``cols`` order, then ``tail``."""
    out = []
    for c in cols:
        out += [k for k in (c, f"{c}_lo", f"{c}_hi", f"{c}_n",
                            *(f"{c}_{s}" for s in SPREADS)) if k in present]
    return out + [k for k in present if k not in out and k in tail] + \
        [k for k in present if k not in out and k not in tail]


def _criterion_of(df: pd.DataFrame) -> dict[str, str]:
    """Columns that are a criterion's bounds, counts or spreads, by the criterion they belong to."""
    out = {}
    for c in df.columns:
        for suffix in ("_lo", "_hi", "_n", *(f"_{s}" for s in SPREADS)):
            base = str(c).removesuffix(suffix)
            if base != str(c) and base in df.columns:
                out[c] = base
    return out


def escape(text: object) -> str:
    """``text`` as one Markdown table cell: ``|`` escaped, line breaks as spaces.

    Names come from files and users (a vehicle's, a controller's, a registered
    model's); a ``|`` or a newline in one would otherwise split its row.
    """
    return " ".join(str(text).splitlines()).replace("|", "\\|")


def cell(v: object, digits: int = 4) -> str:
    """One value as table text: ``-`` for a missing number, never ``nan``; text escaped."""
    if isinstance(v, float | np.floating):
        return "-" if not math.isfinite(v) else f"{v:.{digits}g}"
    if isinstance(v, bool | np.bool_):
        return "yes" if v else "no"
    return escape(v)


def pipe_table(head: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    """Cells already as text (:func:`cell`, :func:`escape`) as one Markdown pipe table.

    ``DataFrame.to_markdown`` (tabulate's ``pipe`` format) with the cells as they
    are: no number parsing (a cell's digits are the interval's, never re-rounded)
    and no padding, so a row reads ``| a | b |``; the rule under the header spans
    each column's width.
    """
    frame = pd.DataFrame([list(r) for r in rows], columns=list(head), dtype=object)
    return frame.to_markdown(index=False, tablefmt="pipe", disable_numparse=True,
                             stralign=None)


def markdown(df: pd.DataFrame, digits: int = 4) -> str:
    """A small frame as a Markdown table; units from :data:`UNITS` in the header.

    A column ``c`` with ``c_lo`` and ``c_hi`` beside it prints as ``value ±
    half-width`` (:func:`artic.validation.criteria.statistics.format_ci`), with
    ``(n = k)`` where fewer runs than the row's ``n`` have it; its bound and
    count columns are not printed. Other numbers print with ``digits``
    significant digits; nothing prints as ``nan``.
    """
    hidden = _criterion_of(df)
    shown = [c for c in df.columns if c not in hidden]
    head = [escape(df.index.name or "")] + [f"{c} [{UNITS[c]}]" if c in UNITS else escape(c)
                                            for c in shown]

    def text(row: pd.Series, c) -> str:
        if f"{c}_lo" in hidden and f"{c}_hi" in hidden:
            n_row = int(row["n"]) if "n" in row and pd.notna(row["n"]) else None
            n = int(row[f"{c}_n"]) if f"{c}_n" in row and pd.notna(row[f"{c}_n"]) else n_row
            s = format_ci(float(row[c]), float(row[f"{c}_lo"]), float(row[f"{c}_hi"]), n or 0)
            return s + (f" (n = {n})" if n is not None and n != n_row and "(n" not in s
                        and s != "-" else "")
        return cell(row[c], digits)

    def name(idx, row: pd.Series) -> str:
        off = row.get(OFF_RUN) if OFF_RUN in row else None
        if off is not None and pd.notna(off) and int(off) > 0:
            n = f" of {int(row['n'])}" if "n" in row and pd.notna(row["n"]) else ""
            return f"{cell(idx)} (**off the run** on {int(off)}{n})"
        return cell(idx)

    return pipe_table(head, ([name(idx, row), *(text(row, c) for c in shown)]
                             for idx, row in df.iterrows()))


def versus_paper(ours: pd.DataFrame, paper: pd.DataFrame) -> pd.DataFrame:
    """Side by side: our value with its interval, the paper's, and their ratio.

    The paper's values carry no interval; the ratio's interval is ours over
    the paper's value. Models the paper did not have (the floor) get no
    paper columns (``-`` in Markdown, never ``nan``).
    """
    rows = {}
    for model in ours.index:
        row = {}
        for c in paper.columns:
            if c not in ours:
                continue
            a = float(ours.loc[model, c])
            lo = float(ours.loc[model, f"{c}_lo"]) if f"{c}_lo" in ours else math.nan
            hi = float(ours.loc[model, f"{c}_hi"]) if f"{c}_hi" in ours else math.nan
            b = float(paper.loc[model, c]) if model in paper.index else math.nan
            row[c], row[f"{c}_lo"], row[f"{c}_hi"] = a, lo, hi
            row[f"{c} (paper)"] = b
            ratio = f"{c} ratio"
            row[ratio] = a / b if b else math.nan
            row[f"{ratio}_lo"] = lo / b if b else math.nan
            row[f"{ratio}_hi"] = hi / b if b else math.nan
        if "n" in ours:
            row["n"] = ours.loc[model, "n"]
        rows[model] = row
    out = pd.DataFrame.from_dict(rows, orient="index")
    out.index.name = "model"
    return out


def _pivots(metrics: pd.DataFrame, direction: str, criteria: Iterable[str],
            by: tuple[str, ...] = ("log",)) -> dict[str, pd.DataFrame]:
    """Each criterion per ``by`` (rows) and model (columns), results only.

    One ``pivot_table`` of all the criteria (``aggfunc="first"``, the rows
    and models in their order of first appearance, ``dropna=False``), each
    criterion's columns the frame that the criterion pivoted alone gives
    (``tests/test_tables.py`` holds them equal): a pivot costs about as much
    for one criterion as for twenty, and the paired tables ask for every
    criterion of a direction.
    """
    crit = list(dict.fromkeys(criteria))
    if not crit:
        return {}
    part = _ok(metrics)
    part = part[part["direction"] == direction]
    names = {c: f"_v{i}" for i, c in enumerate(crit)}
    values = {names[c]: pd.to_numeric(part[c], errors="coerce") for c in crit}
    if part.empty:  # no value columns come out of an empty pivot: each alone (empty frames)
        return {c: _pivot_table(part.assign(**{names[c]: values[names[c]]}), by, names[c])
                for c in crit}
    table = _pivot_table(part.assign(**values), by, list(values))
    return {c: table[names[c]] for c in crit}


def _pivot_table(part: pd.DataFrame, by: tuple[str, ...], values: str | list[str]) -> pd.DataFrame:
    """``values`` per ``by`` (rows) and model (columns): each cell's first, rows as they come."""
    return part.pivot_table(index=list(by), columns="model", values=values, aggfunc="first",
                            sort=False, dropna=False)


def _models(metrics: pd.DataFrame) -> list[str]:
    return list(dict.fromkeys(metrics["model"]))


def _model_pairs(metrics: pd.DataFrame, direction: str, criteria: list[str] | None,
                 by: tuple[str, ...]) -> Iterator[tuple[str, str, str, pd.DataFrame]]:
    """``(criterion, a, b, table)`` for every criterion and pair of models in it.

    ``table`` is :func:`_pivots`'s: the criterion per ``by`` (rows) and model.
    """
    models = _models(metrics)
    wanted = [c for c in criteria or columns(metrics, direction) if c in metrics]
    tables = _pivots(metrics, direction, wanted, by=by)
    for c in wanted:
        table = tables[c]
        for a, b in itertools.combinations([m for m in models if m in table], 2):
            yield c, a, b, table


RATING_PREFIX = "iso_gap"
"""Criteria of ISO/TS 18571's rating: a family of their own in :func:`corrected`."""

PAIRED_COLUMNS = ["criterion", "a", "b", "n", "diff", "diff_lo", "diff_hi", "resolved", "lower",
                  "test", "p", "p_adj", "resolved_adj"]
"""The columns of :func:`paired_table`."""


def corrected(rows: pd.DataFrame) -> pd.DataFrame:
    """``rows`` with ``p_adj`` (Holm within each family) and ``resolved_adj``.

    The family is the whole table: every pair of models and every criterion
    of one direction against one reference
    (:mod:`artic.validation.criteria.multiplicity` says why Holm), except the
    columns of ISO/TS 18571's rating (``iso_gap*``), a question of their own
    asked beside the paper's distance criteria: they form a second family, so
    that adding the rating did not change which distance rankings resolve. A
    row not testable (NaN ``p``) is left out of its family and is never
    resolved after the correction.
    """
    out = rows.copy()
    out["p_adj"] = _adjusted(out)
    out["resolved_adj"] = (out["p_adj"] < ALPHA) & out["resolved"].astype(bool) \
        if len(out) else []
    return out


def _adjusted(rows: pd.DataFrame) -> np.ndarray:
    """Holm's adjusted p values of ``rows``, each family on its own (see :func:`corrected`)."""
    p = rows["p"].to_numpy(dtype=float) if len(rows) else np.zeros(0)
    adj = np.full(p.size, np.nan)
    if p.size:
        rating = rows["criterion"].astype(str).str.startswith(RATING_PREFIX).to_numpy()
        for family in (rating, ~rating):
            if family.any():
                adj[family] = holm(p[family])
    return adj


def paired_table(metrics: pd.DataFrame, direction: str,
                 criteria: list[str] | None = None, intervals: bool = True) -> pd.DataFrame:
    """Every pair of models compared on the same manoeuvres, per criterion.

    Parameters
    ----------
    metrics : DataFrame
        One row per (manoeuvre, model) with the criteria.
    direction : str
        ``forward`` or ``reverse``.
    criteria : list of str, optional
        The criteria to compare; every one of the direction by default.
    intervals : bool
        False computes a row's bootstrap interval only where its adjusted p
        value is below the level, the only rows that can resolve after the
        correction: the findings, ``resolved_adj`` and ``diff`` are the same
        to the bit, the other rows have NaN ``diff_lo``, ``diff_hi`` and
        ``resolved`` False. For tables that are read for their findings alone
        (:func:`artic.validation.campaign.classes.carried_by`'s).

    Returns
    -------
    DataFrame
        One row per (criterion, pair ``a``, ``b``): ``n`` (manoeuvres both
        have), ``diff`` (mean of ``a - b``), ``diff_lo``, ``diff_hi`` (95 %
        interval), ``resolved`` (the interval excludes zero) and ``lower``:
        the model with the smaller error where resolved, ``not resolved``
        otherwise. Smaller is better for every criterion. Then ``test``
        (``tested``, or ``not testable at n = ...`` and why:
        :func:`artic.validation.criteria.multiplicity.paired_test`), ``p``
        (its p value, NaN where not testable), ``p_adj`` (Holm over the rows
        of this table, :func:`corrected`) and ``resolved_adj`` (resolved after
        the correction). :func:`artic.validation.campaign.findings.mark` adds
        whether each is a finding.
    """
    rows, pairs = [], []
    for c, a, b, table in _model_pairs(metrics, direction, criteria, ("log",)):
        x, y = table[a].to_numpy(dtype=float), table[b].to_numpy(dtype=float)
        ok = np.isfinite(x) & np.isfinite(y)
        if not ok.any():
            continue
        test = paired_test(x - y)
        rows.append({"criterion": c, "a": a, "b": b, "n": int(ok.sum()), "test": test.status,
                     "p": test.p})
        pairs.append((x, y, a, b))
    frame = pd.DataFrame(rows, columns=["criterion", "a", "b", "n", "test", "p"])
    wanted = np.ones(len(frame), bool) if intervals else _adjusted(frame) < ALPHA
    for i, (x, y, a, b) in enumerate(pairs):
        if wanted[i]:
            p = paired(x, y, (a, b))
            rows[i] |= {"diff": p.diff.mean, "diff_lo": p.diff.lo, "diff_hi": p.diff.hi,
                        "resolved": p.resolved, "lower": p.lower or "not resolved"}
        else:
            ok = np.isfinite(x) & np.isfinite(y)
            rows[i] |= {"diff": float(np.mean(x[ok] - y[ok])), "diff_lo": math.nan,
                        "diff_hi": math.nan, "resolved": False, "lower": "not resolved"}
    return corrected(pd.DataFrame(rows, columns=PAIRED_COLUMNS[:-2]))


def _p_text(p: float, test: str = "") -> str:
    """A p value in two significant digits; the test's status where not testable, else ``-``."""
    if not math.isfinite(p):
        return test if str(test).startswith(NOT_TESTABLE) else "-"
    return f"{p:.2g}" if p >= 1e-3 else f"{p:.1e}"


def paired_markdown(table: pd.DataFrame) -> str:
    """A paired table in Markdown: ``a - b`` as ``value ± half-width`` in the criterion's unit.

    With ``p_adj`` the adjusted p value (:data:`CORRECTION` over the table's
    rows) and whether the ranking is resolved after it; with ``finding``,
    whether it is a finding (resolved after the correction on the logs and
    on their noise-free twins), and the twins' difference; with ``carried_by``
    (:func:`artic.validation.campaign.classes.carried_by`), the manoeuvre classes
    whose removal loses each finding.
    """
    adj = "p_adj" in table
    twins = "finding" in table
    head = ["criterion", "a", "b", "a - b", "n", "resolved"]
    if adj:
        head += [f"p ({CORRECTION})", "resolved after correction"]
    if twins and "twin_diff" in table:
        head += ["a - b on the twins", f"twins p ({CORRECTION})"]
    if twins:
        head.append("finding")
    carried = "carried_by" in table
    if carried:
        head.append("carried by (leave one class out)")
    head.append("lower")
    rows = []
    for r in table.itertuples(index=False):
        unit = f" [{UNITS[r.criterion]}]" if r.criterion in UNITS else ""
        diff = format_ci(r.diff, r.diff_lo, r.diff_hi, int(r.n))
        extra = f" ({r.seeds_resolved} of {r.seeds} seeds alone)" \
            if hasattr(r, "seeds_resolved") else ""
        cells = [f"{r.criterion}{unit}", r.a, r.b, diff, str(int(r.n)),
                 f"{'yes' if r.resolved else 'no'}{extra}"]
        if adj:
            cells += [_p_text(r.p_adj, getattr(r, "test", "")),
                      "yes" if r.resolved_adj else "no"]
        if twins and "twin_diff" in table:
            cells += [format_ci(r.twin_diff, r.twin_diff_lo, r.twin_diff_hi, int(r.n))
                      if math.isfinite(r.twin_diff) else "-", _p_text(r.twin_p_adj)]
        if twins:
            mark = "**yes**" if r.finding else "no"
            if hasattr(r, "seeds_findings"):
                mark += f" ({r.seeds_findings} of {r.seeds} trucks)"
            cells.append(mark)
        if carried:
            cells.append(str(r.carried_by) or "-")
        cells.append(str(r.lower))
        rows.append(cells)
    return pipe_table(head, rows)


def differences(metrics: pd.DataFrame, direction: str, of: str = "floor") -> pd.DataFrame:
    """Each model's criteria minus ``of``'s on the same manoeuvre (and seed), as metrics rows.

    The rows keep ``log``, ``model``, ``direction`` and ``seed`` (if any), so
    :func:`summary` and :func:`pooled` average them like criteria. Empty when
    ``of`` has no rows.
    """
    part = _ok(metrics)
    part = part[part["direction"] == direction]
    keys = ["seed", "log"] if "seed" in part else ["log"]
    crit = columns(metrics, direction)
    ref = part[part["model"] == of].set_index(keys)[crit].apply(pd.to_numeric, errors="coerce")
    if ref.empty:
        return pd.DataFrame(columns=["log", "model", "direction", *crit])
    rows = []
    for model, g in part[part["model"] != of].groupby("model", sort=False):
        vals = g.set_index(keys)[crit].apply(pd.to_numeric, errors="coerce")
        common = vals.index.intersection(ref.index)
        d = (vals.loc[common] - ref.loc[common]).reset_index()
        d["model"], d["direction"] = model, direction
        # the model's own runs off their log (the differences are not criteria to mark)
        d[OFF_RUN] = g.set_index(keys)[OFF_RUN].reindex(common).to_numpy() \
            if OFF_RUN in g else 0
        rows.append(d)
    return pd.concat(rows, ignore_index=True) if rows else pd.DataFrame()


def excess(metrics: pd.DataFrame, direction: str, floor: str = "floor") -> pd.DataFrame:
    """Each model's criteria above the floor row's, paired per manoeuvre, with intervals.

    Returns
    -------
    DataFrame
        As :func:`summary`, of the per-manoeuvre differences model minus
        floor (the floor left out). Empty without a floor row.
    """
    d = differences(metrics, direction, floor)
    return summary(d, direction) if len(d) else pd.DataFrame()


def by_seed(metrics: pd.DataFrame, direction: str) -> pd.DataFrame:
    """:func:`summary` per seed (``metrics`` with a ``seed`` column), one row per (seed, model)."""
    parts = []
    for seed, g in metrics.groupby("seed", sort=True):
        t = summary(g, direction)
        t.insert(0, "seed", int(seed))
        parts.append(t)
    return pd.concat(parts) if parts else pd.DataFrame()


def pooled(metrics: pd.DataFrame, direction: str) -> pd.DataFrame:
    """The mean over seeds and manoeuvres, its interval over trucks, and both spreads.

    ``metrics`` has a ``seed`` column (one truck per seed). Rows of one truck
    share that truck, so they are not independent draws: the interval of the
    pooled mean is taken over the trucks' own means (Student's t for fewer than
    eight trucks, see :mod:`artic.validation.criteria.statistics`), which holds
    for another truck drawn alike, and is wide with few trucks.

    Returns
    -------
    DataFrame
        Indexed by model: per criterion ``col`` (mean over every seed and
        manoeuvre), ``col_lo``, ``col_hi`` (interval over trucks),
        ``col_sd_trucks`` (standard deviation of the per-seed means) and
        ``col_sd_manoeuvres`` (the pooled standard deviation of the manoeuvres
        within a seed); ``n`` (runs) and ``seeds``.
    """
    def row_of(g: pd.DataFrame, cols: list[str]) -> dict:
        row: dict = {}
        for c in cols:
            v = pd.to_numeric(g[c], errors="coerce")
            per_seed = v.groupby(g["seed"]).agg(["mean", "var", "count"])
            per_seed = per_seed[per_seed["count"] > 0]
            iv = mean_ci(per_seed["mean"].to_numpy())
            row[c], row[f"{c}_lo"], row[f"{c}_hi"] = float(v.mean()), iv.lo, iv.hi
            row[f"{c}_sd_trucks"] = float(per_seed["mean"].std(ddof=1)) \
                if len(per_seed) > 1 else math.nan
            dof = (per_seed["count"] - 1).clip(lower=0)
            within = float((per_seed["var"].fillna(0) * dof).sum() / dof.sum()) \
                if dof.sum() > 0 else math.nan
            row[f"{c}_sd_manoeuvres"] = math.sqrt(within) if math.isfinite(within) else math.nan
            if int(v.notna().sum()) != len(g):
                row[f"{c}_n"] = int(v.notna().sum())
        if OFF_RUN in g:
            row[OFF_RUN] = int(g[OFF_RUN].sum())
        row["n"], row["seeds"] = len(g), int(g["seed"].nunique())
        return row

    return _per_model(metrics, direction, row_of, (OFF_RUN, "n", "seeds"))


def spread_markdown(table: pd.DataFrame) -> str:
    """The pooled table's spreads: between trucks and between manoeuvres, per criterion."""
    crits = [c for c in table.columns if f"{c}_sd_trucks" in table]
    head = ["model"] + [f"{c} [{UNITS.get(c, '')}] trucks / manoeuvres" for c in crits]
    return pipe_table(head, ([str(m), *(f"{cell(float(row[f'{c}_sd_trucks']), 2)} / "
                                        f"{cell(float(row[f'{c}_sd_manoeuvres']), 2)}"
                                        for c in crits)] for m, row in table.iterrows()))


def pooled_paired(metrics: pd.DataFrame, direction: str,
                  criteria: list[str] | None = None) -> pd.DataFrame:
    """:func:`paired_table` over several trucks: the per-seed mean differences, pooled.

    The difference ``a - b`` is averaged per seed over the manoeuvres both
    have; the interval is over those per-seed means (as in :func:`pooled`), and
    decides ``resolved``; ``p`` is Student's t over them
    (:func:`artic.validation.criteria.multiplicity.truck_p`: a truck's mean
    over its manoeuvres is nearer normal than they are, and the sign-flip test
    cannot resolve a few values). ``seeds_resolved`` counts the seeds whose
    own paired comparison resolves it with the pooled sign.
    """
    rows = []
    for c, a, b, table in _model_pairs(metrics, direction, criteria, ("seed", "log")):
        d = (table[a] - table[b]).dropna()
        if d.empty:
            continue
        per_seed = d.groupby(level="seed").mean()
        iv = mean_ci(per_seed.to_numpy())
        resolved = iv.excludes(0.0)
        sign = np.sign(d.mean())
        alone = sum(mean_ci(g.to_numpy()).excludes(0.0) and np.sign(g.mean()) == sign
                    for _, g in d.groupby(level="seed"))
        rows.append({"criterion": c, "a": a, "b": b, "n": len(d), "diff": float(d.mean()),
                     "diff_lo": iv.lo, "diff_hi": iv.hi, "resolved": resolved,
                     "lower": (a if sign < 0 else b) if resolved else "not resolved",
                     "test": ("Student t over trucks" if len(per_seed) > 1
                              else f"{NOT_TESTABLE} at n = 1 (one truck)"),
                     "p": truck_p(per_seed.to_numpy()),
                     "seeds_resolved": int(alone), "seeds": len(per_seed)})
    cols = [*PAIRED_COLUMNS[:-2], "seeds_resolved", "seeds"]
    return corrected(pd.DataFrame(rows, columns=cols))


def write_table(df: pd.DataFrame, path_stem: Path, title: str,
                text: str | None = None) -> tuple[Path, Path]:
    """Write ``STEM.csv`` and ``STEM.md`` atomically.

    ``text`` is the Markdown body if not :func:`markdown` of ``df``.
    """
    path_stem = Path(path_stem)
    csv = atomic_write(path_stem.with_suffix(".csv"),
                       lambda p: df.to_csv(p, float_format="%.6g"))
    body = markdown(df) if text is None else text
    md = atomic_write_text(path_stem.with_suffix(".md"), f"# {title}\n\n{body}\n")
    return csv, md
