"""The measures' tables: each model's value, the truth's, the error, and the PBS level met.

Two tables from the runs of :func:`artic.validation.pbs.run.run_model`, both
written atomically: ``pbs.csv``, one row per (model, measure), and
``pbs.md``, the same as a Markdown table with the documents the manoeuvres
and limits come from.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import pandas as pd

from artic.validation.logs.runfile import atomic_write, atomic_write_text
from artic.validation.pbs.run import MEASURES, ModelRun
from artic.validation.pbs.standards import FHWA_STUDY, PBS_RULES, SAE_J695, level

LEVELLED = ("truth", "mbd")
"""The models whose PBS level is stated: the truth, and the plant that stands for it."""


def table(runs: Mapping[str, ModelRun]) -> pd.DataFrame:
    """One row per (model, measure): value, truth's value, error, PBS level."""
    truth = runs.get("truth")
    rows = []
    for name, r in runs.items():
        for col, (unit, man, _) in MEASURES.items():
            value = r.measures.get(col, math.nan)
            ref = truth.measures.get(col, math.nan) if truth is not None else math.nan
            rows.append({"model": name, "measure": col, "unit": unit, "manoeuvre": man,
                         "value": value, "truth": ref,
                         "error": value - ref if name != "truth" else math.nan,
                         "pbs_level": level(col, value) if name in LEVELLED else ""})
    return pd.DataFrame(rows)


def _cell(x: float, digits: int) -> str:
    return "n/a" if not math.isfinite(x) else f"{x:.{digits}f}"


def markdown(df: pd.DataFrame, vehicle: str) -> str:
    """The table as Markdown: measures down, models across, the truth's levels."""
    models = list(dict.fromkeys(df["model"]))
    head = ["measure", "unit", *models, *(f"PBS level ({m})" for m in LEVELLED if m in models)]
    lines = [f"# Low-speed performance measures: {vehicle}", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for col in MEASURES:
        sub = df[df["measure"] == col].set_index("model")
        digits = 1 if sub["unit"].iloc[0] == "%" else 3
        cells = [_cell(float(sub.loc[m, "value"]), digits) for m in models]
        levels = [sub.loc[m, "pbs_level"] or "-" for m in LEVELLED if m in models]
        lines.append(f"| {col} | {sub['unit'].iloc[0]} | " + " | ".join(cells + levels) + " |")
    lines += ["", "Measures: " + "; ".join(f"`{c}`: {w} ({m})" for c, (_, m, w)
                                          in MEASURES.items()) + ".", "",
              f"Manoeuvre `pbs` and the levels' limits: {PBS_RULES}. Manoeuvre `fhwa`: "
              f"{FHWA_STUDY}. Manoeuvre `j695`: {SAE_J695}.", ""]
    return "\n".join(lines)


def write_tables(out_dir: Path, runs: Mapping[str, ModelRun], vehicle: str) -> list[Path]:
    """Write ``pbs.csv`` and ``pbs.md`` into ``out_dir`` atomically."""
    df = table(runs)
    csv = atomic_write(Path(out_dir) / "pbs.csv", lambda p: df.to_csv(p, index=False))
    md = atomic_write_text(Path(out_dir) / "pbs.md", markdown(df, vehicle))
    return [csv, md]
