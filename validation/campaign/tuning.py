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
terms whose sum is ``eps_n``. The fit works in coordinates scaled to the
bounds, so all parameters weigh alike. Forward, the harness's feedback is
off, so the fit sees the models' open-loop response, as the paper's does.

Solvers. A model that tunes ``f`` (the STM): L-BFGS-B on the sum of
squares, its gradient ``2 J^T r`` from forward differences of the residuals
(:func:`quasi_newton_fit`). The others: ``scipy.optimize.least_squares``
(trust-region reflective, a Gauss-Newton method), with its own differences
for KIN and with Broyden's updates for the plant
(:class:`ParallelJacobian`). Gauss-Newton models the cost's curvature by
``J^T J`` alone and leaves out ``sum r_i grad^2 r_i``, which is small only
where the residuals are: a model that cannot fit the logs exactly (the STM's
eps_n stays near 5 %) is a large-residual problem, and along the STM's
flat valley in ``f`` (its lateral slip scales as ``1/f``) Gauss-Newton's
steps were short: ``least_squares`` took 119 and 251 evaluations (seed 0,
unloaded and loaded), 170 of them moving ``f`` from 11.8 to 13.1 for 0.16 %
of the cost. L-BFGS-B learns the whole curvature from its gradients and
reaches the same optimum (``f`` within 1e-4 relative, the cost within 1e-9
relative) in 65 and 105 (seeds 0-2: 455 evaluations in all of 947;
``tests/test_tuning.py`` holds it to ``least_squares``' optimum). Without
``f`` the residuals are nearly linear in the steering parameters (``i_s``,
``q``, the offset) and Gauss-Newton is the quicker: KIN's fits take 20-24
evaluations by ``least_squares`` and 52 by L-BFGS-B, to the same optimum; the
plant's, with Broyden's updates, 6-8.

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
from scipy.optimize import least_squares, minimize

from artic.mjcf.errors import UserError
from artic.mjcf.interface import OBS_INDEX
from artic.mjcf.vehicle import Vehicle
from artic.validation.criteria.distance import distance_mean_abs, distance_weights
from artic.validation.harness.batch import run_batch, run_many
from artic.validation.harness.loop import DEFAULT_GAIN, steered, unsteered_inputs
from artic.validation.logs.runfile import Run
from artic.validation.models import spec, steering_for
from artic.validation.plumbing.progress import duration

SIGNALS = (("r_1", "r"), ("r_2", "r"), ("v_y_1", "v_y"), ("v_y_2", "v_y"))

DIFF_STEP = 1e-3
"""Forward-difference step in the bound-scaled coordinates [-]."""

GRADIENT_STEP = 1e-6
"""Forward-difference step of :func:`quasi_newton_fit`'s gradient, in the
bound-scaled coordinates [-]: the STM's runs are smooth in their
parameters to rounding, and the gradient must still resolve the STM's flat
valley near the optimum, where ``DIFF_STEP`` (1e-3) would not (its truncation
error, ``h/2`` times the curvature, is then the size of the gradient)."""

QUASI_NEWTON_FTOL = 1e-10
"""L-BFGS-B's stop (the STM's fit): the cost fell by less than this in
one iteration (relative to ``max(cost, 1)``, i.e. absolutely, as the costs are
below 1). The cost at the optimum is about 4e-3: this is 2.5e-8 of it, where
``least_squares``' ftol was 1e-8 of it."""

TOLERANCES = {"batched": (1e-6, 1e-8), "plant": (1e-4, 1e-6)}
"""``least_squares``' xtol and ftol: ``batched`` for KIN (and
:func:`full_difference_fit`, the reference the tests hold the fits against),
``plant`` for the plant.

The plant's are looser: each of its evaluations costs a second, and it stops
within 1e-4 of each bound's span (1e-3 in i_s, 5e-5 rad in the offset), far
inside what tuning can tell apart. On the campaign's logs its fit is within
2e-6 relative in i_s and 9e-5 rad (0.005 deg) in the offset of the fit with
full differences from the nominal values and the tighter tolerances, in 8-9
evaluations instead of 21-25; 6-8 since a last step shorter than xtol is not
run (:class:`ParallelJacobian`), which moves the fit by less than that step
(on the campaign's seed 0: 1e-5 relative in i_s, 3e-5 rad in the offset)."""

MBD_MAX_EVALUATIONS = 40
"""Cap on objective evaluations for the plant (one run per tuning log each)."""

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
    s = steering_for(vehicle, model)
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
        self._unsteered = [unsteered_inputs(log, vehicle) for log in logs]
        for log in logs:
            f = log.frame
            w = distance_weights(f["t"].to_numpy(), np.hypot(f["v_x_1"], f["v_y_1"]))
            s_max = float(w.sum())
            if s_max <= 0:
                raise UserError(f"{log.name}: the tractor does not move; it cannot tune")
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
        return self.simulate_many([x])[0]

    def simulate_many(self, xs: Sequence[np.ndarray]) -> list:
        """Run the model at every ``x`` of ``xs`` on every log, all runs on one pool.

        For a model without a compiled form (the plant) the ``len(xs) * len(logs)``
        runs share :attr:`jobs` threads, so a finite-difference Jacobian's
        columns run in parallel; KIN and STM run one compiled batch per ``x``.
        Returns one batch result per ``x``.
        """
        vehicles = [self.vehicle_at(x) for x in xs]
        inputs = []
        for v in vehicles:
            steering = steering_for(v, self.model)
            inputs.append([steered(base, steering, f"{log.name}: column delta_h")
                           for log, base in zip(self.logs, self._unsteered, strict=True)])
        build = spec(self.model).build
        if spec(self.model).batched:
            results = [run_batch(build, v, inp, self.gain, self.jobs)
                       for v, inp in zip(vehicles, inputs, strict=True)]
        else:
            flat = run_many(build, [v for v in vehicles for _ in self.logs],
                            [i for inp in inputs for i in inp], self.gain, self.jobs)
            n = len(self.logs)
            results = [flat.part(k * n, (k + 1) * n) for k in range(len(xs))]
        for res in results:
            self.evaluations += 1
            for log, text in zip(self.logs, res.limited, strict=False):
                if text:
                    self.limited.setdefault(log.name, text)
            if self.on_evaluation is not None:
                self.on_evaluation(self)
        return results

    def residuals(self, x: np.ndarray) -> np.ndarray:
        """The stacked, normalised residuals (see the module docstring)."""
        return self.residuals_of(self.simulate(x))

    def residuals_of(self, res) -> np.ndarray:
        """:meth:`residuals` from a batch result already computed."""
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


def forward_steps(z: np.ndarray, lo: float = 0.0, hi: float = 1.0) -> np.ndarray:
    """Steps of ``least_squares``' two-point differences at ``z`` within [lo, hi].

    ``DIFF_STEP * |z|`` (``DIFF_STEP * max(1, |z|)`` where that would vanish),
    turned backwards where it would leave the bounds, or cut to the room
    there is, as ``scipy.optimize._numdiff`` does with ``rel_step`` and bounds.
    """
    sign = (z >= 0).astype(float) * 2 - 1
    h = DIFF_STEP * sign * np.abs(z)
    h = np.where((z + h) - z == 0, DIFF_STEP * sign * np.maximum(1.0, np.abs(z)), h)
    lower, upper = z - lo, hi - z
    x = z + h
    violated = (x < lo) | (x > hi)
    fitting = np.abs(h) <= np.maximum(lower, upper)
    h = np.where(violated & fitting, -h, h)
    h = np.where((upper >= lower) & ~fitting, upper, h)
    return np.where((upper < lower) & ~fitting, -lower, h)


class WithinTolerance(Exception):  # noqa: N818 - a result, not an error
    """A trial point so near the current one that ``least_squares`` would stop after it.

    Carries the current point ``z`` and its residuals ``f`` [scaled units].
    """

    def __init__(self, z: np.ndarray, f: np.ndarray) -> None:
        super().__init__("the next step is within xtol")
        self.z, self.f = z, f


class ParallelJacobian:
    """The plant's Jacobian: one forward difference, then Broyden's updates.

    At the first point, a forward-difference Jacobian whose columns run at
    once on the objective's pool, with the steps of
    ``least_squares(diff_step=DIFF_STEP)``'s own two-point scheme
    (:func:`forward_steps`). At every later point ``least_squares`` accepts,
    Broyden's rank-one update from the last one,

        J += ((f - f_prev) - J dz) dz^T / (dz^T dz),

    which costs no plant run: the residual ``f`` at the new point is the one
    ``least_squares`` evaluated just before asking for the Jacobian. On the
    campaign's tuning logs, at the same tolerances, this reaches the optimum
    of the full differences within 1e-6 relative in the ratio and 2.4e-4 rad
    in the offset, with half the plant runs (``tests/test_tuning.py`` checks
    it on a plant fit).

    With ``xtol``, a trial point whose step from the current point is shorter
    than ``least_squares``' own step tolerance, ``xtol * (xtol + |z|)``, is
    not run: :meth:`fun` raises :class:`WithinTolerance` instead. Such a step
    is always ``least_squares``' last, whatever its outcome (trf checks the
    step length after every evaluation, accepted or not), and it would only
    choose between two points closer than the tolerance it stops at. The fit
    then ends at the current point; on the campaign's logs this spares the
    plant's last evaluation (4 runs of 40 s) in most fits.
    """

    def __init__(self, obj: Objective, lo: np.ndarray, span: np.ndarray,
                 xtol: float | None = None) -> None:
        self.obj, self.lo, self.span, self.xtol = obj, lo, span, xtol
        self.last: tuple[np.ndarray, np.ndarray] | None = None
        self.accepted = None

    def fun(self, z: np.ndarray) -> np.ndarray:
        """Residuals at scaled ``z``; remembered for the Jacobian at the same point."""
        if self.last is not None and np.array_equal(self.last[0], z):
            return self.last[1].copy()
        if self.xtol is not None and self.accepted is not None:
            here, f_here = self.accepted[0], self.accepted[1]
            if np.linalg.norm(z - here) < self.xtol * (self.xtol + np.linalg.norm(here)):
                raise WithinTolerance(here.copy(), f_here.copy())
        f = self.obj.residuals(self.lo + self.span * z)
        self.last = (np.array(z, dtype=float), f)
        return f

    def __call__(self, z: np.ndarray) -> np.ndarray:
        """The Jacobian of the residuals at scaled ``z``, shape (n_residuals, n_parameters)."""
        return self.update(z) if self.accepted is not None else self.differences(z)

    def update(self, z: np.ndarray) -> np.ndarray:
        """Broyden's update of the last Jacobian to ``z`` (no plant run)."""
        z = np.asarray(z, dtype=float)
        z1, f1, J = self.accepted
        f0 = self.fun(z)  # remembered: least_squares evaluated it just now
        dz = z - z1
        if not np.any(dz):
            return J
        J = J + np.outer((f0 - f1) - J @ dz, dz) / float(dz @ dz)
        self.accepted = (z.copy(), f0, J)
        return J

    def differences(self, z: np.ndarray) -> np.ndarray:
        """The forward-difference Jacobian at ``z``, its columns run at once."""
        z = np.asarray(z, dtype=float)
        if self.last is not None and np.array_equal(self.last[0], z):
            f0 = self.last[1]
        else:
            f0 = self.fun(z)
        h = forward_steps(z)
        steps = [z + np.where(np.arange(z.size) == i, h, 0.0) for i in range(z.size)]
        dz = np.array([s[i] - z[i] for i, s in enumerate(steps)])
        runs = self.obj.simulate_many([self.lo + self.span * s for s in steps])
        cols = [(self.obj.residuals_of(r) - f0) / d for r, d in zip(runs, dz, strict=True)]
        J = np.column_stack(cols)
        self.accepted = (z.copy(), f0, J)
        return J


def quasi_newton_fit(obj: Objective, z0: np.ndarray, r0: np.ndarray,
                     max_nfev: int) -> tuple[np.ndarray, np.ndarray]:
    """The fit of a model that tunes ``f``: L-BFGS-B on the sum of squared residuals.

    The gradient is ``2 J^T r``, ``J`` by forward differences of
    :data:`GRADIENT_STEP` in the bound-scaled coordinates ``z`` (backwards at
    the upper bound), the point and its steps run together. See the module
    docstring for why not Gauss-Newton.

    Parameters
    ----------
    obj : Objective
        The residuals.
    z0 : ndarray
        Start, bound-scaled [-].
    r0 : ndarray
        The residuals at ``z0``, already run.
    max_nfev : int
        Most points L-BFGS-B may evaluate (each with its gradient).

    Returns
    -------
    z : ndarray
        The fit, bound-scaled [-]: the point of lowest cost evaluated, where
        L-BFGS-B, a descent method, ends.
    r : ndarray
        Its residuals.
    """
    lo = np.array([b.lo for b in obj.bounds])
    span = np.array([b.hi - b.lo for b in obj.bounds])
    z0 = np.asarray(z0, dtype=float)
    best = [float(r0 @ r0), z0, r0]  # the lowest cost evaluated: L-BFGS-B descends

    def cost_and_gradient(z: np.ndarray) -> tuple[float, np.ndarray]:
        z = np.asarray(z, dtype=float)
        h = np.where(z + GRADIENT_STEP <= 1.0, GRADIENT_STEP, -GRADIENT_STEP)
        steps = [z + hk * e for hk, e in zip(h, np.eye(z.size), strict=True)]
        known = np.array_equal(z, z0)
        runs = [obj.residuals_of(res) for res in
                obj.simulate_many([lo + span * p for p in (steps if known else [z, *steps])])]
        r = r0 if known else runs.pop(0)
        cost = float(r @ r)
        if cost < best[0]:
            best[:] = [cost, z.copy(), r]
        J = np.column_stack([(rk - r) / hk for rk, hk in zip(runs, h, strict=True)])
        return cost, 2.0 * (J.T @ r)

    minimize(cost_and_gradient, z0, jac=True, method="L-BFGS-B",
             bounds=[(0.0, 1.0)] * len(obj.bounds),
             options={"ftol": QUASI_NEWTON_FTOL, "gtol": 1e-12, "maxfun": max_nfev})
    return best[1], best[2]


def full_difference_fit(obj: Objective) -> tuple[dict[str, float], float]:
    """The reference fit: ``least_squares``' own two-point differences at every step.

    From the nominal values, with KIN's tolerances, one evaluation
    after another: the plant's fit before its shortcuts (start values,
    :class:`ParallelJacobian`, looser tolerances), which the tests and
    ``benchmarks/bench_tuning.py`` hold them against.

    Returns
    -------
    fitted : dict
        Parameter values by name.
    cost : float
        Sum of the squared residuals at the fit.
    """
    lo = np.array([b.lo for b in obj.bounds])
    span = np.array([b.hi - b.lo for b in obj.bounds])
    z0 = (np.array([b.nominal for b in obj.bounds]) - lo) / span
    xtol, ftol = TOLERANCES["batched"]
    sol = least_squares(lambda z: obj.residuals(lo + span * z), z0, bounds=(0.0, 1.0),
                        method="trf", diff_step=DIFF_STEP, xtol=xtol, ftol=ftol)
    fitted = dict(zip(obj.names, map(float, lo + span * sol.x), strict=True))
    return fitted, float(2.0 * sol.cost)


def start_values(bounds: Sequence[Bound], start: dict[str, float] | None) -> np.ndarray:
    """The fit's first point: ``start``'s values where it has them, else the nominal ones.

    Values are moved strictly inside their bounds: by 1e-3 of the span below
    the upper one, so a forward difference fits, and by 1e-6 of the span
    above the lower one. ``least_squares`` would otherwise nudge a start on
    the lower bound inside itself, and the plant's first run at the start
    (remembered for the Jacobian) would be run again a hair away.
    """
    out = []
    for b in bounds:
        x = (start or {}).get(b.name, b.nominal)
        span = b.hi - b.lo
        out.append(min(max(float(x), b.lo + 1e-6 * span), b.hi - 1e-3 * span))
    return np.array(out)


def tune_model(model: str, vehicle: Vehicle, logs: Sequence[Run], jobs: int = 1,
               progress: Callable[[str], None] | None = None,
               start: dict[str, float] | None = None) -> Fit:
    """Fit one model's parameters on ``logs``; see the module docstring.

    Parameters
    ----------
    model : str
        A registry name.
    vehicle : Vehicle
        The preset; its values are the nominal ones.
    logs : sequence of Run
        The tuning logs.
    jobs : int
        Threads for the plant's runs.
    progress : callable, optional
        Receives progress lines.
    start : dict, optional
        Start values by parameter name (the campaign passes the STM's fitted
        steering ratio and offset to the plant); the nominal values otherwise.
    """
    t0 = time.perf_counter()
    obj = Objective(model, vehicle, logs, jobs)
    lo = np.array([b.lo for b in obj.bounds])
    hi = np.array([b.hi for b in obj.bounds])
    x0 = start_values(obj.bounds, start)
    span = hi - lo
    xtol, ftol = TOLERANCES["batched" if spec(model).batched else "plant"]
    # The plant's last step within xtol is not run (see ParallelJacobian).
    jac = ParallelJacobian(obj, lo, span, None if spec(model).batched else xtol)
    fun = jac.fun

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
    if not obj.bounds:  # a registered model that tunes nothing: its error as it is
        return Fit(model=model, bounds=[], fitted={}, cost_before=before, cost_after=before,
                   eps_n_before=obj.eps_n_of(r0), eps_n_after=obj.eps_n_of(r0),
                   evaluations=obj.evaluations, wall_s=time.perf_counter() - t0)
    # The STM (it tunes f): L-BFGS-B. KIN: least_squares' own differences, each
    # a compiled batch. The plant: those differences once, all columns' runs on
    # the thread pool, then Broyden's updates (ParallelJacobian). See the
    # module docstring.
    if "f" in obj.names:
        z_fit, f_fit = quasi_newton_fit(obj, z0, r0, max_nfev)
        cost = float(np.dot(f_fit, f_fit))
    else:
        kw = {"diff_step": DIFF_STEP} if spec(model).batched else {"jac": jac}
        try:
            sol = least_squares(fun, z0, bounds=(0.0, 1.0), method="trf", x_scale=1.0,
                                xtol=xtol, ftol=ftol, max_nfev=max_nfev, **kw)
            z_fit, f_fit, cost = sol.x, sol.fun, float(2.0 * sol.cost)
        except WithinTolerance as done:  # the fit is where it stands, within xtol
            z_fit, f_fit = done.z, done.f
            cost = float(np.dot(f_fit, f_fit))  # as least_squares computes it
    x = lo + span * z_fit
    fit = Fit(model=model, bounds=obj.bounds, fitted=dict(zip(obj.names, map(float, x),
                                                              strict=True)),
              cost_before=before, cost_after=cost,
              eps_n_before=obj.eps_n_of(r0), eps_n_after=obj.eps_n_of(f_fit),
              evaluations=obj.evaluations, wall_s=time.perf_counter() - t0,
              at_bound=[n for n, z in zip(obj.names, z_fit, strict=True)
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
        raise UserError("no tuning logs given")
    fits = [tune_model(m, vehicle, logs, jobs, progress) for m in models]
    out = vehicle
    for fit in fits:
        out = apply(out, fit.model, fit.fitted)
    return out, fits
