"""Physics-based consistency checks of a canonical log: its channels must describe one motion.

A log whose every channel is plausible on its own can still be wrong as a
whole: velocities in km/h, a yaw rate about the wrong axis, a heading in
radians where degrees were expected, latitude and longitude swapped. Each of
these passes the structural checks of :func:`artic.validation.logs.runfile.check_frame`
and then gives garbage criteria. The checks here compare channels that measure
the same motion twice, *globally* (fits over windows of the whole log, not
per sample, so noise averages out), and name the channel, the time window and
the likely cause when they disagree:

``gap``
    No time step longer than :data:`artic.validation.logs.checks.MAX_GAP`.
``turning``
    No unit turns tighter than its geometry allows: the tractor's sensor on a
    radius of at least ``L1 / tan(delta_max)`` (less its lateral offset), the
    semitrailer's on one of at least its distance from the axle (about which
    the semitrailer may turn on the spot), judged per metre of the sensor's
    own track with :data:`TURN_MARGIN` for tyre slip. Positions
    in too small a unit (millimetres declared as metres) turn the unit a
    hundred or a thousand times tighter. Larger units are refused by the
    structural limits on speed.
``axes``
    Each unit's axle (the tractor's drive axle, the semitrailer's axle
    group) travels along the unit's heading, forwards or backwards, over
    :data:`VELOCITY_WINDOW` windows: swapped x and y, a mirrored axis, or a
    heading of another sense or zero direction moves it sideways.
``yaw-rate``
    The integral of the yaw rate ``r_i`` against the change of the heading
    ``psi_i``, over :data:`YAW_WINDOW` windows, on any log whose heading
    changes by more than the noise (docking and parking included).
``curvature``
    The course of the position track (its direction of travel, from chords of
    the track alone) against the integrated yaw rate: the integral form of
    "path curvature equals ``r / v``". It tells which of ``r_i`` and ``psi_i``
    is wrong when they disagree, and finds a mirrored track (swapped
    latitude and longitude, or x and y).
``velocity``
    The velocity ``(v_x_i, v_y_i)``, turned into the plane by ``psi_i`` and
    integrated over :data:`VELOCITY_WINDOW` windows, against the position
    track's displacement: sign, scale (km/h) and direction.
``jump``
    No single position step more than :data:`artic.validation.logs.checks.MAX_JUMP`
    beyond what the velocity explains (a GNSS jump).
``steering``
    The steering-wheel angle through the vehicle's steering map, eq. (3):
    within the linkage's reach, and with the kinematic curvature
    ``tan(delta) / L1`` that the tractor shows (heading rate over speed along
    the heading, both from ``psi_1`` and the track, so that this check does not
    repeat the others; sign and scale, tolerant of understeer and of a
    driver holding the wheel at lock).
``hitch``
    The semitrailer's position and heading against the tractor's: both
    sensors must put the hitch at one point. Fitted freely (the hitch's
    position in each unit is estimated) and, with a vehicle, with the
    vehicle file's sensor positions and ``L1c``.
``articulation``
    On a log whose one unit is derived from the other and ``gamma`` (where
    the hitch check cannot fail), the sign and the scale of ``gamma``: the
    derived unit's axle must roll along its heading. With the tractor
    measured, that is the kinematic trailer equation ``gamma' = r_1 (1 - L1c
    cos(gamma) / L2) - u_1 sin(gamma) / L2``; with the semitrailer measured,
    the tractor's drive axle: ``u_K sin(gamma) + L1c gamma' = v_K cos(gamma) -
    r_2 L1c`` with the kingpin's velocity ``(u_K, v_K)`` in the semitrailer's
    axes. Over :data:`YAW_WINDOW` windows the terms odd in ``gamma`` must equal
    the even (yaw-rate) ones: their mirror (a flipped sign) or a multiple of
    them (a unit mistake, radians declared as degrees) fitting better is refused.
``metadata``
    The direction a canonical log's metadata states (``direction``, or the
    one its ``manoeuvre`` implies: ``docking``, ``parking`` and ``*-reverse``
    reverse, the other kinds drive forward) must cover at least
    :data:`METADATA_SHARE` of the distance the tractor travels.

Each check returns nothing or one :class:`Finding`. :func:`check_log` raises a
:class:`~artic.validation.logs.runfile.LogError` for the first finding that the
caller did not accept (``--accept CHECK``), and returns the accepted ones as
lines for the run's metadata. A check with too little motion to judge (a
log standing still, a straight run for the yaw rate) passes: its noise floor
is stated with each window size below.

The distances and speeds below are the full-size ones; with a vehicle of the
``scale-model`` class they scale with its size and speed range
(:mod:`artic.validation.logs.scale`).
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Collection, Iterator, Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import load_vehicle, resolve_vehicle_path
from artic.validation.logs.checks import MAX_GAP, MAX_JUMP
from artic.validation.logs.runfile import LogError
from artic.validation.logs.scale import FULL_SIZE, LogScale
from artic.validation.logs.schema import CHECKS

YAW_WINDOW = 2.0
"""Window of the yaw-rate and curvature fits [s]."""

YAW_NOISE = 2e-3
"""Heading-change noise per :data:`YAW_WINDOW` window [rad]: an RTK-aided INS heading
(0.05 deg, slowly wandering) differenced over 2 s, with a generous margin."""

YAW_FLOOR = 0.03
"""Least root-sum-square heading change over the windows that is judged [rad]."""

CHORD = 0.5
"""Half-length in time of the track chords that give the course [s]."""

CHORD_MIN = 0.3
"""Shortest chord whose direction counts as a course [m]: 1 cm of position noise
then turns it by at most 2 deg."""

COURSE_NOISE = 0.03
"""Course-change noise per window [rad] (two chords of at least ``CHORD_MIN``)."""

COURSE_FLOOR = 0.15
"""Least root-sum-square course change over the windows that is judged [rad]."""

VELOCITY_WINDOW = 1.0
"""Window of the velocity fit [s]."""

VELOCITY_MIN_STEP = 0.3
"""Least displacement in a window for it to count in the velocity fit [m]."""

VELOCITY_SCALE_TOL = 0.15
"""Accepted relative difference of the integrated velocity's and the track's lengths."""

VELOCITY_ANGLE_TOL = math.radians(25.0)
"""Largest angle between integrated velocity and track in a window that counts as agreeing."""

STEER_WINDOW = 1.0
"""Window of the steering fit [s]."""

STEER_MIN_SPEED = 0.5
"""Least tractor speed for a window to count in the steering fit [m/s]."""

STEER_FLOOR = 0.08
"""Least root-sum-square ``u tan(delta)`` (or ``r_1 L1``) over the windows that is judged
[m/s]: about 30 windows at 2 m/s and one degree of road-wheel angle."""

STEER_NOISE = 0.005
"""Noise of ``u tan(delta)`` per window [m/s]: a steering-wheel offset half a degree
off the map's at 10 km/h, with margin; the floor grows with its root-sum-square."""

STEER_SLOPE = (0.3, 3.0)
"""Accepted slope of ``psi_1' L1`` on ``u tan(delta)``: understeer, tyre slip at lock and a
driver turning against the stop lower it; a different tractor moves it by tens of percent,
never by the factor 57.3 of a unit mistake."""

STEER_REACH = 2.0
"""Largest road-wheel angle accepted, as a multiple of the vehicle's ``delta_max``:
drivers turn the wheel against its stop, but not to twice the lock."""

HITCH_RMS = 0.25
"""Largest RMS distance between the hitch points the two units' sensors give [m]."""

HITCH_RMS_VEHICLE = 0.5
"""The same with the vehicle file's sensor positions and ``L1c`` [m]."""

ARTICULATION_FLOOR = 0.02
"""Least RMS over the windows of the yaw-rate term's articulation change that is judged
[rad]: what a hitch-angle sensor with 0.8 deg of noise (camera-based ones reach 0.6-0.8 deg
RMS) shows between two samples. A log that turns less cannot tell the sign."""

ARTICULATION_MIRROR = 0.5
"""The mirror must fit at least twice as well (RMS misfit) for a refusal. A flipped sign
puts twice the yaw-rate term into the logged fit's misfit; noise ``sigma`` per window then
gives ``sqrt(sigma^2 + 4 a^2)`` against ``sigma``, past the ratio once the term's RMS ``a``
exceeds ``0.9 sigma``. With the right sign the mirror's misfit is the larger one."""

ARTICULATION_SCALE = (1.0 / 3.0, 3.0)
"""Accepted factor between the articulation's odd and even terms: tyre slip and a hitch
sensor's offset move it by tens of percent; a unit mistake by 57.3 (degrees) or more."""

TURN_MARGIN = 2.0
"""How much tighter than its kinematic limit a unit may appear to turn: tyre slip in
reverse (a semitrailer pushing the tractor's rear out) and the heading's noise over short
windows, with a factor of two to spare; a unit mistake is a factor of 100 or 1000."""

TURN_WINDOW_MIN = 4.0 * YAW_NOISE
"""Least heading change in a window for it to count in the turning check [rad]: windows
of heading noise alone (a unit standing still) leave it."""

AXES_TOL = math.radians(30.0)
"""Largest median angle between a unit's axle travel and its heading [rad]: tyre slip
at yard speeds is a few degrees, a chord over a window in a turn adds less; swapped
axes are off by tens of degrees in every turn."""

AXES_SLIP = math.radians(2.0)
"""Median angle between axle travel and heading below which a track is not judged for a
mirror [rad]: a semitrailer's heading may swing by only a few degrees, and a mirror moves
the travel by twice the swing. Beyond it, a track that fits at least twice as well mirrored
back is refused. Tyre slip and a sensor off the vehicle file's place move the travel off the
heading too, but alike for the track and its mirror: they never make the mirror fit twice
as well (on a log that keeps its heading both fit alike, and nothing is refused)."""

ARTICULATION_OFFSET = math.radians(2.0)
"""Largest constant difference between a measured ``gamma`` and the measured headings'
``psi_1 - psi_2`` (less the sensors' declared mounting yaws) [rad]: ten times what
dual-antenna GNSS/INS headings (0.1-0.2 deg each) and a hitch encoder (0.1 deg) leave, and
what a rear camera's 1.25 deg RMS leaves in a median over a log. A hitch sensor's zero or an
undeclared mounting yaw shows as more."""

METADATA_SHARE = 0.25
"""Least share of the distance driven in the direction the metadata states: a docking
or parking manoeuvre pulls forward to set up, but reverses for most of its distance."""

REVERSE_KINDS = ("ramp-steer-reverse", "docking", "parking")
"""Manoeuvre kinds that reverse; every other kind drives forward."""

# Factors that mark a unit mistake, with their names.
_DEG = math.degrees(1.0)
_KPH = 3.6


@dataclass(frozen=True)
class Finding:
    """One disagreement between channels.

    Parameters
    ----------
    check : str
        Its check's name (a key of :data:`CHECKS`).
    channel : str
        The channel(s) to blame, as the source names them.
    t0, t1 : float
        Time window [s].
    problem : str
        What disagrees, with numbers.
    cause : str
        The likely cause.
    """

    check: str
    channel: str
    t0: float
    t1: float
    problem: str
    cause: str

    def message(self, source: str) -> str:
        """One line naming the source, channel, window, problem, cause and the fix."""
        return (f"{source}: channel {self.channel}, t = {self.t0:.2f} to {self.t1:.2f} s: "
                f"{self.problem}; {self.cause}. Fix the log, or pass --accept {self.check} "
                "to use it as it is")


@dataclass(frozen=True)
class Context:
    """How the log's channels are named and in which unit they arrived.

    Parameters
    ----------
    names : mapping
        Canonical column to the name in the source (``"tractor.csv: AngRateZ"``).
    units : mapping
        Canonical column to the unit its source column is expected in.
    signs : mapping
        Canonical column to the sign convention of its source column.
    """

    names: Mapping[str, str]
    units: Mapping[str, str]
    signs: Mapping[str, str]

    def name(self, col: str) -> str:
        """The source's name of a canonical column."""
        return self.names.get(col, col)


CANONICAL = Context(
    names={}, units={"r_1": "rad/s", "r_2": "rad/s", "psi_1": "rad", "psi_2": "rad",
                     "delta_h": "rad", "v_x_1": "m/s", "v_x_2": "m/s"},
    signs={"r_1": "counter-clockwise positive", "r_2": "counter-clockwise positive",
           "psi_1": "counter-clockwise from x", "psi_2": "counter-clockwise from x",
           "delta_h": "left positive", "v_x_1": "forward positive",
           "v_x_2": "forward positive", "gamma": "tractor yaw minus semitrailer yaw"})
"""A log in the signal schema (SI, ISO 8855)."""


def export_context(tractor: str, trailer: str, can: str, cols: Mapping[str, str]) -> Context:
    """The context of an OXTS-style export: its files, column names and units.

    Parameters
    ----------
    tractor, trailer, can : str
        The three sources.
    cols : mapping
        Wanted channel (``heading``, ``yaw_rate``, ``vel_forward``, ``pos``, ``swa``) to
        the column names found.
    """
    names, units, signs = {}, {}, {}
    for i, src in ((1, tractor), (2, trailer)):
        names.update({f"r_{i}": f"{src}: {cols['yaw_rate']}",
                      f"psi_{i}": f"{src}: {cols['heading']}",
                      f"v_x_{i}": f"{src}: {cols['vel_forward']}",
                      f"x_{i}": f"{src}: {cols['pos']}"})
        units.update({f"r_{i}": "deg/s", f"psi_{i}": "deg", f"v_x_{i}": "m/s"})
        signs.update({f"r_{i}": "about z down", f"psi_{i}": "clockwise from north",
                      f"v_x_{i}": "forward positive"})
    names["delta_h"] = f"{can}: {cols['swa']}"
    units["delta_h"] = "deg"
    signs["delta_h"] = "left positive"
    return Context(names, units, signs)


def explain(factor: float, col: str, ctx: Context, known_only: bool = False) -> str:
    """The likely cause of a channel reading ``factor`` times what the others imply.

    Parameters
    ----------
    factor : float
        Channel over its expected value; negative for a flipped sign.
    col : str
        Canonical column.
    ctx : Context
        Names and units of the source.
    known_only : bool
        Return ``""`` unless the factor is a known mistake (a flipped sign, the
        degree/radian factor where the unit makes it plausible, km/h).
    """
    name, unit = ctx.name(col), ctx.units.get(col, "")
    sign = " (" + ctx.signs[col] + ")" if col in ctx.signs else ""
    mag = abs(factor)

    def near(x: float, ref: float) -> bool:
        return abs(math.log(x / ref)) < 0.25 if x > 0 else False

    wrong = ""
    if near(mag, _DEG):
        wrong = {"rad/s": "deg/s where rad/s is expected",
                 "rad": "degrees where radians are expected"}.get(unit, "")
        wrong = wrong or f"{_DEG:.1f} times too large"
    elif near(mag, 1.0 / _DEG):
        wrong = {"deg/s": "rad/s where deg/s is expected",
                 "deg": "radians where degrees are expected"}.get(unit, "")
        wrong = wrong or f"{_DEG:.1f} times too small (converted to radians twice?)"
    elif near(mag, _KPH) and unit == "m/s":
        wrong = "km/h where m/s is expected"
    elif near(mag, 1.0 / _KPH) and unit == "m/s":
        wrong = "3.6 times too small (m/s divided by 3.6?)"
    elif near(mag, 1.0 / _KPH) and unit == "km/h":
        wrong = "m/s where km/h is expected"
    elif not near(mag, 1.0):
        wrong = f"{mag:.3g} times what the other channels imply"
    if known_only and wrong and not wrong.endswith("expected"):
        return ""
    if factor < 0 and wrong:
        return f"{name} looks like {wrong}, and its sign is flipped{sign}"
    if factor < 0:
        return f"{name} sign is flipped{sign}"
    if wrong.endswith("expected"):
        return f"{name} looks like {wrong}"
    return f"{name} looks {wrong}"


# ------------------------------------------------------------------ helpers
def _windows(t: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray]:
    """Start and end sample of consecutive windows of ``width`` seconds (shared ends)."""
    k = np.floor((t - t[0]) / width).astype(np.int64)
    edges = np.flatnonzero(np.diff(k)) + 1
    edges = np.concatenate([[0], edges, [t.size - 1]])
    edges = np.unique(edges)
    return edges[:-1], edges[1:]


def _cumtrapz(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Running trapezoidal integral, starting at zero."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t))])


@dataclass(frozen=True)
class _Fit:
    """Two window series measuring one quantity: agreement statistics."""

    corr: float  # correlation without removing the mean (sign agreement)
    factor: float  # signed ratio of RMS values, b over a
    rms_a: float
    rms_b: float
    worst: int  # window that disagrees most

    def agrees(self, lo: float = 0.8, hi: float = 1.25, corr: float = 0.8) -> bool:
        """Correlated and of the same scale."""
        return self.corr >= corr and lo <= self.factor <= hi


def _fit(a: np.ndarray, b: np.ndarray) -> _Fit:
    """How far ``b`` is ``a`` times a constant; ``factor`` is that constant, signed."""
    sa, sb = math.sqrt(float(np.sum(a * a))), math.sqrt(float(np.sum(b * b)))
    if sa == 0.0 or sb == 0.0:
        corr = 0.0
        factor = math.inf if sa == 0.0 and sb > 0.0 else 0.0
    else:
        corr = float(np.sum(a * b)) / (sa * sb)
        factor = math.copysign(sb / sa, corr)
    scale = factor if math.isfinite(factor) and factor != 0.0 else 1.0
    worst = int(np.argmax(np.abs(b - scale * a) + np.abs(b / scale - a))) if a.size else 0
    return _Fit(corr, factor, sa, sb, worst)


def _course_change(t: np.ndarray, x: np.ndarray, y: np.ndarray, i0: np.ndarray,
                   i1: np.ndarray, scale: LogScale = FULL_SIZE) -> tuple[np.ndarray, np.ndarray]:
    """Course change of the track over each window, and which windows have one.

    The course at a sample is the direction of the chord from ``CHORD`` seconds
    before to ``CHORD`` after. A window counts when every chord in it is at
    least :data:`CHORD_MIN` long, so the course is defined throughout (no stop,
    no change of direction); its change is the sum of the wrapped changes
    from sample to sample.
    """
    n = t.size
    dt = float(np.median(np.diff(t))) if n > 1 else 1.0
    h = max(1, int(round(CHORD / dt)))
    lo = np.clip(np.arange(n) - h, 0, n - 1)
    hi = np.clip(np.arange(n) + h, 0, n - 1)
    cx, cy = x[hi] - x[lo], y[hi] - y[lo]
    long_enough = np.hypot(cx, cy) >= scale.distance(CHORD_MIN)
    course = np.arctan2(cy, cx)
    step = np.concatenate([[0.0], np.angle(np.exp(1j * np.diff(course)))])
    cum = np.cumsum(step)
    bad = np.cumsum(~long_enough)
    ok = (bad[i1] - bad[i0] == 0) & long_enough[i0]
    return cum[i1] - cum[i0], ok


# ------------------------------------------------------------------ checks
def check_gap(t: np.ndarray, max_gap: float = MAX_GAP) -> Finding | None:
    """No time step longer than ``max_gap`` [s]."""
    dt = np.diff(t)
    if not dt.size or float(dt.max()) <= max_gap:
        return None
    i = int(np.argmax(dt))
    return Finding("gap", "t", float(t[i]), float(t[i + 1]),
                   f"{dt[i]:.4g} s without samples (more than {max_gap} s)",
                   "the log has a hole: cut the run there")


def _turns(t: np.ndarray, df: pd.DataFrame, i: int, i0: np.ndarray, i1: np.ndarray,
           scale: LogScale = FULL_SIZE
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per window: heading change, yaw-rate integral, track course change, which have a course.

    The course changes as the heading does plus the change of the sensor's
    sideslip ``atan2(v_y, v_x)``, which is added to the yaw-rate integral here.
    """
    integ = _cumtrapz(t, df[f"r_{i}"].to_numpy(dtype=float))
    psi = df[f"psi_{i}"].to_numpy(dtype=float)
    beta = np.unwrap(np.arctan2(df[f"v_y_{i}"].to_numpy(float), df[f"v_x_{i}"].to_numpy(float)))
    course, ok = _course_change(t, df[f"x_{i}"].to_numpy(float), df[f"y_{i}"].to_numpy(float),
                                i0, i1, scale)
    slip = beta[i1] - beta[i0]
    return psi[i1] - psi[i0], integ[i1] - integ[i0], course - slip, ok


def check_yaw(t: np.ndarray, df: pd.DataFrame, i: int, ctx: Context,
              scale: LogScale = FULL_SIZE) -> Finding | None:
    """Integrated yaw rate against heading change; the track's course decides which is wrong."""
    i0, i1 = _windows(t, YAW_WINDOW)
    if not i0.size:
        return None
    head_w, rate_w, course, ok = _turns(t, df, i, i0, i1, scale)
    floor = max(YAW_FLOOR, 4.0 * YAW_NOISE * math.sqrt(i0.size))
    fit = _fit(head_w, rate_w)  # factor: yaw-rate integral over heading change
    if max(fit.rms_a, fit.rms_b) < floor or fit.agrees():
        return None
    w0, w1 = float(t[i0[fit.worst]]), float(t[i1[fit.worst]])
    span0, span1 = float(t[i0[0]]), float(t[i1[-1]])
    # The track's course is a third measurement of the turning: it sides with one of the two.
    judged, blame_heading = False, False
    if ok.sum() >= 3:
        vs_rate = _fit(course[ok], rate_w[ok])
        vs_head = _fit(course[ok], head_w[ok])
        judged = max(vs_rate.rms_a, vs_rate.rms_b) >= max(
            COURSE_FLOOR, 4.0 * COURSE_NOISE * math.sqrt(ok.sum()))
        blame_heading = judged and vs_rate.agrees(0.7, 1.4, 0.6) and not vs_head.agrees(
            0.7, 1.4, 0.6)
    problem = (f"the integral of r_{i} is {_ratio(fit.factor)} times the change of psi_{i} "
               f"(worst over t = {w0:.2f} to {w1:.2f} s)")
    if blame_heading:
        return Finding("yaw-rate", ctx.name(f"psi_{i}"), span0, span1, problem,
                       explain(1.0 / fit.factor, f"psi_{i}", ctx)
                       + "; the position track turns with the yaw rate")
    if judged or abs(math.log(abs(fit.factor))) < 0.5:
        return Finding("yaw-rate", ctx.name(f"r_{i}"), span0, span1, problem,
                       explain(fit.factor, f"r_{i}", ctx))
    # Too little travel to tell which is wrong: name the known mistakes that fit.
    rate = explain(fit.factor, f"r_{i}", ctx, known_only=True)
    head = explain(1.0 / fit.factor, f"psi_{i}", ctx, known_only=True)
    if rate and head:
        return Finding("yaw-rate", f"{ctx.name(f'r_{i}')} or {ctx.name(f'psi_{i}')}", span0,
                       span1, problem, f"{rate}, or {head}")
    if head:
        return Finding("yaw-rate", ctx.name(f"psi_{i}"), span0, span1, problem, head)
    return Finding("yaw-rate", ctx.name(f"r_{i}"), span0, span1, problem,
                   rate or explain(fit.factor, f"r_{i}", ctx))


def _ratio(f: float) -> str:
    """A ratio for a message: ``57.3``, ``-1.00``, ``1/57.3`` (never ``0.0``)."""
    if not math.isfinite(f):
        return "infinitely many"
    if f != 0.0 and abs(f) < 0.1:
        return f"{'-' if f < 0 else ''}1/{1.0 / abs(f):.3g}"
    return f"{f:.3g}"


def check_curvature(t: np.ndarray, df: pd.DataFrame, i: int, ctx: Context,
                    scale: LogScale = FULL_SIZE) -> Finding | None:
    """Course change of the position track against the integrated yaw rate (see :func:`_turns`)."""
    i0, i1 = _windows(t, YAW_WINDOW)
    if not i0.size:
        return None
    _, rate_w, course, ok = _turns(t, df, i, i0, i1, scale)
    if ok.sum() < 3:
        return None
    fit = _fit(rate_w[ok], course[ok])  # factor: the track's turning over the yaw rate's
    floor = max(COURSE_FLOOR, 4.0 * COURSE_NOISE * math.sqrt(ok.sum()))
    if max(fit.rms_a, fit.rms_b) < floor or fit.agrees(0.7, 1.4, 0.6):
        return None
    j = np.flatnonzero(ok)[fit.worst]
    pos = ctx.name(f"x_{i}") if f"x_{i}" in ctx.names else f"x_{i}, y_{i}"
    mirrored = fit.corr < -0.3
    cause = (f"{pos} looks mirrored: latitude and longitude (or x and y) swapped, or one of "
             "them with the wrong sign" if mirrored else
             f"{pos} does not follow the yaw rate: a position of another unit or time base, "
             "or a wrong scale of latitude or longitude")
    return Finding("curvature", pos, float(t[i0[ok][0]]), float(t[i1[ok][-1]]),
                   f"the track's course changes {_ratio(fit.factor)} times as much as the "
                   f"heading (r_{i} integrated) says, correlation {fit.corr:.2f} (worst over "
                   f"t = {t[i0[j]]:.2f} to {t[i1[j]]:.2f} s)", cause)


@dataclass(frozen=True)
class _Velocity:
    """A velocity finding, and whether it is about direction (not sign or scale)."""

    finding: Finding
    direction: bool


def check_velocity(t: np.ndarray, df: pd.DataFrame, i: int, ctx: Context,
                   scale: LogScale = FULL_SIZE) -> _Velocity | None:
    """Integrated velocity, turned by the heading, against the track's displacement."""
    i0, i1 = _windows(t, VELOCITY_WINDOW)
    if not i0.size:
        return None
    psi = df[f"psi_{i}"].to_numpy(float)
    vx, vy = df[f"v_x_{i}"].to_numpy(float), df[f"v_y_{i}"].to_numpy(float)
    ve = _cumtrapz(t, np.cos(psi) * vx - np.sin(psi) * vy)
    vn = _cumtrapz(t, np.sin(psi) * vx + np.cos(psi) * vy)
    x, y = df[f"x_{i}"].to_numpy(float), df[f"y_{i}"].to_numpy(float)
    dv = np.column_stack([ve[i1] - ve[i0], vn[i1] - vn[i0]])
    dm = np.column_stack([x[i1] - x[i0], y[i1] - y[i0]])
    lv, lm = np.hypot(dv[:, 0], dv[:, 1]), np.hypot(dm[:, 0], dm[:, 1])
    use = np.maximum(lv, lm) >= scale.distance(VELOCITY_MIN_STEP)
    if use.sum() < 3:
        return None
    dv, dm, lv, lm = dv[use], dm[use], lv[use], lm[use]
    idx = np.flatnonzero(use)
    angle = np.arctan2(dv[:, 0] * dm[:, 1] - dv[:, 1] * dm[:, 0],
                       dv[:, 0] * dm[:, 0] + dv[:, 1] * dm[:, 1])
    # The median of the windows' ratios: a single jump (the jump check's business) or a
    # stop does not move it; a unit or scale mistake moves every window alike.
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = float(np.median(np.where(lm > 0, lv / lm, np.inf)))
    agree = np.abs(angle) <= VELOCITY_ANGLE_TOL
    same_scale = 0.0 < scale < math.inf and abs(math.log(scale)) <= math.log1p(
        VELOCITY_SCALE_TOL)
    if same_scale and agree.mean() >= 0.9:
        return None
    span0, span1 = float(t[i0[idx[0]]]), float(t[i1[idx[-1]]])
    worst = int(np.argmax(np.abs(angle) + np.abs(np.log(np.maximum(lv, 1e-9)
                                                         / np.maximum(lm, 1e-9)))))
    w = f"worst over t = {t[i0[idx[worst]]]:.2f} to {t[i1[idx[worst]]]:.2f} s"
    names = ctx.name(f"v_x_{i}") if f"v_x_{i}" in ctx.names else f"v_x_{i}, v_y_{i}"
    flipped = float(np.median(np.abs(angle))) > math.radians(120.0)
    if flipped or agree.mean() >= 0.9:
        factor = -scale if flipped else scale
        return _Velocity(Finding(
            "velocity", names, span0, span1,
            f"integrated over time it covers {scale:.3g} times the track's length"
            + (", pointing backwards along it" if flipped else "") + f" ({w})",
            explain(factor, f"v_x_{i}", ctx).replace(ctx.name(f"v_x_{i}"), "the velocity", 1)),
            direction=False)
    med = math.degrees(float(np.median(np.abs(angle))))
    return _Velocity(Finding(
        "velocity", f"{names}, {ctx.name(f'psi_{i}')}", span0, span1,
        f"turned by the heading it points {med:.0f} deg (median) away from the track's "
        f"direction, {scale:.3g} times its length ({w})",
        "the heading is wrong (unit, sense or zero direction), or latitude and longitude "
        "(x and y) are swapped"), direction=True)


def check_jump(t: np.ndarray, df: pd.DataFrame, i: int, ctx: Context,
               scale: LogScale = FULL_SIZE) -> Finding | None:
    """No position step more than :data:`MAX_JUMP` (scaled) beyond what the velocity explains."""
    psi = df[f"psi_{i}"].to_numpy(float)
    vx, vy = df[f"v_x_{i}"].to_numpy(float), df[f"v_y_{i}"].to_numpy(float)
    ve, vn = np.cos(psi) * vx - np.sin(psi) * vy, np.sin(psi) * vx + np.cos(psi) * vy
    x, y = df[f"x_{i}"].to_numpy(float), df[f"y_{i}"].to_numpy(float)
    dt = np.diff(t)
    step = np.hypot(np.diff(x) - 0.5 * (ve[1:] + ve[:-1]) * dt,
                    np.diff(y) - 0.5 * (vn[1:] + vn[:-1]) * dt)
    limit = scale.distance(MAX_JUMP)
    if not step.size or float(step.max()) <= limit:
        return None
    k = int(np.argmax(step))
    return Finding("jump", ctx.name(f"x_{i}") if f"x_{i}" in ctx.names else f"x_{i}, y_{i}",
                   float(t[k]), float(t[k + 1]),
                   f"the position jumps {step[k]:.3g} m more than the velocity explains "
                   f"(limit {limit:.3g} m)", "a GNSS jump: cut the run there or correct it")


def check_steering(t: np.ndarray, df: pd.DataFrame, vehicle, ctx: Context,
                   scale: LogScale = FULL_SIZE) -> Finding | None:
    """Steering wheel through eq. (3): within reach, and turning the tractor as it does."""
    s = vehicle.steering_for("kin")
    smap = s
    dh = df["delta_h"].to_numpy(float)
    delta = np.asarray(smap.road_wheel(dh), dtype=float)
    reach = STEER_REACH * vehicle.steering.delta_max
    name = ctx.name("delta_h")
    peak = int(np.argmax(np.abs(delta)))
    if abs(delta[peak]) > reach:
        return Finding("steering", name, float(t[peak]), float(t[peak]),
                       f"the steering wheel's {math.degrees(dh[peak]):.0f} deg is "
                       f"{math.degrees(delta[peak]):.0f} deg at the road wheels through the "
                       f"steering map of {vehicle.name} (i_s = {s.i_s:g}), beyond "
                       f"{STEER_REACH:g} times its lock of "
                       f"{math.degrees(vehicle.steering.delta_max):.0f} deg",
                       explain(_DEG, "delta_h", ctx) if ctx.units.get("delta_h") == "rad"
                       else f"{name} is not the steering-wheel angle of this vehicle")
    i0, i1 = _windows(t, STEER_WINDOW)
    if not i0.size:
        return None
    # Speed and turning from the track and the heading alone, so that this check
    # does not repeat the velocity and yaw-rate checks: the tractor sensor's
    # displacement along the heading, and the heading's change, per window.
    span = t[i1] - t[i0]
    x, y = df["x_1"].to_numpy(float), df["y_1"].to_numpy(float)
    psi = df["psi_1"].to_numpy(float)
    mid = 0.5 * (psi[i0] + psi[i1])
    u_w = ((x[i1] - x[i0]) * np.cos(mid) + (y[i1] - y[i0]) * np.sin(mid)) / span
    moving = np.abs(u_w) >= scale.speed_of(STEER_MIN_SPEED)
    if moving.sum() < 3:
        return None
    tan_w = (_cumtrapz(t, np.tan(np.clip(delta, -1.5, 1.5))))
    tan_w = (tan_w[i1] - tan_w[i0]) / span
    # psi_1' L1 = k u tan(delta) + c u: c takes up a steering-wheel offset other than the
    # map's; k is the slope that a unit or sign mistake changes.
    a = ((psi[i1] - psi[i0]) / span * vehicle.L1)[moving]
    uw = u_w[moving]
    b = uw * tan_w[moving]
    a_perp, b_perp = a - uw * (uw @ a) / (uw @ uw), b - uw * (uw @ b) / (uw @ uw)
    floor = scale.speed_of(max(STEER_FLOOR, STEER_NOISE * math.sqrt(a.size)))
    fit = _fit(b_perp, a_perp)  # factor: observed turning over the map's
    if max(fit.rms_a, fit.rms_b) < floor or fit.agrees(STEER_SLOPE[0], STEER_SLOPE[1], 0.5):
        return None
    idx = np.flatnonzero(moving)
    j = idx[fit.worst]
    return Finding("steering", name, float(t[i0[idx[0]]]), float(t[i1[idx[-1]]]),
                   f"the tractor turns {_ratio(fit.factor)} times as much as the steering "
                   f"map of {vehicle.name} gives for it (heading rate times L1 against speed "
                   f"times tan(delta), correlation {fit.corr:.2f}; worst over t = "
                   f"{t[i0[j]]:.2f} to {t[i1[j]]:.2f} s)",
                   explain(1.0 / fit.factor if fit.factor else 0.0, "delta_h", ctx))


def check_hitch(t: np.ndarray, df: pd.DataFrame, vehicle, ctx: Context,
                scale: LogScale = FULL_SIZE) -> Finding | None:
    """Both units' sensors must put the hitch at one point.

    The hitch sits at ``a`` in the tractor sensor's frame and ``b`` in the
    semitrailer sensor's: ``p_1 + R(psi_1) a = p_2 + R(psi_2) b`` at every
    sample, a linear least-squares problem in ``(a, b)``. Its residual is the
    check; with a vehicle, ``a`` and ``b`` also come from its file.
    """
    step = max(1, t.size // 4000)
    sl = slice(None, None, step)
    p1 = np.column_stack([df["x_1"].to_numpy(float)[sl], df["y_1"].to_numpy(float)[sl]])
    p2 = np.column_stack([df["x_2"].to_numpy(float)[sl], df["y_2"].to_numpy(float)[sl]])
    c1, s1 = np.cos(df["psi_1"].to_numpy(float)[sl]), np.sin(df["psi_1"].to_numpy(float)[sl])
    c2, s2 = np.cos(df["psi_2"].to_numpy(float)[sl]), np.sin(df["psi_2"].to_numpy(float)[sl])
    ts = t[sl]
    n = ts.size
    A = np.zeros((2 * n, 4))
    A[0::2, 0], A[0::2, 1], A[1::2, 0], A[1::2, 1] = c1, -s1, s1, c1
    A[0::2, 2], A[0::2, 3], A[1::2, 2], A[1::2, 3] = -c2, s2, -s2, -c2
    rhs = (p2 - p1).reshape(-1)
    if not np.all(np.isfinite(A)) or not np.all(np.isfinite(rhs)):
        return None
    sol, *_ = np.linalg.lstsq(A, rhs, rcond=1e-9)
    candidates = [("fitted", sol, scale.distance(HITCH_RMS))]
    if vehicle is not None:
        xs1, ys1, _ = vehicle.sensor1
        xs2, ys2, _ = vehicle.sensor2
        candidates.append(("vehicle", np.array([vehicle.L1c - xs1, -ys1, -xs2, -ys2]),
                           scale.distance(HITCH_RMS_VEHICLE)))
    for kind, geom, limit in candidates:
        res = (A @ geom - rhs).reshape(-1, 2)
        dist = np.hypot(res[:, 0], res[:, 1])
        rms = float(np.sqrt(np.mean(dist ** 2)))
        if rms <= limit:
            continue
        k = int(np.argmax(dist))
        if kind == "fitted":
            cause = ("the semitrailer's channels do not describe a unit hitched to the "
                     "tractor: another time base, frame or heading sense on one unit")
            what = "fitted best"
        else:
            cause = (f"the log's sensors are not where {vehicle.name}'s file puts them "
                     "(sensor positions, L1c): the wrong vehicle file for this log")
            what = f"placed by {vehicle.name}'s sensor positions and L1c"
        return Finding("hitch", "x_2, y_2, psi_2 against x_1, y_1, psi_1", float(ts[0]),
                       float(ts[-1]), f"with the hitch {what}, the two units' sensors put it "
                       f"{rms:.3g} m apart (RMS; {dist[k]:.3g} m at t = {ts[k]:.2f} s)", cause)
    return None


def _default_vehicle(vehicle):
    if vehicle is None:
        return _preset(DEFAULT_PRESET)
    return vehicle


DEFAULT_PRESET = "gosar2022-unloaded"
"""The vehicle whose steering map and geometry the checks use when given none."""


def _preset(name: str):
    """The preset ``name``, read again only when its file changes.

    Five checks per log ask for it, and reading it costs a tenth of importing
    a log. The object is only read by the checks here.
    """
    st = resolve_vehicle_path(name).stat()
    return _preset_as_of(name, st.st_mtime_ns, st.st_size)


@functools.lru_cache(maxsize=4)
def _preset_as_of(name: str, mtime_ns: int, size: int):
    return load_vehicle(name)


def _pose_names(i: int, ctx: Context) -> str:
    if f"x_{i}" in ctx.names:
        return ", ".join(dict.fromkeys(ctx.name(c) for c in (f"x_{i}", f"y_{i}", f"psi_{i}")
                                       if c in ctx.names))
    return f"x_{i}, y_{i}, psi_{i}"


def _point(df: pd.DataFrame, i: int, at: tuple[float, float], sensor) -> tuple[np.ndarray,
                                                                              np.ndarray]:
    """Where a point of unit ``i`` (``at`` in the unit's frame) is, from its sensor's track."""
    psi = df[f"psi_{i}"].to_numpy(float)
    dx, dy = at[0] - sensor[0], at[1] - sensor[1]
    c, s_ = np.cos(psi), np.sin(psi)
    return (df[f"x_{i}"].to_numpy(float) + c * dx - s_ * dy,
            df[f"y_{i}"].to_numpy(float) + s_ * dx + c * dy)


def check_turning(t: np.ndarray, df: pd.DataFrame, i: int, vehicle, ctx: Context,
                  scale: LogScale = FULL_SIZE) -> Finding | None:
    """Unit ``i`` turns no tighter than its geometry allows (see the module docstring).

    Judged on the sensor's own track (the positions as logged, no offset in
    another unit added): the tractor's drive axle turns on a radius of at least
    ``R = L1 / tan(delta_max)``, so its sensor, ``(x_s, y_s)`` from the axle, on
    one of at least ``R - |y_s|``; the semitrailer's axle may turn on the spot,
    so its sensor, ``d`` ahead of the axle, on a radius of at least ``|d|`` (not
    judged within half a metre of the axle). Summed over the :data:`YAW_WINDOW`
    windows that turn by more than :data:`TURN_WINDOW_MIN`.
    """
    v = _default_vehicle(vehicle)
    if i == 1:
        radius = v.L1 / math.tan(v.steering.delta_max) - abs(v.sensor1[1])
        limit = (f"a radius of {radius:.3g} m at its sensor: L1 / tan(delta_max) with "
                 f"L1 = {v.L1:g} m, delta_max = {math.degrees(v.steering.delta_max):.0f} deg")
    else:
        radius = abs(v.sensor2[0] + v.L2)
        limit = (f"a radius of {radius:.3g} m at its sensor, {radius:.3g} m from its axle, "
                 "about which it may turn on the spot")
    if radius < scale.distance(0.5):
        return None
    i0, i1 = _windows(t, YAW_WINDOW)
    if not i0.size:
        return None
    psi = df[f"psi_{i}"].to_numpy(float)
    x, y = df[f"x_{i}"].to_numpy(float), df[f"y_{i}"].to_numpy(float)
    path = np.cumsum(np.concatenate([[0.0], np.hypot(np.diff(x), np.diff(y))]))
    turn = np.abs(psi[i1] - psi[i0])
    use = turn > TURN_WINDOW_MIN
    turned = float(turn[use].sum())
    if turned < max(YAW_FLOOR, 4.0 * YAW_NOISE * math.sqrt(max(1, int(use.sum())))):
        return None
    travelled = float((path[i1] - path[i0])[use].sum())
    most = travelled / radius
    if turned <= TURN_MARGIN * most:
        return None
    factor = turned / most if most > 0 else math.inf
    unit = "tractor" if i == 1 else "semitrailer"
    return Finding("turning", _pose_names(i, ctx), float(t[i0[use][0]]), float(t[i1[use][-1]]),
                   f"the {unit} turns {turned:.3g} rad while its sensor travels "
                   f"{travelled:.3g} m, {_ratio(factor)} times tighter than its geometry "
                   f"allows ({limit} of {v.name})",
                   f"the positions look at least {_ratio(factor)} times too small "
                   "(millimetres or centimetres declared as metres), or the heading as many "
                   "times too large (degrees declared as radians): declare their units")


_AXES_MIRRORS = (("y (or latitude) with its sign flipped", (1.0, 0.0, 0.0, -1.0)),
                 ("x (or longitude) with its sign flipped", (-1.0, 0.0, 0.0, 1.0)),
                 ("latitude and longitude (or x and y) swapped", (0.0, 1.0, 1.0, 0.0)))
"""The mirrored tracks the axes check names: (what, the matrix ``(a, b, c, d)`` that undoes it)."""


def check_axes(t: np.ndarray, df: pd.DataFrame, i: int, vehicle, ctx: Context,
               scale: LogScale = FULL_SIZE) -> Finding | None:
    """Unit ``i``'s axle travels along its heading, forwards or backwards (module docstring).

    The angle between the axle's travel over :data:`VELOCITY_WINDOW` windows and
    the heading, its median over the windows that travel, is judged against
    :data:`AXES_TOL`; beyond :data:`AXES_SLIP`, the track is also mirrored
    (each of :data:`_AXES_MIRRORS` undone), and one that fits twice as well is
    named.
    """
    v = _default_vehicle(vehicle)
    axle = (0.0, 0.0) if i == 1 else (-v.L2, 0.0)
    sensor = v.sensor1 if i == 1 else v.sensor2
    psi = df[f"psi_{i}"].to_numpy(float)
    xs, ys = df[f"x_{i}"].to_numpy(float), df[f"y_{i}"].to_numpy(float)
    i0, i1 = _windows(t, VELOCITY_WINDOW)
    if not i0.size:
        return None

    def off(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x, y = _point(pd.DataFrame({f"x_{i}": x, f"y_{i}": y, f"psi_{i}": psi}), i, axle,
                      sensor)
        dx, dy = x[i1] - x[i0], y[i1] - y[i0]
        use = np.hypot(dx, dy) >= scale.distance(VELOCITY_MIN_STEP)
        mid = 0.5 * (psi[i0] + psi[i1])
        return _fold(np.arctan2(dy, dx) - mid), use

    angle, use = off(xs, ys)
    if use.sum() < 3:
        return None
    med = float(np.median(angle[use]))
    if med <= AXES_SLIP:
        return None
    undone = []
    for what, (a, b, c, d) in _AXES_MIRRORS:
        m_angle, m_use = off(a * xs + b * ys, c * xs + d * ys)
        both = use & m_use
        if both.sum() >= 3:
            undone.append((float(np.median(m_angle[both])), what))
    best = min(undone) if undone else (math.inf, "")
    if med <= AXES_TOL and not best[0] < 0.5 * med:
        return None
    idx = np.flatnonzero(use)
    j = idx[int(np.argmax(angle[use]))]
    unit, where = ("tractor", "drive axle") if i == 1 else ("semitrailer", "axle")
    mirrored = (f"; with {best[1].split(' (')[0]} undone, {math.degrees(best[0]):.1f} deg"
                if best[0] < 0.5 * med else "")
    cause = (f"{best[1]} (a mirrored track): fix the axes at their source"
             if best[0] < 0.5 * med else
             "latitude and longitude (or x and y) swapped, or one of them with the wrong "
             "sign (a mirrored track), or a heading that is not counter-clockwise from x: "
             "fix the axes at their source")
    return Finding("axes", _pose_names(i, ctx), float(t[i0[idx[0]]]), float(t[i1[idx[-1]]]),
                   f"the {unit}'s {where} travels {math.degrees(med):.1f} deg (median over "
                   f"{idx.size} windows of {VELOCITY_WINDOW:g} s; worst over t = "
                   f"{t[i0[j]]:.2f} to {t[i1[j]]:.2f} s) off the direction its heading "
                   f"points, where it can only roll along it{mirrored}", cause)


def _fold(a: np.ndarray) -> np.ndarray:
    """``|a|`` wrapped to [0, pi/2]: an angle to a line, travelled either way."""
    a = np.abs(np.angle(np.exp(1j * a)))
    return np.minimum(a, math.pi - a)


def check_articulation(t: np.ndarray, df: pd.DataFrame, vehicle, ctx: Context,
                       scale: LogScale = FULL_SIZE, tracked: int = 1) -> Finding | None:
    """``gamma`` against the derived unit's kinematics: its sign and scale (module doc).

    With ``tracked = 1`` (the semitrailer derived), the kinematic trailer
    equation driven by the tractor's speed ``u_1 = v_x_1`` and yaw rate; with
    ``tracked = 2`` (the tractor derived), the tractor's drive axle rolling
    along its heading, from the semitrailer's velocity and yaw rate. ``L1c``
    and ``L2`` are the vehicle's (``gosar2022-unloaded``'s without one). The
    sign is told by the yaw-rate term, so a log that barely turns passes.
    """
    vehicle = _default_vehicle(vehicle)
    i0, i1 = _windows(t, YAW_WINDOW)
    if i0.size < 3:
        return None
    g = np.unwrap(df["gamma"].to_numpy(float))
    L1c, L2 = vehicle.L1c, vehicle.L2
    if tracked == 1:
        # gamma' + u_1 sin(gamma) / L2 = r_1 (1 - L1c cos(gamma) / L2)
        r1, u1 = df["r_1"].to_numpy(float), df["v_x_1"].to_numpy(float)
        even = _cumtrapz(t, r1 * (1.0 - L1c * np.cos(g) / L2))
        odd = _cumtrapz(t, u1 * np.sin(g) / L2) + g
        driven = "the tractor's speed and yaw rate"
    else:
        # (u_K sin(gamma) + L1c gamma') / L2 = (v_K cos(gamma) - r_2 L1c) / L2, the kingpin's
        # velocity (u_K, v_K) in the semitrailer's axes from its sensor's
        s2x, s2y = vehicle.sensor2[0], vehicle.sensor2[1]
        r2 = df["r_2"].to_numpy(float)
        uk = df["v_x_2"].to_numpy(float) + r2 * s2y
        vk = df["v_y_2"].to_numpy(float) - r2 * s2x
        even = _cumtrapz(t, (vk * np.cos(g) - r2 * L1c) / L2)
        odd = _cumtrapz(t, uk * np.sin(g) / L2) + g * L1c / L2
        driven = "the semitrailer's speed and yaw rate"
    a, b = even[i1] - even[i0], odd[i1] - odd[i0]
    if math.sqrt(float(np.mean(a * a))) < ARTICULATION_FLOOR:
        return None
    logged = float(np.sqrt(np.mean((b - a) ** 2)))
    mirror = float(np.sqrt(np.mean((b + a) ** 2)))
    name = ctx.name("gamma")
    what = (f"with L1c = {vehicle.L1c:g} m and L2 = {vehicle.L2:g} m of {vehicle.name}")
    equation = ("the kinematic trailer equation" if tracked == 1
                else "the tractor's drive axle rolling along its heading")
    if mirror < ARTICULATION_MIRROR * logged:
        return Finding("articulation", name, float(t[i0[0]]), float(t[i1[-1]]),
                       f"its change over {YAW_WINDOW:g} s windows follows {equation} driven by "
                       f"{driven} with the opposite sign (RMS misfit {logged:.3g} rad as "
                       f"logged, {mirror:.3g} rad mirrored, {what})",
                       f"{name} (the articulation angle gamma) likely has its sign flipped: "
                       "gamma is tractor yaw minus semitrailer yaw, psi_1 - psi_2; flip it "
                       "(scale = -1 in a channel map)")
    k = float(a @ b) / float(a @ a)  # the odd terms' factor on the even ones: 1 if right
    scaled = float(np.sqrt(np.mean((b - k * a) ** 2)))
    if ARTICULATION_SCALE[0] <= abs(k) <= ARTICULATION_SCALE[1] or k <= 0.0 \
            or scaled >= ARTICULATION_MIRROR * logged:
        return None
    # gamma scaled by c scales the odd terms by about c: gamma is k times what it should be
    return Finding("articulation", name, float(t[i0[0]]), float(t[i1[-1]]),
                   f"its terms in {equation} driven by {driven} come out {_ratio(k)} times "
                   f"what the yaw-rate term needs (RMS misfit {logged:.3g} rad as logged, "
                   f"{scaled:.3g} rad scaled by {_ratio(1.0 / k)}, {what})",
                   explain(k, "gamma", ctx) + "; declare its unit in the channel map")


def check_articulation_offset(t: np.ndarray, df: pd.DataFrame, vehicle,
                              ctx: Context) -> Finding | None:
    """A measured ``gamma`` against both measured headings: ``gamma = psi_1 - psi_2``.

    The sensors' mounting yaws (``sensor_yaw`` of each unit in the vehicle file) turn
    each heading; what is left is noise about zero. Its median beyond
    :data:`ARTICULATION_OFFSET` is an offset of the articulation (or of one heading).
    """
    mount = 0.0 if vehicle is None else vehicle.sensor1_yaw - vehicle.sensor2_yaw
    d = np.angle(np.exp(1j * (df["gamma"].to_numpy(float) - df["psi_1"].to_numpy(float)
                              + df["psi_2"].to_numpy(float) + mount)))
    if not d.size or not np.all(np.isfinite(d)):
        return None
    off = float(np.median(d))
    if abs(off) <= ARTICULATION_OFFSET:
        return None
    spread = float(np.median(np.abs(d - off)))
    name = ctx.name("gamma")
    return Finding("articulation", name, float(t[0]), float(t[-1]),
                   f"it differs from the headings' difference psi_1 - psi_2 by "
                   f"{math.degrees(off):.3g} deg (median over the log, spread "
                   f"{math.degrees(spread):.2g} deg; at most "
                   f"{math.degrees(ARTICULATION_OFFSET):g} deg expected)",
                   f"{name} (the articulation angle gamma) has an offset: the hitch sensor's "
                   "zero, or a heading sensor's mounting yaw not declared (sensor_yaw in the "
                   "vehicle file); give its offset in the channel map")


def check_metadata(frame: pd.DataFrame, meta: Mapping) -> Finding | None:
    """The direction the metadata states, or its manoeuvre implies, against the motion.

    Parameters
    ----------
    frame : DataFrame
        A log in the signal schema.
    meta : mapping
        Its metadata: ``direction`` and ``manoeuvre`` are judged when present.
    """
    t = frame["t"].to_numpy(float)
    v = frame["v_x_1"].to_numpy(float)
    total = float(np.trapezoid(np.abs(v), t)) if t.size > 1 else 0.0
    if total <= 0.0:
        return None
    back = float(np.trapezoid(np.abs(v) * (v < 0), t)) / total
    stated = []
    if meta.get("direction") in ("forward", "reverse"):
        stated.append((str(meta["direction"]), f"direction {meta['direction']!r}"))
    kind = meta.get("manoeuvre")
    if isinstance(kind, str) and kind:
        implied = "reverse" if kind in REVERSE_KINDS or kind.endswith("reverse") else "forward"
        stated.append((implied, f"manoeuvre {kind!r} (which drives {implied})"))
    for direction, what in stated:
        share = back if direction == "reverse" else 1.0 - back
        if share < METADATA_SHARE:
            return Finding("metadata", "v_x_1", float(t[0]), float(t[-1]),
                           f"its metadata says {what}, but the tractor covers only "
                           f"{100.0 * share:.0f} % of its {total:.3g} m in that direction "
                           f"(at least {100.0 * METADATA_SHARE:.0f} % expected)",
                           "the metadata belongs to another log, or the log's v_x_1 sign is "
                           "flipped; correct the metadata (direction, manoeuvre) or the log")
    return None


# ------------------------------------------------------------------ entry points
def findings(frame: pd.DataFrame, vehicle=None, ctx: Context = CANONICAL,
             only: Collection[str] | None = None, derived: bool = False,
             tracked: int | None = None) -> Iterator[Finding]:
    """Every check's finding on a frame that passed ``check_frame``, lazily, in check order.

    Per unit, the turning radius comes after the yaw rate (which names a
    heading in degrees) and before the velocity (positions in too small a unit
    would otherwise be named as a velocity in too large a one), the
    velocity's sign and scale are judged before the axes and the track's
    curvature (a flipped velocity also turns the sideslip the curvature
    check uses) and its direction after them (a mirrored track is named as
    such rather than as a heading off by some angle). The articulation comes
    before the steering, which a derived tractor's wrong sign would upset.

    Parameters
    ----------
    frame : DataFrame
        A log in the signal schema.
    vehicle : Vehicle, optional
        For the steering map and the hitch geometry; without one the steering
        check uses the ``gosar2022-unloaded`` preset's map (its bounds are wide
        enough for any tractor) and the hitch is only fitted.
    ctx : Context
        Names and units of the source, for the messages.
    only : collection of str, optional
        Run only these checks.
    derived : bool
        Whether one unit's channels were derived from the other's and
        ``gamma``: the ``articulation`` check runs on such logs.
    tracked : int, optional
        The unit measured when the other is derived (1 by default with
        ``derived``): the ``turning`` and ``axes`` checks judge the measured
        units only (a derived unit's are the articulation check's).
    """
    t = frame["t"].to_numpy(dtype=float)
    run = set(CHECKS) if only is None else set(only)
    sc = LogScale.of(vehicle)
    if derived and tracked is None:
        tracked = 1
    measured = (1, 2) if tracked is None else (tracked,)
    if "gap" in run and (f := check_gap(t)) is not None:
        yield f
    for i in (1, 2):
        if "yaw-rate" in run and (f := check_yaw(t, frame, i, ctx, sc)) is not None:
            yield f
        if i in measured and "turning" in run and (
                f := check_turning(t, frame, i, vehicle, ctx, sc)) is not None:
            yield f
        vel = check_velocity(t, frame, i, ctx, sc) if "velocity" in run else None
        if vel is not None and not vel.direction:
            yield vel.finding
        if i in measured and "axes" in run and (
                f := check_axes(t, frame, i, vehicle, ctx, sc)) is not None:
            yield f
        curv = check_curvature(t, frame, i, ctx, sc) if "curvature" in run else None
        if curv is not None:
            yield curv
        if vel is not None and vel.direction and curv is None:
            yield vel.finding
        if "jump" in run and (f := check_jump(t, frame, i, ctx, sc)) is not None:
            yield f
    if derived and "articulation" in run and (
            f := check_articulation(t, frame, vehicle, ctx, sc, tracked or 1)) is not None:
        yield f
    if not derived and "articulation" in run and (
            f := check_articulation_offset(t, frame, vehicle, ctx)) is not None:
        yield f
    if "steering" in run:
        steer_vehicle = vehicle
        if steer_vehicle is None:
            steer_vehicle = _preset(DEFAULT_PRESET)
        if (f := check_steering(t, frame, steer_vehicle, ctx, sc)) is not None:
            yield f
    if "hitch" in run and (f := check_hitch(t, frame, vehicle, ctx, sc)) is not None:
        yield f


def parse_accept(values: Collection[str] | None) -> tuple[str, ...]:
    """Check names given to ``--accept`` (comma-separated or repeated), validated.

    Raises
    ------
    ValueError
        For an unknown name, listing the known ones.
    """
    names: list[str] = []
    for v in values or ():
        names += [n.strip() for n in str(v).split(",") if n.strip()]
    unknown = [n for n in names if n not in CHECKS]
    if unknown:
        raise UserError(f"--accept {', '.join(unknown)}: unknown check; the checks are "
                         f"{', '.join(CHECKS)}")
    return tuple(dict.fromkeys(names))


def check_log(frame: pd.DataFrame, source: str, vehicle=None, accept: Collection[str] = (),
              ctx: Context = CANONICAL, derived: bool = False, tracked: int | None = None,
              meta: Mapping | None = None) -> list[str]:
    """Run every check; refuse the first finding not accepted.

    Parameters
    ----------
    frame : DataFrame
        A log in the signal schema that passed :func:`check_frame`.
    source : str
        File, for the messages.
    vehicle : Vehicle, optional
        See :func:`findings`.
    accept : collection of str
        Checks whose findings are accepted knowingly (``--accept``).
    ctx : Context
        Names and units of the source.
    derived, tracked : bool, int
        See :func:`findings`.
    meta : mapping, optional
        The run's metadata, for the ``metadata`` check.

    Returns
    -------
    list of str
        The accepted findings' messages, for the run's metadata
        (``meta["accepted_checks"]``).

    Raises
    ------
    LogError
        The first finding whose check is not in ``accept``.
    """
    accepted = []
    found = findings(frame, vehicle, ctx, derived=derived, tracked=tracked)
    if meta is not None and (f := check_metadata(frame, meta)) is not None:
        found = itertools.chain([f], found)
    for f in found:
        if f.check not in accept:
            raise LogError(f.message(source))
        accepted.append(f"accepted {f.check}: {f.message(source)}")
    return accepted


def accepted_in(meta: Mapping) -> tuple[str, ...]:
    """The checks a run's metadata records as accepted (``--accept`` at import).

    From ``meta["accepted"]``, and from the ``"accepted CHECK: ..."`` lines of
    ``meta["accepted_checks"]`` that runs imported before it was written carry.
    """
    names = [str(n) for n in meta.get("accepted", []) if str(n) in CHECKS]
    for line in meta.get("accepted_checks", []):
        head = str(line).split(":", 1)[0].removeprefix("accepted ").strip()
        if head in CHECKS:
            names.append(head)
    return tuple(dict.fromkeys(names))
