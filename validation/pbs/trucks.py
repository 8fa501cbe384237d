"""The low-speed measures in the campaign: each model's error against the truth, per truck.

Per truck (a campaign's seed), :func:`truck_table` drives the PBS low-speed
turn (:mod:`artic.validation.pbs.run`; the turn alone, the cheapest of the
three manoeuvres, which carries the swept path and the swings) on each model
built from the loaded preset and on the truck's truth, and tabulates each
measure's error against the truth (``error``) and, for KIN and the STM,
against the plant (``error_vs_plant``): ``pbs_truck.csv`` in the truck's
folder. Over trucks, :func:`pooled` gives each model's mean error on each
measure with its 95 % interval over the trucks (Student's t below eight
trucks, :func:`artic.validation.criteria.statistics.mean_ci`), and compares
the models' absolute errors pairwise, truck by truck, with Student's test on
the trucks' differences (:func:`artic.validation.criteria.multiplicity.truck_p`)
and Holm's correction over the table (family-wise 5 %): ``pbs_trucks.csv``
and ``pbs_trucks.md``.
"""

from __future__ import annotations

import contextlib
import itertools
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from artic.validation.criteria.multiplicity import holm, truck_p
from artic.validation.criteria.statistics import format_ci, mean_ci
from artic.validation.logs.runfile import atomic_write, atomic_write_text
from artic.validation.pbs.run import LOAD, MEASURES, truck_measures
from artic.validation.plumbing.workers import completed

COLUMNS = ("swept_width", "frontal_swing", "tail_swing")
"""The measures compared with the truth: those of the PBS turn that every model has."""

MODELS = ("kin", "stm", "mbd")
ALPHA = 0.05


def truck_table(seed: int, models: Sequence[str] = MODELS, truth: str | None = None,
                load: str = LOAD, jobs: int = 1, fresh: bool = False) -> pd.DataFrame:
    """One truck's measures: a row per (model, measure) with the truth's and the plant's.

    The models and the truth are driven on ``jobs`` worker processes, or in
    this one (:func:`artic.validation.plumbing.workers.completed`); with
    ``fresh`` on that many new processes however many, so that what they
    build (the truth's model, the reduced models' compiled code) stays out of
    this process's memory. The numbers are the same either way.
    """
    names = [m for m in MODELS if m in models]
    # truck_measures lives in the light run module: a fresh worker imports that
    # (0.2 s), not this one's statistics (1.3 s).
    tasks = [(n, (n, seed, truth, load)) for n in ["truth", *names]]
    with contextlib.closing(completed(truck_measures, tasks, jobs, fresh=fresh)) as done:
        runs = dict(done)
    rows = []
    for n in names:
        for c in COLUMNS:
            value, ref = runs[n][c], runs["truth"][c]
            plant = runs["mbd"][c] if "mbd" in runs and n != "mbd" else math.nan
            rows.append({"seed": seed, "load": load, "model": n, "measure": c,
                         "unit": MEASURES[c][0], "value": value, "truth": ref,
                         "error": value - ref, "plant": plant, "error_vs_plant": value - plant})
    return pd.DataFrame(rows, columns=["seed", "load", "model", "measure", "unit", "value",
                                       "truth", "error", "plant", "error_vs_plant"])


def write_truck_table(out_dir: Path, seed: int, models: Sequence[str] = MODELS,
                      truth: str | None = None, jobs: int = 1, fresh: bool = False) -> Path:
    """Write one truck's table as ``out_dir/pbs_truck.csv``, atomically.

    ``jobs`` and ``fresh`` as in :func:`truck_table`.
    """
    df = truck_table(seed, models, truth, jobs=jobs, fresh=fresh)
    return atomic_write(Path(out_dir) / "pbs_truck.csv", lambda p: df.to_csv(p, index=False))


def pooled(trucks: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Over trucks: each model's mean error per measure, and the pairwise comparisons.

    Parameters
    ----------
    trucks : DataFrame
        :func:`truck_table`'s rows of every truck.

    Returns
    -------
    errors : DataFrame
        Per (model, measure, reference): the trucks' mean error, its interval,
        the mean absolute error and its interval, the number of trucks.
    pairs : DataFrame
        Per (measure, model a, model b): the mean over trucks of
        ``|error a| - |error b|`` against the truth, its interval, Student's p
        over the trucks, Holm's adjusted p over the table, and whether it resolves.
    """
    rows = []
    for (model, measure), g in trucks.groupby(["model", "measure"], sort=False):
        for ref, col in (("truth", "error"), ("plant", "error_vs_plant")):
            e = g.sort_values("seed")[col].to_numpy(dtype=float)
            if not np.isfinite(e).any():
                continue
            iv, ia = mean_ci(e), mean_ci(np.abs(e))
            rows.append({"model": model, "measure": measure, "reference": ref,
                         "unit": g["unit"].iloc[0], "trucks": iv.n, "mean_error": iv.mean,
                         "lo": iv.lo, "hi": iv.hi, "mean_abs_error": ia.mean,
                         "abs_lo": ia.lo, "abs_hi": ia.hi})
    pairs = []
    for measure, g in trucks.groupby("measure", sort=False):
        wide = g.pivot(index="seed", columns="model", values="error").abs()
        for a, b in itertools.combinations([m for m in MODELS if m in wide.columns], 2):
            d = (wide[a] - wide[b]).to_numpy(dtype=float)
            iv = mean_ci(d)
            pairs.append({"measure": measure, "a": a, "b": b, "trucks": iv.n,
                          "mean_diff": iv.mean, "lo": iv.lo, "hi": iv.hi, "p": truck_p(d)})
    pairs_df = pd.DataFrame(pairs)
    if len(pairs_df):
        p = pairs_df["p"].to_numpy(dtype=float)
        adj = np.full(p.size, np.nan)
        ok = np.isfinite(p)
        if ok.any():
            adj[ok] = holm(p[ok])
        pairs_df["p_holm"] = adj
        pairs_df["resolved"] = pairs_df["p_holm"] < ALPHA
    return pd.DataFrame(rows), pairs_df


def markdown(errors: pd.DataFrame, pairs: pd.DataFrame) -> str:
    """The pooled tables as Markdown, with the digits each interval supports."""
    lines = ["# Low-speed measures over trucks", "",
             "Each model's error on the PBS low-speed turn's measures against the truth "
             "(and KIN's and the STM's against the plant): mean over trucks with its 95 % "
             "interval over the trucks; the mean absolute error beside it.", "",
             "| model | measure | reference | trucks | mean error | mean absolute error |",
             "|---|---|---|---|---|---|"]
    for r in errors.itertuples():
        lines.append(f"| {r.model} | {r.measure} [{r.unit}] | {r.reference} | {r.trucks} | "
                     f"{format_ci(r.mean_error, r.lo, r.hi, r.trucks)} | "
                     f"{format_ci(r.mean_abs_error, r.abs_lo, r.abs_hi, r.trucks)} |")
    if len(pairs):
        lines += ["", "Pairwise, truck by truck: |error a| - |error b| against the truth "
                  "(negative: a is closer); a finding where Holm's adjusted p over this "
                  "table is below 0.05.", "",
                  "| measure | a | b | trucks | mean difference | p (Holm) | finding |",
                  "|---|---|---|---|---|---|---|"]
        for r in pairs.itertuples():
            p = "-" if not math.isfinite(r.p_holm) else f"{r.p_holm:.2g}"
            lines.append(f"| {r.measure} | {r.a} | {r.b} | {r.trucks} | "
                         f"{format_ci(r.mean_diff, r.lo, r.hi, r.trucks)} | {p} | "
                         f"{'yes' if r.resolved else 'no'} |")
    return "\n".join(lines) + "\n"


def write_pooled(out_dir: Path, tables: Sequence[Path]) -> list[Path]:
    """Pool the trucks' ``pbs_truck.csv`` files into ``pbs_trucks.csv`` and ``.md``."""
    trucks = pd.concat([pd.read_csv(p) for p in tables], ignore_index=True)
    errors, pairs = pooled(trucks)
    csv = atomic_write(Path(out_dir) / "pbs_trucks.csv",
                       lambda p: errors.to_csv(p, index=False))
    md = atomic_write_text(Path(out_dir) / "pbs_trucks.md", markdown(errors, pairs))
    return [csv, md]
