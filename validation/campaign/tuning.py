"""Tuning: fit each model's free parameters to forward manoeuvres.

The paper tunes the normalised cornering stiffness ``f`` (STM), the steering
ratio ``i_s`` and the asymmetry ``q`` (all models) on 8 forward manoeuvres,
by its error criteria. artic also fits the steering-wheel offset, which the
paper removes by hand.

Objective. For every tuning log and every signal of ``eps_n`` (the yaw
rates and lateral velocities of both units) the residual is

    sqrt(w_k / s_max) * (model_k - measured_k) / mean_abs,

with ``w_k`` the distance weights of eq. (8) and ``mean_abs`` the
distance-averaged mean magnitude that normalises eq. (9)'s ``eps_n``. The
sum of squares over a signal is then exactly that signal's
``(eps / mean_abs)**2``: the fit minimises the squares of the normalised
terms whose sum is ``eps_n``. ``scipy.optimize.least_squares`` (trust-region
reflective) works in coordinates scaled to the bounds, so all parameters
weigh alike. Forward, the harness's feedback is off, so the fit sees the
models' open-loop response, as the paper's does.

Bounds. ``i_s`` within 25 % of its nominal value; ``q`` from 0 (the
parameter files' domain: a linkage driven from the left wheel) to 0.04 /rad
and below 90 % of the fold of eq. (3) for the largest steering angle in the
logs; the offset within +-15 deg; ``f`` from 1 to 30 /rad. A fit that ends
on a bound is reported as such: the plant, whose linkage makes its
asymmetry, typically ends at ``q = 0``.

The fit minimises the sum of the squared normalised terms; ``eps_n`` is the
sum of the terms themselves, so on a small tuning set ``eps_n`` can end a
little above its start while the squares have fallen.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import least_squares

from mjcf.interface import OBS_INDEX
from mjcf.vehicle import Vehicle
from validation.batch import run_batch
from validation.harness import DEFAULT_GAIN, loop_inputs
from validation.logs.runfile import Run
from validation.metrics import distance_mean_abs, distance_weights
from validation.models import spec
from validation.progress import duration
from validation.steering import SteeringMap

SIGNALS = (("r_1", "r"), ("r_2", "r"), ("v_y_1", "v_y"), ("v_y_2", "v_y"))

MBD_MAX_EVALUATIONS = 40
"""Cap on objective evaluations for the plant (8 plant runs each)."""

TUNING_EVERY = 10.0
"""Shortest time between two progress lines of one fit [s]."""


@dataclass(frozen=True)
class Bound:
    """A fitted parameter: name, nominal value and bounds [SI]."""

    name: str
    nominal: float
    lo: float
    hi: float


@dataclass
class Fit:
    """The result of tuning one model."""

    model: str
    bounds: list[Bound]
    fitted: dict[str, float]
    cost_before: float
    cost_after: float
    eps_n_before: float
    eps_n_after: float
    evaluations: int
    wall_s: float
    at_bound: list[str] = field(default_factory=list)

    def rows(self) -> list[dict]:
        """One row per parameter, for tables."""
        return [{"model": self.model, "parameter": b.name, "nominal": b.nominal,
                 "fitted": self.fitted[b.name], "lo": b.lo, "hi": b.hi,
                 "at_bound": b.name in self.at_bound} for b in self.bounds]


def bounds_for(model: str, vehicle: Vehicle, logs: Sequence[Run]) -> list[Bound]:
    """The fitted parameters of ``model`` with their bounds (see the module docstring)."""
    s = vehicle.steering_for(model)
    peak = max(float(np.nanmax(np.abs(log.frame["delta_h"].to_numpy()))) for log in logs)
    q_max = min(0.04, 0.9 / (2.0 * (peak + math.radians(15.0))))
    out = []
    for name in spec(model).tuned:
        if name == "f":
            out.append(Bound("f", vehicle.f, 1.0, 30.0))
        elif name == "i_s":
            out.append(Bound("i_s", s.i_s, 0.75 * s.i_s, 1.25 * s.i_s))
        elif name == "q":
            out.append(Bound("q", min(s.q, q_max), 0.0, q_max))
        else:
            off = math.radians(15.0)
            out.append(Bound("delta_h_offset", s.delta_h_offset, -off, off))
    return out


def apply(vehicle: Vehicle, model: str, values: dict[str, float]) -> Vehicle:
    """The vehicle with ``model``'s fitted values in place."""
    steer = {k: v for k, v in values.items() if k in ("i_s", "q", "delta_h_offset")}
    overrides = {m: dict(o) for m, o in vehicle.steering_overrides.items()}
    overrides[model] = {**overrides.get(model, {}), **steer}
    out = replace(vehicle, steering_overrides=overrides)
    if "f" in values:
        out = replace(out, f=values["f"])
    return out


class Objective:
    """Residuals of one model on a set of logs, as a function of its parameters."""

    def __init__(self, model: str, vehicle: Vehicle, logs: Sequence[Run], jobs: int = 1,
                 gain: float = DEFAULT_GAIN) -> None:
        self.model, self.vehicle, self.logs, self.jobs, self.gain = model, vehicle, logs, jobs, gain
        self.bounds = bounds_for(model, vehicle, logs)
        self.evaluations = 0
        self.limited: dict[str, str] = {}  # log -> what the model limited, first seen
        self.on_evaluation: Callable[[Objective], None] | None = None
        self._meas = []
        for log in logs:
            f = log.frame
            w = distance_weights(f["t"].to_numpy(), np.hypot(f["v_x_1"], f["v_y_1"]))
            s_max = float(w.sum())
            if s_max <= 0:
                raise ValueError(f"{log.name}: the tractor does not move; it cannot tune")
            sig = {c: f[c].to_numpy(dtype=float) for c, _ in SIGNALS}
            scale = {"r": distance_mean_abs(sig["r_1"], w) + distance_mean_abs(sig["r_2"], w),
                     "v_y": distance_mean_abs(sig["v_y_1"], w)
                     + distance_mean_abs(sig["v_y_2"], w)}
            self._meas.append((np.sqrt(w / s_max), sig, scale))

    def vehicle_at(self, x: np.ndarray) -> Vehicle:
        """The vehicle with parameter vector ``x`` applied."""
        return apply(self.vehicle, self.model, dict(zip(self.names, map(float, x), strict=True)))

    @property
    def names(self) -> list[str]:
        """Fitted parameter names, in vector order."""
        return [b.name for b in self.bounds]

    def simulate(self, x: np.ndarray):
        """Run the model at ``x`` on every log; returns the batch result."""
        v = self.vehicle_at(x)
        steering = SteeringMap.from_steering(v.steering_for(self.model))
        inputs = [loop_inputs(log, v, steering) for log in self.logs]
        self.evaluations += 1
        res = run_batch(spec(self.model).build, v, inputs, self.gain, self.jobs)
        for log, text in zip(self.logs, res.limited, strict=False):
            if text:
                self.limited.setdefault(log.name, text)
        if self.on_evaluation is not None:
            self.on_evaluation(self)
        return res

    def residuals(self, x: np.ndarray) -> np.ndarray:
        """The stacked, normalised residuals (see the module docstring)."""
        res = self.simulate(x)
        out = []
        for i, (sw, sig, scale) in enumerate(self._meas):
            obs, n = res.obs[i], int(res.n_done[i])
            for col, kind in SIGNALS:
                e = np.full(sw.size, 10.0)  # a run that stopped early: a large, finite error
                e[:n] = (obs[:n, OBS_INDEX[col]] - sig[col][:n]) / scale[kind]
                out.append(sw * e)
        return np.concatenate(out)

    def eps_n(self, x: np.ndarray) -> float:
        """Mean over the logs of the eq. (9) normalised error [%] at ``x``."""
        return self.eps_n_of(self.residuals(x))

    def eps_n_of(self, flat: np.ndarray) -> float:
        """:meth:`eps_n` from residuals already computed (no simulation).

        Each signal's residuals have the root sum of squares ``eps / mean_abs``,
        so their sum per log is ``eps_n / 100``.
        """
        per_log, k = [], 0
        for sw, _, _ in self._meas:
            total = 0.0
            for _ in SIGNALS:
                total += float(np.sqrt(np.sum(flat[k:k + sw.size] ** 2)))
                k += sw.size
            per_log.append(100.0 * total)
        return float(np.mean(per_log))


def tune_model(model: str, vehicle: Vehicle, logs: Sequence[Run], jobs: int = 1,
               progress: Callable[[str], None] | None = None) -> Fit:
    """Fit one model's parameters on ``logs``; see the module docstring."""
    t0 = time.perf_counter()
    obj = Objective(model, vehicle, logs, jobs)
    lo = np.array([b.lo for b in obj.bounds])
    hi = np.array([b.hi for b in obj.bounds])
    x0 = np.array([b.nominal for b in obj.bounds])
    span = hi - lo

    def fun(z):
        return obj.residuals(lo + span * z)

    z0 = (x0 - lo) / span
    max_nfev = MBD_MAX_EVALUATIONS if model == "mbd" else 100 * len(obj.bounds)
    # least_squares counts neither the Jacobian's len(bounds) evaluations per
    # step in max_nfev, nor the start, evaluated here once more.
    bound = 1 + max_nfev * (1 + len(obj.bounds))
    last = [t0]
    first = [0.0]  # end of the first evaluation, which may include compiling

    def report(o: Objective) -> None:
        now = time.perf_counter()
        if o.evaluations == 1:
            first[0] = now
        if progress is None or o.evaluations < 3 or now - last[0] < TUNING_EVERY:
            return
        last[0] = now
        per = (now - first[0]) / (o.evaluations - 1)
        progress(f"tuning {model} on {len(logs)} logs: evaluation {o.evaluations} of at most "
                 f"{bound} ({duration(now - t0)} so far, {duration(per)} each; at most "
                 f"{duration(per * (bound - o.evaluations))} left, usually far less)")

    obj.on_evaluation = report
    r0 = fun(z0)
    before = float(np.sum(r0 ** 2))
    kw = {"max_nfev": max_nfev}
    sol = least_squares(fun, z0, bounds=(0.0, 1.0), method="trf", diff_step=1e-3,
                        x_scale=1.0, xtol=1e-6, ftol=1e-8, **kw)
    x = lo + span * sol.x
    fit = Fit(model=model, bounds=obj.bounds, fitted=dict(zip(obj.names, map(float, x),
                                                              strict=True)),
              cost_before=before, cost_after=float(2.0 * sol.cost),
              eps_n_before=obj.eps_n_of(r0), eps_n_after=obj.eps_n_of(sol.fun),
              evaluations=obj.evaluations, wall_s=time.perf_counter() - t0,
              at_bound=[n for n, z in zip(obj.names, sol.x, strict=True)
                        if z < 1e-4 or z > 1 - 1e-4])
    if progress is not None:
        for name, text in obj.limited.items():
            progress(f"tuning {model} on {name}: limited: {text}")
        vals = ", ".join(f"{k} = {v:.5g}" for k, v in fit.fitted.items())
        progress(f"tuned {model} on {len(logs)} logs: {vals}; eps_n {fit.eps_n_before:.2f} -> "
                 f"{fit.eps_n_after:.2f} % ({fit.evaluations} evaluations, {fit.wall_s:.1f} s)"
                 + (f"; at bound: {', '.join(fit.at_bound)}" if fit.at_bound else ""))
    return fit


def tune(vehicle: Vehicle, logs: Sequence[Run], models: Sequence[str], jobs: int = 1,
         progress: Callable[[str], None] | None = None) -> tuple[Vehicle, list[Fit]]:
    """Tune every model in turn; returns the vehicle with all fits applied, and the fits."""
    if not logs:
        raise ValueError("no tuning logs given")
    fits = [tune_model(m, vehicle, logs, jobs, progress) for m in models]
    out = vehicle
    for fit in fits:
        out = apply(out, fit.model, fit.fitted)
    return out, fits
