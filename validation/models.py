"""The models the harness drives: their protocol, and the one registry of them.

Every model (KIN, STM and the multibody plant) offers the calls of
:class:`Model`. The registry :data:`REGISTRY` is the one place that names
them: the command line, tuning, validation, the efficiency study, the
recordings, the plots and the report read their constructors, colours and
tuned parameters from it.

The registry builds the plant lazily, so that importing this module does
not import mujoco.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import Vehicle

if TYPE_CHECKING:
    from artic.validation.logs.runfile import Run


class Model(Protocol):
    """What the harness needs of a model.

    - ``reset(initial)`` places the combination at an :class:`InitialState`,
      taken from a log's first sample;
    - ``step(dt, delta, u1, u1_dot)`` advances by ``dt`` [s] with the road-wheel
      angle ``delta`` [rad] held and the tractor's longitudinal speed rising
      linearly from ``u1`` [m/s] at rate ``u1_dot`` [m/s^2];
    - ``observe(delta)`` returns the signals a measured log has, in
      :data:`artic.mjcf.interface.OBSERVATION` order;
    - ``compiled()`` returns the model's compiled form for the harness's
      compiled loop, or ``None`` when it has none (the plant);
    - ``closed_loop()`` returns a loop of the model's own that runs a whole
      log (the plant's, in C: :func:`artic.plant.closedloop.run`), or ``None``;
    - ``close()`` releases what the model holds (the plant's callback);
    - ``gamma`` is the current articulation angle [rad].
    """

    name: str

    def reset(self, initial: InitialState) -> None:
        """Place the combination at ``initial``."""

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance by ``dt`` [s] with the inputs held."""

    def observe(self, delta: float | None = None) -> np.ndarray:
        """Signals in ``OBSERVATION`` order."""

    def compiled(self) -> tuple | None:
        """The compiled form ``(kind, x, P, s1, s2)``, or ``None``."""

    def closed_loop(self) -> Callable | None:
        """The model's own whole-log loop, or ``None``."""

    def close(self) -> None:
        """Release held resources; the model is unusable afterwards."""

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""


def _kin(vehicle: Vehicle) -> Model:
    from artic.reduced import KinematicModel

    return KinematicModel(vehicle)


def _stm(vehicle: Vehicle) -> Model:
    from artic.reduced import SingleTrackModel

    return SingleTrackModel(vehicle)


def _mbd(vehicle: Vehicle) -> Model:
    from artic.plant import Plant

    return Plant(vehicle)


def _floor(vehicle: Vehicle, log: Run | None = None) -> Model:
    """The truth of ``log`` (its metadata's ``truth``) without its random processes.

    Every deterministic mechanism of the truth that made the log, through the
    harness: for the independent truth its own model, tyres, column, play and
    all (:func:`artic.validation.synthetic.truthplant.truth_model`); for the
    structural and legacy truths the plant. ``vehicle`` is the truth's, with
    the log's yard slope (the campaign's ``_floor`` makes it). Left out are
    what no model can know: the sensors' noise, the trailer unit's clock skew
    and the drift of the column's zero. Without a log, the plant.
    """
    truth = (log.meta.get("truth") if log is not None else None) or {}
    if truth.get("kind") == "independent":
        from artic.validation.synthetic.truthplant import truth_model

        return truth_model(vehicle, truth, speed="follow")
    return _mbd(vehicle)


@dataclass(frozen=True)
class ModelSpec:
    """One model of the registry.

    Attributes
    ----------
    name : str
        The name used on the command line and in every result (lower case).
    label : str
        The name in tables and plots (the paper's: KIN, STM, MBD).
    build : callable
        ``build(vehicle)`` returns a :class:`Model`.
    colour : tuple of int
        RGB [0-255] in recordings and plots.
    tuned : tuple of str
        Parameters that tuning fits (vehicle-file names).
    batched : bool
        Whether a batch of logs runs in one compiled call.
    reference : bool
        A reference row rather than a model under validation (the floor:
        the truth itself); not tuned, not in ``--models``.
    per_log : bool
        ``build(vehicle, log)``: the model depends on the log it runs (the
        floor is the truth that made it).
    """

    name: str
    label: str
    build: Callable[[Vehicle], Model]
    colour: tuple[int, int, int]
    tuned: tuple[str, ...]
    batched: bool
    reference: bool = False
    per_log: bool = False

    @property
    def hex_colour(self) -> str:
        """The colour as ``#rrggbb``."""
        return "#{:02x}{:02x}{:02x}".format(*self.colour)


REGISTRY: dict[str, ModelSpec] = {
    s.name: s for s in (
        ModelSpec("kin", "KIN", _kin, (66, 133, 244), ("i_s", "q", "delta_h_offset"), True),
        ModelSpec("stm", "STM", _stm, (52, 168, 83), ("f", "i_s", "q", "delta_h_offset"), True),
        ModelSpec("mbd", "MBD", _mbd, (251, 140, 0), ("i_s", "q", "delta_h_offset"), False),
        # The floor: the truth that made each log, without its random
        # processes, through the same harness. No model can beat it.
        ModelSpec("floor", "floor", _floor, (150, 150, 150), (), False, reference=True,
                  per_log=True),
    )
}
"""Every model artic validates, and the floor, by name, in the order tables list them."""

NAMES: tuple[str, ...] = tuple(n for n, s in REGISTRY.items() if not s.reference)
"""Names of the models under validation, in table order."""

MEASURED_COLOUR = (230, 230, 230)
"""RGB of the measured combination in recordings and plots."""


def spec(name: str) -> ModelSpec:
    """The registry entry of ``name`` (case-insensitive).

    Raises
    ------
    ValueError
        For an unknown name, listing the known ones.
    """
    s = REGISTRY.get(name.strip().lower())
    if s is None:
        raise ValueError(f"unknown model {name!r}; choose from {', '.join(NAMES)}")
    return s


def build(name: str, vehicle: Vehicle, log: Run | None = None) -> Model:
    """A new model ``name`` built from ``vehicle`` (and the log it runs, for the floor)."""
    s = spec(name)
    return s.build(vehicle, log) if s.per_log else s.build(vehicle)


def colour(source: str) -> tuple[int, int, int]:
    """RGB of a model, of ``"measured"``, or grey for anything else."""
    if source == "measured":
        return MEASURED_COLOUR
    s = REGISTRY.get(source)
    return s.colour if s is not None else (200, 200, 200)


def parse_models(text: str) -> list[str]:
    """Split ``"kin,STM"`` into registry names (lower case), checking each.

    Raises
    ------
    ValueError
        For an empty list or an unknown name.
    """
    names = [spec(m).name for m in text.split(",") if m.strip()]
    refs = [n for n in names if REGISTRY[n].reference]
    if refs:
        raise ValueError(f"{', '.join(refs)} is a reference row the campaign adds, not a "
                         f"model to validate; choose from {', '.join(NAMES)}")
    if not names:
        raise ValueError(f"no model given; use for example --models {','.join(NAMES)}")
    return names
