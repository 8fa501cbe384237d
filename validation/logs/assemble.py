"""From mapped channels to canonical runs: clean stamps, gap-free segments, derived channels.

The channels of a mapped log (:mod:`artic.validation.logs.channelmap`) come in
streams, each on its own time base: a CSV is one stream, a bag one per topic
and time source. Each stream goes through the checks and repairs of
:mod:`artic.validation.logs.checks` (exact duplicates dropped, short NaN runs
interpolated, time going back refused). Then:

- **Gaps.** An interval longer than ``max_gap`` (the map's, or 2.5 times the
  stream's median interval and at least :data:`GAP_FLOOR`) in any stream is a
  gap. The log is split there into gap-free segments, each a canonical run
  of its own (``NAME.seg1``, ``NAME.seg2``, ... with ``meta["segment"]``),
  which ``artic validate`` validates separately and pools by distance
  (:mod:`artic.validation.criteria.pooled`). A segment shorter than
  :data:`MIN_SEGMENT` is left out, and the report says so.
- **Jitter.** Every channel is interpolated linearly from its own stamps onto
  one 100 Hz base per segment, over the span that every stream covers
  (what lies outside is reported). Bursty stamps (intervals far below the
  median) are used as they are: interpolation takes convex combinations of
  neighbouring samples, so it cannot invent a rate, and no derivative is ever
  taken on the raw stamps.
- **Derived channels.** On the 100 Hz base of each segment, in this order:
  a unit's velocities and yaw rate missing from the map from its pose
  (:mod:`artic.validation.logs.differentiate`); ``gamma`` from the two
  headings when both units are there; the missing unit from the other and
  ``gamma`` (:mod:`artic.validation.logs.derive`), with ``gamma_rate`` or the
  same differentiator on ``gamma``; without ``delta_h``, the steering-wheel
  angle that turns the tractor at its yaw rate through the vehicle's map
  (:mod:`artic.validation.logs.yawsteer`), so that the models are steered from
  the yaw rate. Each derivation is one line of the report and of
  ``meta["derived"]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from artic.mjcf.interface import wrap_angle
from artic.mjcf.vehicle import Vehicle
from artic.validation.logs import consistency, noise
from artic.validation.logs.channelmap import GEODETIC, POSE, RATES, ChannelMap, Entry
from artic.validation.logs.checks import MAX_JUMP, Report, check_jumps, clean_time, fill_nan_runs
from artic.validation.logs.consistency import CANONICAL, Context
from artic.validation.logs.derive import TRACTOR, TRAILER, derive_tractor, derive_trailer
from artic.validation.logs.differentiate import derivative, rates_from_pose, smooth_speed
from artic.validation.logs.oxts import radii
from artic.validation.logs.runfile import LogError, Run, check_frame
from artic.validation.logs.scale import FULL_SIZE, LogScale
from artic.validation.logs.schema import COLUMNS, MIN_SEGMENT
from artic.validation.logs.yawsteer import (
    equivalent_wheelbase,
    road_wheel_from_yaw_rate,
    steering_wheel,
)

RATE = 100.0
"""Sample rate of the canonical log [Hz]."""

GAP_FACTOR = 2.5
"""Default ``max_gap`` in median intervals of a stream."""

GAP_FLOOR = 0.1
"""Least default ``max_gap`` [s]: linear interpolation over a hole of ``g`` seconds errs by at
most ``a g**2 / 8``, 1.3 mm at the yard's 1 m/s**2, and bursty stamps (messages delivered in
clumps) leave holes of several median intervals at 100 Hz."""

MAX_INTERVAL = 1.0
"""Longest mean interval between a stream's samples over a segment [s] (full-size; times
scale with the square root of a scale model's size): linear interpolation over ``T``
seconds errs by up to ``a T**2 / 8``, 0.125 m at the yard's 1 m/s**2 for 1 Hz, the
slowest GNSS fix rate in use; ten times sparser errs by metres."""

BURST = 1e-3
"""An interval shorter than this is counted as a burst in the report [s]."""

ANGLES = ("delta_h", "psi_1", "psi_2", "gamma")
"""Channels unwrapped before interpolation."""


@dataclass
class Stream:
    """Samples of some channels on one time base.

    Parameters
    ----------
    name : str
        The time base, for messages (a CSV's time column; a topic and its stamps).
    t : ndarray
        Stamps in the map's time unit, as recorded.
    raw : dict
        Source label (:attr:`Entry.label`) to the values as recorded.
    entries : list of Entry
        The channels this stream carries.
    """

    name: str
    t: np.ndarray
    raw: dict[str, np.ndarray]
    entries: list[Entry]


@dataclass
class _Clean:
    t: np.ndarray  # [s]
    si: dict[str, np.ndarray]
    gaps: list[tuple[float, float]]
    max_gap: float
    name: str


def _clean(stream: Stream, chmap: ChannelMap, report: Report, factor: float,
           split: bool = True) -> _Clean:
    df = pd.DataFrame({stream.name: stream.t, **stream.raw})
    df = clean_time(df, stream.name, report, max_gap=math.inf)
    df = fill_nan_runs(df, list(stream.raw), stream.name, report)
    t = df[stream.name].to_numpy(dtype=float) * factor
    if t.size < 2:
        raise LogError(f"{report.source}: {stream.name}: {t.size} sample(s); a log needs at "
                       "least two: the file may be truncated")
    si = {}
    for e in stream.entries:
        v = e.factor * (e.scale * df[e.label].to_numpy(dtype=float) + e.offset)
        si[e.channel] = np.unwrap(v) if e.channel in ANGLES else v
    dt = np.diff(t)
    med = float(np.median(dt[dt > 0])) if (dt > 0).any() else 0.0
    max_gap = chmap.max_gap if chmap.max_gap is not None else max(GAP_FACTOR * med, GAP_FLOOR)
    max_gap = max_gap if split else math.inf  # --accept gap: interpolated across
    gaps = [(float(t[i]), float(t[i + 1])) for i in np.flatnonzero(dt > max_gap)]
    bursts = int(np.sum(dt < BURST))
    report.add(f"{stream.name}: {t.size} samples at intervals of {dt.min():.3g} to "
               f"{dt.max():.3g} s (median {med:.3g} s"
               + (f"; {bursts} ({100.0 * bursts / dt.size:.0f} %) under {BURST * 1e3:g} ms, "
                  "bursty stamps" if bursts else "")
               + f") interpolated linearly onto {RATE:g} Hz")
    return _Clean(t, si, gaps, max_gap, stream.name)


def _local_plane(cleaned: list[_Clean], chmap: ChannelMap, report: Report) -> None:
    """Latitude and longitude [rad] to east and north [m] in the plane tangent at the first fix."""
    geo = {e.channel: e.unit for e in chmap.entries.values() if e.unit in GEODETIC}
    if not geo:
        return
    lats = [c.si[ch] for c in cleaned for ch in c.si if geo.get(ch) == "latitude"]
    lons = [c.si[ch] for c in cleaned for ch in c.si if geo.get(ch) == "longitude"]
    if not lats or not lons:
        raise LogError(f"{chmap.path}: a position in latitude needs its longitude (and the "
                       "other way round): give both x and y of the unit in degrees")
    lat0, lon0 = float(lats[0][0]), float(lons[0][0])
    M, N = radii(lat0)
    for c in cleaned:
        for ch in c.si:
            if geo.get(ch) == "latitude":
                c.si[ch] = M * (c.si[ch] - lat0)
            elif geo.get(ch) == "longitude":
                c.si[ch] = N * math.cos(lat0) * (c.si[ch] - lon0)
    report.add(f"latitude and longitude to a local east/north plane tangent at "
               f"{math.degrees(lat0):.7f}, {math.degrees(lon0):.7f} deg (WGS84)")


def segments(cleaned: list[_Clean], report: Report) -> list[tuple[float, float]]:
    """The gap-free spans [s] that every stream covers, each at least :data:`MIN_SEGMENT` long."""
    start = max(c.t[0] for c in cleaned)
    end = min(c.t[-1] for c in cleaned)
    if end <= start:
        spans = "; ".join(f"{c.name} {c.t[0]:.6g} to {c.t[-1]:.6g} s" for c in cleaned)
        raise LogError(f"{report.source}: the channels' streams do not overlap in time ({spans}); "
                       "are they on the same clock? Use one time source for all channels")
    for c in cleaned:
        before, after = int(np.sum(c.t < start - 1e-9)), int(np.sum(c.t > end + 1e-9))
        if before or after:
            report.add(f"{c.name}: {before} sample(s) before t = {start:.6g} s and {after} "
                       f"after t = {end:.6g} s left out (outside the span every channel "
                       "covers)")
    gaps = sorted((a, b) for c in cleaned for a, b in c.gaps if b > start and a < end)
    for c in cleaned:
        for a, b in c.gaps:
            if b > start and a < end:
                report.add(f"{c.name}: {b - a:.3g} s without samples after t = {a:.6g} s "
                           f"(more than {c.max_gap:.3g} s): the log is split there")
    spans, t0 = [], start
    for a, b in gaps:
        if a > t0:
            spans.append((t0, a))
        t0 = max(t0, b)
    spans.append((t0, end))
    kept = []
    for a, b in spans:
        if b - a < MIN_SEGMENT:
            report.add(f"{b - a:.3g} s between gaps from t = {a:.6g} s left out: shorter than "
                       f"{MIN_SEGMENT:g} s")
        else:
            kept.append((a, b))
    if not kept:
        raise LogError(f"{report.source}: no gap-free stretch of at least {MIN_SEGMENT:g} s; "
                       "the log has too many gaps (see max_gap in the channel map)")
    if len(kept) > 1:
        report.add(f"split into {len(kept)} gap-free segments, validated separately and "
                   "pooled by distance")
    return kept


def assemble(streams: list[Stream], chmap: ChannelMap, vehicle: Vehicle, source: str,
             report: Report, time_factor: float = 1.0, accept: tuple[str, ...] = (),
             scale: LogScale = FULL_SIZE, ctx: Context | None = None) -> list[Run]:
    """Canonical runs, one per gap-free segment, from a map's streams (see the module docstring).

    Parameters
    ----------
    streams : list of Stream
        The channels as read.
    chmap : ChannelMap
        The map, for ``max_gap``, the differentiator's window and the channels named.
    vehicle : Vehicle
        Geometry for derived units and the steering map for a derived ``delta_h``.
    source : str
        The file, for messages.
    report : Report
        Receives every repair, trim, split and derivation.
    time_factor : float
        Stamps to seconds.
    accept : tuple of str
        ``gap``: interpolate across gaps, no split; ``velocity``, ``jump``: skip
        the measured velocities' unit and jump checks here.
    scale : LogScale
        The vehicle's scale, for the checks' thresholds.
    ctx : Context, optional
        The channels' names and declared units, for the messages.
    """
    cleaned = [_clean(s, chmap, report, time_factor, "gap" not in accept) for s in streams]
    _local_plane(cleaned, chmap, report)
    spans = segments(cleaned, report)
    _check_density(cleaned, spans, report, scale)
    origin = min(float(c.t[0]) for c in cleaned)
    runs = []
    for k, (a, b) in enumerate(spans, start=1):
        grid = a + np.arange(int(math.floor((b - a) * RATE + 1e-9)) + 1) / RATE
        frame = {"t": grid - grid[0]}
        for c in cleaned:
            frame.update({name: np.interp(grid, c.t, v) for name, v in c.si.items()})
        df, derived = complete(pd.DataFrame(frame), chmap, vehicle)
        where = source if len(spans) == 1 else f"{source} (segment {k} of {len(spans)})"
        if k == 1:
            for note in derived.get("notes", []):
                report.add(note)
        _check_measured(df, chmap, where, report, accept, scale, ctx or CANONICAL)
        check_frame(df, f"{where}, imported through {chmap.path}", scale,
                    derived.get("channels", ()))
        meta: dict = {"source": "measured",
                      "import": {"file": source, "channels": chmap.path}}
        if derived:
            meta["derived"] = derived
        if chmap.noise:
            meta[noise.META_KEY] = noise.to_meta(chmap.noise)
        if len(spans) > 1:
            # from the log's first sample [s]: where the segment lies in the source
            meta["segment"] = {"index": k, "of": len(spans), "t0": a - origin,
                               "t1": b - origin}
        runs.append(Run(df, meta))
    direction = _direction(runs)
    report.add(f"direction: {direction[0]} ({100.0 * direction[1]:.0f} % of the distance)")
    for r in runs:
        r.meta["direction"] = direction[0]
        r.meta["import"]["report"] = report.lines
    return runs


def _check_density(cleaned: list[_Clean], spans: list[tuple[float, float]], report: Report,
                   scale: LogScale) -> None:
    """Refuse a stream far sparser over a segment than interpolation onto 100 Hz can bridge.

    Raises
    ------
    LogError
        Naming the stream, its samples over the segment and the limit.
    """
    limit = MAX_INTERVAL * scale.speed
    for a, b in spans:
        for c in cleaned:
            n = int(np.sum((c.t >= a - 1e-9) & (c.t <= b + 1e-9)))
            mean = (b - a) / max(n - 1, 1)
            if mean > limit:
                elsewhere = (f"; over the whole log it has {c.t.size} over "
                             f"{c.t[-1] - c.t[0]:.6g} s" if c.t.size != n else "")
                raise LogError(f"{report.source}: {c.name}: sample check: {n} sample(s) over "
                               f"the {b - a:.6g} s from t = {a:.6g} s that every channel "
                               f"covers, one per {mean:.3g} s, where interpolation needs one "
                               f"per {limit:.3g} s at most{elsewhere}; its stamps may be in "
                               "another unit, or the topic dropped most of its messages")


def _direction(runs: list[Run]) -> tuple[str, float]:
    """``forward`` or ``reverse``: how the tractor covers most of the distance, and its share."""
    ds = [(np.abs(f["v_x_1"].to_numpy()), f["v_x_1"].to_numpy() < 0, f["t"].to_numpy())
          for f in (r.frame for r in runs)]
    total = sum(float(np.trapezoid(v, t)) for v, _, t in ds)
    back = sum(float(np.trapezoid(v * rev, t)) for v, rev, t in ds)
    share = back / total if total > 0 else 0.0
    return ("reverse", share) if share > 0.5 else ("forward", 1.0 - share)


def _check_measured(df: pd.DataFrame, chmap: ChannelMap, where: str, report: Report,
                    accept: tuple[str, ...], scale: LogScale, ctx: Context) -> None:
    """A measured velocity's unit and sign, then GNSS jumps, named before the structural checks.

    A speed in km/h is named as such here (it would also move every position
    step away from what the velocity explains, and read as a jump).
    """
    t = df["t"].to_numpy()
    for i in chmap.units():
        if not all(c in chmap.entries for c in (f"v_x_{i}", f"v_y_{i}")):
            continue  # derived from the pose: consistent with it by construction
        if "velocity" not in accept:
            found = consistency.check_velocity(t, df, i, ctx, scale)
            if found is not None and not found.direction:
                raise LogError(found.finding.message(where))
        if "jump" not in accept:
            psi = df[f"psi_{i}"].to_numpy()
            vx, vy = df[f"v_x_{i}"].to_numpy(), df[f"v_y_{i}"].to_numpy()
            c, s = np.cos(psi), np.sin(psi)
            check_jumps(t, df[f"x_{i}"].to_numpy(), df[f"y_{i}"].to_numpy(), c * vx - s * vy,
                        s * vx + c * vy, Report(where), scale.distance(MAX_JUMP))


def complete(df: pd.DataFrame, chmap: ChannelMap, vehicle: Vehicle) -> tuple[pd.DataFrame, dict]:
    """Derive every schema channel the map does not name, on one uniform segment.

    Returns
    -------
    frame : DataFrame
        The schema's columns, in order.
    derived : dict
        ``channels`` derived, ``notes`` (one line each), ``note`` (them joined),
        the vehicle and, where used, the differentiator's ``window`` [s] and the
        articulation ``rate``; empty when nothing was derived.
    """
    t = df["t"].to_numpy()
    w = chmap.window
    channels: list[str] = []
    notes: list[str] = []
    info: dict = {}
    for i in chmap.units():
        missing = [c for c in RATES[i] if c not in df]
        if missing:
            x, y, psi = (df[c].to_numpy() for c in POSE[i])
            rates = rates_from_pose(t, x, y, psi, w)
            for c in missing:
                df[c] = rates[c.rsplit("_", 1)[0]]
            channels += missing
            unit = "tractor" if i == 1 else "semitrailer"
            notes.append(f"{', '.join(missing)} derived from the {unit}'s pose with a quadratic "
                         f"Savitzky-Golay differentiator over {w:g} s")
            info["window"] = w
    units = chmap.units()
    if len(units) == 2:
        df["gamma"] = wrap_angle(df["psi_1"].to_numpy() - df["psi_2"].to_numpy())
    else:
        if "gamma_rate" in df:
            rate, rate_from, label = df["gamma_rate"].to_numpy(), None, "gamma_rate"
        else:
            rate = derivative(t, np.unwrap(df["gamma"].to_numpy()), w)
            rate_from = f"its Savitzky-Golay derivative over {w:g} s"
            label = "d gamma / dt"
            info["window"] = w
        derive = derive_trailer if units == (1,) else derive_tractor
        df, note = derive(df, vehicle, rate, rate_from)
        channels += list(TRAILER if units == (1,) else TRACTOR)
        notes.append(note)
        info["rate"] = label
    if "delta_h" not in df:
        df["delta_h"] = _delta_h_from_yaw_rate(df, vehicle)
        channels.insert(0, "delta_h")
        notes.append("no steering channel: delta_h derived from the tractor's yaw rate and "
                     f"speed through {vehicle.name}'s KIN steering map; the models are steered "
                     "from the yaw rate (--steer-from yaw-rate), so the comparison is about the "
                     "semitrailer")
        info["steer_from"] = "yaw-rate"
    df["gamma"] = wrap_angle(df["gamma"].to_numpy())
    df = df[list(COLUMNS)]
    if not channels:
        return df, {}
    return df, {"channels": channels, "notes": notes, "note": "; ".join(notes),
                "vehicle": vehicle.name, "vehicle_path": str(vehicle.path), **info}


def _delta_h_from_yaw_rate(df: pd.DataFrame, vehicle: Vehicle) -> np.ndarray:
    """The steering-wheel angle that turns the tractor at its yaw rate (KIN's map) [rad]."""
    t = df["t"].to_numpy()
    r1 = df["r_1"].to_numpy()
    u1 = smooth_speed(t, df["v_x_1"].to_numpy() + r1 * vehicle.sensor1[1])
    delta = road_wheel_from_yaw_rate(u1, smooth_speed(t, r1), equivalent_wheelbase(vehicle))
    smap = vehicle.steering_for("kin")
    return steering_wheel(smap, delta, vehicle.steering.delta_max)
