"""Rerun recordings: one ``.rrd`` per manoeuvre, and one for the campaign.

This is artic's only module that imports rerun.

A manoeuvre recording holds, on two timelines, ``time`` (a duration [s]) and
``distance_cm`` (the measured tractor sensor's travelled distance [cm], the
variable of the error criteria):

- ``/yard``: the measured combination and every model's, as boxes for the
  bodies and the wheels, moving with their own poses; their sensor paths; the
  swept envelope (the tracks of the tractor's front and the semitrailer's
  rear corners); the ground and,
  for docking and parking, the dock;
- ``/signals``: steering inputs (the measured steering-wheel angle; each
  model's centre road-wheel angle and the feedback the harness added), yaw
  rates and lateral velocities of both units, articulation, and the running
  errors of eq. (8) (lateral position and yaw rate of the tractor);
- ``/description``: the vehicle file, the parameters of each model, the
  criteria, and the artic version;
- a default blueprint, so the viewer opens on the yard, seen from behind and
  above the paths, beside the plots.

Files are written to a temporary name and renamed when complete.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Mapping
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np
import pandas as pd
import rerun as rr
import rerun.blueprint as rrb
from rerun.chunk import RrdReader

from mjcf.outline import DOCK_DEPTH, DOCK_FACE, outline
from mjcf.tir import read_tir
from mjcf.vehicle import Vehicle
from validation.logs.runfile import Run
from validation.metrics import distance_weights, travelled
from validation.models import colour as model_colour
from validation.pathdist import distance_to_polyline

YARD_RATE = 10.0
"""Samples per second of the 3-D yard (the plots keep every sample) [Hz]."""

APPLICATION = "artic"


def artic_version() -> str:
    """The installed artic version."""
    try:
        return version("artic")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "unknown"


def _timelines(t: np.ndarray, s: np.ndarray) -> list[rr.TimeColumn]:
    return [rr.TimeColumn("time", duration=t),
            rr.TimeColumn("distance_cm", sequence=np.round(100.0 * s).astype(np.int64))]


def _quat_z(psi: np.ndarray) -> np.ndarray:
    """Quaternions (x, y, z, w) of yaw angles [rad]."""
    z = np.zeros_like(psi)
    return np.column_stack([z, z, np.sin(psi / 2), np.cos(psi / 2)])


class _Geometry:
    """Boxes of the bodies and wheels, in each unit's frame, from the vehicle file.

    The tractor frame sits at the drive axle, the trailer frame at the kingpin,
    both ISO (x forward, y left). Wheels have the tyre file's radius; the
    bodies are :func:`mjcf.outline.outline`'s, as the plant and the docking
    driver have them.
    """

    def __init__(self, v: Vehicle) -> None:
        o = outline(v)
        self.tractor_body = ((o.tractor_front + o.tractor_rear) / 2,
                             (o.tractor_front - o.tractor_rear) / 2, o.width / 2)
        self.trailer_body = ((o.trailer_front + o.trailer_rear) / 2,
                             (o.trailer_front - o.trailer_rear) / 2, o.width / 2)
        self.s1 = np.array(v.sensor1[:2])
        self.s2 = np.array(v.sensor2[:2])
        self.R0 = read_tir(v.tyre_file).number("UNLOADED_RADIUS")

        def wheels(axles):
            c = [[a.x, side * a.track / 2, self.R0] for a in axles for side in (1, -1)]
            return np.array(c)

        self.tractor_wheels = wheels(v.tractor_axles)
        self.trailer_wheels = wheels(v.trailer_axles)

    def corners(self, unit: str) -> np.ndarray:
        """The corners that bound the swept path, in the unit's frame [m].

        The tractor's front corners and the semitrailer's rear corners: in
        a turn the outer front corner sweeps the outside of the path and the
        trailer's inner rear corner the inside.
        """
        if unit == "tractor":
            cx, hx, hy = self.tractor_body
            return np.array([[cx + hx, hy], [cx + hx, -hy]])
        cx, hx, hy = self.trailer_body
        return np.array([[cx - hx, hy], [cx - hx, -hy]])


def _origin(x, y, psi, s):
    """Unit frame origin from its sensor's position and the yaw."""
    c, sn = np.cos(psi), np.sin(psi)
    return x - (c * s[0] - sn * s[1]), y - (sn * s[0] + c * s[1])


def _log_combination(rec: rr.RecordingStream, src: str, frame: pd.DataFrame, geo: _Geometry,
                     t: np.ndarray, s_cm: np.ndarray, every: int) -> None:
    colour = model_colour(src)
    base = f"/yard/{src}"
    paths = []
    for i, unit, s, body, wheels in ((1, "tractor", geo.s1, geo.tractor_body,
                                      geo.tractor_wheels),
                                     (2, "trailer", geo.s2, geo.trailer_body,
                                      geo.trailer_wheels)):
        x, y, psi = (frame[f"{c}_{i}"].to_numpy() for c in ("x", "y", "psi"))
        ox, oy = _origin(x, y, psi, s)
        sel = slice(None, None, every)
        rec.send_columns(f"{base}/{unit}", indexes=_timelines(t[sel], s_cm[sel]),
                         columns=rr.Transform3D.columns(
                             translation=np.column_stack([ox, oy, np.zeros_like(ox)])[sel],
                             quaternion=_quat_z(psi)[sel]))
        cx, hx, hy = body
        rec.log(f"{base}/{unit}/body", rr.Boxes3D(centers=[[cx, 0.0, 1.8]],
                                                  half_sizes=[[hx, hy, 1.3]],
                                                  colors=[colour], fill_mode="majorwireframe"),
                static=True)
        rec.log(f"{base}/{unit}/wheels",
                rr.Boxes3D(centers=wheels, half_sizes=[[geo.R0, 0.15, geo.R0]] * len(wheels),
                           colors=[colour], fill_mode="solid"), static=True)
        paths.append(np.column_stack([x, y, np.full_like(x, 0.05)]))
        c, sn = np.cos(psi), np.sin(psi)
        tracks = [np.column_stack([ox + c * px - sn * py, oy + sn * px + c * py,
                                   np.full_like(ox, 0.02)]) for px, py in geo.corners(unit)]
        rec.log(f"{base}/envelope/{unit}", rr.LineStrips3D(tracks, colors=[colour],
                                                           radii=0.015), static=True)
    rec.log(f"{base}/path", rr.LineStrips3D(paths, colors=[colour], radii=0.05), static=True)


def _series(rec, path: str, times, values: np.ndarray, name: str, colour) -> None:
    rec.send_columns(path, indexes=times, columns=rr.Scalars.columns(scalars=values))
    rec.log(path, rr.SeriesLines(colors=[colour], names=[name]), static=True)


def _running_rms(eps: np.ndarray, w: np.ndarray) -> np.ndarray:
    cw = np.cumsum(w)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.sqrt(np.cumsum(w * eps ** 2) / np.where(cw > 0, cw, np.nan))


def _blueprint(lo: np.ndarray, hi: np.ndarray) -> rrb.Blueprint:
    """The layout: the yard, looked at from behind and above its paths, beside the plots."""
    plots = [rrb.TimeSeriesView(origin=f"/signals/{g}", name=title) for g, title in (
        ("steering_wheel", "Steering wheel [rad]"),
        ("steering", "Road-wheel angle and harness feedback [rad]"),
        ("yaw_rate", "Yaw rate [rad/s]"), ("lateral_velocity", "Lateral velocity [m/s]"),
        ("articulation", "Articulation [rad]"), ("error", "Running errors, eq. (8) [m, rad/s]"))]
    centre = (lo + hi) / 2
    span = float(max(hi - lo))
    eye = rrb.EyeControls3D(position=[centre[0] + 0.15 * span, centre[1] - 0.55 * span,
                                      0.45 * span],
                            look_target=[centre[0], centre[1], 0.0], eye_up=[0.0, 0.0, 1.0])
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(rrb.Spatial3DView(origin="/yard", name="Yard", eye_controls=eye),
                         rrb.TextDocumentView(origin="/description", name="Description"),
                         row_shares=[3, 1]),
            rrb.Vertical(*plots),
            column_shares=[3, 2]),
        collapse_panels=True)


def _description(log: Run, runs: Mapping[str, Run], vehicle: Vehicle,
                 metrics: pd.DataFrame | None, extra: str) -> str:
    lines = [f"# {log.name}", "",
             f"artic {artic_version()}; vehicle `{vehicle.name}` from `{vehicle.path}`.", "",
             "| model | i_s | q [1/rad] | offset [deg] | f [1/rad] | status |",
             "|---|---|---|---|---|---|"]
    for name, run in runs.items():
        st = run.meta.get("steering", {})
        f = f"{vehicle.f:.3g}" if name == "stm" else "-"
        lines.append(f"| {name} | {st.get('i_s', float('nan')):.4g} | "
                     f"{st.get('q', float('nan')):.4g} | "
                     f"{np.degrees(st.get('delta_h_offset', float('nan'))):.3g} | {f} | "
                     f"{run.meta.get('status', '')} |")
    if metrics is not None and len(metrics):
        cols = ["eps_p", "eps_a", "eps_v", "eps_n", "J_steer"]
        lines += ["", "| model | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
        for _, row in metrics.iterrows():
            lines.append(f"| {row['model']} | " + " | ".join(f"{row[c]:.4g}" for c in cols)
                         + " |")
    if extra:
        lines += ["", extra]
    return "\n".join(lines)


@contextlib.contextmanager
def _recording(path: Path, recording_id: str, blueprint: rrb.Blueprint):
    """A recording stream saved to ``path``: complete, or not at all.

    The stream writes to a temporary file beside ``path``, which is renamed
    onto it once everything is logged and flushed; on any error the
    temporary file is removed and ``path`` is left as it was.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    rec = rr.RecordingStream(APPLICATION, recording_id=recording_id, send_properties=False)
    try:
        rec.save(tmp, default_blueprint=blueprint)
        yield rec
        rec.flush()
        rec.disconnect()
        os.replace(tmp, path)
    finally:
        rec.disconnect()
        tmp.unlink(missing_ok=True)


def record_manoeuvre(path: Path, log: Run, runs: Mapping[str, Run], vehicle: Vehicle,
                     metrics: pd.DataFrame | None = None, extra: str = "") -> Path:
    """Write one manoeuvre's recording.

    Parameters
    ----------
    path : Path
        The ``.rrd`` to write.
    log : Run
        The measured log.
    runs : mapping of str to Run
        Each model's run from the harness, by model name.
    vehicle : Vehicle
        The parameters the models ran with (geometry of the boxes).
    metrics : DataFrame, optional
        The manoeuvre's metrics rows, for the description.
    extra : str
        Further Markdown for the description.
    """
    f = log.frame
    xy = np.concatenate([f[["x_1", "y_1"]].to_numpy(), f[["x_2", "y_2"]].to_numpy()])
    with _recording(path, f"artic-{log.name}", _blueprint(xy.min(axis=0), xy.max(axis=0))) as rec:
        _log_manoeuvre(rec, log, runs, vehicle, metrics, extra)
    return Path(path)


def _log_manoeuvre(rec: rr.RecordingStream, log: Run, runs: Mapping[str, Run], vehicle: Vehicle,
                   metrics: pd.DataFrame | None, extra: str) -> None:
    f = log.frame
    t = f["t"].to_numpy()
    s = travelled(f)
    every = max(1, round(1.0 / (YARD_RATE * float(np.median(np.diff(t))))))
    geo = _Geometry(vehicle)
    margin = 15.0
    xy = np.concatenate([f[["x_1", "y_1"]].to_numpy(), f[["x_2", "y_2"]].to_numpy()])
    lo, hi = xy.min(axis=0) - margin, xy.max(axis=0) + margin
    rec.log("/yard/ground", rr.Boxes3D(centers=[[*(lo + hi) / 2, -0.05]],
                                       half_sizes=[[*(hi - lo) / 2, 0.05]],
                                       colors=[(90, 90, 85)], fill_mode="solid"), static=True)
    if log.meta.get("manoeuvre") in ("docking", "parking"):
        rec.log("/yard/dock", rr.Boxes3D(centers=[[DOCK_FACE[0] - DOCK_DEPTH / 2, DOCK_FACE[1],
                                                   1.3]],
                                         half_sizes=[[DOCK_DEPTH / 2, 3.0, 1.3]],
                                         colors=[(110, 110, 120)], fill_mode="solid"),
                static=True)
    sources = {"measured": log.frame, **{k: r.frame for k, r in runs.items()}}
    w = distance_weights(t, np.hypot(f["v_x_1"], f["v_y_1"]))
    path_1 = f[["x_1", "y_1"]].to_numpy()
    for src, frame in sources.items():
        n = len(frame)
        tt = _timelines(t[:n], s[:n])
        colour = model_colour(src)
        _log_combination(rec, src, frame, geo, t[:n], s[:n], every)
        for sig, group, unit in (("r", "yaw_rate", "tractor"), ("r", "yaw_rate", "trailer"),
                                 ("v_y", "lateral_velocity", "tractor"),
                                 ("v_y", "lateral_velocity", "trailer")):
            i = 1 if unit == "tractor" else 2
            _series(rec, f"/signals/{group}/{unit}/{src}", tt,
                    frame[f"{sig}_{i}"].to_numpy(), f"{src} {unit}", colour)
        _series(rec, f"/signals/articulation/{src}", tt, frame["gamma"].to_numpy(), src, colour)
        if src == "measured":
            _series(rec, "/signals/steering_wheel/delta_h", tt, frame["delta_h"].to_numpy(),
                    "steering wheel (measured)", colour)
            continue
        delta = frame["delta"].to_numpy()
        fb = frame["delta_fb"].to_numpy()
        _series(rec, f"/signals/steering/delta_center/{src}", tt, delta - fb,
                f"{src} centre angle", colour)
        _series(rec, f"/signals/steering/delta_fb/{src}", tt, fb, f"{src} feedback", colour)
        e_y = distance_to_polyline(frame[["x_1", "y_1"]].to_numpy(), path_1)
        e_r = frame["r_1"].to_numpy() - f["r_1"].to_numpy()[:n]
        _series(rec, f"/signals/error/lateral_position/{src}", tt, _running_rms(e_y, w[:n]),
                f"{src} eps_y1", colour)
        _series(rec, f"/signals/error/yaw_rate/{src}", tt, _running_rms(e_r, w[:n]),
                f"{src} eps_r1", colour)
    rec.log("/description", rr.TextDocument(_description(log, runs, vehicle, metrics, extra),
                                            media_type=rr.MediaType.MARKDOWN), static=True)


def record_summary(path: Path, metrics: pd.DataFrame, text: str) -> Path:
    """Write the campaign summary: the report as text, and the criteria per manoeuvre.

    Each model's criteria are scalars on the ``manoeuvre`` timeline (the
    manoeuvres in campaign order), one plot per criterion.
    """
    crit = ("eps_p", "eps_a", "eps_v", "eps_n", "J_steer")
    bp = rrb.Blueprint(rrb.Horizontal(
        rrb.TextDocumentView(origin="/report", name="Report"),
        rrb.Vertical(*[rrb.TimeSeriesView(origin=f"/criteria/{c}", name=c) for c in crit])),
        collapse_panels=True)
    with _recording(path, "artic-campaign", bp) as rec:
        logs = list(dict.fromkeys(metrics["log"]))
        index = {name: i for i, name in enumerate(logs)}
        for model, group in metrics.groupby("model", sort=False):
            idx = [rr.TimeColumn("manoeuvre", sequence=group["log"].map(index).to_numpy())]
            for c in crit:
                _series(rec, f"/criteria/{c}/{model}", idx, group[c].to_numpy(dtype=float),
                        model, model_colour(model))
        names = "\n".join(f"{i}. {name}" for i, name in enumerate(logs))
        rec.log("/report", rr.TextDocument(text + "\n\n## Manoeuvre index\n\n" + names,
                                           media_type=rr.MediaType.MARKDOWN), static=True)
    return Path(path)


def read_rows(path: Path) -> dict[str, int]:
    """Rows per entity on its timelines, read back from a file.

    Entities logged only statically appear with 0 rows. For checks that a
    recording holds what was logged.
    """
    out: dict[str, int] = {}
    for chunk in RrdReader(Path(path)).stream():
        out[chunk.entity_path] = out.get(chunk.entity_path, 0) + (
            0 if chunk.is_static else chunk.num_rows)
    return out


def read_text(path: Path, entity: str) -> str:
    """The text of a ``TextDocument`` entity in a recording."""
    for chunk in RrdReader(Path(path)).stream():
        if chunk.entity_path == entity:
            batch = chunk.to_record_batch()
            for name in batch.schema.names:
                if name.endswith(":text"):
                    return str(batch.column(name)[0][0])
    raise KeyError(f"{path}: no text document at {entity}")
