"""Tractor-only logs with a hitch-angle sensor, through a channel map, from a plant run."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from artic.mjcf.interface import wrap_angle
from artic.plant import Plant
from artic.validation.harness.simulate import simulate
from artic.validation.logs.channels import read_map
from artic.validation.logs.derive import derive_trailer
from artic.validation.logs.importers import import_source
from artic.validation.logs.runfile import LogError, read_run
from artic.validation.runs.validate import validate_runs
from artic.validation.synthetic.manoeuvres import make_profile
from artic.validation.synthetic.sensors import SensorModel, measure

EXAMPLE = Path(__file__).resolve().parents[1] / "docs" / "channels-example.toml"

HITCH_SIGMA = math.radians(0.1)
"""A hitch-angle encoder's noise [rad]; its rate channel's is HITCH_RATE_SIGMA [rad/s]."""
HITCH_RATE_SIGMA = math.radians(0.1)


@pytest.fixture(scope="module")
def plant_run(unloaded):
    """The truth: a 20 s slalom of the plant at 100 Hz, both units."""
    p = make_profile("slalom", amplitude_deg=200.0, speed_kph=6.0, duration=20.0)
    with Plant(unloaded) as plant:
        return simulate(plant, unloaded, p)


def _dataset_csv(truth: pd.DataFrame, path: Path, seed: int = 3) -> Path:
    """The truth as a public dataset logs it: tractor sensors and a hitch sensor only,
    irregular stamps at about 10 Hz, the dataset's own names and units, image paths."""
    rng = np.random.default_rng(seed)
    meas = measure(truth, rng, SensorModel())  # RTK/INS figures for the tractor channels
    t100 = truth["t"].to_numpy()
    base = np.arange(0.0, t100[-1] - 0.1, 0.1)
    stamps = base + rng.uniform(-0.03, 0.03, base.size)  # 10 Hz, +-30 ms of jitter
    stamps[0] = 0.0

    def at(col, frame=meas):
        return np.interp(stamps, t100, frame[col].to_numpy())

    gamma = at("gamma", truth) + rng.normal(0.0, HITCH_SIGMA, stamps.size)
    gamma_dot = (at("r_1", truth) - at("r_2", truth)
                 + rng.normal(0.0, HITCH_RATE_SIGMA, stamps.size))
    df = pd.DataFrame({
        "t": stamps + 1000.0,  # stamps from the logger's clock, not from zero
        "steer_ang": np.degrees(at("delta_h")), "vx": at("v_x_1"), "yaw": at("psi_1"),
        "yaw_rate": at("r_1"), "X": at("x_1"), "Y": at("y_1"), "vy": at("v_y_1"),
        "hitch": -np.degrees(gamma), "hitch_rate": -np.degrees(gamma_dot),
        "img_left": [f"left/{i:05d}.png" for i in range(stamps.size)],
        "img_right": [f"right/{i:05d}.png" for i in range(stamps.size)]})
    df.to_csv(path, index=False)
    return path


def test_tractor_and_hitch_log_through_a_channel_map(tmp_path, unloaded, plant_run):
    truth = plant_run.frame
    csv = _dataset_csv(truth, tmp_path / "dataset.csv")
    run, report = import_source(csv, channels=EXAMPLE, vehicle=unloaded)
    assert run.meta["derived"]["channels"] == ["x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2"]
    # The map's [noise] table travels with the log, in SI, for artic validate's floor.
    assert run.meta["sensor_noise"]["gamma"] == {"sigma": HITCH_SIGMA, "tau": 0.0, "bias": 0.0}
    assert run.meta["sensor_noise"]["psi_1"]["sigma"] == pytest.approx(math.radians(0.05))
    assert run.meta["derived"]["vehicle"] == unloaded.name
    assert any("img_left, img_right not in the channel map" in line for line in report)
    assert any("interpolated linearly onto 100 Hz" in line for line in report)
    assert any("derived" in line for line in report)
    f = run.frame
    assert np.allclose(np.diff(f["t"]), 0.01)  # the 100 Hz base
    # Compare with the plant's own semitrailer at the same instants.
    t = f["t"].to_numpy()  # the first stamp was 0 of the truth's clock
    tr = {c: np.interp(t, truth["t"], truth[c]) for c in ("x_2", "y_2", "psi_2", "v_x_2",
                                                           "v_y_2", "r_2", "gamma")}

    def rms(x):
        return float(np.sqrt(np.mean(np.square(x))))

    # Tolerances from the sensor figures: heading 0.05 deg and hitch 0.1 deg add to about
    # 0.11 deg of semitrailer yaw error (3 sigma 0.35 deg; 0.5 deg allows for 10 Hz).
    e_psi = wrap_angle(f["psi_2"].to_numpy() - tr["psi_2"])
    assert rms(e_psi) < math.radians(0.2) and np.abs(e_psi).max() < math.radians(0.5)
    # Position: 10 mm of RTK noise, and 0.11 deg of yaw error on the ~14 m lever from the
    # tractor sensor over the kingpin to the semitrailer sensor (~27 mm); the plant's
    # roll and pitch move its sensors by a few cm more, which a planar derivation ignores.
    e_pos = np.hypot(f["x_2"] - tr["x_2"], f["y_2"] - tr["y_2"])
    assert rms(e_pos) < 0.05 and e_pos.max() < 0.12
    # Yaw rate: the hitch-rate channel's 0.1 deg/s noise and the rate sensor's bias.
    e_r = f["r_2"].to_numpy() - tr["r_2"]
    assert rms(e_r) < math.radians(0.25)
    # Velocities: 10 mm/s of noise, plus yaw-rate error times the ~11 m lever.
    for c in ("v_x_2", "v_y_2"):
        assert rms(f[c].to_numpy() - tr[c]) < 0.03, c
    # Without the derivation the comparison would fail: the trailer is not the tractor.
    assert rms(np.hypot(f["x_1"] - tr["x_2"], f["y_1"] - tr["y_2"])) > 5.0
    # And validation runs on it.
    rows = validate_runs([run], unloaded, ["kin", "stm"], jobs=1)
    assert list(rows["status"]) == ["ok", "ok"]
    assert rows["eps_n"].notna().all() and (rows["eps_n"] < 50.0).all()


def test_derivation_is_exact_for_a_rigid_turn(unloaded):
    """A steady turn, worked by hand: both units turn at r about one centre."""
    v = unloaded
    r, gamma = 0.2, 0.3  # [rad/s], [rad]
    t = np.linspace(0.0, 5.0, 501)
    psi1 = r * t
    s1 = np.array(v.sensor1[:2])
    # Tractor origin on a circle of radius 20 m about (0, 20), moving along +x at t = 0.
    o = np.column_stack([20 * np.sin(psi1), 20 - 20 * np.cos(psi1)])
    p1 = o + np.column_stack([np.cos(psi1) * s1[0] - np.sin(psi1) * s1[1],
                              np.sin(psi1) * s1[0] + np.cos(psi1) * s1[1]])
    # Velocity of the tractor sensor in tractor axes: u = 20 r forward, plus r x s1.
    vx1, vy1 = 20 * r - r * s1[1], r * s1[0]
    frame = pd.DataFrame({"t": t, "x_1": p1[:, 0], "y_1": p1[:, 1], "psi_1": psi1,
                          "v_x_1": vx1, "v_y_1": vy1, "r_1": r, "gamma": gamma})
    out, note = derive_trailer(frame, v)
    psi2 = psi1 - gamma
    k = o + np.column_stack([np.cos(psi1) * v.L1c, np.sin(psi1) * v.L1c])
    s2 = np.array(v.sensor2[:2])
    p2 = k + np.column_stack([np.cos(psi2) * s2[0] - np.sin(psi2) * s2[1],
                              np.sin(psi2) * s2[0] + np.cos(psi2) * s2[1]])
    np.testing.assert_allclose(out["x_2"], p2[:, 0], atol=1e-9)
    np.testing.assert_allclose(out["y_2"], p2[:, 1], atol=1e-9)
    np.testing.assert_allclose(out["r_2"], r, atol=1e-9)  # gamma constant
    # The semitrailer sensor's speed is r times its distance from the turn centre (0, 20).
    speed = np.hypot(out["v_x_2"], out["v_y_2"])
    np.testing.assert_allclose(speed, r * np.hypot(p2[:, 0], p2[:, 1] - 20.0), rtol=1e-9)
    assert "derivative of gamma" in note


def test_channel_map_errors_name_the_key(tmp_path):
    bad = tmp_path / "map.toml"
    bad.write_text('[time]\ncolumn = "t"\nunit = "s"\n[channels]\n'
                   'delta_h = { column = "a", unit = "deg" }\n'
                   'x_1 = { column = "X", unit = "deg" }\n')
    with pytest.raises(LogError, match=r"channels.x_1: unit 'deg' is not a unit of length"):
        read_map(bad)
    bad.write_text('[time]\ncolumn = "t"\nunit = "s"\n[channels]\n'
                   'delta_h = { column = "a", unit = "deg" }\n')
    with pytest.raises(LogError, match=r"no unit's pose; name x_1, y_1, psi_1"):
        read_map(bad)
    bad.write_text('[time]\ncolumn = "t"\nunit = "s"\n[channels]\n'
                   'x_1 = { column = "X", unit = "m" }\npsi_1 = { column = "h", unit = "rad" }\n')
    with pytest.raises(LogError, match=r"has x_1, psi_1 but not y_1"):
        read_map(bad)
    spec = read_map(EXAMPLE)
    assert spec.entries["gamma"].scale == -1.0 and spec.max_gap == 0.3


@pytest.mark.parametrize("pair, units, said", [
    (("x_2", "y_2"), ('"m"', '"cm"'), "channels.x_2 is in m and channels.y_2 in cm"),
    (("x_2", "y_2"), ('"m", scale = 0.001', '"m"'), "channels.x_2 is in m x 0.001 and "
                                                    "channels.y_2 in m"),
    (("v_x_2", "v_y_2"), ('"km/h"', '"m/s"'), "channels.v_x_2 is in km/h and channels.v_y_2 "
                                            "in m/s"),
    (("x_2", "y_2"), ('"longitude"', '"m"'), "a position is either longitude and latitude"),
])
def test_the_components_of_one_vector_share_a_unit(tmp_path, pair, units, said):
    """Issue 46, item 6(b), as a family: a position's or a velocity's two components."""
    bad = tmp_path / "map.toml"
    head = ('[time]\ncolumn = "t"\nunit = "s"\n[channels]\n'
            'x_2 = { column = "X", unit = "m" }\ny_2 = { column = "Y", unit = "m" }\n'
            'psi_2 = { column = "h", unit = "rad" }\ngamma = { column = "g", unit = "rad" }\n')
    lines = [f'{pair[0]} = {{ column = "A", unit = {units[0]} }}',
             f'{pair[1]} = {{ column = "B", unit = {units[1]} }}']
    keep = [ln for ln in head.splitlines() if not ln.startswith((pair[0] + " ", pair[1] + " "))]
    bad.write_text("\n".join(keep + lines) + "\n")
    with pytest.raises(LogError, match=re.escape(said)):
        read_map(bad)
    # Mirrored (a negative scale) is the axes' business, not the unit's: accepted.
    bad.write_text(head.replace('unit = "m" }\npsi_2', 'unit = "m", scale = -1.0 }\npsi_2'))
    assert read_map(bad).entries["y_2"].scale == -1.0


def test_canonical_csv_without_the_semitrailer_is_derived(tmp_path, unloaded, plant_run):
    truth = plant_run.frame
    cols = ["t", "delta_h", "x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1", "gamma"]
    csv = tmp_path / "tractor_only.csv"
    truth[cols].to_csv(csv, index=False)
    run, report = import_source(csv, vehicle=unloaded)
    assert run.meta["derived"]["rate"] == "d gamma / dt" and any("derived" in r for r in report)
    # Noise-free and at 100 Hz: only the plant's roll and pitch, which the planar
    # derivation ignores, and the differentiated articulation rate remain.
    e = np.hypot(run.frame["x_2"] - truth["x_2"], run.frame["y_2"] - truth["y_2"])
    assert float(e.max()) < 0.05


def test_a_csv_with_a_gap_is_split_and_a_reimport_replaces_its_segments(tmp_path, unloaded,
                                                                         plant_run, capsys):
    from artic.validation.logs.importers import import_sources

    csv = _dataset_csv(plant_run.frame, tmp_path / "dataset.csv")
    full = pd.read_csv(csv)
    t = full["t"] - full["t"].iloc[0]
    full[(t < 8.0) | (t > 9.0)].to_csv(csv, index=False)  # a 1 s hole at 10 Hz
    out = tmp_path / "logs"
    paths = import_sources([csv], out, vehicle=unloaded, channels=EXAMPLE)
    assert [p.name for p in paths] == ["dataset.seg1.parquet", "dataset.seg2.parquet"]
    seg = read_run(paths[1]).meta["segment"]
    assert seg["log"] == "dataset" and seg["index"] == 2 and seg["of"] == 2
    assert 8.9 < seg["t0"] < 9.2  # the first sample after the hole
    # The same source again, hole repaired: one run, and the segments of before are gone.
    full.to_csv(csv, index=False)
    paths = import_sources([csv], out, vehicle=unloaded, channels=EXAMPLE)
    assert sorted(p.name for p in out.iterdir()) == ["dataset.parquet"]
    assert "removed" in capsys.readouterr().out
