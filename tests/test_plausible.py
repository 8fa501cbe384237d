"""Plausibility of vehicle and tyre files: the impossible refused, the unusual warned, by key."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.plausible import VEHICLE_RANGES, PlausibilityWarning
from artic.mjcf.schema import VehicleFileError
from artic.mjcf.tir import COEFFICIENT_RANGES, TirError, read_tir
from artic.validation.cli.commands import main

PRESET = Path(load_vehicle("gosar2022-unloaded").path)
TYRE = Path(load_vehicle("gosar2022-unloaded").tyre_file)


def vehicle_file(tmp_path: Path, old: str, new: str, tyre: str | None = None) -> Path:
    text = PRESET.read_text()
    assert re.search(old, text, flags=re.M), old
    text = re.sub(old, new, text, count=1, flags=re.M)
    if tyre is not None:
        (tmp_path / "t.tir").write_text(tyre)
        text = text.replace('file = "artic-truck-315-80R22.5.tir"', 'file = "t.tir"')
    p = tmp_path / "v.toml"
    p.write_text(text)
    return p


def tyre_with(old: str, new: str) -> str:
    text = TYRE.read_text(encoding="latin-1")
    assert re.search(old, text, flags=re.M), old
    return re.sub(old, new, text, count=1, flags=re.M)


def test_presets_and_shipped_tyre_are_plausible():
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        for name in ("gosar2022-unloaded", "gosar2022-loaded", "six-axle", "scale-model-1to14"):
            load_vehicle(name)
        read_tir(TYRE)


@pytest.mark.parametrize("old,new,key", [
    (r"^h2 = 1.3 ", "h2 = 100.0 ", "trailer.h2"),  # the review's 100 m centre of gravity
    (r"^m1 = 8060.0 ", "m1 = 2.0 ", "tractor.m1"),
    (r"^J2 = 34613.0 ", "J2 = 1e9 ", "trailer.J2"),
    (r"^i_s = 21.0 ", "i_s = 0.001 ", "steering.i_s"),
    (r"^track = 2.05", "track = 20.5", "tractor.axle 'front'.track"),
    (r"^suspension_stiffness = 600000.0", "suspension_stiffness = 1e12",
     "tractor.axle 'front'.suspension_stiffness"),
])
def test_impossible_values_are_refused_naming_the_key(tmp_path, old, new, key):
    p = vehicle_file(tmp_path, old, new)
    with pytest.raises(VehicleFileError, match=re.escape(f"{p}: key '{key}'")) as err:
        load_vehicle(p)
    assert "impossible for a tractor-semitrailer" in str(err.value)


def test_non_finite_values_are_refused(tmp_path):
    p = vehicle_file(tmp_path, r"^sensor = \[3.825", "sensor = [nan")
    with pytest.raises(VehicleFileError, match="key 'tractor.sensor': expected three finite"):
        load_vehicle(p)
    p = vehicle_file(tmp_path, r"^m2 = 7100.0 ", "m2 = inf ")
    with pytest.raises(VehicleFileError, match="key 'trailer.m2': expected a finite number"):
        load_vehicle(p)


def test_unusual_values_are_warned_naming_the_key(tmp_path):
    p = vehicle_file(tmp_path, r"^h2 = 1.3 ", "h2 = 3.0 ")
    with pytest.warns(PlausibilityWarning, match=r"key 'trailer.h2': 3 m is unusual "
                                                 r"\(usual: 0.5 to 2.6 m\)"):
        load_vehicle(p)


def test_cli_warning_is_one_line(tmp_path, capsys):
    import sys

    p = vehicle_file(tmp_path, r"^h2 = 1.3 ", "h2 = 3.0 ")
    with warnings.catch_warnings():
        # As outside pytest, which records warnings instead of showing them.
        warnings.simplefilter("always")
        warnings.showwarning = lambda m, c, f, n, file=None, line=None: sys.stderr.write(
            warnings.formatwarning(m, c, f, n, line))
        assert main(["vehicle", "show", str(p)]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("artic: warning: ") and "trailer.h2" in err[0]


@pytest.mark.filterwarnings("ignore::artic.mjcf.plausible.PlausibilityWarning")
@pytest.mark.parametrize("old,new,words", [
    (r"^PTY1 .*$", "PTY1 = 0.0", "key PTY1: 0 is impossible"),
    (r"^FNOMIN .*$", "FNOMIN = nan", "key FNOMIN: nan is not a finite number"),
    (r"^PDY1 .*$", "PDY1 = 40.0", "key PDY1: 40 is impossible"),
    (r"^UNLOADED_RADIUS .*$", "UNLOADED_RADIUS = -0.5",
     "key UNLOADED_RADIUS: -0.5 m is impossible"),
    (r"^FZMIN .*$", "FZMIN = 95000", "keys FZMIN, FZMAX: FZMIN = 95000 must be below"),
    (r"^PKY1 .*$", "PKY1 = 0.0", "key PKY1: must not be zero"),
])
def test_impossible_tyre_coefficients_are_file_and_key_errors(tmp_path, capsys, old, new,
                                                               words):
    p = vehicle_file(tmp_path, "^$", "", tyre=tyre_with(old, new))
    with pytest.raises(VehicleFileError) as err:
        load_vehicle(p)
    msg = str(err.value)
    assert msg.startswith(f"{p}: key 'tyre.file': {tmp_path / 't.tir'}") and words in msg
    # The plant's run ends with exit 2 and that line, not with a divergence (exit 1).
    assert main(["simulate", "--model", "mbd", "--vehicle", str(p), "--manoeuvre", "straight",
                 "--duration", "1", "--out", str(tmp_path / "r.parquet")]) == 2
    assert words in capsys.readouterr().err


def test_unusual_tyre_coefficient_is_warned(tmp_path):
    with pytest.warns(PlausibilityWarning, match="key PDY1: 2 is unusual"):
        read_tir_text(tmp_path, tyre_with(r"^PDY1 .*$", "PDY1 = 2.0"))


def read_tir_text(tmp_path: Path, text: str):
    p = tmp_path / "x.tir"
    p.write_text(text)
    return read_tir(p)


def test_tyre_file_must_be_a_tir_and_is_never_echoed(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("root:SECRET-HASH:0:0\n")
    p = vehicle_file(tmp_path, r'^file = "artic-truck-315-80R22.5.tir"',
                     f'file = "{secret}"')
    with pytest.raises(VehicleFileError, match="is not a .tir file") as err:
        load_vehicle(p)
    assert "SECRET" not in str(err.value)
    fake = tmp_path / "fake.tir"
    fake.write_text("root:SECRET-HASH:0:0\n")
    with pytest.raises(TirError, match=r"fake.tir:1: line 1 is neither") as err:
        read_tir(fake)
    assert "SECRET" not in str(err.value)
    fake.write_text("[MODEL]\nFNOMIN = SECRET-HASH\n")
    with pytest.raises(TirError) as err:
        read_tir(fake)
    assert "SECRET" not in str(err.value) and "FNOMIN: the value is not a number" in str(err.value)
    fake.write_bytes(b"\x00\x01binary")
    with pytest.raises(TirError, match="a binary file"):
        read_tir(fake)


def test_every_range_is_ordered():
    for table in (VEHICLE_RANGES, COEFFICIENT_RANGES):
        for key, r in table.items():
            assert r.lo <= r.plo <= r.phi <= r.hi, key


def _semitrailer_with(tmp_path: Path, n: int) -> Path:
    """The unloaded preset with ``n`` light semitrailer axles 1.3 m apart about L2 = 15 m."""
    import tomllib

    import tomli_w

    data = tomllib.loads(Path(load_vehicle("gosar2022-unloaded").path).read_text())
    data["trailer"]["L2"] = 15.0
    first = data["trailer"]["axle"][0]
    data["trailer"]["axle"] = [
        {**first, "name": f"trailer-{i + 1}", "x": -15.0 - 1.3 * (i - (n - 1) / 2),
         "load_share": 1.0 / n, "unsprung_mass": 100.0} for i in range(n)]
    p = tmp_path / f"axles-{n}.toml"
    p.write_text(tomli_w.dumps(data))
    return p


def test_the_number_of_axles_is_judged_like_any_number(tmp_path):
    # 20 semitrailer axles were accepted by vehicle show and the STM, refused later by the
    # plant (issue 46, item 8): one rule, in the file's check, for every model.
    with pytest.raises(VehicleFileError, match=r"key 'trailer.axle': 20 axles is impossible "
                                               r"for a tractor-semitrailer .* 1 to 8 axles"):
        load_vehicle(_semitrailer_with(tmp_path, 20))
    with pytest.warns(PlausibilityWarning, match=r"key 'trailer.axle': 6 axles is unusual "
                                                 r"\(usual: 1 to 4 axles\)"):
        assert sum(a.unit == 2 for a in load_vehicle(_semitrailer_with(tmp_path, 6)).axles) == 6


@pytest.mark.parametrize("name", ["two\nlines", "tab\there", "bell\x07"])
def test_a_name_with_a_control_character_is_refused(tmp_path, name):
    import tomllib

    import tomli_w

    data = tomllib.loads(PRESET.read_text())
    data["vehicle"]["name"] = name  # TOML escapes it: "two\nlines"
    p = tmp_path / "v.toml"
    p.write_text(tomli_w.dumps(data))
    with pytest.raises(VehicleFileError, match=r"key 'vehicle.name': .* holds the control "
                                               r"character .* give it on one line"):
        load_vehicle(p)


def test_a_bar_in_a_name_stays_in_its_markdown_cell():
    import pandas as pd

    from artic.validation.docking.scores import markdown as dock_markdown
    from artic.validation.review.tables import markdown

    t = pd.DataFrame({"vehicle": ["a|b"], "success": ["1 of 1"]})
    for text in (dock_markdown(t), markdown(t.set_index("vehicle"))):
        row = text.strip().splitlines()[-1]
        assert row.replace("\\|", "").count("|") == 3, text  # two cells: three bars
        assert "a\\|b" in row


def test_a_tyre_file_read_again_is_parsed_from_its_bytes_and_warned_again(tmp_path):
    # read_tir keeps the parse of the last few files' bytes: every caller still gets
    # its own sections, an edited file is read anew, and the judgement of its
    # coefficients (its warnings) is made on every read.
    first = read_tir(TYRE)
    longvl = first.number("LONGVL")
    first.sections["MODEL"]["LONGVL"] = -1.0
    again = read_tir(TYRE)
    assert again.number("LONGVL") == longvl != -1.0
    assert again.sections == read_tir(TYRE).sections
    p = tmp_path / "x.tir"
    p.write_text(tyre_with(r"^PDY1 .*$", "PDY1 = 1.1"))
    assert read_tir(p).number("PDY1") == 1.1
    p.write_text(tyre_with(r"^PDY1 .*$", "PDY1 = 2.0"))  # the same name, new bytes
    for _ in range(2):
        with pytest.warns(PlausibilityWarning, match="key PDY1: 2 is unusual"):
            assert read_tir(p).number("PDY1") == 2.0
