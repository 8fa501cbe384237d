"""Docking runs of the reference controller on the Warp plant: a batch of worlds at once.

:func:`dock_batch` is :func:`artic.validation.docking.run.dock` with the
reference controller for many runs at once, each a world of an
:class:`artic.plant.warp_plant.WarpPlant` (``pip install "artic[gpu]"``). The
host plans every run (the planner, as ``dock`` does) and packs the plans, the
controller's gain tables and the sensors' noise for the device; then, per
sample of :data:`~artic.validation.docking.run.DT`, on the device and without
returning to the host (on a GPU one CUDA graph per sample):

1. the sensors: the plant's signals at the sample with the run's noise (the
   same draws as the CPU run's, :class:`~artic.validation.docking.sensing.SensorStream`)
   and the steering wheel as the CAN bus reports it;
2. the reference controller's law (:mod:`artic.validation.docking.warp_law`);
3. the plant's steps of the sample with the actuators between: the steering
   wheel at most the steer rate, the speed at most the pedal's acceleration, the
   plant's steering map; after every step the jackknife check on the plant's
   articulation. A world that jackknifes, diverges (:meth:`WarpPlant.failures`)
   or is given a non-finite command ends its run there; the others go on;
4. the settling after the controller is done, and the timeout, as on the CPU.

Collisions are checked on the host afterwards, over every sample's plant steps
as the CPU run checks them, and a run that hit something ends at that sample's
end. Each run's row has ``dock.csv``'s columns (``plant`` is ``mbd-warp``), so
that a sweep's table compares with the CPU's; the controller's compute times
are not measured (``solve_ms_*`` NaN).

What runs only on the CPU (:func:`~artic.validation.docking.run.dock`): other
controllers, the synthetic truth, the tractor-only sensor sets, the actuators'
dead time, a clock skew of the semitrailer's unit, the kinematic yard models and
the recordings; each is refused in one line.
"""

from __future__ import annotations

import dataclasses
import math
import os
import time
from collections.abc import Sequence
from itertools import accumulate

import numpy as np
import warp as wp

from artic.mjcf.errors import UserError
from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import load_vehicle
from artic.plant.warp_loop import advance_kernel
from artic.plant.warp_plant import WarpPlant, find_device
from artic.validation.docking import warp_law
from artic.validation.docking.conditions import road
from artic.validation.docking.controllers import Task
from artic.validation.docking.controllers.reference import ReferenceController
from artic.validation.docking.geometry import Frames, box_array
from artic.validation.docking.identify import WheelbaseIdentifier
from artic.validation.docking.planner import HybridAStar, PlanningError
from artic.validation.docking.run import (
    ACCEL_MAX,
    DT,
    PLANT_DT,
    SENSOR_STREAM,
    SETTLE,
    SPEED,
    SPEED_MAX,
    TRAILER_STREAM,
    Result,
    Trace,
)
from artic.validation.docking.scores import estimate_scores, score
from artic.validation.docking.sensing import SensorStream
from artic.validation.docking.spec import STEER_RATE, Conditions, DockRun
from artic.validation.docking.variants import (
    Draw,
    check_trailer,
    draw_semitrailer,
    effective_wheelbase,
)
from artic.validation.synthetic.sensors import SensorModel

f64 = wp.float64

# Ends of a world's run (LoopState.fail).
RUNNING, JACKKNIFE, DIVERGED, NON_FINITE, TIMEOUT = range(5)
# Phases (LoopState.phase).
DRIVING, SETTLING, ENDED = range(3)
# Columns of the loop's per-world constants (Loop.consts).
MBD_I_S, MBD_Q, MBD_OFFSET, WHEEL_STEP, U_STEP, GAMMA_MAX, N_CTRL, CAN_EVERY, CAN_LATE, \
    CAN_STEP, IDEAL, SAMPLE_DT, STEP_DT = range(13)


@wp.struct
class Loop:
    """The loop's constants: per world the columns above, the sensors' noise per sample."""

    consts: wp.array2d(dtype=wp.float64)
    noise: wp.array3d(dtype=wp.float64)
    hitch_qpos: int
    n_sub: int


@wp.struct
class LoopState:
    """Per world: phase, how it ended, plant steps and samples recorded, the actuators.

    ``wheel`` [rad] and ``u``, ``u_next`` [m/s] the actuators' state, their targets
    ``wheel_target``, ``u_target``; ``settle_until`` [s]; ``done`` the controller's.
    """

    phase: wp.array(dtype=int)
    fail: wp.array(dtype=int)
    steps: wp.array(dtype=int)
    samples: wp.array(dtype=int)
    done: wp.array(dtype=int)
    wheel: wp.array(dtype=wp.float64)
    u: wp.array(dtype=wp.float64)
    u_next: wp.array(dtype=wp.float64)
    wheel_target: wp.array(dtype=wp.float64)
    u_target: wp.array(dtype=wp.float64)
    settle_until: wp.array(dtype=wp.float64)


@wp.struct
class Records:
    """What a run's trace keeps, per world.

    At every plant step the plant's signals (``plant``), the steering wheel and the
    speed; at every sample the measured signals, the wheel from the bus and the commands.
    """

    plant: wp.array3d(dtype=float)
    wheel: wp.array2d(dtype=wp.float64)
    speed: wp.array2d(dtype=wp.float64)
    measured: wp.array3d(dtype=wp.float64)
    delta_h: wp.array2d(dtype=wp.float64)
    commands: wp.array3d(dtype=wp.float64)


@wp.func
def bus(loop: Loop, records: Records, w: int, j: int):
    """The steering wheel as the CAN bus reports it at plant step ``j`` [rad] (``SensorStream``)."""
    c = loop.consts
    if c[w, IDEAL] != f64(0.0):
        return records.wheel[w, j]
    every = int(c[w, CAN_EVERY])
    i = wp.min(wp.max((j // every) * every - int(c[w, CAN_LATE]), 0), j)
    held = records.wheel[w, i]
    q = c[w, CAN_STEP]
    if q > f64(0.0):
        return wp.rint(held / q) * q
    return held


@wp.kernel
def sample_kernel(counter: wp.array(dtype=int), loop: Loop, law: warp_law.Law,
                  state: LoopState, records: Records):
    """Sample ``counter[0]`` of world ``w``: the sensors, the law, the settling, the timeout."""
    w = wp.tid()
    k = counter[0]
    if state.phase[w] == ENDED:
        return
    c = loop.consts
    j = state.steps[w]
    if k >= int(c[w, N_CTRL]):
        if state.phase[w] == DRIVING:
            state.fail[w] = TIMEOUT
        state.phase[w] = ENDED
        return
    now = f64(k) * c[w, SAMPLE_DT]
    if state.phase[w] == SETTLING:
        if now >= state.settle_until[w] or (wp.abs(state.u[w]) < f64(1e-9) and wp.abs(
                f64(records.plant[w, j, 3])) < f64(0.01)):
            state.phase[w] = ENDED
        return
    m = records.measured
    for i in range(12):
        m[w, k, i] = f64(records.plant[w, j, i]) + loop.noise[w, k, i]
    m[w, k, 12] = warp_law.wrap_angle(m[w, k, 2] - m[w, k, 8])
    dh = bus(loop, records, w, j)
    records.delta_h[w, k] = dh
    wheel, u1, done = warp_law.command(law, w, m, k, dh)
    records.commands[w, k, 0] = wheel
    records.commands[w, k, 1] = u1
    if not (wp.isfinite(wheel) and wp.isfinite(u1)):
        state.fail[w] = NON_FINITE
        state.phase[w] = ENDED
        return
    state.samples[w] = k + 1
    state.wheel_target[w] = wheel
    if done != 0:
        state.done[w] = 1
        state.settle_until[w] = now + f64(SETTLE)
        state.phase[w] = SETTLING
        state.u_target[w] = f64(0.0)
    else:
        state.u_target[w] = warp_law.clamp(u1, f64(-SPEED_MAX), f64(SPEED_MAX))


@wp.kernel
def actuate_kernel(loop: Loop, state: LoopState, command: wp.array2d(dtype=float)):
    """One plant step's actuators: the wheel's rate, the pedal's acceleration, the steering map."""
    w = wp.tid()
    if state.phase[w] == ENDED:
        command[w, 1] = 0.0
        command[w, 2] = 0.0
        return
    c = loop.consts
    step = c[w, WHEEL_STEP]
    wheel = state.wheel[w] + warp_law.clamp(state.wheel_target[w] - state.wheel[w], -step, step)
    u = state.u[w]
    du = c[w, U_STEP]
    u_next = u + warp_law.clamp(state.u_target[w] - u, -du, du)
    state.wheel[w] = wheel
    state.u_next[w] = u_next
    command[w, 0] = float(warp_law.road_wheel(c[w, MBD_I_S], c[w, MBD_Q], c[w, MBD_OFFSET],
                                              wheel))
    command[w, 1] = float(u)
    command[w, 2] = float((u_next - u) / c[w, STEP_DT])


@wp.kernel
def record_kernel(loop: Loop, failed: wp.array(dtype=int), qpos: wp.array2d(dtype=float),
                  sensor_yaw: wp.array2d(dtype=float), signals: wp.array2d(dtype=float),
                  state: LoopState, records: Records):
    """After a plant step: record it, and end a world that diverged or jackknifed."""
    w = wp.tid()
    if state.phase[w] == ENDED:
        return
    if failed[w] != 0:
        state.fail[w] = DIVERGED
        state.phase[w] = ENDED
        return
    state.u[w] = state.u_next[w]
    j = state.steps[w] + 1
    state.steps[w] = j
    for i in range(13):
        records.plant[w, j, i] = signals[w, i]
    records.wheel[w, j] = state.wheel[w]
    records.speed[w, j] = state.u[w]
    # The plant's articulation as its inertial units report it (Plant.gamma).
    gamma = warp_law.wrap_angle(f64(-qpos[w, loop.hitch_qpos] + sensor_yaw[w, 0]
                                    - sensor_yaw[w, 1]))
    if wp.abs(gamma) > loop.consts[w, GAMMA_MAX]:
        state.fail[w] = JACKKNIFE
        state.phase[w] = ENDED


@dataclasses.dataclass
class Job:
    """One run prepared on the host: what ``dock`` sets up before its loop."""

    run: DockRun
    conditions: Conditions
    vehicle: object
    plant_vehicle: object
    yard: object
    start: object
    frames: Frames
    draw: Draw
    trailer: str
    plan: object = None
    plan_ms: float = 0.0
    failure: str = ""


def _check(run: DockRun, c: Conditions) -> None:
    """One line for what the Warp backend does not run."""
    name = run.controller if isinstance(run.controller, str) else getattr(
        run.controller, "__name__", str(run.controller))
    if run.controller not in ("reference", ReferenceController):
        raise UserError(f"--controller {name}: the Warp backend runs the reference controller "
                        "only; run it on the CPU backend (--backend cpu)")
    what = [(c.truth is not None, "--truth (the synthetic truth)"),
            (c.sensor_set != "full", f"--sensors {c.sensor_set}"),
            (c.delay != 0.0, "an actuator delay"),
            (c.sensors is not None and c.sensors.trailer_skew != 0.0,
             "a semitrailer clock skew"),
            (run.yard_model != "mbd", f"yard model {run.yard_model}"),
            (run.record is not None, "recordings")]
    for bad, text in what:
        if bad:
            raise UserError(f"{text}: runs only on the CPU backend; leave it out with "
                            "--backend warp, or use --backend cpu")
    if not (math.isfinite(c.steer_rate) and c.steer_rate > 0.0):
        raise UserError(f"steer_rate {c.steer_rate:g} rad/s: the steering actuator's rate limit "
                        "must be positive")


def _job(run: DockRun, c: Conditions) -> Job:
    """Plan one run and find its plant's vehicle, as ``dock`` does."""
    _check(run, c)
    _timeout(run)
    scen = run.scenario
    vehicle = load_vehicle(run.vehicle)
    plant_vehicle, draw, trailer = vehicle, Draw(), c.trailer
    if isinstance(trailer, Draw) or check_trailer(trailer) == "unknown":
        if isinstance(trailer, Draw):
            draw, plant_vehicle, trailer = trailer, trailer.vary(vehicle), "given"
        else:
            draw, plant_vehicle = draw_semitrailer(
                vehicle, np.random.default_rng([run.seed, scen.number, TRAILER_STREAM]))
    if c.friction != 1.0 or c.grade != 0.0:
        plant_vehicle = road(plant_vehicle, c.friction, c.grade)
    yard, start = scen.yard(vehicle), scen.start(run.seed)
    job = Job(run, c, vehicle, plant_vehicle, yard, start, Frames.of(plant_vehicle), draw, trailer)
    t0 = time.perf_counter()
    try:
        job.plan = (run.planner or HybridAStar()).plan(yard, vehicle, start)
    except PlanningError as exc:
        job.failure = f"no plan: {exc}"
    job.plan_ms = 1e3 * (time.perf_counter() - t0)
    return job


def _timeout(run: DockRun) -> float:
    """The run's time limit [s], checked."""
    t = run.scenario.timeout if run.timeout is None else float(run.timeout)
    if not (math.isfinite(t) and t > 0.0):
        raise UserError(f"timeout {t:g}: a run's time limit must be a positive number of seconds")
    return t


def _law_consts(ctrl: ReferenceController, yard) -> np.ndarray:
    """The law's constants (:mod:`~artic.validation.docking.warp_law`'s columns) of a run."""
    fr, st, task = ctrl.frames, ctrl.steering, ctrl.task
    out = np.zeros(warp_law.N_CONSTS)
    out[[warp_law.S2X, warp_law.S2Y, warp_law.YAW2]] = (*fr.s2[:2], fr.sensor_yaw[1])
    out[[warp_law.S1X, warp_law.S1Y, warp_law.YAW1]] = (*fr.s1[:2], fr.sensor_yaw[0])
    out[[warp_law.X_REF, warp_law.L2, warp_law.REAR, warp_law.HALF_WIDTH, warp_law.X_DOCK]] = (
        fr.x_ref, fr.kin.params.L2, fr.rear, fr.trailer_box[2], yard.x_dock)
    out[[warp_law.I_S, warp_law.Q, warp_law.OFFSET]] = (st.i_s, st.q, st.delta_h_offset)
    out[[warp_law.DELTA_MAX, warp_law.DELTA_RATE, warp_law.SPEED, warp_law.ACCEL,
         warp_law.DT]] = (ctrl.vehicle.steering.delta_max, ctrl.delta_rate, task.speed,
                          task.accel_max, task.dt)
    return out


def _loop_consts(job: Job, n_ctrl: int) -> np.ndarray:
    """The loop's constants (this module's columns) of a run."""
    mbd = job.plant_vehicle.steering_for("mbd")
    s = job.conditions.sensors or SensorModel()
    out = np.zeros(13)
    out[[MBD_I_S, MBD_Q, MBD_OFFSET]] = (mbd.i_s, mbd.q, mbd.delta_h_offset)
    out[[WHEEL_STEP, U_STEP, GAMMA_MAX, N_CTRL]] = (
        job.conditions.steer_rate * PLANT_DT, ACCEL_MAX * PLANT_DT, job.plant_vehicle.gamma_max,
        n_ctrl)
    out[[CAN_EVERY, CAN_LATE, CAN_STEP, IDEAL]] = (
        max(1, round(1.0 / (s.can_rate * PLANT_DT))), round(s.can_delay / PLANT_DT), s.can_step,
        float(s.is_ideal))
    out[[SAMPLE_DT, STEP_DT]] = (DT, PLANT_DT)
    return out


def record_bytes(timeout: float) -> int:
    """Bytes of one run's records on the device for a run of ``timeout`` [s]."""
    samples = int(round(timeout / DT)) + 1
    steps = samples * round(DT / PLANT_DT) + 1
    # per step the signals (float32) and the wheel and speed (float64); per sample the
    # measured signals, the wheel from the bus, the commands and the noise (float64)
    return steps * (13 * 4 + 2 * 8) + samples * 8 * (13 + 1 + 2 + 12)


def free_bytes(device: str) -> int:
    """The free memory of Warp's ``device`` [bytes] (the host's for ``"cpu"``)."""
    dev = find_device(device)
    if dev.is_cuda:
        return int(dev.free_memory)
    return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")


def runs_that_fit(timeout: float, device: str) -> int:
    """How many runs of ``timeout`` [s] one batch on ``device`` takes, at least 1.

    Their records in half its free memory; the plant's worlds take the rest.
    """
    return max(1, int(0.5 * free_bytes(device) // record_bytes(timeout)))


class Batch:
    """The planned runs of :func:`dock_batch` on one Warp plant, ready to run.

    Attributes
    ----------
    jobs : list of Job
        Every run, in the order given.
    worlds : list of int
        The jobs that have a plan, in the order of the plant's worlds.
    plant : WarpPlant or None
        Their plant, placed at their starts (None when no run has a plan).
    """

    def __init__(self, jobs: list[Job], device: str) -> None:
        self.jobs = jobs
        self.worlds = [i for i, j in enumerate(jobs) if j.plan is not None]
        self._world_of = {i: w for w, i in enumerate(self.worlds)}
        self.plant = None
        if not self.worlds:
            return
        js = [jobs[i] for i in self.worlds]
        self.n_ctrl = [int(round(_timeout(j.run) / DT)) for j in js]
        self.n_sub = round(DT / PLANT_DT)
        need = len(js) * record_bytes(max(self.n_ctrl) * DT)
        free = free_bytes(device)
        if need > 0.5 * free:
            raise UserError(f"{len(js)} runs: their records need about {need / 2**30:.1f} GiB, "
                            f"more than half of {device}'s free memory ({free / 2**30:.1f} GiB); "
                            f"give at most about {runs_that_fit(max(self.n_ctrl) * DT, device)} "
                            "runs per batch, or shorter timeouts")
        self.plant = WarpPlant([j.plant_vehicle for j in js], device=device)
        starts = []
        for j in js:
            x0 = j.frames.kin_from_rear(j.start.x_r, j.start.y_r, j.start.psi_2, j.start.gamma)
            xs, ys = j.frames.tractor_sensor_of_kin(x0)
            starts.append(InitialState(xs, ys, float(x0[2]), float(x0[3]), u1=0.0))
        self.plant.reset(starts)
        self._arrays(js)

    def _arrays(self, js: list[Job]) -> None:
        """The device's copies of the plans, gains, noise, constants, state and records."""
        nw, n_max = len(js), max(self.n_ctrl)
        ctrls, rows, segs = [], [], []
        for j in js:
            ctrl = ReferenceController()
            ctrl.reset(Task(j.vehicle, j.yard, j.plan, DT, SPEED, SPEED_MAX, ACCEL_MAX,
                            STEER_RATE))
            ctrls.append(ctrl)
            segs.append([])
            for d, p, g_ref, d_ref, s in ctrl.refs:
                segs[-1].append((sum(len(r) for r in rows), len(p), d))
                rows.append(np.column_stack([p[:, :3], g_ref, d_ref, s]))
        n_seg = max(len(s) for s in segs)
        table = np.zeros((3, nw, n_seg), dtype=np.int32)
        for w, ss in enumerate(segs):
            for g, seg in enumerate(ss):
                table[:, w, g] = seg
        noise = np.zeros((nw, n_max + 1, 12))
        for w, j in enumerate(js):
            stream = SensorStream(j.conditions.sensors or SensorModel(), np.random.default_rng(
                [j.run.seed, j.run.scenario.number, SENSOR_STREAM]), self.n_ctrl[w] + 1, DT,
                PLANT_DT)
            noise[w, :len(stream.noise)] = stream.noise
        n_steps = n_max * self.n_sub + 1
        mbd = [j.plant_vehicle.steering_for("mbd") for j in js]
        true0 = np.full((nw, n_steps, 13), np.nan, dtype=np.float32)
        true0[:, 0] = self.plant.observe()
        wheel0 = np.full((nw, n_steps), np.nan)
        wheel0[:, 0] = [float(m.steering_wheel(0.0)) for m in mbd]
        speed0 = np.full((nw, n_steps), np.nan)
        speed0[:, 0] = 0.0
        with wp.ScopedDevice(self.plant.device):
            def a64(x):
                return wp.array(np.ascontiguousarray(x, dtype=np.float64), dtype=f64)

            def zeros(dtype=int):
                return wp.zeros(nw, dtype=dtype)

            paths = warp_law.Paths()
            paths.first, paths.count, paths.direction = (wp.array(t, dtype=int) for t in table)
            paths.segments = wp.array(np.array([len(s) for s in segs], dtype=np.int32), dtype=int)
            paths.rows = a64(np.concatenate(rows))
            gains = warp_law.Gains()
            gains.speeds = a64(ctrls[0].schedule[-1].speeds)
            gains.reverse = a64(np.stack([c.schedule[-1].table for c in ctrls]))
            gains.forward = a64(np.stack([c.schedule[1].table for c in ctrls]))
            law = warp_law.Law()
            law.paths, law.gains = paths, gains
            law.consts = a64(np.stack([_law_consts(c, j.yard) for c, j in zip(ctrls, js,
                                                                             strict=True)]))
            law.segment, law.nearest, law.waiting, law.started = (zeros() for _ in range(4))
            law.delta = zeros(f64)
            loop = Loop()
            loop.consts = a64(np.stack([_loop_consts(j, n) for j, n in zip(js, self.n_ctrl,
                                                                         strict=True)]))
            loop.noise = a64(noise)
            loop.hitch_qpos = int(self.plant.mj_model.jnt_qposadr[self.plant.hosts[0]._hitch_yaw])
            loop.n_sub = self.n_sub
            state = LoopState()
            for name in ("phase", "fail", "steps", "samples", "done"):
                setattr(state, name, zeros())
            for name in ("u", "u_next", "wheel_target", "u_target", "settle_until"):
                setattr(state, name, zeros(f64))
            state.wheel = a64(wheel0[:, 0])
            state.wheel_target = a64(wheel0[:, 0])
            rec = Records()
            rec.plant = wp.array(true0, dtype=float)
            rec.wheel, rec.speed = a64(wheel0), a64(speed0)
            rec.measured = a64(np.full((nw, n_max, 13), np.nan))
            rec.delta_h = a64(np.full((nw, n_max), np.nan))
            rec.commands = a64(np.full((nw, n_max, 2), np.nan))
            self.law, self.loop, self.state, self.records = law, loop, state, rec
            self.counter = wp.zeros(1, dtype=int)

    def _sample(self) -> None:
        """One sample's launches: the law, then the plant's steps with the actuators."""
        p, nw = self.plant, self.plant.n_worlds
        wp.launch(sample_kernel, dim=nw, inputs=[self.counter, self.loop, self.law, self.state,
                                                 self.records])
        for _ in range(self.n_sub):
            wp.launch(actuate_kernel, dim=nw, inputs=[self.loop, self.state],
                      outputs=[p.ctl.command])
            p._step_launches(1)
            p.ctl.observe(p)
            wp.launch(record_kernel, dim=nw, inputs=[
                self.loop, p.ctl.state.failed, p.d.qpos, p.ctl.sensors.yaw, p.ctl.signals],
                outputs=[self.state, self.records])
        wp.launch(advance_kernel, dim=1, inputs=[self.counter])

    def run(self, check_every: int = 50) -> list[Result]:
        """Drive every world to its end; one :class:`Result` per job, in the jobs' order.

        The host reads back whether every world has ended once every ``check_every``
        samples, to stop early; nothing else until the end.
        """
        if self.plant is not None:
            with wp.ScopedDevice(self.plant.device):
                graph = None
                for k in range(max(self.n_ctrl) + 1):
                    if graph is not None:
                        wp.capture_launch(graph)
                    else:
                        self._sample()
                        if self.plant._graph and k == 0:
                            with wp.ScopedCapture() as capture:  # recorded, not run
                                self._sample()
                            graph = capture.graph
                    if (k + 1) % check_every == 0 and np.all(
                            self.state.phase.numpy() == ENDED):
                        break
            self._read_back()
            self.plant.close()
        return [self._result(i) for i in range(len(self.jobs))]

    def _read_back(self) -> None:
        """The records and the worlds' ends, on the host once."""
        st, rec = self.state, self.records
        self.host = {name: getattr(st, name).numpy() for name in ("steps", "samples", "fail",
                                                                  "done")}
        self.host.update({name: getattr(rec, name).numpy() for name in (
            "plant", "wheel", "speed", "measured", "commands")})
        self.host["failures"] = self.plant.failures()

    def _trace(self, w: int) -> Trace:
        """World ``w``'s trace as ``dock`` keeps it, with the collision check of its samples."""
        h = self.host
        n_steps = int(h["steps"][w]) + 1
        n_samples = int(h["samples"][w])
        fail = int(h["fail"][w])
        true = h["plant"][w, :n_steps].astype(float)
        job = self.jobs[self.worlds[w]]
        n = self.n_sub
        # Every sample's steps were checked after them, but for the one a jackknife ended.
        checked = (n_steps - 2) // n if fail == JACKKNIFE else (n_steps - 1) // n
        # The first hit over the checked samples' steps is the first sample's with one.
        i, b, unit = job.frames.first_hit_of_signals(true[1:1 + checked * n],
                                                     box_array(job.yard.obstacles))
        if i >= 0:
            n_steps = 1 + (i // n + 1) * n  # the run ends with the sample that hit
            n_samples = min(n_samples, i // n + 1)
        tr = Trace()
        tr.true = list(true[:n_steps])
        tr.steering_wheel = h["wheel"][w, :n_steps].tolist()
        tr.speed = h["speed"][w, :n_steps].tolist()
        tr.t = list(accumulate([0.0] + [PLANT_DT] * (n_steps - 1)))
        tr.t_ctrl = [k * DT for k in range(n_samples)]
        tr.measured = list(h["measured"][w, :n_samples])
        tr.commands = [tuple(c) for c in h["commands"][w, :n_samples].tolist()]
        tr.seen_at = [k * n for k in range(n_samples)]
        tr.horizons = [None] * n_samples
        tr.references = [None] * n_samples
        tr.done = bool(h["done"][w])
        gamma_max = job.plant_vehicle.gamma_max
        if i >= 0:
            tr.failure = (f"collision: {('tractor', 'semitrailer')[unit]} hit "
                          f"{job.yard.obstacles[b].name} at t = {tr.t[1 + i]:.2f} s")
        elif fail == JACKKNIFE:
            tr.failure = (f"jackknife: |gamma| {math.degrees(abs(true[-1, 12])):.1f} deg beyond "
                          f"{math.degrees(gamma_max):.1f} deg at t = {tr.t[-1]:.2f} s")
        elif fail == DIVERGED:
            tr.failure = f"plant diverged: {h['failures'].get(w, f'world {w}')}"
        elif fail == NON_FINITE:
            c = h["commands"][w, n_samples]
            tr.failure = (f"controller error: non-finite command {tuple(c)} at "
                          f"t = {n_samples * DT:.1f} s")
        elif fail == TIMEOUT:
            tr.failure = f"timeout: not docked after {_timeout(job.run):.0f} s"
        return tr

    def _result(self, i: int) -> Result:
        """Job ``i``'s result: its row as ``dock`` writes it."""
        job = self.jobs[i]
        if i in self._world_of:
            trace = self._trace(self._world_of[i])
        else:
            trace = Trace(failure=job.failure)
        identifier = WheelbaseIdentifier(job.vehicle)
        for t, signals in zip(trace.t_ctrl, trace.measured, strict=True):
            identifier.update(t, signals)
        c, run = job.conditions, job.run
        plan = job.plan
        row = {"scenario": run.scenario.name, "vehicle": job.vehicle.name,
               "controller": "reference", "plant": WarpPlant.name, "seed": run.seed,
               **score(trace, job.yard, job.plant_vehicle, job.frames, job.start),
               "late_commands": 0,
               "plan_ms": job.plan_ms, "plan_expansions": plan.expansions if plan else 0,
               "plan_direction_changes": plan.direction_changes if plan else 0,
               "plan_length_m": plan.length if plan else math.nan,
               "sensors": c.sensor_set,
               **estimate_scores(trace, Frames.of(job.vehicle), job.frames),
               "trailer": job.trailer, "l2_nominal_m": effective_wheelbase(job.vehicle),
               "l2_true_m": effective_wheelbase(job.plant_vehicle),
               "l2_identified_m": identifier.L2 if identifier.updates else math.nan,
               "l2_updates": identifier.updates, **job.draw.row()}
        return Result(row, trace, plan, job.yard, job.start)


def prepare(runs: Sequence[DockRun], conditions: Conditions | Sequence[Conditions] | None = None,
            device: str = "cpu") -> Batch:
    """Plan every run and place its world on one Warp plant (see :func:`dock_batch`)."""
    runs = list(runs)
    if not runs:
        raise UserError("dock_batch: no runs given; give at least one DockRun")
    conds = conditions if isinstance(conditions, Sequence) else [conditions] * len(runs)
    if len(conds) != len(runs):
        raise UserError(f"conditions: {len(conds)} for {len(runs)} runs; give one per run, or "
                        "one for all")
    return Batch([_job(r, c or Conditions()) for r, c in zip(runs, conds, strict=True)], device)


def dock_batch(runs: Sequence[DockRun], conditions: Conditions | Sequence[Conditions] | None = None,
               device: str = "cpu") -> list[Result]:
    """Many docking runs of the reference controller at once, on the Warp plant.

    Parameters
    ----------
    runs : sequence of DockRun
        Each run's scenario, vehicle (their plants must share a model layout: the
        presets' payloads and semitrailer variants do), ``"reference"`` controller and
        seed; ``timeout`` and ``planner`` as for :func:`~artic.validation.docking.run.dock`.
    conditions : Conditions or sequence of Conditions, optional
        For all runs or one per run: the sensors' noise (``SensorModel``), the
        semitrailer (``trailer``), the steering rate, friction and grade.
    device : str
        The Warp device, ``"cpu"`` or ``"cuda"``.

    Returns
    -------
    list of Result
        One per run, in order; a run that failed (no plan, jackknife, a diverged
        world, collision, timeout) is a row with its reason, and the others go on.
    """
    return prepare(runs, conditions, device).run()

