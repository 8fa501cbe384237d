"""Rerun recordings: one ``.rrd`` per manoeuvre, and one for the campaign.

This is artic's only module that imports rerun.

A manoeuvre recording is named after its manoeuvre and holds, on two
timelines, ``time`` (a duration [s]) and ``distance_cm`` (the measured tractor
sensor's travelled distance [cm], the variable of the error criteria):

- ``/yard``: the measured combination, KIN and STM as boxes for the bodies
  and the wheels, moving with their own poses; the plant drawn from its own
  MuJoCo bodies and geoms (:mod:`artic.validation.review.plantshape`): chassis,
  semitrailer, axles on their suspension, wheels that steer and spin, and
  the fifth wheel, posed from the plant's state at every logged step; the
  plant's tyre forces in the ground plane as arrows at the contact points;
  every combination's sensor paths and swept envelope (the tracks of the
  tractor's front and the semitrailer's rear corners); the ground and, for
  docking and parking, the dock;
- ``/signals``: the steering inputs (the measured steering-wheel angle; each
  model's centre road-wheel angle and the feedback the harness added), the
  tractor speed, yaw rates and lateral velocities of both units,
  articulation, the running errors of eq. (8), and for the plant the wheel
  loads, the tyre slip angles and the steering servo's torque. Angles are in
  degrees, and every plot's title carries its unit;
- ``/description``: the vehicle file, the parameters of each model, the
  criteria, and the artic version;
- a default blueprint: the yard, seen from beside and above the combination
  and following it, beside the plots on three tabs, each showing the whole
  run with its legend in a corner.

The 3-D yard is logged at :data:`YARD_RATE` and the plots at
:data:`PLOT_RATE`, which keeps a minute of manoeuvre near 1 MB. Files are
written to a temporary name and renamed when complete.
"""

from __future__ import annotations

import contextlib
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd
import rerun as rr
import rerun.blueprint as rrb
from rerun.chunk import RrdReader

from artic.mjcf.outline import DOCK_DEPTH, DOCK_FACE, outline
from artic.mjcf.tir import read_tir
from artic.mjcf.vehicle import Vehicle
from artic.validation.criteria.distance import distance_weights, travelled
from artic.validation.criteria.pathdist import distance_to_polyline
from artic.validation.logs.runfile import Run
from artic.validation.models import colour as model_colour
from artic.validation.review.plantshape import (
    Geom,
    Part,
    has_pose,
    plant_shape,
    rad2deg,
    wheel_names,
    wheel_quat,
    xyzw,
)
from artic.validation.review.tables import pipe_table

YARD_RATE = 5.0
"""Samples per second of the 3-D yard [Hz]: at the yard's 1-10 km/h the
combination moves at most 0.6 m between frames, and turns by well under a
degree (yaw rates below 0.3 rad/s)."""

PLOT_RATE = 5.0
"""Samples per second of the plots [Hz]: the yard's yaw rates and speeds
change over seconds (the CAN steering's 10 Hz steps show every other one).
With the yard's rate, half the recordings' size at 10 Hz less the fixed part:
a manoeuvre's recording is about 1 MB."""

FORCE_SCALE = 1.0 / 5000.0
"""Length of the tyre-force arrows per newton [m/N]: 1 m per 5 kN."""

APPLICATION = "artic"

WHEEL_COLOURS = ((230, 25, 75), (60, 180, 75), (255, 225, 25), (0, 130, 200), (245, 130, 48),
                 (145, 30, 180), (70, 240, 240), (240, 50, 230), (210, 245, 60),
                 (250, 190, 212), (0, 128, 128), (170, 110, 40), (128, 0, 0), (0, 0, 128))
"""Colours of the wheels' lines in the tyre plots."""


def artic_version() -> str:
    """The installed artic version: ``artic.__version__``, the one place it is read."""
    import artic  # the front door: light, and it reads the version once per process

    return artic.__version__


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
    bodies are :func:`artic.mjcf.outline.outline`'s, as the plant and the docking
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
        # Drawn wheels: the tyre file's radius; a truck wheel's half metre at the vehicle's
        # scale for a scale model without tyre data (a drawing only, no model uses it).
        self.R0 = (read_tir(v.tyre_file).number("UNLOADED_RADIUS") if v.tyre_file
                   else 0.5 * v.length_ratio)

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


def _tracks(frame: pd.DataFrame, geo: _Geometry, i: int, unit: str, s) -> tuple:
    """Unit origin and its swept-envelope corner tracks [m]."""
    x, y, psi = (frame[f"{c}_{i}"].to_numpy() for c in ("x", "y", "psi"))
    ox, oy = _origin(x, y, psi, s)
    c, sn = np.cos(psi), np.sin(psi)
    tracks = [np.column_stack([ox + c * px - sn * py, oy + sn * px + c * py,
                               np.full_like(ox, 0.02)]) for px, py in geo.corners(unit)]
    return ox, oy, psi, tracks


def _log_paths(rec: rr.RecordingStream, base: str, frame: pd.DataFrame, geo: _Geometry,
               every: int, colour) -> None:
    """The sensor paths and the swept envelope, static, at the yard's rate."""
    sel = slice(None, None, every)
    paths = []
    for i, unit, s in ((1, "tractor", geo.s1), (2, "trailer", geo.s2)):
        _, _, _, tracks = _tracks(frame, geo, i, unit, s)
        rec.log(f"{base}/envelope/{unit}",
                rr.LineStrips3D([tr[sel] for tr in tracks], colors=[colour], radii=0.015),
                static=True)
        paths.append(np.column_stack([frame[f"x_{i}"], frame[f"y_{i}"],
                                      np.full(len(frame), 0.05)])[sel])
    rec.log(f"{base}/path", rr.LineStrips3D(paths, colors=[colour], radii=0.05), static=True)


def _log_boxes(rec: rr.RecordingStream, base: str, frame: pd.DataFrame, geo: _Geometry,
               times, every: int, colour) -> None:
    """A combination as boxes for the bodies and the wheels (measured, KIN, STM)."""
    sel = slice(None, None, every)
    for i, unit, s, body, wheels in ((1, "tractor", geo.s1, geo.tractor_body,
                                      geo.tractor_wheels),
                                     (2, "trailer", geo.s2, geo.trailer_body,
                                      geo.trailer_wheels)):
        ox, oy, psi, _ = _tracks(frame, geo, i, unit, s)
        rec.send_columns(f"{base}/{unit}", indexes=times,
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
                           colors=[colour], fill_mode="majorwireframe"), static=True)


def _rgb(rgba: np.ndarray) -> list[int]:
    return [int(round(255 * c)) for c in rgba]


def _log_geoms(rec: rr.RecordingStream, path: str, part: Part, tint) -> None:
    """A part's MuJoCo geoms, static in its frame; chassis geoms take the model's colour."""
    chassis = part.name in ("tractor", "trailer")
    groups: dict[str, list] = {"box": [], "cylinder": [], "capsule": []}
    for g in part.geoms:
        rgba = g.rgba.copy()
        colour = [*tint, int(round(255 * rgba[3]))] if chassis else _rgb(rgba)
        groups[g.kind].append((g, xyzw(g.quat), colour))
    if part.spin is not None:  # a spoke in the model's colour, so that the spin shows
        r = part.geoms[0].size[0]
        spoke = Geom("cylinder", np.array([0.06, 0.5 * r, 0.0]), np.array([0.0, 0.0, 0.5 * r]),
                     np.array([1.0, 0.0, 0.0, 0.0]), np.ones(4))
        groups["cylinder"].append((spoke, xyzw(spoke.quat), list(tint)))
    if groups["box"]:
        gs = groups["box"]
        rec.log(f"{path}/boxes", rr.Boxes3D(
            centers=[g.pos for g, _, _ in gs], half_sizes=[g.size for g, _, _ in gs],
            quaternions=[q for _, q, _ in gs], colors=[c for _, _, c in gs],
            fill_mode="solid"), static=True)
    if groups["cylinder"]:
        gs = groups["cylinder"]
        rec.log(f"{path}/cylinders", rr.Cylinders3D(
            lengths=[2 * g.size[1] for g, _, _ in gs], radii=[g.size[0] for g, _, _ in gs],
            centers=[g.pos for g, _, _ in gs], quaternions=[q for _, q, _ in gs],
            colors=[c for _, _, c in gs], fill_mode="solid"), static=True)
    if groups["capsule"]:  # Rerun's capsule runs from its translation along +z
        gs = groups["capsule"]
        starts = []
        for g, _, _ in gs:
            w, x, y, z = g.quat
            axis = np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])
            starts.append(g.pos - g.size[1] * axis)
        rec.log(f"{path}/capsules", rr.Capsules3D(
            lengths=[2 * g.size[1] for g, _, _ in gs], radii=[g.size[0] for g, _, _ in gs],
            translations=starts, quaternions=[q for _, q, _ in gs],
            colors=[c for _, _, c in gs]), static=True)


def _log_plant(rec: rr.RecordingStream, base: str, frame: pd.DataFrame, vehicle: Vehicle,
               times, sel: np.ndarray, colour) -> None:
    """The plant from its own bodies and geoms, posed from its run's columns at rows ``sel``."""
    for part in plant_shape(vehicle):
        path = f"{base}/{part.name}" if part.parent is None else f"{base}/{part.parent}/{part.name}"
        _log_geoms(rec, path, part, colour)
        if part.parent is None:
            cols = [f"pose.{part.name}.{c}" for c in ("x", "y", "z", "qw", "qx", "qy", "qz")]
            pose = frame[cols].to_numpy(dtype=float)[sel]
            rec.send_columns(path, indexes=times, columns=rr.Transform3D.columns(
                translation=pose[:, :3], quaternion=xyzw(pose[:, 3:])))
        elif part.spin is not None:
            spin = frame[part.spin].to_numpy(dtype=float)[sel]
            steer = (frame[part.steer].to_numpy(dtype=float)[sel] if part.steer
                     else np.zeros_like(spin))
            rec.send_columns(path, indexes=times, columns=rr.Transform3D.columns(
                translation=np.tile(part.offset, (spin.size, 1)),
                quaternion=xyzw(wheel_quat(steer, spin))))
        else:
            rec.log(path, rr.Transform3D(translation=part.offset), static=True)
    wheels = wheel_names(frame.columns)
    origins = np.stack([frame[[f"contact.{w}.{c}" for c in "xyz"]].to_numpy(dtype=float)[sel]
                        for w in wheels], axis=1)
    forces = np.stack([frame[[f"force.{w}.{c}" for c in "xy"]].to_numpy(dtype=float)[sel]
                       for w in wheels], axis=1)
    vectors = np.concatenate([forces * FORCE_SCALE, np.zeros(forces.shape[:2] + (1,))], axis=2)
    origins[:, :, 2] = 0.05
    n = len(wheels)
    rec.send_columns(f"{base}/tyre_forces", indexes=times, columns=rr.Arrows3D.columns(
        origins=origins.reshape(-1, 3), vectors=vectors.reshape(-1, 3)).partition(
        [n] * origins.shape[0]))
    rec.log(f"{base}/tyre_forces", rr.Arrows3D.from_fields(colors=[(255, 60, 60)], radii=[0.04]),
            static=True)


def _series(rec, path: str, times, values, names, colours) -> None:
    """Lines on one entity: ``values`` one column per line (several lines share the row cost)."""
    names = [names] if isinstance(names, str) else list(names)
    colours = [colours] if np.ndim(colours) == 1 else list(colours)
    v = np.asarray(values, dtype=float).reshape(len(times[0].as_arrow_array()), -1)
    cols = rr.Scalars.columns(scalars=v.ravel())
    if v.shape[1] > 1:
        cols = cols.partition([v.shape[1]] * v.shape[0])
    rec.send_columns(path, indexes=times, columns=cols)
    rec.log(path, rr.SeriesLines(colors=colours, names=names, widths=[1.5] * len(names)),
            static=True)


def _running_rms(eps: np.ndarray, w: np.ndarray) -> np.ndarray:
    cw = np.cumsum(w)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.sqrt(np.cumsum(w * eps ** 2) / np.where(cw > 0, cw, np.nan))


PLOTS = (
    ("Signals", (
        ("steering_wheel", "Steering wheel delta_h [deg]"),
        ("road_wheel", "Road-wheel angle delta [deg]"),
        ("feedback", "Harness feedback delta_fb [deg]"),
        ("speed", "Speed v_x_1 [km/h]"),
        ("articulation", "Articulation gamma [deg]"),
        ("yaw_rate/tractor", "Tractor yaw rate r_1 [deg/s]"))),
    ("More signals", (
        ("yaw_rate/trailer", "Semitrailer yaw rate r_2 [deg/s]"),
        ("lateral_velocity/tractor", "Tractor lateral velocity v_y_1 [m/s]"),
        ("lateral_velocity/trailer", "Semitrailer lateral velocity v_y_2 [m/s]"),
        ("error/lateral_position", "Running error eps_y1, eq. (8) [m]"),
        ("error/yaw_rate", "Running error eps_r1, eq. (8) [deg/s]"))),
    ("Plant tyres", (
        ("wheel_load", "Plant wheel loads Fz [kN]"),
        ("slip_angle", "Plant tyre slip angles alpha [deg]"),
        ("steer_torque", "Plant steering servo torque [kN m]"))),
)
"""The plots by tab: their entity under ``/signals`` and their title, unit included.
Six to a tab at most, so that every legend has room."""


def _frame_box(log: Run, vehicle: Vehicle) -> tuple[np.ndarray, np.ndarray]:
    """Bounds in the plane of everything the combination covers on its path [m]."""
    f = log.frame
    o = outline(vehicle)
    pts = []
    for i, xs in ((1, (o.tractor_front, o.tractor_rear)), (2, (o.trailer_front, o.trailer_rear))):
        s = np.array(vehicle.sensor1[:2] if i == 1 else vehicle.sensor2[:2])
        x, y, psi = (f[f"{c}_{i}"].to_numpy() for c in ("x", "y", "psi"))
        ox, oy = _origin(x, y, psi, s)
        for px in xs:
            for py in (o.width / 2, -o.width / 2):
                pts.append(np.column_stack([ox + np.cos(psi) * px - np.sin(psi) * py,
                                            oy + np.sin(psi) * px + np.cos(psi) * py]))
    xy = np.concatenate(pts)
    return xy.min(axis=0), xy.max(axis=0)


def _blueprint(name: str, start: np.ndarray, plant: bool) -> rrb.Blueprint:
    """The layout: the yard following the combination, beside the plots of the whole run.

    ``start`` is the kingpin's position and the semitrailer's yaw at the
    first sample [m, m, rad]: the eye starts beside and above it and then
    tracks the measured semitrailer, so the combination stays in the middle
    of the view with its path around it.
    """
    whole = [rrb.VisibleTimeRange(tl, start=rrb.TimeRangeBoundary.infinite(),
                                  end=rrb.TimeRangeBoundary.infinite())
             for tl in ("time", "distance_cm")]
    def view(g, title):
        return rrb.TimeSeriesView(
            origin=f"/signals/{g}", name=title, time_ranges=whole,
            axis_x=rrb.TimeAxis(view_range=rrb.TimeRange(start=rrb.TimeRangeBoundary.infinite(),
                                                         end=rrb.TimeRangeBoundary.infinite())),
            plot_legend=rrb.PlotLegend(corner=rrb.Corner2D.LeftTop, visible=True))

    panels = [rrb.Grid(*[view(g, title) for g, title in plots], grid_columns=2, name=tab)
              for tab, plots in PLOTS if plant or tab != "Plant tyres"]
    x, y, psi = start
    # 26 m to the right of the kingpin, 8 m behind it and 20 m up: the ~17 m
    # combination fills about half the view's width.
    c, sn = np.cos(psi), np.sin(psi)
    off = np.array([-8.0 * c + 26.0 * sn, -8.0 * sn - 26.0 * c])
    target = np.array([x, y])
    eye = rrb.EyeControls3D(position=[target[0] + off[0], target[1] + off[1], 20.0],
                            look_target=[target[0], target[1], 1.0], eye_up=[0.0, 0.0, 1.0],
                            tracking_entity="/yard/measured/trailer")
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(rrb.Spatial3DView(origin="/yard", name=f"{name}: yard",
                                           eye_controls=eye),
                         rrb.TextDocumentView(origin="/description", name=f"{name}: description"),
                         row_shares=[4, 1]),
            rrb.Tabs(*panels),
            column_shares=[1, 1]),
        rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline="time"))


def _description(log: Run, runs: Mapping[str, Run], vehicle: Vehicle,
                 metrics: pd.DataFrame | None, extra: str) -> str:
    lines = [f"# {log.name}", "",
             f"artic {artic_version()}; vehicle `{vehicle.name}` from `{vehicle.path}`.", "",
             "The measured combination is white, KIN blue, STM green and the plant (MBD) "
             "orange, drawn from its own MuJoCo bodies; the red arrows are the plant's tyre "
             f"forces in the ground plane, {1 / FORCE_SCALE / 1000:g} kN per metre. Angles "
             "are in degrees.", ""]
    rows = []
    for name, run in runs.items():
        st = run.meta.get("steering", {})
        f = f"{vehicle.f:.3g}" if name == "stm" else "-"
        rows.append([name, f"{st.get('i_s', float('nan')):.4g}", f"{st.get('q', float('nan')):.4g}",
                     f"{np.degrees(st.get('delta_h_offset', float('nan'))):.3g}", f,
                     str(run.meta.get("status", ""))])
    lines.append(pipe_table(["model", "i_s", "q [1/rad]", "offset [deg]", "f [1/rad]", "status"],
                            rows))
    if metrics is not None and len(metrics):
        cols = ["eps_p", "eps_a", "eps_v", "eps_n", "J_steer"]
        lines += ["", pipe_table(["model", *cols], ([str(row["model"]), *(f"{row[c]:.4g}"
                                                                           for c in cols)]
                                                     for _, row in metrics.iterrows()))]
    if extra:
        lines += ["", extra]
    return "\n".join(lines)


@contextlib.contextmanager
def _recording(path: Path, recording_id: str, blueprint: rrb.Blueprint, name: str):
    """A recording stream named ``name``, saved to ``path``: complete, or not at all.

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
        rec.send_recording_name(name)
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
        The parameters the models ran with (geometry of the boxes and of the plant).
    metrics : DataFrame, optional
        The manoeuvre's metrics rows, for the description.
    extra : str
        Further Markdown for the description.
    """
    lo, hi = _frame_box(log, vehicle)
    plant = any(has_pose(r.frame.columns) for r in runs.values())
    f0 = log.frame.iloc[0]
    ox, oy = _origin(f0["x_2"], f0["y_2"], f0["psi_2"], np.array(vehicle.sensor2[:2]))
    with _recording(path, f"artic-{log.name}",
                    _blueprint(log.name, np.array([ox, oy, f0["psi_2"]]), plant),
                    log.name) as rec:
        _log_manoeuvre(rec, log, runs, vehicle, metrics, extra, lo, hi)
    return Path(path)


def _every(t: np.ndarray, rate: float) -> int:
    """Every how many samples of ``t`` [s] to draw at ``rate`` [Hz]; 1 for fewer than two.

    A run that ended at its first sample (a controller that failed in ``reset``)
    has no step to take the median of; its one sample is drawn.
    """
    steps = np.diff(np.asarray(t, dtype=float))
    steps = steps[np.isfinite(steps) & (steps > 0.0)]
    if not steps.size:
        return 1
    return max(1, round(1.0 / (rate * float(np.median(steps)))))


def _log_manoeuvre(rec: rr.RecordingStream, log: Run, runs: Mapping[str, Run], vehicle: Vehicle,
                   metrics: pd.DataFrame | None, extra: str, lo: np.ndarray,
                   hi: np.ndarray) -> None:
    f = log.frame
    t = f["t"].to_numpy()
    s = travelled(f)
    every, pe = _every(t, YARD_RATE), _every(t, PLOT_RATE)
    geo = _Geometry(vehicle)
    lo, hi = lo - 15.0, hi + 15.0
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
    # Every plot is one entity whose lines are the sources' columns: one row per
    # sample for all of them, so the recording stays small.
    lines: dict[str, list] = {g: [] for _, plots in PLOTS for g, _ in plots}

    def add(group, values, names, colours):
        v = np.full((len(t), np.size(names)), np.nan)
        v[:len(values)] = np.asarray(values, dtype=float).reshape(len(values), -1)
        lines[group].append((v, names, colours))

    for src, frame in sources.items():
        n = len(frame)
        colour = model_colour(src)
        base = f"/yard/{src}"
        _log_paths(rec, base, frame, geo, every, colour)
        if has_pose(frame.columns):
            # The plant's extra columns may be stored at a lower rate (NaN between).
            rows = np.flatnonzero(np.isfinite(frame["pose.tractor.x"].to_numpy(dtype=float)))
            if rows.size > 1:
                yr = rows[::_every(t[rows], YARD_RATE)]
                pr = rows[::_every(t[rows], PLOT_RATE)]
                _log_plant(rec, base, frame, vehicle, _timelines(t[yr], s[yr]), yr, colour)
                _log_tyre_plots(rec, frame, _timelines(t[pr], s[pr]), pr)
        else:
            _log_boxes(rec, base, frame, geo, _timelines(t[:n:every], s[:n:every]), every,
                       colour)
        for i, unit in ((1, "tractor"), (2, "trailer")):
            add(f"yaw_rate/{unit}", rad2deg(frame[f"r_{i}"].to_numpy()), [src], [colour])
            add(f"lateral_velocity/{unit}", frame[f"v_y_{i}"].to_numpy(), [src], [colour])
        add("articulation", rad2deg(frame["gamma"].to_numpy()), [src], [colour])
        add("speed", 3.6 * frame["v_x_1"].to_numpy(), [src], [colour])
        if src == "measured":
            add("steering_wheel", rad2deg(frame["delta_h"].to_numpy()), [src], [colour])
            continue
        add("road_wheel", rad2deg(frame["delta"].to_numpy()), [src], [colour])
        add("feedback", rad2deg(frame["delta_fb"].to_numpy()), [src], [colour])
        e_y = distance_to_polyline(frame[["x_1", "y_1"]].to_numpy(), path_1)
        e_r = frame["r_1"].to_numpy() - f["r_1"].to_numpy()[:n]
        add("error/lateral_position", _running_rms(e_y, w[:n]), [src], [colour])
        add("error/yaw_rate", rad2deg(_running_rms(e_r, w[:n])), [src], [colour])
    tt = _timelines(t[::pe], s[::pe])
    for group, parts in lines.items():
        if parts:
            _series(rec, f"/signals/{group}", tt,
                    np.concatenate([v for v, _, _ in parts], axis=1)[::pe],
                    [x for _, names, _ in parts for x in names],
                    [c for _, _, cs in parts for c in cs])
    rec.log("/description", rr.TextDocument(_description(log, runs, vehicle, metrics, extra),
                                            media_type=rr.MediaType.MARKDOWN), static=True)


def _log_tyre_plots(rec: rr.RecordingStream, frame: pd.DataFrame, times,
                    sel: np.ndarray) -> None:
    """The plant's wheel loads, slip angles and steering torque at rows ``sel``."""
    wheels = wheel_names(frame.columns)
    colours = [WHEEL_COLOURS[k % len(WHEEL_COLOURS)] for k in range(len(wheels))]
    labels = [w.replace(".", " ") for w in wheels]
    loads = frame[[f"force.{w}.z" for w in wheels]].to_numpy(dtype=float)[sel] / 1000.0
    slips = frame[[f"slip.{w}" for w in wheels]].to_numpy(dtype=float)[sel]
    _series(rec, "/signals/wheel_load", times, loads, labels, colours)
    _series(rec, "/signals/slip_angle", times, rad2deg(slips), labels, colours)
    if "steer_torque" in frame.columns:
        _series(rec, "/signals/steer_torque", times,
                frame["steer_torque"].to_numpy(dtype=float)[sel] / 1000.0, "servo",
                model_colour("mbd"))


def _index_of(name: str, fallback: int) -> int:
    """The manoeuvre number that starts a campaign name (``45-docking-...``), or ``fallback``."""
    m = re.match(r"(\d+)-", name)
    return int(m.group(1)) if m else fallback


def record_summary(path: Path, metrics: pd.DataFrame, text: str) -> Path:
    """Write the campaign summary: the report as text, and the criteria per manoeuvre.

    Each model's criteria are scalars on the ``manoeuvre`` timeline, at the
    number that starts each manoeuvre's name (``45`` for
    ``45-docking-unloaded-left``, its recording's file name), and
    ``/manoeuvre`` logs the name itself there, so the timeline reads by name.
    """
    crit = ("eps_p", "eps_a", "eps_v", "eps_n", "J_steer")
    units = {"eps_p": "m", "eps_a": "rad/s", "eps_v": "m/s", "eps_n": "%", "J_steer": "%"}
    bp = rrb.Blueprint(rrb.Horizontal(
        rrb.Vertical(rrb.TextDocumentView(origin="/report", name="Report"),
                     rrb.TextLogView(origin="/manoeuvre", name="Manoeuvres"), row_shares=[3, 1]),
        rrb.Vertical(*[rrb.TimeSeriesView(
            origin=f"/criteria/{c}", name=f"{c} [{units[c]}] per manoeuvre",
            plot_legend=rrb.PlotLegend(corner=rrb.Corner2D.LeftTop, visible=True))
            for c in crit])),
        rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(timeline="manoeuvre"))
    with _recording(path, "artic-campaign", bp, "artic campaign") as rec:
        logs = list(dict.fromkeys(metrics["log"]))
        index = {name: _index_of(name, i) for i, name in enumerate(logs)}
        if len(set(index.values())) < len(index):  # not campaign names: number them in order
            index = {name: i for i, name in enumerate(logs)}
        rec.send_columns("/manoeuvre",
                         indexes=[rr.TimeColumn("manoeuvre", sequence=list(index.values()))],
                         columns=rr.TextLog.columns(text=list(index)))
        for model, group in metrics.groupby("model", sort=False):
            idx = [rr.TimeColumn("manoeuvre", sequence=group["log"].map(index).to_numpy())]
            for c in crit:
                _series(rec, f"/criteria/{c}/{model}", idx, group[c].to_numpy(dtype=float),
                        model, model_colour(model))
        names = "\n".join(f"- {index[name]}: `{name}`" for name in logs)
        rec.log("/report", rr.TextDocument(text + "\n\n## Manoeuvre index\n\n" + names,
                                           media_type=rr.MediaType.MARKDOWN), static=True)
    return Path(path)


DOCK_PLOTS = (("steering_wheel", "Steering wheel delta_h [deg]"),
              ("speed", "Speed v_x_1 [km/h]"),
              ("articulation", "Articulation gamma [deg]"))
"""The docking recording's plots: entity under ``/signals`` and title."""


class DockScene(NamedTuple):
    """The yard a docking recording draws, and the planner's path through it.

    Attributes
    ----------
    obstacles : sequence of (name, x_min, x_max, y_min, y_max)
        The yard's obstacles [m]: the dock, its far edge, parked semitrailers.
    doors : sequence of float
        The doors' centre lines [m].
    dock_face : tuple of float
        The dock face's x and the target door's y [m].
    plan : sequence of ndarray
        The planner's path as polylines ``(n, 2)`` [m].
    """

    obstacles: Sequence[tuple[str, float, float, float, float]]
    doors: Sequence[float]
    dock_face: tuple[float, float]
    plan: Sequence[np.ndarray]


class DockIntent(NamedTuple):
    """What a docking controller intended and saw at its samples, for the recording.

    Attributes
    ----------
    horizons : sequence of (float, ndarray or None)
        The controller's predicted path ``(n, 2)`` [m] at each of its samples [s].
    references : sequence of (float, ndarray or None)
        The plan's points ``(n, 2)`` [m] it tracked at each sample.
    seen : tuple of ndarray, optional
        Its samples' times [s], the articulation [rad] and the semitrailer's rear
        ``(n, 2)`` [m] it saw.
    """

    horizons: Sequence[tuple[float, np.ndarray | None]]
    references: Sequence[tuple[float, np.ndarray | None]] = ()
    seen: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None


def record_docking(path: Path, name: str, frame: pd.DataFrame, vehicle: Vehicle,
                   scene: DockScene, intent: DockIntent, text: str) -> Path:
    """Write one docking run's recording.

    Parameters
    ----------
    path : Path
        The ``.rrd`` to write.
    name : str
        The run's name (``SCENARIO-VEHICLE-CONTROLLER-SEED``).
    frame : DataFrame
        The plant's run in the signal schema, with the pose columns of
        :meth:`artic.plant.Plant.extras` (rows without them are skipped).
    vehicle : Vehicle
        The plant's parameters.
    scene : DockScene
        The yard and the plan (:class:`DockScene`).
    intent : DockIntent
        The controller's horizons, references and what it saw, as below.
    text : str
        Markdown for the description: the scores.

    How the fields of ``intent`` are drawn (those of ``scene`` as
    :class:`DockScene` says):

    horizons : sequence of (float, ndarray or None)
        The controller's predicted path ``(n, 2)`` [m] at each of its samples
        [s], ``None`` where it gave none: one row of ``/yard/horizon`` per
        sample, empty where ``None`` (so that no stale horizon stays drawn).
    references : sequence of (float, ndarray or None)
        The plan's points ``(n, 2)`` [m] the controller tracked at each
        sample, the one it tracked then first: one row per sample of
        ``/yard/plan/tracked`` (the points) and ``/yard/plan/point`` (the
        first), empty where ``None``.
    seen : tuple of ndarray, optional
        What the controller saw at its samples: their times [s], the articulation
        [rad] and the semitrailer's rear ``(n, 2)`` [m]. Drawn as
        ``/signals/articulation/seen`` beside the plant's, and as the point
        ``/yard/seen/rear`` at every sample with its whole path
        ``/yard/seen/rear_path`` (orange).
    """
    obstacles, doors, dock_face, plan = scene
    horizons, references, seen = intent
    f = frame
    t = f["t"].to_numpy()
    s = travelled(f)
    geo = _Geometry(vehicle)
    x_d, y_d = dock_face
    with _recording(path, f"artic-dock-{name}", _dock_blueprint(name, dock_face), name) as rec:
        xs = [b[1] for b in obstacles] + [b[2] for b in obstacles]
        ys = [b[3] for b in obstacles] + [b[4] for b in obstacles]
        rec.log("/yard/ground", rr.Boxes3D(centers=[[(min(xs) + max(xs)) / 2,
                                                     (min(ys) + max(ys)) / 2, -0.05]],
                                           half_sizes=[[(max(xs) - min(xs)) / 2,
                                                        (max(ys) - min(ys)) / 2, 0.05]],
                                           colors=[(90, 90, 85)], fill_mode="solid"),
                static=True)
        for ob, x0, x1, y0, y1 in obstacles:
            parked = ob.startswith("neighbour")
            h = 2.0 if parked else 2.5
            rec.log(f"/yard/{ob}", rr.Boxes3D(
                centers=[[(x0 + x1) / 2, (y0 + y1) / 2, h + (0.5 if parked else 0.0)]],
                half_sizes=[[(x1 - x0) / 2, (y1 - y0) / 2, h]],
                colors=[(70, 110, 170) if parked else (110, 110, 120)],
                fill_mode="majorwireframe" if parked else "solid"), static=True)
        rec.log("/yard/doors", rr.LineStrips3D(
            [[[x_d + 0.02, y - 1.3, 0.05], [x_d + 0.02, y + 1.3, 0.05]] for y in doors],
            colors=[(255, 210, 0)], radii=0.08), static=True)
        rec.log("/yard/door_line", rr.LineStrips3D([[[x_d, y_d, 0.03], [x_d + 30.0, y_d, 0.03]]],
                                                   colors=[(255, 210, 0)], radii=0.02),
                static=True)
        rec.log("/yard/plan", rr.LineStrips3D([np.column_stack([p, np.full(len(p), 0.08)])
                                               for p in plan], colors=[(0, 200, 255)],
                                              radii=0.06), static=True)
        if len(t):  # a run that ended before its first sample (failed in reset) has none
            _log_docking_run(rec, f, t, s, vehicle, geo, horizons, references, seen)
        rec.log("/description", rr.TextDocument(text, media_type=rr.MediaType.MARKDOWN),
                static=True)
    return Path(path)


def _log_docking_run(rec: rr.RecordingStream, f: pd.DataFrame, t: np.ndarray, s: np.ndarray,
                     vehicle: Vehicle, geo: _Geometry, horizons: Sequence, references: Sequence,
                     seen: tuple | None) -> None:
    """A docking run's samples: paths, plant, intent, signals and what was seen."""
    colour = model_colour("mbd")
    every = _every(t, YARD_RATE)
    _log_paths(rec, "/yard/mbd", f, geo, every, colour)
    if has_pose(f.columns):
        rows = np.flatnonzero(np.isfinite(f["pose.tractor.x"].to_numpy(dtype=float)))
        if rows.size > 1:
            _log_plant(rec, "/yard/mbd", f, vehicle, _timelines(t[rows], s[rows]), rows,
                       colour)
    _log_intent(rec, "/yard/horizon", horizons, t, s, 0.12, (255, 0, 200), 0.05)
    _log_intent(rec, "/yard/plan/tracked", references, t, s, 0.10, (0, 255, 140), 0.09)
    if any(r is not None for _, r in references):
        rt = np.array([r[0] for r in references])
        pts = [r[1][:1, :2] for r in references if r[1] is not None]
        rec.send_columns("/yard/plan/point", indexes=_timelines(rt, np.interp(rt, t, s)),
                         columns=rr.Points3D.columns(positions=np.column_stack(
                             [np.concatenate(pts), np.full(len(pts), 0.15)])).partition(
                             [0 if r is None else 1 for _, r in references]))
        rec.log("/yard/plan/point", rr.Points3D.from_fields(colors=[(0, 255, 140)],
                                                            radii=[0.25]), static=True)
    pe = _every(t, PLOT_RATE)
    ts = _timelines(t[::pe], s[::pe])
    _series(rec, "/signals/steering_wheel", ts, np.degrees(f["delta_h"].to_numpy()[::pe]),
            "delta_h", colour)
    _series(rec, "/signals/speed", ts, 3.6 * f["v_x_1"].to_numpy()[::pe], "v_x_1", colour)
    _series(rec, "/signals/articulation", ts, np.degrees(f["gamma"].to_numpy()[::pe]),
            "gamma", colour)
    if seen is not None:
        _log_seen(rec, seen, t, s)


SEEN_COLOUR = (255, 150, 0)
"""What the controller saw (measured or estimated), in a docking recording."""


def _log_seen(rec: rr.RecordingStream, seen: tuple[np.ndarray, np.ndarray, np.ndarray],
              t: np.ndarray, s: np.ndarray) -> None:
    """The controller's view of the articulation and the semitrailer's rear, per sample."""
    tc, gamma, rear = (np.asarray(x, dtype=float) for x in seen)
    times = _timelines(tc, np.interp(tc, t, s))
    _series(rec, "/signals/articulation/seen", times, np.degrees(gamma), "gamma seen",
            SEEN_COLOUR)
    rec.send_columns("/yard/seen/rear", indexes=times, columns=rr.Points3D.columns(
        positions=np.column_stack([rear, np.full(len(rear), 0.2)])))
    rec.log("/yard/seen/rear", rr.Points3D.from_fields(colors=[SEEN_COLOUR], radii=[0.2]),
            static=True)
    rec.log("/yard/seen/rear_path", rr.LineStrips3D(
        [np.column_stack([rear, np.full(len(rear), 0.1)])], colors=[SEEN_COLOUR],
        radii=0.03), static=True)


def _log_intent(rec: rr.RecordingStream, entity: str,
                paths: Sequence[tuple[float, np.ndarray | None]], t: np.ndarray, s: np.ndarray,
                z: float, colour: tuple[int, int, int], radius: float) -> None:
    """One line strip per controller sample at ``entity`` (an empty row for ``None``).

    Nothing is logged when no sample gave one.
    """
    if not any(p is not None for _, p in paths):
        return
    times = np.array([p[0] for p in paths])
    strips = [np.column_stack([p[:, :2], np.full(len(p), z)]) for _, p in paths
              if p is not None]
    rec.send_columns(entity, indexes=_timelines(times, np.interp(times, t, s)),
                     columns=rr.LineStrips3D.columns(strips=strips).partition(
                         [0 if p is None else 1 for _, p in paths]))
    rec.log(entity, rr.LineStrips3D.from_fields(colors=[colour], radii=[radius]), static=True)


def _dock_blueprint(name: str, dock_face: tuple[float, float]) -> rrb.Blueprint:
    """The docking layout: the yard seen from above the apron, the plots, the scores."""
    x_d, y_d = dock_face
    eye = rrb.EyeControls3D(position=[x_d + 55.0, y_d - 25.0, 45.0],
                            look_target=[x_d + 15.0, y_d, 0.0], eye_up=[0.0, 0.0, 1.0])
    whole = [rrb.VisibleTimeRange(tl, start=rrb.TimeRangeBoundary.infinite(),
                                  end=rrb.TimeRangeBoundary.infinite())
             for tl in ("time", "distance_cm")]
    plots = [rrb.TimeSeriesView(origin=f"/signals/{g}", name=title, time_ranges=whole)
             for g, title in DOCK_PLOTS]
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(rrb.Spatial3DView(origin="/yard", name=f"{name}: yard", eye_controls=eye),
                         rrb.TextDocumentView(origin="/description", name=f"{name}: scores"),
                         row_shares=[4, 1]),
            rrb.Vertical(*plots), column_shares=[2, 1]),
        rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline="time"))


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


def read_times(path: Path, entity: str, timeline: str = "time") -> np.ndarray:
    """The times [s] of an entity's rows on a duration timeline, read back, in order."""
    out: list[float] = []
    for chunk in RrdReader(Path(path)).stream():
        if chunk.entity_path == entity and not chunk.is_static:
            column = chunk.to_record_batch().column(timeline)
            out.extend(v.total_seconds() for v in column.to_pylist())
    return np.sort(np.array(out, dtype=float))


def read_text(path: Path, entity: str) -> str:
    """The text of a ``TextDocument`` entity in a recording."""
    for chunk in RrdReader(Path(path)).stream():
        if chunk.entity_path == entity:
            batch = chunk.to_record_batch()
            for name in batch.schema.names:
                if name.endswith(":text"):
                    return str(batch.column(name)[0][0])
    raise KeyError(f"{path}: no text document at {entity}")


def read_column(path: Path, entity: str, component: str) -> list:
    """One component of an entity, read back: per row on its timelines, statics apart.

    ``component`` is Rerun's column name, such as ``Transform3D:quaternion``
    or ``Scalars:scalars``; each row's value is a list (a batch). Static
    values come first when there are no temporal ones.
    """
    rows: list = []
    static: list = []
    for chunk in RrdReader(Path(path)).stream():
        if chunk.entity_path != entity:
            continue
        batch = chunk.to_record_batch()
        if component in batch.schema.names:
            (static if chunk.is_static else rows).extend(batch.column(component).to_pylist())
    if not rows and not static:
        raise KeyError(f"{path}: no {component} at {entity}")
    return rows or static


def read_views(path: Path) -> dict[str, str]:
    """The default blueprint's views, read back: origin to title."""
    reader = RrdReader(Path(path))
    out = {}
    for store in reader.blueprints():
        for chunk in reader.stream(store=store):
            batch = chunk.to_record_batch()
            if "ViewBlueprint:display_name" in batch.schema.names:
                for name, origin in zip(batch.column("ViewBlueprint:display_name").to_pylist(),
                                        batch.column("ViewBlueprint:space_origin").to_pylist(),
                                        strict=True):
                    out[origin[0]] = name[0]
    return out
