"""KIN, STM and the multibody plant against each other.

In the linear low-speed regime the three must agree, within bounds argued
from what each leaves out; in reverse all three must be held by the harness
with K = 3 and run away without it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf.linkage import centre_angle
from artic.mjcf.vehicle import G
from artic.plant import Plant
from artic.plant.tyre import TyreParams
from artic.reduced import KinematicModel, SingleTrackModel
from artic.validation.harness import run_closed_loop
from conftest import steady_turn, straight_log

U = 5 / 3.6
"""Speed of the linear-regime runs [m/s]."""


def steady(model, delta):
    """Steady tractor yaw rate and articulation at a fixed steering angle and 5 km/h."""
    return steady_turn(model, delta, U, seconds=90.0, tail=500)


def trailer_equivalent_length(v):
    """``L_eq = sum C l^2 / sum C l`` of the trailer axles: its no-slip point [m]."""
    dist = v.trailer_axle_distances
    C = v.static_loads[len(v.tractor_axles):]
    return float(np.sum(C * dist ** 2) / np.sum(C * dist))


@pytest.fixture(scope="module")
def linear(unloaded):
    # The plant steers its left wheel; KIN and STM take the centre angle of
    # eq. (3). All three run at the plant's own centre angle, 100 deg of
    # steering wheel. The plant's tyres have the tyre file's cornering
    # stiffness at each axle's static load; the STM gets the same, so the two
    # differ only in what the STM leaves out.
    tyre = TyreParams.from_tir(unloaded.tyre_file)
    n = np.array([2.0 * (2 if a.dual else 1) for a in unloaded.axles])
    C = n * tyre.cornering_stiffness(unloaded.static_loads / n)
    stm = SingleTrackModel(unloaded)
    stm.P[-len(C):] = C
    # The same with the trailer's axles merged into one at L2, where KIN puts
    # the trailer's no-slip point: the STM then departs from KIN by slip alone.
    n_tr = len(unloaded.trailer_axles)
    stm1 = SingleTrackModel(unloaded, trailer_axles=np.array([unloaded.L2]))
    stm1.P[-(len(C) - n_tr + 1):] = np.append(C[:-n_tr], C[-n_tr:].sum())
    with Plant(unloaded) as plant:
        mbd = steady(plant, math.radians(100.0) / unloaded.steering_for("mbd").i_s)
        qL = plant.data.qpos[plant._steer_L[0]]
        qR = plant.data.qpos[plant._steer_R[0]]
    dc = float(centre_angle(np.array(qL), np.array(qR)))
    out = {"kin": steady(KinematicModel(unloaded, "paper"), dc), "stm1": steady(stm1, dc),
           "stm": steady(stm, dc), "mbd": mbd}
    return out, float(np.min(C / unloaded.static_loads))


@pytest.mark.slow
def test_linear_regime_kin_and_stm(unloaded, linear):
    # With the trailer's axles merged at L2, the STM departs from KIN by its
    # tyres' slip only: slip angles of order u r / (f g) against road-wheel
    # angles of order L1 r / u. Their ratio u^2 / (f g L1) bounds the relative
    # difference of the steady states, three times it for the articulated
    # geometry's sums of such terms.
    out, f_eq = linear
    slip = 3 * U ** 2 / (f_eq * G * unloaded.L1)
    for i in (0, 1):
        assert abs(out["stm1"][i] / out["kin"][i] - 1) < slip, out
    # The tridem's scrub is what KIN leaves out beyond that: the STM with
    # all three axles puts the trailer's no-slip point at L_eq > L2 and
    # articulates further.
    assert out["stm"][1] / out["kin"][1] - 1 > trailer_equivalent_length(unloaded) / \
        unloaded.L2 - 1 > 0


@pytest.mark.slow
def test_linear_regime_stm_and_mbd(linear):
    # Same tyre stiffness, same centre angle: what remains is the plant's tyre
    # non-linearity at 0.03 g, its load transfer and suspension, and its
    # individual wheel angles against the single track's centre angle, each
    # below 1 % here; 3 % bounds them together.
    out, _ = linear
    for i in (0, 1):
        assert abs(out["mbd"][i] / out["stm"][i] - 1) < 0.03, out
    assert out["mbd"][0] > 0 and out["mbd"][1] > 0


@pytest.mark.parametrize("name", ["kin", "stm", "mbd"])
def test_reverse_held_with_k3_diverges_without(unloaded, name):
    # Straight reversing at 0.8 m/s from 3 deg of articulation, 25 s (20 m,
    # about 2.5 trailer lengths: the open loop grows by e^(0.13 * 25) ~ 25x).
    log = straight_log(n=2500, u=-0.8, gamma0=math.radians(3.0))
    cls = {"kin": KinematicModel, "stm": SingleTrackModel, "mbd": Plant}[name]
    gammas = {}
    for k in (0.0, 3.0):
        model = cls(unloaded)
        try:
            run = run_closed_loop(model, log, unloaded, gain=k)
        finally:
            if hasattr(model, "close"):
                model.close()
        gammas[k] = np.abs(run.frame.gamma.to_numpy())
    g0 = math.radians(3.0)
    assert gammas[3.0][-1] < 0.1 * g0 and gammas[3.0].max() < 1.5 * g0
    assert gammas[0.0].max() > 5 * g0
