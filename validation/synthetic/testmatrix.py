"""The paper's test matrix (section 2.3), spread over both load conditions.

The paper's matrix, 58 manoeuvres. Forward, 25:

- constant steer at 200, 360 and 500 deg of steering wheel, 5 and 10 km/h,
  left and right: all 12 cells unloaded, and the same 12 loaded except
  500 deg at 10 km/h to the right (the paper ran 25 forward, not 26);
- a slalom at 5 km/h (200 deg, unloaded) and a figure-of-8 at 5 km/h
  (360 deg, loaded).

Reverse, 33 manoeuvres:

- ramp steer to 30 and 90 deg at 3 and 6 km/h, left and right, in both
  load conditions: 16; the driver stops before jackknife;
- docking, 9 (5 unloaded, 4 loaded), and parking, 8 (4 and 4), driven by
  :class:`artic.validation.synthetic.driver.DockingDriver` from seeded start poses. Parking
  starts further off line and at a larger angle than docking.

Tuning, 4 manoeuvres beyond the paper's matrix, appended after it (indices
58-61): a slalom at 360 deg and 8 km/h per load condition, starting to the left
and to the right. They are driven only for tuning.

The frequency response, 1 manoeuvre beyond the paper's (index 62,
:data:`SWEEP`): a swept sine of 90 deg at 10 km/h, loaded, validated as the
others and analysed by :mod:`artic.validation.review.frequency`.

The forward tuning set has 8 manoeuvres, as in the paper, 4 per load
condition so that each is tuned on its own, of two kinds (:data:`TUNING`):
the constant steers at 200 deg and 5 km/h, left and right, and the two
tuning slaloms at 360 deg and 8 km/h. None of them is validated: the
validation keeps the paper's other 21 forward manoeuvres (the constant
steers at 360 and 500 deg and at 200 deg and 10 km/h, the slalom and the
figure-of-8) and all 33 reverse ones.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass

from artic.mjcf.errors import UserError

SWEEP = (90, 10)
"""The swept sine's steering-wheel amplitude [deg] and speed [km/h]: 4.3 deg of road
wheel, inside the tyres' linear range at the loaded truck's 10 km/h."""

TUNING_SLALOM = (360.0, 8.0)
"""The tuning slaloms' steering-wheel amplitude [deg] and speed [km/h]: an
amplitude and a speed the constant steers of the tuning set do not have."""


@dataclass(frozen=True)
class Manoeuvre:
    """One cell of the test matrix.

    Parameters
    ----------
    name : str
        Unique name, also the folder name of its export.
    kind : str
        ``constant-steer``, ``slalom``, ``figure-8``, ``ramp-steer-reverse``,
        ``docking``, ``parking`` or ``swept-sine``.
    load : str
        ``unloaded`` or ``loaded``.
    amplitude_deg : float
        Steering-wheel amplitude [deg] (0 for docking and parking).
    speed_kph : float
        Speed [km/h], positive.
    side : str
        ``left`` or ``right`` (for docking and parking: which side the
        start is offset to).
    index : int
        Position in the matrix, which seeds its random numbers.
    """

    name: str
    kind: str
    load: str
    amplitude_deg: float
    speed_kph: float
    side: str
    index: int

    @property
    def direction(self) -> str:
        """``forward`` or ``reverse``."""
        return "reverse" if self.kind in ("ramp-steer-reverse", "docking", "parking") \
            else "forward"

    def meta(self) -> dict:
        """Metadata for the run."""
        return {**asdict(self), "direction": self.direction, "manoeuvre": self.kind}


def _matrix() -> tuple[Manoeuvre, ...]:
    cells: list[tuple] = []
    for load in ("unloaded", "loaded"):
        for amp in (200, 360, 500):
            for speed in (5, 10):
                for side in ("left", "right"):
                    if load == "loaded" and (amp, speed, side) == (500, 10, "right"):
                        continue
                    cells.append(("constant-steer", load, amp, speed, side))
    cells.append(("slalom", "unloaded", 200, 5, "left"))
    cells.append(("figure-8", "loaded", 360, 5, "left"))
    for load in ("unloaded", "loaded"):
        for amp in (30, 90):
            for speed in (3, 6):
                for side in ("left", "right"):
                    cells.append(("ramp-steer-reverse", load, amp, speed, side))
    for i in range(9):
        cells.append(("docking", "unloaded" if i < 5 else "loaded", 0, 3,
                      "left" if i % 2 == 0 else "right"))
    for i in range(8):
        cells.append(("parking", "unloaded" if i < 4 else "loaded", 0, 3,
                      "left" if i % 2 == 0 else "right"))
    for load in ("unloaded", "loaded"):  # the tuning slaloms, beyond the paper's matrix
        for side in ("left", "right"):
            cells.append(("slalom", load, int(TUNING_SLALOM[0]), int(TUNING_SLALOM[1]), side))
    cells.append(("swept-sine", "loaded", *SWEEP, "left"))  # the frequency response
    out = []
    for i, (kind, load, amp, speed, side) in enumerate(cells):
        name = f"{i:02d}-{kind}-{load}-{amp}deg-{speed}kph-{side}" if amp else \
            f"{i:02d}-{kind}-{load}-{side}"
        out.append(Manoeuvre(name, kind, load, float(amp), float(speed), side, i))
    return tuple(out)


MATRIX = _matrix()
"""All 63 manoeuvres, in order: the paper's 58, the 4 tuning slaloms, the swept sine."""

PAPER = 58
"""The paper's manoeuvres: the first 58 of :data:`MATRIX`."""

TUNING = tuple(m.name for m in MATRIX if (m.kind, m.amplitude_deg, m.speed_kph) in (
    ("constant-steer", 200.0, 5.0), ("slalom", *TUNING_SLALOM)))
"""The 8 forward tuning manoeuvres, 4 per load condition, of two kinds: the
constant steers at 200 deg and 5 km/h, left and right, and the tuning slaloms
at 360 deg and 8 km/h starting left and right. A steady state and a transient
one: the constant steers fix the steering ratio and the offset at steady
cornering (left against right separates the offset from the asymmetry q), the
slaloms the yaw and lateral-velocity response to a changing steer, at another
amplitude and speed, which separates the cornering stiffness f (whose effect
grows with the square of the speed) from i_s."""


TUNING_SETS: dict[str, tuple[str, ...]] = {
    "default": TUNING,
    "slaloms": tuple(m.name for m in MATRIX if m.index >= PAPER and m.kind == "slalom"),
    "transient": tuple(m.name for m in MATRIX if m.kind in ("slalom", "figure-8")),
}
"""The campaign's choices of tuning manoeuvres (``artic campaign --tuning``), 4 to 6 per
direction's forward logs, none validated:

- ``default``: :data:`TUNING`, the constant steers at 200 deg and 5 km/h and the tuning
  slaloms (8); the validated forward logs are then 19 constant steers of the tuning
  logs' family, the slalom and the figure-8;
- ``slaloms``: the 4 tuning slaloms alone; every constant steer is validated, and no
  validated class is a tuning class;
- ``transient``: the 4 tuning slaloms, the paper's slalom and its figure-8 (6): the
  fit sees every transient forward manoeuvre, and the forward validation keeps the
  24 constant steers alone."""


def tuning_set(name: str) -> tuple[str, ...]:
    """The tuning manoeuvres of a choice of :data:`TUNING_SETS`.

    Raises
    ------
    UserError
        An unknown choice, naming the choices.
    """
    if name not in TUNING_SETS:
        raise UserError(f"--tuning {name}: choose from {', '.join(TUNING_SETS)}")
    return TUNING_SETS[name]


def selected(only: Sequence[str] | None) -> list[Manoeuvre]:
    """The manoeuvres whose names start with one of ``only``, in the matrix's order; all if none."""
    return [m for m in MATRIX if not only or any(m.name.startswith(o) for o in only)]


def check_only(only: Sequence[str] | None) -> None:
    """Refuse an ``--only`` prefix that names no manoeuvre, before anything is made.

    Raises
    ------
    UserError
        Naming the prefixes and what manoeuvre names look like.
    """
    unknown = [o for o in only or [] if not any(m.name.startswith(o) for m in MATRIX)]
    if unknown:
        raise UserError(f"--only: no manoeuvre matches {', '.join(unknown)}; names look like "
                        f"{MATRIX[0].name} (the campaign guide lists the test matrix)")
