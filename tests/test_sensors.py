"""Both reduced models: sensor velocities are the derivatives of sensor positions."""

from __future__ import annotations

import numpy as np
import pytest

from artic.reduced import KIN, STM, Driven, InitialState


def velocities_from_positions(obs, dt):
    """Sensor velocities in body axes from central differences of positions."""
    out = {}
    for i, (ix, iy, ipsi) in ((1, (0, 1, 2)), (2, (6, 7, 8))):
        vx, vy = np.gradient(obs[:, ix], dt), np.gradient(obs[:, iy], dt)
        psi = obs[:, ipsi]
        out[i] = (np.cos(psi) * vx + np.sin(psi) * vy, -np.sin(psi) * vx + np.cos(psi) * vy)
    return out


@pytest.mark.parametrize("cls", [KIN, STM])
def test_sensor_velocities_are_derivatives_of_sensor_positions(unloaded, cls):
    # Constant steering from an articulated start: a smooth path (no held-input
    # jumps) with a trailer transient of its own. The first 3 s are skipped:
    # the STM's tyre-lag mode (sigma / u ~ 0.4 s) is too fast there for a 10 ms
    # central difference to follow to 2e-4 m/s; after it, the difference's
    # error (dt^2 times the jerk) is far below that.
    m = Driven(cls(unloaded))
    m.reset(InitialState(0.0, 0.0, 0.0, 0.4, u1=1.2))
    dt, obs = 0.01, []
    for _ in range(1500):
        m.step(dt, 0.25, 1.2, 0.0)
        obs.append(m.observe(0.25))
    obs = np.array(obs)
    fd = velocities_from_positions(obs, dt)
    ok = slice(300, -5)
    for i, (ivx, ivy) in ((1, (3, 4)), (2, (9, 10))):
        np.testing.assert_allclose(fd[i][0][ok], obs[ok, ivx], atol=2e-4)
        np.testing.assert_allclose(fd[i][1][ok], obs[ok, ivy], atol=2e-4)
    # The articulation really moved, so the trailer's own motion was tested.
    assert np.ptp(obs[:, 12]) > 0.05


@pytest.mark.parametrize("cls", [KIN, STM])
def test_both_sensors_agree_on_the_kingpin(unloaded, cls):
    # The kingpin is one point of both units. Rebuilt from the tractor sensor
    # (s1 from the drive axle, kingpin L1c ahead of it) and from the trailer
    # sensor (s2 from the kingpin), it must be the same point to rounding.
    v = unloaded
    m = Driven(cls(v))
    m.reset(InitialState(3.0, -2.0, 0.7, -0.5, u1=-1.0))
    s1 = np.array(v.sensor1[:2]) - [v.L1c, 0.0]
    s2 = np.array(v.sensor2[:2])
    for k in range(400):
        m.step(0.01, 0.3 * np.sin(k / 40), -1.0, 0.0)
        o = m.observe()
        p1, p2 = o[2], o[8]
        R1 = np.array([[np.cos(p1), -np.sin(p1)], [np.sin(p1), np.cos(p1)]])
        R2 = np.array([[np.cos(p2), -np.sin(p2)], [np.sin(p2), np.cos(p2)]])
        k1 = o[0:2] - R1 @ s1
        k2 = o[6:8] - R2 @ s2
        np.testing.assert_allclose(k1, k2, atol=1e-12)
