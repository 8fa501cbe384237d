"""The artic command line: the forms others script against."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from artic.validation.cli.commands import main
from artic.validation.criteria.metrics import CRITERIA
from artic.validation.logs.runfile import read_run
from artic.validation.logs.schema import COLUMNS


def test_vehicle_show_json(capsys):
    assert main(["vehicle", "show", "gosar2022-loaded", "--json"]) == 0
    flat = json.loads(capsys.readouterr().out)
    assert flat["L1"] == pytest.approx(3.8) and flat["Lc"] == pytest.approx(2.04)
    assert flat["a2"] == 5.19 and flat["Fz2"] == pytest.approx(67100, rel=0.02)
    assert flat["L23"] == pytest.approx(8.8)


def test_vehicle_keys(capsys):
    assert main(["vehicle", "keys"]) == 0
    out = capsys.readouterr().out
    assert "delta_h_offset" in out and "[rad]" in out
    # Every description starts in one column, after the longest key and two spaces.
    rows = [line for line in out.splitlines() if line.startswith("  ")]
    starts = {len(line) - len(line[2:].split(None, 1)[1]) for line in rows}
    assert len(starts) == 1
    assert "suspension_stiffness  vertical rate" in out


@pytest.mark.parametrize("model", ["kin", "stm"])
def test_simulate_writes_schema(tmp_path, model, capsys):
    out = tmp_path / "run.parquet"
    assert main(["simulate", "--model", model, "--vehicle", "six-axle", "--manoeuvre",
                 "slalom", "--amplitude-deg", "200", "--speed-kph", "5", "--duration", "20",
                 "--out", str(out)]) == 0
    run = read_run(out)
    assert set(COLUMNS) | {"delta"} <= set(run.frame.columns)
    assert len(run.frame) == 2001
    assert run.meta["manoeuvre"] == "slalom" and run.meta["model"] == model


def test_simulate_reverse_stops_at_jackknife(tmp_path, capsys):
    out = tmp_path / "rev.parquet"
    assert main(["simulate", "--model", "kin", "--manoeuvre", "ramp-steer-reverse",
                 "--speed-kph", "6", "--duration", "300", "--out", str(out)]) == 0
    assert "jackknife" in capsys.readouterr().out
    assert read_run(out).meta["status"].startswith("stopped")


def constant_steer_logs(tmp_path) -> list[str]:
    """Two 20 s STM constant steers, left and right, written by ``artic simulate``."""
    logs = []
    for side in ("left", "right"):
        p = tmp_path / f"{side}.parquet"
        main(["simulate", "--model", "stm", "--manoeuvre", "constant-steer", "--side", side,
              "--duration", "20", "--out", str(p)])
        logs.append(str(p))
    return logs


def test_validate_writes_metrics_and_runs(tmp_path, capsys):
    logs = constant_steer_logs(tmp_path)
    out = tmp_path / "val"
    assert main(["validate", *logs, "--models", "KIN,stm", "--gain", "3",
                 "--out-dir", str(out)]) == 0
    # Recordings by default, one per log, for the user's own logs too.
    assert sorted(p.name for p in (out / "recordings").glob("*.rrd")) == \
        sorted(f"{Path(p).stem}.rrd" for p in logs)
    assert main(["validate", *logs, "--models", "kin", "--no-recordings",
                 "--out-dir", str(tmp_path / "quiet")]) == 0
    assert not (tmp_path / "quiet" / "recordings").exists()
    m = pd.read_csv(out / "metrics.csv")
    assert list(m.columns[:2]) == ["log", "model"]
    assert set(CRITERIA) <= set(m.columns)
    assert len(m) == 4 and sorted(m.model.unique()) == ["kin", "stm"]
    assert len(list((out / "runs").glob("*.parquet"))) == 4
    # The STM replays its own log; KIN misses by its lack of tyre slip.
    stm = m[m.model == "stm"]
    assert (stm.eps_y1 < 1e-6).all() and (m[m.model == "kin"].eps_y1 > 1e-3).all()


def test_user_errors_exit_2_with_message(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("[vehicle]\nname = 1\n")
    assert main(["vehicle", "show", str(bad)]) == 2
    err = capsys.readouterr().err
    assert str(bad) in err and "Traceback" not in err
    assert main(["validate", str(tmp_path / "none.parquet"), "--out-dir", str(tmp_path)]) == 2
    assert "no such file" in capsys.readouterr().err
    assert main(["validate", str(bad), "--models", "kin,abc", "--out-dir", str(tmp_path)]) == 2
    assert "unknown model" in capsys.readouterr().err
    # The option is named, and a near miss gets its likely meaning.
    assert main(["campaign", "--models", "kin,STN", "--out-dir", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err
    assert "--models: unknown model 'STN'; choose from kin, stm, mbd" in err
    assert "did you mean stm?" in err and len(err.strip().splitlines()) == 1


def test_validate_refuses_duplicate_log_names(tmp_path, capsys):
    from artic.mjcf import load_vehicle
    from artic.validation.runs.validate import validate_runs
    from tests.helpers import straight_log

    with pytest.raises(ValueError, match="share the name"):
        validate_runs([straight_log(), straight_log()], load_vehicle("six-axle"), ["kin"])


def test_tune_writes_a_vehicle_file_the_other_commands_accept(tmp_path, capsys):
    logs = constant_steer_logs(tmp_path)
    out = tmp_path / "tuned.toml"
    assert main(["tune", *logs, "--models", "kin", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "kin    i_s" in text and "eps_n before" in text and f"wrote {out}" in text
    assert main(["vehicle", "show", str(out)]) == 0
    assert "i_s_kin" in capsys.readouterr().out
    assert main(["validate", *logs, "--vehicle", str(out), "--models", "kin",
                 "--out-dir", str(tmp_path / "val")]) == 0
    assert (tmp_path / "val" / "table2_forward.md").is_file()
    # Reverse logs are refused: tuning is on forward manoeuvres.
    rev = tmp_path / "rev.parquet"
    main(["simulate", "--model", "kin", "--manoeuvre", "ramp-steer-reverse", "--duration", "10",
          "--out", str(rev)])
    assert main(["tune", str(rev), "--out", str(tmp_path / "x.toml")]) == 2
    assert "forward" in capsys.readouterr().err and not (tmp_path / "x.toml").exists()


def test_validate_gain_sweep_marks_the_bound(tmp_path, capsys):
    rev = tmp_path / "rev.parquet"
    main(["simulate", "--model", "stm", "--manoeuvre", "ramp-steer-reverse",
          "--amplitude-deg", "30", "--duration", "15", "--out", str(rev)])
    out = tmp_path / "val"
    assert main(["validate", str(rev), "--models", "kin", "--gain-sweep",
                 "--out-dir", str(out)]) == 0
    text = capsys.readouterr().out
    assert "K_min" in text and "| bound |" in text
    sweep = pd.read_csv(out / "gain_sweep.csv")
    assert len(sweep) == 12 and (out / "gain_sweep.png").is_file()
    assert (out / "table3_reverse.csv").is_file()


def test_version_names_the_installed_release(capsys):
    from importlib.metadata import version

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"artic {version('artic')}"


def test_every_option_of_every_command_says_what_it_is():
    # Some simulate options had no description or default in --help, and dock --help did not
    # say --out-dir is required (issue 46, item 19).
    import argparse

    from artic.validation.cli.commands import build_parser

    bare = []

    def walk(parser, path):
        for a in parser._actions:
            if isinstance(a, argparse._SubParsersAction):
                for name, sub in a.choices.items():
                    walk(sub, [*path, name])
            elif a.dest != "help" and not (a.help or "").strip():
                bare.append(f"{' '.join(path)} {'/'.join(a.option_strings) or a.dest}")
            elif a.default not in (None, False, "", argparse.SUPPRESS, []) \
                    and not a.required and "default" not in a.help and a.option_strings:
                bare.append(f"{' '.join(path)} {a.option_strings[0]}: no default in its help")

    walk(build_parser(), ["artic"])
    assert not bare, bare
    dock = next(a for a in build_parser()._subparsers._group_actions[0].choices["dock"]._actions
                if "--out-dir" in a.option_strings)
    assert "required" in dock.help
