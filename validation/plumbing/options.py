"""Command-line option types: every number finite and in range, every mistake one line.

``argparse`` calls these as ``type=`` converters; a ``ValueError`` (here an
:class:`argparse.ArgumentTypeError`) becomes ``artic: error: argument --X: ...``
and exit code 2. The ranges are what a yard manoeuvre and this machine can
take, not what the code happens to survive.
"""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Callable
from pathlib import Path

from artic.mjcf.errors import UserError

BYTES_PER_SAMPLE = 1024
"""Memory a simulated sample needs at its peak [B]: inputs, the model's outputs, the run's
frame and its Parquet copy, about 70 float64 values, with a margin of two."""

MEMORY_SHARE = 0.5
"""Largest share of the available memory one run may plan to use."""


def number(lo: float, hi: float, *, unit: str = "", lo_open: bool = False,
           integer: bool = False) -> Callable[[str], float]:
    """A converter for a finite number in ``[lo, hi]`` (``(lo, hi]`` with ``lo_open``).

    Parameters
    ----------
    lo, hi : float
        Bounds, inclusive unless ``lo_open``.
    unit : str
        Shown in the message.
    integer : bool
        Require an integer.
    """
    left = "(" if lo_open else "["
    shown = f" [{unit}]" if unit else ""

    def convert(text: str) -> float:
        try:
            x = int(text) if integer else float(text)
        except ValueError:
            kind = "an integer" if integer else "a number"
            raise argparse.ArgumentTypeError(f"expected {kind}{shown}, got {text!r}") from None
        if not math.isfinite(x):
            raise argparse.ArgumentTypeError(f"expected a finite number{shown}, got {text!r}")
        if x < lo or x > hi or (lo_open and x == lo):
            bounds = f"{int(lo)}, {int(hi)}" if integer else f"{lo:g}, {hi:g}"
            raise argparse.ArgumentTypeError(f"{text} is outside {left}{bounds}]{shown}")
        return x

    return convert


def output_path(text: str) -> Path:
    """An output file or folder: refuses an empty one.

    ``Path("")`` is the current folder, so an empty ``--out-dir ""`` (an unset shell
    variable) would otherwise write there.
    """
    if not text.strip():
        raise argparse.ArgumentTypeError("no path given; name a folder or file")
    return Path(text)


SPEED_KPH = number(0.0, 60.0, unit="km/h", lo_open=True)
"""Manoeuvre speed: positive (the manoeuvre sets the direction), at most 60 km/h."""

AMPLITUDE_DEG = number(-1080.0, 1080.0, unit="deg")
"""Steering-wheel amplitude: at most three turns either way."""

DURATION = number(0.0, 86400.0, unit="s", lo_open=True)
"""Simulated time: positive, at most a day (the memory it needs is checked apart)."""

GAIN = number(0.0, 100.0, unit="rad/rad")
"""Reversing feedback gain K."""

JOBS = number(1, 1024, integer=True)
"""Processes or threads."""

SEED = number(0, 2 ** 63 - 1, integer=True)
"""Random seed (numpy wants it non-negative)."""

SEEDS = number(1, 1000, integer=True)
"""Trucks of a campaign (``--seeds``): one campaign of about 90 s each."""

TIMEOUT = number(0.0, 3600.0, unit="s", lo_open=True)
"""A network timeout."""


def add_executor_options(parser: argparse.ArgumentParser, what: str) -> None:
    """``--executor``, ``--scheduler`` and the Dask security options, as every command words them.

    Parameters
    ----------
    parser : ArgumentParser
        The command's parser.
    what : str
        What runs on the executor, for ``--executor``'s help (e.g. "a sweep's runs").
    """
    from pathlib import Path

    parser.add_argument("--executor", choices=("local", "dask"), default="local",
                        help=f"where {what} run: this machine's --jobs processes, or a Dask "
                             "cluster (default: %(default)s)")
    parser.add_argument("--scheduler", default=None,
                        help="with --executor dask: a running scheduler, tcp://HOST:PORT or "
                             "tls://HOST:PORT; a local cluster of --jobs workers otherwise. The "
                             "cluster must be trusted: its results are unpickled here")
    parser.add_argument("--scheduler-timeout", type=TIMEOUT, default=10.0,
                        help="seconds to wait for the scheduler (default: %(default)s)")
    parser.add_argument("--tls-ca-file", type=Path, default=None,
                        help="with a tls:// scheduler: the CA certificate (PEM)")
    parser.add_argument("--tls-cert", type=Path, default=None,
                        help="with a tls:// scheduler: this client's certificate (PEM)")
    parser.add_argument("--tls-key", type=Path, default=None,
                        help="with a tls:// scheduler: this client's private key (PEM)")


def available_memory() -> int:
    """Memory available to a new allocation now [B] (``MemAvailable`` on Linux)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return 2 ** 63


def check_memory(samples: int, what: str, rate: float = 100.0) -> None:
    """Refuse a run whose estimated memory exceeds :data:`MEMORY_SHARE` of what is available.

    Parameters
    ----------
    samples : int
        Samples the run will hold.
    what : str
        The option that sets its length, for the message.
    rate : float
        Sample rate [Hz], for the message.

    Raises
    ------
    ValueError
        With the estimate, the memory available and the longest run that fits.
    """
    need = float(samples) * BYTES_PER_SAMPLE
    have = available_memory()
    if need > MEMORY_SHARE * have:
        longest = MEMORY_SHARE * have / BYTES_PER_SAMPLE / rate
        raise UserError(f"{what}: {samples:.3g} samples at {rate:g} Hz need about "
                         f"{need / 2 ** 30:.3g} GiB of memory, and {have / 2 ** 30:.3g} GiB "
                         f"are available; make it at most {longest:.0f} s of simulated time")
