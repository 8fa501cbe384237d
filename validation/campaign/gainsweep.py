"""How the reversing criteria depend on the feedback gain K.

The harness adds ``K (gamma_model - gamma_measured)`` to the steering while
reversing. Linearised about straight reversing, KIN's articulation then has
the eigenvalue ``u1 (K (L2 - L1c) - L1) / (L1 L2)`` (the paper's eqs. (6)-(7)), so
for ``u1 < 0`` the loop is stable only for

    K > K_min = L1 / (L2 - L1c).

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
from artic.validation.batch import BatchResult, run_batch
from artic.validation.harness import LoopInputs, loop_inputs
from artic.validation.logs.runfile import Run, new_frame
from artic.validation.metrics import run_metrics
from artic.validation.models import spec
from artic.validation.progress import Counter
from artic.validation.steering import SteeringMap

DEFAULT_GAINS = (0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0)
"""Gains swept by default [rad/rad]; the bound of every vehicle is added."""


def stability_bound(vehicle: Vehicle) -> float:
    """``K_min = L1 / (L2 - L1c)`` [rad/rad] (see the module docstring)."""
    return vehicle.L1 / (vehicle.L2 - vehicle.L1c)


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
        K values [rad/rad]; each vehicle's ``K_min`` is added.
    jobs : int
        Threads for the plant.
    progress : callable, optional
        Receives progress lines with counts and the time left, and one line
        per (model, log) on which the model had to limit something.

    Returns
    -------
    DataFrame
        One row per (model, K): ``model, K, J_steer, eps_n, eps_a, eps_v``
        (means over the logs), ``stopped`` (runs that reached the jackknife
        limit) and ``n``; ``K_min`` (largest over the vehicles) in ``attrs``.
    """
    bounds = [stability_bound(v) for v, _ in logs_by_vehicle.values()]
    ks = sorted(set(map(float, gains)) | set(bounds))
    rows = []
    counter = Counter(len(models) * len(ks), "gain sweep", progress)
    with ThreadPoolExecutor(max(1, jobs)) as pool:
        for model in models:
            limited: dict[str, str] = {}
            for k in ks:
                m, stopped = _at_gain(model, k, logs_by_vehicle, jobs, pool, limited)
                rows.append({"model": model, "K": k, "J_steer": m["J_steer"].mean(),
                             "eps_n": m["eps_n"].mean(), "eps_a": m["eps_a"].mean(),
                             "eps_v": m["eps_v"].mean(), "stopped": stopped, "n": len(m)})
                counter.step(f"{model} K = {k:.3g}: J_steer {rows[-1]['J_steer']:.1f} %, eps_n "
                             f"{rows[-1]['eps_n']:.1f} %, {stopped} of {len(m)} stopped")
            if progress is not None:
                for name, text in limited.items():
                    progress(f"gain sweep {model} on {name}: limited (first at {text})")
    out = pd.DataFrame(rows)
    out.attrs["K_min"] = float(max(bounds))
    return out


def _at_gain(model: str, k: float, logs_by_vehicle: Mapping[str, tuple[Vehicle, Sequence[Run]]],
             jobs: int, pool: ThreadPoolExecutor,
             limited: dict[str, str]) -> tuple[pd.DataFrame, int]:
    """One model's criteria on every log at gain ``k``, and the runs stopped early.

    Notes in ``limited`` the first gain at which the model limited something on a log.
    """
    per_log = []
    stopped = 0
    for vehicle, logs in logs_by_vehicle.values():
        if not logs:
            continue
        steering = SteeringMap.from_steering(vehicle.steering_for(model))
        inputs = [loop_inputs(log, vehicle, steering) for log in logs]
        res = run_batch(spec(model).build, vehicle, inputs, k, jobs)
        # The path distances release the GIL: the metrics of a batch take
        # about as long as its runs, so they share the threads.
        per_log.extend(pool.map(_metrics, logs, inputs, [res] * len(logs), range(len(logs))))
        for i, log in enumerate(logs):
            if res.limited and res.limited[i]:
                limited.setdefault(log.name, f"K = {k:.3g}: {res.limited[i]}")
            stopped += int(res.n_done[i]) < inputs[i].t.size
    return pd.DataFrame(per_log), stopped


def _metrics(log: Run, inputs: LoopInputs, res: BatchResult, i: int) -> dict[str, float]:
    """The criteria of log ``i`` of a batch against its measured log."""
    n = int(res.n_done[i])
    frame = new_frame(inputs.t[:n], inputs.delta_h[:n], res.obs[i][:n])
    frame["delta"] = res.delta[i][:n]
    frame["delta_fb"] = res.delta_fb[i][:n]
    return run_metrics(log.frame, frame)


def plot_gain_sweep(sweep: pd.DataFrame, path, gain: float) -> None:
    """Plot ``J_steer`` and ``eps_n`` against K, with the bound and the campaign's K marked."""
    from matplotlib.figure import Figure

    from artic.validation.logs.runfile import atomic_write

    k_min = sweep.attrs["K_min"]
    fig = Figure(figsize=(10, 4), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, col, label in ((axes[0], "J_steer", "J_steer [%]"), (axes[1], "eps_n", "eps_n [%]")):
        for model, g in sweep.groupby("model", sort=False):
            ax.plot(g["K"], g[col], marker="o", label=model)
        ax.axvspan(0.0, k_min, color="0.85", label=f"unstable: K < K_min = {k_min:.2f}")
        ax.axvline(gain, color="k", ls="--", lw=1, label=f"campaign K = {gain:g}")
        ax.set_xlabel("feedback gain K [rad/rad]")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Reversing criteria against the feedback gain (mean over the reverse logs)")
    atomic_write(path, lambda p: fig.savefig(p, format="png", dpi=110))


def sweep_table(sweep: pd.DataFrame) -> pd.DataFrame:
    """The sweep as a wide table: one row per K, columns per model and criterion."""
    wide = sweep.pivot(index="K", columns="model", values=["J_steer", "eps_n", "stopped"])
    wide.columns = [f"{c}_{m}" for c, m in wide.columns]
    k_min = sweep.attrs["K_min"]
    k = wide.index.to_numpy(dtype=float)
    wide.insert(0, "stable", np.where(np.isclose(k, k_min, rtol=1e-9), "bound",
                                      np.where(k > k_min, "yes", "no")))
    return wide
