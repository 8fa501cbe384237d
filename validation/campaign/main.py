"""The main job: the validation campaign on the embedded default.

Stages, each timed and each resumable:

1. **logs**: the synthetic measured campaign (:mod:`artic.validation.synthetic.generate`),
   generated on first use into ``OUT/synthetic`` and imported through the
   same importer as real logs into ``OUT/logs``; meanwhile numba compiles
   the reduced models ahead in a process of its own (:mod:`artic.validation.runs.warmup`);
2. **tuning**: every model's parameters fitted per load condition on its 4
   forward tuning manoeuvres (:mod:`artic.validation.campaign.tuning`); ``OUT/tuning.json``,
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
5. **tables**: the paper's Table 2 and Table 3 columns, overall and per load,
   with the floor row (``table2_forward``, ``table3_reverse``), and the same
   against the plant (``table2_vs_plant``, ``table3_vs_plant``), ``.csv`` and ``.md``;
   the paired comparisons with Holm's correction and the findings
   (:mod:`artic.validation.campaign.findings`), and the noise share of every
   criterion (``noise_share_forward``, ``noise_share_reverse``);
6. **efficiency**: wall time per simulated second of each model, from the
   validation runs' own times (``efficiency.csv``);
7. **gain sweep**: the reverse criteria against K (``gain_sweep.csv``, ``plots/gain_sweep.png``);
8. **recordings**: one ``.rrd`` per manoeuvre and ``recordings/campaign.rrd``;
9. **report**: ``report.md``, written last.

Resuming. Every cached result carries a key: the hash of artic's code, the
seed, the models and the gain (:mod:`artic.validation.runs.fingerprint`). A rerun
reuses what matches and redoes the rest, so an interrupted campaign picks up
where it stopped. ``report.md`` is deleted when a run starts and written only
when every stage has finished, and every file is written atomically, so no
half-written result looks complete. Tuning is saved after every (load, model)
fit, so a campaign killed while tuning keeps the fits it finished. A cached
log that no longer reads is imported again from its export.

Several trucks: ``seeds=N`` (``artic campaign --seeds N``) runs one such
campaign per seed in ``OUT/seed-K`` and pools them in ``OUT``
(:mod:`artic.validation.campaign.seeds`); one seed writes into ``OUT`` itself.

One campaign at a time per output folder: a second one is refused, naming the
first (:class:`artic.validation.runs.outputs.OutDirLock`). The temporaries a killed
campaign left behind are removed when the next one starts.

A (log, model) pair that fails becomes a row of ``metrics.csv`` with its
status; a model whose tuning fails keeps the preset's values and says so.
The tables and the report use the pairs with results.
"""

from __future__ import annotations

import contextlib
import json
import os
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, ThreadPoolExecutor
from pathlib import Path

import pandas as pd

from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import Vehicle, load_vehicle
from artic.mjcf.writer import fitted_changes, updated, write_vehicle
from artic.validation.campaign import findings
from artic.validation.campaign.executors import DaskOptions, cluster_executor
from artic.validation.cli.progress import BUDGET, Counter, budget_text
from artic.validation.criteria.fixedscale import SCALE_FILE, campaign_scale, write_scale
from artic.validation.criteria.multiplicity import CORRECTION
from artic.validation.harness.loop import DEFAULT_GAIN
from artic.validation.logs.importers import import_source
from artic.validation.logs.runfile import (
    LogError,
    Run,
    atomic_write,
    atomic_write_text,
    check_frame,
    read_run,
    write_run,
)
from artic.validation.models import code_of, names
from artic.validation.review.tables import (
    paired_markdown,
    paired_table,
    summary,
    write_table,
)
from artic.validation.runs import fingerprint, warmup
from artic.validation.runs.outputs import OutDirLock, clean_stale
from artic.validation.runs.validate import (
    is_failed,
    stderr_progress,
    validate_runs,
    write_metrics,
)
from artic.validation.runs.workers import completed
from artic.validation.synthetic.generate import generate_campaign
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX, TUNING
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
    time (:data:`artic.validation.cli.progress.BUDGET` counted over the stage),
    from ``saved_budget``. ``save`` receives the times and the budgets after
    every stage.
    """

    def __init__(self, progress: Callable[[str], None], saved: dict[str, float] | None = None,
                 save: Callable[[dict[str, float], dict[str, dict]], None] | None = None,
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
            self.save(self.times, self.budget)


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
    if sensors not in ("default", "ideal"):
        raise UserError(f"--sensors {sensors}: expected default or ideal")
    return SensorModel.ideal() if sensors == "ideal" else SensorModel()


def _load_logs(out_dir: Path, seed: int, jobs: int, only: list[str] | None,
               executor: Executor | None, truth: str = DEFAULT_TRUTH,
               sensors: str = "default", drift: bool = True, twins: bool = True
               ) -> tuple[list[Run], bool, list[Run] | None]:
    """:func:`load_logs`, whether every log was reused as it was, and the twins.

    With noisy sensors every log's noise-free twin (the same truth run
    measured with ideal sensors) is exported into ``OUT/twins/synthetic`` by
    the same simulation and imported into ``OUT/twins/logs``; with ideal
    sensors the logs are noise-free themselves and there are no twins (``None``);
    ``twins=False`` makes none either.
    """
    chain = _sensor_model(sensors)
    where = None if chain.is_ideal or not twins else out_dir / TWINS / "synthetic"
    exports = generate_campaign(out_dir / "synthetic", seed=seed, progress=stderr_progress,
                                jobs=jobs, only=only, executor=executor, truth=truth,
                                sensors=chain, drift=drift, twins=where)
    logs, reused = _import(exports, out_dir / "logs")
    if where is None:
        return logs, reused, None
    twin_logs, twins_reused = _import([where / f.name for f in exports],
                                      out_dir / TWINS / "logs")
    return logs, reused and twins_reused, twin_logs


def _import(exports: list[Path], into: Path) -> tuple[list[Run], bool]:
    """Import exports into ``into`` (or reuse the imports); and whether all were reused."""
    logs, imported = [], 0
    for folder in exports:
        target = into / f"{folder.name}.parquet"
        if target.is_file() and target.stat().st_mtime >= (folder / "meta.json").stat().st_mtime:
            try:
                logs.append(read_run(target))
                continue
            except LogError as exc:  # a damaged cache: the export is the source
                stderr_progress(f"re-importing {folder.name}: {exc}")
        run, report = import_source(folder)
        for line in report:
            stderr_progress(f"repaired: {line}")
        write_run(run, target)
        logs.append(run)
        imported += 1
    if imported < len(exports):
        stderr_progress(f"{len(exports) - imported} of {len(exports)} imported logs reused from "
                        f"{into}")
    return logs, imported == 0


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
          jobs: int) -> dict:
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
    from artic.validation.campaign.tuning import tune_model  # here: scipy.optimize takes 0.7 s

    out: dict = {"key": key, "loads": {}, "complete": False}
    lock = threading.Lock()  # guards out and tuning.json
    todo = []
    for load in LOADS:
        tuning = [log for log in logs if log.name in TUNING and log.meta.get("load") == load]
        if not tuning:
            stderr_progress(f"{load}: no tuning manoeuvre among the logs; the preset's "
                            "parameters are used untuned")
            continue
        names = [log.name for log in tuning]
        part = saved["loads"].get(load)
        if not (isinstance(part, dict) and part.get("logs") == names):
            part = None
        vehicle = load_vehicle(PRESET.format(load=load))
        out["loads"][load] = {"logs": names, "rows": [], "summary": [], "fitted": {},
                              "truth": tuning[0].meta.get("truth", {}),
                              "nominal": {"i_s": vehicle.steering_for("mbd").i_s}}
        todo.append((load, vehicle, tuning, part))

    stop = threading.Event()  # set when the campaign is interrupted: no further fit starts

    def tune_load(load: str, vehicle: Vehicle, tuning: list[Run], part: dict | None,
                  threads: int) -> None:
        entry = out["loads"][load]
        for m in models:
            if stop.is_set():
                return
            done = [r for r in (part or {}).get("summary", []) if r.get("model") == m]
            if done:
                with lock:
                    entry["rows"] += [r for r in part.get("rows", []) if r.get("model") == m]
                    entry["summary"] += done
                    if m in part.get("fitted", {}):
                        entry["fitted"][m] = part["fitted"][m]
                stderr_progress(f"{load}: tuning of {m} reused from {path}")
                continue
            stderr_progress(f"{load}: tuning {m} on {len(tuning)} logs")
            try:
                with lock:
                    start = start_from(m, entry["fitted"])
                fit = tune_model(m, vehicle, tuning, threads,
                                 lambda line, load=load: stderr_progress(f"{load}: {line}"),
                                 start=start)
            except (MemoryError, RecursionError):
                raise
            except Exception as exc:  # noqa: BLE001 - one model's failure is a row
                why = " ".join(str(exc).split()) or type(exc).__name__
                stderr_progress(f"{load}: tuning {m} failed ({why}); its preset values are "
                                "used")
                row = {"load": load, "model": m, "status": f"failed: {why}"}
                with lock:
                    entry["summary"].append(row)
                    atomic_write_text(path, json.dumps(out, indent=1) + "\n")
            else:
                with lock:
                    entry["rows"] += [{"load": load, **row} for row in fit.rows()]
                    entry["fitted"][m] = fit.fitted
                    entry["summary"].append(
                        {"load": load, "model": m, "eps_n_before": fit.eps_n_before,
                         "eps_n_after": fit.eps_n_after, "cost_before": fit.cost_before,
                         "cost_after": fit.cost_after, "evaluations": fit.evaluations,
                         "wall_s": fit.wall_s, "status": "ok"})
                    atomic_write_text(path, json.dumps(out, indent=1) + "\n")

    side_by_side = min(len(todo), max(1, jobs))
    threads = max(1, jobs // side_by_side)
    if side_by_side > 1:
        with ThreadPoolExecutor(side_by_side, thread_name_prefix="artic-tune") as pool:
            futures = [pool.submit(tune_load, *t, threads) for t in todo]
            try:
                for f in futures:
                    f.result()
            except BaseException:  # interrupted, or a fit raised: the fits running end theirs
                stop.set()
                raise
    else:
        for t in todo:
            tune_load(*t, threads)
    if not out["loads"]:
        raise UserError(f"{out_dir}: none of the tuning manoeuvres is among the logs "
                         f"({', '.join(TUNING[:2])}, ...)")
    out["complete"] = True
    atomic_write_text(path, json.dumps(out, indent=1) + "\n")
    out["reused"] = False
    return out


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


def run_campaign(out_dir: Path, models: tuple[str, ...] | None = None, seed: int = 0,
                 jobs: int | None = None, only: list[str] | None = None,
                 gain: float = DEFAULT_GAIN, sweep_models: tuple[str, ...] = ("kin", "stm"),
                 recordings: bool = True, executor: str = "local",
                 scheduler: str | None = None, dask: DaskOptions | None = None,
                 truth: str = DEFAULT_TRUTH, remeasure: bool = False, seeds: int = 1,
                 closing: bool = True, sensors: str = "default",
                 drift: bool = True) -> dict[str, Path]:
    """Run the campaign; see the module docstring.

    Parameters
    ----------
    out_dir : Path
        Output folder.
    models : tuple of str, optional
        Models to tune and validate; every model of the registry by default
        (:func:`artic.validation.models.names`, registered ones included).
    seed : int
        Seed of the synthetic campaign.
    jobs : int, optional
        Processes for generation, threads for the plant; the number of cores by default.
    only : list of str, optional
        Manoeuvre names or prefixes: a part of the campaign (tests, studies).
    gain : float
        Reversing feedback gain K [rad/rad].
    sweep_models : tuple of str
        Models in the gain sweep (the plant makes it long: 33 logs per gain).
    recordings : bool
        Write the Rerun recordings.
    executor, scheduler : str
        Where generation and validation run: ``local`` or ``dask``, and a
        Dask scheduler's address (a local cluster when omitted); see
        :mod:`artic.validation.campaign.executors`.
    truth : str
        The synthetic campaign's truth: ``"independent"``, ``"structural"`` or
        ``"legacy"`` (see :mod:`artic.validation.synthetic.truth`).
    dask : DaskOptions, optional
        The scheduler's timeout and TLS files.
    remeasure : bool
        Compute the efficiency again from the validation runs' times, even
        when an earlier run with the same key computed it (a resumed run keeps
        the original figures otherwise; a run simulated again has new times).
    seeds : int
        Trucks: with more than one, a campaign per seed (``seed`` on) in
        ``out_dir/seed-K`` and the pooled results in ``out_dir``
        (:mod:`artic.validation.campaign.seeds`).
    closing : bool
        Print the closing tables and where the report is.
    sensors : str
        The logs' measurement chain: ``default`` (noisy RTK/INS/CAN models;
        every log then has a noise-free twin, and the report the noise share
        of every criterion) or ``ideal`` (the truth's own signals).
    drift : bool
        ``False`` stills the steering column's drifting zero; with ideal
        sensors the logs are then what the floor replays.

    Returns
    -------
    dict
        Result files by name.

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
    if seeds < 1:
        raise UserError(f"--seeds {seeds}: a campaign needs at least one truck")
    _sensor_model(sensors)  # a bad name fails before anything is written
    check_selection(only)
    jobs = jobs or os.cpu_count() or 1
    if seeds > 1:
        from artic.validation.campaign.seeds import run_seeds

        return run_seeds(out_dir, seeds, seed, models=models, jobs=jobs, only=only, gain=gain,
                         sweep_models=sweep_models, recordings=recordings, executor=executor,
                         scheduler=scheduler, dask=dask, truth=truth, remeasure=remeasure,
                         sensors=sensors, drift=drift)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    models = tuple(names() if models is None else models)
    # A registered model's code is not artic's: its own fingerprint joins the key.
    outside = {m: c for m in models if (c := code_of(m))}
    chain = {} if (sensors, drift) == ("default", True) else {"sensors": sensors, "drift": drift}
    key = fingerprint.key(seed, list(models), gain, only, truth, *([outside] if outside else []),
                          *([chain] if chain else []))
    state = _saved_timings(out_dir, key)
    if remeasure:
        state["efficiency"] = None

    def save(times: dict[str, float], budget: dict[str, dict]) -> None:
        state["stages"] = {**state["stages"], **times}
        state["budget"] = {**state.get("budget", {}), **budget}
        atomic_write_text(out_dir / TIMINGS, json.dumps(state, indent=1) + "\n")

    with contextlib.ExitStack() as stack:
        stack.enter_context(OutDirLock(out_dir, "campaign"))
        stale = clean_stale(out_dir)
        if stale:
            stderr_progress(f"removed {len(stale)} temporary file(s) left by an interrupted run")
        (out_dir / "report.md").unlink(missing_ok=True)
        pool = stack.enter_context(cluster_executor(executor, jobs, scheduler, dask))
        stage = Stages(stderr_progress, state["stages"], save, state.get("budget"))
        stderr_progress(f"artic campaign: models {', '.join(models)}, seed {seed}, "
                        f"K = {gain:g}, {jobs} jobs ({executor}), output {out_dir}"
                        + (f", sensors {sensors}" if sensors != "default" else "")
                        + ("" if drift else ", no drift"))
        return _run_stages(out_dir, models, seed, jobs, only, gain, sweep_models, recordings, pool,
                           key, stage, truth, state, closing, sensors, drift)


def check_selection(only: list[str] | None) -> None:
    """Refuse an ``--only`` that leaves nothing to validate, before any work.

    The tuning manoeuvres (:data:`~artic.validation.synthetic.testmatrix.TUNING`)
    are fitted on and never validated; a selection of them alone would tune
    and then have no log for the tables.

    Raises
    ------
    ValueError
        One line naming the selection and what to add.
    """
    if not only:
        return
    chosen = [m.name for m in MATRIX if any(m.name.startswith(o) for o in only)]
    if chosen and all(n in TUNING for n in chosen):
        raise UserError(f"--only {','.join(only)}: selects only tuning manoeuvres "
                         f"({', '.join(chosen)}), which are fitted on and never validated, "
                         "so there would be nothing to validate; add a validation manoeuvre "
                         f"(for example --only {','.join(only)},{_first_validated()})")


def _first_validated() -> str:
    return next(m.name for m in MATRIX if m.name not in TUNING)


def _saved_timings(out_dir: Path, key: str) -> dict:
    """The stage times and efficiency an earlier run with ``key`` measured, if any."""
    path = out_dir / TIMINGS
    empty = {"key": key, "stages": {}, "efficiency": None}
    if not path.is_file():
        return empty
    try:
        saved = json.loads(path.read_text())
    except (OSError, ValueError):
        return empty
    return saved if saved.get("key") == key else empty


def _run_stages(out_dir, models, seed, jobs, only, gain, sweep_models, recordings, pool, key,
                stage, truth, state, closing=True, sensors="default",
                drift=True) -> dict[str, Path]:
    from artic.validation.campaign import report as rep
    from artic.validation.campaign.efficiency import from_runs
    from artic.validation.runs.gainsweep import DEFAULT_GAINS, gain_sweep, plot_gain_sweep

    paths: dict[str, Path] = {}
    # numba compiles the reduced models' loop and the criteria on a core of its
    # own while the logs are made, instead of on the critical path of tuning
    # (not on a resume past tuning: loading a warm cache takes tuning no time).
    saved = _read_json(out_dir / "tuning.json") or {}
    warm = None
    if pool is None and set(models) & {"kin", "stm"} and not (
            saved.get("key") == key and saved.get("complete")):
        warm = warmup.start()
    with stage("logs"):
        logs, reused, twin_logs = _load_logs(out_dir, seed, jobs, only, pool, truth, sensors,
                                             drift)
        stage.reused(reused)
    with stage("tuning"):
        if warm is not None:  # a wait for it counts as tuning's, which needs it
            warm.join()
            if warm.exitcode:
                stderr_progress(f"compiling ahead failed (exit code {warm.exitcode}); numba "
                                "compiles on first use instead")
        tuned = _tune(out_dir, logs, models, key, jobs)
        stage.reused(tuned["reused"])
        vehicles = _tuned_vehicles(out_dir, tuned, seed)
        tuning_logs = {n for part in tuned["loads"].values() for n in part["logs"]}
        paths["tuning"] = out_dir / "tuning.json"
    validated = [log for log in logs if log.name not in tuning_logs]
    scale = campaign_scale(validated)  # one scale for every row of eps_n_fixed
    paths["eps_n_fixed_scale"] = write_scale(scale, out_dir / SCALE_FILE)
    with stage("validation"):
        parts = []
        for load in LOADS:
            group = [log for log in logs if log.meta.get("load") == load
                     and log.name not in tuning_logs]
            if group:
                parts.append(validate_runs(group, vehicles[load], models, gain=gain,
                                           out_dir=out_dir, progress=stderr_progress,
                                           reuse_key=f"{key}.{load}", jobs=jobs,
                                           executor=pool, label=f"validation, {load}",
                                           scale=scale))
        stage.reused(all(p.attrs.get("reused") == len(p) for p in parts))
        metrics = pd.concat(parts, ignore_index=True)
    load_of = {log.name: log.meta.get("load") for log in logs}
    with stage("references"):
        floor = _floor(out_dir, validated, seed, truth, gain, key, jobs, pool, scale)
        all_reused = floor.attrs.get("reused") == len(floor)
        metrics = pd.concat([metrics, floor], ignore_index=True)
        metrics["load"] = metrics["log"].map(load_of)
        paths["metrics"] = write_metrics(metrics, out_dir / "metrics.csv")
        vs_plant = None
        if "mbd" in models:
            reduced = [m for m in models if m != "mbd"]
            vs_plant = _versus_plant(out_dir, validated, vehicles, reduced, gain, key, jobs,
                                     scale)
            if vs_plant is not None:
                all_reused = all_reused and vs_plant.attrs.get("reused") == len(vs_plant)
                vs_plant["load"] = vs_plant["log"].map(load_of)
                paths["metrics_vs_plant"] = write_metrics(vs_plant,
                                                          out_dir / "metrics_vs_plant.csv")
        stage.reused(all_reused)
    twins = None
    if twin_logs is not None:
        with stage("twins"):
            twins = _twins(out_dir, twin_logs, tuning_logs, vehicles, models, seed, truth, gain,
                           key, jobs, pool, scale)
            stage.reused(twins.attrs.get("reused") == len(twins))
            twins["load"] = twins["log"].map(load_of)
            paths["metrics_twins"] = write_metrics(twins, out_dir / TWINS / "metrics.csv")
    with stage("tables"):
        stage.reused(stage.all_reused())
        forward, reverse = summary(metrics, "forward"), summary(metrics, "reverse")
        paths["table2"], _ = write_table(forward, out_dir / "table2_forward",
                                         "Forward driving (the paper's Table 2 columns)")
        paths["table3"], _ = write_table(reverse, out_dir / "table3_reverse",
                                         "Reverse driving (the paper's Table 3 columns)")
        forward_p = reverse_p = None
        if vs_plant is not None:
            forward_p, reverse_p = summary(vs_plant, "forward"), summary(vs_plant, "reverse")
            paths["table2_vs_plant"], _ = write_table(
                forward_p, out_dir / "table2_vs_plant",
                "Forward driving against the plant as reference (Table 2 columns)")
            paths["table3_vs_plant"], _ = write_table(
                reverse_p, out_dir / "table3_vs_plant",
                "Reverse driving against the plant as reference (Table 3 columns)")
        paired, shares, headlines = {}, {}, {}
        for d in ("forward", "reverse"):
            twin_pairs = paired_table(twins, d) if twins is not None else None
            paired[d] = findings.mark(paired_table(metrics, d), twin_pairs)
            shares[d] = findings.noise_share(metrics, twins, d) if twins is not None else None
            headlines[d] = findings.headline_criteria(paired[d], shares[d])
            if shares[d] is not None and len(shares[d]):
                paths[f"noise_share_{d}"], _ = write_table(
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
                paths[f"paired_{name}"], _ = write_table(
                    pairs.set_index("criterion"), out_dir / f"paired_{name}",
                    f"Paired comparisons, {name.replace('_vs_plant', ', against the plant')}; "
                    f"{CORRECTION} over the table's {len(pairs)} comparisons, findings "
                    + ("resolved after it on the logs and on their noise-free twins"
                       if twins is not None and "_vs_plant" not in name else
                       "resolved after it"), paired_markdown(pairs))
        per_load = {}
        for load in LOADS:
            part = metrics[metrics["load"] == load]
            for direction in ("forward", "reverse"):
                t = summary(part, direction)
                if len(t):
                    per_load[f"{load}, {direction}"] = t
    by_name = {log.name: log for log in logs}
    with stage("efficiency"):
        if state.get("efficiency") is not None:
            eff = pd.DataFrame(state["efficiency"]).set_index("model")
            stderr_progress(f"efficiency reused from {out_dir / TIMINGS} (as the original "
                            "run timed its validation runs; --remeasure times them again)")
            stage.reused()
        else:  # the validation runs' own times: no run is made for it
            eff = from_runs(metrics, models, out_dir / "runs")
            state["efficiency"] = eff.reset_index().to_dict(orient="records")
        atomic_write(out_dir / "efficiency.csv", lambda p: eff.to_csv(p, float_format="%.6g"))
        paths["efficiency"] = out_dir / "efficiency.csv"
    sweep = None
    if sweep_models:
        with stage("gain sweep"):
            rev = {load: (vehicles[load], [log for log in logs if log.meta.get("load") == load
                                           and log.meta.get("direction") == "reverse"])
                   for load in LOADS}
            sweep = _cached_sweep(out_dir, key, sweep_models)
            stage.reused(sweep is not None)
            if sweep is None:
                sweep = gain_sweep(rev, [m for m in sweep_models if m in models],
                                   DEFAULT_GAINS, jobs, stderr_progress)
                atomic_write_text(out_dir / "gain_sweep.json", json.dumps(
                    {"key": key, "models": list(sweep_models), "K_min": sweep.attrs["K_min"],
                     "rows": sweep.to_dict(orient="records")}) + "\n")
            table, plot = out_dir / "gain_sweep.csv", out_dir / "plots" / "gain_sweep.png"
            # The key covers K, so a reused sweep's table and plot stand if
            # they are newer than it (drawing the plot again takes a second).
            made = (out_dir / "gain_sweep.json").stat().st_mtime
            if not all(p.is_file() and p.stat().st_mtime >= made for p in (table, plot)):
                atomic_write(table, lambda p: sweep.to_csv(p, index=False, float_format="%.6g"))
                plot_gain_sweep(sweep, plot, gain)
            paths["gain_sweep"] = table
    if recordings:
        with stage("recordings"):
            rec_paths, made = _recordings(out_dir, metrics, by_name, vehicles, models, jobs)
            paths.update(rec_paths)
            stage.reused(made == 0)
    results = rep.CampaignResults(
        seed=seed, models=tuple(models), gain=gain, metrics=metrics, forward=forward,
        reverse=reverse, tuned=tuned["loads"], efficiency=eff, sweep=sweep, stages=stage.times,
        budget=stage.budget,
        fingerprint=fingerprint.code(), version=_version(), per_load=per_load,
        files={k: str(v.relative_to(out_dir)) for k, v in paths.items()},
        forward_vs_plant=forward_p, reverse_vs_plant=reverse_p, truth=truth,
        metrics_vs_plant=vs_plant, paired=paired, twins=twins, noise_share=shares,
        headline_criteria=headlines, sensors=sensors, drift=drift)
    with stage("report"):
        stage.reused(stage.all_reused())
        draft = rep.render(results)  # the summary recording's copy, before the last timing
        if recordings:
            from artic.validation.review.recording import record_summary

            paths["summary_recording"] = record_summary(
                out_dir / "recordings" / "campaign.rrd", metrics, draft)
    text = rep.render(results)
    paths["report"] = atomic_write_text(out_dir / "report.md", text)
    failed = metrics[[is_failed(st) for st in metrics["status"]]]
    if closing:
        print(_closing_summary(forward, reverse, stage.times, paths["report"], len(failed),
                               stage.budget))
    return paths


def _floor(out_dir: Path, logs: list[Run], seed: int, truth: str, gain: float, key: str,
           jobs: int, pool, scale: dict | None = None, samples: bool = True) -> pd.DataFrame:
    """The truth against the logs: the ``floor`` rows of the tables against logs.

    Each log's floor is the truth that made it (:func:`artic.validation.models.build`
    reads its metadata), from ``truth-LOAD.toml`` with the log's yard slope.
    """
    from artic.validation.synthetic.truth import truth_configuration, truth_vehicle

    config = truth_configuration(seed, truth)

    def vehicle_of(log: Run) -> Vehicle:
        return truth_vehicle(log.meta["load"], config, seed, log.meta.get("slope"))

    return validate_runs(logs, vehicle_of, ["floor"], gain=gain, out_dir=out_dir,
                         progress=stderr_progress, reuse_key=f"{key}.floor", jobs=jobs,
                         executor=pool, label="references, the truth", scale=scale,
                         samples=samples)


def _twins(out_dir: Path, twin_logs: list[Run], tuning_logs: set[str],
           vehicles: dict[str, Vehicle], models: Sequence[str], seed: int, truth: str,
           gain: float, key: str, jobs: int, pool, scale: dict | None) -> pd.DataFrame:
    """Every model and the floor on the noise-free twins of the validated logs.

    The same tuned vehicles, gain and ``eps_n_fixed`` scale as on the logs,
    so that a criterion's difference between a log and its twin is the
    measurement's alone. Runs go to ``OUT/twins/runs``, their metadata only
    (the criteria; ``validate_runs(samples=False)``); no recordings.
    """
    twin_out = out_dir / TWINS
    validated = [log for log in twin_logs if log.name not in tuning_logs]
    parts = []
    for load in LOADS:
        group = [log for log in validated if log.meta.get("load") == load]
        if group:
            parts.append(validate_runs(group, vehicles[load], models, gain=gain,
                                       out_dir=twin_out, progress=stderr_progress,
                                       reuse_key=f"{key}.{load}.twins", jobs=jobs,
                                       executor=pool, label=f"twins, {load}", scale=scale,
                                       samples=False))
    parts.append(_floor(twin_out, validated, seed, truth, gain, f"{key}.twins", jobs, pool,
                        scale, samples=False))
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


def _cached_sweep(out_dir: Path, key: str, models: Sequence[str]) -> pd.DataFrame | None:
    """The gain sweep of an earlier run with the same key and models, if any."""
    path = out_dir / "gain_sweep.json"
    saved = _read_json(path)
    if saved is None or saved.get("key") != key or saved.get("models") != list(models) \
            or not isinstance(saved.get("K_min"), dict):
        return None
    stderr_progress(f"gain sweep reused from {path}")
    sweep = pd.DataFrame(saved["rows"])
    sweep.attrs["K_min"] = saved["K_min"]
    return sweep


def _version() -> str:
    from artic.validation.review.recording import artic_version

    return artic_version()


def _record_one(target: Path, log: Run, run_paths: dict[str, Path], vehicle: Vehicle,
                rows: pd.DataFrame) -> int:
    """Write one manoeuvre's recording from its run files; returns its size [bytes]."""
    from artic.validation.review.recording import record_manoeuvre

    loaded = {m: read_run(p) for m, p in run_paths.items()}
    record_manoeuvre(target, log, loaded, vehicle, rows)
    return target.stat().st_size


def _recordings(out_dir: Path, metrics: pd.DataFrame, logs: dict[str, Run],
                vehicles: dict[str, Vehicle], models: Sequence[str],
                jobs: int = 1) -> tuple[dict[str, Path], int]:
    """One recording per validated manoeuvre, skipped when newer than its runs; a few plots.

    The recordings are written on ``jobs`` local worker processes: drawing
    them is Python work that holds the GIL. They are local even with a Dask
    executor, whose workers need not share this file system.

    Returns the paths and the number of recordings written.
    """
    from artic.validation.review.plots import plot_manoeuvre

    names = list(dict.fromkeys(metrics["log"]))
    failed = {(r.log, r.model) for r in metrics.itertuples() if is_failed(r.status)}
    todo = []
    for name in names:
        runs = {m: out_dir / "runs" / f"{name}.{m}.parquet" for m in models
                if (name, m) not in failed}
        if not runs:
            continue
        target = out_dir / "recordings" / f"{name}.rrd"
        newest = max(p.stat().st_mtime for p in runs.values())
        if not (target.is_file() and target.stat().st_mtime >= newest):
            todo.append((name, runs, target))
    if len(todo) < len(names):
        stderr_progress(f"{len(names) - len(todo)} of {len(names)} recordings reused from "
                        f"{out_dir / 'recordings'} (newer than their runs)")
    counter = Counter(len(todo), "recordings", stderr_progress)

    tasks = [(target, (target, logs[name], runs,
                       vehicles[logs[name].meta.get("load", "unloaded")],
                       metrics[metrics["log"] == name])) for name, runs, target in todo]
    with contextlib.closing(completed(_record_one, tasks, jobs)) as done:
        for target, size in done:
            counter.step(f"{target.name} ({size / 1e6:.1f} MB)")
    for name, runs, _ in todo:  # a plot of the first manoeuvre of each kind drawn
        log = logs[name]
        plot = out_dir / "plots" / f"{log.meta.get('manoeuvre')}.png"
        if log.meta.get("manoeuvre") in ("docking", "constant-steer") and not plot.is_file():
            plot_manoeuvre(plot, log, {m: read_run(p) for m, p in runs.items()})
    return {"recordings": out_dir / "recordings"}, len(todo)
