"""Open-loop manoeuvres: steering-wheel and speed profiles of the paper's test matrix.

Each profile gives, per sample at 100 Hz, the steering-wheel angle
``delta_h`` [rad] (offset included) and the tractor speed ``u1`` [m/s]. The
amplitude is a steering-wheel angle, as in the paper (200, 360, 500 deg forward;
30 and 90 deg in reverse). ``side="left"`` steers to positive angles.

Beyond the paper's kinds, ``swept-sine``: a forward sine of the steering wheel
whose frequency rises exponentially from :data:`SWEEP_F0` to :data:`SWEEP_F1`
over :data:`SWEEP_TIME`, faded in over :data:`RAMP_TIME` and followed by
:data:`SWEEP_REST` of straight steering, for the frequency response
(:mod:`artic.validation.review.frequency`).
"""

from __future__ import annotations

import math

import numpy as np

from artic.mjcf.errors import UserError
from artic.validation.logs.profile import Profile

KINDS = ("straight", "constant-steer", "slalom", "figure-8", "ramp-steer-reverse", "swept-sine")

DT = 0.01
"""Sample period of every profile [s]: 100 Hz, as the paper's INS."""

RAMP_TIME = 3.0
"""Time to turn the steering wheel to its amplitude [s]."""

SLALOM_PITCH = 12.0
"""Distance between slalom cones [m]."""

SWEEP_F0, SWEEP_F1 = 0.05, 0.8
"""The swept sine's first and last frequency [Hz]: from below the semitrailer's
articulation lag at walking pace (its time constant, about its wheelbase over the
speed, is 3 s at 10 km/h: 0.05 Hz) to a steering-wheel rate of 450 deg/s at
90 deg of amplitude, about what a driver turns."""

SWEEP_TIME = 60.0
"""The sweep's length [s]: 15 s per octave, one period in the lowest and nine in the highest."""

SWEEP_REST = 5.0
"""Straight steering after the sweep [s], so the responses settle inside the record."""


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _circle_time(amp: float, u: float, L1: float, i_s: float) -> float:
    """Time to drive one steady circle at steering-wheel amplitude ``amp`` [deg] [s]."""
    return 2.0 * math.pi * L1 / max(math.tan(abs(math.radians(amp)) / i_s), 1e-3) / u


def swept_sine(t: np.ndarray) -> np.ndarray:
    """The unit sweep [-] at times ``t`` [s], 0 after :data:`SWEEP_TIME`.

    ``sin`` of a phase whose rate rises exponentially from :data:`SWEEP_F0` to
    :data:`SWEEP_F1`; it ends at a zero of the sine, so the steering returns to
    straight without a step.
    """
    k = math.log(SWEEP_F1 / SWEEP_F0) / SWEEP_TIME
    phase = 2.0 * math.pi * SWEEP_F0 * np.expm1(k * np.minimum(t, SWEEP_TIME)) / k
    end = 2.0 * math.pi * SWEEP_F0 * math.expm1(k * SWEEP_TIME) / k
    last_zero = math.floor(end / math.pi) * math.pi
    return np.where(phase < last_zero, np.sin(phase), 0.0)


def default_duration(kind: str, amplitude_deg: float, speed_kph: float, L1: float = 3.8,
                     i_s: float = 21.0) -> float:
    """Length of a manoeuvre when none is given: one that completes it [s]."""
    u = speed_kph / 3.6
    return {"straight": 30.0, "constant-steer": 60.0, "slalom": 6.0 * SLALOM_PITCH / u,
            "figure-8": 2.0 * _circle_time(amplitude_deg, u, L1, i_s) + 3.0 * RAMP_TIME,
            "ramp-steer-reverse": 60.0, "swept-sine": SWEEP_TIME + SWEEP_REST}[kind]


def make_profile(kind: str, *, amplitude_deg: float | None = None, speed_kph: float | None = None,
                 side: str = "left", duration: float | None = None,
                 delta_h_offset: float = 0.0, L1: float = 3.8, i_s: float = 21.0) -> Profile:
    """Build the inputs of a manoeuvre.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.
    amplitude_deg : float, optional
        Steering-wheel amplitude [deg]; default 200 forward, 90 in reverse.
    speed_kph : float, optional
        Speed [km/h], positive; default 5 forward, 3 in reverse.
    side : str
        ``"left"`` or ``"right"``.
    duration : float, optional
        Length [s]; a default that completes the manoeuvre otherwise.
    delta_h_offset : float
        Steering-wheel angle while driving straight [rad], added to the profile.
    L1, i_s : float
        Wheelbase [m] and steering ratio [-], to size a figure-8's circles.

    Raises
    ------
    ValueError
        For an unknown kind or side, or a non-positive speed or duration.

    See Also
    --------
    artic.Profile : what it returns.
    artic.simulate : drive a model through it.

    Examples
    --------
    >>> import artic
    >>> profile = artic.make_profile("constant-steer", amplitude_deg=90, speed_kph=5,
    ...                              duration=8.0)
    >>> profile.t.size, profile.meta["direction"]  # 100 Hz for 8 s
    (801, 'forward')
    """
    if kind not in KINDS:
        raise UserError(f"unknown manoeuvre {kind!r}; choose one of {', '.join(KINDS)}")
    if side not in ("left", "right"):
        raise UserError(f"side must be 'left' or 'right', got {side!r}")
    reverse = kind.endswith("reverse")
    speed = (3.0 if reverse else 5.0) if speed_kph is None else float(speed_kph)
    amp = (90.0 if reverse else 200.0) if amplitude_deg is None else float(amplitude_deg)
    if speed <= 0:
        raise UserError(f"speed must be positive [km/h] (the direction follows the "
                         f"manoeuvre), got {speed}")
    if abs(amp) > 1080:
        raise UserError(f"amplitude {amp} deg is beyond three steering-wheel turns")
    u = speed / 3.6
    A = math.radians(amp) * (1.0 if side == "left" else -1.0)
    circle = _circle_time(amp, u, L1, i_s)
    T = default_duration(kind, amp, speed, L1, i_s) if duration is None else float(duration)
    if T <= 0:
        raise UserError(f"duration must be positive [s], got {T}")
    t = np.arange(0.0, T + 0.5 * DT, DT)
    if kind == "straight":
        d = np.zeros_like(t)
    elif kind == "constant-steer":
        d = A * _smoothstep((t - 2.0) / RAMP_TIME)
    elif kind == "slalom":
        period = 2.0 * SLALOM_PITCH / u
        d = A * np.sin(2.0 * math.pi * t / period) * _smoothstep(t / RAMP_TIME)
    elif kind == "figure-8":
        up = _smoothstep(t / RAMP_TIME)
        swap = _smoothstep((t - RAMP_TIME - circle) / (2 * RAMP_TIME))
        d = A * (up - 2.0 * swap)
    elif kind == "swept-sine":
        d = A * swept_sine(t) * _smoothstep(t / RAMP_TIME)
    else:  # ramp-steer-reverse: straight back, then a slow ramp to the amplitude
        d = A * np.clip((t - 5.0) / 20.0, 0.0, 1.0)
    u1 = np.full_like(t, -u if reverse else u)
    meta = {"manoeuvre": kind, "amplitude_deg": amp, "speed_kph": speed, "side": side,
            "direction": "reverse" if reverse else "forward", "duration": T}
    return Profile(kind, t, d + delta_h_offset, u1, meta)
