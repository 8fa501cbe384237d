"""Open-loop simulation of a manoeuvre, and an articulation-tracking driver.

``simulate`` feeds a profile's steering wheel and speed to a model with no
feedback. A reversing run with steady steer diverges. It stops when the
articulation passes the vehicle's jackknife limit and says so in its status.

``drive_articulation`` reverses while a driver steers so that the articulation
follows a reference. It is the simplest stable way to produce a reversing
run, and it is what a driver does: steer the tractor so that the trailer swings
the right way.
"""

from __future__ import annotations

import math

import numpy as np

from artic.mjcf.interface import InitialState
from artic.mjcf.steering import Steering
from artic.mjcf.vehicle import Vehicle
from artic.validation.harness.feedback import feedback_law
from artic.validation.harness.loop import LoopInputs, beyond_limits, run_inputs
from artic.validation.logs.profile import Profile
from artic.validation.logs.runfile import Run, new_frame
from artic.validation.models import Model, driven, steering_for


def simulate(model: Model, vehicle: Vehicle, profile: Profile) -> Run:
    """Run a model open loop through a manoeuvre profile.

    Parameters
    ----------
    model : Model
        Built from ``vehicle``.
    vehicle : Vehicle
        Its steering map (for ``model.name``) turns ``delta_h`` into ``delta``.
    profile : Profile
        The inputs.

    Returns
    -------
    Run
        Signal schema plus ``delta``; ``meta["status"]`` reports an early stop.

    See Also
    --------
    artic.make_profile : a profile of inputs.
    artic.Profile : what it drives through.
    artic.run_closed_loop : a model through a log, with feedback.

    Examples
    --------
    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> profile = artic.make_profile("constant-steer", amplitude_deg=90, speed_kph=5,
    ...                              duration=8.0)
    >>> run = artic.simulate(artic.build_model("kin", vehicle), vehicle, profile)
    >>> run.frame.shape[0], bool(run.frame["gamma"].abs().max() > 0.01)  # it turned [rad]
    (801, True)
    """
    steering = steering_for(vehicle, model)
    steering.check_range(profile.delta_h, f"manoeuvre {profile.kind}")
    u1_dot = np.zeros_like(profile.u1)
    u1_dot[:-1] = np.diff(profile.u1) / np.diff(profile.t)
    n = profile.t.size
    inputs = LoopInputs(
        t=profile.t, delta_h=profile.delta_h,
        delta_c=np.asarray(steering.road_wheel(profile.delta_h)), u1=profile.u1,
        u1_dot=u1_dot, gamma_meas=np.zeros(n), weight=np.zeros(n),
        initial=InitialState(0.0, 0.0, 0.0, 0.0, u1=float(profile.u1[0])))
    obs, delta, _, sat, k = run_inputs(model, inputs, vehicle, gain=0.0)
    status = "ok"
    beyond = beyond_limits(obs[k - 1]) if k < n else ""
    if beyond:  # not finite, or beyond every physical range (loop.OBSERVATION_LIMIT)
        status = f"stopped at t = {profile.t[k - 1]:.2f} s: {beyond}"
        k -= 1  # the run keeps its sound samples only
    elif k < n:
        status = (f"stopped at t = {profile.t[k - 1]:.2f} s: articulation "
                  f"{math.degrees(obs[k - 1, 12]):.1f} deg passed the jackknife limit "
                  f"{math.degrees(vehicle.gamma_max):.1f} deg")
    frame = new_frame(profile.t[:k], profile.delta_h[:k], obs[:k])
    frame["delta"] = delta[:k]
    frame["delta_saturated"] = sat[:k]
    meta = {"name": f"{profile.kind}.{model.name}", "source": f"model:{model.name}",
            "model": model.name, "vehicle": vehicle.name, "vehicle_path": vehicle.path,
            "status": status, **profile.meta}
    return Run(frame, meta)


def steady_articulation_delta(gamma: float, vehicle: Vehicle) -> float:
    """Road-wheel angle that holds articulation ``gamma`` steady, from eq. (1) [rad].

    ``gamma_dot = 0`` gives ``tan(delta) = L1 sin(gamma) / (L2 - L1c cos(gamma))``
    for either direction of travel.
    """
    return math.atan(vehicle.L1 * math.sin(gamma)
                     / (vehicle.L2 - vehicle.L1c * math.cos(gamma)))


def drive_articulation(model: Model, vehicle: Vehicle, t: np.ndarray, u1: np.ndarray,
                       gamma_ref: np.ndarray, gain: float = 2.0,
                       steering: Steering | None = None) -> Run:
    """Drive a model with a driver who steers the articulation onto a reference.

    ``delta = delta_ss(gamma_ref) + gain * (gamma - gamma_ref)`` while
    reversing, and ``delta_ss(gamma_ref)`` forward. The feedback has the
    harness's stabilising sign (see :mod:`artic.validation.harness.loop`).

    Parameters
    ----------
    model : Model
        The vehicle being driven (the "truth").
    vehicle : Vehicle
        Its parameters.
    t, u1, gamma_ref : ndarray
        Time [s], tractor speed [m/s] and articulation reference [rad].
    gain : float
        Driver gain [rad/rad]; above ``L1 / (L2 - L1c)`` to stabilise.
    steering : Steering, optional
        Map used to record ``delta_h`` from the road-wheel angle; the
        vehicle's (for ``model.name``) by default.

    Returns
    -------
    Run
        Signal schema with ``delta_h`` as the driver turned the wheel.
    """
    steering = steering or steering_for(vehicle, model)
    n = t.size
    model = driven(model)
    model.reset(InitialState(0.0, 0.0, 0.0, float(gamma_ref[0]), u1=float(u1[0])))
    obs = np.empty((n, 13))
    delta = np.empty(n)
    for k in range(n):
        d_ff = steady_articulation_delta(float(gamma_ref[k]), vehicle)
        delta[k], _, _ = feedback_law(d_ff, model.gamma, float(gamma_ref[k]), float(u1[k] < 0),
                                      gain, vehicle.steering.delta_max)
        obs[k] = model.observe(delta[k])
        if k + 1 < n:
            model.step(float(t[k + 1] - t[k]), float(delta[k]), float(u1[k]),
                       float((u1[k + 1] - u1[k]) / (t[k + 1] - t[k])))
    delta_h = np.asarray(steering.steering_wheel(delta))
    return Run(new_frame(t, delta_h, obs), {"source": "synthetic", "model": model.name})
