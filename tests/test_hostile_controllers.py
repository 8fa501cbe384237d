"""Controllers that misbehave: nothing they do ends ``artic dock`` silently.

Each controller is a module written here, as a user's would be, and run
through the command line: an import failure is one line naming the module and
the error; an exit, a crash or a hang fails its run (a row with the reason)
and the benchmark goes on to write ``dock.csv``; a controller slower than its
sample period fails the real-time criterion unless ``--no-realtime``.
"""

from __future__ import annotations

import io
import textwrap
import warnings
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import pandas as pd
import pytest

from artic.validation.cli.commands import main
from artic.validation.docking import supervise
from artic.validation.docking.scores import COLUMNS

VEHICLE = "gosar2022-unloaded"

USER_CONTROLLER = (Path(__file__).resolve().parents[1] / "docs" / "guide" / "docking.md"
                   ).read_text().split("```python\n", 1)[1].split("```", 1)[0]
"""The docking guide's controller (``Proportional``), which docks the straight start."""

MISBEHAVING = USER_CONTROLLER + textwrap.dedent('''

    import os
    import sys
    import time


    class Exits(Proportional):
        def command(self, obs):
            if obs.t > 0.25:
                sys.exit(3)
            return super().command(obs)


    class OsExit(Proportional):
        def command(self, obs):
            if obs.t > 0.25:
                os._exit(7)
            return super().command(obs)


    class Killed(Proportional):
        """Ends as a crash in compiled code would: by a signal, with no word."""

        def command(self, obs):
            if obs.t > 0.25:
                import signal
                os.kill(os.getpid(), signal.SIGKILL)
            return super().command(obs)


    class Hangs(Proportional):
        def command(self, obs):
            if obs.t > 0.25:
                time.sleep(3600)
            return super().command(obs)


    class Slow(Proportional):
        """Late (0.15 s against the 0.1 s period) on its second to sixth commands."""

        def command(self, obs):
            if 0.05 < obs.t < 0.55:
                time.sleep(0.15)
            return super().command(obs)
''')


def artic(*argv) -> tuple[int, str, str]:
    """Exit code, stdout, stderr, with any Python warning appended to stderr."""
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err), warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue() + "".join(f"{x.category.__name__}: "
                                                          f"{x.message}\n" for x in w)


@pytest.fixture
def user_module(tmp_path, monkeypatch):
    """``misbehaving.py`` on ``sys.path``; returns a writer of further modules."""
    monkeypatch.syspath_prepend(str(tmp_path))
    (tmp_path / "misbehaving.py").write_text(MISBEHAVING)

    def write(name: str, text: str) -> str:
        (tmp_path / f"{name}.py").write_text(textwrap.dedent(text))
        return name

    return write


def dock(tmp_path, controllers: str, *extra) -> tuple[int, str, str, Path]:
    out = tmp_path / "out"
    code, so, se = artic("dock", "--scenario", "straight", "--vehicle", VEHICLE, "--controller",
                         controllers, "--seeds", "1", "--no-recordings", "--out-dir", out,
                         *extra)
    return code, so, se, out


def one_line(code: int, err: str) -> str:
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("artic: error: "), err
    return lines[0]


@pytest.mark.parametrize("jobs", ["1", "2"])
@pytest.mark.parametrize("body, what", [
    ("def broken(:\n    pass\n", "SyntaxError"),
    ("raise RuntimeError('no licence for the solver')\n", "RuntimeError: no licence"),
    ("import sys\nsys.exit(4)\n", "SystemExit: 4"),
])
def test_a_controller_that_fails_at_import_is_one_line(tmp_path, user_module, body, what, jobs):
    name = user_module("bad_import", body)
    code, _, err, out = dock(tmp_path, f"{name}:C", "--jobs", jobs)
    line = one_line(code, err)
    assert "importing module 'bad_import' failed" in line and what in line, line
    assert "bad_import.py" in line  # where
    assert not out.exists()


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_exit_crash_and_hang_are_failed_rows_and_the_benchmark_completes(
        tmp_path, user_module, monkeypatch, jobs):
    monkeypatch.setattr(supervise, "CALL_DEADLINE", 3.0)  # the hang is judged after 3 s
    code, so, err, out = dock(
        tmp_path, "misbehaving:Exits,misbehaving:OsExit,misbehaving:Killed,misbehaving:Hangs,"
        "misbehaving:Proportional", "--jobs", jobs)
    assert code == 0, err
    rows = pd.read_csv(out / "dock.csv", keep_default_na=False)
    assert list(rows.columns) == list(COLUMNS)
    rows = rows.set_index("controller")
    assert len(rows) == 5
    assert "controller error: SystemExit: 3" in rows.loc["misbehaving:Exits", "failure"]
    assert "exit code 7" in rows.loc["misbehaving:OsExit", "failure"]
    assert "killed by signal SIGKILL" in rows.loc["misbehaving:Killed", "failure"]
    assert rows.loc["misbehaving:Hangs", "failure"] == (
        "controller hang: command() at t = 0.3 s did not return within 3 s")
    assert not any(rows.loc[c, "success"] for c in ("misbehaving:Exits", "misbehaving:OsExit",
                                                    "misbehaving:Killed", "misbehaving:Hangs"))
    assert rows.loc["misbehaving:Proportional", "success"] in (True, "True")  # went on
    assert "1 of 5 runs docked" in so
    assert "Traceback" not in err and "All-NaN" not in err


def test_a_slow_controller_fails_the_real_time_criterion_unless_told(tmp_path, user_module):
    code, _, err, out = dock(tmp_path, "misbehaving:Slow", "--jobs", "1")
    assert code == 1, err  # no run docked: the tables are written, and the exit says so
    row = pd.read_csv(out / "dock.csv", keep_default_na=False).iloc[0]
    assert not row["success"] and row["failure"].startswith("not real-time: 4 of 4 commands")
    assert row["late_commands"] == 4
    assert "Warning" not in err  # the all-failed table drew no stray All-NaN warning
    assert "artic: warning: controller misbehaving:Slow: 4 command(s) in 1 run(s) took " \
           "longer than the 0.1 s sample period" in err
    code, _, err, out = dock(tmp_path, "misbehaving:Slow", "--jobs", "1", "--no-realtime")
    assert code == 0, err
    row = pd.read_csv(out / "dock.csv", keep_default_na=False).iloc[0]
    assert row["success"], row["failure"]  # it docks; only the criterion was waived
    assert row["late_commands"] == 5
    assert "counted only (--no-realtime)" in err
    assert "Warning" not in err  # no stray warning (an all-failed table had two)


@pytest.mark.parametrize("option, value, named", [
    ("--scenario", "straight,straight", "straight named twice"),
    ("--controller", "reference,reference", "reference named twice"),
    ("--vehicle", f"{VEHICLE},{VEHICLE}", f"{VEHICLE} named twice"),
])
def test_a_name_given_twice_is_refused(tmp_path, option, value, named):
    args = {"--scenario": "straight", "--controller": "reference", "--vehicle": VEHICLE,
            option: value}
    out = tmp_path / "out"
    line = one_line(*artic("dock", *[x for kv in args.items() for x in kv], "--seeds", "1",
                           "--out-dir", out)[::2])
    assert option in line and named in line, line
    assert not out.exists()


def test_a_controller_and_its_module_path_are_one(tmp_path):
    line = one_line(*artic("dock", "--scenario", "straight", "--vehicle", VEHICLE,
                           "--controller", "reference,artic.validation.docking.controllers."
                           "reference:ReferenceController", "--seeds", "1", "--out-dir",
                           tmp_path / "out")[::2])
    assert "named twice" in line


def test_stale_temporaries_and_recordings_of_other_runs_are_removed(tmp_path, user_module):
    out = tmp_path / "out"
    rec = out / "recordings"
    rec.mkdir(parents=True)
    stale = [rec / ".straight-x-0.rrd.4242.tmp", out / ".dock.csv.abcd.part"]
    for p in stale:
        p.write_bytes(b"half a file")
    other = rec / "bay-gosar2022-unloaded-reference-3.rrd"  # not in the new table
    other.write_bytes(b"an earlier benchmark's")
    code, _, err = artic("dock", "--scenario", "straight", "--vehicle", VEHICLE, "--controller",
                         "misbehaving:Exits", "--seeds", "1", "--jobs", "1", "--out-dir", out)
    assert code == 1, err  # its one run failed
    assert not any(p.exists() for p in stale) and not other.exists()
    assert "removed 2 temporary file(s)" in err
    assert f"removed 1 recording(s) in {rec} of runs that dock.csv does not list" in err
    assert sorted(p.name for p in rec.iterdir()) == [
        "straight-gosar2022-unloaded-misbehaving_Exits-0.rrd"]


# ------------------------------------------------------------------ issue 46, items 3, 11, 12
FAILS_IN_RESET = """
from artic.validation.docking.controllers import Controller


class FailsInReset(Controller):
    def reset(self, task):
        raise RuntimeError("no licence for the solver")

    def command(self, obs):
        raise AssertionError("never called")
"""


def test_a_controller_failing_in_reset_is_reported_with_its_reason_and_recording(
        tmp_path, user_module):
    # With recordings on (the default) the reason was "ValueError: cannot convert float NaN
    # to integer": the recording's sampling took the median of an empty time step array.
    name = user_module("fails_in_reset", FAILS_IN_RESET)
    out = tmp_path / "out"
    code, so, err = artic("dock", "--scenario", "straight", "--vehicle", VEHICLE,
                          "--controller", f"{name}:FailsInReset", "--seeds", "1", "--jobs", "1",
                          "--out-dir", out)
    row = pd.read_csv(out / "dock.csv", keep_default_na=False).iloc[0]
    assert row["failure"] == "controller error: RuntimeError: no licence for the solver"
    assert (out / "recordings" / f"straight-{VEHICLE}-{name}_FailsInReset-0.rrd").is_file()
    # Nothing docked: exit 1 with one line naming the first failure, after the tables.
    assert code == 1 and "0 of 1 runs docked" in so, err
    assert err.strip().splitlines()[-1] == (
        "artic: error: none of the 1 run(s) docked (first: controller error: RuntimeError: no "
        f"licence for the solver); see {out / 'dock.csv'}")
    assert (out / "dock_table.md").is_file()


def test_a_recording_that_cannot_be_written_is_an_output_error_not_a_failed_run(
        tmp_path, monkeypatch):
    import errno

    from artic.validation.review import recording

    def full_disk(path, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(recording, "record_docking", full_disk)  # the workers are forked
    out = tmp_path / "out"
    code, so, err = artic("dock", "--scenario", "straight", "--vehicle", VEHICLE,
                          "--controller", "reference", "--seeds", "1", "--jobs", "1",
                          "--out-dir", out)
    row = pd.read_csv(out / "dock.csv", keep_default_na=False).iloc[0]
    assert row["success"] in (True, "True"), row["failure"]  # the run docked: it says so
    assert "1 of 1 runs docked" in so
    assert code == 1, err  # but the recording it was asked for is not there
    line = err.strip().splitlines()[-1]
    assert line.startswith("artic: error: 1 of 1 recording(s) not written (first: "), line
    assert "No space left on device" in line and "give --no-recordings" in line
    assert not any(out.glob("recordings/*.rrd"))


@pytest.mark.parametrize("controller", ["mpc-kin", "mpc-stm"])
def test_the_mpcs_without_casadi_are_refused_before_any_run(tmp_path, monkeypatch, controller):
    import sys

    monkeypatch.setitem(sys.modules, "casadi", None)  # as if not installed: find_spec is None
    out = tmp_path / "out"
    code, _, err = artic("dock", "--scenario", "straight", "--vehicle", VEHICLE, "--controller",
                         f"reference,{controller}", "--seeds", "1", "--out-dir", out)
    line = one_line(code, err)
    assert line == (f"artic: error: --controller '{controller}': needs casadi, which is not "
                    'installed: pip install "artic[mpc]"'), line
    assert not out.exists()  # not even the reference's runs started


def test_a_preset_the_plant_cannot_be_built_for_is_marked_and_refused(tmp_path):
    code, listing, err = artic("dock", "--list")
    assert code == 0, err
    marked = [x for x in listing.splitlines() if "cannot dock" in x]
    assert [x.split()[0] for x in marked] == ["scale-model-1to14"], listing
    assert "has no tyre file; the plant needs one" in marked[0]
    out = tmp_path / "out"
    code, _, err = artic("dock", "--scenario", "straight", "--vehicle",
                         f"{VEHICLE},scale-model-1to14", "--seeds", "1", "--out-dir", out)
    line = one_line(code, err)
    assert "scale-model-1to14" in line and "has no tyre file" in line, line
    # the advice is one artic dock has (it once said "use --models kin")
    assert "--models" not in line and line.endswith("(artic dock --list marks the presets that "
                                                    "cannot dock)"), line
    assert not out.exists()
