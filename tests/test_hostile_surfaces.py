"""Canonical logs whose metadata lies, runs too short to validate, tuning-only campaigns and
impossible vehicle limits: one line each, exit 2 (or 1 for a failed simulation), nothing
written."""

from __future__ import annotations

import json

import pytest

from artic.mjcf.vehicle import resolve_vehicle_path
from artic.validation.cli.commands import main
from artic.validation.logs import consistency
from artic.validation.logs.runfile import Run, write_run
from tests.hostile_logs import docking, slalom


def fails(capsys, *argv, code: int = 2) -> str:
    got = main([str(a) for a in argv])
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert got == code, err
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# ------------------------------------------------------------------ metadata against motion
@pytest.mark.parametrize("make, meta, says", [
    (slalom, {"direction": "reverse"}, "direction 'reverse'"),
    (slalom, {"manoeuvre": "docking", "direction": None}, "manoeuvre 'docking' (which drives "
                                                          "reverse)"),
    (docking, {"direction": "forward"}, "direction 'forward'"),
    (docking, {"manoeuvre": "slalom", "direction": None}, "manoeuvre 'slalom' (which drives "
                                                          "forward)"),
])
def test_metadata_that_contradicts_the_motion_is_refused(capsys, tmp_path, make, meta, says):
    run = make()
    run.meta.update(meta)
    log = write_run(run, tmp_path / "log.parquet")
    out = tmp_path / "val"
    line = fails(capsys, "validate", log, "--models", "kin", "--no-recordings", "--out-dir",
                 out)
    assert f"its metadata says {says}, but the tractor covers only" in line, line
    assert "--accept metadata" in line and str(log) in line
    assert not out.exists() or not any(out.glob("*.csv"))


@pytest.mark.parametrize("key, value, must", [
    ("direction", "sideways", '"forward" or "reverse"'),
    ("sensor_noise", "loud", "an object of channels"),
    ("manoeuvre", 7, "a string"),
])
def test_a_metadata_value_artic_reads_but_cannot_use_is_refused(capsys, tmp_path, key, value,
                                                                 must):
    # direction "sideways" left the log out of every table without a word; sensor_noise
    # "loud" was read as none declared (issue 46, items 4 and 5).
    run = slalom()
    run.meta[key] = value
    log = tmp_path / "log.parquet"
    write_run(run, log)  # written as given: the reader judges it
    out = tmp_path / "val"
    line = fails(capsys, "validate", log, "--models", "kin", "--no-recordings", "--out-dir",
                 out)
    assert line.startswith(f"artic: error: {log}: Parquet metadata"), line
    assert f"metadata {key!r} is {json.dumps(value)}; it must be {must}" in line, line
    assert not out.exists()


def test_metadata_that_agrees_passes_and_the_share_is_the_distances():
    # the docking log pulls forward to set up but reverses for most of its distance
    run = docking()
    assert consistency.check_metadata(run.frame, run.meta) is None
    assert consistency.check_metadata(slalom().frame, slalom().meta) is None
    found = consistency.check_metadata(run.frame, {"direction": "forward"})
    assert found is not None and found.check == "metadata"
    v = run.frame["v_x_1"].to_numpy()
    forward = float((abs(v) * (v > 0)).sum() / abs(v).sum())  # uniform steps: sums suffice
    assert f"covers only {100 * forward:.0f} %" in found.problem


# ------------------------------------------------------------------ runs too short
def test_simulate_refuses_a_run_too_short_to_validate(capsys, tmp_path):
    out = tmp_path / "r.parquet"
    line = fails(capsys, "simulate", "--model", "kin", "--manoeuvre", "slalom", "--duration",
                 "0.001", "--out", out)
    assert "--duration: a run of 0.001 s is too short to validate" in line
    assert "give --duration 1 or more" in line
    assert not out.exists() and not list(tmp_path.iterdir())
    # one second is enough, and read_log takes it
    assert main(["simulate", "--model", "kin", "--manoeuvre", "slalom", "--duration", "1",
                 "--out", str(out)]) == 0
    from artic.validation.logs.importers import read_log

    assert len(read_log(out).frame) == 101


# ------------------------------------------------------------------ campaign and vehicles
@pytest.mark.parametrize("only", ["00-", "00-,01-", "00-constant-steer-unloaded-200deg"])
def test_a_tuning_only_campaign_is_one_line_before_any_work(capsys, tmp_path, only):
    out = tmp_path / "camp"
    line = fails(capsys, "campaign", "--only", only, "--out-dir", out)
    assert f"--only {only}: selects only tuning manoeuvres (00-constant-steer" in line, line
    assert "nothing to validate; add a validation manoeuvre" in line
    assert not out.exists()


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_campaign_without_tuning_manoeuvres_keeps_the_presets(capsys, tmp_path, jobs):
    # artic campaign --only 02- (issue 46, item 1): no tuning log, nothing to fit; it was a
    # ZeroDivisionError (jobs // 0 threads) and, past it, a refusal that --only's help
    # contradicts ("include tuning manoeuvres ... to tune").
    from artic.validation.campaign import main as campaign

    logs = [Run(slalom().frame, {"name": "02-constant-steer-unloaded", "load": "unloaded"})]
    tuned = campaign._tune(tmp_path, logs, ("kin",), "key", jobs)
    assert tuned["complete"] and tuned["loads"] == {}
    assert "unloaded: no tuning manoeuvre among the logs; the preset's parameters are used " \
           "untuned" in capsys.readouterr().err
    vehicles = campaign._tuned_vehicles(tmp_path, tuned, 0)
    assert {v.name for v in vehicles.values()} == {"gosar2022-unloaded", "gosar2022-loaded"}


@pytest.mark.parametrize("key, value, words", [
    ("hitch_pitch", "0.0", "limits.hitch_pitch': must be positive [rad], got 0.0"),
    ("hitch_pitch", "-0.1", "limits.hitch_pitch': must be positive [rad], got -0.1"),
    ("gamma_max", "0.0", "limits.gamma_max': must be positive [rad], got 0.0"),
])
def test_impossible_vehicle_limits_are_one_line(capsys, tmp_path, key, value, words):
    text = resolve_vehicle_path("gosar2022-unloaded").read_text()
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.split("=")[0].strip() == key)
    lines[k] = f"{key} = {value}"
    vfile = tmp_path / "v.toml"
    vfile.write_text("\n".join(lines) + "\n")
    out = tmp_path / "r.parquet"
    line = fails(capsys, "simulate", "--model", "mbd", "--vehicle", vfile, "--manoeuvre",
                 "straight", "--duration", "1", "--out", out)
    assert words in line and str(vfile) in line, line
    assert "range" not in line.split(words)[0]  # not MuJoCo's joint-range message
    assert not out.exists()
