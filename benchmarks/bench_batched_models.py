"""KIN and the STM on a batch, and one KIN step per call, against plain loops of their equations.

Three ratios, each measured within one round and given as the median and
range of three rounds (machines are noisy; ratios within a round are not):

- **batched KIN**: ``KIN.step`` of a batch of :data:`BATCH` states (one
  compiled call, the harness's fourth-order Runge-Kutta) per state-step,
  against a plain numba explicit-Euler loop of eq. (1) written here (one
  evaluation a step, where RK4 takes four). The issue's target: at most 5.
- **batched STM**: the same for the STM, against a plain numba Euler loop
  over its right-hand side (:func:`artic.reduced.single_track.stm_rhs_into`:
  its equations are too long to write twice). No target.
- **per call**: ``KIN.step`` of one state (a planner's loop), against a
  plain-Python step of eq. (1) in floats, explicit Euler (the strictest
  baseline; a plain-Python RK4 step is also timed). The issue's target: at
  most 5 times the plain-Python Euler step.

The batch's rollout (``KIN.rollout`` of a (batch, steps) input sequence) is
timed too, per state-step.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import math
import statistics

import numpy as np
from numba import njit

from _timing import best_wall
from artic.mjcf import load_vehicle
from artic.reduced import KIN, STM
from artic.reduced.single_track import stm_rhs_into

ROUNDS = 3
BATCH = 4096
STEPS = 20
CALLS = 20_000
DT = 0.05


@njit(cache=True)
def euler_kin(x, u, dt, P, steps):
    """Plain explicit Euler of eq. (1) over a batch, in place: the baseline."""
    L1, L1c, L2 = P[0], P[1], P[2]
    for _ in range(steps):
        for i in range(x.shape[0]):
            psi, gamma, u1 = x[i, 2], x[i, 3], u[i, 1]
            r1 = u1 * math.tan(u[i, 0]) / L1
            x[i, 0] += dt * u1 * math.cos(psi)
            x[i, 1] += dt * u1 * math.sin(psi)
            x[i, 2] += dt * r1
            x[i, 3] += dt * (-u1 * math.sin(gamma) / L2 + (1.0 - L1c * math.cos(gamma) / L2) * r1)
    return x


@njit(cache=True)
def euler_stm(x, u, dt, P, steps):
    """Plain explicit Euler of the STM's right-hand side over a batch, in place."""
    f = np.empty(x.shape[1])
    for _ in range(steps):
        for i in range(x.shape[0]):
            stm_rhs_into(x[i], u[i, 1], u[i, 2], u[i, 0], P, f)
            for j in range(x.shape[1]):
                x[i, j] += dt * f[j]
    return x


def python_euler(x, u, dt, L1, L1c, L2):
    """One plain-Python Euler step of eq. (1) on floats."""
    X, Y, psi, gamma = x
    delta, u1 = u
    r1 = u1 * math.tan(delta) / L1
    return (X + dt * u1 * math.cos(psi), Y + dt * u1 * math.sin(psi), psi + dt * r1,
            gamma + dt * (-u1 * math.sin(gamma) / L2 + (1.0 - L1c * math.cos(gamma) / L2) * r1))


def python_rk4(x, u, dt, L1, L1c, L2):
    """One plain-Python RK4 step of eq. (1) on floats."""
    delta, u1 = u
    r1 = u1 * math.tan(delta) / L1

    def f(psi, gamma):
        return (u1 * math.cos(psi), u1 * math.sin(psi), r1,
                -u1 * math.sin(gamma) / L2 + (1.0 - L1c * math.cos(gamma) / L2) * r1)

    X, Y, psi, gamma = x
    a = f(psi, gamma)
    b = f(psi + 0.5 * dt * a[2], gamma + 0.5 * dt * a[3])
    c = f(psi + 0.5 * dt * b[2], gamma + 0.5 * dt * b[3])
    d = f(psi + dt * c[2], gamma + dt * c[3])
    w = dt / 6.0
    return tuple(s + w * (p + 2.0 * q + 2.0 * r + t)
                 for s, p, q, r, t in zip(x, a, b, c, d, strict=True))


def _batch(model, rng):
    X = np.zeros((BATCH, model.nstates))
    X[:, :2] = rng.uniform(-5.0, 5.0, (BATCH, 2))
    X[:, 2] = rng.uniform(-math.pi, math.pi, BATCH)
    X[:, 3] = rng.uniform(-0.5, 0.5, BATCH)
    U = np.zeros((BATCH, model.ninputs))
    U[:, 0] = rng.uniform(-0.4, 0.4, BATCH)
    U[:, 1] = -1.0
    return X, U


def _round(kin: KIN, stm: STM) -> dict[str, float]:
    rng = np.random.default_rng(0)
    out: dict[str, float] = {}
    for name, model, euler in (("kin", kin, euler_kin), ("stm", stm, euler_stm)):
        X, U = _batch(model, rng)
        U3 = np.zeros((BATCH, 3))
        U3[:, :model.ninputs] = U
        t_step = best_wall(lambda m=model, X=X, U=U: m.step(X, U, DT)) / BATCH
        t_euler = best_wall(lambda X=X, U3=U3, P=model.P, e=euler: e(X.copy(), U3, DT, P, STEPS))
        t_euler = t_euler / (BATCH * STEPS)
        seq = np.repeat(U[:, None, :], STEPS, axis=1)
        t_roll = best_wall(lambda m=model, X=X, seq=seq: m.rollout(X, seq, DT)) / (BATCH * STEPS)
        out[f"{name}_step_ns"] = 1e9 * t_step
        out[f"{name}_rollout_ns"] = 1e9 * t_roll
        out[f"{name}_euler_ns"] = 1e9 * t_euler
        out[f"{name}_batch_ratio"] = t_step / t_euler
    x = np.array([1.0, 2.0, 0.3, 0.1])
    u = np.array([0.1, -1.0])
    xt, ut = tuple(x), tuple(u)
    L1, L1c, L2 = (float(p) for p in kin.P)

    def calls(fn):
        return best_wall(lambda: [fn() for _ in range(CALLS)]) / CALLS

    t_call = calls(lambda: kin.step(x, u, DT))
    t_py = calls(lambda: python_euler(xt, ut, DT, L1, L1c, L2))
    t_py4 = calls(lambda: python_rk4(xt, ut, DT, L1, L1c, L2))
    out.update(step_us=1e6 * t_call, python_euler_us=1e6 * t_py, python_rk4_us=1e6 * t_py4,
               call_ratio=t_call / t_py, call_ratio_rk4=t_call / t_py4)
    return out


def _fmt(xs: list[float], digits: int = 2) -> str:
    return f"{statistics.median(xs):.{digits}g} ({min(xs):.{digits}g}-{max(xs):.{digits}g})"


def main() -> dict[str, list[float]]:
    v = load_vehicle("gosar2022-unloaded")
    kin, stm = KIN(v), STM(v)
    rounds = [_round(kin, stm) for _ in range(ROUNDS)]
    fig = {k: [r[k] for r in rounds] for k in rounds[0]}
    print(f"Batched steps, {BATCH} states, per state-step; median (range) of {ROUNDS} rounds:")
    for m in ("kin", "stm"):
        print(f"  {m.upper()}: step {_fmt(fig[f'{m}_step_ns'])} ns, rollout of {STEPS} steps "
              f"{_fmt(fig[f'{m}_rollout_ns'])} ns, plain numba Euler "
              f"{_fmt(fig[f'{m}_euler_ns'])} ns: {_fmt(fig[f'{m}_batch_ratio'])} x the Euler "
              "loop" + (" (target: at most 5)" if m == "kin" else ""))
    print(f"One KIN.step a call: {_fmt(fig['step_us'])} us; a plain-Python Euler step "
          f"{_fmt(fig['python_euler_us'])} us ({_fmt(fig['call_ratio'])} x, target: at most "
          f"5), a plain-Python RK4 step {_fmt(fig['python_rk4_us'])} us "
          f"({_fmt(fig['call_ratio_rk4'])} x)")
    return fig


if __name__ == "__main__":
    from artic.validation.plumbing import runtime

    runtime.configure()
    main()
