"""The reference docking controller batched on the Warp plant, against the CPU run.

Skipped where the optional ``gpu`` extra (``mujoco-warp``, ``warp-lang``) is not
installed. Warp's CPU device is slow (about 2 s of wall time per simulated second
for a few worlds), so the runs are cut at 2 s: long enough for the controller to
start, steer onto its path and reach the cruising speed.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

pytest.importorskip("warp", reason="the gpu extra (warp-lang) is not installed")
pytest.importorskip("mujoco_warp", reason="the gpu extra (mujoco-warp) is not installed")

import warp as wp  # noqa: E402

from artic.mjcf.errors import UserError  # noqa: E402
from artic.validation.docking import warp_dock  # noqa: E402
from artic.validation.docking.geometry import Box  # noqa: E402
from artic.validation.docking.run import drive  # noqa: E402
from artic.validation.docking.scenarios import scenario  # noqa: E402
from artic.validation.docking.spec import Conditions, DockRun  # noqa: E402

wp.config.quiet = True

SHORT = 2.0  # [s] of each run

# Tolerances. The Warp plant is float32 and the CPU plant float64: over these 2 s
# the positions part by about 1e-5 m (the plant alone: 1e-6 m in 1 s, the design
# note's table), so 1e-4 m, as tests/test_warp_plant.py. The commanded steering
# wheel is the LQR's response to those differences through the steering ratio
# (about 20) and gains of about 1 rad/m: measured 1.1e-4 rad in the alley at 4 rad
# of wheel, so 1e-3 rad; the speed profile is the same numbers on both, 1e-9 m/s.
POS_TOL = 1e-4
GAMMA_TOL = 1e-3  # [deg]
WHEEL_TOL = 1e-3  # [rad]


def _runs():
    return [DockRun(scenario("straight"), "gosar2022-unloaded", "reference", 0, timeout=SHORT),
            DockRun(scenario("alley"), "gosar2022-loaded", "reference", 1, timeout=SHORT),
            DockRun(scenario("straight"), "gosar2022-unloaded", "reference", 2, timeout=SHORT),
            DockRun(scenario("alley"), "gosar2022-unloaded", "reference", 3, timeout=SHORT),
            DockRun(scenario("straight"), "gosar2022-unloaded", "reference", 0, timeout=SHORT)]


def test_batch_matches_the_cpu_run_and_failed_worlds_do_not_stop_it():
    batch = warp_dock.prepare(_runs())
    # World 2 jackknifes at once (its limit below the start's articulation); world 3
    # diverges (a state that is not finite): each fails alone.
    consts = batch.loop.consts.numpy()
    consts[2, warp_dock.GAMMA_MAX] = 1e-4
    batch.loop.consts.assign(consts)
    qvel = batch.plant.d.qvel.numpy()
    qvel[3, 0] = np.nan
    batch.plant.d.qvel.assign(qvel)
    # World 4 reverses into a wall 0.3 m behind its rear, which it reaches in about 1.1 s
    # (from rest at 0.5 m/s^2); collisions are checked on the host after the batch.
    job = batch.jobs[4]
    x_r = job.start.x_r
    wall = Box("wall", x_r - 0.6, x_r - 0.3, job.start.y_r - 5.0, job.start.y_r + 5.0)
    job.yard = dataclasses.replace(job.yard, obstacles=(*job.yard.obstacles, wall))
    results = batch.run()
    for res, run in zip(results[:2], _runs()[:2], strict=True):
        ref = drive(run.scenario, run.vehicle, "reference", run.seed, timeout=SHORT)
        got, want = np.array(res.trace.commands), np.array(ref.trace.commands)
        assert got.shape == want.shape == (20, 2)
        assert np.abs(got[:, 0] - want[:, 0]).max() < WHEEL_TOL
        assert np.abs(got[:, 1] - want[:, 1]).max() < 1e-9
        assert np.ptp(want[:, 0]) > 10 * WHEEL_TOL  # the controller steered
        a, b = np.array(res.trace.true), np.array(ref.trace.true)
        assert a.shape == b.shape == (201, 13)
        assert np.abs(a[:, [0, 1, 6, 7]] - b[:, [0, 1, 6, 7]]).max() < POS_TOL
        assert np.degrees(np.abs(a[:, 12] - b[:, 12]).max()) < GAMMA_TOL
        # the end pose the scores are taken from
        for key, tol in (("lateral_error_m", POS_TOL), ("longitudinal_error_m", POS_TOL),
                         ("heading_error_deg", GAMMA_TOL), ("max_gamma_deg", GAMMA_TOL)):
            assert abs(res.row[key] - ref.row[key]) < tol, (key, res.row[key], ref.row[key])
        assert res.row["failure"] == ref.row["failure"] == "timeout: not docked after 2 s"
        assert res.row["plant"] == "mbd-warp" and set(ref.row) <= set(res.row)
    assert results[2].row["failure"].startswith("jackknife:")
    assert len(results[2].trace.t) == 2  # the start and the step that jackknifed
    assert results[3].row["failure"].startswith("plant diverged: world 3")
    hit = results[4]
    assert hit.row["failure"].startswith("collision: semitrailer hit wall at t = "), hit.row
    hit_t = float(hit.row["failure"].split("t = ")[1].split(" s")[0])
    assert 0.5 < hit_t < SHORT and hit.trace.t[-1] >= hit_t
    # the run ends with the sample whose steps hit: its 10 plant steps, no later sample
    assert len(hit.trace.t) - 1 == 10 * len(hit.trace.t_ctrl) < 10 * 20
    assert np.array_equal(hit.trace.commands, results[0].trace.commands[:len(hit.trace.t_ctrl)])
    assert not any(r.row["success"] for r in results)


@pytest.mark.parametrize("run, conditions, match", [
    (DockRun(scenario("straight"), "gosar2022-unloaded", "mpc", 0), None, "reference controller"),
    (DockRun(scenario("straight"), "gosar2022-unloaded", "reference", 0),
     Conditions(sensor_set="tractor"), "CPU backend"),
    (DockRun(scenario("straight"), "gosar2022-unloaded", "reference", 0),
     Conditions(delay=0.05), "CPU backend"),
])
def test_what_runs_only_on_the_cpu_is_refused_in_one_line(run, conditions, match):
    with pytest.raises(UserError, match=match) as exc:
        warp_dock.prepare([run], conditions)
    assert "\n" not in str(exc.value)


def test_bad_batches_are_refused_in_one_line(monkeypatch):
    with pytest.raises(UserError, match="at least one"):
        warp_dock.prepare([])
    runs = _runs()[:2]
    with pytest.raises(UserError, match="one per run"):
        warp_dock.prepare(runs, [Conditions()] * 3)
    run = DockRun(scenario("straight"), "gosar2022-unloaded", "reference", 0, timeout=-1.0)
    with pytest.raises(UserError, match="positive number of seconds"):
        warp_dock.prepare([run])
    # a batch whose records do not fit the device: refused before the plant is built
    monkeypatch.setattr(warp_dock, "free_bytes", lambda device: 3 * warp_dock.record_bytes(SHORT))
    with pytest.raises(UserError, match="give at most about 1 runs per batch") as exc:
        warp_dock.prepare(runs)
    assert "\n" not in str(exc.value)


@pytest.mark.skipif(wp.is_cuda_available(), reason="a CUDA GPU is here")
def test_a_missing_gpu_is_one_line():
    run = _runs()[0]
    with pytest.raises(UserError, match="no CUDA GPU") as exc:
        warp_dock.prepare([run], device="cuda")
    assert "\n" not in str(exc.value)


def test_a_sweep_on_the_warp_backend_writes_the_cpu_sweep_s_tables(tmp_path, monkeypatch,
                                                                    capsys):
    import pandas as pd

    from artic.validation.cli.entry import main
    from artic.validation.docking import scenarios
    from artic.validation.docking.scores import COLUMNS

    # 1 s runs: the sweep's tables, not a docking (the test above compares the runs).
    monkeypatch.setitem(scenarios.SCENARIOS, "straight",
                        dataclasses.replace(scenarios.SCENARIOS["straight"], timeout=1.0))
    out = tmp_path / "out"
    code = main(["dock", "--sweep", "friction=1,0.5", "--scenario", "straight", "--vehicle",
                 "gosar2022-unloaded", "--seeds", "1", "--backend", "warp", "--device", "cpu",
                 "--no-recordings", "--out-dir", str(out)])
    assert code == 1  # none docked in 1 s: the tables are written, and the exit says so
    runs = pd.read_csv(out / "sweep_runs.csv")
    assert list(runs.columns) == ["axis", "level", *COLUMNS]
    assert list(runs["level"]) == [1.0, 0.5] and set(runs["plant"]) == {"mbd-warp"}
    assert set(runs["failure"]) == {"timeout: not docked after 1 s"}
    summary = pd.read_csv(out / "sweep.csv")
    assert len(summary) == 2 and {"success", "success_lo", "timeouts"} <= set(summary.columns)
    assert (out / "sweep.md").is_file() and (out / "sweep.png").is_file()
    assert "none of the 2 run(s) docked" in capsys.readouterr().err


class _NoPath:
    """A planner that finds nothing."""

    def plan(self, yard, vehicle, start):
        from artic.validation.docking.planner import PlanningError

        raise PlanningError("boxed in")


def test_a_run_without_a_plan_is_a_failed_row_beside_the_others():
    runs = [DockRun(scenario("straight"), "gosar2022-unloaded", "reference", 0, timeout=1.0),
            DockRun(scenario("straight"), "gosar2022-unloaded", "reference", 1, timeout=1.0,
                    planner=_NoPath())]
    batch = warp_dock.prepare(runs)
    assert batch.worlds == [0] and batch.plant.n_worlds == 1  # no world for the unplanned run
    first, second = batch.run()
    assert first.row["failure"] == "timeout: not docked after 1 s" and len(first.trace.t) == 101
    assert second.row["failure"] == "no plan: boxed in" and not second.trace.t
    assert second.row["seed"] == 1 and second.row["plant"] == "mbd-warp"
