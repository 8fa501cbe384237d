"""Channel-mapped logs: the articulation's sign, speed units, --accept for every check, scale.

The triggers, on campaign-like logs (the single-track model through the campaign's
sensor models) written as a tractor-plus-hitch CSV: an articulation with the
wrong sign is refused naming gamma; a speed column in km/h is named as km/h, not
as a GNSS jump; every consistency check, the jump check included, can be
accepted, is recorded, and is remembered by ``validate`` and ``tune``; the
thresholds scale with the vehicle.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from artic.mjcf import load_vehicle
from artic.validation.cli.commands import main
from artic.validation.logs import consistency
from artic.validation.logs.importers import import_source, read_log
from artic.validation.logs.runfile import LogError, check_frame, read_run
from artic.validation.logs.scale import FULL_SIZE, LogScale
from tests.hostile_logs import docking, slalom

EXAMPLE = Path(__file__).resolve().parents[1] / "docs" / "channels-example.toml"


def hitch_csv(run, path: Path, hitch_sign: float = -1.0, speed_factor: float = 1.0,
              step: int = 1) -> Path:
    """A log in the example map's layout: tractor channels and a hitch sensor only.

    The example map reads ``hitch`` with ``scale = -1``; ``hitch_sign = +1`` writes it
    with the wrong sign. ``speed_factor`` multiplies ``vx`` and ``vy`` (3.6: km/h).
    """
    f = run.frame.iloc[::step]
    gamma_dot = f["r_1"] - f["r_2"]
    pd.DataFrame({
        "t": f["t"] + 50.0, "steer_ang": np.degrees(f["delta_h"]),
        "vx": speed_factor * f["v_x_1"], "yaw": f["psi_1"], "yaw_rate": f["r_1"],
        "X": f["x_1"], "Y": f["y_1"], "vy": speed_factor * f["v_y_1"],
        "hitch": hitch_sign * np.degrees(f["gamma"]),
        "hitch_rate": hitch_sign * np.degrees(gamma_dot)}).to_csv(path, index=False)
    return path


@pytest.mark.parametrize("make", [slalom, docking])
def test_right_sign_passes_and_flipped_articulation_is_refused(tmp_path, unloaded, make):
    run = make()
    ok, _ = import_source(hitch_csv(run, tmp_path / "ok.csv", step=10), channels=EXAMPLE,
                          vehicle=unloaded)
    assert ok.meta["derived"] and "accepted_checks" not in ok.meta
    bad = hitch_csv(run, tmp_path / "flipped.csv", hitch_sign=+1.0, step=10)
    with pytest.raises(LogError) as err:
        import_source(bad, channels=EXAMPLE, vehicle=unloaded)
    msg = str(err.value)
    assert msg.startswith(f"{bad}: channel {bad}: hitch, t = ")
    assert "(the articulation angle gamma) likely has its sign flipped" in msg
    assert "--accept articulation" in msg and "\n" not in msg


def test_flipped_gamma_in_a_canonical_tractor_only_csv_is_refused(tmp_path, unloaded):
    f = docking().frame
    cols = ["t", "delta_h", "x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1", "gamma"]
    csv = tmp_path / "tractor_only.csv"
    f[cols].assign(gamma=-f["gamma"]).to_csv(csv, index=False)
    with pytest.raises(LogError, match=r"channel .*: gamma \(the articulation angle gamma\) "
                                       "likely has its sign flipped"):
        import_source(csv, vehicle=unloaded)
    run, _ = import_source(csv, vehicle=unloaded, accept=("articulation",))
    assert run.meta["accepted"] == ["articulation"]
    assert run.meta["accepted_checks"][0].startswith("accepted articulation: ")


def test_articulation_check_is_the_kinematic_equation(unloaded):
    # A steady turn at 2 m/s (R ~ 25 m): gamma' = 0 = r_1 (1 - L1c cos g / L2) - u sin g / L2
    # holds for the logged sign only. The mirror predicts 2 r_1 (1 - L1c cos g / L2) per
    # second, 0.15 rad per 2 s window; the logged sign, 0.
    v = unloaded
    u, r1 = 2.0, 0.08
    g = math.asin(r1 * (v.L2 - v.L1c * math.cos(0.3)) / u)  # a first guess ...
    for _ in range(50):  # ... iterated to the fixed point
        g = math.asin(r1 * (v.L2 - v.L1c * math.cos(g)) / u)
    t = np.arange(0.0, 20.0, 0.01)
    frame = pd.DataFrame({"t": t, "gamma": np.full_like(t, g), "r_1": r1, "v_x_1": u})
    ctx = consistency.CANONICAL
    assert consistency.check_articulation(t, frame, v, ctx) is None
    found = consistency.check_articulation(t, frame.assign(gamma=-g), v, ctx)
    assert found is not None and found.check == "articulation" and found.channel == "gamma"
    # Straight driving cannot tell the sign: the floor passes it.
    straight = frame.assign(r_1=0.0, gamma=0.0)
    assert consistency.check_articulation(t, straight, v, ctx) is None


def test_speed_in_kph_is_named_as_kph_not_as_a_gnss_jump(tmp_path, unloaded):
    csv = hitch_csv(slalom(), tmp_path / "kph.csv", speed_factor=3.6, step=10)
    with pytest.raises(LogError) as err:
        import_source(csv, channels=EXAMPLE, vehicle=unloaded)
    msg = str(err.value)
    assert f"channel {csv}: vx, t = " in msg and "km/h where m/s is expected" in msg
    assert "GNSS" not in msg and "jump" not in msg
    # Declared as km/h, the same column imports.
    kmh = tmp_path / "kmh.toml"
    kmh.write_text(EXAMPLE.read_text().replace('column = "vx", unit = "m/s"',
                                               'column = "vx", unit = "km/h"')
                   .replace('column = "vy", unit = "m/s"', 'column = "vy", unit = "km/h"'))
    run, _ = import_source(csv, channels=kmh, vehicle=unloaded)
    assert float(run.frame["v_x_1"].max()) == pytest.approx(slalom().frame["v_x_1"].max(),
                                                            rel=0.01)


def test_jump_is_accepted_recorded_and_remembered(tmp_path, unloaded, capsys):
    run = slalom()
    f = run.frame
    f.loc[f["t"] >= 12.0, ["x_1", "x_2"]] += 2.0  # a 2 m GNSS jump, both units
    csv = hitch_csv(run, tmp_path / "jump.csv")
    with pytest.raises(LogError, match="a GNSS jump; .* or pass --accept jump"):
        import_source(csv, channels=EXAMPLE, vehicle=unloaded)
    out = tmp_path / "imp"
    assert main(["logs", "import", str(csv), "--channels", str(EXAMPLE), "--out-dir",
                 str(out), "--accept", "jump", "--accept", "curvature,velocity"]) == 0
    imported = read_run(out / "jump.parquet")
    assert imported.meta["accepted"] == ["jump", "curvature", "velocity"]
    assert any(line.startswith("accepted jump: ") for line in imported.meta["accepted_checks"])
    # validate and tune remember it: no --accept needed again, and nothing recorded twice.
    back = read_log(out / "jump.parquet")
    assert len(back.meta["accepted_checks"]) == len(set(back.meta["accepted_checks"]))
    capsys.readouterr()
    assert main(["validate", str(out / "jump.parquet"), "--models", "kin", "--no-recordings",
                 "--out-dir", str(tmp_path / "val")]) == 0, capsys.readouterr().err
    kin = read_run(tmp_path / "val" / "runs" / "jump.kin.parquet")
    assert kin.meta["log"] == "jump"
    tuned = tmp_path / "tuned.toml"
    assert main(["tune", str(out / "jump.parquet"), "--models", "kin", "--out",
                 str(tuned)]) == 0, capsys.readouterr().err
    assert "checks accepted with --accept: curvature, jump, velocity" in tuned.read_text()


def test_every_check_can_be_accepted():
    # The names --accept takes are every check's, the jump and the articulation included.
    assert consistency.parse_accept(list(consistency.CHECKS)) == tuple(consistency.CHECKS)
    assert {"jump", "gap", "articulation"} <= set(consistency.CHECKS)
    meta = {"accepted_checks": ["accepted jump: x.csv: ...", "accepted hitch: ..."],
            "accepted": ["gap"]}
    assert consistency.accepted_in(meta) == ("gap", "jump", "hitch")


def test_thresholds_scale_with_the_vehicle():
    model = load_vehicle("scale-model-1to14")
    sc = LogScale.of(model)
    assert LogScale.of(load_vehicle("six-axle")) == FULL_SIZE == LogScale.of(None)
    assert sc.length == pytest.approx(1 / 14, rel=1e-5)
    # Froude similitude: speeds by sqrt(1/14), yaw rates by sqrt(14), angles unchanged.
    assert sc.plausible["v_x_1"] == pytest.approx(15.0 / math.sqrt(14), rel=1e-5)
    assert sc.plausible["r_1"] == pytest.approx(3.0 * math.sqrt(14), rel=1e-5)
    assert sc.plausible["gamma"] == FULL_SIZE.plausible["gamma"]
    # A 1:14 log at 5 m/s is 18.7 m/s full-size: km/h read as m/s, at the model's scale.
    f = slalom().frame
    fast = f.assign(v_x_1=f["v_x_1"] * 5.0 / f["v_x_1"].max())
    check_frame(fast, "log")
    with pytest.raises(LogError, match=r"column v_x_1: peak 5 is beyond 4.009 .* at the "
                                       r"vehicle's scale \(0.0714\)"):
        check_frame(fast, "log", sc)
    # A 0.1 m position jump: noise for a truck, a GNSS jump for a 1:14 model.
    t = f["t"].to_numpy()
    jumped = f.copy()
    jumped.loc[jumped["t"] >= 10.0, "x_1"] += 0.1
    ctx = consistency.CANONICAL
    assert consistency.check_jump(t, jumped, 1, ctx) is None
    found = consistency.check_jump(t, jumped, 1, ctx, sc)
    assert found is not None and "(limit 0.0357 m)" in found.problem
