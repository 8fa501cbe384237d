"""Vehicle parameter files: presets, derived quantities, static loads, bad files."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from artic.mjcf import VehicleFileError, load_vehicle, preset_names
from artic.mjcf.vehicle import G, resolve_vehicle_path
from tests.helpers import PRESETS

# Appendix of the paper: measured axle loads [N]; drive axle, trailer axles 1-3.
MEASURED = {
    "gosar2022-unloaded": (34727.0, (17658.0, 18639.0, 18835.0)),
    "gosar2022-loaded": (67100.0, (38651.0, 39632.0, 39436.0)),
}


def test_presets_are_shipped():
    assert set(PRESETS) <= set(preset_names())


@pytest.mark.parametrize("name", list(MEASURED))
def test_static_loads_match_measured_axle_loads(name):
    # The drive-axle load and the trailer-group total follow from masses and
    # geometry alone; 2 % is the bound (the design notes find 0.8 % and
    # 1.8 %). Each trailer axle's share comes from the measured distribution,
    # so each trailer axle is held to the same 2 %.
    v = load_vehicle(name)
    drive, trailer = MEASURED[name]
    loads = v.static_loads
    assert loads[1] == pytest.approx(drive, rel=0.02)
    assert loads[2:].sum() == pytest.approx(sum(trailer), rel=0.02)
    np.testing.assert_allclose(loads[2:], trailer, rtol=0.02)


@pytest.mark.parametrize("name,front", [("gosar2022-unloaded", 58.9e3),
                                        ("gosar2022-loaded", 65.6e3)])
def test_front_axle_load_from_equilibrium(name, front):
    # Seed notes section 2: the unlisted front load is about 58.9 / 65.6 kN.
    assert load_vehicle(name).static_loads[0] == pytest.approx(front, rel=0.005)


@pytest.mark.parametrize("name", PRESETS)
def test_static_loads_are_in_equilibrium(name):
    # Sum of forces and sum of moments about the drive axle, for the whole
    # combination standing straight: both must vanish to rounding.
    v = load_vehicle(name)
    loads = v.static_loads
    x = np.array([a.x if a.unit == 1 else v.L1c + a.x for a in v.axles])
    W1, W2 = v.m1 * G, v.m2 * G
    assert loads.sum() == pytest.approx(W1 + W2, rel=1e-12)
    moment = (loads * x).sum() - W1 * v.b1 - W2 * (v.L1c - v.a2)
    assert abs(moment) < 1e-9 * (W1 + W2) * v.L2
    # The trailer alone: kingpin load and its axles carry W2, moments about the kingpin.
    tl = loads[len(v.tractor_axles):]
    assert tl.sum() + v.kingpin_load == pytest.approx(W2, rel=1e-12)
    assert (tl * v.trailer_axle_distances).sum() == pytest.approx(W2 * v.a2, rel=1e-12)


def test_derived_quantities(unloaded):
    v = unloaded
    assert v.L1 == pytest.approx(3.8)
    assert v.Lc == pytest.approx(2.04)
    np.testing.assert_allclose(v.trailer_axle_distances, [6.2, 7.5, 8.8])
    # Table 1 gives the trailer sensor from the drive axle.
    assert v.sensor2_from_drive_axle == pytest.approx((-10.492, -0.004, 0.1))
    assert v.cornering_stiffness == pytest.approx(6.0 * v.static_loads)


def test_six_axle_preset():
    v = load_vehicle("six-axle")
    assert len(v.axles) == 6
    assert [a.name for a in v.tractor_axles] == ["front", "drive", "tag"]
    drive, tag = v.static_loads[1:3]
    assert drive / (drive + tag) == pytest.approx(0.605)
    # EU axle limits: 7.5 t on a tag axle, 11.5 t on a drive axle.
    assert tag < 7.5e3 * G and drive < 11.5e3 * G


def test_flat_has_paper_symbols(unloaded):
    flat = unloaded.flat()
    for key in ("m1", "J1", "a1", "b1", "L1c", "L1", "Lc", "m2", "J2", "a2", "b2", "L2", "j",
                "L21", "L22", "L23", "f", "i_s", "q", "delta_h_offset", "Fz1", "Fz5", "Fz_k",
                "i_s_kin", "i_s_stm", "i_s_mbd"):
        assert key in flat, key
    assert flat["i_s_kin"] == 20.5 and flat["i_s_stm"] == 21.5 and flat["i_s_mbd"] == 21.0


def test_resolve_name_or_path(tmp_path):
    p = resolve_vehicle_path("six-axle")
    assert p.is_file()
    copy = tmp_path / "mine.toml"
    copy.write_text(p.read_text())
    assert load_vehicle(copy).name == "six-axle"
    with pytest.raises(VehicleFileError, match="neither a preset nor a file"):
        load_vehicle("no-such-truck")


def _edited(tmp_path: Path, old: str, new: str) -> Path:
    src = resolve_vehicle_path("gosar2022-unloaded").read_text()
    assert old in src, old
    p = tmp_path / "edited.toml"
    p.write_text(src.replace(old, new, 1))
    return p


@pytest.mark.parametrize("old,new,key,words", [
    ("m1 = 8060.0", "m1x = 8060.0", "tractor.m1x", "unknown key"),
    ("J2 = 34613.0", "", "trailer.J2", "missing"),
    ("m2 = 7100.0", "m2 = -7100.0", "trailer.m2", "must be positive"),
    ("m1 = 8060.0", 'm1 = "heavy"', "tractor.m1", "expected a number"),
    ("x = 3.8", "x = 3.9", "tractor.a1", "must agree"),
    ("j = 1.3", "j = 1.4", "trailer.j", "spacings"),
    ("L2 = 7.5", "L2 = 7.8", "trailer.L2", "centred"),
    ("a2 = 5.96", "a2 = 9.5", "trailer.a2", "behind the axle group"),
    ("delta_h_offset = 0.0873", "delta_h_offset = 5.0", "steering.delta_h_offset", "radians"),
    ("load_share = 0.320286", "load_share = 0.5", "load_share", "sum to 1"),
    ("[limits]", "[limit]", "limit", "unknown section"),
])
def test_bad_file_names_file_and_key(tmp_path, old, new, key, words):
    p = _edited(tmp_path, old, new)
    with pytest.raises(VehicleFileError) as err:
        load_vehicle(p)
    msg = str(err.value)
    assert str(p) in msg and f"'{key}'" in msg and words in msg, msg


def test_an_unknown_key_lists_the_keys_apart_from_the_tables_and_the_likely_one(tmp_path):
    p = _edited(tmp_path, "i_s = 21.0", "i_ss = 21.0")
    with pytest.raises(VehicleFileError) as err:
        load_vehicle(p)
    msg = str(err.value)
    assert ("unknown key (did you mean i_s?); known keys of [steering] are: delta_h_offset, "
            "delta_max, i_s, q, steering_arm; its tables: [steering.kin], [steering.stm], "
            "[steering.mbd]") in msg, msg
    p = _edited(tmp_path, "L1c = 0.67", "l1c = 0.67")
    with pytest.raises(VehicleFileError, match=r"'tractor\.l1c': unknown key \(did you mean "
                       r"L1c\?\); known keys of \[tractor\] are: .*; its tables: \[\[tractor"
                       r"\.axle\]\]"):
        load_vehicle(p)


def test_invalid_toml_names_file(tmp_path):
    p = _edited(tmp_path, "m1 = 8060.0", "m1 = = 8060.0")
    with pytest.raises(VehicleFileError, match="not valid TOML") as err:
        load_vehicle(p)
    assert str(p) in str(err.value)


def test_steering_overrides(unloaded):
    assert unloaded.steering_for("kin").i_s == 20.5
    assert unloaded.steering_for("stm").i_s == 21.5
    assert unloaded.steering_for("mbd").i_s == 21.0
    assert unloaded.steering_for("kin").q == unloaded.steering.q
    assert unloaded.steering.delta_h_offset == pytest.approx(math.radians(5.0), rel=1e-3)


def test_vehicle_is_hashable_and_equal_vehicles_hash_equal(unloaded):
    again = load_vehicle("gosar2022-unloaded")
    assert again == unloaded and hash(again) == hash(unloaded)
    assert {unloaded: 1}[again] == 1
