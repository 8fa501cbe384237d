"""Steady-state tyre curves, for checking a ``.tir`` file before trusting it.

``artic tyre curves`` writes them: pure longitudinal slip Fx(kappa) at zero
slip angle, pure side slip Fy(alpha) and Mz(alpha) at zero longitudinal slip,
and a combined-slip grid, each at the loads asked for. The formulas are the
plant's own (:func:`artic.plant.tyre.steady_state`), forward rolling, zero camber,
in artic's conventions (ISO axes; a positive slip angle slides to the right
and pushes left).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from artic.plant.tyre import TyreParams, steady_state

COLUMNS = ("fz", "kappa", "alpha_deg", "gamma_deg", "fx", "fy", "mz")
"""One row per point, SI units except the angles [deg]."""

KAPPA_RANGE = 0.3
"""Pure longitudinal sweep: kappa over +-this [-]."""

ALPHA_RANGE_DEG = 20.0
"""Pure lateral sweep: alpha over +-this [deg]."""


def curves(p: TyreParams, loads: list[float], n: int = 121) -> pd.DataFrame:
    """The sweeps and the combined grid at each load, as one table (:data:`COLUMNS`).

    Parameters
    ----------
    p : TyreParams
        The tyre.
    loads : list of float
        Vertical loads [N].
    n : int
        Points per pure sweep.
    """
    rows = []
    kappa = np.linspace(-KAPPA_RANGE, KAPPA_RANGE, n)
    alpha = np.radians(np.linspace(-ALPHA_RANGE_DEG, ALPHA_RANGE_DEG, n))
    grid_k, grid_a = np.meshgrid(np.linspace(-KAPPA_RANGE, KAPPA_RANGE, 13),
                                 np.radians(np.linspace(-ALPHA_RANGE_DEG, ALPHA_RANGE_DEG, 9)))
    for fz in loads:
        for k, a in ((kappa, np.zeros_like(kappa)), (np.zeros_like(alpha), alpha),
                     (grid_k.ravel(), grid_a.ravel())):
            fx, fy, mz = steady_state(p, np.full(k.shape, float(fz)), k, a)
            rows.append(pd.DataFrame({"fz": float(fz), "kappa": k, "alpha_deg": np.degrees(a),
                                      "gamma_deg": 0.0, "fx": fx, "fy": fy, "mz": mz}))
    return pd.concat(rows, ignore_index=True)[list(COLUMNS)]


def plot_curves(table: pd.DataFrame, path: Path, title: str) -> None:
    """Fx(kappa), Fy(alpha) and Mz(alpha) per load, and Fy against Fx on the grid, as a PNG."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(12, 8), layout="constrained")
    ax = fig.subplots(2, 2)
    for fz, g in table.groupby("fz"):
        label = f"Fz = {fz / 1e3:g} kN"
        pure_k = g[g.alpha_deg == 0.0].drop_duplicates("kappa").sort_values("kappa")
        ax[0, 0].plot(pure_k.kappa, pure_k.fx / 1e3, label=label)
        pure_a = g[g.kappa == 0.0].drop_duplicates("alpha_deg").sort_values("alpha_deg")
        ax[0, 1].plot(pure_a.alpha_deg, pure_a.fy / 1e3, label=label)
        ax[1, 0].plot(pure_a.alpha_deg, pure_a.mz, label=label)
        ax[1, 1].plot(g.fx / 1e3, g.fy / 1e3, ".", ms=3, label=label)
    for a, (x, y) in zip(ax.ravel(), (("kappa [-]", "Fx [kN]"), ("alpha [deg]", "Fy [kN]"),
                                      ("alpha [deg]", "Mz [N m]"), ("Fx [kN]", "Fy [kN]")),
                         strict=True):
        a.set_xlabel(x)
        a.set_ylabel(y)
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8)
    ax[1, 1].set_title("combined slip")
    fig.suptitle(title)
    fig.savefig(path, format="png", dpi=90)
