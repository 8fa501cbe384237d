"""The campaign's frequency response: each model against the truth, per truck and pooled.

From the validation's runs of the swept sine (forward: the harness's feedback
is off, so every model runs open loop on the log's steering), per truck
``frequency_response.csv`` (every band, :func:`artic.validation.review.frequency.compare`)
and ``frequency_departure.md`` (where each model first leaves the bound); over
trucks the mean errors per band with their intervals and the departure of the
mean. The floor's run (the truth's own replay) shows what the estimate itself
costs, where its run file keeps samples.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import pandas as pd

from artic.validation.criteria.statistics import format_ci, mean_ci
from artic.validation.logs.runfile import LogError, Run, read_run
from artic.validation.review.frequency import GAIN_BOUND, PHASE_BOUND, compare, departure
from artic.validation.review.tables import markdown, write_table

STEM = "frequency_response"
"""The per-band table's file stem."""

DEPARTURE = "frequency_departure"
"""The departure table's file stem."""

_NOTE = (f"The lowest band [Hz] where a model's gain departs from the truth's by more than "
         f"{GAIN_BOUND:.0%} or its phase by more than {PHASE_BOUND:g} deg (-: within the "
         "bound over the whole sweep); the truth drives the swept sine, each model is driven "
         "by the log's steering (docs: guide/rating.md).")


def _centres(dep: pd.DataFrame) -> pd.DataFrame:
    """The departure table with its band centres to 3 significant digits, for reading."""
    return dep.map(lambda f: float(f"{f:.3g}"))


def write(out_dir: Path, logs: Iterable[Run]) -> dict[str, Path]:
    """Write one truck's frequency tables, from its swept-sine logs and their run files.

    Returns
    -------
    dict of str to Path
        The files written by name; empty without a swept-sine log or its runs.
    """
    out_dir = Path(out_dir)
    tables = []
    for log in logs:
        if log.meta.get("manoeuvre") != "swept-sine":
            continue
        runs = {}
        for p in sorted((out_dir / "runs").glob(f"{log.name}.*.parquet")):
            try:
                runs[p.name[len(log.name) + 1:-len(".parquet")]] = read_run(p)
            except LogError:  # a reference that keeps its criteria alone (the floor's)
                continue
        if runs:
            tables.append(compare(log, runs).assign(log=log.name))
    if not tables:
        return {}
    table = pd.concat(tables, ignore_index=True)
    paths = {}
    paths[STEM], _ = write_table(table, out_dir / STEM, "Frequency response, per band")
    dep = departure(table)
    paths[DEPARTURE], _ = write_table(dep, out_dir / DEPARTURE, "Frequency response: departure",
                                      f"{_NOTE}\n\n{markdown(_centres(dep))}")
    return paths


def write_pooled(out_dir: Path, seed_dirs: Iterable[Path]) -> dict[str, Path]:
    """Write the frequency tables pooled over trucks, from each truck's per-band table.

    Per model, signal and band: the mean gain error [-] and phase error [deg] over
    trucks with their intervals (:func:`artic.validation.criteria.statistics.mean_ci`),
    and the departure of the means.
    """
    parts = [pd.read_csv(p, index_col=0) for d in seed_dirs
             if (p := Path(d) / f"{STEM}.csv").is_file()]
    if not parts:
        return {}
    every = pd.concat(parts, ignore_index=True)
    rows, text = [], []
    for (model, signal, f), g in every.groupby(["model", "signal", "f"], sort=False):
        gain, phase = mean_ci(g["gain_error"].to_numpy()), mean_ci(g["phase_error"].to_numpy())
        rows.append({"model": model, "signal": signal, "f": f,
                     "gain_error": gain.mean, "gain_error_lo": gain.lo,
                     "gain_error_hi": gain.hi, "phase_error": phase.mean,
                     "phase_error_lo": phase.lo, "phase_error_hi": phase.hi, "n": len(g)})
        text.append({"model": model, "signal": signal, "f [Hz]": f"{f:.3g}",
                     "gain error [-]": format_ci(gain), "phase error [deg]": format_ci(phase),
                     "n": len(g)})
    table = pd.DataFrame(rows)
    out_dir = Path(out_dir)
    paths = {}
    paths[STEM], _ = write_table(table, out_dir / STEM,
                                 "Frequency response over trucks, per band",
                                 markdown(pd.DataFrame(text).set_index("model")))
    dep = departure(table)
    paths[DEPARTURE], _ = write_table(dep, out_dir / DEPARTURE,
                                      "Frequency response over trucks: departure of the mean",
                                      f"{_NOTE}\n\n{markdown(_centres(dep))}")
    return paths
