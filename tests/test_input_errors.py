"""Every input mistake ends with exit code 2 and one line naming the file or option.

The triggers of the reliability review: non-finite and out-of-range options,
runs too long for the memory, read-only, full and wrong-type output paths,
header-only CSVs, 0-byte and malformed ``.mat`` files, non-object metadata,
deep TOML nesting, non-UTF-8 files, same-stem imports and an unreachable
Dask scheduler. Nothing is written, and nothing is lost, on the way out.
"""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import scipy.io

from artic.validation.cli.commands import main
from artic.validation.logs.oxts import export_oxts
from artic.validation.logs.runfile import read_run, write_run
from artic.validation.logs.schema import COLUMNS
from artic.validation.plumbing import options
from tests.hostile_logs import slalom


def fails(capsys, *argv: str, code: int = 2) -> str:
    """Run ``artic ARGV``; assert the exit code and one line on stderr, return it."""
    got = main([str(a) for a in argv])
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert got == code, err
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith("artic: error: ") or lines[0].startswith("artic: simulation")
    return lines[0]


SIM = ("simulate", "--model", "kin", "--manoeuvre", "slalom")


@pytest.mark.parametrize("option,value,words", [
    ("--speed-kph", "nan", "argument --speed-kph: expected a finite number [km/h], got 'nan'"),
    ("--speed-kph", "-5", "outside (0, 60] [km/h]"),
    ("--speed-kph", "1e9", "outside (0, 60]"),
    ("--amplitude-deg", "inf", "expected a finite number [deg]"),
    ("--duration", "1e6", "argument --duration: 1e6 is outside (0, 86400] [s]"),
    ("--duration", "0", "outside (0, 86400]"),
    ("--duration", "ten", "expected a number [s], got 'ten'"),
])
def test_option_values(capsys, tmp_path, option, value, words):
    line = fails(capsys, *SIM, "--out", tmp_path / "r.parquet", option, value)
    assert words in line
    assert not (tmp_path / "r.parquet").exists()


@pytest.mark.parametrize("argv,words", [
    (("validate", "x.parquet", "--out-dir", "o", "--gain", "nan"), "argument --gain"),
    (("validate", "x.parquet", "--out-dir", "o", "--jobs", "0"), "argument --jobs"),
    (("campaign", "--seed", "-1"), "argument --seed"),
    (("campaign", "--scheduler-timeout", "inf"), "argument --scheduler-timeout"),
    (("simulate", "--model", "xyz"), "argument --model: invalid choice"),
    (("logs",), "the following arguments are required"),
])
def test_argparse_errors_are_one_line(capsys, argv, words):
    assert words in fails(capsys, *argv)


def test_run_too_long_for_memory(capsys, tmp_path, monkeypatch):
    # The estimate, not a MemoryError half-way: 2 GiB available, 1 KiB per sample.
    monkeypatch.setattr(options, "available_memory", lambda: 2 * 2 ** 30)
    line = fails(capsys, *SIM, "--out", tmp_path / "r.parquet", "--duration", "20000")
    assert "--duration: 2e+06 samples at 100 Hz need about 1.91 GiB" in line
    assert "make it at most 10486 s" in line
    # A near-zero speed makes a slalom last for ever: caught the same way.
    line = fails(capsys, *SIM, "--out", tmp_path / "r.parquet", "--speed-kph", "1e-6")
    assert "--speed-kph 1e-06 and --amplitude-deg 200" in line and "GiB" in line


@pytest.fixture()
def unwritable(tmp_path, monkeypatch):
    """A read-only folder. Root ignores permissions, so for root the system's refusal is
    reproduced where artic meets it: creating a file or folder in there."""
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    if os.geteuid() == 0:
        real_open, real_mkdir = os.open, os.mkdir

        def deny(path) -> bool:
            return Path(os.fsdecode(path)).resolve().is_relative_to(ro.resolve())

        def fake_open(path, flags, mode=0o777, *a, **kw):
            if flags & os.O_CREAT and deny(path):
                raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), os.fsdecode(path))
            return real_open(path, flags, mode, *a, **kw)

        def fake_mkdir(path, mode=0o777, *a, **kw):
            if deny(path):
                raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), os.fsdecode(path))
            return real_mkdir(path, mode, *a, **kw)

        monkeypatch.setattr(os, "open", fake_open)
        monkeypatch.setattr(os, "mkdir", fake_mkdir)
    yield ro
    ro.chmod(0o755)


def test_read_only_output_folder(capsys, unwritable, tmp_path):
    log = write_run(slalom(), tmp_path / "log.parquet")
    for argv in [(*SIM, "--out", unwritable / "r.parquet"),
                 ("validate", log, "--models", "kin", "--out-dir", unwritable / "val"),
                 ("logs", "import", log, "--out-dir", unwritable),
                 ("mjcf", "-o", unwritable / "m.xml"),
                 ("tune", log, "--models", "kin", "--out", unwritable / "t.toml")]:
        line = fails(capsys, *argv)
        assert str(unwritable) in line and "Permission denied" in line, line
    assert list(unwritable.iterdir()) == []


def test_full_disk_loses_nothing(capsys, tmp_path, monkeypatch):
    # The disk fills while the run is written: one line, the old file intact, no temporary.
    out = tmp_path / "r.parquet"
    assert main([*SIM, "--out", str(out), "--duration", "5"]) == 0
    before = out.read_bytes()
    capsys.readouterr()
    class Full(pq.ParquetWriter):  # write_run writes through a ParquetWriter
        def write_table(self, table, *a, **kw):
            super().write_table(table.slice(0, 10), *a, **kw)  # part of it went out
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(self.where))

    monkeypatch.setattr(pq, "ParquetWriter", Full)
    line = fails(capsys, *SIM, "--out", out, "--duration", "6")
    assert "No space left on device" in line and str(tmp_path) in line
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.parquet"]


def test_wrong_type_output_paths(capsys, tmp_path):
    a_file = tmp_path / "file"
    a_file.write_text("x")
    assert "exists and is not a folder" in fails(capsys, "logs", "generate", "--out-dir", a_file)
    assert "is a folder; give a file name" in fails(capsys, *SIM, "--out", tmp_path)
    assert a_file.read_text() == "x"


def test_header_only_csv(capsys, tmp_path):
    canon = tmp_path / "canon.csv"
    canon.write_text(",".join(COLUMNS) + "\n")
    assert "0 sample(s)" in fails(capsys, "logs", "import", canon, "--out-dir", tmp_path / "o")
    export_oxts(slalom(), tmp_path / "exp")
    t = tmp_path / "exp" / "tractor.csv"
    t.write_text(t.read_text().splitlines()[0] + "\n")
    line = fails(capsys, "logs", "import", tmp_path / "exp", "--out-dir", tmp_path / "o")
    assert f"{t}: 0 data row(s) after the header" in line


def test_malformed_mat_files(capsys, tmp_path):
    zero = tmp_path / "zero.mat"
    zero.write_bytes(b"")
    assert f"{zero}: the file is empty (0 bytes)" in fails(
        capsys, "logs", "import", zero, "--out-dir", tmp_path / "o")
    arr = tmp_path / "arr.mat"
    scipy.io.savemat(arr, {"tractor": np.arange(5.0), "trailer": {"Time": np.arange(3.0)},
                           "can": {"Time": np.arange(3.0)}})
    line = fails(capsys, "logs", "import", arr, "--out-dir", tmp_path / "o")
    assert f"{arr}:tractor: expected a scalar struct" in line
    s = np.empty((2,), dtype=[("Time", "O")])
    s[0]["Time"] = s[1]["Time"] = np.arange(3.0)
    sa = tmp_path / "sa.mat"
    scipy.io.savemat(sa, {"tractor": s, "trailer": s, "can": s})
    assert "a struct array of 2 elements" in fails(capsys, "logs", "import", sa,
                                                   "--out-dir", tmp_path / "o")
    field = tmp_path / "field.mat"
    scipy.io.savemat(field, {"tractor": {"Time": "text"}, "trailer": {"Time": np.arange(3.0)},
                             "can": {"Time": np.arange(3.0)}})
    assert "field Time: expected a numeric vector" in fails(
        capsys, "logs", "import", field, "--out-dir", tmp_path / "o")
    assert not (tmp_path / "o").exists() or list((tmp_path / "o").iterdir()) == []


def test_non_object_metadata(capsys, tmp_path):
    export_oxts(slalom(), tmp_path / "exp")
    (tmp_path / "exp" / "meta.json").write_text("[1, 2, 3]")
    line = fails(capsys, "logs", "import", tmp_path / "exp", "--out-dir", tmp_path / "o")
    assert "meta.json: expected a JSON object of run metadata" in line
    (tmp_path / "exp" / "meta.json").write_bytes(b'{"manoeuvre": "\xff"}')
    assert "meta.json: not UTF-8 text" in fails(capsys, "logs", "import", tmp_path / "exp",
                                                "--out-dir", tmp_path / "o")
    (tmp_path / "exp" / "meta.json").write_text("[" * 100_000)
    assert "meta.json: " in fails(capsys, "logs", "import", tmp_path / "exp",
                                  "--out-dir", tmp_path / "o")
    # Parquet metadata that is JSON but not an object.
    p = write_run(slalom(), tmp_path / "log.parquet")
    table = pq.read_table(p)
    pq.write_table(table.replace_schema_metadata({b"artic": b'"a string"'}), p)
    line = fails(capsys, "validate", p, "--out-dir", tmp_path / "v")
    assert f"{p}: Parquet metadata 'artic': expected a JSON object" in line


def test_deep_toml_and_non_utf8_vehicle_files(capsys, tmp_path):
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * 5000 + "]" * 5000 + "\n")
    assert f"{deep}: not valid TOML: nested too deeply" in fails(capsys, "vehicle", "show", deep)
    latin = tmp_path / "latin.toml"
    latin.write_bytes("[vehicle]\nname = 'Köln'\n".encode("latin-1"))
    assert f"{latin}: not UTF-8 text" in fails(capsys, "vehicle", "show", latin)
    csv = tmp_path / "latin.csv"
    csv.write_bytes(b"t,caf\xe9\n1,2\n")
    assert f"{csv}: not UTF-8 text" in fails(capsys, "logs", "import", csv, "--out-dir",
                                            tmp_path / "o")


def test_same_stem_import_is_refused_before_writing(capsys, tmp_path):
    for d in ("a", "b"):
        write_run(slalom(), tmp_path / d / "run.parquet")
    out = tmp_path / "out"
    line = fails(capsys, "logs", "import", tmp_path / "a" / "run.parquet",
                 tmp_path / "b" / "run.parquet", "--out-dir", out)
    assert "would both be written as" in line and "run.parquet" in line
    assert not (out / "run.parquet").exists()
    # Distinct stems import side by side.
    write_run(slalom(), tmp_path / "b" / "run2.parquet")
    assert main(["logs", "import", str(tmp_path / "a" / "run.parquet"),
                 str(tmp_path / "b" / "run2.parquet"), "--out-dir", str(out)]) == 0
    assert {p.name for p in out.glob("*.parquet")} == {"run.parquet", "run2.parquet"}
    assert read_run(out / "run.parquet").meta["name"] == "run"


def test_unreachable_scheduler(capsys, tmp_path):
    pytest.importorskip("distributed")
    line = fails(capsys, "campaign", "--out-dir", tmp_path / "c", "--executor", "dask",
                 "--scheduler", "tcp://127.0.0.1:9", "--scheduler-timeout", "1")
    assert "--scheduler tcp://127.0.0.1:9: not reached within 1 s" in line
    assert "a tls:// scheduler needs --tls-ca-file" in fails(
        capsys, "campaign", "--out-dir", tmp_path / "c", "--executor", "dask",
        "--scheduler", "tls://127.0.0.1:9")
    assert "need a tls:// --scheduler" in fails(
        capsys, "campaign", "--out-dir", tmp_path / "c", "--tls-ca-file", tmp_path / "x")


def test_vehicle_show_json_is_strict_json(capsys):
    assert main(["vehicle", "show", "six-axle", "--json"]) == 0

    def refuse(name):
        raise AssertionError(f"{name} in JSON output")

    flat = json.loads(capsys.readouterr().out, parse_constant=refuse)
    assert flat["L1"] == pytest.approx(3.7)


def test_parquet_that_is_not_parquet(capsys, tmp_path):
    p = tmp_path / "x.parquet"
    p.write_bytes(b"PAR1 not really")
    assert "not a readable Parquet file" in fails(capsys, "validate", p, "--out-dir",
                                                  tmp_path / "o")
    q = tmp_path / "strings.parquet"
    pq.write_table(pa.table({c: ["a", "b"] for c in COLUMNS}), q)
    assert f"{q}: column t: holds" in fails(capsys, "validate", q, "--out-dir", tmp_path / "o")


@pytest.mark.parametrize("column", ["t", "x_1"])
def test_canonical_parquet_with_text_columns_is_refused_at_import(capsys, tmp_path, column):
    # Numbers written as text: every value parses, but the column is not numbers. It was
    # accepted by `logs import` and ended `validate` in a TypeError.
    run = slalom()
    run.frame[column] = run.frame[column].map(repr)
    p = write_run(run, tmp_path / "text.parquet")
    line = fails(capsys, "logs", "import", p, "--out-dir", tmp_path / "o")
    assert f"{p}: column {column}: holds" in line and "not numbers" in line
    assert not (tmp_path / "o" / "text.parquet").exists()
    assert f"column {column}: holds" in fails(capsys, "validate", p, "--out-dir", tmp_path / "v")


@pytest.mark.parametrize("column,change,words", [
    ("x_1", lambda f: f.assign(x_1=f["x_1"] + 1e15, x_2=f["x_2"] + 1e15),
     "column x_1: 1e+15 m is beyond 1e+07 m"),
    ("y_2", lambda f: f.assign(y_2=f["y_2"] - 3e7), "column y_2: 3e+07 m is beyond"),
    ("psi_1", lambda f: f.assign(psi_1=f["psi_1"] + 2e9 * np.pi, psi_2=f["psi_2"] + 2e9 * np.pi),
     "column psi_1: 6.283e+09 rad at the start is beyond 1000 rad"),
    ("psi_2", lambda f: f.assign(psi_2=f["psi_2"] * 1e3, psi_1=f["psi_1"] * 1e3,
                                 gamma=0.0 * f["gamma"]), "column psi_1: turns"),
    ("t", lambda f: f.assign(t=f["t"] + 1e15), "column t: 1e+15 s is beyond 1e+10 s"),
])
def test_canonical_parquet_of_absurd_size_is_refused_at_import(capsys, tmp_path, column,
                                                               change, words):
    # Positions 1e15 m off, headings of absurd size: validated without a word before.
    from artic.mjcf.interface import wrap_angle

    run = slalom()
    f = change(run.frame)
    f["gamma"] = wrap_angle(f["psi_1"].to_numpy() - f["psi_2"].to_numpy())
    p = write_run(type(run)(f, run.meta), tmp_path / "absurd.parquet")
    line = fails(capsys, "logs", "import", p, "--out-dir", tmp_path / "o")
    assert str(p) in line and words in line, line


def test_an_empty_output_path_is_refused_not_the_current_folder(capsys, tmp_path, monkeypatch):
    # Path("") is ".": an unset shell variable would write into the working folder.
    monkeypatch.chdir(tmp_path)
    for argv in (("dock", "--scenario", "straight", "--seeds", "1", "--out-dir", ""),
                 ("logs", "generate", "--out-dir", " "),
                 (*SIM, "--out", "")):
        assert "no path given; name a folder or file" in fails(capsys, *argv)
    assert list(tmp_path.iterdir()) == []


def test_a_refused_command_leaves_no_folder_behind(capsys, tmp_path, monkeypatch):
    import importlib.util

    bad = tmp_path / "bad.csv"
    bad.write_text("t,x\n")
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "distributed" else real(name, *a))
    cases = [
        (("logs", "import", tmp_path / "nothere", "--out-dir", tmp_path / "o1"),
         f"{tmp_path / 'nothere'}: no such file or folder"),
        (("logs", "import", bad, "--out-dir", tmp_path / "o2"), "bad.csv"),
        (("validate", tmp_path / "nope.parquet", "--models", "kin", "--out-dir",
          tmp_path / "o3"), "nope.parquet"),
        (("logs", "generate", "--only", "zz-", "--out-dir", tmp_path / "o4"),
         "--only: no manoeuvre matches zz-"),
        (("campaign", "--only", "zz-", "--out-dir", tmp_path / "o5"),
         "--only: no manoeuvre matches zz-"),
        (("dock", "--sweep", "friction=1,0.6", "--executor", "dask", "--scenario", "straight",
          "--seeds", "1", "--no-recordings", "--out-dir", tmp_path / "o6"),
         "needs the 'distributed' package"),
    ]
    for argv, words in cases:
        assert words in fails(capsys, *argv), argv
    # Every input is checked before the output folder is made: none was.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv"]


def test_an_integer_option_s_bounds_are_integers(capsys, tmp_path):
    line = fails(capsys, "logs", "generate", "--seed", "-1", "--out-dir", tmp_path / "g")
    assert "argument --seed: -1 is outside [0, 9223372036854775807];" in line


@pytest.mark.parametrize("argv", [
    ["simulate", "--model", "kin", "--manoeuvre", "slalom", "--duration", "1", "--out"],
    ["mjcf", "--vehicle", "gosar2022-unloaded", "-o"],
])
def test_an_output_file_in_a_missing_folder_is_refused_not_made(capsys, tmp_path, argv):
    # artic simulate --out /nonexistent/x.parquet made /nonexistent (issue 46, item 17).
    target = tmp_path / "no" / "such" / "x.out"
    flag = argv[-1]
    line = fails(capsys, *argv, target)
    assert line == (f"artic: error: {flag} {target}: the folder {target.parent} does not "
                    "exist; make it first, or give a file in a folder that does"), line
    assert not (tmp_path / "no").exists()
