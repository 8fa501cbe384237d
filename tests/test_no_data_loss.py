"""No data loss: one campaign per folder, unique temporaries, stale ones cleaned, the umask
honoured, resumable tuning, damaged caches re-imported, workers that end with their parent,
exports named by the client, MuJoCo's log out of the current folder, portable tuned files."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import tomllib
from concurrent.futures import Executor, Future
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.writer import updated, write_vehicle
from artic.validation.cli.commands import main
from artic.validation.logs.oxts import export_oxts
from artic.validation.logs.runfile import Run, atomic_write_text, write_run
from artic.validation.plumbing.outputs import LOCK_NAME, OutDirLock, clean_stale
from artic.validation.synthetic import generate
from artic.validation.synthetic.testmatrix import MATRIX, TUNING
from tests.hostile_logs import slalom

ROOT = Path(__file__).resolve().parents[1]


def python(code: str, **kw) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], env=env,
                            stdout=subprocess.PIPE, text=True, **kw)


def test_two_campaigns_in_one_folder(tmp_path, capsys):
    # Another process runs a campaign in the folder (it holds the lock, as run_campaign
    # does); a second campaign there is refused, naming it; once it is killed, the
    # folder is free: a crash never leaves it locked.
    out = tmp_path / "out"
    holder = python(f"""
        import sys, time
        sys.argv = ["artic", "campaign", "--out-dir", {str(out)!r}]
        from artic.validation.plumbing.outputs import OutDirLock
        with OutDirLock({str(out)!r}, "campaign"):
            print("locked", flush=True)
            time.sleep(60)
    """)
    try:
        assert holder.stdout.readline().strip() == "locked"
        assert main(["campaign", "--out-dir", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1
        assert f"{out}: in use by another artic campaign (process {holder.pid} on " in err[0]
        assert "artic campaign --out-dir" in err[0] and "choose another --out-dir" in err[0]
        # validate takes the same lock.
        log = write_run(slalom(), tmp_path / "log.parquet")
        assert main(["validate", str(log), "--models", "kin", "--out-dir", str(out)]) == 2
        assert "in use by another artic campaign" in capsys.readouterr().err
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    with OutDirLock(out, "campaign"):
        info = json.loads((out / LOCK_NAME).read_text())
        assert info["pid"] == os.getpid() and info["what"] == "campaign"


def test_stale_temporaries_are_cleaned(tmp_path):
    out = tmp_path / "out"
    (out / "runs").mkdir(parents=True)
    (out / "synthetic" / ".45-docking.ab12cd.part").mkdir(parents=True)
    (out / "synthetic" / ".45-docking.ab12cd.part" / "tractor.csv").write_text("half")
    (out / "runs" / ".x.kin.parquet.q1w2e3.part").write_bytes(b"half")
    (out / "params").mkdir()
    (out / "params" / ".t.toml.zz.part").write_text("half")
    keep = [out / "runs" / "x.kin.parquet", out / ".hidden-but-mine"]
    for k in keep:
        k.write_text("whole")
    with OutDirLock(out, "campaign"):
        removed = clean_stale(out)
    assert len(removed) == 3
    assert all(k.read_text() == "whole" for k in keep)
    assert not [p for p in out.rglob("*.part")]


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_files_honour_the_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        f = atomic_write_text(tmp_path / "a.txt", "x")
        v = write_vehicle(updated("six-axle", {}, "test"), tmp_path / "v.toml")
        export = generate.write_export(Run(slalom().frame.iloc[:200].copy(),
                                           {"name": "e"}), tmp_path)
    finally:
        os.umask(old)
    assert f.stat().st_mode & 0o777 == 0o666 & ~mask
    assert Path(v.path).stat().st_mode & 0o777 == 0o666 & ~mask
    assert export.stat().st_mode & 0o777 == 0o777 & ~mask
    for p in export.iterdir():
        assert p.stat().st_mode & 0o777 == 0o666 & ~mask, p


def test_concurrent_write_vehicle_never_corrupts(tmp_path):
    # 8 writers, 15 files each, one target: every version read back is whole.
    target = tmp_path / "tuned.toml"
    errors = []

    def writer(k):
        try:
            for i in range(15):
                write_vehicle(updated("gosar2022-unloaded", {"tyre": {"f": 5.0 + k + i / 100}},
                                      f"writer {k}"), target)
                load_vehicle(target)
        except Exception as exc:  # noqa: BLE001 - collected and asserted below
            errors.append(exc)

    threads = [threading.Thread(target=writer, args=(k,)) for k in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tuned.toml"]


def test_concurrent_write_export_never_deletes_a_whole_export(tmp_path):
    run = Run(slalom().frame.iloc[:300].copy(), {"name": "m"})
    errors = []

    def writer():
        try:
            for _ in range(10):
                generate.write_export(run, tmp_path)
        except Exception as exc:  # noqa: BLE001
            errors.append(exc)

    threads = [threading.Thread(target=writer) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m"]
    assert sorted(p.name for p in (tmp_path / "m").iterdir()) == [
        "can.csv.gz", "meta.json", "tractor.csv.gz", "trailer.csv.gz"]


class HostileExecutor(Executor):
    """A 'cluster' whose results name a folder of their own choosing."""

    def submit(self, fn, *args, **kwargs):
        f = Future()
        f.set_result((Run(slalom().frame.iloc[:300].copy(), {"name": "../../escaped"}), 0.1))
        return f


def test_export_names_come_from_the_client(tmp_path):
    out = tmp_path / "a" / "b" / "synthetic"
    name = MATRIX[45].name
    paths = generate.generate_campaign(out, only=[name], executor=HostileExecutor())
    assert paths == [out / name]
    assert json.loads((out / name / "meta.json").read_text())["name"] == name
    assert not (tmp_path / "escaped").exists() and not (tmp_path / "a" / "escaped").exists()
    with pytest.raises(ValueError, match="not a plain folder name"):
        generate.write_export(Run(slalom().frame.iloc[:10].copy(), {"name": "../x"}), out)


def test_workers_end_with_their_parent():
    # The parent starts two pool workers blocked on long tasks, then is killed.
    parent = python("""
        import os, time
        from concurrent.futures import ProcessPoolExecutor
        from artic.validation.plumbing.workers import init_worker
        pool = ProcessPoolExecutor(2, initializer=init_worker, initargs=(os.getpid(),))
        busy = [pool.submit(time.sleep, 600) for _ in range(2)]
        while len(pool._processes) < 2:
            time.sleep(0.05)
        print(*sorted(pool._processes), flush=True)
        time.sleep(600)
    """)
    try:
        pids = [int(p) for p in parent.stdout.readline().split()]
        assert len(pids) == 2
    finally:
        parent.send_signal(signal.SIGKILL)
        parent.wait()
    deadline = time.monotonic() + 20.0
    alive = set(pids)
    while alive and time.monotonic() < deadline:
        for p in list(alive):
            try:
                os.kill(p, 0)
                with open(f"/proc/{p}/stat") as f:  # a zombie has ended
                    if f.read().split()[2] == "Z":
                        alive.discard(p)
            except (ProcessLookupError, FileNotFoundError):
                alive.discard(p)
        time.sleep(0.2)
    assert not alive, f"workers {alive} outlived their parent"


def test_mujoco_log_not_in_the_current_folder(tmp_path, monkeypatch, unloaded):
    import mujoco

    from artic.validation.plumbing.runtime import MujocoWarning

    monkeypatch.chdir(tmp_path)
    m = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><freejoint/><geom size='1'/></body></worldbody></mujoco>")
    d = mujoco.MjData(m)
    d.qvel[0] = np.nan
    with pytest.warns(MujocoWarning, match="MuJoCo: Nan, Inf or huge value in QVEL"):
        mujoco.mj_step(m, d)
    assert list(tmp_path.iterdir()) == []


def test_tuned_files_name_their_tyre_portably(tmp_path):
    shipped = write_vehicle(updated("six-axle", {}, "test"), tmp_path / "x" / "t.toml")
    data = tomllib.loads(Path(shipped.path).read_text())
    assert data["tyre"]["file"] == "artic-truck-315-80R22.5.tir"
    # A vehicle with its own tyre beside it, tuned into another folder: a relative path.
    own = tmp_path / "own"
    own.mkdir()
    text = Path(load_vehicle("six-axle").path).read_text().replace(
        'file = "artic-truck-315-80R22.5.tir"', 'file = "mine.tir"')
    (own / "v.toml").write_text(text)
    (own / "mine.tir").write_bytes(Path(shipped.tyre_file).read_bytes())
    tuned = write_vehicle(updated(own / "v.toml", {}, "test"), tmp_path / "out" / "t.toml")
    assert tomllib.loads(Path(tuned.path).read_text())["tyre"]["file"] == "../own/mine.tir"
    assert Path(tuned.tyre_file).resolve() == (own / "mine.tir").resolve()


def test_tuning_resumes_per_model_and_load(tmp_path, monkeypatch):
    from artic.validation.campaign import main as campaign
    from artic.validation.campaign import tuning

    logs = [Run(slalom().frame, {"name": n, "load": "unloaded" if "-unloaded-" in n
                                 else "loaded"}) for n in TUNING]
    calls, killed = [], []

    def fake_tune(model, vehicle, logs, jobs, progress, start=None):
        calls.append((model, logs[0].meta["load"]))
        if len(calls) == 3 and not killed:
            killed.append(True)
            raise KeyboardInterrupt  # the campaign is killed while tuning
        return tuning.Fit(model, [tuning.Bound("i_s", 21.0, 15.0, 26.0)], {"i_s": 20.0},
                          1.0, 0.5, 10.0, 9.0, 3, 0.1)

    monkeypatch.setattr(tuning, "tune_model", fake_tune)
    with pytest.raises(KeyboardInterrupt):
        campaign._tune(tmp_path, logs, ("kin", "stm"), "key", 1)
    saved = json.loads((tmp_path / "tuning.json").read_text())
    assert [r["model"] for r in saved["loads"]["unloaded"]["summary"]] == ["kin", "stm"]
    assert not saved["complete"]
    calls.clear()
    done = campaign._tune(tmp_path, logs, ("kin", "stm"), "key", 1)
    assert calls == [("kin", "loaded"), ("stm", "loaded")]  # the unloaded fits were kept
    assert done["complete"] and set(done["loads"]["unloaded"]["fitted"]) == {"kin", "stm"}
    # A changed key (other code, models or seed) tunes again from scratch.
    calls.clear()
    campaign._tune(tmp_path, logs, ("kin", "stm"), "other", 1)
    assert len(calls) == 4


def test_a_damaged_export_is_generated_again(tmp_path, monkeypatch, capsys):
    # The campaign keeps no imported copy of a log: it imports the export each time.
    # An export that no longer imports (a table cut short by a crash) is generated
    # again, once, and gives the same log.
    from artic.validation.campaign import main as campaign

    export = tmp_path / "synthetic" / "run"
    made = []

    def generate(*args, **kwargs):  # as exports_as_written: what lacks its meta.json
        if not (export / "meta.json").is_file():
            export_oxts(slalom(), export)
            (export / "meta.json").write_text(json.dumps({"load": "unloaded"}))
            made.append(export)
            yield [export]

    monkeypatch.setattr(campaign, "exports_as_written", generate)
    monkeypatch.setattr(campaign, "export_folders", lambda out_dir, only: [export])
    first = campaign.load_logs(tmp_path)[0]
    table = export / "tractor.csv"
    table.write_bytes(table.read_bytes()[:100])  # cut short by a crash
    again = campaign.load_logs(tmp_path)[0]
    assert f"{export}: does not import" in capsys.readouterr().err
    assert len(made) == 2
    assert again.frame.equals(first.frame)
    assert not (tmp_path / "logs").exists()  # nothing but the exports


def test_a_resumed_validation_takes_the_criteria_from_the_footer(tmp_path, monkeypatch):
    # A reused run file is not read sample by sample: its criteria, computed when it
    # was simulated, come from its footer; the rows are the same. A file whose
    # footer is damaged (cut short) is simulated again, not trusted.
    from artic.mjcf import load_vehicle
    from artic.validation.runs import validate as val

    v = load_vehicle("gosar2022-unloaded")
    logs = [slalom()]
    first = val.validate_runs(logs, v, ["kin", "stm"], out_dir=tmp_path, reuse_key="k")
    calls = []
    real = val._simulate
    monkeypatch.setattr(val, "_simulate", lambda *a: calls.append(a[0]) or real(*a))
    again = val.validate_runs(logs, v, ["kin", "stm"], out_dir=tmp_path, reuse_key="k")
    assert calls == [] and again.attrs["reused"] == 2
    pd.testing.assert_frame_equal(first, again)
    target = tmp_path / "runs" / f"{logs[0].name}.stm.parquet"
    target.write_bytes(target.read_bytes()[:-100])
    third = val.validate_runs(logs, v, ["kin", "stm"], out_dir=tmp_path, reuse_key="k")
    assert calls == ["stm"]
    pd.testing.assert_frame_equal(first.drop(columns="wall_s"), third.drop(columns="wall_s"))


def _square_and_pid(x):
    return x * x, os.getpid()


def test_completed_gives_every_task_once_and_its_pool_ends_when_closed_early():
    import contextlib

    from artic.validation.plumbing.workers import completed

    tasks = [(k, (k,)) for k in range(6)]
    serial = dict(completed(_square_and_pid, tasks, jobs=1))
    assert {k: v[0] for k, v in serial.items()} == {k: k * k for k in range(6)}
    assert {v[1] for v in serial.values()} == {os.getpid()}  # here, one after another
    pooled = dict(completed(_square_and_pid, tasks, jobs=2))
    assert {k: v[0] for k, v in pooled.items()} == {k: k * k for k in range(6)}
    assert os.getpid() not in {v[1] for v in pooled.values()}  # on worker processes
    # Closed after the first result: the workers it started end with it.
    with contextlib.closing(completed(_square_and_pid, tasks, jobs=2)) as done:
        _, (_, worker) = next(done)
    deadline = time.monotonic() + 20.0
    while time.monotonic() < deadline:
        try:
            os.kill(worker, 0)
        except ProcessLookupError:
            break
        time.sleep(0.05)
    else:
        pytest.fail(f"worker {worker} still runs after the iteration was closed")


def test_tuning_side_by_side_saves_each_fit_and_stops_starting_new_ones(tmp_path, monkeypatch):
    # With two jobs the load conditions are tuned on two threads. A fit that
    # raises (as an interrupted one does) ends the stage: the other load's
    # running fit finishes and is saved, no further fit starts, and the next
    # run resumes from what was saved.
    import threading
    import time

    from artic.validation.campaign import main as campaign
    from artic.validation.campaign import tuning

    logs = [Run(slalom().frame, {"name": n, "load": "unloaded" if "-unloaded-" in n
                                 else "loaded"}) for n in TUNING]
    calls, lock = [], threading.Lock()
    running, interrupted = threading.Event(), threading.Event()

    def fake_tune(model, vehicle, logs, jobs, progress, start=None):
        load = logs[0].meta["load"]
        with lock:
            calls.append((model, load, jobs))
        if (model, load) == ("stm", "unloaded"):
            assert running.wait(10.0)  # the other load's first fit is under way
            interrupted.set()
            raise KeyboardInterrupt
        if (model, load) == ("kin", "loaded"):
            running.set()
            assert interrupted.wait(10.0)
            time.sleep(1.0)  # still running when the stage is interrupted
        return tuning.Fit(model, [tuning.Bound("i_s", 21.0, 15.0, 26.0)], {"i_s": 20.0},
                          1.0, 0.5, 10.0, 9.0, 3, 0.1)

    monkeypatch.setattr(tuning, "tune_model", fake_tune)
    with pytest.raises(KeyboardInterrupt):
        campaign._tune(tmp_path, logs, ("kin", "stm"), "key", 2)
    saved = json.loads((tmp_path / "tuning.json").read_text())
    assert [r["model"] for r in saved["loads"]["unloaded"]["summary"]] == ["kin"]
    assert [r["model"] for r in saved["loads"]["loaded"]["summary"]] == ["kin"]
    assert ("stm", "loaded", 1) not in calls  # it would have started after the interruption
    assert all(jobs == 1 for _, _, jobs in calls)  # two jobs: one thread for each load
    assert not saved["complete"]
    calls.clear()
    interrupted.set()
    monkeypatch.setattr(tuning, "tune_model", lambda model, vehicle, logs, jobs, progress,
                        start=None: calls.append((model, logs[0].meta["load"])) or tuning.Fit(
                            model, [], {}, 1.0, 1.0, 1.0, 1.0, 1, 0.1))
    done = campaign._tune(tmp_path, logs, ("kin", "stm"), "key", 2)
    assert sorted(calls) == [("stm", "loaded"), ("stm", "unloaded")]  # the kin fits were kept
    assert done["complete"]
