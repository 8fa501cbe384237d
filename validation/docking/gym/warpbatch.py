"""``artic/Dock-v0`` vectorised on the Warp plant: every environment a world of one batch.

:class:`WarpDockVectorEnv` is what ``gymnasium.make_vec("artic.gym:artic/Dock-v0",
num_envs=N, vectorization_mode="vector_entry_point", backend="warp", device="cuda")``
gives (``pip install "artic[gpu]"``): the ``N`` runs' plants are the worlds of one
:class:`~artic.plant.warp_plant.WarpPlant`, on a GPU or on Warp's CPU device.
It is :class:`~artic.validation.docking.gym.kinbatch.KinVectorEnv` with the plant
swapped, so everything but the plant is that batch's, in its order:

- on the device, per 0.1 s step and for all ``N`` runs at once, the ten plant
  steps with the actuators between (the steering wheel at most the steer rate,
  the speed at most the pedal's acceleration, the plant's steering map) and,
  after every step, the divergence check and the jackknife check on the plant's
  articulation: :mod:`artic.validation.docking.warp_dock`'s kernels, without
  its controller (the agents are the controllers); on a GPU one CUDA graph;
- on the host, per step: the collision check over the step's plant states, the
  sensors (the run's noise, the CAN bus), the observation vectors and the
  rewards, in array operations over the batch;
- on the host, per episode: the seeded start, the planner, the noise, and at
  the end the scores; a reset places its worlds on the device while the other
  worlds' numbers stay as they were (:class:`~artic.plant.warp_worlds.Worlds`).

A run whose world diverges, jackknifes or collides ends its own episode
(``info["reason"]`` ``"plant diverged"``, ``"jackknife"``, ``"collision"``); the
others go on. While a docked run settles (the steps ``artic dock`` takes after
the controller is done, without asking it), the worlds waiting for their agents
are held: stepped with the batch and put back as they were.

The Warp plant computes in float32 (``docs/design/warp-plant.md``), so a
sub-environment gives what :class:`~artic.validation.docking.gym.env.DockEnv` on
the C plant gives for the same seed and actions within that precision, not to
the bit: ``tests/test_gym_warp.py`` states the tolerances. A row's ``plant`` is
``mbd-warp``. The rest of the contract (autoreset, bad actions, copies) is
:class:`~artic.validation.docking.gym.vector.DockVectorEnv`'s.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import warp as wp

from artic.mjcf.builder import build_model
from artic.mjcf.compiling import compile_spec
from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import load_vehicle
from artic.plant.warp_plant import WarpPlant, check_memory, find_device
from artic.plant.warp_worlds import Worlds
from artic.validation.docking import warp_dock
from artic.validation.docking.gym.kinbatch import N_SUB, KinVectorEnv
from artic.validation.docking.run import ACCEL_MAX, PLANT_DT, STEER_RATE

f64 = wp.float64


def _plant(vehicle, n: int, device: str) -> WarpPlant:
    """The batch's plant: ``n`` worlds of ``vehicle`` on ``device``, or one line why not."""
    try:
        # The memory first: the plant's per-world lists of a count far too large fill
        # the host's before the plant's own check would refuse it.
        check_memory(compile_spec(build_model(vehicle, solver="newton")), n,
                     find_device(device))
        return WarpPlant(vehicle, n_worlds=n, device=device)
    except UserError as exc:  # the worlds are the environments
        raise UserError(str(exc).replace(f"n_worlds {n}", f"num_envs {n}", 1)
                        .replace("worlds per batch", "environments (num_envs)")) from None


def warp_batchable(kwargs: dict[str, Any]) -> bool:
    """Whether :class:`WarpDockVectorEnv` covers the environments of keywords ``kwargs``.

    The plant (``yard_model`` ``"mbd"``), the ``full`` sensor set, no recording, and
    of ``drive``'s options only ``timeout``, as
    :func:`~artic.validation.docking.gym.kinbatch.batchable` for KIN.
    """
    return (kwargs.get("yard_model", "mbd") == "mbd"
            and kwargs.get("sensors", "full") == "full"
            and kwargs.get("render_mode") is None
            and set(kwargs) <= {"yard_model", "sensors", "render_mode", "recording_dir",
                                "scenario", "vehicle", "timeout"})


class WarpDockVectorEnv(KinVectorEnv):
    """``num_envs`` ``artic/Dock-v0`` environments stepped at once on the Warp plant.

    Parameters
    ----------
    num_envs : int
        How many: the plant's worlds.
    device : str
        The Warp device: ``"cuda"`` (``"cuda:1"``...) or ``"cpu"``.
    **kwargs
        The keywords of :class:`~artic.validation.docking.gym.env.DockEnv`
        that :func:`warp_batchable` accepts.

    Raises
    ------
    artic.mjcf.errors.UserError
        One line each: ``num_envs`` not a positive integer or more worlds than the
        device's memory holds, a device Warp does not have (no GPU for
        ``"cuda"``), or keywords the batch does not cover.

    Notes
    -----
    Version history (as Gymnasium's environments keep one):

    - v0, 2026-12-07: ``gymnasium.make_vec("artic.gym:artic/Dock-v0",
      vectorization_mode="vector_entry_point", backend="warp")`` makes it; its
      sub-environments give the single environment's observations and rewards
      within the Warp plant's float32 precision.
    """

    PLANT = "mbd"
    PLANT_NAME = WarpPlant.name

    def __init__(self, num_envs: int, device: str = "cpu", scenario: str = "alley",
                 vehicle: str = "gosar2022-unloaded", yard_model: str = "mbd",
                 sensors: str = "full", render_mode: str | None = None,
                 recording_dir: Any = "recordings", **drive_options: Any) -> None:
        # One line for each bad input before the plant is built (KinVectorEnv's
        # checks, which its __init__ repeats at no cost, and the device's).
        self._check_inputs(num_envs, {"yard_model": yard_model, "sensors": sensors,
                                      "render_mode": render_mode, **drive_options})
        find_device(device)
        self.plant: WarpPlant | None = _plant(load_vehicle(vehicle), int(num_envs), device)
        try:
            super().__init__(num_envs, scenario=scenario, vehicle=vehicle,
                             yard_model=yard_model, sensors=sensors, render_mode=render_mode,
                             recording_dir=recording_dir, **drive_options)
        except BaseException:
            self.close_extras()
            raise

    # ------------------------------------------------------------- the plant
    @staticmethod
    def _refuse(kwargs: dict[str, Any]) -> None:
        if not warp_batchable(kwargs):
            raise UserError("backend='warp': artic/Dock-v0 with the full sensor set, no "
                            "recording and no drive() option but timeout; leave backend out "
                            "for the others (the threaded DockVectorEnv)")

    def _build(self) -> None:
        """The worlds' helper and the loop's arrays on the plant's device."""
        n = self.num_envs
        try:
            self._worlds = Worlds(self.plant)
        except RuntimeError as exc:  # Warp's allocation failed: the memory estimate was short
            raise UserError(f"num_envs {n}: {self.plant.device.alias}'s memory does not hold "
                            f"the batch and its copy ({str(exc).splitlines()[0]}); use fewer "
                            "environments") from None
        self._hold: np.ndarray | None = None
        self._graph = None
        mbd = self.vehicle.steering_for("mbd")
        consts = np.zeros((n, 13))
        consts[:, [warp_dock.MBD_I_S, warp_dock.MBD_Q, warp_dock.MBD_OFFSET]] = (
            mbd.i_s, mbd.q, mbd.delta_h_offset)
        consts[:, [warp_dock.WHEEL_STEP, warp_dock.U_STEP, warp_dock.GAMMA_MAX,
                   warp_dock.STEP_DT]] = (STEER_RATE * PLANT_DT, ACCEL_MAX * PLANT_DT,
                                          self.vehicle.gamma_max, PLANT_DT)
        p = self.plant
        with wp.ScopedDevice(p.device):
            def a64(shape):
                return wp.zeros(shape, dtype=f64)

            loop = warp_dock.Loop()
            loop.consts = wp.array(consts, dtype=f64)
            loop.noise = a64((n, 1, 12))
            loop.hitch_qpos = int(p.mj_model.jnt_qposadr[p.hosts[0]._hitch_yaw])
            loop.n_sub = N_SUB
            state = warp_dock.LoopState()
            for name in ("phase", "fail", "steps", "samples", "done"):
                setattr(state, name, wp.zeros(n, dtype=int))
            for name in ("wheel", "u", "u_next", "wheel_target", "u_target", "settle_until"):
                setattr(state, name, a64(n))
            rec = warp_dock.Records()
            rec.plant = wp.zeros((n, N_SUB + 1, 13), dtype=float)
            rec.wheel, rec.speed = a64((n, N_SUB + 1)), a64((n, N_SUB + 1))
            rec.measured, rec.delta_h, rec.commands = a64((n, 1, 13)), a64((n, 1)), \
                a64((n, 1, 2))
            self._loop, self._state, self._records = loop, state, rec

    def _place(self, idx: np.ndarray) -> None:
        signals = self._worlds.reset(idx, [self._starts.pop(int(i)) for i in idx])
        for k, i in enumerate(idx):
            self._true[i] = signals[k]
            self._runs[i].true0 = signals[k].copy()

    def _launches(self) -> None:
        """One step's launches: ``N_SUB`` plant steps with the actuators and the checks."""
        p, n = self.plant, self.num_envs
        for _ in range(N_SUB):
            wp.launch(warp_dock.actuate_kernel, dim=n, inputs=[self._loop, self._state],
                      outputs=[p.ctl.command])
            p._step_launches(1)
            p.ctl.observe(p)
            wp.launch(warp_dock.record_kernel, dim=n, inputs=[
                self._loop, p.ctl.state.failed, p.d.qpos, p.ctl.sensors.yaw, p.ctl.signals],
                outputs=[self._state, self._records])

    def _period(self, live: np.ndarray, first: bool) -> tuple:
        n, p, st, rec = self.num_envs, self.plant, self._state, self._records
        with wp.ScopedDevice(p.device):
            if not first and self._hold is None:  # a run settles: the others wait
                self._worlds.keep()
                self._hold = ~live
            st.phase.assign(np.where(live, warp_dock.DRIVING, warp_dock.ENDED).astype(np.int32))
            st.fail.zero_()
            st.steps.zero_()
            for name in ("wheel", "u", "wheel_target", "u_target"):
                getattr(st, name).assign(getattr(self, f"_{name}"))
            if self._graph is not None:
                wp.capture_launch(self._graph)
            else:
                self._launches()  # eagerly: the kernels load before any capture
                if p._graph:  # a CUDA device: the next steps replay this one
                    with wp.ScopedCapture() as capture:
                        self._launches()
                    self._graph = capture.graph
            steps = st.steps.numpy().astype(np.int64)
            fail = st.fail.numpy()
            true = rec.plant.numpy()[:, 1:].astype(float)
            wheels, speeds = rec.wheel.numpy()[:, 1:], rec.speed.numpy()[:, 1:]
            self._wheel = np.where(live, st.wheel.numpy(), self._wheel)
            self._u = np.where(live, st.u.numpy(), self._u)
        steps[~live] = 0
        times = np.zeros((n, N_SUB))
        t = self._t.copy()
        for j in range(N_SUB):  # drive's clock: a sum of plant steps
            t = t + PLANT_DT
            times[:, j] = t
        taken = live & (steps > 0)
        self._t[taken] = times[taken, steps[taken] - 1]
        gone = live & (fail != warp_dock.RUNNING)
        failures = p.failures() if np.any(gone & (fail == warp_dock.DIVERGED)) else {}
        gamma_max = math.degrees(self.vehicle.gamma_max)
        for i in np.flatnonzero(gone):
            run = self._runs[i]
            if fail[i] == warp_dock.JACKKNIFE:
                k = steps[i] - 1
                run.failure = (f"jackknife: |gamma| {math.degrees(abs(true[i, k, 12])):.1f} deg "
                               f"beyond {gamma_max:.1f} deg at t = {times[i, k]:.2f} s")
            else:
                run.failure = f"plant diverged: {failures.get(int(i), f'world {i}')}"
        return (steps, times, true, wheels, speeds), gone

    def _advance(self, live: np.ndarray) -> np.ndarray:
        self._hold = None
        try:
            return super()._advance(live)
        finally:
            if self._hold is not None:  # the waiting worlds back as they were
                with wp.ScopedDevice(self.plant.device):
                    self._worlds.restore(wp.array(self._hold.astype(np.int32), dtype=int))
                self._hold = None

    def close_extras(self, **kwargs: Any) -> None:
        """Close the plant (its host plants' callbacks)."""
        if self.plant is not None:
            self.plant.close()
            self.plant = None
