"""The noise floor of users' logs: what a perfect model scores from declared sensor noise alone.

A model that were the truck would still not score zero against a log: the
log is the truck measured through sensors, and the criteria compare the
model with the measurement. With the sensors' noise declared
(:mod:`artic.validation.logs.noise`), the floor of each criterion is
estimated from the model's own run, which stands in for the truck (a perfect
model's output differs from it only by the model's error, which barely
changes how noise scores):

1. the model's run through the harness, its signals only, is the "truck";
2. it is measured through the declared noise with a seeded generator
   (:func:`artic.validation.logs.noise.add_noise`), :data:`DRAWS` times;
3. each measured copy is scored against the run itself with the criteria a
   log and a run get (:func:`artic.validation.criteria.metrics.run_metrics`
   and the rows of :data:`artic.validation.criteria.columns.TABLE` computed
   from a log and a run: ``eps_gamma``, ``eps_cover``, the dock errors), and
   ``eps_n_fixed`` on the set's scale; of the signed dock errors, their
   magnitudes (:data:`SIGNED`).

The floor is the mean over the draws, with the 5-95 % range of single draws
beside it: one log is one draw, so a criterion whose range is wide (a
correlated position noise over a short log, a gyro bias drawn once per log)
varies that much from log to log for a perfect model. A model's score near its
floor measures the sensors, not the model.

What it leaves out: noise in the *inputs* that drive the models (the measured
speed, the steering wheel, and in reverse the articulation the feedback
follows) also moves a model's run; the floor here is the comparison's part
only. ``J_steer`` and the open-loop prediction errors exist only for a model
driven by the log, so they have no floor here (:data:`NOT_ESTIMATED`).

The generator of a (log, model) pair is seeded from ``seed`` and the two names
(CRC-32), so the same inputs give the same floor.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from artic.mjcf.vehicle import Vehicle
from artic.validation.criteria import columns as extra
from artic.validation.criteria import dock
from artic.validation.criteria.direction import direction_of
from artic.validation.criteria.fixedscale import eps_n_fixed
from artic.validation.criteria.metrics import CRITERIA, UNITS, run_metrics
from artic.validation.logs.noise import ChannelNoise, add_noise
from artic.validation.logs.runfile import Run, read_run
from artic.validation.logs.schema import COLUMNS

DRAWS = 16
"""Noise draws per (log, model) run: the standard error of their mean is a
quarter of a single draw's standard deviation."""

NOT_ESTIMATED = {
    "J_steer": "the feedback the harness adds answers noisy inputs; no static comparison has it",
    **{c: "open-loop predictions drive the model from noisy states; no static comparison has it"
       for c in extra.COLUMNS if extra.COMPUTE[c] == "model"},
}
"""Criteria without a floor here, and why."""

FLOORED = tuple(c for c in (*CRITERIA, *extra.COLUMNS) if c not in NOT_ESTIMATED)
"""Criteria with a floor, in ``metrics.csv`` order."""

SIGNED = dock.COLUMNS
"""Signed criteria: their floor is the magnitude a perfect model gets (a mean of signed
noise would be about zero, and a model is ranked by the magnitudes of these errors)."""


def seed_of(log: str, model: str, seed: int = 0) -> list[int]:
    """The generator's seed of a (log, model) pair: ``seed`` and CRC-32 of the names."""
    return [int(seed), zlib.crc32(f"{log}\0{model}".encode())]


def floor_draws(log: Run, run: Run, noise: Mapping[str, ChannelNoise], vehicle: Vehicle,
                scale: Mapping[str, float] | None = None, seed: int = 0,
                draws: int = DRAWS) -> pd.DataFrame:
    """The criteria of :data:`DRAWS` noisy copies of a model run against the run.

    Parameters
    ----------
    log : Run
        The log the model ran on: its name, manoeuvre and direction.
    run : Run
        The model's run through the harness (``meta["model"]`` names it).
    noise : mapping of str to ChannelNoise
        The declared noise, SI.
    vehicle : Vehicle
        The model's vehicle (the dock errors' outline).
    scale : mapping, optional
        The log's direction's fixed scale of ``eps_n_fixed``; NaN without.
    seed : int
        Mixed with the log's and the model's names (:func:`seed_of`).
    draws : int
        Noisy copies.

    Returns
    -------
    DataFrame
        One row per draw, the :data:`FLOORED` columns; empty for a run of
        fewer than two samples.
    """
    if len(run.frame) < 2:
        return pd.DataFrame(columns=list(FLOORED))
    model = str(run.meta.get("model", run.meta.get("name", "")))
    truck = run.frame[list(COLUMNS)].reset_index(drop=True)
    meta = {**log.meta, "name": log.name}
    rng = np.random.default_rng(seed_of(log.name, model, seed))
    rows = []
    for _ in range(draws):
        measured = Run(add_noise(truck, dict(noise), rng), meta)
        crit = run_metrics(measured.frame, truck, beyond=False)
        crit |= extra.of_run(measured, Run(truck, meta), vehicle)
        crit["eps_n_fixed"] = eps_n_fixed(crit["eps_a"], crit["eps_v"], scale)
        rows.append({c: abs(float(crit.get(c, math.nan))) if c in SIGNED
                     else float(crit.get(c, math.nan)) for c in FLOORED})
    return pd.DataFrame(rows, columns=list(FLOORED))


def summarise(draws: pd.DataFrame) -> pd.DataFrame:
    """Per criterion: the floor (mean of the draws) and the 5 and 95 % points of single draws.

    Returns
    -------
    DataFrame
        Indexed by criterion: ``floor``, ``sd`` (standard deviation of single
        draws), ``p5``, ``p95``, ``n`` (draws with a value).
    """
    out = {}
    for c in draws.columns:
        v = pd.to_numeric(draws[c], errors="coerce").dropna().to_numpy()
        out[c] = ({"floor": float(v.mean()), "sd": float(v.std(ddof=1)) if v.size > 1
                   else math.nan, "p5": float(np.percentile(v, 5)),
                   "p95": float(np.percentile(v, 95)), "n": int(v.size)} if v.size
                  else {"floor": math.nan, "sd": math.nan, "p5": math.nan, "p95": math.nan,
                        "n": 0})
    frame = pd.DataFrame.from_dict(out, orient="index")
    frame.index.name = "criterion"
    return frame


def of_runs(logs: Sequence[Run], metrics: pd.DataFrame, runs_dir: Path, vehicle: Vehicle,
            declared: Mapping[str, Mapping[str, ChannelNoise] | None],
            scale: Mapping[str, Mapping[str, float]] | None = None,
            seed: int = 0) -> pd.DataFrame:
    """The floor of every (log, model) run with a result, for the logs with declared noise.

    Parameters
    ----------
    logs : sequence of Run
        The logs validated (a log split at its gaps: its segments).
    metrics : DataFrame
        Their metrics (:func:`artic.validation.runs.validate.validate_runs`).
    runs_dir : Path
        Where the runs were written (``OUT_DIR/runs``).
    vehicle : Vehicle
        The models' vehicle.
    declared : mapping
        Per log name, its declared noise, or None.
    scale : mapping, optional
        The fixed scale of ``eps_n_fixed`` per direction.
    seed : int
        See :func:`floor_draws`.

    Returns
    -------
    DataFrame
        One row per (log, model, criterion), with the log's ``direction``:
        ``floor``, ``sd``, ``p5``, ``p95``, ``n`` (:func:`summarise`) and
        ``score``, the model's own value in ``metrics`` (its magnitude for
        :data:`SIGNED`).
    """
    parts = []
    for log in logs:
        noise = declared.get(log.name)
        if not noise:
            continue
        rows = metrics[(metrics["log"] == log.name) & (metrics["status"].astype(str) == "ok")]
        for r in rows.itertuples(index=False):
            path = Path(runs_dir) / f"{log.name}.{r.model}.parquet"
            if not path.is_file():
                continue
            run = read_run(path, check=False, columns=list(COLUMNS))
            run.meta.setdefault("model", r.model)
            s = (scale or {}).get(direction_of(log))
            table = summarise(floor_draws(log, run, noise, vehicle, s, seed)).reset_index()
            table["score"] = [abs(float(getattr(r, c, math.nan))) if c in SIGNED
                              else float(getattr(r, c, math.nan)) for c in table["criterion"]]
            table.insert(0, "model", r.model)
            table.insert(0, "direction", direction_of(log))
            table.insert(0, "log", log.name)
            parts.append(table)
    cols = ["log", "direction", "model", "criterion", "floor", "sd", "p5", "p95", "n", "score"]
    return pd.concat(parts, ignore_index=True)[cols] if parts else pd.DataFrame(columns=cols)


def text(table: pd.DataFrame, source: str) -> str:
    """The floor per criterion and direction as ``artic validate`` prints it, beside the scores.

    Per direction of travel: ``floor`` is the mean over that direction's
    (log, model) runs of their floors; ``one log (5-95 %)`` the lowest 5 % and
    highest 95 % point of single draws among them; a model's column its mean
    score over the same logs; the last column the floor over the lowest of
    those scores.
    """
    units = {**UNITS, **extra.UNITS}
    models = list(dict.fromkeys(table["model"]))
    runs = len(table[["log", "model"]].drop_duplicates())
    lines = [f"Noise floor: the score a perfect model would get from the sensor noise declared "
             f"in {source} alone (each model's run measured through it, {DRAWS} seeded draws "
             f"per run, {runs} runs); where a model scores near it, the criterion measures "
             "the sensors"]

    def num(x: float) -> str:
        return "-" if not math.isfinite(x) else f"{x:.3g}"

    for direction, part in table.groupby("direction", sort=False):
        head = ["criterion", "floor", "one log (5-95 %)", *models, "floor / lowest score"]
        lines += ["", f"{str(direction).capitalize()} ({part['log'].nunique()} logs)", "",
                  "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for c in FLOORED:
            g = part[part["criterion"] == c]
            if g.empty or not np.isfinite(g["floor"]).any():
                continue
            floor = float(g["floor"].mean())
            scores = [float(g[g["model"] == m]["score"].mean()) for m in models]
            best = min((s for s in scores if math.isfinite(s)), default=math.nan)
            ratio = floor / best if math.isfinite(best) and best > 0 else math.nan
            lines.append(f"| {c} [{units[c]}] | {num(floor)} | {num(float(g['p5'].min()))}-"
                         f"{num(float(g['p95'].max()))} | "
                         + " | ".join(num(s) for s in scores)
                         + f" | {'-' if not math.isfinite(ratio) else f'{100 * ratio:.0f} %'} |")
    shown = sorted({"J_steer" if c == "J_steer" else "pred_*" for c in NOT_ESTIMATED})
    lines.append("")
    lines.append(f"No floor for {', '.join(shown)}: they exist only for a model driven by the "
                 "log, and noisy inputs drive it; the floor is the comparison's part of the noise.")
    return "\n".join(lines)
