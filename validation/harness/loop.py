"""The closed-loop harness: drives any model from a log.

Reversing is open-loop unstable, so a model fed only the measured steering
drifts away from the measurement. The harness closes the loop the way the
paper's eq. (5) intends, with the stabilising sign of its eqs. (6)-(7):

    delta = delta_center(delta_h) + w * K * (gamma_model - gamma_measured)

only while the tractor reverses: the weight ``w`` is 1 while it reverses,
0 otherwise, and ramps between the two over
:data:`~artic.validation.harness.reversing.HANDOVER` (1 s) where a reversing
stretch starts or ends inside the log, so that the steering never steps by the
whole feedback term in one sample (the handover; the ramp's length is argued
in :mod:`artic.validation.harness.reversing`). The linearised articulation
dynamics then have the eigenvalue ``u1 (K (L2 - L1c) - L1) / (L1 L2)``, which is
negative for ``u1 < 0`` once ``K > L1 / (L2 - L1c)``. Forward, the same feedback
would destabilise the loop for such K, so it is off. Whether the tractor
reverses, and the weight, are decided once per log on the speed input ``u1``
below, with a dead band and a minimum duration
(:mod:`artic.validation.harness.reversing`), so that speed noise at standstill
never switches the feedback on in a forward run.

Inputs per sample ``k`` (held over the step to ``k + 1``):

- ``delta_center`` from the log's ``delta_h`` through the model's eq. (3) map,
  or, for a log steered from its yaw rate (``--steer-from yaw-rate``, or a
  ``delta_h`` derived at import), the road-wheel angle of
  :mod:`artic.validation.logs.yawsteer`;
- the tractor speed ``u1 = v_x_1 + r_1 * y_s1``, exact for a rigid tractor
  whose sensor sits ``y_s1`` off its centre line, smoothed by a quadratic
  Savitzky-Golay filter over :data:`SPEED_WINDOW` and rising linearly to the
  next sample's value. The measured speed carries sensor noise (about
  1 cm/s at 100 Hz); its difference quotient, the plant's speed feed-forward,
  would turn that into +-1.4 m/s^2 of drive and brake torque. The filter
  passes a quadratic speed profile exactly and the yard's accelerations
  (about 1 m/s^2, changing over seconds) nearly so;
- the initial pose and motion from the log's first sample.

The applied road-wheel angle is limited to the vehicle's ``delta_max``; the
run's ``delta_saturated`` column says where.

Four loops run this law (:mod:`artic.validation.harness.feedback`): the numba loop of
:mod:`artic.validation.harness.reducedloop` for KIN and the STM (and subclasses
that replace none of what it computes, see :mod:`artic.reduced.control`),
the plant's own loop in C (:mod:`artic.plant.closedloop`, which ``closed_loop()``
offers), the yard truth's in C for the floor and its replay
(:mod:`artic.validation.synthetic.yardloop`, offered the same way), and
:func:`_python_loop` for any other model, through its ``step`` and ``observe``.
The Python loop is the reference the C loops are tested against.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from artic.mjcf.interface import OBSERVATION, InitialState, LoopArgs
from artic.mjcf.steering import Steering
from artic.mjcf.vehicle import Vehicle
from artic.validation.harness.feedback import feedback_law
from artic.validation.harness.reversing import DEFAULT_GAIN, feedback_weight
from artic.validation.logs.differentiate import smooth_speed
from artic.validation.logs.limits import OBSERVATION_LIMIT
from artic.validation.logs.runfile import Run, new_frame
from artic.validation.logs.yawsteer import (
    equivalent_wheelbase,
    road_wheel_from_yaw_rate,
    steering_wheel,
    wants_yaw_rate,
)
from artic.validation.models import Model, compiled_form, driven, own_loop, steering_for
from artic.validation.plumbing.budget import BUDGET


@dataclass(frozen=True)
class LoopInputs:
    """Arrays the loop needs, per sample (see the module docstring)."""

    t: np.ndarray
    delta_h: np.ndarray
    delta_c: np.ndarray
    u1: np.ndarray
    u1_dot: np.ndarray
    gamma_meas: np.ndarray
    weight: np.ndarray
    """The feedback's weight per sample, in [0, 1] (:mod:`artic.validation.harness.reversing`)."""
    initial: InitialState

    @property
    def reversing(self) -> np.ndarray:
        """Which samples reverse (bool): where the feedback's weight is positive."""
        return self.weight > 0.0


def loop_inputs(run: Run, vehicle: Vehicle, steering: Steering) -> LoopInputs:
    """Derive the harness inputs from a log.

    Parameters
    ----------
    run : Run
        A checked log in the signal schema.
    vehicle : Vehicle
        For the tractor sensor's lateral offset.
    steering : Steering
        The model's eq. (3) map.
    """
    inputs = unsteered_inputs(run, vehicle)
    if wants_yaw_rate(run.meta):
        return yaw_steered(inputs, run, vehicle, steering)
    return steered(inputs, steering, f"{run.name}: column delta_h")


def yaw_steered(inputs: LoopInputs, run: Run, vehicle: Vehicle,
                steering: Steering) -> LoopInputs:
    """``inputs`` steered from the measured yaw rate (:mod:`artic.validation.logs.yawsteer`).

    ``delta_h`` becomes the steering-wheel angle that gives ``delta_c`` through
    the model's map, for the record.
    """
    r1 = smooth_speed(inputs.t, run.frame["r_1"].to_numpy(dtype=float))
    delta_c = road_wheel_from_yaw_rate(inputs.u1, r1, equivalent_wheelbase(vehicle))
    delta_h = steering_wheel(steering, delta_c, vehicle.steering.delta_max)
    return _started(replace(inputs, delta_c=delta_c, delta_h=delta_h))


def unsteered_inputs(run: Run, vehicle: Vehicle) -> LoopInputs:
    """:func:`loop_inputs` before the steering map: ``delta_c`` is NaN.

    ``weight`` (and with it ``reversing``) comes from ``u1`` with hysteresis
    (:func:`artic.validation.harness.reversing.feedback_weight`).

    Tuning derives these once per log and applies each trial's map with
    :func:`steered`.
    """
    df = run.frame
    t = df["t"].to_numpy(dtype=float)
    delta_h = df["delta_h"].to_numpy(dtype=float)
    r1 = df["r_1"].to_numpy(dtype=float)
    u1 = smooth_speed(t, df["v_x_1"].to_numpy(dtype=float) + r1 * vehicle.sensor1[1])
    u1_dot = np.zeros_like(u1)
    u1_dot[:-1] = np.diff(u1) / np.diff(t)
    return LoopInputs(
        t=t, delta_h=delta_h, delta_c=np.full_like(delta_h, np.nan), u1=u1,
        u1_dot=u1_dot, gamma_meas=df["gamma"].to_numpy(dtype=float),
        weight=feedback_weight(t, u1, vehicle.speed_ratio),
        initial=initial_state(df, 0, float(u1[0])))


def initial_state(frame: pd.DataFrame, k: int, u1: float) -> InitialState:
    """The state a model starts from at a log's sample ``k``: its pose and motion there.

    Parameters
    ----------
    frame : DataFrame
        The log, in the signal schema.
    k : int
        The sample (0 for the harness's run).
    u1 : float
        The tractor's speed at ``k`` as the harness feeds it (smoothed) [m/s].
    """
    row = frame.iloc[k]
    return InitialState(
        x_1=float(row["x_1"]), y_1=float(row["y_1"]), psi_1=float(row["psi_1"]),
        gamma=float(row["gamma"]), v_y_1=float(row["v_y_1"]), r_1=float(row["r_1"]),
        r_2=float(row["r_2"]), u1=float(u1))


def window(inputs: LoopInputs, frame: pd.DataFrame, start: int, stop: int) -> LoopInputs:
    """The inputs of samples ``start`` to ``stop - 1``, starting from the log's state at ``start``.

    What the open-loop predictions (:mod:`artic.validation.criteria.prediction`)
    drive a model with from a point inside a log.
    """
    part = {f: getattr(inputs, f)[start:stop]
            for f in ("t", "delta_h", "delta_c", "u1", "u1_dot", "gamma_meas", "weight")}
    return _started(LoopInputs(**part, initial=initial_state(frame, start,
                                                             float(inputs.u1[start]))))


def steered(inputs: LoopInputs, steering: Steering, source: str) -> LoopInputs:
    """``inputs`` with ``delta_c`` from ``steering``, after checking its range.

    Raises
    ------
    SteeringRangeError
        When the steering wheel passes the map's fold; ``source`` names the data.
    """
    steering.check_range(inputs.delta_h, source)
    return _started(replace(inputs, delta_c=np.asarray(steering.road_wheel(inputs.delta_h))))


def _started(inputs: LoopInputs) -> LoopInputs:
    """``inputs`` whose initial state carries the first road-wheel angle.

    A log that starts in a turn (a segment after a gap) then starts with its
    tyres at that angle's slip.
    """
    delta = float(inputs.delta_c[0]) if inputs.delta_c.size else 0.0
    if not np.isfinite(delta):  # before the steering map: nothing to start from
        return inputs
    return replace(inputs, initial=replace(inputs.initial, delta=delta))


def loop_args(inputs: LoopInputs, vehicle: Vehicle, gain: float = DEFAULT_GAIN) -> LoopArgs:
    """The per-log arguments of every loop after the model's own: steps, inputs, limits."""
    return LoopArgs(np.diff(inputs.t), inputs.delta_c, inputs.u1, inputs.u1_dot, inputs.gamma_meas,
            inputs.weight, float(gain), vehicle.steering.delta_max, vehicle.gamma_max)


def run_inputs(model: Model, inputs: LoopInputs, vehicle: Vehicle,
               gain: float = DEFAULT_GAIN,
               extras: dict[str, np.ndarray] | None = None,
               start: Callable[[InitialState], None] | None = None) -> tuple[np.ndarray, ...]:
    """Drive a model through prepared inputs.

    With ``extras`` (a dict), a model with ``extras()`` (the plant) has its
    per-sample outputs beyond the schema stored there by column name, as float32.
    ``start`` puts the model into its first state, given ``inputs.initial``;
    ``model.reset`` by default (the open-loop predictions start models in
    other ways, :func:`artic.validation.criteria.prediction.starter`).

    Returns
    -------
    obs, delta, delta_fb, saturated : ndarray
        Per computed sample.
    n_done : int
        Rows computed; fewer than the inputs when the model left the
        plausible range (see :func:`artic.validation.harness.reducedloop.compiled_loop`).
    """
    model = driven(model)
    (model.reset if start is None else start)(inputs.initial)
    args = loop_args(inputs, vehicle, gain)
    form = compiled_form(model)
    if form is not None:
        # Here, not at the top: numba loads only for KIN and the STM, not for the plant's runs.
        from artic.validation.harness.reducedloop import (
            compiled_loop,  # numba: only for KIN and the STM
        )

        out = compiled_loop(tuple(form), tuple(args))
        count_run("reduced", inputs.t, out[4])
        return out
    loop = own_loop(model)
    if loop is not None:  # the plant's loop in C (artic.plant.closedloop)
        res = loop(args, extras=extras is not None)
        if res.raw is not None:
            names = model.extra_columns
            ext = model.extras_from_raw(res.raw).astype(np.float32)
            extras.update((c, ext[:, j]) for j, c in enumerate(names))
        count_run("multibody", inputs.t, res.n_done)
        return res.obs, res.delta, res.delta_fb, res.saturated, res.n_done
    out = _python_loop(model, args, extras=extras)
    # the plant without its compiled parts, a subclass's own dynamics, outside models
    count_run(getattr(model, "budget_kind", "other"), inputs.t, out[4])
    return out


def count_run(kind: str, t: np.ndarray, n_done: int) -> None:
    """Count a run of ``n_done`` samples of ``t`` [s] in the process's budget.

    :data:`artic.validation.plumbing.budget.BUDGET`.
    """
    n = int(n_done)
    BUDGET.add(kind, float(t[n - 1] - t[0]) if n > 1 else 0.0)


DIVERGED = "diverged: "
"""How a status's reason begins when the model's output stopped being finite or left every
physical range (:func:`beyond_limits`): ``artic simulate`` exits 1 on it."""


def beyond_limits(o: np.ndarray) -> str:
    """``""``, or which observed signal of ``o`` is not finite or beyond its limit, and how.

    The text begins with :data:`DIVERGED`.
    """
    for name, value, limit in zip(OBSERVATION, o, OBSERVATION_LIMIT, strict=True):
        if not math.isfinite(value):
            return f"{DIVERGED}{name} stopped being finite"
        if abs(value) > limit:
            return (f"{DIVERGED}{name} = {value:.3g} left the range a model's output may have "
                    f"(|{name}| <= {limit:g} SI)")
    return ""


def _python_loop(model, args: LoopArgs, extras=None):
    dt, delta_c, u1, u1_dot, gamma_meas, weight, gain, delta_max, gamma_max = args
    n = delta_c.size
    obs = np.full((n, 13), np.nan)
    delta, delta_fb = np.full(n, np.nan), np.full(n, np.nan)
    sat = np.zeros(n, dtype=bool)
    names = getattr(model, "extra_columns", ()) if extras is not None else ()
    ext = np.full((n, len(names)), np.nan, dtype=np.float32)
    if names:
        extras.update((c, ext[:, j]) for j, c in enumerate(names))
    for k in range(n):
        d, f, s = feedback_law(delta_c[k], model.gamma, gamma_meas[k], weight[k], gain,
                               delta_max)
        o = model.observe(d)
        obs[k], delta[k], delta_fb[k], sat[k] = o, d, f, s
        if names:
            ext[k] = model.extras()
        if abs(o[12]) > gamma_max or not (np.abs(o) <= OBSERVATION_LIMIT).all():
            return obs, delta, delta_fb, sat, k + 1  # NaN fails the comparison too
        if k + 1 < n:
            model.step(dt[k], d, u1[k], u1_dot[k])
    return obs, delta, delta_fb, sat, n


def run_closed_loop(model: Model, run: Run, vehicle: Vehicle,
                    gain: float = DEFAULT_GAIN, extras: bool = True) -> Run:
    """Drive a model from a log with the reversing feedback.

    Parameters
    ----------
    model : Model
        ``artic.KIN``, ``artic.STM``, the plant or any model of the protocol
        (:class:`artic.validation.models.Model`), built from ``vehicle``.
    run : Run
        The measured log.
    vehicle : Vehicle
        The parameters the model was built from; its steering map for
        ``model.name`` turns ``delta_h`` into ``delta_center``.
    gain : float
        K [rad/rad]; 0 runs open loop.
    extras : bool
        Record the plant's ``extras()`` columns (about a fifth of its step time).

    Returns
    -------
    Run
        The model's run in the signal schema plus ``delta``, ``delta_fb`` and
        ``delta_saturated`` (and the plant's ``extras()`` columns).
        ``meta["status"]`` is ``"ok"``, or says where and why the run stopped
        early; the rows after that are not written.

    See Also
    --------
    artic.simulate : open loop, through a profile.
    artic.run_metrics : the criteria of its run.
    artic.validate_runs : many logs and models at once.

    Examples
    --------
    A model driven from its own simulated log reproduces it:

    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> kin = artic.build_model("kin", vehicle)
    >>> log = artic.simulate(kin, vehicle, artic.make_profile("ramp-steer-reverse",
    ...                                                       duration=10.0))
    >>> run = artic.run_closed_loop(kin, log, vehicle)
    >>> bool(abs(run.frame["gamma"] - log.frame["gamma"]).max() < 1e-6)  # [rad]
    True
    """
    steering = steering_for(vehicle, model)
    inputs = loop_inputs(run, vehicle, steering)
    extra: dict[str, np.ndarray] | None = {} if extras else None
    obs, delta, delta_fb, sat, n = run_inputs(model, inputs, vehicle, gain, extra)
    frame = new_frame(inputs.t[:n], inputs.delta_h[:n], obs[:n])
    frame["delta"] = delta[:n]
    frame["delta_fb"] = delta_fb[:n]
    frame["delta_saturated"] = sat[:n]
    if extra:  # the plant's outputs beyond the schema (see plant.Plant.extras)
        frame = pd.concat([frame, pd.DataFrame({c: a[:n] for c, a in extra.items()})],
                          axis=1)
    status = "ok"
    if n < inputs.t.size:
        g = obs[n - 1, 12]
        why = beyond_limits(obs[n - 1]) or (
            f"articulation {math.degrees(g):.1f} deg passed the jackknife limit "
            f"{math.degrees(vehicle.gamma_max):.1f} deg")
        status = f"stopped at t = {inputs.t[n - 1]:.2f} s: {why}"
    meta = {
        "name": f"{run.name}.{model.name}", "source": f"model:{model.name}",
        "log": run.name, "model": model.name, "gain": float(gain), "vehicle": vehicle.name,
        "vehicle_path": vehicle.path, "status": status,
        "steering": {"i_s": steering.i_s, "q": steering.q,
                     "delta_h_offset": steering.delta_h_offset},
        "steer_from": "yaw-rate" if wants_yaw_rate(run.meta) else "delta_h",
        **{k: run.meta[k] for k in ("manoeuvre", "direction", "load") if k in run.meta},
    }
    return Run(frame, meta)
