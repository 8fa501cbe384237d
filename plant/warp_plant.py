"""The plant as a batch of worlds on MuJoCo Warp: many trucks stepped at once.

:class:`WarpPlant` steps ``n_worlds`` copies of the generated model (with the
Newton solver, ``build_model(..., solver="newton")``: MuJoCo Warp has no PGS)
on a Warp device, a CUDA GPU or Warp's CPU device. Per world it does what
:class:`artic.plant.Plant` does per step:

- the tyre (:mod:`artic.plant.warp_tyre`: PAC2002 with the aligning moment and
  turn slip, the tread deflection states, the spin mode fitted to the step) runs
  as MuJoCo Warp's passive callback, inside every RK4 stage;
- the steering servo's command is limited to the linkage's range, and the speed
  is followed (``speed="follow"``) or driven with drive and brake torques
  (``speed="drive"``), with the CPU plant's gains, as one kernel per step;
- after every step a kernel checks each world's state: a world that diverged
  is put back to its state before that step and held there, and
  :meth:`WarpPlant.failures` names it with the time; the others go on.

Nothing in :meth:`WarpPlant.step_device` reads back to the host, so on a GPU the
step can be captured in a CUDA graph (``graph=True``).

Per-world parameters. The worlds may carry different trucks (``vehicles``: the
payload and its position, the semitrailer's variant) as long as their models
have the same bodies, joints and actuators: the model fields that differ
become MuJoCo Warp's batched model fields, and one that MuJoCo Warp cannot
batch is refused by name. Tyre scaling factors and the road friction (a factor
on ``LMUX`` and ``LMUY``) are per world as well.

MuJoCo Warp computes in float32 (``docs/design/warp-plant.md`` tables what that
costs against the float64 C plant).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping, Sequence

import mujoco
import mujoco_warp as mjw
import numpy as np
import warp as wp

from artic.mjcf.builder import build_model
from artic.mjcf.compiling import compile_spec
from artic.mjcf.errors import UserError
from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import Vehicle
from artic.plant import warp_control, warp_tyre
from artic.plant.plant import Plant, scaled
from artic.plant.tyre import TyreParams

FRICTION_SCALES = ("LMUX", "LMUY")
"""The Magic Formula's friction scaling factors a world's ``friction`` multiplies."""

SPEED_MODES = ("follow", "drive")
"""How the worlds' tractor speed is controlled, as :class:`artic.plant.Plant`'s."""


def find_device(device: str) -> wp.context.Device:
    """Warp's device ``device``, or a :class:`UserError` saying what to do."""
    wp.init()
    try:
        dev = wp.get_device(device)
    except (RuntimeError, ValueError) as exc:
        have = ", ".join(d.alias for d in wp.get_devices())
        if device.startswith("cuda"):
            raise UserError(f"device {device!r}: Warp finds no CUDA GPU here (devices: {have}); "
                            "use device='cpu', or run where an NVIDIA GPU and its driver "
                            "are") from exc
        raise UserError(f"device {device!r}: not a Warp device here (devices: {have})") from exc
    return dev


def _per_world(name: str, values, n_worlds: int) -> list:
    """``values`` as a list of one value per world: one for all, or exactly ``n_worlds``."""
    if values is None or isinstance(values, (int, float, Vehicle, Mapping, InitialState)):
        return [values] * n_worlds
    values = list(values)
    if len(values) != n_worlds:
        raise UserError(f"{name}: {len(values)} values for {n_worlds} worlds; give one per "
                        "world, or a single value for all")
    return values


def _variants(items: list) -> tuple[list, np.ndarray]:
    """The distinct ``items`` (by equality) and each item's index among them."""
    unique: list = []
    index = np.empty(len(items), dtype=np.int32)
    for k, it in enumerate(items):
        for j, u in enumerate(unique):
            if u is it or u == it:
                index[k] = j
                break
        else:
            index[k] = len(unique)
            unique.append(it)
    return unique, index


_SLEEP_ONLY = ("dof_length",)
"""Model fields MuJoCo Warp reads only for sleeping, which the plant's model leaves off."""


def _zero_force(m: mujoco.MjModel, a: int) -> bool:
    """Whether actuator ``a`` never has a force: fixed gain 0 and no bias (the tread states')."""
    return (m.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_FIXED
            and m.actuator_gainprm[a, 0] == 0.0
            and m.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_NONE)


def _model_arrays(m) -> dict[str, np.ndarray]:
    """Every array field of a MuJoCo Warp model, on the host."""
    out = {}
    for f in dataclasses.fields(m):
        a = getattr(m, f.name)
        if isinstance(a, wp.array):
            out[f.name] = a.numpy()
    return out


def _batched_fields(models: list[mujoco.MjModel], index: np.ndarray):
    """One MuJoCo Warp model for worlds whose host models are ``models[index[w]]``.

    Each field that differs between the models is batched (one row per world);
    a field MuJoCo Warp cannot batch raises :class:`UserError` naming it.
    """
    n_worlds = len(index)
    if len(models) == 1:
        return mjw.put_model(models[0])
    per = [_model_arrays(mjw.put_model(mm)) for mm in models]
    batchable = {f.name for f in dataclasses.fields(mjw.Model)
                 if getattr(getattr(f.type, "shape", None), "__getitem__", None)
                 and f.type.shape and f.type.shape[0] == "*"}
    differ = []
    for name, a0 in per[0].items():
        if any(a.shape != a0.shape or not np.array_equal(a, a0, equal_nan=True)
               for a in per[1:] for a in [a[name]]):
            differ.append(name)
    if not models[0].opt.enableflags & mujoco.mjtEnableBit.mjENBL_SLEEP:
        differ = [n for n in differ if n not in _SLEEP_ONLY]  # read by sleeping alone
    refused = [n for n in differ if n not in batchable]
    if refused:
        raise UserError(f"vehicles: the worlds' trucks differ in {', '.join(refused)}, which "
                        "MuJoCo Warp cannot batch per world; give trucks with the same axles "
                        "and joints (payload, masses and positions may differ)")
    mw = mjw.put_model(models[0], batch_sizes={n: n_worlds for n in differ})
    for name in differ:
        rows = np.stack([per[k][name][0] for k in index])
        getattr(mw, name).assign(rows)
    return mw


def check_memory(mj_model: mujoco.MjModel, n_worlds: int, device: wp.context.Device) -> None:
    """Refuse ``n_worlds`` worlds of ``mj_model`` that cannot fit ``device``'s memory.

    Raises
    ------
    UserError
        One line with the memory they need and how many worlds fit.
    """
    m = mj_model
    # The data's arrays scale with the worlds; MuJoCo Warp's are a few times the
    # model's sizes in floats. A generous per-world estimate from a one-world data.
    with wp.ScopedDevice("cpu"):
        d1 = mjw.put_data(m, mujoco.MjData(m), nworld=1)
    per_world = sum(a.capacity for a in vars(d1).values() if isinstance(a, wp.array))
    per_world = 3 * per_world  # the RK4 stages' copies and the solver's scratch
    if device.is_cuda:
        free = device.free_memory
    else:
        free = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    if per_world * n_worlds > 0.8 * free:
        fit = int(0.8 * free // per_world)
        need = per_world * n_worlds / 2**30
        raise UserError(f"n_worlds {n_worlds}: about {need:.1f} GiB, more than "
                        f"{device.alias}'s free memory "
                        f"({free / 2**30:.1f} GiB); use at most about {fit} worlds per batch")


class WarpPlant:
    """``n_worlds`` plants stepped at once on MuJoCo Warp (see the module docstring).

    Parameters
    ----------
    vehicles : Vehicle or sequence of Vehicle
        One truck for every world, or one per world (payloads, their positions
        and the semitrailer's dimensions may differ; the axles and joints may not).
    n_worlds : int
        Number of worlds, at least 1 (the length of ``vehicles`` when that is a sequence).
    device : str
        A Warp device: ``"cpu"`` or ``"cuda"`` (``"cuda:1"``...).
    speed : str
        ``"follow"`` or ``"drive"``, as :class:`artic.plant.Plant`.
    friction : float or sequence of float, optional
        Road friction per world [-], a factor on ``LMUX`` and ``LMUY`` (1: dry).
    tyre_scaling : mapping or sequence of mapping, optional
        Magic Formula scaling factors per world (``{"LKY": 0.9}``), on top of
        the vehicle file's.
    spin_fit : bool
        As :class:`artic.plant.Plant`'s.
    graph : bool
        On a CUDA device, capture each step in a CUDA graph and replay it.

    Raises
    ------
    artic.mjcf.errors.UserError
        For 0 worlds or more than the device's memory holds, a per-world value of
        the wrong length, a device Warp does not have, or trucks that cannot share
        one batched model.
    """

    name = "mbd-warp"

    def __init__(self, vehicles: Vehicle | Sequence[Vehicle], n_worlds: int | None = None,
                 device: str = "cpu", speed: str = "follow",
                 friction: float | Sequence[float] | None = None,
                 tyre_scaling: Mapping[str, float] | Sequence[Mapping[str, float]] | None = None,
                 spin_fit: bool = True, graph: bool = True) -> None:
        if n_worlds is None:
            n_worlds = 1 if isinstance(vehicles, Vehicle) else len(list(vehicles))
        if not isinstance(n_worlds, (int, np.integer)) or n_worlds < 1:
            raise UserError(f"n_worlds {n_worlds!r}: give at least 1 world")
        if speed not in SPEED_MODES:
            raise UserError(f"speed {speed!r}: expected one of {', '.join(SPEED_MODES)} "
                            "(pedals: the CPU plant)")
        self.device = find_device(device)
        self.n_worlds = int(n_worlds)
        self.speed_mode = speed
        per_vehicle = _per_world("vehicles", vehicles, self.n_worlds)
        per_friction = [1.0 if f is None else float(f)
                        for f in _per_world("friction", friction, self.n_worlds)]
        per_scaling = _per_world("tyre_scaling", tyre_scaling, self.n_worlds)
        unique, self._variant = _variants(per_vehicle)
        # One host plant per distinct truck: its indices, constants and resets.
        self.hosts = [Plant(v, speed=speed, spin_fit=spin_fit) for v in unique]
        try:
            h0 = self.hosts[0]
            self.n_wheels = h0.n_wheels
            self.wheel_names = h0.wheel_names
            self.spin_fit = h0.spin_fit
            models = []
            for v, host in zip(unique, self.hosts, strict=True):
                mm = compile_spec(build_model(host.vehicle, solver="newton"))
                first = models[0] if models else mm
                if (mm.nq, mm.nv, mm.nu, mm.na, mm.nbody) != (first.nq, first.nv, first.nu,
                                                              first.na, first.nbody):
                    raise UserError(f"vehicles: {v.name} has another model layout than "
                                    f"{unique[0].name}; give trucks with the same axles")
                if speed != "follow":
                    mm.actuator_gainprm[host._follower, 0] = 0.0
                    mm.actuator_biasprm[host._follower, 2] = 0.0
                models.append(mm)
            self.mj_model = models[0]
            """The first truck's host model, with the Newton solver."""
            check_memory(self.mj_model, self.n_worlds, self.device)
            with wp.ScopedDevice(self.device):
                self.m = _batched_fields(models, self._variant)
                self.d = mjw.put_data(models[0], mujoco.MjData(models[0]), nworld=self.n_worlds)
                self._tables(per_friction, per_scaling)
                self.m.callback = mjw.Callback(passive=self._passive)
            self._graphs: dict[int, object] = {}
            self._graph = graph and self.device.is_cuda
            self.h = float(models[0].opt.timestep)
        except BaseException:  # the host plants' callbacks go with the failed build
            self.close()
            raise

    # ------------------------------------------------------------ setup
    def _tables(self, friction: list[float], scaling: list) -> None:
        """The device's wheel table, tyre sets and per-world controller constants."""
        h0 = self.hosts[0]
        idx = [h0._hub, h0._hub_body, h0._root, h0._wheel_body, h0._spin_dof, h0._act_u,
               h0._act_v, h0._act_w, h0._tread_u, h0._tread_v, h0._tread_w, h0._tyre_set]
        m = self.mj_model
        spin_act = -np.ones((self.n_wheels, 2), dtype=np.int32)
        joint_trn = (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))
        for i, dof in enumerate(h0._spin_dof):
            acts = [a for a in range(m.nu) if int(m.actuator_trntype[a]) in joint_trn
                    and m.actuator_trnid[a, 0] == m.dof_jntid[dof]
                    and not _zero_force(m, a)]  # the tread states' actuators: no force
            for j, a in enumerate(acts):
                if (j >= 2 or m.actuator_dyntype[a] != mujoco.mjtDyn.mjDYN_NONE
                        or m.actuator_gaintype[a] != mujoco.mjtGain.mjGAIN_FIXED
                        or m.actuator_biastype[a] != mujoco.mjtBias.mjBIAS_NONE):
                    raise UserError(f"wheel {self.wheel_names[i]}: the Warp plant's spin fit "
                                    "takes at most a drive and a brake motor on a spin joint")
                spin_act[i, j] = a
        sets = []
        for w in range(self.n_worlds):
            host = self.hosts[self._variant[w]]
            row = []
            for p in host.tyres:
                p = scaled(p, tuple((scaling[w] or {}).items()))
                if friction[w] != 1.0:
                    p = dataclasses.replace(p, **{k: getattr(p, k) * friction[w]
                                                  for k in FRICTION_SCALES})
                row.append(p)
            if len(row) != len(h0.tyres):
                raise UserError("vehicles: every truck needs as many tyre files as the first")
            sets.append(row)
        self.tyre_sets: list[list[TyreParams]] = sets
        """Every world's tyre coefficient sets, scaled as they run."""
        flat = np.stack([warp_tyre.tyre_sets(row) for row in sets])
        self._wheel_ends = warp_tyre.gather(
            warp_tyre.Wheels, table=wp.array(np.column_stack(idx).astype(np.int32), dtype=int),
            spin_act=wp.array(spin_act, dtype=int),
            n_tyres=wp.array(h0._n_tyres.astype(np.float32), dtype=float),
            tyres=wp.array(flat, dtype=warp_tyre.TyreSet),
            moments=int(h0.vehicle.plant.tyre_moments), fit_scale=float(self.spin_fit))
        self._passive_for = None  # the callback's arguments, for the model and data they are of
        self._forces = wp.zeros((self.n_worlds, self.n_wheels), dtype=wp.vec3)
        self._outside = wp.zeros(self.n_worlds, dtype=int)
        self.ctl = warp_control.Tables.build(self, sets)

    # ------------------------------------------------------------ the callback
    def _passive(self, m, d) -> None:
        """MuJoCo Warp's passive callback: every wheel end of every world."""
        known = self._passive_for
        if known is None or known[0] is not m or known[1] is not d:
            clamp = not (self.mj_model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CLAMPCTRL)
            self._passive_for = (m, d, [
                warp_tyre.gather(warp_tyre.Tree, m),
                warp_tyre.gather(warp_tyre.SpinModel, m, timestep=m.opt.timestep,
                                 clamp_ctrl=int(clamp)),
                warp_tyre.gather(warp_tyre.Motion, d), self._wheel_ends])
        wp.launch(warp_tyre.passive_kernel, dim=(d.nworld, self.n_wheels),
                  inputs=self._passive_for[2],
                  outputs=[d.ctrl, d.qfrc_passive, self._forces, self._outside])

    # ------------------------------------------------------------ interface
    def reset(self, initial: InitialState | Sequence[InitialState], steady: bool = False) -> None:
        """Place every world at its ``initial`` state, as :meth:`artic.plant.Plant.reset`.

        ``steady`` starts each as :meth:`artic.plant.Plant.reset_steady` does.
        """
        starts = _per_world("initial", initial, self.n_worlds)
        nq, nv, na, nu = self.mj_model.nq, self.mj_model.nv, self.mj_model.na, self.mj_model.nu
        qpos, qvel = np.empty((self.n_worlds, nq)), np.empty((self.n_worlds, nv))
        act, ctrl = np.empty((self.n_worlds, na)), np.empty((self.n_worlds, nu))
        psi = np.empty((self.n_worlds, 2))
        done: dict = {}
        for w, s in enumerate(starts):
            key = (int(self._variant[w]), s)
            if key not in done:
                host = self.hosts[key[0]]
                (host.reset_steady if steady else host.reset)(s)
                done[key] = (host.data.qpos.copy(), host.data.qvel.copy(), host.data.act.copy(),
                             host.data.ctrl.copy(), host._psi.copy())
            qpos[w], qvel[w], act[w], ctrl[w], psi[w] = done[key]
        d = self.d
        with wp.ScopedDevice(self.device):
            d.qpos.assign(qpos.astype(np.float32))
            d.qvel.assign(qvel.astype(np.float32))
            d.act.assign(act.astype(np.float32))
            d.ctrl.assign(ctrl.astype(np.float32))
            d.time.zero_()
            d.qacc_warmstart.zero_()
            d.qfrc_applied.zero_()
            self._outside.zero_()
            self.ctl.reset(psi)
            mjw.forward(self.m, d)

    def step(self, dt: float, delta, u1, u1_dot) -> None:
        """Advance every world ``dt`` [s] with its commands (scalars, or one per world).

        ``delta`` [rad] turns the left front wheel, ``u1`` [m/s] and ``u1_dot``
        [m/s^2] are the tractor's commanded speed and its rate, as in
        :meth:`artic.plant.Plant.step`.
        """
        cmd = np.empty((self.n_worlds, 3), dtype=np.float32)
        for k, (name, x) in enumerate((("delta", delta), ("u1", u1), ("u1_dot", u1_dot))):
            x = np.asarray(x, dtype=np.float32)
            if x.ndim and x.shape != (self.n_worlds,):
                raise UserError(f"{name}: {x.shape[0] if x.ndim == 1 else x.shape} values for "
                                f"{self.n_worlds} worlds; give one per world, or a scalar")
            cmd[:, k] = x
        self.ctl.command.assign(cmd)
        self.step_device(max(1, round(dt / self.h)))

    def step_device(self, n: int) -> None:
        """``n`` MuJoCo steps of every world on its command in :attr:`ctl`'s ``command``.

        No host synchronisation: a batched controller can write the commands on
        the device and call this in a loop, or in a CUDA graph.
        """
        with wp.ScopedDevice(self.device):
            graph = self._graphs.get(n)
            if graph is not None:
                wp.capture_launch(graph)
                return
            self._step_launches(n)  # eagerly: the kernels load before any capture
            if self._graph:  # the next calls replay this step (a capture does not run it)
                with wp.ScopedCapture() as capture:
                    self._step_launches(n)
                self._graphs[n] = capture.graph

    def _step_launches(self, n: int) -> None:
        self.ctl.before(self, n * self.h)
        for _ in range(n):
            mjw.step(self.m, self.d)
        self.ctl.after(self)

    def observe(self) -> np.ndarray:
        """Every world's signals at the sensor points, ``(n_worlds, 13)``, as ``Plant.observe``."""
        with wp.ScopedDevice(self.device):
            self.ctl.observe(self)
        return self.ctl.signals.numpy().astype(float)

    @property
    def time(self) -> np.ndarray:
        """Every world's simulated time [s]."""
        return self.d.time.numpy().astype(float)

    def wheel_forces(self) -> np.ndarray:
        """Every world's tyre forces from the last callback, world frame [N].

        Shape ``(n_worlds, n_wheels, 3)``, wheel ends in :attr:`wheel_names` order.
        """
        return self._forces.numpy().astype(float)

    def state(self) -> dict[str, np.ndarray]:
        """Every world's ``qpos``, ``qvel`` and ``act`` (the tread deflections among them)."""
        return {"qpos": self.d.qpos.numpy().astype(float),
                "qvel": self.d.qvel.numpy().astype(float),
                "act": self.d.act.numpy().astype(float)}

    def failures(self) -> dict[int, str]:
        """The worlds that diverged, each with one line saying when; empty when none did."""
        failed = self.ctl.state.failed.numpy()
        when = self.ctl.state.fail_time.numpy()
        return {int(w): f"world {w}: the simulation diverged within the step after "
                        f"t = {when[w]:.3f} s; it is held at that state (re-run it on the CPU "
                        "plant, artic.Plant, to find where)"
                for w in np.flatnonzero(failed)}

    def steer_limited(self) -> np.ndarray:
        """Per world, the number of steps whose steering command the linkage limited."""
        return self.ctl.state.steer_limited.numpy().astype(int)

    def tyre_range_counts(self) -> np.ndarray:
        """Per world, tyre evaluations of a loaded wheel outside its file's ranges."""
        return self._outside.numpy().astype(int)

    def close(self) -> None:
        """Close the host plants (their passive callbacks)."""
        for h in self.hosts:
            h.close()

    def __enter__(self) -> WarpPlant:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
