"""The summary tables: the paper's Table 2 (forward) and Table 3 (reverse).

Each table is the mean of the criteria per model over the manoeuvres of one
direction, as the paper reports them. The paper's own values are kept here for
comparison; they come from its Tables 2 and 3 (a Scania tractor with a
tri-axle semitrailer on a test track, 17 forward and 33 reverse manoeuvres).
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from artic.validation.logs.runfile import atomic_write, atomic_write_text

FORWARD_COLUMNS = ("eps_a", "eps_v", "eps_p", "eps_n")
REVERSE_COLUMNS = ("eps_a", "eps_v", "J_steer", "eps_n")
UNITS = {"eps_a": "rad/s", "eps_v": "m/s", "eps_p": "m", "eps_n": "%", "J_steer": "%"}

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


def summary(metrics: pd.DataFrame, direction: str) -> pd.DataFrame:
    """Mean criteria per model over one direction's manoeuvres, with their count ``n``.

    Pairs without a result (status ``failed: ...`` or ``refused: ...``) are left out
    of the means and of ``n``; ``metrics.csv`` lists them.
    """
    cols = list(FORWARD_COLUMNS if direction == "forward" else REVERSE_COLUMNS)
    ok = ~metrics["status"].astype(str).str.startswith(("failed", "refused")) \
        if "status" in metrics else True
    part = metrics[(metrics["direction"] == direction) & ok]
    out = part.groupby("model", sort=False)[cols].mean()
    out["n"] = part.groupby("model", sort=False).size()
    out.index.name = "model"
    return out


def markdown(df: pd.DataFrame, digits: int = 4) -> str:
    """A small frame as a Markdown table; units from :data:`UNITS` in the header."""
    head = [df.index.name or ""] + [f"{c} [{UNITS[c]}]" if c in UNITS else str(c)
                                    for c in df.columns]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    def cell(v) -> str:
        if isinstance(v, float):
            return "-" if pd.isna(v) else f"{v:.{digits}g}"
        return str(v)

    for idx, row in df.iterrows():
        lines.append("| " + " | ".join([cell(idx), *map(cell, row)]) + " |")
    return "\n".join(lines)


def versus_paper(ours: pd.DataFrame, paper: pd.DataFrame) -> pd.DataFrame:
    """Side by side: our value, the paper's, and their ratio, per model and criterion."""
    rows = {}
    for model in ours.index:
        row = {}
        for c in paper.columns:
            a = float(ours.loc[model, c])
            b = float(paper.loc[model, c]) if model in paper.index else float("nan")
            row[f"{c}"] = a
            row[f"{c} (paper)"] = b
            row[f"{c} ratio"] = a / b if b else float("nan")
        rows[model] = row
    out = pd.DataFrame.from_dict(rows, orient="index")
    out.index.name = "model"
    return out


def write_table(df: pd.DataFrame, path_stem: Path, title: str) -> tuple[Path, Path]:
    """Write ``STEM.csv`` and ``STEM.md`` atomically."""
    path_stem = Path(path_stem)
    csv = atomic_write(path_stem.with_suffix(".csv"),
                       lambda p: df.to_csv(p, float_format="%.6g"))
    md = atomic_write_text(path_stem.with_suffix(".md"), f"# {title}\n\n{markdown(df)}\n")
    return csv, md
