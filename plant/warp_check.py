"""The Warp plant against the C plant: the same manoeuvre on both, and their differences.

:func:`reverse_commands` is an open-loop reverse manoeuvre that passes through
standstill: from rest it backs to ``-1.5 m/s`` while the road wheels swing
+-0.08 rad every 6 s (the articulation stays within about 9 deg, the treads'
lateral deflections within about 5 mm), stops, stands still for 2 s with the
wheels still turning (the tyres' standstill spin/tread mode and turn slip), and
backs off again.
:func:`compare` runs it on :class:`artic.plant.warp_plant.WarpPlant` (float32, every
world on the same commands) and on :class:`artic.plant.Plant` (float64, with
the Newton solver like the Warp model, and with its own PGS) and returns the
largest differences over the run.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import Vehicle
from artic.plant.plant import Plant
from artic.plant.warp_plant import WarpPlant

DT = 0.01
"""The commands' sample [s]."""


def reverse_commands(duration: float, dt: float = DT) -> np.ndarray:
    """``(delta [rad], u1 [m/s], u1_dot [m/s^2])`` per sample of the manoeuvre, shape (n, 3).

    A 30 s cycle (shorter runs take its start): 4 s ramp to -1.5 m/s, back at
    speed, stop over 3 s at 14-17 s, 2 s at rest, back off again at 19 s.
    """
    t = np.arange(round(duration / dt)) * dt
    tc = t % 30.0
    u = np.interp(tc, [0.0, 4.0, 14.0, 17.0, 19.0, 23.0, 30.0],
                  [0.0, -1.5, -1.5, 0.0, 0.0, -1.5, -1.5])
    u_dot = np.gradient(u, dt)
    delta = 0.08 * np.sin(2.0 * math.pi * t / 6.0)
    return np.column_stack([delta, u, u_dot])


def _tread(plant_act: np.ndarray, host: Plant) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return plant_act[..., host._act_u], plant_act[..., host._act_v], plant_act[..., host._act_w]


def compare(vehicle: Vehicle, duration: float, n_worlds: int = 2,
            device: str = "cpu") -> dict[str, dict[str, float]]:
    """The largest differences over :func:`reverse_commands` of ``duration`` [s].

    Returns
    -------
    dict
        ``{"warp-f32 vs C-newton": {...}, "C-pgs vs C-newton": {...},
        "worlds": {...}}``, each with ``position [m]`` (either sensor),
        ``heading [deg]``, ``gamma [deg]``, ``tread u [mm]``, ``tread v [mm]``,
        ``twist [rad]``, ``spin [rad/s]`` and ``speed [m/s]``; ``worlds`` is the
        largest difference between the Warp plant's worlds (0: they run alike),
        and ``scale`` the largest magnitude of each quantity over the run.
    """
    cmds = reverse_commands(duration)
    start = InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0)
    with Plant(vehicle) as newton, Plant(vehicle) as pgs, \
            WarpPlant(vehicle, n_worlds, device=device) as warp:
        newton.model.opt.solver = mujoco.mjtSolver.mjSOL_NEWTON
        for p in (newton, pgs):
            p.reset(start)
        warp.reset(start)
        names = ("position [m]", "heading [deg]", "gamma [deg]", "tread u [mm]", "tread v [mm]",
                 "twist [rad]", "spin [rad/s]", "speed [m/s]")
        err = {k: dict.fromkeys(names, 0.0) for k in ("warp-f32 vs C-newton",
                                                      "C-pgs vs C-newton", "worlds", "scale")}
        spin = newton._spin_dof

        def quantities(obs, act, qvel):
            u, v, w = _tread(act, newton)
            return {"xy": np.stack([obs[..., 0:2], obs[..., 6:8]], axis=-2),
                    "heading": np.degrees(obs[..., [2, 8]]), "gamma": np.degrees(obs[..., 12]),
                    "u": 1e3 * u, "v": 1e3 * v, "w": w, "spin": qvel[..., spin],
                    "speed": obs[..., 3]}

        def diff(a, b):
            return {"position [m]": np.max(np.linalg.norm(a["xy"] - b["xy"], axis=-1)),
                    "heading [deg]": np.max(np.abs(a["heading"] - b["heading"])),
                    "gamma [deg]": np.max(np.abs(a["gamma"] - b["gamma"])),
                    "tread u [mm]": np.max(np.abs(a["u"] - b["u"])),
                    "tread v [mm]": np.max(np.abs(a["v"] - b["v"])),
                    "twist [rad]": np.max(np.abs(a["w"] - b["w"])),
                    "spin [rad/s]": np.max(np.abs(a["spin"] - b["spin"])),
                    "speed [m/s]": np.max(np.abs(a["speed"] - b["speed"]))}

        for delta, u1, u1_dot in cmds:
            for p in (newton, pgs):
                p.step(DT, delta, u1, u1_dot)
            warp.step(DT, delta, u1, u1_dot)
            ref = quantities(newton.observe(), newton.data.act, newton.data.qvel)
            other = quantities(pgs.observe(), pgs.data.act, pgs.data.qvel)
            st = warp.state()
            ours = quantities(warp.observe(), st["act"], st["qvel"])
            w0 = {k: v[0] for k, v in ours.items()}
            rows = {"warp-f32 vs C-newton": diff(w0, ref), "C-pgs vs C-newton": diff(other, ref),
                    "worlds": diff(ours, {k: v[:1] for k, v in ours.items()}),
                    "scale": diff(ref, {k: 0.0 * v for k, v in ref.items()})}
            for k, row in rows.items():
                for q, x in row.items():
                    err[k][q] = max(err[k][q], float(x))
        if warp.failures():
            raise AssertionError(f"the Warp plant failed: {warp.failures()}")
    return err
