"""The main job: the validation campaign on the embedded default.

Stages, each timed and each resumable:

1. **logs**: the synthetic measured campaign (:mod:`artic.validation.synthetic.generate`),
   generated on first use into ``OUT/synthetic`` and imported in memory through
   the same importer as real logs (no imported copy is kept: importing an
   export takes as long as reading one); meanwhile numba compiles
   the reduced models ahead in a process of its own (:mod:`artic.validation.runs.warmup`);
2. **tuning**: every model's parameters fitted per load condition on its
   forward tuning manoeuvres (:mod:`artic.validation.campaign.tuning`; which
   ones, ``CampaignConfig.tuning``, ``--tuning``); ``OUT/tuning.json``,
   and one tuned vehicle file per load condition in ``OUT/params``;
3. **validation**: every model through the closed-loop harness on every other
   log, with its load condition's tuned vehicle; ``OUT/runs``, ``metrics.csv``
   (with the criteria of :mod:`artic.validation.criteria`; the fixed scale of
   ``eps_n_fixed``, from the validated logs, in ``OUT/eps_n_fixed_scale.json``);
4. **references**: the two references' own numbers. The *floor*: the truth
   that made each log without its random processes (for the independent truth
   its own model, tyres, column and play; ``truth-LOAD.toml`` with each
   manoeuvre's yard slope), through the same harness against the same logs, a
   ``floor`` row in ``metrics.csv``; no model can beat it, and a model's gap
   above it is its model-form error. And
   *the plant as reference*: KIN and STM against the plant's runs of the same
   manoeuvres (forward open loop, reverse under the harness), into
   ``metrics_vs_plant.csv`` and ``OUT/vs_plant/runs``;
   **twins** (with noisy sensors): every model and the floor on the
   noise-free twins of the validated logs, the same truth runs measured with
   ideal sensors (made by the logs' own simulations), into
   ``OUT/twins/metrics.csv``; no recordings;
   **oracle**: KIN, the STM and the plant untuned with the truth's own
   parameters (:mod:`artic.validation.campaign.oracle`) on the validated logs,
   rows ``kin-oracle``, ... in ``metrics_oracle.csv`` (``--no-oracle`` skips it);
5. **tables**: the paper's Table 2 and Table 3 columns, overall and per load,
   with the floor row (``table2_forward``, ``table3_reverse``), and the same
   against the plant (``table2_vs_plant``, ``table3_vs_plant``), ``.csv`` and ``.md``;
   the paired comparisons with Holm's correction and the findings
   (:mod:`artic.validation.campaign.findings`), and the noise share of every
   criterion (``noise_share_forward``, ``noise_share_reverse``); the same per
   manoeuvre class, with the classes that carry each pooled finding
   (:mod:`artic.validation.campaign.classes`, ``*_by_class``), and each model's
   error split into form and parameters (``form_forward``, ``form_reverse``);
6. **efficiency**: wall time per simulated second of each model, from the
   validation runs' own times (``efficiency.csv``);
7. **gain sweep**: the reverse criteria against K (``gain_sweep.csv``, ``plots/gain_sweep.png``);
8. **recordings**: one ``.rrd`` per manoeuvre and ``recordings/campaign.rrd``,
   drawn on worker processes started before the tables (stage 5), which computes
   on one core, and collected here (:mod:`artic.validation.campaign.recordings`);
   **pbs**: the PBS low-speed turn on each model and the truth (``pbs_truck.csv``),
   started beside the recordings on worker processes of its own;
9. **report**: ``report.md``, written last.

Resuming. Every stage goes through one cache
(:mod:`artic.validation.campaign.cache`): its entry holds the key of its
inputs (artic's code, the :class:`~artic.validation.campaign.config.CampaignConfig`
fields it depends on, the keys of the stages it reads) and its outputs; a
stage whose entry matches and whose outputs are intact is reused whole, and
each stage returns a :class:`~artic.validation.campaign.cache.StageResult`
saying whether it was. A stage that computes resumes inside itself from what
an interrupted run finished (the exports, the fits in ``tuning.json``, the run
files, each carrying the stage's key), so an interrupted campaign picks up
where it stopped. ``report.md`` is deleted when a run starts and written only
when every stage has finished, and every file is written atomically, so no
half-written result looks complete. Tuning is saved after every (load, model)
fit, so a campaign killed while tuning keeps the fits it finished. An
export that no longer imports (a table cut short) is generated again.

Several trucks: ``seeds=N`` (``artic campaign --seeds N``) runs one such
campaign per seed in ``OUT/seed-K`` and pools them in ``OUT``
(:mod:`artic.validation.campaign.seeds`); one seed writes into ``OUT`` itself.

One campaign at a time per output folder: a second one is refused, naming the
first (:class:`artic.validation.plumbing.outputs.OutDirLock`). The temporaries a killed
campaign left behind are removed when the next one starts.

A (log, model) pair that fails becomes a row of ``metrics.csv`` with its
status; a model whose tuning fails keeps the preset's values and says so.
The tables and the report use the pairs with results.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import threading
import time
import zlib
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Executor, Future, ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pandas as pd

from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import Vehicle, load_vehicle
from artic.mjcf.writer import fitted_changes, updated, write_vehicle
from artic.validation.campaign import findings, frequency
from artic.validation.campaign.cache import Entry, StageCache, StageResult
from artic.validation.campaign.config import SENSORS, CampaignConfig
from artic.validation.campaign.executors import cluster_executor
from artic.validation.campaign.recordings import Recordings
from artic.validation.campaign.seeds import run_seeds
from artic.validation.criteria.fixedscale import SCALE_FILE, campaign_scale, write_scale
from artic.validation.criteria.multiplicity import CORRECTION
from artic.validation.logs.importers import import_source
from artic.validation.logs.runfile import (
    LogError,
    Run,
    atomic_write,
    atomic_write_text,
    check_frame,
    read_run,
)
from artic.validation.models import code_of
from artic.validation.plumbing import fingerprint
from artic.validation.plumbing.budget import BUDGET, budget_text
from artic.validation.plumbing.outputs import OutDirLock, clean_stale
from artic.validation.review.tables import (
    paired_markdown,
    paired_table,
    summary,
    write_table,
)
from artic.validation.runs import warmup
from artic.validation.runs.validate import (
    is_failed,
    stderr_progress,
    validate_runs,
    write_metrics,
)
from artic.validation.synthetic.generate import META_FILE, export_folders, exports_as_written
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import TUNING
from artic.validation.synthetic.truth import DEFAULT as DEFAULT_TRUTH

LOADS = ("unloaded", "loaded")
PRESET = "gosar2022-{load}"


TIMINGS = "timings.json"
"""Wall times of the stages and the efficiency figures as first measured, with the run's key."""


class Stages:
    """Wall time and simulated time per stage, with progress lines.

    A stage that only reused earlier results (see :meth:`reused`) reports the
    wall time it took when it was computed, from ``saved``, so that a resumed
    campaign's report matches the original run's; likewise its simulated
    time (:data:`artic.validation.plumbing.budget.BUDGET` counted over the stage),
    from ``saved_budget``. ``save`` receives the times, the budgets and
    which stages were reused after every stage.
    """

    def __init__(self, progress: Callable[[str], None], saved: dict[str, float] | None = None,
                 save: Callable[[dict[str, float], dict[str, dict], dict[str, bool]], None]
                 | None = None,
                 saved_budget: dict[str, dict] | None = None) -> None:
        self.times: dict[str, float] = {}
        self.budget: dict[str, dict[str, tuple[int, float]]] = {}
        self.progress = progress
        self.saved = dict(saved or {})
        self.saved_budget = dict(saved_budget or {})
        self.save = save
        self._name = ""
        self._t0 = 0.0
        self._b0: dict[str, tuple[int, float]] = {}
        self._reused = False

    def __call__(self, name: str) -> Stages:
        """Name the stage the next ``with`` block times."""
        self._name = name
        return self

    def reused(self, yes: bool = True) -> None:
        """Mark the current stage as one that computed nothing new."""
        self._reused = yes

    def all_reused(self) -> bool:
        """Whether every stage so far was reused."""
        return all(self._was.values())

    def __enter__(self) -> Stages:
        self._t0 = time.perf_counter()
        self._b0 = BUDGET.snapshot()
        self._reused = False
        if not hasattr(self, "_was"):
            self._was: dict[str, bool] = {}
        self.progress(f"== {self._name}")
        return self

    def __exit__(self, *exc) -> None:
        measured = time.perf_counter() - self._t0
        counted = BUDGET.since(self._b0)
        if exc[0] is not None:
            return
        name = self._name
        self._was[name] = self._reused
        if self._reused and name in self.saved:
            self.times[name] = self.saved[name]
            self.budget[name] = {k: tuple(v) for k, v in self.saved_budget.get(name, {}).items()}
            self.progress(f"== {name}: reused ({measured:.1f} s now; the {self.saved[name]:.1f} s "
                          "it took when computed are kept)")
        else:
            self.times[name] = measured
            self.budget[name] = counted
            simulated = budget_text(counted)
            self.progress(f"== {name}: {measured:.1f} s" + (f"; {simulated}" if simulated else ""))
        if self.save is not None:
            self.save(self.times, self.budget, self._was)


TWINS = "twins"
"""The folder of the noise-free twins' exports (``synthetic``), imports (``logs``),
runs (``runs``) and metrics, under the campaign's output folder."""


def load_logs(out_dir: Path, seed: int = 0, jobs: int = 1,
              only: list[str] | None = None, executor: Executor | None = None,
              truth: str = DEFAULT_TRUTH) -> list[Run]:
    """Generate (or reuse) the synthetic campaign and import it (or reuse the import).

    The logs alone: no noise-free twins are made (the campaign makes them).
    """
    return _load_logs(out_dir, seed, jobs, only, executor, truth, twins=False)[0]


def _sensor_model(sensors: str) -> SensorModel:
    """``--sensors``: the campaign's measurement chain by name (``default`` or ``ideal``)."""
    if sensors not in SENSORS:
        raise UserError(f"--sensors {sensors}: expected default or ideal")
    return SensorModel.ideal() if sensors == "ideal" else SensorModel()


def _load_logs(out_dir: Path, seed: int, jobs: int, only: list[str] | None,
               executor: Executor | None, truth: str = DEFAULT_TRUTH,
               sensors: str = "default", drift: bool = True, twins: bool = True
               ) -> tuple[list[Run], list[Run] | None]:
    """:func:`load_logs` and the twins.

    With noisy sensors every log's noise-free twin (the same truth run
    measured with ideal sensors) is exported into ``OUT/twins/synthetic`` by
    the same simulation; with ideal sensors the logs are noise-free
    themselves and there are no twins (``None``); ``twins=False`` makes none
    either. The exports are imported in memory, through the same importer as
    real logs, every time the stage computes: importing one takes as long as
    reading a stored import, which the campaign therefore does not keep. An
    export that no longer imports (a table cut short) is generated again.
    """
    chain = _sensor_model(sensors)
    where = None if chain.is_ideal or not twins else out_dir / TWINS / "synthetic"
    runs: dict[Path, Run] = {}
    damaged: list[Path] = []

    def imported(folders: list[Path]) -> None:
        got, bad = _import(folders)
        runs.update(got)
        damaged.extend(bad)

    def generate() -> Iterator[list[Path]]:
        return exports_as_written(out_dir / "synthetic", seed=seed, progress=stderr_progress,
                                  jobs=jobs, only=only, executor=executor, truth=truth,
                                  sensors=chain, drift=drift, twins=where)

    # a fresh export is imported as soon as it is written, while the workers
    # simulate the next manoeuvres, instead of on one core after the last
    for written in generate():
        imported(written)
    exports = export_folders(out_dir / "synthetic", only)
    folders = exports + ([where / f.name for f in exports] if where is not None else [])
    imported([f for f in folders if f not in runs and f not in damaged])  # the ones reused
    if damaged:  # generated again (export and twin together), then imported once more
        for folder in damaged:
            (folder / META_FILE).unlink(missing_ok=True)
        for _ in generate():  # imported below, together
            pass
        again, still = _import(damaged)
        if still:
            raise LogError(f"{still[0]}: generated again, and still does not import")
        runs.update(again)
    logs = [runs[f] for f in exports]
    return logs, (None if where is None else [runs[where / f.name] for f in exports])


def _import(exports: list[Path]) -> tuple[dict[Path, Run], list[Path]]:
    """Import exports in memory; the runs by folder, and the folders that did not import."""
    runs, damaged = {}, []
    for folder in exports:
        try:
            run, report = import_source(folder)
        except (LogError, OSError, EOFError, ValueError, zlib.error) as exc:
            stderr_progress(f"{folder}: does not import ({exc}); generated again")
            damaged.append(folder)
            continue
        for line in report:
            stderr_progress(f"repaired: {line}")
        runs[folder] = run
    return runs, damaged


def _read_json(path: Path) -> dict | None:
    """A JSON object saved by an earlier run, or ``None`` if absent or unreadable."""
    if not path.is_file():
        return None
    try:
        saved = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError) as exc:
        stderr_progress(f"{path}: unreadable ({type(exc).__name__}); computed again")
        return None
    return saved if isinstance(saved, dict) else None


def start_from(model: str, fitted: dict[str, dict[str, float]]) -> dict[str, float] | None:
    """Where the plant's fit starts: the STM's fitted steering ratio and offset.

    They describe the truth's steering column, which every model sees alike;
    the asymmetry ``q`` stays the plant's own (its linkage makes it), and the
    STM's ``f`` has no counterpart. Other models start from their presets.
    """
    if model != "mbd" or "stm" not in fitted:
        return None
    return {k: fitted["stm"][k] for k in ("i_s", "delta_h_offset") if k in fitted["stm"]}


def _tune(out_dir: Path, logs: list[Run], models: Sequence[str], key: str,
          jobs: int, names: Sequence[str] = TUNING) -> dict:
    """Tuning per load condition, resumable per (load, model) from ``tuning.json``.

    Each load condition is tuned on its own tuning manoeuvres with its own
    preset. A load condition without tuning logs (a part of the campaign)
    keeps the preset's values, and says so. ``tuning.json`` is written after
    every (load, model) fit with the fits so far; a rerun with the same key
    reuses them and fits only the rest. A model whose fit fails keeps the
    preset's values; its summary row says why.

    The load conditions are fitted side by side, on ``jobs // 2`` threads
    each (one each on two cores): their fits are independent, and one
    load's Python (the optimiser's steps, the residuals) then runs while the
    other's models compute, where one after the other left a core idle in
    each fit's serial part. The fits do not depend on the threads.
    """
    path = out_dir / "tuning.json"
    saved = _read_json(path)
    if saved is None or saved.get("key") != key or not isinstance(saved.get("loads"), dict):
        saved = {"key": key, "loads": {}}
    elif saved.get("complete"):
        stderr_progress(f"tuning reused from {path} (fitted earlier with the same code and "
                        "settings)")
        saved["reused"] = True
        return saved
    run = _Tuning(path, {"key": key, "loads": {}, "complete": False})
    todo = _tuning_plan(logs, saved, run.out, names)
    side_by_side = max(1, min(len(todo), jobs))  # no tuning logs: nothing to fit, untuned
    threads = max(1, jobs // side_by_side)
    if side_by_side > 1:
        with ThreadPoolExecutor(side_by_side, thread_name_prefix="artic-tune") as pool:
            futures = [pool.submit(_tune_load, run, models, *t, threads) for t in todo]
            try:
                for f in futures:
                    f.result()
            except BaseException:  # interrupted, or a fit raised: the fits running end theirs
                run.stop.set()
                raise
    else:
        for t in todo:
            _tune_load(run, models, *t, threads)
    run.out["complete"] = True
    run.save()
    run.out["reused"] = False
    return run.out


@dataclasses.dataclass
class _Tuning:
    """Tuning under way: the fits so far (``out``), saved to ``path`` after each fit."""

    path: Path
    out: dict
    lock: threading.Lock = dataclasses.field(default_factory=threading.Lock)
    """Guards ``out`` and ``tuning.json`` between the load conditions' threads."""
    stop: threading.Event = dataclasses.field(default_factory=threading.Event)
    """Set when the campaign is interrupted: no further fit starts."""

    def save(self) -> None:
        """Write the fits so far (hold :attr:`lock`, or be the only thread)."""
        atomic_write_text(self.path, json.dumps(self.out, indent=1) + "\n")


def _tuning_plan(logs: list[Run], saved: dict, out: dict, names: Sequence[str] = TUNING
                 ) -> list[tuple[str, Vehicle, list[Run], dict | None]]:
    """Each load condition to tune: its preset, tuning logs and the saved part to resume.

    Its entry in ``out["loads"]`` is made here; a load condition without
    tuning logs keeps its preset and says so.
    """
    todo = []
    for load in LOADS:
        tuning = [log for log in logs if log.name in names and log.meta.get("load") == load]
        if not tuning:
            stderr_progress(f"{load}: no tuning manoeuvre among the logs; the preset's "
                            "parameters are used untuned")
            continue
        fitted_on = [log.name for log in tuning]
        part = saved["loads"].get(load)
        if not (isinstance(part, dict) and part.get("logs") == fitted_on):
            part = None
        vehicle = load_vehicle(PRESET.format(load=load))
        out["loads"][load] = {"logs": fitted_on, "rows": [], "summary": [], "fitted": {},
                              "truth": tuning[0].meta.get("truth", {}),
                              "nominal": {"i_s": vehicle.steering_for("mbd").i_s}}
        todo.append((load, vehicle, tuning, part))
    return todo


def _tune_load(run: _Tuning, models: Sequence[str], load: str, vehicle: Vehicle,
               tuning: list[Run], part: dict | None, threads: int) -> None:
    """Fit every model on one load condition's logs, or take its fit from ``part``."""
    from artic.validation.campaign.tuning import tune_model  # here: scipy.optimize takes 0.7 s

    entry = run.out["loads"][load]
    for m in models:
        if run.stop.is_set():
            return
        done = [r for r in (part or {}).get("summary", []) if r.get("model") == m]
        if done:
            with run.lock:
                entry["rows"] += [r for r in part.get("rows", []) if r.get("model") == m]
                entry["summary"] += done
                if m in part.get("fitted", {}):
                    entry["fitted"][m] = part["fitted"][m]
            stderr_progress(f"{load}: tuning of {m} reused from {run.path}")
            continue
        stderr_progress(f"{load}: tuning {m} on {len(tuning)} logs")
        try:
            with run.lock:
                start = start_from(m, entry["fitted"])
            fit = tune_model(m, vehicle, tuning, threads,
                             lambda line: stderr_progress(f"{load}: {line}"), start=start)
        except (MemoryError, RecursionError):
            raise
        except Exception as exc:  # noqa: BLE001 - one model's failure is a row
            why = " ".join(str(exc).split()) or type(exc).__name__
            stderr_progress(f"{load}: tuning {m} failed ({why}); its preset values are used")
            row = {"load": load, "model": m, "status": f"failed: {why}"}
            with run.lock:
                entry["summary"].append(row)
                run.save()
        else:
            with run.lock:
                entry["rows"] += [{"load": load, **row} for row in fit.rows()]
                entry["fitted"][m] = fit.fitted
                entry["summary"].append(
                    {"load": load, "model": m, "eps_n_before": fit.eps_n_before,
                     "eps_n_after": fit.eps_n_after, "cost_before": fit.cost_before,
                     "cost_after": fit.cost_after, "evaluations": fit.evaluations,
                     "wall_s": fit.wall_s, "status": "ok"})
                run.save()


def _tuned_vehicles(out_dir: Path, tuned: dict, seed: int) -> dict[str, Vehicle]:
    out = {}
    for load in LOADS:
        base = load_vehicle(PRESET.format(load=load))
        part = tuned["loads"].get(load)
        if part is None:
            out[load] = base
            continue
        data = updated(PRESET.format(load=load), fitted_changes(base, part["fitted"]),
                       f"Tuned by artic on the synthetic campaign (seed {seed}), on the "
                       f"{load} forward tuning manoeuvres {', '.join(part['logs'])}: see "
                       "tuning.json beside this file's folder", name=f"{base.name}-tuned")
        out[load] = write_vehicle(data, out_dir / "params" / f"{base.name}.tuned.toml")
    return out


def run_campaign(config: CampaignConfig | Path | str, /, **options: Any) -> dict[str, Path]:
    """Run the campaign; see the module docstring.

    Parameters
    ----------
    config : CampaignConfig or Path
        The campaign (:class:`artic.validation.campaign.config.CampaignConfig`),
        or its output folder, the other choices then given as keywords.
    **options
        With an output folder: the other fields of
        :class:`~artic.validation.campaign.config.CampaignConfig` (``models``,
        ``seed``, ``jobs``, ``only``, ``gain``, ``sweep_models``, ``recordings``,
        ``executor``, ``scheduler``, ``dask``, ``truth``, ``remeasure``,
        ``seeds``, ``closing``, ``sensors``, ``drift``, ``oracle``, ``tuning``).

    Returns
    -------
    dict
        Result files by name.

    Raises
    ------
    UserError
        A bad option (one line naming it), before anything is written.

    See Also
    --------
    artic.CampaignConfig : its choices.
    artic.validate_runs : validate models on logs of your own.

    Notes
    -----
    The PBS stage and the recordings run on new worker processes (``spawn``),
    which import the calling script's main module again, as every pool does
    on macOS: call this from a script under ``if __name__ == "__main__":``.

    Examples
    --------
    A part of the campaign (a forward tuning log and a reverse ramp steer, KIN
    alone, no recordings), in a few seconds:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import artic
    >>> out = Path(tempfile.mkdtemp())
    >>> paths = artic.run_campaign(out, models=("kin",), only=["00-", "28-"],
    ...                            recordings=False, sweep_models=(), closing=False)
    >>> paths["report"].name, paths["table3"].exists()
    ('report.md', True)
    """
    if isinstance(config, CampaignConfig):
        if options:
            config = dataclasses.replace(config, **options)
    else:
        config = CampaignConfig(Path(config), **options)
    if config.seeds > 1:
        return run_seeds(config, run_campaign)
    config = config.resolved()
    out_dir = config.out_dir
    out_dir.mkdir(parents=True, exist_ok=True)
    key = config.key()
    state = _saved_timings(out_dir, key)

    def save(times: dict[str, float], budget: dict[str, dict], reused: dict[str, bool]) -> None:
        state["stages"] = {**state["stages"], **times}
        state["budget"] = {**state.get("budget", {}), **budget}
        state["reused"] = dict(reused)
        atomic_write_text(out_dir / TIMINGS, json.dumps(state, indent=1) + "\n")

    with contextlib.ExitStack() as stack:
        stack.enter_context(OutDirLock(out_dir, "campaign"))
        stale = clean_stale(out_dir)
        if stale:
            stderr_progress(f"removed {len(stale)} temporary file(s) left by an interrupted run")
        (out_dir / "report.md").unlink(missing_ok=True)
        pool = stack.enter_context(cluster_executor(config.executor, config.jobs,
                                                    config.scheduler, config.dask))
        stage = Stages(stderr_progress, state["stages"], save, state.get("budget"))
        stderr_progress(f"artic campaign: models {', '.join(config.models or ())}, seed "
                        f"{config.seed}, K = {config.gain:g}, {config.jobs} jobs "
                        f"({config.executor}), output {out_dir}"
                        + (f", sensors {config.sensors}" if config.sensors != "default" else "")
                        + ("" if config.drift else ", no drift"))
        return _run_stages(_Campaign(config, pool, StageCache(out_dir, stderr_progress), stage))


def _saved_timings(out_dir: Path, key: str) -> dict:
    """The stage times an earlier run with ``key`` measured, if any."""
    path = out_dir / TIMINGS
    empty = {"key": key, "stages": {}}
    if not path.is_file():
        return empty
    try:
        saved = json.loads(path.read_text())
    except (OSError, ValueError):
        return empty
    return saved if saved.get("key") == key else empty


@dataclasses.dataclass
class _Campaign:
    """One campaign under way: its choices, executor, cache and stage timer."""

    config: CampaignConfig
    pool: Executor | None
    cache: StageCache
    timer: Stages
    results: dict[str, StageResult] = dataclasses.field(default_factory=dict)
    replays: dict = dataclasses.field(default_factory=dict)
    """The floor's replay runs on the measured logs, by log name, for the twins to reuse
    (:class:`artic.validation.criteria.prediction.ReplayRuns`); emptied by the twins."""

    @property
    def out_dir(self) -> Path:
        return self.config.out_dir

    @property
    def models(self) -> tuple[str, ...]:
        return self.config.models or ()

    @property
    def jobs(self) -> int:
        return self.config.jobs or 1

    def fields(self, *names: str) -> dict[str, Any]:
        """The config fields ``names`` (what a stage's key depends on).

        With ``models``, a registered model's own code fingerprint joins them:
        its code is not artic's.
        """
        out = {n: getattr(self.config, n) for n in names}
        if "models" in names:
            out["outside"] = {m: code for m in self.models if (code := code_of(m))}
        return out

    def run(self, name: str, key: str, compute: Callable[[], tuple[dict[str, Path], dict, Any]],
            restore: Callable[[Entry], Any], *, force: bool = False) -> StageResult:
        """Time stage ``name``: its entry's outputs if valid (``restore``), else ``compute``.

        ``compute`` returns the outputs to record, a JSON payload and the value;
        ``restore`` makes the value from a valid entry. ``force`` computes anyway.
        """
        with self.timer(name):
            entry = None if force else self.cache.lookup(name, key)
            value = None
            if entry is not None:
                try:
                    value = restore(entry)
                except (LogError, OSError, ValueError, KeyError, TypeError) as exc:
                    stderr_progress(f"{name}: its cached outputs do not read ({exc}); the "
                                    "stage computes again")
                    entry = None
            if entry is not None:
                stderr_progress(f"{name} reused from {self.cache.path(name)} (made earlier "
                                "with the same code and inputs)")
                result = StageResult(name, key, True, entry.outputs, value)
            else:
                self.cache.forget(name)
                outputs, data, value = compute()
                self.cache.store(name, key, outputs, data)
                result = StageResult(name, key, False, dict(outputs), value)
            self.timer.reused(result.reused)
        self.results[name] = result
        release_memory()
        return result

    def derived(self, name: str, make: Callable[[], Any]) -> StageResult:
        """A presentation stage (tables, report): drawn on every run from its inputs.

        Its files are not cached: the fingerprint leaves presentation code out,
        so a cached table would outlive an edit of the code that draws it. It
        counts as reused when every stage before it was.
        """
        with self.timer(name):
            reused = all(r.reused for r in self.results.values())
            value = make()
            self.timer.reused(reused)
        self.results[name] = StageResult(name, "", reused, {}, value)
        release_memory()
        return self.results[name]


def release_memory() -> None:
    """Collect what a finished stage left unreferenced and give freed heap back to the system.

    Between stages, for the campaign's peak memory: a stage's temporaries (the
    runs' frames, the models' MuJoCo data) are freed in cycles that only the
    collector breaks, and glibc keeps freed arenas mapped until ``malloc_trim``
    returns them. Elsewhere than glibc the trim is skipped. Nothing computed
    depends on it.
    """
    import ctypes
    import gc
    import sys

    gc.collect()
    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL("libc.so.6").malloc_trim(0)
        except (OSError, AttributeError):  # not glibc (musl has no malloc_trim)
            pass


def _stage_logs(c: _Campaign) -> StageResult:
    """Stage 1: the logs (and their noise-free twins); value ``(logs, twin_logs)``.

    Its outputs are the exports' files; reused, the exports are imported again
    (the campaign keeps no imported copy, see :func:`_load_logs`).
    """
    key = c.cache.key("logs", c.fields("seed", "only", "truth", "sensors", "drift"))

    def compute():
        cfg = c.config
        logs, twin_logs = _load_logs(c.out_dir, cfg.seed, c.jobs,
                                     list(cfg.only) if cfg.only else None, c.pool, cfg.truth,
                                     cfg.sensors, cfg.drift)
        return (_export_files(c.out_dir, logs, twin_logs), {"twins": twin_logs is not None},
                (logs, twin_logs))

    def restore(entry: Entry):
        folders = {kind: list(dict.fromkeys(p.parent for n, p in entry.outputs.items()
                                            if n.startswith(f"{kind}:")))
                   for kind in ("log", "twin")}
        runs, damaged = _import(folders["log"] + folders["twin"])
        if damaged:
            raise LogError(f"{damaged[0]}: does not import")
        twins = [runs[f] for f in folders["twin"]]
        return [runs[f] for f in folders["log"]], (twins if entry.data.get("twins") else None)

    return c.run("logs", key, compute, restore)


def _export_files(out_dir: Path, logs: list[Run], twin_logs: list[Run] | None
                  ) -> dict[str, Path]:
    """The exports' files (and their twins') by name, in the logs' order."""
    files = {}
    for kind, root, runs in (("log", out_dir / "synthetic", logs),
                             ("twin", out_dir / TWINS / "synthetic", twin_logs or [])):
        for log in runs:
            for f in sorted((root / log.name).iterdir()):
                files[f"{kind}:{log.name}/{f.name}"] = f
    return files


def _tuning_key(c: _Campaign, logs_key: str) -> str:
    return c.cache.key("tuning", c.fields("models", "seed", "tuning"), [logs_key])


def _stage_tuning(c: _Campaign, logs: StageResult) -> StageResult:
    """Stage 2: the fits per load; value ``(tuned, vehicles, tuning_logs)``."""
    key = _tuning_key(c, logs.key)

    def value(tuned: dict, vehicles: dict[str, Vehicle]):
        return tuned, vehicles, {n for part in tuned["loads"].values() for n in part["logs"]}

    def compute():
        tuned = _tune(c.out_dir, logs.value[0], c.models, key, c.jobs, c.config.tuning_logs())
        vehicles = _tuned_vehicles(c.out_dir, tuned, c.config.seed)
        outputs = {"tuning": c.out_dir / "tuning.json"}
        outputs |= {f"params:{load}": Path(v.path) for load, v in vehicles.items()
                    if load in tuned["loads"]}
        return outputs, {}, value(tuned, vehicles)

    def restore(entry: Entry):
        tuned = json.loads(entry.outputs["tuning"].read_text(encoding="utf-8"))
        vehicles = {load: load_vehicle(entry.outputs[f"params:{load}"])
                    if f"params:{load}" in entry.outputs
                    else load_vehicle(PRESET.format(load=load)) for load in LOADS}
        return value(tuned, vehicles)

    return c.run("tuning", key, compute, restore)


def _stage_validation(c: _Campaign, logs: StageResult, tuning: StageResult) -> StageResult:
    """Stage 3: every model on every validated log; value ``(metrics, scale, validated)``."""
    key = c.cache.key("validation", c.fields("models", "gain"), [logs, tuning])
    _, vehicles, tuning_logs = tuning.value
    validated = [log for log in logs.value[0] if log.name not in tuning_logs]
    scale = campaign_scale(validated)  # one scale for every row of eps_n_fixed

    def metrics() -> pd.DataFrame:
        parts = []
        for load in LOADS:
            group = [log for log in validated if log.meta.get("load") == load]
            if group:
                parts.append(validate_runs(group, vehicles[load], c.models, gain=c.config.gain,
                                           out_dir=c.out_dir, progress=stderr_progress,
                                           reuse_key=f"{key}.{load}", jobs=c.jobs,
                                           executor=c.pool, label=f"validation, {load}",
                                           scale=scale))
        return pd.concat(parts, ignore_index=True)

    def compute():
        m = metrics()
        outputs = {"eps_n_fixed_scale": write_scale(scale, c.out_dir / SCALE_FILE)}
        outputs |= _run_files(c.out_dir, m)
        return outputs, {}, (m, scale, validated)

    return c.run("validation", key, compute, lambda entry: (metrics(), scale, validated))


def _run_files(root: Path, metrics: pd.DataFrame) -> dict[str, Path]:
    """The run file of each (log, model) row of ``metrics`` under ``root/runs``, by name."""
    return {f"run:{r.log}.{r.model}": root / "runs" / f"{r.log}.{r.model}.parquet"
            for r in metrics.itertuples()}


def _stage_references(c: _Campaign, logs: StageResult, tuning: StageResult,
                      validation: StageResult) -> StageResult:
    """Stage 4: the floor and the plant as reference; value ``(metrics, vs_plant)``."""
    cfg = c.config
    key = c.cache.key("references", c.fields("models", "gain", "seed", "truth"),
                      [logs, tuning, validation])
    metrics, scale, validated = validation.value
    vehicles = tuning.value[1]
    load_of = {log.name: log.meta.get("load") for log in logs.value[0]}

    def tables() -> tuple[pd.DataFrame, pd.DataFrame | None, pd.DataFrame]:
        # The floor's runs as their metadata (criteria, key): the tables read no
        # more, and no recording draws them.
        floor = _floor(c.out_dir, validated, _Settings.of(c, key, scale), samples=False,
                       replays=c.replays)
        both = pd.concat([metrics, floor], ignore_index=True)
        both["load"] = both["log"].map(load_of)
        vs_plant = None
        if "mbd" in c.models:
            reduced = [m for m in c.models if m != "mbd"]
            vs_plant = _versus_plant(c.out_dir, validated, vehicles, reduced, cfg.gain, key,
                                     c.jobs, scale)
            if vs_plant is not None:
                vs_plant["load"] = vs_plant["log"].map(load_of)
        return both, vs_plant, floor

    def compute():
        both, vs_plant, floor = tables()
        outputs = {"metrics": write_metrics(both, c.out_dir / "metrics.csv")}
        outputs |= _run_files(c.out_dir, floor)
        if vs_plant is not None:
            outputs["metrics_vs_plant"] = write_metrics(vs_plant,
                                                        c.out_dir / "metrics_vs_plant.csv")
            outputs |= _run_files(c.out_dir / "vs_plant", vs_plant)
        return outputs, {}, (both, vs_plant)

    return c.run("references", key, compute, lambda entry: tables()[:2])


def _stage_twins(c: _Campaign, logs: StageResult, tuning: StageResult,
                 validation: StageResult) -> StageResult:
    """Stage 4b: every model and the floor on the noise-free twins; value the metrics."""
    key = c.cache.key("twins", c.fields("models", "gain", "seed", "truth"),
                      [logs, tuning, validation])
    _, vehicles, tuning_logs = tuning.value
    scale = validation.value[1]
    load_of = {log.name: log.meta.get("load") for log in logs.value[0]}

    def table() -> pd.DataFrame:
        try:
            twins = _twins(c.out_dir, logs.value[1], tuning_logs, vehicles, c.models,
                           _Settings.of(c, key, scale), c.replays)
        finally:
            c.replays.clear()  # the twins were their only use
        twins["load"] = twins["log"].map(load_of)
        return twins

    def compute():
        twins = table()
        outputs = {"metrics_twins": write_metrics(twins, c.out_dir / TWINS / "metrics.csv")}
        outputs |= _run_files(c.out_dir / TWINS, twins)
        return outputs, {}, twins

    return c.run("twins", key, compute, lambda entry: table())


ORACLE_DIR = "oracle"
"""The folder of the oracle rows' runs (their metadata) under the campaign's output folder."""


def _has_oracle(c: _Campaign) -> bool:
    """Whether the campaign runs oracle rows: asked for, a truth that has them, a model of them."""
    from artic.validation.campaign import oracle

    if not c.config.oracle:
        return False
    if not oracle.applies(c.config.truth):
        stderr_progress(f"oracle rows: the {c.config.truth} truth has no TMeasy tyres to take "
                        "the cornering stiffness from; no oracle rows")
        return False
    return any(m in oracle.MODELS for m in c.models)


def _stage_oracle(c: _Campaign, logs: StageResult, validation: StageResult) -> StageResult:
    """Stage 4c: KIN, the STM and the plant untuned with the truth's own parameters.

    On the validated logs only, not on their twins (the form's findings are
    resolved on the logs, see :func:`artic.validation.campaign.oracle.form_pairs`);
    the oracle vehicles go to ``OUT/params/oracle-LOAD.toml``, the runs' metadata
    to ``OUT/oracle/runs``, the rows (``kin-oracle``, ...) to ``metrics_oracle.csv``.
    Value: those rows.
    """
    from artic.validation.campaign import oracle

    cfg = c.config
    models = [m for m in c.models if m in oracle.MODELS]
    key = c.cache.key("oracle", c.fields("models", "gain", "seed", "truth", "oracle"),
                      [logs, validation])
    _, scale, validated = validation.value
    load_of = {log.name: log.meta.get("load") for log in logs.value[0]}

    def table(saved: dict[str, Path] | None = None) -> tuple[pd.DataFrame, dict[str, Path]]:
        # Computing, the oracle vehicles are written; restoring, read back (writing
        # them again would change the outputs the cache entry checks).
        parts, files = [], {}
        for load in LOADS:
            group = [log for log in validated if log.meta.get("load") == load]
            if not group:
                continue
            path = c.out_dir / "params" / f"oracle-{load}.toml"
            files[f"params_oracle:{load}"] = path
            vehicle = load_vehicle(saved[f"params_oracle:{load}"]) if saved is not None \
                else oracle.oracle_vehicle(load, cfg.seed, cfg.truth, path)
            parts.append(validate_runs(group, vehicle, models, gain=cfg.gain,
                                       out_dir=c.out_dir / ORACLE_DIR, progress=stderr_progress,
                                       reuse_key=f"{key}.{load}.oracle", jobs=c.jobs,
                                       executor=c.pool, label=f"oracle, {load}", scale=scale,
                                       samples=False))
        rows = pd.concat(parts, ignore_index=True)
        files |= _run_files(c.out_dir / ORACLE_DIR, rows)
        rows["model"] = rows["model"] + oracle.ORACLE
        rows["load"] = rows["log"].map(load_of)
        return rows, files

    def compute():
        rows, files = table()
        files["metrics_oracle"] = write_metrics(rows, c.out_dir / "metrics_oracle.csv")
        return files, {}, rows

    return c.run("oracle", key, compute, lambda entry: table(entry.outputs)[0])


@dataclasses.dataclass
class _Tables:
    """What the tables stage computed, for the report."""

    forward: pd.DataFrame
    reverse: pd.DataFrame
    forward_p: pd.DataFrame | None
    reverse_p: pd.DataFrame | None
    paired: dict[str, pd.DataFrame]
    shares: dict[str, pd.DataFrame | None]
    headlines: dict[str, Any]
    per_load: dict[str, pd.DataFrame]
    files: dict[str, Path]
    classes: dict[str, Any] = dataclasses.field(default_factory=dict)
    """Per direction: ``table`` (per class), ``paired`` (per class), ``answer`` (docking,
    parking), and ``tuning`` (the tuning classes)."""
    oracle: dict[str, Any] = dataclasses.field(default_factory=dict)
    """Per direction: ``split`` (form and parameters) and ``pairs`` (the form's findings)."""


def _stage_tables(c: _Campaign, metrics: pd.DataFrame, vs_plant: pd.DataFrame | None,
                  twins: pd.DataFrame | None, oracle_rows: pd.DataFrame | None = None,
                  tuning_logs: set[str] | frozenset[str] = frozenset()) -> StageResult:
    """Stage 5: Tables 2 and 3 (and against the plant), paired comparisons, noise share.

    Then the same per manoeuvre class, with the classes that carry each pooled
    finding, and each model's error split into form and parameters.
    """
    out_dir = c.out_dir

    def make() -> _Tables:
        files: dict[str, Path] = {}
        forward, reverse = summary(metrics, "forward"), summary(metrics, "reverse")
        files["table2"], _ = write_table(forward, out_dir / "table2_forward",
                                         "Forward driving (the paper's Table 2 columns)")
        files["table3"], _ = write_table(reverse, out_dir / "table3_reverse",
                                         "Reverse driving (the paper's Table 3 columns)")
        forward_p = reverse_p = None
        if vs_plant is not None:
            forward_p, reverse_p = summary(vs_plant, "forward"), summary(vs_plant, "reverse")
            files["table2_vs_plant"], _ = write_table(
                forward_p, out_dir / "table2_vs_plant",
                "Forward driving against the plant as reference (Table 2 columns)")
            files["table3_vs_plant"], _ = write_table(
                reverse_p, out_dir / "table3_vs_plant",
                "Reverse driving against the plant as reference (Table 3 columns)")
        paired, shares, headlines = _paired(out_dir, metrics, vs_plant, twins, files)
        per_load = {f"{load}, {d}": t for load in LOADS for d in ("forward", "reverse")
                    if len(t := summary(metrics[metrics["load"] == load], d))}
        per_class = _by_class(out_dir, metrics, vs_plant, twins, paired, tuning_logs, files)
        form = _form(out_dir, metrics, oracle_rows, files)
        _write_answer(out_dir, per_class, form, files)
        return _Tables(forward, reverse, forward_p, reverse_p, paired, shares, headlines,
                       per_load, files, per_class, form)

    result = c.derived("tables", make)
    return dataclasses.replace(result, outputs=result.value.files)


def _paired(out_dir: Path, metrics: pd.DataFrame, vs_plant: pd.DataFrame | None,
            twins: pd.DataFrame | None, files: dict[str, Path]
            ) -> tuple[dict[str, pd.DataFrame], dict[str, pd.DataFrame | None], dict[str, Any]]:
    """The paired comparisons, findings and noise shares; their files go into ``files``."""
    paired, shares, headlines = {}, {}, {}
    for d in ("forward", "reverse"):
        twin_pairs = paired_table(twins, d) if twins is not None else None
        paired[d] = findings.mark(paired_table(metrics, d), twin_pairs)
        shares[d] = findings.noise_share(metrics, twins, d) if twins is not None else None
        headlines[d] = findings.headline_criteria(paired[d], shares[d])
        if shares[d] is not None and len(shares[d]):
            files[f"noise_share_{d}"], _ = write_table(
                shares[d].set_index("model"), out_dir / f"noise_share_{d}",
                f"Noise share, {d}: each criterion on the logs, on their noise-free twins, "
                "and the difference (paired per manoeuvre)",
                findings.share_markdown(shares[d]))
    if vs_plant is not None:
        # The plant's runs carry no sensor noise: findings are the corrected rankings.
        paired["forward_vs_plant"] = findings.mark(paired_table(vs_plant, "forward"), None)
        paired["reverse_vs_plant"] = findings.mark(paired_table(vs_plant, "reverse"), None)
    for name, pairs in paired.items():
        if len(pairs):
            files[f"paired_{name}"], _ = write_table(
                pairs.set_index("criterion"), out_dir / f"paired_{name}",
                f"Paired comparisons, {name.replace('_vs_plant', ', against the plant')}; "
                f"{CORRECTION} over the table's {len(pairs)} comparisons, findings "
                + ("resolved after it on the logs and on their noise-free twins"
                   if twins is not None and "_vs_plant" not in name else
                   "resolved after it"), paired_markdown(pairs))
    return paired, shares, headlines


def _by_class(out_dir: Path, metrics: pd.DataFrame, vs_plant: pd.DataFrame | None,
              twins: pd.DataFrame | None, paired: dict[str, pd.DataFrame],
              tuning_logs: set[str] | frozenset[str], files: dict[str, Path]) -> dict[str, Any]:
    """The tables per manoeuvre class (:mod:`artic.validation.campaign.classes`).

    ``table2_forward_by_class``, ``table3_reverse_by_class`` (and against the
    plant), ``paired_DIRECTION_by_class``, ``noise_share_DIRECTION_by_class``
    (with twins); the pooled paired tables gain
    ``carried_by`` (leave one class out) and are written again. Their files go
    into ``files``.
    """
    from artic.validation.campaign import classes

    tuning = classes.tuning_classes(tuning_logs)
    out: dict[str, Any] = {"tuning": tuning}
    stems = {"forward": "table2_forward", "reverse": "table3_reverse"}
    for d, stem in stems.items():
        table = classes.by_class(metrics, d, tuning)
        if table.empty:
            continue
        files[f"{stem}_by_class"], _ = write_table(
            table, out_dir / f"{stem}_by_class",
            f"{d.capitalize()} driving per manoeuvre class", classes.class_markdown(table))
        per = classes.paired_by_class(metrics, twins, d, tuning)
        if per:
            text = "\n\n".join(f"## {k}\n\n{paired_markdown(p)}" for k, p in per.items())
            both = pd.concat([p.assign(**{classes.CLASS: k}) for k, p in per.items()])
            files[f"paired_{d}_by_class"], _ = write_table(
                both.set_index("criterion"), out_dir / f"paired_{d}_by_class",
                f"Paired comparisons per manoeuvre class, {d}; {CORRECTION} over each "
                "class's own table", text)
        if twins is not None:
            shares = {}
            for kind in classes.classes_of(metrics, d):
                share = findings.noise_share(metrics[metrics["manoeuvre"] == kind],
                                             twins[twins["manoeuvre"] == kind], d)
                if len(share):
                    shares[classes.class_name(kind, tuning)] = share
            if shares:
                files[f"noise_share_{d}_by_class"], _ = write_table(
                    pd.concat([v.assign(**{classes.CLASS: k}) for k, v in shares.items()])
                    .set_index("model"), out_dir / f"noise_share_{d}_by_class",
                    f"Noise share per manoeuvre class, {d}",
                    "\n\n".join(f"## {k}\n\n{findings.share_markdown(v)}"
                                for k, v in shares.items()))
        if d in paired and len(paired[d]):
            paired[d] = classes.carried_by(paired[d], metrics, twins, d, tuning)
            files[f"paired_{d}"], _ = write_table(
                paired[d].set_index("criterion"), out_dir / f"paired_{d}",
                f"Paired comparisons, {d}; {CORRECTION} over the table's {len(paired[d])} "
                "comparisons; the classes that carry each finding (leave one class out)",
                paired_markdown(paired[d]))
        out[d] = {"table": table, "paired": per,
                  "answer": classes.answer(table, per, tuning=tuning) if d == "reverse" else []}
        if vs_plant is not None:
            against = classes.by_class(vs_plant, d, tuning)
            if len(against):
                files[f"{stem}_vs_plant_by_class"], _ = write_table(
                    against, out_dir / f"{stem}_vs_plant_by_class",
                    f"{d.capitalize()} driving per manoeuvre class, against the plant",
                    classes.class_markdown(against))
    return out


ANSWER = "docking_parking.md"
"""The paper's question answered for docking and parking on their own (the report's section)."""


def _write_answer(out_dir: Path, per_class: dict[str, Any], form: dict[str, Any],
                  files: dict[str, Path]) -> None:
    """``docking_parking.md``: the report's answer for docking and parking, on its own."""
    from artic.validation.campaign.report import articulation_lines

    lines = articulation_lines(per_class, form)
    if lines:
        files["docking_parking"] = atomic_write_text(
            out_dir / ANSWER, "# " + lines[0].removeprefix("## ") + "\n" +
            "\n".join(lines[1:]) + "\n")


def _form(out_dir: Path, metrics: pd.DataFrame, oracle_rows: pd.DataFrame | None,
          files: dict[str, Path]) -> dict[str, Any]:
    """Each model's error split into form and parameters, and the form's findings."""
    from artic.validation.campaign import oracle

    if oracle_rows is None or oracle_rows.empty:
        return {}
    both = oracle.oracle_metrics(metrics, oracle_rows)
    out: dict[str, Any] = {}
    for d in ("forward", "reverse"):
        split, pairs = oracle.split(both, d), oracle.form_pairs(both, d)
        if split.empty:
            continue
        files[f"form_{d}"], _ = write_table(
            split, out_dir / f"form_{d}",
            f"{d.capitalize()}: each model's excess over the floor split into its form "
            "(the oracle row minus the floor) and its parameters (the tuned row minus the "
            "oracle row), paired per manoeuvre")
        if len(pairs):
            files[f"paired_{d}_oracle"], _ = write_table(
                pairs.set_index("criterion"), out_dir / f"paired_{d}_oracle",
                f"Paired comparisons of the oracle rows (model form), {d}; {CORRECTION} over "
                f"the table's {len(pairs)} comparisons, on the logs", paired_markdown(pairs))
        rows = both[both["model"].str.endswith(oracle.ORACLE) | (both["model"] == "floor")]
        out[d] = {"split": split, "pairs": pairs, "table": summary(rows, d)}
        if d == "reverse":  # the form's answer for docking and parking, from the oracle rows
            from artic.validation.campaign import classes

            per_class = classes.by_class(rows, d)
            out[d]["answer"] = classes.answer(per_class, classes.paired_by_class(rows, None, d))
    return out


def _stage_efficiency(c: _Campaign, metrics: pd.DataFrame) -> StageResult:
    """Stage 6: wall time per simulated second, from the validation runs' own times.

    Its key is the campaign's (:meth:`CampaignConfig.key`), not the runs': a
    resumed campaign keeps the figures as first measured, though a run it
    simulated again has a new time; ``remeasure`` measures them again.
    """
    from artic.validation.campaign.efficiency import from_runs

    key = c.cache.key("efficiency", {"campaign": c.config.key()})
    path = c.out_dir / "efficiency.csv"

    def compute():
        eff = from_runs(metrics, c.models, c.out_dir / "runs")
        atomic_write(path, lambda p: eff.to_csv(p, float_format="%.6g"))
        return {"efficiency": path}, {"rows": eff.reset_index().to_dict(orient="records")}, eff

    def restore(entry: Entry) -> pd.DataFrame:
        return pd.DataFrame(entry.data["rows"]).set_index("model")

    return c.run("efficiency", key, compute, restore, force=c.config.remeasure)


def _stage_sweep(c: _Campaign, logs: StageResult, tuning: StageResult) -> StageResult:
    """Stage 7: the reverse criteria against K (the table and the plot)."""
    from artic.validation.runs.gainsweep import DEFAULT_GAINS, gain_sweep, plot_gain_sweep

    models = [m for m in c.config.sweep_models if m in c.models]
    key = c.cache.key("gain sweep", {"sweep_models": models, "gain": c.config.gain,
                                     "outside": c.fields("models")["outside"]}, [logs, tuning])
    table, plot = c.out_dir / "gain_sweep.csv", c.out_dir / "plots" / "gain_sweep.png"
    vehicles = tuning.value[1]

    def compute():
        rev = {load: (vehicles[load], [log for log in logs.value[0]
                                       if log.meta.get("load") == load
                                       and log.meta.get("direction") == "reverse"])
               for load in LOADS}
        sweep = gain_sweep(rev, models, DEFAULT_GAINS, c.jobs, stderr_progress)
        atomic_write(table, lambda p: sweep.to_csv(p, index=False, float_format="%.6g"))
        plot_gain_sweep(sweep, plot, c.config.gain)
        data = {"K_min": sweep.attrs["K_min"], "rows": sweep.to_dict(orient="records")}
        return {"gain_sweep": table, "gain_sweep_plot": plot}, data, sweep

    def restore(entry: Entry) -> pd.DataFrame:
        sweep = pd.DataFrame(entry.data["rows"])
        sweep.attrs["K_min"] = entry.data["K_min"]
        return sweep

    return c.run("gain sweep", key, compute, restore)


def _recordings_key(c: _Campaign, logs: StageResult, tuning: StageResult,
                    references: StageResult) -> str:
    return c.cache.key("recordings", c.fields("models"), [logs, tuning, references])


def _start_recordings(c: _Campaign, logs: StageResult, tuning: StageResult,
                      references: StageResult) -> Recordings | None:
    """The recordings the recordings stage will compute, started now; ``None`` if reused.

    Their workers draw while the tables stage computes on one core (see
    :mod:`artic.validation.campaign.recordings`).
    """
    if c.cache.lookup("recordings", _recordings_key(c, logs, tuning, references),
                      quiet=True) is not None:
        return None
    by_name = {log.name: log for log in logs.value[0]}
    return Recordings(c.out_dir, references.value[0], by_name, tuning.value[1], c.models,
                      c.jobs)


def _stage_recordings(c: _Campaign, logs: StageResult, tuning: StageResult,
                      references: StageResult, started: Recordings | None) -> StageResult:
    """Stage 8: one ``.rrd`` per validated manoeuvre and a plot of a few.

    ``started``: the recordings :func:`_start_recordings` started, collected
    here when the stage computes (and stopped when it reuses its entry).
    """
    key = _recordings_key(c, logs, tuning, references)

    def compute():
        made = (started if started is not None else _start_recordings(c, logs, tuning,
                                                                      references)).collect()
        return {f"recording:{n}": p for n, p in made.items()}, {}, None

    with contextlib.ExitStack() as stack:
        if started is not None:
            stack.enter_context(started)
        result = c.run("recordings", key, compute, lambda entry: None)
    return dataclasses.replace(result, outputs={"recordings": c.out_dir / "recordings"})


def _run_stages(c: _Campaign) -> dict[str, Path]:
    """Every stage in order (see the module docstring); the result files by name."""
    cfg = c.config
    # numba compiles the reduced models' loop and the criteria on a core of its
    # own while the logs are made, instead of on the critical path of tuning
    # (not when tuning will be reused: it then compiles nothing).
    logs_key = c.cache.key("logs", c.fields("seed", "only", "truth", "sensors", "drift"))
    warm = None
    if c.pool is None and set(c.models) & {"kin", "stm"} and c.cache.lookup(
            "tuning", _tuning_key(c, logs_key), quiet=True) is None:
        warm = warmup.start()
    logs = _stage_logs(c)
    if warm is not None:  # a wait for it counts as tuning's, which needs it
        warm.join()
        if warm.exitcode:
            stderr_progress(f"compiling ahead failed (exit code {warm.exitcode}); numba "
                            "compiles on first use instead")
    tuning = _stage_tuning(c, logs)
    validation = _stage_validation(c, logs, tuning)
    references = _stage_references(c, logs, tuning, validation)
    metrics, vs_plant = references.value
    twins = _stage_twins(c, logs, tuning, validation) if logs.value[1] is not None else None
    logs = _without_twin_logs(c, logs)
    oracle = _stage_oracle(c, logs, validation) if _has_oracle(c) else None
    started = _start_recordings(c, logs, tuning, references) if cfg.recordings else None
    pbs = _start_pbs(c)
    with contextlib.ExitStack() as stack:  # a failing stage stops the recordings' workers
        if started is not None:
            stack.enter_context(started)
        tables = _stage_tables(c, metrics, vs_plant,
                               twins.value if twins is not None else None,
                               oracle.value if oracle is not None else None, tuning.value[2])
        efficiency = _stage_efficiency(c, metrics)
        swept = frequency.write(c.out_dir, validation.value[2])  # the swept sine's responses
        sweep = _stage_sweep(c, logs, tuning) if cfg.sweep_models else None
        recordings = _stage_recordings(c, logs, tuning, references, started) \
            if cfg.recordings else None
    # The result files by name (a stage's single runs and recordings are not named here).
    paths = {k: v for r in (tuning, validation, references, twins, oracle, tables, efficiency,
                            sweep, recordings) if r is not None
             for k, v in r.outputs.items() if ":" not in k and k != "gain_sweep_plot"} | swept
    paths["pbs_truck"] = _stage_pbs(c, pbs).outputs["pbs_truck"]
    return _report(c, paths, tables.value, tuning.value[0], efficiency.value,
                   sweep.value if sweep is not None else None, metrics, vs_plant,
                   twins.value if twins is not None else None)


def _without_twin_logs(c: _Campaign, logs: StageResult) -> StageResult:
    """``logs`` without the noise-free twins' runs, which no stage after the twins reads.

    For the campaign's peak memory: the twins' frames (as large as the logs') would
    otherwise stay alive to the report, through the stages that draw the most. They
    hold no reference cycle, so they are freed here, and the next stages reuse their
    heap (no collection needed; the next stage's :func:`release_memory` trims it).
    """
    if logs.value[1] is None:
        return logs
    c.results["logs"] = dataclasses.replace(logs, value=(logs.value[0], None))
    return c.results["logs"]


def _pbs_key(c: _Campaign) -> str:
    return c.cache.key("pbs", c.fields("seed", "models", "truth"))


def _start_pbs(c: _Campaign) -> Future | None:
    """The PBS stage's table, started now on a thread of its own; ``None`` if reused.

    The thread only waits: the turns drive on new worker processes
    (:func:`_pbs_table`), which share the cores with the tables stage's one
    and the recordings' workers instead of running after them.
    """
    if c.cache.lookup("pbs", _pbs_key(c), quiet=True) is not None:
        return None
    pool = ThreadPoolExecutor(1, thread_name_prefix="artic-pbs")
    try:
        return pool.submit(_pbs_table, c)
    finally:
        pool.shutdown(wait=False)  # the thread ends with its one task


def _pbs_table(c: _Campaign) -> Path:
    from artic.validation.pbs.trucks import write_truck_table

    # on fresh processes: the truth's model and the reduced models' compiled
    # code would otherwise grow the campaign's process past its peak (85 MB)
    return write_truck_table(c.out_dir, c.config.seed, c.models, c.config.truth,
                             jobs=c.jobs, fresh=True)


def _stage_pbs(c: _Campaign, started: Future | None) -> StageResult:
    """Stage 8b: the low-speed measures of this truck's models against its truth.

    The PBS turn on each model and the truth (:mod:`artic.validation.pbs.trucks`),
    ``pbs_truck.csv``; it reads none of the other stages' outputs (the loaded
    preset, untuned), so its key is the truck, the models and the truth.
    ``started``: the table :func:`_start_pbs` started, waited for here
    (``None``: computed here).
    """

    def compute():
        path = started.result() if started is not None else _pbs_table(c)
        return {"pbs_truck": path}, {}, None

    return c.run("pbs", _pbs_key(c), compute, lambda entry: None)


def _report(c: _Campaign, paths: dict[str, Path], t: _Tables, tuned: dict,
            eff: pd.DataFrame, sweep: pd.DataFrame | None, metrics: pd.DataFrame,
            vs_plant: pd.DataFrame | None, twins: pd.DataFrame | None) -> dict[str, Path]:
    """Stage 9: ``report.md`` (and the summary recording), written last; the closing lines."""
    from artic.validation.campaign import report as rep

    cfg, out_dir, stage = c.config, c.out_dir, c.timer
    results = rep.CampaignResults(
        seed=cfg.seed, models=tuple(c.models), gain=cfg.gain, metrics=metrics,
        forward=t.forward, reverse=t.reverse, tuned=tuned["loads"], efficiency=eff, sweep=sweep,
        stages=stage.times, budget=stage.budget, fingerprint=fingerprint.code(),
        version=_version(), per_load=t.per_load,
        files={k: str(v.relative_to(out_dir)) for k, v in paths.items()},
        forward_vs_plant=t.forward_p, reverse_vs_plant=t.reverse_p, truth=cfg.truth,
        metrics_vs_plant=vs_plant, paired=t.paired, twins=twins, noise_share=t.shares,
        headline_criteria=t.headlines, sensors=cfg.sensors, drift=cfg.drift,
        classes=t.classes, form=t.oracle, pbs=_table(paths.get("pbs_truck")),
        departure=_table(paths.get("frequency_departure"), index_col=0))

    def draft() -> None:
        text = rep.render(results)  # the summary recording's copy, before the last timing
        if cfg.recordings:
            from artic.validation.review.recording import record_summary

            paths["summary_recording"] = record_summary(
                out_dir / "recordings" / "campaign.rrd", metrics, text)

    c.derived("report", draft)
    paths["report"] = atomic_write_text(out_dir / "report.md", rep.render(results))
    reused = [n for n, r in c.results.items() if r.reused]
    stderr_progress("stages reused: " + (", ".join(reused) or "none") + "; computed: "
                    + (", ".join(n for n in c.results if n not in reused) or "none"))
    failed = metrics[[is_failed(st) for st in metrics["status"]]]
    if cfg.closing:
        print(_closing_summary(t.forward, t.reverse, stage.times, paths["report"], len(failed),
                               stage.budget))
    return paths


def _table(path: Path | None, index_col: int | None = None) -> pd.DataFrame | None:
    """A table the campaign wrote, for the report; None where it wrote none."""
    return pd.read_csv(path, index_col=index_col) if path is not None else None


@dataclasses.dataclass(frozen=True)
class _Settings:
    """What the references' and the twins' runs share: the truck, the loop, the workers."""

    seed: int
    truth: str
    gain: float
    """K [rad/rad]."""
    key: str
    """The stage's key, the prefix of every run's reuse key."""
    jobs: int
    pool: Executor | None
    scale: dict | None
    """``eps_n_fixed``'s scale, the measured logs'."""

    @classmethod
    def of(cls, c: _Campaign, key: str, scale: dict | None) -> _Settings:
        """The settings of campaign ``c``'s stage of ``key``."""
        cfg = c.config
        return cls(cfg.seed, cfg.truth, cfg.gain, key, c.jobs, c.pool, scale)


def _floor(out_dir: Path, logs: list[Run], s: _Settings, samples: bool = True,
           replays: dict | None = None) -> pd.DataFrame:
    """The truth against the logs: the ``floor`` rows of the tables against logs.

    Each log's floor is the truth that made it (:func:`artic.validation.models.build`
    reads its metadata), from ``truth-LOAD.toml`` with the log's yard slope.
    ``replays``: the open-loop predictions' replay runs, kept and reused
    (:func:`artic.validation.runs.validate.validate_runs`).
    """
    from artic.validation.synthetic.truth import truth_configuration, truth_vehicle

    config = truth_configuration(s.seed, s.truth)
    made: dict[tuple[str, str], Vehicle] = {}

    def vehicle_of(log: Run) -> Vehicle:
        # Asked twice per log (the run, then its criteria), a few milliseconds each: made once.
        load, slope = log.meta["load"], log.meta.get("slope")
        key = (load, json.dumps(slope, sort_keys=True))
        if key not in made:
            made[key] = truth_vehicle(load, config, s.seed, slope)
        return made[key]

    return validate_runs(logs, vehicle_of, ["floor"], gain=s.gain, out_dir=out_dir,
                         progress=stderr_progress, reuse_key=f"{s.key}.floor", jobs=s.jobs,
                         executor=s.pool, label="references, the truth", scale=s.scale,
                         samples=samples, replays=replays)


def _twins(out_dir: Path, twin_logs: list[Run], tuning_logs: set[str],
           vehicles: dict[str, Vehicle], models: Sequence[str], s: _Settings,
           replays: dict | None = None) -> pd.DataFrame:
    """Every model and the floor on the noise-free twins of the validated logs.

    The same tuned vehicles, gain and ``eps_n_fixed`` scale as on the logs,
    so that a criterion's difference between a log and its twin is the
    measurement's alone. Runs go to ``OUT/twins/runs``, their metadata only
    (the criteria; ``validate_runs(samples=False)``); no recordings. The
    floor's open-loop predictions reuse the replay runs in ``replays`` (the
    measured logs', :func:`_floor`): a replay does not depend on the sensors.
    """
    twin_out = out_dir / TWINS
    validated = [log for log in twin_logs if log.name not in tuning_logs]
    parts = []
    for load in LOADS:
        group = [log for log in validated if log.meta.get("load") == load]
        if group:
            parts.append(validate_runs(group, vehicles[load], models, gain=s.gain,
                                       out_dir=twin_out, progress=stderr_progress,
                                       reuse_key=f"{s.key}.{load}.twins", jobs=s.jobs,
                                       executor=s.pool, label=f"twins, {load}", scale=s.scale,
                                       samples=False))
    parts.append(_floor(twin_out, validated, dataclasses.replace(s, key=f"{s.key}.twins"),
                        samples=False, replays=replays))
    out = pd.concat(parts, ignore_index=True)
    out.attrs["reused"] = sum(p.attrs.get("reused", 0) for p in parts)
    return out


def _versus_plant(out_dir: Path, logs: list[Run], vehicles: dict[str, Vehicle],
                  models: Sequence[str], gain: float, key: str,
                  jobs: int, scale: dict | None = None) -> pd.DataFrame | None:
    """KIN and STM against the plant's runs of the same manoeuvres, the plant as reference.

    The plant's run of a log (``runs/LOG.mbd.parquet``) becomes the reference
    log: its signals, the log's steering wheel and speed, and the log's
    metadata. It ran forward open loop and in reverse under the harness; the
    reduced models run through the same harness against it. ``eps_n_fixed``
    uses ``scale``, the measured logs' (the same unit as against the logs).
    Their run files hold the metadata only (``validate_runs(samples=False)``):
    the tables read the criteria, and the plant's reference run is in ``runs``.
    """
    from artic.validation.logs.schema import COLUMNS

    if not models:
        return None
    refs = []
    for log in logs:
        run = read_run(out_dir / "runs" / f"{log.name}.mbd.parquet", check=False,
                       columns=COLUMNS)
        if is_failed(str(run.meta.get("status", ""))) or len(run.frame) < 2:
            # The plant has no run of this log (its row in metrics.csv says why),
            # so there is nothing to compare KIN and STM with.
            stderr_progress(f"references: {log.name} has no plant run "
                            f"({run.meta.get('status', 'empty')}); left out against the plant")
            continue
        check_frame(run.frame, str(out_dir / "runs" / f"{log.name}.mbd.parquet"))
        meta = {**log.meta, "source": "model:mbd", "reference": "mbd"}
        refs.append(Run(run.frame[list(COLUMNS)].reset_index(drop=True), meta))
    parts = []
    for load in LOADS:
        group = [r for r in refs if r.meta.get("load") == load]
        if group:
            parts.append(validate_runs(group, vehicles[load], models, gain=gain,
                                       out_dir=out_dir / "vs_plant", progress=stderr_progress,
                                       reuse_key=f"{key}.{load}.vs_plant", jobs=jobs,
                                       label=f"references, {load}, against the plant",
                                       scale=scale, samples=False))
    if not parts:
        return None
    out = pd.concat(parts, ignore_index=True)
    out.attrs["reused"] = sum(p.attrs.get("reused", 0) for p in parts)
    return out


def _closing_summary(forward: pd.DataFrame, reverse: pd.DataFrame, times: dict[str, float],
                     report: Path, failed: int = 0,
                     budget: dict[str, dict] | None = None) -> str:
    """What the campaign prints at the end: the two tables, the stage times, the report."""
    from artic.validation.review.tables import markdown

    lines = []
    for title, table in (("Forward, mean over the validation manoeuvres (Table 2 columns)",
                          forward),
                         ("Reverse, mean over the validation manoeuvres (Table 3 columns)",
                          reverse)):
        if len(table):
            lines += [title, "", markdown(table, digits=3), ""]
    lines.append("Wall time: " + ", ".join(f"{k} {v:.0f} s" for k, v in times.items())
                 + f"; total {sum(times.values()):.0f} s.")
    simulated = {k: sec for k, b in (budget or {}).items()
                 if (sec := (b or {}).get("multibody", (0, 0.0))[1]) > 0}
    if simulated:
        lines.append("Multibody simulated time: " + ", ".join(
            f"{k} {v:.0f} s" for k, v in simulated.items())
            + f"; total {sum(simulated.values()):.0f} s.")
    if failed:
        lines.append(f"{failed} (manoeuvre, model) pair(s) have no result; report.md lists "
                     "them and why.")
    lines.append(f"The whole report, with the paper's values beside ours: {report}")
    return "\n".join(lines)


def _version() -> str:
    from artic.validation.review.recording import artic_version

    return artic_version()
