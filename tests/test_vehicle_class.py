"""Vehicles of any size: the scale-model class, its ranges and the shipped 1:14 preset.

KIN works at any scale; the STM and the plant only with tyre data that fits,
and they say so. A value outside every class's possible range stays refused.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.plausible import (
    CLASS_RANGES,
    SCALE_MODEL_RANGES,
    VEHICLE_RANGES,
    PlausibilityWarning,
)
from artic.mjcf.schema import VehicleFileError
from artic.mjcf.vehicle import REFERENCE_LENGTH
from artic.reduced import KIN, STM
from artic.validation.cli.commands import main
from artic.validation.logs.runfile import read_run

SCALE = "scale-model-1to14"
SCALE_PATH = Path(load_vehicle(SCALE).path)
FULL_PATH = Path(load_vehicle("gosar2022-unloaded").path)
TRUCK_TYRE = '\n[tyre]\nf = 6.0\nsigma_alpha = 0.032\nfile = "artic-truck-315-80R22.5.tir"\n'


def edited(tmp_path: Path, base: Path, old: str, new: str, name: str = "v.toml") -> Path:
    text = base.read_text()
    assert re.search(old, text, flags=re.M), old
    p = tmp_path / name
    p.write_text(re.sub(old, new, text, count=1, flags=re.M))
    return p


def one_line(capsys, argv) -> str:
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("artic: error: "), err
    return err[0]


def test_the_scale_preset_is_a_plausible_one_to_fourteen_model():
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        v = load_vehicle(SCALE)
    full = load_vehicle("gosar2022-unloaded")
    assert v.vehicle_class == "scale-model" and full.vehicle_class == "full-size"
    # Similitude at 1:14: lengths /14, masses /14^3, yaw inertias /14^5 (to the file's digits).
    assert v.L1 == pytest.approx(full.L1 / 14, rel=1e-5)
    assert v.L2 == pytest.approx(full.L2 / 14, rel=1e-5)
    assert v.m1 == pytest.approx(full.m1 / 14 ** 3, rel=1e-5)
    assert v.J2 == pytest.approx(full.J2 / 14 ** 5, rel=1e-5)
    assert v.length_ratio == pytest.approx(1 / 14, rel=1e-5)
    assert v.speed_ratio == pytest.approx(math.sqrt(1 / 14), rel=1e-5)
    assert full.length_ratio == 1.0 and REFERENCE_LENGTH == pytest.approx(full.L1 + full.L2)
    # Axle loads scale as the masses: the same load distribution.
    np.testing.assert_allclose(v.static_loads / full.static_loads, 14.0 ** -3, rtol=1e-4)
    assert not v.has_tyre_data and math.isnan(v.f) and v.tyre_file == ""


def test_scale_model_ranges_follow_similitude():
    # A length range carried by 1:32 to 1:4 (plausible) and 1:100 to 1:2 (possible).
    L2, L2m = VEHICLE_RANGES["trailer.L2"], SCALE_MODEL_RANGES["trailer.L2"]
    assert (L2m.lo, L2m.plo, L2m.phi, L2m.hi) == pytest.approx(
        (L2.lo / 100, L2.plo / 32, L2.phi / 4, L2.hi / 2))
    m, mm = VEHICLE_RANGES["tractor.m1"], SCALE_MODEL_RANGES["tractor.m1"]
    assert mm.phi == pytest.approx(m.phi / 4 ** 3) and mm.lo == pytest.approx(m.lo / 100 ** 3)
    # Angles and ratios do not scale.
    assert SCALE_MODEL_RANGES["limits.gamma_max"] == VEHICLE_RANGES["limits.gamma_max"]
    for table in CLASS_RANGES.values():
        for key, r in table.items():
            assert r.lo <= r.plo <= r.phi <= r.hi, key


def test_a_20_kg_tractor_without_a_class_is_refused_naming_the_class_option(tmp_path, capsys):
    p = edited(tmp_path, FULL_PATH, r"^m1 = 8060.0 ", "m1 = 20.0 ")
    with pytest.raises(VehicleFileError) as err:
        load_vehicle(p)
    msg = str(err.value)
    assert msg.startswith(f"{p}: key 'tractor.m1': 20 kg is impossible for a "
                          "tractor-semitrailer of class full-size (possible: 500 to 60000 kg)")
    assert 'declare [vehicle] class = "scale-model"' in msg
    assert 'class = "scale-model"' in one_line(capsys, ["vehicle", "show", p])


def test_a_20_kg_robot_tractor_is_a_scale_model(tmp_path):
    # The robot: a 20 kg tractor on a model's geometry. With its class it loads.
    p = edited(tmp_path, SCALE_PATH, r"^m1 = 2.937318 ", "m1 = 20.0 ")
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        v = load_vehicle(p)
    assert v.m1 == 20.0
    # Without the class line the same file is refused, at its first full-size-impossible key.
    q = edited(tmp_path, p, r'^class = "scale-model"\n', "", name="noclass.toml")
    q.write_text(q.read_text() + TRUCK_TYRE)
    with pytest.raises(VehicleFileError, match=r"noclass.toml: key 'tractor.m1'.*"
                                               r'class = \\?"scale-model'):
        load_vehicle(q)


@pytest.mark.parametrize("base,old,new,key", [
    (SCALE_PATH, r"^h2 = 0.092857 ", "h2 = 100.0 ", "trailer.h2"),
    (FULL_PATH, r"^h2 = 1.3 ", "h2 = 100.0 ", "trailer.h2"),
    (SCALE_PATH, r"^m2 = 2.587464 ", "m2 = 1e6 ", "trailer.m2"),
    (FULL_PATH, r"^m2 = 7100.0 ", "m2 = 1e6 ", "trailer.m2"),
    (SCALE_PATH, r"^track = 0.146429", "track = 20.0", "tractor.axle 'front'.track"),
    (FULL_PATH, r"^track = 2.05", "track = 20.0", "tractor.axle 'front'.track"),
])
def test_values_outside_every_class_stay_refused(tmp_path, base, old, new, key):
    p = edited(tmp_path, base, old, new)
    with pytest.raises(VehicleFileError) as err:
        load_vehicle(p)
    msg = str(err.value)
    assert msg.startswith(f"{p}: key '{key}': ")
    assert "impossible for a tractor-semitrailer of any class (full-size: " in msg
    assert "; scale-model: " in msg and "[vehicle] class" not in msg


def test_unknown_class_is_refused_naming_the_key(tmp_path):
    p = edited(tmp_path, SCALE_PATH, r'^class = "scale-model"', 'class = "toy"')
    with pytest.raises(VehicleFileError, match=r"key 'vehicle.class': 'toy' is not a vehicle "
                                               "class; use one of full-size, scale-model"):
        load_vehicle(p)


def test_stm_and_plant_refuse_a_scale_model_without_tyre_data(capsys, tmp_path):
    v = load_vehicle(SCALE)
    KIN(v)  # KIN needs none
    with pytest.raises(VehicleFileError, match=r"key 'tyre.f': vehicle scale-model-1to14 "
                                               r"\(class scale-model\) has no tyre data"):
        STM(v)
    from artic.plant import Plant

    with pytest.raises(VehicleFileError, match=r"key 'tyre.file': .* has no tyre file"):
        Plant(v)
    for model, key in (("stm", "tyre.f"), ("mbd", "tyre.file")):
        line = one_line(capsys, ["simulate", "--model", model, "--vehicle", SCALE,
                                 "--manoeuvre", "straight", "--duration", "1",
                                 "--out", tmp_path / "r.parquet"])
        assert f"key '{key}'" in line and "--models kin" in line
        line = one_line(capsys, ["validate", tmp_path / "none.parquet", "--vehicle", SCALE,
                                 "--models", f"kin,{model}", "--out-dir", tmp_path / "v"])
        assert f"key '{key}'" in line
    assert not (tmp_path / "r.parquet").exists()


def test_a_truck_tyre_does_not_fit_a_scale_model(tmp_path):
    # With the model's own f and sigma_alpha the STM runs; the plant with a truck's tyre
    # file would put 3 to 11 N on tyres whose data starts at 500 N: refused, by key.
    p = tmp_path / "v.toml"
    p.write_text(SCALE_PATH.read_text() + TRUCK_TYRE)
    v = load_vehicle(p)
    assert v.has_tyre_data
    stm = STM(v)
    assert stm.P.size > 0
    from artic.plant import Plant

    with pytest.raises(VehicleFileError) as err:
        Plant(v)
    msg = str(err.value)
    assert msg.startswith(f"{p}: key 'tyre.file': the static load of a tyre on axle 'front'")
    assert "outside the load range FZMIN = 500 N to FZMAX = 90000 N" in msg
    # Full-size vehicles keep their tyres' load ranges.
    from artic.mjcf.plausible import check_tyre_data

    for name in ("gosar2022-unloaded", "gosar2022-loaded", "six-axle"):
        check_tyre_data(load_vehicle(name), "mbd")


def test_the_scale_preset_simulates_imports_and_validates_with_kin(tmp_path, capsys):
    # artic simulate -> logs import -> validate, all at 1:14 with KIN; the log gets the
    # noise of a motion tracker (1 mm, 0.2 deg) and a hitch encoder (0.5 deg).
    run = tmp_path / "slalom.parquet"
    assert main(["simulate", "--model", "kin", "--vehicle", SCALE, "--manoeuvre", "slalom",
                 "--amplitude-deg", "20", "--speed-kph", "1.3", "--duration", "60",
                 "--out", str(run)]) == 0
    log = read_run(run)
    rng = np.random.default_rng(3)
    f = log.frame
    n = len(f)
    for c, s in (("x_1", 1e-3), ("y_1", 1e-3), ("x_2", 1e-3), ("y_2", 1e-3),
                 ("v_x_1", 0.005), ("v_y_1", 0.005), ("r_1", 0.005)):
        f[c] = f[c] + rng.normal(0.0, s, n)
    heading = rng.normal(0.0, math.radians(0.2), n)
    f["psi_1"] = f["psi_1"] + heading
    f["psi_2"] = f["psi_1"] - (f["gamma"] + rng.normal(0.0, math.radians(0.5), n))
    from artic.mjcf.interface import wrap_angle
    from artic.validation.logs.runfile import write_run

    f["gamma"] = wrap_angle((f["psi_1"] - f["psi_2"]).to_numpy())
    noisy = write_run(type(log)(f[list(f.columns[:15])], log.meta), tmp_path / "noisy.parquet")
    capsys.readouterr()
    assert main(["logs", "import", str(noisy), "--vehicle", SCALE, "--out-dir",
                 str(tmp_path / "imp")]) == 0, capsys.readouterr().err
    assert main(["validate", str(tmp_path / "imp" / "noisy.parquet"), "--vehicle", SCALE,
                 "--models", "kin", "--no-recordings", "--out-dir",
                 str(tmp_path / "val")]) == 0, capsys.readouterr().err
    m = pd.read_csv(tmp_path / "val" / "metrics.csv")
    assert list(m.status) == ["ok"]
    # KIN against its own run with sensor noise: the position error stays at the noise's
    # millimetres (eps_p is an RMS over distance) and far below the model's 0.81 m length.
    assert float(m.eps_p.iloc[0]) < 0.01
