"""Robustness sweeps: the docking benchmark along one axis of what a yard throws at it.

``artic dock --sweep AXIS=L1,L2,...`` runs every scenario x vehicle x
controller x seed at each level of one axis (:data:`AXES`), with the same
starts and sensor noise at every level, so levels and controllers compare
paired. Adding an axis is one entry of :data:`AXES`: its name, unit, how a
level is read, and the :func:`~artic.validation.docking.run.drive` keywords it
sets.

**Scale and resumption.** The runs go through :func:`execute`: on this
machine to the benchmark's supervised worker processes (``--jobs``; a
controller that crashes or hangs fails its run), or with ``--executor dask``
to the campaign's Dask executor
(:func:`artic.validation.plumbing.executors.cluster_executor`: a local cluster,
or ``--scheduler ADDRESS`` with its TLS options; the cluster must be trusted).
Each finished run is written at once, atomically, as
``sweep_runs/AXIS=LEVEL-SCENARIO-VEHICLE-CONTROLLER-SEED.json`` holding what
was asked (:class:`RunSpec`, with fingerprints of the vehicle's numbers and of the
code the run executes) and its row; a
sweep started again into the same folder skips every run whose file holds
the same request, so a killed sweep resumes where it stopped; a run that its
supervisor failed (a hang, a crashed worker, a lost cluster worker:
:data:`RETRIED`) is run again. Runs of other
sweeps in the folder stay (a later sweep of that axis reuses them) and are
not listed.

**What is written** (:func:`summarise`, :func:`compare`):

- ``sweep_runs.csv``: every run's row (``dock.csv``'s columns after ``axis``
  and ``level``);
- ``sweep.csv``: one row per axis, level, scenario, vehicle and controller:
  the runs, the success rate at the benchmark's gates and at each tier of
  :data:`~artic.validation.docking.scores.TIERS`, each with its Wilson 95 %
  interval; over the runs that came to rest at the dock (``finished``: docked
  or missed the door, so no survivor's bias at the gate), the mean final
  |lateral| [cm] and |heading| [deg] errors and time [s] with the project's
  95 % intervals (Student's t below 8 runs, the expanded BCa bootstrap from 8
  on; ``interval`` names it); the jackknifes, collisions and timeouts;
- ``sweep_pairs.csv``: every two controllers at each level, scenario and
  vehicle, over the same starts: success by McNemar's exact test (the
  binomial test of the discordant pairs: the starts one docked and the other
  did not), the |lateral| and |heading| errors over the starts both finished
  by the mean paired difference with its interval and the p value of the
  campaign's paired test (:func:`artic.validation.criteria.multiplicity.paired_test`:
  the sign-flip test and Hall's t; NaN, and ``test`` says "not testable",
  where the differences are too skewed for any test at their number). Holm's
  correction over the whole sweep's family (every level, pair, metric,
  scenario and vehicle; the rows not testable left out) gives ``p_holm``; a
  comparison is a ``finding`` only where ``p_holm < 0.05``;
- ``sweep.md``: the table and the findings in words; ``sweep.png``: success
  and errors against the level, one line per controller
  (:func:`artic.validation.docking.plots.plot_sweep`).
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import dataclasses
import hashlib
import importlib.util
import json
import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from artic.mjcf.errors import UserError, one_line
from artic.validation.docking import pairs
from artic.validation.docking.pairs import ERRORS, finished

RUNS_DIR = "sweep_runs"
"""Folder of the per-run files in the output folder."""


# ---------------------------------------------------------------- the axes
def _available() -> str | None:
    return None


def _drive_takes(keyword: str, part: str) -> Callable[[], str | None]:
    """An axis's check: ``drive`` has ``keyword`` (the other part of the issue is merged)."""
    def check() -> str | None:
        from artic.validation.docking.spec import CONDITIONS, RUN_OPTIONS

        if keyword in CONDITIONS + RUN_OPTIONS:  # drive's keywords
            return None
        return f"{part} (drive's {keyword}=) is not in this artic"
    return check


def _variants() -> str | None:
    """The semitrailer axes' check: the variants module and ``drive(trailer=...)``."""
    if importlib.util.find_spec("artic.validation.docking.variants") is None:
        return "the semitrailer variants (artic.validation.docking.variants) are not in this artic"
    return _drive_takes("trailer", "the unknown semitrailer")()


def _semitrailer(**change) -> dict:
    """The drive keywords for a semitrailer that differs from the vehicle file by ``change``.

    ``drive(trailer=Draw(...))`` builds every start's plant on that semitrailer
    (:class:`artic.validation.docking.variants.Draw`), the controllers knowing the file's.
    """
    from artic.validation.docking.variants import Draw

    return {"trailer": Draw(**change)}


def _number(lo: float, hi: float, unit: str, step: float | None = None,
            lo_open: bool = False) -> Callable[[str], float]:
    """A level's reader: a number in ``[lo, hi]`` (``(lo, hi]``), a multiple of ``step``."""
    def parse(text: str) -> float:
        try:
            x = float(text)
        except ValueError:
            raise ValueError(f"{text!r} is not a number") from None
        if not math.isfinite(x) or x > hi or (x <= lo if lo_open else x < lo):
            raise ValueError(f"{text} is outside {'(' if lo_open else '['}{lo:g}, {hi:g}] "
                             f"{unit}".rstrip())
        if step is not None and abs(round(x / step) * step - x) > 1e-9:
            raise ValueError(f"{text} is not a multiple of {step:g} {unit}")
        return x
    return parse


def _choice(names: Sequence[str]) -> Callable[[str], str]:
    def parse(text: str) -> str:
        if text not in names:
            raise ValueError(f"{text!r} is not one of {', '.join(names)}")
        return text
    return parse


@dataclass(frozen=True)
class Axis:
    """One axis of a robustness sweep.

    Parameters
    ----------
    name : str
        ``--sweep NAME=...``.
    unit : str
        The levels' unit (empty for a choice).
    description : str
        What it varies, for ``artic dock --list`` and the guide.
    nominal : float or str
        Today's benchmark.
    parse : callable
        A level's text to its value; raises ``ValueError`` saying what is wrong.
    keywords : callable
        A level to :func:`~artic.validation.docking.run.drive`'s keyword arguments.
    missing : callable
        ``None`` when the axis can run, else what this artic lacks for it.
    nominal_text : callable, optional
        The nominal as ``artic dock --list`` shows it, where ``nominal`` alone would
        mislead (the articulation's noise is the sensor set's own).
    """

    name: str
    unit: str
    description: str
    nominal: float | str
    parse: Callable[[str], float | str]
    keywords: Callable[[float | str], dict]
    missing: Callable[[], str | None] = _available
    nominal_text: Callable[[], str] | None = None

    def shown_nominal(self) -> str:
        """The nominal level as ``artic dock --list`` prints it."""
        return self.nominal_text() if self.nominal_text is not None else str(self.nominal)

    @property
    def categorical(self) -> bool:
        """Whether the levels are names rather than numbers."""
        return isinstance(self.nominal, str)


def _sensor_noise() -> str:
    """The articulation sensors' own noise RMS, the nominal of ``articulation_noise``."""
    from artic.validation.docking.sensing import articulation_model

    rms = {s: math.degrees(articulation_model(s).noise_rms) for s in ("tractor", "camera")}
    return ("the sensor's (" + ", ".join(f"{s} {v:.2g} deg" for s, v in rms.items())
            + "; full measures none)")


AXES: dict[str, Axis] = {a.name: a for a in (
    Axis("delay", "s", "actuator delay between the controller's command and the actuators "
         "(a FIFO at the plant's 10 ms step)", 0.0,
         _number(0.0, 2.0, "s", step=0.01), lambda x: {"delay": float(x)}),
    Axis("steer_rate", "deg/s", "the steering wheel's rate limit (the controller is told "
         "360 deg/s whatever it is)", 360.0,
         _number(0.0, 3600.0, "deg/s", lo_open=True),
         lambda x: {"steer_rate": math.radians(float(x))}),
    Axis("friction", "-", "road friction factor on the tyres' LMUX, LMUY: 1.0 dry, 0.7 wet, "
         "0.3 packed snow", 1.0, _number(0.0, 1.5, "", lo_open=True),
         lambda x: {"friction": float(x)}),
    Axis("grade", "%", "yard slope along the dock's approach, positive falling towards the "
         "dock", 0.0, _number(-15.0, 15.0, "%"), lambda x: {"grade": float(x)}),
    Axis("articulation_noise", "deg", "noise of the articulation measurement (RMS)", 0.0,
         _number(0.0, 20.0, "deg"), lambda x: {"articulation_noise_deg": float(x)},
         _drive_takes("articulation_noise_deg", "the sensor sets"), _sensor_noise),
    Axis("sensors", "", "sensor set: full (RTK/INS on both units), tractor (and a hitch "
         "encoder), camera (a rear-facing articulation sensor)", "full",
         _choice(("full", "tractor", "camera")), lambda x: {"sensor_set": str(x)},
         _drive_takes("sensor_set", "the sensor sets")),
    Axis("trailer_length_error", "m", "the plant's semitrailer kingpin-to-axle length "
         "less the vehicle file's", 0.0, _number(-3.0, 3.0, "m"),
         lambda x: _semitrailer(length_error_m=float(x)), _variants),
    Axis("payload", "kg", "payload added to the plant's semitrailer, its box centred where "
         "the draws centre it by default", 0.0, _number(0.0, 40000.0, "kg"),
         lambda x: _semitrailer(payload_kg=float(x)), _variants),
)}
"""The sweep's axes, by name. ``missing`` of the last four checks for the parts of the
docking issue that other work adds (the sensor sets, the unknown semitrailer)."""


def level_text(level: float | str) -> str:
    """A level as the file names and tables write it."""
    return level if isinstance(level, str) else f"{level:g}"


def parse_sweep(text: str | Sequence[str]) -> tuple[Axis, list[float | str]]:
    """``--sweep``'s value: one axis and its levels (one clear :class:`UserError` if bad).

    Parameters
    ----------
    text : str or sequence of str
        ``AXIS=L1,L2,...``; a sequence is ``--sweep`` given several times (refused).
    """
    if not isinstance(text, str):
        if len(text) != 1:
            raise UserError(f"--sweep given {len(text)} times: a sweep varies one axis at a "
                            "time; run one artic dock --sweep per axis")
        text = text[0]
    example = "e.g. --sweep friction=1.0,0.6,0.3"
    if "=" not in text:
        raise UserError(f"--sweep {text}: expected AXIS=L1,L2,... ({example}); axes: "
                        f"{', '.join(AXES)}")
    name, _, levels = text.partition("=")
    name = name.strip()
    if "=" in levels:
        second = levels.split("=")[0].split(",")[-1].strip()
        raise UserError(f"--sweep {text}: one axis at a time ({name} and {second}); run one "
                        "artic dock --sweep per axis")
    axis = AXES.get(name)
    if axis is None:
        raise UserError(f"--sweep {text}: no axis {name!r}; axes: {', '.join(AXES)} "
                        "(artic dock --list describes them)")
    why = axis.missing()
    if why is not None:
        raise UserError(f"--sweep {name}: not available yet: {why}; sweep "
                        + ", ".join(a for a in AXES if AXES[a].missing() is None))
    parts = [p.strip() for p in levels.split(",")]
    if not levels.strip() or not all(parts):
        raise UserError(f"--sweep {text}: give the levels as {name}=L1,L2,... with no empty "
                        f"one ({example})")
    values = []
    for p in parts:
        try:
            values.append(axis.parse(p))
        except ValueError as exc:
            unit = f" [{axis.unit}]" if axis.unit and axis.unit != "-" else ""
            raise UserError(f"--sweep {name}: level {exc}; {name}{unit} is the "
                            f"{axis.description}") from None
    seen = [level_text(v) for v in values]
    twice = sorted({s for s in seen if seen.count(s) > 1})
    if twice:
        raise UserError(f"--sweep {text}: level {twice[0]} given twice; its runs would count "
                        "twice: name it once")
    return axis, values


# ---------------------------------------------------------------- the runs
@dataclass(frozen=True)
class RunSpec:
    """What one run of a sweep asks for: the file's key, compared on resumption."""

    axis: str
    level: float | str
    scenario: str
    vehicle: str
    controller: str
    seed: int
    vehicle_fingerprint: str
    truth: int | None = None
    realtime: bool = True
    sensors: str = "full"
    """The sensor set of every run (``artic dock --sensors``) unless the axis sweeps it."""
    trailer: str = "nominal"
    """The plant's semitrailer (``artic dock --trailer``) unless the axis gives one."""
    code: str = ""
    """:func:`code_fingerprint` of the run's controller: a run made by other code is not
    reused."""
    backend: str = "cpu"
    """The plant the run drives: ``"cpu"``, or ``"warp"`` (``artic dock --backend warp``,
    :mod:`artic.validation.docking.warp_dock`); a run on the other is not reused."""

    @property
    def name(self) -> str:
        """The run's file name, without suffix."""
        from artic.validation.docking.run import _safe, run_name

        return (f"{_safe(self.axis)}={_safe(level_text(self.level))}-"
                f"{run_name(self.scenario, self.vehicle, self.controller, self.seed)}")

    def as_dict(self) -> dict:
        """As JSON stores it (without ``backend`` for the CPU's: the files of before it)."""
        out = dataclasses.asdict(self)
        if self.backend == "cpu":
            del out["backend"]
        return out


def vehicle_fingerprint(vehicle: str) -> str:
    """A short hash of every number of the vehicle ``vehicle`` names (preset or file)."""
    from artic.mjcf.vehicle import load_vehicle

    return hashlib.sha256(repr(load_vehicle(vehicle)).encode()).hexdigest()[:16]


def code_fingerprint(controller: str) -> str:
    """A short hash of the code a run of ``controller`` executes.

    artic's computing code (:func:`artic.validation.plumbing.fingerprint.code`, the
    campaign's cache key: the plant, the models, the benchmark and the built-in
    controllers) and, for a ``module:Class`` controller, its module's source file
    (found without importing the module itself; a module that cannot be found adds nothing, and
    its runs fail on their own).
    """
    from artic.validation.docking.controllers import BUILTIN
    from artic.validation.plumbing import fingerprint

    h = hashlib.sha256(fingerprint.code().encode())
    if controller not in BUILTIN and ":" in controller:
        try:
            found = importlib.util.find_spec(controller.partition(":")[0])
        except (ImportError, ValueError):
            found = None
        if found is not None and found.origin and Path(found.origin).is_file():
            h.update(Path(found.origin).read_bytes())
    return h.hexdigest()[:16]


def check_base(axis: Axis, sensors: str = "full", trailer: str = "nominal") -> None:
    """Refuse an axis that contradicts the sweep's sensor set or semitrailer.

    Raises
    ------
    UserError
        The articulation's noise with the ``full`` set (it measures no articulation
        of its own), the sensor set with another ``sensors``, a given semitrailer
        with ``unknown``.
    """
    if axis.name == "articulation_noise" and sensors == "full":
        raise UserError("--sweep articulation_noise: the full set measures the articulation "
                        "by the two units' headings; add --sensors tractor or camera")
    if axis.name == "sensors" and sensors != "full":
        raise UserError(f"--sweep sensors sweeps the sensor set; leave --sensors {sensors} out")
    if axis.name in ("trailer_length_error", "payload") and trailer != "nominal":
        raise UserError(f"--sweep {axis.name} gives the plant's semitrailer; leave "
                        f"--trailer {trailer} out")


def plan(axis: Axis, levels: Sequence[float | str], scenarios: Sequence[str],
         vehicles: Sequence[str], controllers: Sequence[str], seeds: Sequence[int],
         truth: int | None = None, realtime: bool = True, sensors: str = "full",
         trailer: str = "nominal") -> list[RunSpec]:
    """Every run of a sweep, level by level, in the order of the tables (see :func:`check_base`)."""
    check_base(axis, sensors, trailer)
    prints = {v: vehicle_fingerprint(v) for v in vehicles}
    codes = {c: code_fingerprint(c) for c in controllers}
    return [RunSpec(axis.name, lv, s, v, c, int(seed), prints[v], truth, realtime, sensors,
                    trailer, codes[c])
            for lv in levels for s in scenarios for v in vehicles for c in controllers
            for seed in seeds]


def run_one(spec: RunSpec, recordings: str | None = None) -> dict:
    """One run of a sweep: its scores row, with ``axis`` and ``level`` (a worker's task)."""
    from artic.validation.docking.run import drive
    from artic.validation.docking.scenarios import scenario

    axis = AXES[spec.axis]
    record = None if recordings is None else Path(recordings) / f"{spec.name}.rrd"
    keywords = {"sensor_set": spec.sensors, "trailer": spec.trailer,
                **axis.keywords(spec.level)}
    row = drive(scenario(spec.scenario), spec.vehicle, spec.controller, spec.seed,
                record=record, truth=spec.truth, realtime=spec.realtime, **keywords).row
    return stored({"axis": spec.axis, "level": spec.level, **row})


def run_in_child(spec: RunSpec, recordings: str | None = None) -> dict:
    """:func:`run_one` in a forked child (a cluster's task): a run that ends it is a row.

    A controller that ends its process then fails its run with the exit code or the
    signal, as on the local executor, instead of killing the cluster's worker.
    """
    from artic.validation.docking.supervise import ChildEnded, in_child

    try:
        return in_child(run_one, spec, recordings)  # type: ignore[return-value]
    except ChildEnded as exc:
        return _failed(spec, str(exc))


def _failed(spec: RunSpec, reason: str) -> dict:
    from artic.validation.docking.run import failed_row

    row = failed_row(spec.scenario, spec.vehicle, spec.controller, spec.seed, spec.truth,
                     reason, spec.sensors, spec.trailer)
    return stored({"axis": spec.axis, "level": spec.level, **row})


def stored(row: dict) -> dict:
    """``row`` as a run file keeps it: plain numbers, without the per-command compute times."""
    out = {}
    for k, v in row.items():
        if k == "solve_ms":
            continue
        if isinstance(v, np.generic):
            v = v.item()
        out[k] = v
    return out


RETRIED = ("controller hang:", "controller ended the run's process",
           "run failed on the cluster")
"""How the failures begin that the supervisor or the cluster gave a run, rather than the run
itself: a hang (a first call that compiles on a loaded machine can be one), a worker that
died, a cluster worker lost. Their runs are run again when the sweep resumes."""


def done_runs(folder: Path, specs: Sequence[RunSpec]) -> dict[str, dict]:
    """The rows of ``specs`` already in ``folder``, by run name: same request, same file.

    A run failed by its supervisor or the cluster (:data:`RETRIED`) is not done, nor one
    whose recording could not be written (a full disk): the resumed sweep records it.
    """
    out = {}
    for spec in specs:
        p = folder / f"{spec.name}.json"
        try:
            stored = json.loads(p.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue  # not run, or unreadable: run it (again)
        if stored.get("spec") == json.loads(json.dumps(spec.as_dict())) \
                and not str(stored["row"].get("failure") or "").startswith(RETRIED) \
                and not stored["row"].get("recording_error"):
            out[spec.name] = stored["row"]
    return out


def _other_runs(folder: Path, specs: Sequence[RunSpec]) -> list[Path]:
    """Remove the run files in ``folder`` that ``specs`` do not list; return them.

    A sweep of the same axis planned again (other levels, starts or controllers) left them;
    beside the new tables they would pass for its runs. A sweep of another axis is refused
    before anything is removed: its runs are another study's.

    Raises
    ------
    UserError
        When the folder holds runs of another axis, naming it and the way out.
    """
    if not folder.is_dir() or not specs:
        return []
    keep = {f"{s.name}.json" for s in specs}
    axis = specs[0].axis
    stale = [p for p in sorted(folder.glob("*.json")) if p.name not in keep]
    axes = sorted({p.name.split("=", 1)[0] for p in stale} - {_safe_axis(axis)})
    if axes:
        raise UserError(f"{folder.parent}: holds the runs of a sweep of {', '.join(axes)} "
                        f"({len(stale)} run file(s) in {folder}); a sweep of {axis} there "
                        "would mix the two: choose another --out-dir, or remove that folder")
    for p in stale:
        p.unlink(missing_ok=True)
    return stale


def _safe_axis(axis: str) -> str:
    from artic.validation.docking.run import _safe

    return _safe(axis)


def write_run(folder: Path, spec: RunSpec, row: dict) -> Path:
    """The run's file, atomically: a killed sweep leaves whole files or none."""
    from artic.validation.logs.runfile import atomic_write_text

    return atomic_write_text(folder / f"{spec.name}.json",
                             json.dumps({"spec": spec.as_dict(), "row": row}))


def execute(specs: Sequence[RunSpec], jobs: int = 1, executor: str = "local",
            scheduler: str | None = None, dask=None, recordings: Path | None = None,
            deadline: float | None = None,
            device: str | None = None) -> Iterator[tuple[RunSpec, dict]]:
    """``(spec, row)`` of each run as it finishes.

    Parameters
    ----------
    specs : sequence of RunSpec
        The runs.
    jobs : int
        Local worker processes (or a local Dask cluster's).
    executor : str
        ``"local"``: the docking benchmark's supervised workers
        (:func:`artic.validation.docking.supervise.supervised`); ``"dask"``: the
        campaign's Dask executor, where a run that raises or ends its worker is a
        failed row with the error.
    scheduler : str, optional
        A running Dask scheduler's address.
    dask : DaskOptions, optional
        Its timeout and TLS files.
    recordings : Path, optional
        Folder for one recording per run.
    deadline : float, optional
        Longest controller call [s] (local only).
    device : str, optional
        The Warp device (``"cuda"``, ``"cpu"``) of runs on the Warp plant
        (batch by batch, :data:`WORLDS_PER_BATCH` worlds at most; no recordings);
        ``None``: the CPU plant.
    """
    if device is not None:
        yield from _on_warp(specs, device)
        return
    rec = None if recordings is None else str(recordings)
    by_name = {s.name: s for s in specs}
    if executor == "local":
        from artic.validation.docking.supervise import supervised

        tasks = [(s.name, (s, rec)) for s in specs]
        with contextlib.closing(supervised(run_one, tasks, jobs,
                                           lambda key, args, why: _failed(args[0], why),
                                           deadline)) as done:
            for name, row in done:
                yield by_name[name], row
        return
    from artic.validation.plumbing.executors import cluster_executor

    with cluster_executor(executor, jobs, scheduler, dask) as pool:
        futures = {pool.submit(run_in_child, s, rec): s for s in specs}
        try:
            for f in concurrent.futures.as_completed(futures):
                s = futures[f]
                try:
                    row = f.result()
                except Exception as exc:  # noqa: BLE001 - a lost worker or a raising run
                    row = _failed(s, "run failed on the cluster: "
                                     + one_line(f"{type(exc).__name__}: {exc}"))
                yield s, row
        finally:
            for f in futures:
                f.cancel()


WORLDS_PER_BATCH = 4096
"""Most runs of one vehicle a sweep puts on one Warp plant; more go in further batches."""


def _on_warp(specs: Sequence[RunSpec], device: str) -> Iterator[tuple[RunSpec, dict]]:
    """``(spec, row)`` of each run on the Warp plant, batch by batch (:func:`execute`).

    The runs of one vehicle go in batches of at most :data:`WORLDS_PER_BATCH` worlds,
    fewer where their records would not fit the device
    (:func:`~artic.validation.docking.warp_dock.runs_that_fit`; a batch's plant holds one
    model layout):
    :func:`artic.validation.docking.warp_dock.dock_batch`.
    """
    from artic.validation.docking.scenarios import scenario
    from artic.validation.docking.spec import DockRun, split_options
    from artic.validation.docking.warp_dock import dock_batch, runs_that_fit

    by_vehicle: dict[str, list[RunSpec]] = {}
    for s in specs:
        by_vehicle.setdefault(s.vehicle, []).append(s)
    longest = max((scenario(s.scenario).timeout for s in specs), default=0.0)
    size = min(WORLDS_PER_BATCH, runs_that_fit(longest, device)) if specs else 1
    for group in by_vehicle.values():
        for at in range(0, len(group), size):
            chunk = group[at:at + size]
            runs, conds = [], []
            for s in chunk:
                options, c = split_options({"sensor_set": s.sensors, "trailer": s.trailer,
                                            **AXES[s.axis].keywords(s.level)})
                runs.append(DockRun(scenario(s.scenario), s.vehicle, s.controller, s.seed,
                                    **options))
                conds.append(c)
            for s, res in zip(chunk, dock_batch(runs, conds, device), strict=True):
                yield s, stored({"axis": s.axis, "level": s.level, **res.row})


def sweep(specs: Sequence[RunSpec], out: Path, jobs: int = 1, executor: str = "local",
          scheduler: str | None = None, dask=None, recordings: Path | None = None,
          progress: Callable[[str], None] | None = None,
          deadline: float | None = None, device: str | None = None) -> list[dict]:
    """Run the sweep's runs not yet done in ``out``; every run's row, in ``specs``' order.

    Each run's row is written to ``out/sweep_runs`` as it finishes
    (:func:`write_run`), so an interrupted sweep resumes (:func:`done_runs`). With
    ``device`` the runs go to the Warp plant on that device (:func:`execute`).
    """
    from artic.validation.plumbing.progress import Counter

    folder = Path(out) / RUNS_DIR
    others = _other_runs(folder, specs)
    folder.mkdir(parents=True, exist_ok=True)
    if others and progress is not None:
        progress(f"removed {len(others)} run file(s) in {folder} of runs this sweep does not "
                 f"list (an earlier plan's levels, starts or controllers): "
                 f"{', '.join(p.name for p in others[:3])}" + (", ..." if len(others) > 3
                                                                else ""))
    rows = done_runs(folder, specs)
    todo = [s for s in specs if s.name not in rows]
    if progress is not None:
        where = (f"{jobs} local process{'es' if jobs > 1 else ''}" if executor == "local"
                 else f"Dask ({scheduler or f'a local cluster of {jobs}'})")
        if device is not None:
            where = f"the Warp plant ({device})"
        progress(f"sweep {specs[0].axis if specs else ''}: {len(specs)} runs"
                 + (f", {len(rows)} already done in {folder} (resumed)" if rows else "")
                 + (f", {len(todo)} to run on {where}" if todo else ""))
    counter = Counter(len(todo), f"sweep {specs[0].axis if specs else ''}", progress)
    for spec, row in execute(todo, jobs, executor, scheduler, dask, recordings, deadline,
                             device):
        write_run(folder, spec, row)
        rows[spec.name] = row
        counter.step(f"{spec.axis}={level_text(spec.level)} {spec.scenario} "
                     f"{row['vehicle']} {spec.controller} seed {spec.seed}: "
                     + ("docked" if row["success"] else str(row["failure"])))
    return [rows[s.name] for s in specs]


# ---------------------------------------------------------------- the tables
def _rate(prefix: str, k: int, n: int) -> dict:
    from artic.validation.docking.scores import rate_ci

    iv = rate_ci(k, n)
    return {prefix: iv.mean, f"{prefix}_lo": iv.lo, f"{prefix}_hi": iv.hi}


def _mean(prefix: str, x: np.ndarray) -> dict:
    from artic.validation.criteria.statistics import mean_ci

    iv = mean_ci(x)
    return {prefix: iv.mean, f"{prefix}_lo": iv.lo, f"{prefix}_hi": iv.hi}


GROUP = ["axis", "level", "scenario", "vehicle", "controller"]


def summarise(rows: pd.DataFrame) -> pd.DataFrame:
    """``sweep.csv``: one row per axis, level, scenario, vehicle and controller (module doc)."""
    from artic.validation.criteria.statistics import mean_ci
    from artic.validation.docking.scores import TIERS

    out = []
    rows = rows.assign(_finished=finished(rows), _level=rows["level"].map(level_text))
    for (axis_, _lv, scen, veh, ctrl), g in rows.groupby(
            ["axis", "_level", "scenario", "vehicle", "controller"], sort=False):
        axis = AXES.get(axis_)
        ok = g[g["_finished"]]
        rec = {"axis": axis_, "unit": axis.unit if axis else "", "level": g["level"].iloc[0],
               "scenario": scen, "vehicle": veh, "controller": ctrl, "runs": len(g),
               "docked": int(g["success"].astype(bool).sum())}
        rec |= _rate("success", rec["docked"], len(g))
        for t in TIERS:
            rec |= _rate(t.column, int(g[t.column].astype(bool).sum()), len(g))
        rec["finished"] = len(ok)
        for name, col, scale in ERRORS:
            rec |= _mean(name, scale * np.abs(ok[col].to_numpy(dtype=float)))
        rec["interval"] = mean_ci(np.abs(ok["lateral_error_m"].to_numpy(dtype=float))).method
        fail = g["failure"].fillna("").astype(str)
        rec["jackknifes"] = int(fail.str.startswith("jackknife").sum())
        rec["collisions"] = int(fail.str.startswith("collision").sum())
        rec["timeouts"] = int(fail.str.startswith("timeout").sum())
        rec |= _mean("time_s", ok["time_s"].to_numpy(dtype=float))
        out.append(rec)
    return pd.DataFrame(out)


def compare(rows: pd.DataFrame, controllers: Sequence[str]) -> pd.DataFrame:
    """``sweep_pairs.csv``: every two controllers at each level, scenario and vehicle.

    :func:`artic.validation.docking.pairs.compare` at each level (its ``level``
    as the rows give it), one Holm family over the whole sweep.
    """
    rows = rows.assign(_level=rows["level"].map(level_text))
    t = pairs.compare(rows, controllers, by=("axis", "_level", "scenario", "vehicle"))
    level = rows.groupby("_level", sort=False)["level"].first()
    t.insert(1, "level", t.pop("_level").map(level))
    return t


def findings(found: pd.DataFrame) -> list[str]:
    """The comparisons resolved after Holm's correction, in words."""
    return [pairs.finding_words(r, f"at {r.axis} = {level_text(r.level)} ({r.scenario}, "
                                   f"{r.vehicle})")
            for r in found[found["finding"].astype(bool)].itertuples(index=False)]


def markdown(summary: pd.DataFrame, found: pd.DataFrame) -> str:
    """``sweep.md``: the table, and the findings after Holm's correction."""
    from artic.validation.criteria.statistics import format_ci
    from artic.validation.docking.scores import TIERS
    from artic.validation.docking.scores import markdown as md_table

    def ci(r, prefix):
        return format_ci(r[prefix], r[f"{prefix}_lo"], r[f"{prefix}_hi"])

    recs = []
    for _, r in summary.iterrows():
        unit = f" [{r['unit']}]" if r["unit"] and r["unit"] != "-" else ""
        rec = {f"{r['axis']}{unit}": level_text(r["level"]), "scenario": r["scenario"],
               "vehicle": r["vehicle"], "controller": r["controller"], "runs": r["runs"],
               "success [95 % CI]": ci(r, "success")}
        for t in TIERS:
            rec[t.label] = ci(r, t.column)
        rec["|lateral| [cm]"] = ci(r, "lateral_cm")
        rec["|heading| [deg]"] = ci(r, "heading_deg")
        rec["jackknifes"], rec["collisions"] = r["jackknifes"], r["collisions"]
        rec["time [s]"] = ci(r, "time_s")
        recs.append(rec)
    text = md_table(pd.DataFrame(recs)) if recs else ""
    if not len(found):  # say why, rather than a bare 0
        controllers = summary["controller"].nunique() if len(summary) else 0
        why = ("one controller: a comparison pairs two controllers over the same starts; "
               "give --controller A,B" if controllers < 2
               else "no level has two controllers' runs of the same starts")
        return text + f"\nPaired comparisons: none ({why}).\n"
    text += pairs.summary(found, findings(found), "sweep_pairs.csv")
    return text
