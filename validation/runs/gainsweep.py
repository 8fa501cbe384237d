"""How the reversing criteria depend on the feedback gain K.

The harness adds ``K (gamma_model - gamma_measured)`` to the steering while
reversing. Linearised about straight reversing, KIN's articulation then has
the eigenvalue ``u1 (K (L2 - L1c) - L1) / (L1 L2)`` (the paper's eqs. (6)-(7)), so
for ``u1 < 0`` the loop is stable only for

    K > K_min = L1 / (L2 - L1c).

Each model has its own bound, from the lengths it runs on
(:func:`model_lengths`): KIN's equivalent wheelbases (the axle groups' no-slip
points, :mod:`artic.reduced.kinematic`), not the paper's drive axle and middle
trailer axle (0.504 against 0.556 on the gosar presets). The STM's reversing
articulation has the same bound: at low speed its inertia forces vanish
(they scale with ``u1**2``), every slip angle is geometric, and its linear
tyres (``C_i = f Fz_i``) balance exactly as the equivalent lengths assume,
``f`` cancelling. The plant's tyres are not linear in load, so for it the
equivalent lengths are the linear estimate (within 3 % of its steady turns).

Below that bound a model's articulation runs away from the log's, which shows
as large ``eps_n`` and runs stopped at the jackknife limit. Far above it the
feedback tracks the measured articulation tightly, at the price of more
steering effort ``J_steer``. The sweep runs each model through every reverse
log at every gain and reports the means.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd

from artic.mjcf.vehicle import Vehicle
from artic.reduced.kinematic import kin_parameters
from artic.validation.criteria.metrics import run_metrics
from artic.validation.criteria.statistics import mean_ci
from artic.validation.harness.batch import BatchResult, run_batch
from artic.validation.harness.loop import LoopInputs, loop_inputs
from artic.validation.logs.runfile import Run, atomic_write, new_frame
from artic.validation.models import spec, steering_for
from artic.validation.plumbing.progress import Counter

DEFAULT_GAINS = (0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0)
"""Gains swept by default [rad/rad]; the bound of every vehicle is added."""


def model_lengths(vehicle: Vehicle, model: str = "kin") -> tuple[float, float, float]:
    """The lengths ``(L1, L1c, L2)`` [m] a model's reversing articulation runs on.

    ``"paper"``: the paper's (drive axle, middle trailer axle); ``"kin"``:
    what :class:`artic.KIN` is built with; any other model
    (STM, the plant, the floor): the equivalent lengths, their low-speed limit
    (see the module docstring).
    """
    if model == "paper":
        return vehicle.L1, vehicle.L1c, vehicle.L2
    if model == "kin":
        # Here, not at the top: numba loads only for a sweep of KIN.
        from artic.reduced.control import KIN

        L1, L1c, L2 = KIN(vehicle).params
    else:
        L1, L1c, L2 = kin_parameters(vehicle, "equivalent")
    return float(L1), float(L1c), float(L2)


def stability_bound(vehicle: Vehicle, model: str = "kin") -> float:
    """``K_min = L1 / (L2 - L1c)`` [rad/rad] from ``model``'s lengths (:func:`model_lengths`)."""
    L1, L1c, L2 = model_lengths(vehicle, model)
    return L1 / (L2 - L1c)


def gain_sweep(logs_by_vehicle: Mapping[str, tuple[Vehicle, Sequence[Run]]],
               models: Sequence[str], gains: Sequence[float] = DEFAULT_GAINS, jobs: int = 1,
               progress: Callable[[str], None] | None = None) -> pd.DataFrame:
    """Run the reverse logs at every gain.

    Parameters
    ----------
    logs_by_vehicle : mapping
        Load condition to (vehicle, reverse logs).
    models : sequence of str
        Models to sweep.
    gains : sequence of float
        K values [rad/rad]; each model's ``K_min`` on each vehicle is added.
    jobs : int
        Threads for the plant.
    progress : callable, optional
        Receives progress lines with counts and the time left, and one line
        per (model, log) on which the model had to limit something.

    Returns
    -------
    DataFrame
        One row per (model, K): ``model, K, J_steer, eps_n, eps_a, eps_v``
        (means over the logs), ``J_steer_lo, J_steer_hi, eps_n_lo, eps_n_hi``
        (their 95 % intervals over the logs), ``stopped`` (runs that reached
        the jackknife limit), ``n`` and the model's ``K_min`` (largest over the
        vehicles); ``attrs["K_min"]`` maps each model to it.
    """
    per_vehicle = {m: [stability_bound(v, m) for v, _ in logs_by_vehicle.values()]
                   for m in models}
    bounds = {m: float(max(b)) for m, b in per_vehicle.items() if b}
    ks = sorted(set(map(float, gains)) | {k for b in per_vehicle.values() for k in b})
    # The harness's inputs do not depend on K: derived once per model and log.
    prepared = {m: [(vehicle, logs, _inputs(m, vehicle, logs))
                    for vehicle, logs in logs_by_vehicle.values() if logs] for m in models}
    tasks = [(m, k) for m in models for k in ks]
    rows = []
    counter = Counter(len(tasks), "gain sweep", progress)
    limited: dict[str, dict[str, str]] = {m: {} for m in models}
    # One (model, K) per thread: its runs and criteria on one thread, the
    # gains side by side, so that no thread waits for another between them.
    with ThreadPoolExecutor(max(1, jobs)) as pool:
        done = pool.map(lambda task: _at_gain(task[0], task[1], prepared[task[0]]), tasks)
        for (model, k), (m, stopped, notes) in zip(tasks, done, strict=True):
            for name, text in notes.items():
                limited[model].setdefault(name, f"K = {k:.3g}: {text}")
            steer, eps_n = mean_ci(m["J_steer"]), mean_ci(m["eps_n"])
            rows.append({"model": model, "K": k, "J_steer": m["J_steer"].mean(),
                         "J_steer_lo": steer.lo, "J_steer_hi": steer.hi,
                         "eps_n": m["eps_n"].mean(), "eps_n_lo": eps_n.lo,
                         "eps_n_hi": eps_n.hi, "eps_a": m["eps_a"].mean(),
                         "eps_v": m["eps_v"].mean(), "stopped": stopped, "n": len(m),
                         "K_min": bounds[model]})
            counter.step(f"{model} K = {k:.3g}: J_steer {rows[-1]['J_steer']:.1f} %, eps_n "
                         f"{rows[-1]['eps_n']:.1f} %, {stopped} of {len(m)} stopped")
    if progress is not None:
        for model in models:
            for name, text in limited[model].items():
                progress(f"gain sweep {model} on {name}: limited (first at {text})")
    out = pd.DataFrame(rows)
    out.attrs["K_min"] = bounds
    return out


def _inputs(model: str, vehicle: Vehicle, logs: Sequence[Run]) -> list[LoopInputs]:
    """The harness's inputs of ``model`` on each log (:func:`loop_inputs`)."""
    steering = steering_for(vehicle, model)
    return [loop_inputs(log, vehicle, steering) for log in logs]


def _at_gain(model: str, k: float,
             prepared: Sequence[tuple[Vehicle, Sequence[Run], list[LoopInputs]]],
             ) -> tuple[pd.DataFrame, int, dict[str, str]]:
    """One model's criteria on every log at gain ``k``, on one thread.

    Returns the criteria per log, the runs stopped early, and per log what
    the model had to limit.
    """
    per_log = []
    stopped = 0
    limited: dict[str, str] = {}
    for vehicle, logs, inputs in prepared:
        res = run_batch(spec(model).build, vehicle, inputs, k, 1)
        per_log.extend(_metrics(log, inp, res, i)
                       for i, (log, inp) in enumerate(zip(logs, inputs, strict=True)))
        for i, log in enumerate(logs):
            if res.limited and res.limited[i]:
                limited.setdefault(log.name, res.limited[i])
            stopped += int(res.n_done[i]) < inputs[i].t.size
    return pd.DataFrame(per_log), stopped, limited


def _metrics(log: Run, inputs: LoopInputs, res: BatchResult, i: int) -> dict[str, float]:
    """The criteria of log ``i`` of a batch against its measured log.

    The sweep reports no position error, so the path distances are not computed.
    """
    n = int(res.n_done[i])
    frame = new_frame(inputs.t[:n], inputs.delta_h[:n], res.obs[i][:n])
    frame["delta"] = res.delta[i][:n]
    frame["delta_fb"] = res.delta_fb[i][:n]
    return run_metrics(log.frame, frame, positions=False, beyond=False)


def plot_gain_sweep(sweep: pd.DataFrame, path, gain: float) -> None:
    """Plot ``J_steer`` and ``eps_n`` against K, each model's bound and the campaign's K marked.

    Below the smallest bound every model's loop is unstable (shaded); each
    model's own ``K_min`` is a dotted line in its colour.
    """
    from matplotlib.figure import Figure

    bounds = sweep.attrs["K_min"]
    fig = Figure(figsize=(10, 4), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, col, label in ((axes[0], "J_steer", "J_steer [%]"), (axes[1], "eps_n", "eps_n [%]")):
        for model, g in sweep.groupby("model", sort=False):
            colour = _colour(model)
            ax.plot(g["K"], g[col], marker="o", label=model, color=colour)
            if f"{col}_lo" in g:
                ax.fill_between(g["K"], g[f"{col}_lo"], g[f"{col}_hi"], color=colour,
                                alpha=0.15, lw=0)
            if model in bounds:
                ax.axvline(bounds[model], color=colour, ls=":", lw=1.5,
                           label=f"K_min {model} = {bounds[model]:.3f}")
        ax.axvspan(0.0, min(bounds.values()), color="0.85", label="unstable for every model")
        ax.axvline(gain, color="k", ls="--", lw=1, label=f"campaign K = {gain:g}")
        # Both criteria are non-negative; a few logs' wide intervals must not hide the means.
        means = sweep[col].to_numpy(dtype=float)
        if np.isfinite(means).any():
            top = float(np.nanmax(means)) * 1.1
            his = sweep[f"{col}_hi"].to_numpy(dtype=float) if f"{col}_hi" in sweep else means
            if np.isfinite(his).any():
                top = min(max(top, float(np.nanmax(his)) * 1.05), 2.0 * top)
            if top > 0:
                ax.set_ylim(0.0, top)
        ax.set_xlabel("feedback gain K [rad/rad]")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Reversing criteria against the feedback gain (mean over the reverse logs, "
                 "95 % interval shaded)")
    atomic_write(path, lambda p: fig.savefig(p, format="png", dpi=110))


def _colour(model: str) -> str | None:
    """The registry's colour of a model (``None``: matplotlib's next)."""
    try:
        return spec(model).hex_colour
    except ValueError:
        return None


def sweep_table(sweep: pd.DataFrame) -> pd.DataFrame:
    """The sweep as a wide table: one row per K, columns per model and criterion.

    ``J_steer_MODEL`` and ``eps_n_MODEL`` carry their intervals (``_lo``,
    ``_hi``). ``stable`` says whether K is above the bound (``bound`` on it);
    one column per model (``stable_MODEL``) when the models' bounds differ.
    """
    bounds = sweep.attrs["K_min"]
    values = [c for c in ("J_steer", "J_steer_lo", "J_steer_hi", "eps_n", "eps_n_lo",
                          "eps_n_hi", "stopped") if c in sweep]
    wide = sweep.pivot(index="K", columns="model", values=values)
    models = list(dict.fromkeys(sweep["model"]))
    order = [(c, m) for m in models for c in ("J_steer", "J_steer_lo", "J_steer_hi") if c in values]
    order += [(c, m) for m in models for c in ("eps_n", "eps_n_lo", "eps_n_hi") if c in values]
    order += [("stopped", m) for m in models]
    wide = wide[order]
    names = []
    for c, m in order:
        base = c.removesuffix("_lo").removesuffix("_hi")
        names.append(f"{base}_{m}{c[len(base):]}")
    wide.columns = names
    k = wide.index.to_numpy(dtype=float)

    def stable(k_min: float) -> np.ndarray:
        return np.where(np.isclose(k, k_min, rtol=1e-9), "bound",
                        np.where(k > k_min, "yes", "no"))

    distinct = sorted(set(np.round(list(bounds.values()), 9)))
    if len(distinct) == 1:
        wide.insert(0, "stable", stable(next(iter(bounds.values()))))
    else:
        for i, m in enumerate(bounds):
            wide.insert(i, f"stable_{m}", stable(bounds[m]))
    return wide


def bounds_text(bounds: dict[str, float]) -> str:
    """Each model's ``K_min`` as text: ``KIN 0.504, STM 0.504``."""
    return ", ".join(f"{m.upper()} {k:.3f}" for m, k in bounds.items())
