"""The final errors of a docking benchmark as a picture, for documents without a viewer.

One panel per scenario: each run's final lateral error [cm] against its
heading error [deg], a marker per controller, the issue's bar (10 cm, 1 deg)
as a dashed box; failed runs are listed under the panel rather than drawn at
the place they stopped. matplotlib renders off-screen (Agg); the file is
written atomically.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from artic.validation.logs.runfile import atomic_write

BAR = (10.0, 1.0)
"""The issue's bar on a docked run: |lateral| [cm] and |heading| [deg]."""

MARKERS = ("o", "s", "^", "D", "v", "P", "X")


def plot_errors(rows: pd.DataFrame, path: Path) -> Path:
    """Write the final-error plot of ``rows`` (``dock.csv``'s) to the PNG ``path``."""
    from matplotlib.figure import Figure

    scenarios = list(dict.fromkeys(rows["scenario"]))
    controllers = list(dict.fromkeys(rows["controller"]))
    vehicles = list(dict.fromkeys(rows["vehicle"]))
    fig = Figure(figsize=(4.0 * len(scenarios), 4.4))
    axes = fig.subplots(1, len(scenarios), squeeze=False)[0]
    colours = {v: f"C{i}" for i, v in enumerate(vehicles)}
    for ax, scen in zip(axes, scenarios, strict=True):
        g = rows[rows["scenario"] == scen]
        ok = g[g["success"].astype(bool)]
        for k, c in enumerate(controllers):
            for v in vehicles:
                sel = ok[(ok["controller"] == c) & (ok["vehicle"] == v)]
                ax.scatter(100.0 * sel["lateral_error_m"], sel["heading_error_deg"], s=22,
                           marker=MARKERS[k % len(MARKERS)], color=colours[v], alpha=0.8,
                           label=f"{c}, {v}")
        ax.plot([-BAR[0], BAR[0], BAR[0], -BAR[0], -BAR[0]],
                [-BAR[1], -BAR[1], BAR[1], BAR[1], -BAR[1]], "k--", lw=0.8)
        lim_x = max(BAR[0] * 1.3, _largest(100.0 * ok["lateral_error_m"]) * 1.1)
        lim_y = max(BAR[1] * 1.3, _largest(ok["heading_error_deg"]) * 1.1)
        ax.set_xlim(-lim_x, lim_x)
        ax.set_ylim(-lim_y, lim_y)
        ax.axhline(0.0, color="0.8", lw=0.6)
        ax.axvline(0.0, color="0.8", lw=0.6)
        ax.set_xlabel("final lateral error of the rear [cm]")
        failed = len(g) - len(ok)
        ax.set_title(f"{scen}: {len(ok)} of {len(g)} docked"
                     + (f" ({failed} failed)" if failed else ""), fontsize=10)
    axes[0].set_ylabel("final heading error [deg]")
    handles, labels = axes[0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 4), fontsize=8,
                   frameon=False)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    return atomic_write(path, lambda p: fig.savefig(p, format="png", dpi=110))


def _largest(values) -> float:
    """The largest finite magnitude, 0 without one (no all-NaN warning for an all-failed table)."""
    x = np.abs(np.asarray(values, dtype=float))
    x = x[np.isfinite(x)]
    return float(x.max()) if x.size else 0.0


SWEEP_PANELS = (("success", "success rate (Wilson 95 % CI)", 1.0),
                ("lateral_cm", "final |lateral| [cm] (finished runs)", 1.0),
                ("heading_deg", "final |heading| [deg] (finished runs)", 1.0))
"""A sweep's panels: sweep.csv's column (with ``_lo``, ``_hi``), label, scale."""


def plot_sweep(summary: pd.DataFrame, path: Path, note: str = "") -> Path:
    """Write ``sweep.png``: success and errors against the level, one line per controller.

    One row of panels per axis, scenario and vehicle (several sweeps' tables
    concatenated draw one row each); each point has its 95 % interval as an
    error bar (Wilson for the rates, the project's mean interval for the
    errors), the controllers' points a little apart at each level so that
    every bar shows. Named levels (a sensor set) stand at equal spacing in
    the order given.

    Parameters
    ----------
    summary : DataFrame
        ``sweep.csv`` (:func:`artic.validation.docking.sweep.summarise`), or several.
    path : Path
        The PNG.
    note : str
        A line under the title (where it was measured).
    """
    from matplotlib.figure import Figure

    from artic.validation.docking.sweep import level_text

    cases = list(dict.fromkeys(zip(summary["axis"], summary["scenario"], summary["vehicle"],
                                   strict=True)))
    controllers = list(dict.fromkeys(summary["controller"]))
    fig = Figure(figsize=(4.2 * len(SWEEP_PANELS), 3.2 * len(cases) + 0.9))
    axes = fig.subplots(len(cases), len(SWEEP_PANELS), squeeze=False)
    for row, (axis, scen, veh) in zip(axes, cases, strict=True):
        g = summary[(summary["axis"] == axis) & (summary["scenario"] == scen)
                    & (summary["vehicle"] == veh)]
        unit = str(g["unit"].iloc[0]) if isinstance(g["unit"].iloc[0], str) else ""
        levels = list(dict.fromkeys(g["level"].map(level_text)))
        try:
            values = g["level"].to_numpy(dtype=float)
            numeric = True
        except ValueError:
            numeric = False
        span = (float(np.ptp(values)) if numeric else 1.0) or 1.0
        dodge = 0.012 * span  # the controllers' points side by side, so each bar shows
        for ax, (col, label, scale) in zip(row, SWEEP_PANELS, strict=True):
            for k, c in enumerate(controllers):
                s = g[g["controller"] == c]
                x = (s["level"].to_numpy(dtype=float) if numeric
                     else np.array([levels.index(level_text(v)) for v in s["level"]], float))
                x = x + dodge * (k - 0.5 * (len(controllers) - 1))
                y = scale * s[col].to_numpy(dtype=float)
                lo = np.clip(y - scale * s[f"{col}_lo"].to_numpy(dtype=float), 0.0, None)
                hi = np.clip(scale * s[f"{col}_hi"].to_numpy(dtype=float) - y, 0.0, None)
                ax.errorbar(x, y, yerr=np.nan_to_num(np.vstack([lo, hi])),
                            marker=MARKERS[k % len(MARKERS)], capsize=3, lw=1.2, ms=5,
                            color=f"C{k}", label=c)
            if numeric:  # every level's place, also where a panel has no value there
                ax.set_xlim(values.min() - 0.06 * span, values.max() + 0.06 * span)
            else:
                ax.set_xticks(range(len(levels)), levels)
                ax.set_xlim(-0.5, len(levels) - 0.5)
            ax.set_xlabel(f"{axis} [{unit}]" if unit and unit != "-" else axis)
            ax.set_title(f"{scen}, {veh}", fontsize=9)
            ax.set_ylabel(label, fontsize=9)
            if col == "success":
                ax.set_ylim(-0.05, 1.05)
            else:
                ax.set_ylim(bottom=0.0)
    handles, labels = axes[0][0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 5), fontsize=9,
                   frameon=False)
    names = ", ".join(dict.fromkeys(a for a, _, _ in cases))
    fig.suptitle(f"robustness sweep: {names}" + (f" ({note})" if note else ""), fontsize=11)
    fig.tight_layout(rect=(0, 0.6 / (3.2 * len(cases) + 0.9), 1, 0.97))
    return atomic_write(path, lambda p: fig.savefig(p, format="png", dpi=100))
