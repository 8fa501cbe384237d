"""The swept paths drawn: each model's over the truth's, one column per model.

Above, the swept path of the PBS turn, the envelope of both bodies
(:func:`artic.validation.pbs.sweep.swept`) drawn back in the yard, with the
steer axle's prescribed path; below, its width along the path, where the
models' centimetres show. Written atomically as ``swept-path.png``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from artic.validation.logs.runfile import atomic_write
from artic.validation.pbs.motion import Geometry, Motion
from artic.validation.pbs.paths import TurnPath
from artic.validation.pbs.run import ModelRun, paths
from artic.validation.pbs.sweep import swept


def envelope(path: TurnPath, run: ModelRun) -> tuple[np.ndarray, np.ndarray]:
    """The PBS turn's swept path of ``run`` as outer and inner curves in the yard, (K, 2) each."""
    t, obs, _ = run.drives["pbs"]
    m = Motion.from_observations(run.vehicle, t, obs)
    sw = swept(path, m.body_points())
    keep = np.isfinite(sw.outer) & (sw.station >= 0.0) & (sw.station <= path.length)
    s = sw.station[keep]
    x, y, h = path.pose(s)
    curves = []
    for n in (sw.outer[keep], sw.inner[keep]):
        curves.append(np.c_[x - n * np.sin(h), y + n * np.cos(h)])
    return curves[0], curves[1]


def plot_swept_paths(out: Path, runs: Mapping[str, ModelRun], title: str) -> Path:
    """Draw each model's swept path over the truth's (or alone without a truth)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from artic.validation.models import REGISTRY

    models = [n for n in runs if n != "truth"]
    fig, axes = plt.subplots(2, len(models), figsize=(4.2 * len(models), 7.6),
                             sharex="row", sharey="row", squeeze=False,
                             gridspec_kw={"height_ratios": [3, 2]})
    truth = runs.get("truth")
    for ax, prof, name in zip(axes[0], axes[1], models, strict=True):
        r = runs[name]
        path = paths(Geometry.of(r.vehicle))["pbs"][0]
        if truth is not None:
            tpath = paths(Geometry.of(truth.vehicle))["pbs"][0]
            for c in envelope(tpath, truth):
                ax.plot(c[:, 0], c[:, 1], color="black", lw=2.5, alpha=0.35, label="truth")
        colour = REGISTRY[name].hex_colour if name in REGISTRY else "C0"
        for c in envelope(path, r):
            ax.plot(c[:, 0], c[:, 1], color=colour, lw=1.0, label=name)
        px, py, _ = path.pose(np.linspace(0.0, path.length, 400))
        ax.plot(px, py, color="grey", lw=0.6, ls="--", label="steer axle's path")
        ax.set_title(f"{name}: swept width {r.measures['swept_width']:.2f} m")
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        handles, labels = ax.get_legend_handles_labels()
        uniq = dict(zip(labels, handles, strict=True))
        ax.legend(uniq.values(), uniq.keys(), fontsize=7, loc="upper left")
        for rr_, c, lw in ((truth, "black", 2.5), (r, colour, 1.0)):
            if rr_ is None:
                continue
            p_ = paths(Geometry.of(rr_.vehicle))["pbs"][0]
            t, obs, _ = rr_.drives["pbs"]
            sw = swept(p_, Motion.from_observations(rr_.vehicle, t, obs).body_points())
            keep = (sw.station >= p_.entry - 5.0) & (sw.station <= p_.length)
            prof.plot(sw.station[keep] - p_.entry, sw.width[keep], color=c, lw=lw,
                      alpha=0.35 if rr_ is truth else 1.0,
                      label="truth" if rr_ is truth else name)
        prof.set_xlabel("station from the arc's start [m]")
        prof.legend(fontsize=7)
    axes[0][0].set_ylabel("y [m]")
    axes[1][0].set_ylabel("swept width [m]")
    fig.suptitle(title)
    fig.tight_layout()

    def save(p: Path) -> None:
        fig.savefig(p, format="png", dpi=110)

    try:
        return atomic_write(out, save)
    finally:
        plt.close(fig)
