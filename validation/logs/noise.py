"""Declared sensor noise of a user's logs: its TOML table, and noise drawn from it.

A channel map (:mod:`artic.validation.logs.channelmap`) may carry a ``[noise]``
table, and ``artic validate --noise FILE.toml`` reads one from any TOML file (a
channel map, or a file with the table alone). It declares, per measured
channel, the noise of the sensor behind it:

.. code-block:: toml

    [noise]
    x_1 = { sigma = 0.01, tau = 5.0 }                    # [m], [s]: RTK position
    y_1 = { sigma = 0.01, tau = 5.0 }
    psi_1 = { sigma = 0.05, unit = "deg", tau = 10.0 }   # heading
    v_x_1 = { sigma = 0.01 }                             # [m/s], white
    v_y_1 = { sigma = 0.01 }
    r_1 = { sigma = 0.005, bias = 0.01, unit = "deg/s" } # white, and a constant per run

- ``sigma``: the standard deviation of the noise, in ``unit`` (default the
  channel's SI unit: m, rad, m/s, rad/s), >= 0;
- ``tau`` [s]: its correlation time, a first-order Gauss-Markov process
  (stationary, ``exp(-dt / tau)`` from one sample to the next); 0 or absent
  for white noise;
- ``bias``: the standard deviation of a constant offset drawn once per log
  (a gyro's turn-on bias), in ``unit``; 0 by default.

The channels are those the criteria compare: ``x_i``, ``y_i``, ``psi_i``,
``v_x_i``, ``v_y_i``, ``r_i`` (``i = 1`` the tractor's unit, ``2`` the
semitrailer's) and ``gamma``. Without a ``gamma`` entry the articulation is
the difference of the noisy headings, as a log without a hitch sensor derives
it; with one, the hitch sensor's own noise. A channel not declared is
noise-free.

:func:`add_noise` draws the declared noise onto a run, so that
:mod:`artic.validation.criteria.noisefloor` can score a perfect model's
output against itself measured through it.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.signal import lfilter

from artic.mjcf.interface import wrap_angle
from artic.mjcf.plausible import PlausibilityWarning
from artic.validation.logs.runfile import LogError
from artic.validation.logs.units import DIMENSION, UNITS

CHANNELS = (*(f"{c}_{i}" for i in (1, 2) for c in ("x", "y", "psi", "v_x", "v_y", "r")),
            "gamma")
"""The channels a declaration may name: those the criteria compare."""

KEYS = ("sigma", "tau", "bias", "unit")

META_KEY = "sensor_noise"
"""Where an imported log's metadata keeps its channel map's declaration (SI)."""


@dataclass(frozen=True)
class ChannelNoise:
    """The noise of one channel, SI.

    Attributes
    ----------
    sigma : float
        Standard deviation [channel's SI unit].
    tau : float
        Correlation time [s]; 0 for white noise.
    bias : float
        Standard deviation of a constant offset per log [channel's SI unit].
    """

    sigma: float
    tau: float = 0.0
    bias: float = 0.0


def _si_units(channel: str) -> list[str]:
    dim = DIMENSION[channel]
    return [u for u, (d, _) in UNITS.items()
            if d == dim and u not in ("quaternion", "latitude", "longitude")]


def parse_noise(table: object, where: str) -> dict[str, ChannelNoise]:
    """Check a ``[noise]`` table (see the module docstring) and make it SI.

    Parameters
    ----------
    table : object
        The table as TOML gives it.
    where : str
        The file, for messages.

    Returns
    -------
    dict of str to ChannelNoise
        Per channel declared.

    Raises
    ------
    LogError
        One line naming the file, the key and the fix.
    """
    if not isinstance(table, dict) or not table:
        raise LogError(f"{where}: [noise] must be a table of channels, such as "
                       "x_1 = { sigma = 0.01, tau = 5.0 }")
    out = {}
    for channel, spec in table.items():
        key = f"noise.{channel}"
        if channel not in CHANNELS:
            raise LogError(f"{where}: {key}: not a channel whose noise the criteria see; "
                           f"declare {', '.join(CHANNELS)}")
        if not isinstance(spec, dict) or "sigma" not in spec:
            raise LogError(f"{where}: {key}: give a table with sigma (and optionally tau, "
                           f"bias, unit), such as {channel} = {{ sigma = 0.01, tau = 5.0 }}")
        extra = sorted(set(spec) - set(KEYS))
        if extra:
            raise LogError(f"{where}: {key}: unknown key(s) {', '.join(extra)}; use "
                           f"{', '.join(KEYS)}")
        units = _si_units(channel)
        unit = str(spec.get("unit", units[0]))
        if unit not in units:
            raise LogError(f"{where}: {key}: unit {unit!r} is not a unit of "
                           f"{DIMENSION[channel]}; use one of {', '.join(units)}")
        values = {}
        for name in ("sigma", "tau", "bias"):
            v = spec.get(name, 0.0)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise LogError(f"{where}: {key}: {name} = {v!r}; give a finite number")
            if v < 0:
                what = "[s]" if name == "tau" else f"[{unit}]"
                raise LogError(f"{where}: {key}: {name} = {v!r}; a {name} {what} is >= 0")
            values[name] = float(v)
        factor = UNITS[unit][1]
        out[channel] = ChannelNoise(values["sigma"] * factor, values["tau"],
                                    values["bias"] * factor)
        for name in ("sigma", "bias"):
            _judge(where, key, name, values[name], unit, factor, DIMENSION[channel])
    return out


@dataclass(frozen=True)
class NoiseRange:
    """How large a declared noise of one dimension may be (SI).

    Attributes
    ----------
    usual : float
        The largest of the sensors of that kind; above it a warning.
    possible : float
        Above it no sensor of that kind measures anything a criterion could use: a
        unit mistake (degrees read as radians, millimetres as metres); refused.
    sensors : str
        The sensors and their accuracies the bounds rest on, for the messages.
    """

    usual: float
    possible: float
    sensors: str


NOISE_RANGES: dict[str, NoiseRange] = {
    "length": NoiseRange(0.5, 10.0, "RTK GNSS/INS 0.01-0.02 m, DGNSS 0.3-0.5 m, standalone "
                                    "GNSS 1-3 m"),
    "angle": NoiseRange(math.radians(2.0), math.radians(20.0),
                        "dual-antenna GNSS/INS heading 0.1-0.2 deg, hitch encoder 0.1 deg, "
                        "rear camera 1.25 deg"),
    "speed": NoiseRange(0.5, 5.0, "GNSS Doppler 0.02-0.05 m/s, wheel speed 0.1-0.3 m/s"),
    "rate": NoiseRange(math.radians(2.0), math.radians(30.0),
                       "automotive MEMS gyro 0.05-0.5 deg/s, turn-on bias up to 1 deg/s"),
}
"""Plausible and possible noise per dimension, from the datasheet accuracies of the sensors
a yard's tractor-semitrailer carries (the ``sensors`` of each). The possible bound is ten
times the usual or more: a noise above it would make every criterion measure the noise."""


def _judge(where: str, key: str, name: str, value: float, unit: str, factor: float,
           dimension: str) -> None:
    """Refuse a noise no sensor of ``dimension`` has; warn beyond the usual (see above)."""
    import warnings

    r = NOISE_RANGES[dimension]
    si = value * factor
    if si <= r.usual:
        return
    lo, hi = r.usual / factor, r.possible / factor
    if si > r.possible:
        raise LogError(f"{where}: {key}: {name} = {value:g} {unit} is beyond any sensor of its "
                       f"kind ({r.sensors}; refused above {hi:.3g} {unit}); check the value "
                       "and its unit (unit = \"deg\" for degrees)")
    warnings.warn(f"{where}: {key}: {name} = {value:g} {unit} is unusual: more than the usual "
                  f"{lo:.3g} {unit} ({r.sensors}); check it", PlausibilityWarning,
                  stacklevel=4)


def read_noise(path: Path) -> dict[str, ChannelNoise]:
    """The ``[noise]`` table of a TOML file (a channel map, or the table alone).

    Raises
    ------
    LogError
        For a file that cannot be read, has no ``[noise]`` table, or a bad one.
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError as exc:
        raise LogError(f"{path}: no such noise declaration") from exc
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise LogError(f"{path}: cannot read as TOML ({exc})") from exc
    if "noise" not in data:
        raise LogError(f"{path}: no [noise] table; declare each sensor's noise, such as "
                       "[noise] x_1 = { sigma = 0.01, tau = 5.0 }")
    return parse_noise(data["noise"], str(path))


def to_meta(noise: dict[str, ChannelNoise]) -> dict[str, dict[str, float]]:
    """A declaration as a run's metadata keeps it (SI, JSON)."""
    return {c: asdict(n) for c, n in noise.items()}


def from_meta(meta: dict) -> dict[str, ChannelNoise] | None:
    """The declaration an imported log's metadata carries (:data:`META_KEY`), or None."""
    got = meta.get(META_KEY)
    if not isinstance(got, dict) or not got:
        return None
    return parse_noise(got, f"log {meta.get('name', '')} (metadata {META_KEY})".strip())


def noise_sequence(rng: np.random.Generator, n: int, dt: float,
                   noise: ChannelNoise) -> np.ndarray:
    """One channel's noise over ``n`` samples ``dt`` [s] apart (SI).

    White for ``tau = 0``; otherwise the stationary first-order Gauss-Markov
    process ``x_k = a x_(k-1) + w_k``, ``a = exp(-dt / tau)``, ``w_k`` of
    standard deviation ``sigma sqrt(1 - a^2)``, ``x_0`` of ``sigma``; plus one
    constant draw of standard deviation ``bias``.
    """
    if noise.tau > 0.0:
        a = math.exp(-dt / noise.tau)
        w = rng.normal(0.0, noise.sigma * math.sqrt(1.0 - a * a), n)
        w[0] = rng.normal(0.0, noise.sigma)
        x = lfilter([1.0], [1.0, -a], w)
    else:
        x = rng.normal(0.0, noise.sigma, n)
    return x + rng.normal(0.0, noise.bias)


def add_noise(frame: pd.DataFrame, noise: dict[str, ChannelNoise],
              rng: np.random.Generator) -> pd.DataFrame:
    """``frame`` (the signal schema) measured through the declared noise.

    Channels in :data:`CHANNELS` order, each from ``rng`` in turn, so that one
    seed gives one answer. Without a ``gamma`` entry, ``gamma`` is the wrapped
    difference of the noisy headings whenever a heading is declared (see the
    module docstring).
    """
    out = frame.copy()
    t = frame["t"].to_numpy(dtype=float)
    n = len(t)
    if n < 2:
        return out
    dt = float(np.median(np.diff(t)))
    for c in CHANNELS:
        if c in noise:
            out[c] = frame[c].to_numpy(dtype=float) + noise_sequence(rng, n, dt, noise[c])
    if "gamma" not in noise and ("psi_1" in noise or "psi_2" in noise):
        out["gamma"] = wrap_angle(frame["gamma"].to_numpy(dtype=float)
                                  + (out["psi_1"] - frame["psi_1"]).to_numpy(dtype=float)
                                  - (out["psi_2"] - frame["psi_2"]).to_numpy(dtype=float))
    return out
