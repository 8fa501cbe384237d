"""The models the harness drives: their protocol, and the one registry of them.

The harness drives two kinds of model. A state-space model, :class:`artic.KIN`,
:class:`artic.STM` or a subclass of either, goes in as it is: the harness
holds its state (:func:`driven`). Any other model, the multibody plant and
models from outside artic, offers the calls of :class:`Model`: ``name``,
``reset``, ``step``, ``observe`` and ``gamma``; ``compiled``, ``closed_loop``
and ``close`` are optional fast paths and clean-up.

The registry :data:`REGISTRY` is the one place that names them: the command
line, tuning, validation, the efficiency study, the recordings, the plots and
the report read their constructors, colours and tuned parameters from it, at
the time they run.

Models from outside artic join the registry in one of two ways:

- :func:`register_model` in the running process (a test file, a script);
- an entry point in the group ``artic.models`` of an installed distribution,
  naming a :class:`ModelSpec` or a function returning one::

      [project.entry-points."artic.models"]
      mykin = "mypackage.models:MYKIN_SPEC"

  Entry points are loaded on the first look-up of a name, so that importing
  artic loads no other distribution's code. One that fails to load gives one
  warning naming its distribution and entry point; every other model works.
  Entry points reach every process (a process pool, a Dask worker);
  :func:`register_model` reaches only the process that calls it.

A registered model then appears in ``--models`` of ``artic validate`` and
``artic campaign``, in the harness, the tables, the recordings and the plots.
It uses the vehicle file's ``[steering]`` map, with the overrides of a
``[steering.NAME]`` table if the file has one; tuning fits only what it names
in ``tuned`` (of its steering map: ``i_s``, ``q``, ``delta_h_offset``).

The registry builds the plant lazily, so that importing this module does
not import mujoco.
"""

from __future__ import annotations

import difflib
import functools
import hashlib
import inspect
import os
import re
import threading
import warnings
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from artic.mjcf.errors import UserError, one_line
from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import Steering, Vehicle

if TYPE_CHECKING:
    from artic.validation.logs.runfile import Run


class Model(Protocol):
    """What the harness needs of a model that holds its own state.

    - ``name``: its name in runs and tables (lower case);
    - ``reset(initial)`` places the combination at an
      :class:`~artic.mjcf.interface.InitialState`, taken from a log's first sample;
    - ``step(dt, delta, u1, u1_dot)`` advances by ``dt`` [s] with the road-wheel
      angle ``delta`` [rad] held and the tractor's longitudinal speed rising
      linearly from ``u1`` [m/s] at rate ``u1_dot`` [m/s^2];
    - ``observe(delta)`` returns the signals a measured log has, in
      :data:`artic.mjcf.interface.OBSERVATION` order (``x_1, y_1`` the
      tractor's sensor), with ``delta`` [rad] the angle about to be held
      (``None``: the last one);
    - ``gamma`` is the current articulation angle [rad].

    Optional (:data:`OPTIONAL`): ``close()`` releases what the model holds
    (the plant's callback); ``compiled()`` returns a compiled form for the
    harness's compiled loop, or ``None``; ``closed_loop()`` returns a loop of
    the model's own that runs a whole log (the plant's, in C:
    :func:`artic.plant.closedloop.run`), or ``None``. A model without them is
    stepped by the harness's Python loop.
    """

    name: str

    def reset(self, initial: InitialState) -> None:
        """Place the combination at ``initial``."""

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance by ``dt`` [s] with the inputs held."""

    def observe(self, delta: float | None = None) -> np.ndarray:
        """Signals in ``OBSERVATION`` order."""

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""


OPTIONAL = ("close", "compiled", "closed_loop")
"""The optional calls of :class:`Model`."""


def is_state_space(model: object) -> bool:
    """Whether ``model`` is a state-space model (``artic.KIN``, ``artic.STM``, a subclass).

    Such a model keeps no state: its ``initial_state``, ``advance`` and
    ``signals`` take it. The harness holds the state (:func:`driven`).
    """
    return (not callable(getattr(model, "reset", None))
            and all(callable(getattr(model, m, None))
                    for m in ("initial_state", "advance", "signals")))


def driven(model: object) -> Model:
    """``model`` as the harness drives it: a state-space model with its state, else itself.

    Parameters
    ----------
    model : object
        ``artic.KIN``, ``artic.STM`` (or a subclass), which get a state
        holder (:class:`artic.reduced.models.Driven`); or a :class:`Model`.
    """
    if is_state_space(model):
        # Here, not at the top: the registry is light to import; numba loads with a model.
        from artic.reduced.models import Driven

        return Driven(model)
    return model


def compiled_form(model: Model) -> tuple | None:
    """The model's ``compiled()`` form, or ``None`` when it has none (an optional call)."""
    f = getattr(model, "compiled", None)
    return f() if callable(f) else None


def own_loop(model: Model) -> Callable | None:
    """The model's ``closed_loop()``, or ``None`` when it has none (an optional call)."""
    f = getattr(model, "closed_loop", None)
    return f() if callable(f) else None


def close(model: Model) -> None:
    """Call the model's ``close()``, if it has one (an optional call)."""
    f = getattr(model, "close", None)
    if callable(f):
        f()


def _kin(vehicle: Vehicle) -> Model:
    # Here, not at the top: numba loads with the first KIN built, not with the registry.
    from artic.reduced.control import KIN

    return KIN(vehicle)


def _stm(vehicle: Vehicle) -> Model:
    # Here, not at the top: numba loads with the first STM built, not with the registry.
    from artic.reduced.control import STM

    return STM(vehicle)


def _mbd(vehicle: Vehicle) -> Model:
    # Here, not at the top: MuJoCo loads with the first plant built, not with the registry.
    from artic.plant import Plant

    return Plant(vehicle)


def _floor(vehicle: Vehicle, log: Run | None = None) -> Model:
    """The truth of ``log`` (its metadata's ``truth``) without its random processes.

    Every deterministic mechanism of the truth that made the log, through the
    harness: for the independent truth its own model, tyres, column, play and
    all (:func:`artic.validation.synthetic.truthmodel.truth_model`); for the
    structural and legacy truths the plant. ``vehicle`` is the truth's, with
    the log's yard slope (the campaign's ``_floor`` makes it). Left out are
    what no model can know: the sensors' noise, the trailer unit's clock skew
    and the drift of the column's zero. Without a log, the plant. The
    independent truth steps as it did making the log, at its step for the
    log's kind (:func:`artic.validation.synthetic.truthmodel.timestep_for`).
    """
    truth = (log.meta.get("truth") if log is not None else None) or {}
    if truth.get("kind") == "independent":
        # Upward, and allowed by name in pyproject's layers contract: the registry's
        # floor is the truth of each log, which the synthetic room models.
        from artic.validation.synthetic.truthmodel import timestep_for, truth_model

        return truth_model(vehicle, truth, speed="follow",
                           timestep=timestep_for(log.meta.get("kind")))
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


_BUILTIN: dict[str, ModelSpec] = {
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
_ADDED: dict[str, ModelSpec] = {}
_lock = threading.RLock()
_discovered = False

ENTRY_POINT_GROUP = "artic.models"
"""The entry-point group that distributions list their models in."""

NAMES: tuple[str, ...] = tuple(n for n, s in _BUILTIN.items() if not s.reference)
"""The built-in models under validation, in table order; :func:`names` gives every model."""

MEASURED_COLOUR = (230, 230, 230)
"""RGB of the measured combination in recordings and plots."""

TUNABLE = ("i_s", "q", "delta_h_offset")
"""What tuning may fit for a registered model: its own steering map (``[steering.NAME]``).
The STM's ``f`` is the vehicle file's ``tyre.f``, shared, and stays the STM's."""

_NAME = re.compile(r"[a-z][a-z0-9_]{0,31}")

_PROTOCOL = ("name", "reset", "step", "observe", "gamma")
"""The members every :class:`Model` has (:data:`OPTIONAL` are optional)."""

_PALETTE = ((219, 68, 55), (171, 71, 188), (0, 172, 193), (124, 179, 66), (255, 112, 67),
            (92, 107, 192), (240, 98, 146), (0, 137, 123))
"""Colours a registered model gets when it names none: apart from the built-ins' and grey."""


class ModelEntryPointWarning(UserWarning):
    """An entry point of the group ``artic.models`` that could not be loaded."""


class _Registry(Mapping):
    """The built-in models, then the registered ones, read at the time of each look-up."""

    def _all(self) -> dict[str, ModelSpec]:
        _discover()
        with _lock:
            return {**_BUILTIN, **_ADDED}

    def __getitem__(self, name: str) -> ModelSpec:
        return self._all()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._all())

    def __len__(self) -> int:
        return len(self._all())

    def __repr__(self) -> str:
        return f"REGISTRY({', '.join(self)})"


REGISTRY: Mapping[str, ModelSpec] = _Registry()
"""Every model artic validates, and the floor, by name, in the order tables list them:
the built-in ones first, then the registered ones in the order they were registered."""


def names() -> tuple[str, ...]:
    """The names of the models under validation, built-ins first, registered ones after.

    See Also
    --------
    artic.build_model : build one by name.
    artic.register_model : add one.

    Examples
    --------
    >>> import artic
    >>> {"kin", "stm", "mbd"} <= set(artic.model_names())
    True
    """
    return tuple(n for n, s in REGISTRY.items() if not s.reference)


def _checked_build(name: str, build: Callable[[Vehicle], Model]) -> Callable[[Vehicle], Model]:
    """``build``, checking that what it returns satisfies :class:`Model` and is named ``name``."""

    @functools.wraps(build)
    def checked(vehicle: Vehicle) -> Model:
        model = build(vehicle)
        missing = [] if is_state_space(model) else [m for m in _PROTOCOL if not _has(model, m)]
        if missing:
            raise TypeError(f"model {name!r}: its build returned a {type(model).__name__}, "
                            f"which lacks {', '.join(missing)} of the model protocol "
                            "(artic.validation.models.Model; or subclass artic.KIN or "
                            "artic.STM)")
        if model.name != name:
            raise TypeError(f"model {name!r}: its build returned a model named "
                            f"{model.name!r}; set its name to {name!r}, under which the runs "
                            "and tables list it")
        return model

    checked.__artic_checked__ = True
    return checked


def _has(model: object, member: str) -> bool:
    """Whether ``model`` has ``member`` (a method callable), without calling a property."""
    try:
        inspect.getattr_static(model, member)
    except AttributeError:
        return False
    if member in ("name", "gamma"):
        return True
    return callable(getattr(model, member, None))


def _check_spec(s: ModelSpec) -> ModelSpec:
    """``s`` with its build checked, or a ``ValueError``/``TypeError`` naming what is wrong."""
    if not isinstance(s.name, str) or not _NAME.fullmatch(s.name):
        raise UserError(f"model name {s.name!r}: use 1-32 lower-case letters, digits or _, "
                         "starting with a letter (it names files and --models entries)")
    if s.name in _BUILTIN:
        raise UserError(f"model name {s.name!r} is artic's built-in "
                         f"{_BUILTIN[s.name].label}; choose another name")
    if not callable(s.build):
        raise TypeError(f"model {s.name!r}: build must be a function of the vehicle returning "
                        f"a model, got {type(s.build).__name__}")
    if not isinstance(s.label, str) or not s.label.strip():
        raise UserError(f"model {s.name!r}: label must be a non-empty string")
    if not (isinstance(s.colour, tuple) and len(s.colour) == 3
            and all(isinstance(c, int) and 0 <= c <= 255 for c in s.colour)):
        raise UserError(f"model {s.name!r}: colour {s.colour!r}: expected three integers "
                         "0-255 (red, green, blue)")
    bad = [t for t in s.tuned if t not in TUNABLE]
    if bad or len(set(s.tuned)) != len(s.tuned):
        raise UserError(f"model {s.name!r}: tuned {s.tuned!r}: a registered model tunes its "
                         f"steering map only, without repeats: choose from {', '.join(TUNABLE)}")
    if not isinstance(s.batched, bool) or s.reference:
        raise UserError(f"model {s.name!r}: batched must be True or False, and a registered "
                         "model is not a reference row")
    if getattr(s.build, "__artic_checked__", False):
        return s
    return ModelSpec(s.name, s.label, _checked_build(s.name, s.build), s.colour, s.tuned,
                     s.batched)


def _add(s: ModelSpec) -> ModelSpec:
    s = _check_spec(s)
    with _lock:
        if s.name in _ADDED:
            raise UserError(f"model {s.name!r} is registered already (as "
                             f"{_ADDED[s.name].label}); choose another name, or "
                             "unregister_model it first")
        _ADDED[s.name] = s
    return s


def model_spec(name: str, build: Callable[[Vehicle], Model], *, label: str | None = None,
               colour: tuple[int, int, int] | None = None, tuned: tuple[str, ...] = (),
               batched: bool = False) -> ModelSpec:
    """A checked registry entry for a model from outside artic, not yet registered.

    What an ``artic.models`` entry point names; :func:`register_model` takes
    the same arguments. See :func:`register_model` for the parameters.

    Raises
    ------
    ValueError
        For a malformed name or a built-in's, or a bad label, colour or ``tuned``.
    TypeError
        For a ``build`` that is not callable.

    See Also
    --------
    artic.register_model : register one in this process.

    Examples
    --------
    A spec for an ``artic.models`` entry point, without registering it:

    >>> import artic
    >>> spec = artic.model_spec("kin_paper", lambda v: artic.KIN(v, wheelbase="paper"),
    ...                         label="KIN (drive axle)")
    >>> spec.name, spec.label
    ('kin_paper', 'KIN (drive axle)')
    """
    if colour is None:
        digest = hashlib.sha256(str(name).encode()).digest()
        colour = _PALETTE[digest[0] % len(_PALETTE)]
    label = str(name).upper() if label is None else label
    return _check_spec(ModelSpec(name, label, build, tuple(colour), tuple(tuned), batched))


def register_model(name: str, build: Callable[[Vehicle], Model], *, label: str | None = None,
                   colour: tuple[int, int, int] | None = None, tuned: tuple[str, ...] = (),
                   batched: bool = False) -> ModelSpec:
    """Add a model to the registry of this process.

    It then appears wherever artic lists models: ``--models`` of ``artic
    validate`` and ``artic campaign``, the harness, the tables, the
    recordings and the plots.

    Parameters
    ----------
    name : str
        Its name on the command line and in every result: 1-32 lower-case
        letters, digits or ``_``; not a built-in's (kin, stm, mbd, floor).
    build : callable
        ``build(vehicle)`` returns a new model satisfying :class:`Model`,
        whose ``name`` is ``name``; checked on every build.
    label : str, optional
        Its name in tables and plots; ``name`` in capitals by default.
    colour : tuple of int, optional
        RGB [0-255] in recordings and plots; one of a palette apart from the
        built-ins' by default, chosen by the name.
    tuned : tuple of str
        What tuning fits, of :data:`TUNABLE` (its ``[steering.NAME]`` map).
    batched : bool
        Whether tuning should run its logs as one batch (a model with a
        compiled form, such as a subclass of ``artic.KIN``).

    Returns
    -------
    ModelSpec
        The registry entry.

    Raises
    ------
    ValueError
        For a name taken (built-in or registered) or malformed, or a bad
        label, colour or ``tuned``.
    TypeError
        For a ``build`` that is not callable.

    See Also
    --------
    artic.model_spec : the same for an ``artic.models`` entry point.
    artic.model_names : every model's name.
    artic.build_model : build one by name.

    Examples
    --------
    KIN with the paper's wheelbase (the drive axle) as a model of its own:

    >>> import artic
    >>> spec = artic.register_model("kin_paper", lambda v: artic.KIN(v, wheelbase="paper"),
    ...                             label="KIN (drive axle)")
    >>> "kin_paper" in artic.model_names()
    True
    >>> from artic.validation.models import unregister_model
    >>> unregister_model("kin_paper")
    """
    return _add(model_spec(name, build, label=label, colour=colour, tuned=tuned,
                           batched=batched))


def unregister_model(name: str) -> None:
    """Remove a registered model (a test's, say); built-in models stay.

    Raises
    ------
    ValueError
        For a built-in or unknown name.
    """
    with _lock:
        if name not in _ADDED:
            raise UserError(f"model {name!r} is not a registered model; registered: "
                             f"{', '.join(_ADDED) or 'none'}")
        del _ADDED[name]


def _discover() -> None:
    """Register the models of the ``artic.models`` entry points, once per process."""
    global _discovered
    if _discovered:
        return
    with _lock:
        if _discovered:
            return
        _discovered = True
        from importlib.metadata import entry_points

        for ep in entry_points(group=ENTRY_POINT_GROUP):
            try:
                obj = ep.load()
                s = obj if isinstance(obj, ModelSpec) else obj() if callable(obj) else obj
                if not isinstance(s, ModelSpec):
                    raise TypeError(f"it gives a {type(s).__name__}, not a ModelSpec or a "
                                    "function returning one")
                if s.name != ep.name:
                    raise UserError(f"its ModelSpec is named {s.name!r}; name the entry "
                                     "point after the model")
                _add(s)
            except Exception as exc:  # noqa: BLE001 - one broken distribution leaves the rest
                dist = getattr(getattr(ep, "dist", None), "name", None) or "an unknown "\
                    "distribution"
                warnings.warn(f"model entry point {ep.name} = {ep.value} of {dist} "
                              f"(group {ENTRY_POINT_GROUP}) was not loaded: "
                              f"{type(exc).__name__}: {one_line(exc)}; the other models "
                              "are available", ModelEntryPointWarning, stacklevel=2)


def spec(name: str) -> ModelSpec:
    """The registry entry of ``name`` (case-insensitive).

    Raises
    ------
    ValueError
        For an unknown name, listing the known ones.
    """
    s = REGISTRY.get(name.strip().lower())
    if s is None:
        near = difflib.get_close_matches(name.strip().lower(), names(), n=1)
        hint = f" (did you mean {near[0]}?)" if near else ""
        raise UserError(f"unknown model {name!r}; choose from {', '.join(names())}{hint}")
    return s


def build(name: str, vehicle: Vehicle, log: Run | None = None) -> Model:
    """A new model ``name`` built from ``vehicle`` (and the log it runs, for the floor).

    A ``[steering.NAME]`` table of the vehicle that names no registered model
    (a misspelt one) is a :class:`SteeringTableWarning`: the file is read
    before models are registered, and the table may be for a model registered
    in another process, so it is not an error here (``artic`` commands refuse
    it, :func:`check_vehicle`).

    See Also
    --------
    artic.model_names : the names it takes.
    artic.register_model : add a model of your own.
    artic.model_spec : a model for an entry point.

    Examples
    --------
    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> model = artic.build_model("kin", vehicle)
    >>> type(model).__name__, model.name
    ('KIN', 'kin')
    """
    for line in _unknown_tables(vehicle):
        warnings.warn(f"{line}; it is unused: every model without a table of its own uses "
                      "the [steering] map", SteeringTableWarning, stacklevel=2)
    s = spec(name)
    return s.build(vehicle, log) if s.per_log else s.build(vehicle)


def colour(source: str) -> tuple[int, int, int]:
    """RGB of a model, of ``"measured"``, or grey for anything else."""
    if source == "measured":
        return MEASURED_COLOUR
    s = REGISTRY.get(source)
    return s.colour if s is not None else (200, 200, 200)


def label(name: str) -> str:
    """A model's name in tables and text (``KIN``), or ``name`` itself if none is registered."""
    s = REGISTRY.get(name)
    return s.label if s is not None else name


def code_of(name: str) -> str:
    """A fingerprint of a registered model's code, for the campaign's cache keys.

    ``""`` for a built-in model, which artic's own code fingerprint covers
    (:mod:`artic.validation.plumbing.fingerprint`). For a registered model:
    the hash of its entry and of the source file of its build's module, or,
    when that file cannot be read, a value new in every process, so that its
    cached results are never reused.
    """
    s = spec(name)
    if s.name in _BUILTIN:
        return ""
    fn = inspect.unwrap(s.build)
    h = hashlib.sha256(repr((s.name, s.tuned, s.batched)).encode())
    try:
        path = inspect.getsourcefile(fn)
        with open(path, "rb") as f:
            h.update(f.read())
    except (TypeError, OSError):
        return f"{_PROCESS_TOKEN}.{s.name}"
    return h.hexdigest()[:16]


_PROCESS_TOKEN = os.urandom(8).hex()
"""New in every process: the fingerprint of a model whose source cannot be read."""


def check_vehicle(vehicle: Vehicle) -> Vehicle:
    """``vehicle``, if each of its ``[steering.NAME]`` tables names a model of the registry.

    The vehicle file accepts such a table for any model name, the registry's
    being unknown where files are read; this catches a misspelt one.

    Raises
    ------
    ValueError
        Naming the file and the table of a model that is not registered.
    """
    unknown = _unknown_tables(vehicle)
    if unknown:
        raise UserError(f"{unknown[0]}; correct the table's name, or register the model "
                         "(artic.register_model)")
    return vehicle


def steering_name(vehicle: Vehicle, model: object) -> str:
    """The ``[steering.NAME]`` table ``model`` steers by in ``vehicle``: the first that exists.

    Its own name's; else its nearest base class's (``class Mine(artic.KIN)`` with
    another ``name`` steers as KIN, and a pure rename changes nothing); else its own
    name, which :meth:`~artic.mjcf.vehicle.Vehicle.steering_for` gives the file's
    ``[steering]``.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle file's parameters.
    model : str or object
        A model, a model class, or a registered model's name.
    """
    name = model if isinstance(model, str) else getattr(model, "name", "")
    if name in vehicle.steering_overrides:
        return name
    cls = model if isinstance(model, type) else type(model)
    if isinstance(model, str):
        built = REGISTRY[model].build if model in REGISTRY else None
        built = getattr(built, "__wrapped__", built)  # functools.wraps of the checked build
        cls = built if isinstance(built, type) else object
    for base in cls.__mro__:
        own = getattr(base, "name", None)
        if isinstance(own, str) and own in vehicle.steering_overrides:
            return own
    return name


def steering_for(vehicle: Vehicle, model: object) -> Steering:
    """``vehicle``'s steering-map parameters for ``model`` (:func:`steering_name`).

    Returns
    -------
    Steering
        The ``[steering]`` table with the model's overrides.
    """
    return vehicle.steering_for(steering_name(vehicle, model))


class SteeringTableWarning(UserWarning):
    """A vehicle's ``[steering.NAME]`` table names no registered model."""


def _unknown_tables(vehicle: Vehicle) -> list[str]:
    """One line per ``[steering.NAME]`` table of ``vehicle`` that names no registered model."""
    lines = []
    for name in vehicle.steering_overrides:
        if name not in REGISTRY:
            near = difflib.get_close_matches(name, names(), n=1)
            hint = f"; did you mean {near[0]}?" if near else ""
            lines.append(f"{vehicle.path}: key 'steering.{name}': no model {name!r} is "
                         f"registered (models: {', '.join(names())}{hint})")
    return lines


def parse_models(text: str, option: str = "--models") -> list[str]:
    """Split ``"kin,STM"`` into registry names (lower case), checking each.

    ``option`` is the command-line option the text came from, which the errors
    name first (none when empty).

    Raises
    ------
    ValueError
        For an empty list or an unknown name.
    """
    where = f"{option}: " if option else ""
    try:
        names_ = [spec(m).name for m in text.split(",") if m.strip()]
    except ValueError as exc:
        raise UserError(f"{where}{exc}") from None
    refs = [n for n in names_ if REGISTRY[n].reference]
    if refs:
        raise UserError(f"{where}{', '.join(refs)} is a reference row the campaign adds, not "
                         f"a model to validate; choose from {', '.join(names())}")
    if not names_:
        raise UserError(f"{where}no model given; use for example {option or '--models'} "
                         f"{','.join(NAMES)}")
    return names_
