"""Findings, noise shares and the headline criteria.

The default campaign validates every model twice: on the measured logs and
on their noise-free twins, the same truth runs measured with ideal sensors
(:func:`artic.validation.synthetic.generate.noise_free_twin`). From the two:

- **the noise share** (:func:`noise_share`): per criterion, direction and
  model (the floor included), the score on the logs minus the score on the
  twins, paired per manoeuvre with its interval: the part of the score that
  the sensor noise, the clock skew and the CAN bus make;
- **findings** (:func:`mark`): a ranking of two models is a finding only
  where it is resolved after Holm's correction over its table
  (:func:`artic.validation.review.tables.corrected`) on the logs *and*
  resolved after the correction, with the same sign, on the twins; a
  ranking that the noise makes, or that it hides, is not one;
- **the headline criteria** (:func:`headline_criteria`): those that rank
  models rather than sensors, that is, with a finding between the models
  under validation (so every ranking they state holds on the twins). Beside
  each, what the noise adds to any model's score as a ratio of the smallest
  difference its findings state, with an interval that combines the two
  differences' 95 % intervals (the noise's over the finding's: both hold at
  least 90 % of the time), and, pooled over several trucks, on how many
  trucks' own campaigns the criterion has a finding. The ratio is stated,
  not cut: a ratio of two noisy means decides nothing at a fixed threshold
  (on other trucks it moves across any such cut), so the report gives it
  with its interval and the reader weighs it. A ranking the noise makes
  (resolved on the logs, not on the twins) is not stated, and the headline
  says that the noise made it. The paper's criteria stay in the tables, with
  their noise share beside them.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from artic.validation.criteria.statistics import Interval, format_ci, mean_ci
from artic.validation.review.tables import UNITS, _ok, columns, pipe_table

FLOOR = "floor"

CRITERIA_COLUMNS = ["findings", "noise_made", "smallest", "smallest_lo", "smallest_hi", "noise",
                    "noise_lo", "noise_hi", "ratio", "ratio_lo", "ratio_hi", "trucks",
                    "trucks_with_finding", "headline"]
"""The columns of :func:`headline_criteria`."""


def _magnitude(mean: float, lo: float, hi: float) -> tuple[float, float, float]:
    """``|mean|`` and the bounds of ``|value|`` over the interval ``[lo, hi]``."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return abs(mean), math.nan, math.nan
    low = 0.0 if lo <= 0.0 <= hi else min(abs(lo), abs(hi))
    return abs(mean), low, max(abs(lo), abs(hi))


def mark(pairs: pd.DataFrame, twin_pairs: pd.DataFrame | None) -> pd.DataFrame:
    """``pairs`` with the twins' verdicts and ``finding``.

    Parameters
    ----------
    pairs : DataFrame
        A paired table on the logs (:func:`artic.validation.review.tables.paired_table`).
    twin_pairs : DataFrame or None
        The same table on the noise-free twins; ``None`` where the logs have no
        twins because they are noise-free themselves (``--sensors ideal``):
        then a finding is a ranking resolved after the correction.

    Returns
    -------
    DataFrame
        ``pairs`` with ``twin_diff``, ``twin_diff_lo``, ``twin_diff_hi``,
        ``twin_p_adj``, ``twin_resolved_adj`` (NaN or False where the twins
        lack the pair) and ``finding``.
    """
    out = pairs.copy()
    if out.empty:
        out["finding"] = pd.Series(dtype=bool)
        return out
    if twin_pairs is None:
        out["finding"] = out["resolved_adj"].astype(bool)
        return out
    keys = ["criterion", "a", "b"]
    twin = twin_pairs.set_index(keys)
    idx = pd.MultiIndex.from_frame(out[keys])
    for src, dst in (("diff", "twin_diff"), ("diff_lo", "twin_diff_lo"),
                     ("diff_hi", "twin_diff_hi"), ("p_adj", "twin_p_adj")):
        out[dst] = twin[src].reindex(idx).to_numpy(dtype=float) if len(twin) else math.nan
    resolved = twin["resolved_adj"].reindex(idx) if len(twin) else None
    out["twin_resolved_adj"] = (resolved.fillna(False).astype(bool).to_numpy()
                                if resolved is not None else False)
    same_sign = np.sign(out["diff"].to_numpy(dtype=float)) == np.sign(
        out["twin_diff"].to_numpy(dtype=float))
    out["finding"] = out["resolved_adj"].astype(bool) & out["twin_resolved_adj"] & same_sign
    return out


def noise_share(metrics: pd.DataFrame, twins: pd.DataFrame, direction: str) -> pd.DataFrame:
    """What the sensor noise adds to each model's score, per criterion, paired per manoeuvre.

    Parameters
    ----------
    metrics, twins : DataFrame
        ``metrics.csv`` rows on the logs and on their twins (same ``log`` names;
        with a ``seed`` column, paired per seed and log).
    direction : str
        ``forward`` or ``reverse``.

    Returns
    -------
    DataFrame
        One row per (model, criterion): the mean on the logs ``noisy`` and on
        the twins ``twin`` with their intervals (``_lo``, ``_hi``), the mean
        of the per-manoeuvre difference ``noise`` (logs minus twins) with its
        interval, ``share`` (``noise`` over ``noisy`` [%]) and ``n`` (the
        manoeuvres both have). For the signed dock errors ``dock_*`` the
        magnitudes are compared.
    """
    a, b = _ok(metrics), _ok(twins)
    a, b = a[a["direction"] == direction], b[b["direction"] == direction]
    keys = ["seed", "log"] if "seed" in a and "seed" in b else ["log"]
    rows = []
    # Per model, the rows on the logs and on the twins by manoeuvre, and the
    # manoeuvres both have: the same for every criterion.
    per_model = []
    for model, g in a.groupby("model", sort=False):
        g, h = g.set_index(keys), b[b["model"] == model].set_index(keys)
        per_model.append((model, g, h, g.index.intersection(h.index)))
    for c in columns(metrics, direction):
        if c not in b:
            continue
        for model, g, h, common in per_model:
            x = pd.to_numeric(g[c], errors="coerce")
            y = pd.to_numeric(h[c], errors="coerce")
            if c.startswith("dock_"):
                x, y = x.abs(), y.abs()
            x, y = x.loc[common].to_numpy(float), y.loc[common].to_numpy(float)
            ok = np.isfinite(x) & np.isfinite(y)
            if not ok.any():
                continue
            x, y = x[ok], y[ok]
            row = {"model": model, "criterion": c, "n": int(ok.sum())}
            for name, v in (("noisy", x), ("twin", y), ("noise", x - y)):
                iv = mean_ci(v)
                row[name], row[f"{name}_lo"], row[f"{name}_hi"] = iv.mean, iv.lo, iv.hi
            row["share"] = 100.0 * row["noise"] / row["noisy"] if row["noisy"] else math.nan
            rows.append(row)
    cols = ["model", "criterion", "noisy", "noisy_lo", "noisy_hi", "twin", "twin_lo", "twin_hi",
            "noise", "noise_lo", "noise_hi", "share", "n"]
    return pd.DataFrame(rows, columns=cols)


def share_markdown(table: pd.DataFrame) -> str:
    """A noise-share table in Markdown: one row per criterion, one column per model."""
    if table.empty:
        return "(no criterion has values on both the logs and the twins)"
    models = list(dict.fromkeys(table["model"]))
    head = ["criterion", *[f"{m}: logs / twins / noise (share)" for m in models]]
    rows = []
    for c, g in table.groupby("criterion", sort=False):
        unit = f" [{UNITS[c]}]" if c in UNITS else ""
        cells = [f"{c}{unit}"]
        for m in models:
            r = g[g["model"] == m]
            if r.empty:
                cells.append("-")
                continue
            r = r.iloc[0]
            n = int(r["n"])
            parts = [format_ci(Interval(r[k], r[f"{k}_lo"], r[f"{k}_hi"], n, ""))
                     for k in ("noisy", "twin", "noise")]
            share = f"{r['share']:.0f} %" if math.isfinite(r["share"]) else "-"
            cells.append(f"{parts[0]} / {parts[1]} / {parts[2]} ({share})")
        rows.append(cells)
    return pipe_table(head, rows)


def headline_criteria(pairs: pd.DataFrame, share: pd.DataFrame | None,
                      exclude: tuple[str, ...] = (FLOOR,)) -> pd.DataFrame:
    """Which criteria of one direction rank models rather than sensors (module docstring).

    Parameters
    ----------
    pairs : DataFrame
        The direction's paired table on the logs, marked by :func:`mark`;
        pooled over trucks it has ``seeds`` and ``seeds_findings``
        (:func:`artic.validation.campaign.seeds.seeds_findings`).
    share : DataFrame or None
        Its :func:`noise_share`; ``None`` for noise-free logs (nothing to add).
    exclude : tuple of str
        Rows that are not models under validation (the floor).

    Returns
    -------
    DataFrame
        Indexed by criterion (:data:`CRITERIA_COLUMNS`): ``findings``
        (between models), ``noise_made`` (rankings resolved after correction
        on the logs that do not hold on the twins), ``smallest`` (the
        smallest |difference| a finding states) with the bounds of its
        magnitude over its interval (``_lo``, ``_hi``), ``noise`` (the largest
        |noise addition| to a model's score) with the same, ``ratio``
        (``noise / smallest``) with ``ratio_lo = noise_lo / smallest_hi`` and
        ``ratio_hi = noise_hi / smallest_lo``; pooled over trucks ``trucks``
        and ``trucks_with_finding`` (the most trucks on which one of its
        rankings is a finding of that truck's own campaign; NaN for one
        truck); ``headline`` (a finding between models).
    """
    rows = {}
    if pairs is None or pairs.empty:
        return pd.DataFrame(columns=CRITERIA_COLUMNS)
    models = pairs[~pairs["a"].isin(exclude) & ~pairs["b"].isin(exclude)]
    for c, g in models.groupby("criterion", sort=False):
        found = g[g["finding"].astype(bool)]
        noise_made = int((g["resolved_adj"].astype(bool) & ~g["finding"].astype(bool)).sum())
        smallest = (math.nan,) * 3
        if len(found):
            r = found.loc[found["diff"].abs().idxmin()]
            smallest = _magnitude(float(r["diff"]), float(r["diff_lo"]), float(r["diff_hi"]))
        noise = (0.0, 0.0, 0.0)
        if share is not None and len(share):
            s = share[(share["criterion"] == c) & ~share["model"].isin(exclude)]
            noise = (math.nan,) * 3
            if len(s):
                r = s.loc[s["noise"].abs().idxmax()]
                noise = _magnitude(float(r["noise"]), float(r["noise_lo"]),
                                   float(r["noise_hi"]))
        ratio = (noise[0] / smallest[0] if smallest[0] > 0 else math.nan,
                 noise[1] / smallest[2] if smallest[2] > 0 else math.nan,
                 noise[2] / smallest[1] if smallest[1] > 0 else math.inf)
        if not len(found):
            ratio = (math.nan,) * 3
        trucks, with_finding = math.nan, math.nan
        if "seeds_findings" in g and "seeds" in g and len(g):
            trucks = int(g["seeds"].max())
            with_finding = int(g["seeds_findings"].max())
        rows[c] = {"findings": len(found), "noise_made": noise_made,
                   "smallest": smallest[0], "smallest_lo": smallest[1],
                   "smallest_hi": smallest[2], "noise": noise[0], "noise_lo": noise[1],
                   "noise_hi": noise[2], "ratio": ratio[0], "ratio_lo": ratio[1],
                   "ratio_hi": ratio[2], "trucks": trucks, "trucks_with_finding": with_finding,
                   "headline": bool(len(found))}
    out = pd.DataFrame.from_dict(rows, orient="index", columns=CRITERIA_COLUMNS)
    out.index.name = "criterion"
    return out


def ratio_text(row: pd.Series) -> str:
    """A criterion's noise ratio with its interval, as text: ``0.3 [0.2, 0.5]``; ``-`` without."""
    r, lo, hi = (float(row[k]) for k in ("ratio", "ratio_lo", "ratio_hi"))
    if not math.isfinite(r):
        return "-"
    if not math.isfinite(hi):
        return f"{r:.2g} [{lo:.2g}, unbounded]"
    if hi == lo == r:
        return f"{r:.2g}"
    return format_ci(r, lo, hi)


def trucks_text(row: pd.Series) -> str:
    """``k of N trucks`` (a finding of each truck's own campaign); empty for one truck."""
    t, k = row.get("trucks", math.nan), row.get("trucks_with_finding", math.nan)
    if not (pd.notna(t) and pd.notna(k)):
        return ""
    return f"{int(k)} of {int(t)} trucks"


def criteria_markdown(table: pd.DataFrame) -> str:
    """:func:`headline_criteria` as a Markdown table."""
    trucks = "trucks" in table and table["trucks"].notna().any()
    head = ["criterion", "findings", "rankings the noise makes", "smallest finding",
            "largest noise addition", "ratio (noise / smallest finding)"]
    head += ["a finding on the trucks' own campaigns"] if trucks else []
    rows = []
    for c, r in table.iterrows():
        unit = f" {UNITS[c]}" if c in UNITS and UNITS[c] != "%" else (
            " points" if UNITS.get(c) == "%" else "")
        cells = [str(c), str(int(r["findings"])), str(int(r["noise_made"]))]
        for k in ("smallest", "noise"):
            if not math.isfinite(r[k]):
                cells.append("-")
            elif math.isfinite(r[f"{k}_lo"]) and r[f"{k}_hi"] > r[f"{k}_lo"]:
                cells.append(f"{r[k]:.3g}{unit} [{r[f'{k}_lo']:.2g}, {r[f'{k}_hi']:.2g}]")
            else:
                cells.append(f"{r[k]:.3g}{unit}")
        cells.append(ratio_text(r))
        if trucks:
            cells.append(trucks_text(r) or "-")
        rows.append(cells)
    return pipe_table(head, rows)
