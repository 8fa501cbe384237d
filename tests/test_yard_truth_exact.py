"""The yard truth's per-sample signals give, to the bit, what their first forms gave.

``observe``, ``sensor_speed`` and ``full_state`` run once per 10 ms sample of
every synthetic log; they were rewritten on Python floats and cached views.
The first forms are kept here and run on the same states, with their own copy
of the units' unwrapped headings (which both advance).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from artic.mjcf import load_vehicle
from artic.mjcf.interface import InitialState, wrap_angle
from artic.validation.synthetic.yardtruth import YardSetup, YardTruth
from tests.helpers import needs_compiled

YARD = "the yard truth's compiled loop (artic_yard_advance)"


def _observe(t: YardTruth, psis: np.ndarray) -> np.ndarray:
    d, m = t.data, t.model
    out, vel = np.empty(13), np.zeros(6)
    for i, (site, body) in enumerate(t._sensor_bodies):
        R = d.site_xmat[site]
        prev = float(psis[i])
        psi = prev + (math.pi - (math.pi - (math.atan2(R[3], R[0]) - prev)) % (2.0 * math.pi))
        psis[i] = psi
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_SITE, site, vel, 0)
        v0, v1, v2, v3, v4, _ = vel.tolist()
        h = psi + t._eps[i]
        c, s = math.cos(h), math.sin(h)
        B, p = d.xmat[body], d.site_xpos[site]
        out[6 * i:6 * i + 6] = [p[0], p[1], h, c * v3 + s * v4, -s * v3 + c * v4,
                                v0 * float(B[2]) + v1 * float(B[5]) + v2 * float(B[8])]
    out[12] = wrap_angle(out[2] - out[8])
    return out


def _sensor_speed(t: YardTruth, psis: np.ndarray) -> float:
    d, vx, vel = t.data, 0.0, np.zeros(6)
    for i, site in enumerate(t.layout.sensor_sites):
        R = d.site_xmat[site]
        psi = psis[i] + float(wrap_angle(math.atan2(R[3], R[0]) - psis[i]))
        psis[i] = psi
        if i == 0:
            mujoco.mj_objectVelocity(t.model, d, mujoco.mjtObj.mjOBJ_SITE, site, vel, 0)
            h = psi + t._eps[0]
            vx = math.cos(h) * vel[3] + math.sin(h) * vel[4]
    return float(vx)


def _full_state(t: YardTruth) -> np.ndarray:
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    st = np.empty(mujoco.mj_stateSize(t.model, spec))
    mujoco.mj_getState(t.model, t.data, st, spec)
    extra = [t._decel, float(t._parked), *t._psi, float(t.steer_limited),
             *map(float, t.pedals), *t._ctl]
    return np.concatenate([st, t.z, extra])


def _bits(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float64).view(np.int64)


@needs_compiled(YARD)
def test_samples_as_first_computed():
    """A pedal-driven drive: away, braking, reversing through standstill on full lock
    (the headings pass +-pi, where the unwrapping matters)."""
    v = load_vehicle("gosar2022-unloaded")
    with YardTruth(v, YardSetup(play=math.radians(1.0)), speed="pedals") as t:
        t.reset(InitialState(0.0, 0.0, math.pi - 0.05, 0.1, u1=2.0))
        psis = t._psi.copy()
        n = 0
        for k in range(600):
            t.pedals = (0.6, 0.0) if k < 200 else ((0.0, 0.5) if k < 350 else (0.5, 0.0))
            u = 2.0 if k < 350 else -1.0
            want = _sensor_speed(t, psis.copy())  # the same state, before it advances
            assert np.array_equal(_bits(t.sensor_speed()), _bits(want)), k
            _sensor_speed(t, psis)  # keep the reference's headings in step
            t.step(0.01, 0.6 if k % 200 < 100 else -0.6, u, 0.0)
            if k % 3 == 0:
                want = _observe(t, psis)
                assert np.array_equal(_bits(t.observe()), _bits(want)), k
                assert np.array_equal(_bits(t.full_state()), _bits(_full_state(t))), k
                n += 1
        assert np.array_equal(_bits(t._psi), _bits(psis))
        # the tractor's unwrapped heading went past pi, where a wrapped one jumps
        assert t._psi[0] > math.pi and n == 200
