"""artic's pytest plugin: cross-model checks in your own test suite.

Installing artic registers this module as the pytest plugin ``artic`` (entry
point group ``pytest11``); ``pytest -p no:artic`` turns it off. It imports
nothing heavy until a fixture or an assertion is used.

Fixtures
    ``artic_vehicle`` (session)
        The vehicle named by the ini option ``artic_vehicle``, a preset name
        or a vehicle file (default ``gosar2022-unloaded``). Define a fixture
        of the same name in your ``conftest.py`` to give another.
    ``artic_plant``
        The multibody plant built from ``artic_vehicle``, closed after the test.
    ``artic_logs`` (session)
        A small seeded synthetic measured campaign, by manoeuvre name: a
        forward constant steer and a reverse ramp steer of the unloaded
        combination, driven on the plant in artic's truth configuration and
        measured through its sensor models
        (:mod:`artic.validation.synthetic.generate`). Made once and cached
        in pytest's cache folder, under a key of artic's code fingerprint
        (:mod:`artic.validation.plumbing.fingerprint`), the seed and the
        manoeuvres, so a later session reads it back until artic changes.
        The ini options ``artic_logs`` (manoeuvre names or name prefixes of
        :data:`artic.validation.synthetic.testmatrix.MATRIX`) and
        ``artic_seed`` choose others.

Assertions
    :func:`assert_tracks`: this model tracks this log within these criteria.
    :func:`assert_agree`: these two models agree within these criteria on
    these manoeuvres.

Both drive the models through artic's closed-loop harness
(:func:`artic.validation.harness.loop.run_closed_loop`) and compare with the
criteria of eqs. (8)-(10) (:func:`artic.validation.criteria.metrics.run_metrics`).
``within`` maps criterion names (:data:`artic.validation.criteria.metrics.CRITERIA`,
the articulation error ``eps_gamma`` of
:mod:`artic.validation.criteria.articulation` and the progress term
``eps_cover`` of :mod:`artic.validation.criteria.coverage`) to upper limits in
their units (``eps_p`` and ``eps_cover`` [m], ``eps_a`` [rad/s], ``eps_v``
[m/s], ``eps_n`` and ``J_steer`` [%], ``eps_gamma`` [rad]).

The progress term is always checked: a model that stays at its start sits on
the measured path and passes any limit on ``eps_p``, so unless ``within``
limits ``eps_cover`` itself, its limit is :data:`COVER_LIMIT`, whatever the
limit given for ``eps_p`` (see :func:`default_limits`). A
failure's message is the criteria table: manoeuvre, criterion, value, limit
(``(default)`` beside one the check added) and pass or FAIL, with the status
of any run that stopped early. A model is given as a registry
name (``"kin"``, or one of :func:`artic.validation.models.register_model`),
a model object (:class:`artic.validation.models.Model`), or a function
building one from a vehicle (a model class is one).

A user's test::

    from artic.validation.testing import assert_agree, assert_tracks

    def test_my_model(artic_vehicle, artic_logs):
        for log in artic_logs.values():
            assert_tracks(MyModel(artic_vehicle), log, within={"eps_p": 2.0, "eps_n": 40.0})
        assert_agree("kin", MyModel, artic_logs.values(), within={"eps_a": 0.01})
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from artic.mjcf.errors import UserError

# The fixtures import artic's rooms inside themselves, not here: pytest loads this
# plugin in every session of every project that installs artic, which should not
# pay for MuJoCo, numba or pandas until a test asks for them.

if TYPE_CHECKING:
    from artic.mjcf.vehicle import Vehicle
    from artic.validation.logs.runfile import Run

DEFAULT_VEHICLE = "gosar2022-unloaded"
"""The ``artic_vehicle`` fixture's vehicle when the ini option names none."""

COVER_LIMIT = 7.0
"""Default limit of the progress term ``eps_cover`` [m]: a lane's width, 3.5 m, per sensor point,
the tables' bound :data:`artic.validation.criteria.coverage.FOLLOW_BOUND` (which says why;
written here as a number so that the plugin loads no pandas, and a test keeps them equal). It holds
whatever limit the caller gives ``eps_p``; only a limit on ``eps_cover`` itself
replaces it."""

DEFAULT_LOGS = ("00-constant-steer-unloaded-200deg-5kph-left",
                "28-ramp-steer-reverse-unloaded-30deg-6kph-right")
"""The ``artic_logs`` manoeuvres: 40 s of constant steer at 5 km/h, and a reverse
ramp steer at 6 km/h until the driver stops before jackknife (about 36 s)."""

_configured = False


def _configure() -> None:
    """Make artic's process settings (:func:`artic.validation.plumbing.runtime.configure`), once."""
    global _configured
    if not _configured:
        from artic.validation.plumbing import runtime

        runtime.configure()
        _configured = True


# --------------------------------------------------------------------------- hooks

def pytest_addoption(parser: pytest.Parser) -> None:
    """The plugin's ini options."""
    parser.addini("artic_vehicle", f"artic: preset or vehicle file of the artic_vehicle "
                  f"fixture (default {DEFAULT_VEHICLE})", default=DEFAULT_VEHICLE)
    parser.addini("artic_logs", "artic: manoeuvre names or prefixes of the artic_logs "
                  "fixture, space-separated", type="args", default=list(DEFAULT_LOGS))
    parser.addini("artic_seed", "artic: seed of the artic_logs fixture (default 0)",
                  default="0")


# ------------------------------------------------------------------------ fixtures

@pytest.fixture(scope="session")
def artic_vehicle(pytestconfig: pytest.Config) -> Vehicle:
    """The vehicle of the ini option ``artic_vehicle`` (a preset name or a vehicle file)."""
    from artic.mjcf.vehicle import load_vehicle

    name = str(pytestconfig.getini("artic_vehicle")).strip() or DEFAULT_VEHICLE
    path = Path(name)
    if not path.is_absolute() and path.suffix == ".toml":  # relative to the ini file
        path = Path(pytestconfig.rootpath) / path
        name = str(path)
    return load_vehicle(name)


@pytest.fixture
def artic_plant(artic_vehicle: Vehicle) -> Iterator[Any]:
    """The multibody plant built from ``artic_vehicle``, closed after the test."""
    _configure()
    from artic.plant import Plant

    with Plant(artic_vehicle) as plant:
        yield plant


@pytest.fixture(scope="session")
def artic_logs(pytestconfig: pytest.Config,
               tmp_path_factory: pytest.TempPathFactory) -> dict[str, Run]:
    """A small seeded synthetic measured campaign by manoeuvre name (see the module)."""
    return session_logs(pytestconfig, tmp_path_factory)


def session_logs(config: pytest.Config, tmp_path_factory: pytest.TempPathFactory | None = None
                 ) -> dict[str, Run]:
    """The logs of ``artic_logs``: read from pytest's cache, or made and cached.

    Without pytest's cache (``-p no:cacheprovider``) they are made in a
    temporary folder of the session.
    """
    _configure()
    from artic.validation.campaign.main import load_logs
    from artic.validation.plumbing import fingerprint

    try:
        seed = int(str(config.getini("artic_seed")).strip() or 0)
    except ValueError:
        raise pytest.UsageError(f"ini option artic_seed = {config.getini('artic_seed')!r}: "
                                "expected a whole number") from None
    only = [str(o) for o in config.getini("artic_logs")] or list(DEFAULT_LOGS)
    key = fingerprint.key("pytest artic_logs", seed, only)
    cache = getattr(config, "cache", None)
    if cache is not None:
        folder = Path(cache.mkdir("artic")) / f"logs-{key}"
    elif tmp_path_factory is not None:
        folder = tmp_path_factory.mktemp("artic-logs")
    else:
        raise pytest.UsageError("artic_logs needs pytest's cache or a temporary folder")
    return {log.name: log for log in load_logs(folder, seed=seed, only=only)}


# ---------------------------------------------------------------------- assertions

@contextlib.contextmanager
def _model(model: Any, vehicle: Vehicle) -> Iterator[Any]:
    """A model to drive: built from ``vehicle`` (and closed after) unless it is one already."""
    from artic.validation.models import ModelSpec, build, close, is_state_space

    if isinstance(model, str):
        built = build(model, vehicle)
    elif isinstance(model, ModelSpec):
        built = model.build(vehicle)
    elif not isinstance(model, type) and (is_state_space(model) or (
            hasattr(model, "reset") and hasattr(model, "step"))):
        yield model  # a model already: a class has these methods too, but builds one
        return
    elif callable(model):
        built = model(vehicle)
    else:
        raise TypeError(f"model {model!r}: give a model name, a model, or a function "
                        "building one from a vehicle")
    try:
        yield built
    finally:
        close(built)


def _name(model: Any) -> str:
    if isinstance(model, str):
        return model.strip().lower()
    name = getattr(model, "name", None)
    if isinstance(name, str):
        return name
    return getattr(model, "__name__", type(model).__name__)


def _vehicle(vehicle: Vehicle | str | None, model: Any, log: Run) -> Vehicle:
    """The vehicle given; or the model object's own; or the one the log names."""
    from artic.mjcf.vehicle import Vehicle, load_vehicle

    if isinstance(vehicle, Vehicle):
        return vehicle
    if isinstance(vehicle, str | Path):
        return load_vehicle(vehicle)
    own = getattr(model, "vehicle", None)
    if isinstance(own, Vehicle):
        return own
    named = log.meta.get("vehicle_path") or log.meta.get("vehicle")
    if not named:
        raise UserError(f"log {log.name}: its metadata names no vehicle; pass vehicle=")
    return load_vehicle(named)


def _logs(manoeuvres: Run | Iterable[Run] | Mapping[str, Run]) -> list[Run]:
    from artic.validation.logs.runfile import Run

    if isinstance(manoeuvres, Run):
        return [manoeuvres]
    if isinstance(manoeuvres, Mapping):
        manoeuvres = manoeuvres.values()
    out = list(manoeuvres)
    if not out or not all(isinstance(r, Run) for r in out):
        raise TypeError("give one log (a Run), or a non-empty sequence or mapping of them")
    return out


def _known() -> dict[str, str]:
    """The criteria a check may limit, with their units."""
    from artic.validation.criteria.metrics import CRITERIA, UNITS

    return {**{c: UNITS[c] for c in CRITERIA}, "eps_gamma": "rad", "eps_cover": "m"}


def _criteria(log: Run, run: Run) -> dict[str, float]:
    """The criteria of ``run`` against ``log``: eqs. (8)-(10), ``eps_gamma`` and ``eps_cover``."""
    from artic.validation.criteria.metrics import run_metrics

    return run_metrics(log.frame, run.frame)


def default_limits(within: Mapping[str, float]) -> dict[str, float]:
    """The limits a check adds to ``within``: the progress term's, unless it is given.

    ``eps_cover`` <= :data:`COVER_LIMIT`, whatever ``within`` gives ``eps_p``:
    a loose position limit does not loosen the progress bound, which only a
    limit on ``eps_cover`` itself replaces (a model that never moves scores
    near zero on ``eps_p``, so a position limit says nothing about progress).

    Parameters
    ----------
    within : mapping of str to float
        The limits given [criterion's unit].

    Returns
    -------
    dict
        The limits added [m]; empty when ``within`` limits ``eps_cover``.
    """
    if "eps_cover" in within:
        return {}
    return {"eps_cover": COVER_LIMIT}


def _limits(within: Mapping[str, float]) -> dict[str, float]:
    known = _known()
    if not within:
        raise UserError(f"within: give at least one criterion, from {', '.join(known)}")
    out = {}
    for k, v in within.items():
        if k not in known:
            raise UserError(f"within: unknown criterion {k!r}; choose from {', '.join(known)}")
        if not isinstance(v, int | float) or not math.isfinite(v) or v < 0:
            raise UserError(f"within: {k} = {v!r}: a limit is a finite number >= 0")
        out[k] = float(v)
    return out


def criteria_table(rows: list[tuple[str, dict[str, float], str]],
                   limits: Mapping[str, float],
                   defaults: Iterable[str] = ()) -> tuple[str, int]:
    """The criteria table of a check, and its number of failures.

    Parameters
    ----------
    rows : list of (str, dict, str)
        Per manoeuvre: its name, its criteria
        (:func:`artic.validation.criteria.metrics.run_metrics`) and the status of its
        run(s), ``"ok"`` or why it stopped early.
    limits : mapping of str to float
        Upper limit per criterion, in its unit.
    defaults : iterable of str
        The criteria whose limit the check added (:func:`default_limits`); their
        limit reads ``(default)``.
    """
    units = _known()
    added = set(defaults)

    def num(x: float, unit: str) -> str:
        return "nan" if not math.isfinite(x) else f"{x:.4g} {unit}"

    head = ("manoeuvre", "criterion", "value", "limit", "result")
    lines, failed, notes = [], 0, []
    for name, crit, status in rows:
        for i, (k, lim) in enumerate(limits.items()):
            v = float(crit.get(k, math.nan))
            ok = math.isfinite(v) and v <= lim
            failed += not ok
            limit = num(lim, units[k]) + (" (default)" if k in added else "")
            lines.append((name if i == 0 else "", k, num(v, units[k]), limit,
                          "pass" if ok else "FAIL"))
        if status != "ok":
            failed += 1
            notes.append(f"FAIL {name}: {status}")
    width = [max(len(r[j]) for r in (head, *lines)) for j in range(len(head))]
    text = ["  ".join(c.ljust(w) for c, w in zip(r, width, strict=True)).rstrip()
            for r in (head, *lines)]
    return "\n".join([*text, *notes]), failed


def assert_tracks(model: Any, log: Run | Iterable[Run] | Mapping[str, Run],
                  within: Mapping[str, float], *, vehicle: Vehicle | str | None = None,
                  gain: float | None = None) -> dict[str, dict[str, float]]:
    """Assert that ``model`` tracks ``log`` within the criteria ``within``.

    The model runs through the closed-loop harness on each log and its
    criteria against the log must not exceed the limits; a run that stops
    early (jackknife, a state gone non-finite) fails.

    Parameters
    ----------
    model : str, Model or callable
        A registry name, a model, or ``build(vehicle)`` returning one (a model
        class, such as ``MyModel``, is one).
    log : Run, or a sequence or mapping of Run
        The measured log(s), such as ``artic_logs`` or one of its values.
    within : mapping of str to float
        Upper limit per criterion, in the criterion's unit; ``eps_cover`` is
        limited by default (:func:`default_limits`) when not given.
    vehicle : Vehicle or str, optional
        The vehicle the model is built from, and whose steering map and limits
        the harness uses; by default the model object's own (``model.vehicle``)
        or the one the log's metadata names.
    gain : float, optional
        The harness's reversing feedback gain K [rad/rad]; the paper's 3 by
        default (:data:`artic.validation.harness.reversing.DEFAULT_GAIN`); 0 runs open loop.

    Returns
    -------
    dict
        The criteria per log name, for further checks.

    Raises
    ------
    AssertionError
        With the criteria table, when a limit is exceeded or a run stopped early.
    """
    __tracebackhide__ = True
    _configure()
    from artic.validation.harness.loop import DEFAULT_GAIN, run_closed_loop

    gain = DEFAULT_GAIN if gain is None else gain
    limits = _limits(within)
    added = default_limits(limits)
    limits |= added
    rows, out = [], {}
    for one in _logs(log):
        v = _vehicle(vehicle, model, one)
        with _model(model, v) as m:
            run = run_closed_loop(m, one, v, gain, extras=False)
        crit = _criteria(one, run)
        rows.append((one.name, crit, run.meta["status"]))
        out[one.name] = crit
    table, failed = criteria_table(rows, limits, added)
    if failed:
        raise AssertionError(f"{_name(model)} does not track the log(s) within the criteria "
                             f"({failed} failure(s), K = {gain:g}):\n{table}")
    return out


def assert_agree(model_a: Any, model_b: Any,
                 manoeuvres: Run | Iterable[Run] | Mapping[str, Run],
                 within: Mapping[str, float], *, vehicle: Vehicle | str | None = None,
                 gain: float | None = None) -> dict[str, dict[str, float]]:
    """Assert that two models agree within the criteria ``within`` on ``manoeuvres``.

    On each manoeuvre ``model_a`` runs through the closed-loop harness on the
    log, and its run becomes the reference: its signals, with the log's
    steering wheel and speed. ``model_b`` then runs through the same harness
    against that reference, and its criteria against it must not exceed the
    limits: the campaign's "against the plant as reference" with ``model_a``
    as the reference. A run of either that stops early fails.

    Parameters
    ----------
    model_a, model_b : str, Model or callable
        The reference model and the model compared with it (see
        :func:`assert_tracks`).
    manoeuvres : Run, or a sequence or mapping of Run
        The logs whose inputs drive both, such as ``artic_logs``.
    within : mapping of str to float
        Upper limit per criterion, in the criterion's unit; ``eps_cover`` as
        in :func:`assert_tracks`.
    vehicle : Vehicle or str, optional
        As in :func:`assert_tracks`, for both models.
    gain : float, optional
        As in :func:`assert_tracks`.

    Returns
    -------
    dict
        The criteria of ``model_b`` against ``model_a`` per manoeuvre.

    Raises
    ------
    AssertionError
        With the criteria table, when a limit is exceeded or a run stopped early.
    """
    __tracebackhide__ = True
    _configure()
    from artic.validation.harness.loop import DEFAULT_GAIN, run_closed_loop
    from artic.validation.logs.runfile import Run
    from artic.validation.logs.schema import COLUMNS

    gain = DEFAULT_GAIN if gain is None else gain
    limits = _limits(within)
    added = default_limits(limits)
    limits |= added
    a_name, b_name = _name(model_a), _name(model_b)
    rows, out = [], {}
    for log in _logs(manoeuvres):
        va = _vehicle(vehicle, model_a, log)
        vb = _vehicle(vehicle, model_b, log)
        with _model(model_a, va) as a:
            run_a = run_closed_loop(a, log, va, gain, extras=False)
        ref = Run(run_a.frame[list(COLUMNS)].reset_index(drop=True),
                  {**log.meta, "name": log.name, "source": f"model:{a_name}",
                   "reference": a_name})
        with _model(model_b, vb) as b:
            run_b = run_closed_loop(b, ref, vb, gain, extras=False)
        crit = _criteria(ref, run_b)
        status = "; ".join(f"{who} {run.meta['status']}" for who, run in
                           ((a_name, run_a), (b_name, run_b)) if run.meta["status"] != "ok")
        rows.append((log.name, crit, status or "ok"))
        out[log.name] = crit
    table, failed = criteria_table(rows, limits, added)
    if failed:
        raise AssertionError(f"{b_name} does not agree with {a_name} within the criteria "
                             f"({failed} failure(s), K = {gain:g}):\n{table}")
    return out

