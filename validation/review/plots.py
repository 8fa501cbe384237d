"""Static plots of a manoeuvre: the yard seen from above, and its key signals.

The same data as a manoeuvre's recording (:mod:`artic.validation.review.recording`), for
reports and documents where a viewer is not at hand. matplotlib renders
off-screen (Agg); files are written atomically.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from artic.validation.criteria.distance import travelled
from artic.validation.logs.runfile import Run, atomic_write
from artic.validation.models import REGISTRY


def _style(name: str) -> dict:
    """Line style of the measured run (dark, heavy) or of a registered model."""
    if name == "measured":
        return {"color": "0.1", "lw": 2.2}
    s = REGISTRY.get(name)
    return {"color": s.hex_colour} if s is not None else {}


def plot_manoeuvre(path: Path, log: Run, runs: Mapping[str, Run], title: str = "") -> Path:
    """Top view of the sensor paths, articulation and harness feedback against distance.

    Parameters
    ----------
    path : Path
        PNG to write.
    log : Run
        The measured log.
    runs : mapping of str to Run
        Model runs by model name.
    """
    from matplotlib.figure import Figure

    f = log.frame
    s = travelled(f)
    fig = Figure(figsize=(12, 5.5), layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=[1.4, 1])
    top = fig.add_subplot(grid[:, 0])
    art = fig.add_subplot(grid[0, 1])
    fb = fig.add_subplot(grid[1, 1], sharex=art)
    frames = {"measured": f, **{k: r.frame for k, r in runs.items()}}
    for name, frame in frames.items():
        st = _style(name)
        top.plot(frame["x_1"], frame["y_1"], label=f"{name} tractor", **st)
        top.plot(frame["x_2"], frame["y_2"], ls="--", label=f"{name} trailer", **st)
        n = len(frame)
        art.plot(s[:n], np.degrees(frame["gamma"]), label=name, **st)
        if "delta_fb" in frame:
            fb.plot(s[:n], np.degrees(frame["delta_fb"]), label=name, **st)
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x [m]")
    top.set_ylabel("y [m]")
    top.set_title("sensor paths (tractor solid, trailer dashed)")
    top.legend(fontsize=7, ncol=2)
    art.set_ylabel("articulation [deg]")
    fb.set_ylabel("harness feedback [deg]")
    fb.set_xlabel("distance travelled by the tractor sensor [m]")
    for ax in (top, art, fb):
        ax.grid(True, alpha=0.3)
    fig.suptitle(title or log.name)
    atomic_write(path, lambda p: fig.savefig(p, format="png", dpi=100))
    return Path(path)
