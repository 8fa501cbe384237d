"""Plant runs as ROS bags and MCAP files: imported through a map, validated with KIN.

Each log (see ``bag_logs``) has poses only, no steering channel, a 1.5 s gap,
bursty receive stamps and a topic of a custom type. ``artic logs import``
reads it through its map; ``artic validate --models kin`` runs the two
gap-free segments and pools them; KIN's articulation is compared with the
plant's.
"""

from __future__ import annotations

import io
import math
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")
pytest.importorskip("mcap_ros2", reason="mcap-ros2-support (test extra) is not installed")

import bag_logs  # noqa: E402
from artic.plant import Plant  # noqa: E402
from artic.validation.cli import main  # noqa: E402
from artic.validation.logs.runfile import read_run  # noqa: E402
from artic.validation.simulate import simulate  # noqa: E402
from artic.validation.synthetic.manoeuvres import make_profile  # noqa: E402

G = 9.81


@pytest.fixture(scope="module")
def truth(unloaded):
    """The plant: a 24 s slalom at 6 km/h, 100 Hz."""
    p = make_profile("slalom", amplitude_deg=200.0, speed_kph=6.0, duration=24.0)
    with Plant(unloaded) as plant:
        return simulate(plant, unloaded, p).frame


def artic(*argv) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def articulation_bound(truth: pd.DataFrame, f: float) -> float:
    """How far KIN, its tractor steered onto the measured yaw rate, may miss the plant's gamma.

    KIN has no tyre slip. The plant's axle groups slip by about their lateral
    acceleration over the cornering coefficient, ``alpha_i ~ a_y,i / (f g)``;
    with the tractor's yaw imposed, a tractor slip moves the hitch sideways and
    a semitrailer slip turns the semitrailer, each by about its ``alpha`` in
    articulation (the articulation's dynamics pass a slow slip at gain one).
    The pose-only log adds the heading noise that the differentiated yaw rate
    carries (order ``YAW_SIGMA`` after the articulation's first-order lag).
    Twice the slip plus twice the noise [rad].
    """
    a1 = rms(truth["v_x_1"] * truth["r_1"])
    a2 = rms(truth["v_x_2"] * truth["r_2"])
    return 2.0 * math.hypot(a1, a2) / (f * G) + 2.0 * bag_logs.YAW_SIGMA


def run_format(fmt: str, tmp_path: Path, truth: pd.DataFrame, unloaded):
    path, text = bag_logs.write_log(fmt, tmp_path / f"rig_{fmt}", truth)
    chmap = tmp_path / f"{fmt}.toml"
    chmap.write_text(text)
    code, out, err = artic("logs", "import", path, "--channels", chmap, "--out-dir",
                           tmp_path / "logs")
    assert code == 0, err
    assert "left out unread: /diagnostics/rig (my_rig/msg/Diagnostics)" in out
    assert "split into 2 gap-free segments" in out
    logs = sorted((tmp_path / "logs").glob("*.parquet"))
    assert [p.stem for p in logs] == [f"{path.stem}.seg1", f"{path.stem}.seg2"]
    code, out, err = artic("validate", *logs, "--models", "kin", "--no-recordings",
                           "--out-dir", tmp_path / "val")
    assert code == 0, err
    assert "no steering channel" in out and "derived from the" in out
    metrics = pd.read_csv(tmp_path / "val" / "metrics.csv", keep_default_na=False)
    return path, logs, metrics


@pytest.mark.parametrize("fmt", ["mcap", pytest.param("ros1", marks=pytest.mark.slow),
                                 pytest.param("sqlite3", marks=pytest.mark.slow),
                                 pytest.param("ros2-mcap", marks=pytest.mark.slow)])
def test_bag_through_a_map_recovers_the_articulation(fmt, tmp_path, truth, unloaded):
    path, logs, metrics = run_format(fmt, tmp_path, truth, unloaded)
    bound = articulation_bound(truth, unloaded.flat()["f"])
    assert math.radians(0.1) < bound < math.radians(0.5)  # a bound that can fail
    covered = 0.0
    for lp in logs:
        log = read_run(lp)
        derived = log.meta["derived"]["channels"]
        assert "delta_h" in derived and log.meta["derived"]["steer_from"] == "yaw-rate"
        unit = 2 if fmt == "ros2-mcap" else 1
        assert {f"v_x_{unit}", f"v_y_{unit}", f"r_{unit}"} <= set(derived)
        assert {f"x_{3 - unit}", f"psi_{3 - unit}"} <= set(derived)  # the other unit
        run = read_run(tmp_path / "val" / "runs" / f"{lp.stem}.kin.parquet").frame
        # The import's clock starts at the first stamp read: the plant's t = 0 plus at
        # most the receive latency of 3 ms, i.e. at most 0.02 deg of articulation here.
        t = log.frame["t"].to_numpy()[: len(run)] + log.meta["segment"]["t0"]
        gamma = np.interp(t, truth["t"], truth["gamma"])
        assert len(run) == len(log.frame)  # KIN ran through the segment
        assert rms(run["gamma"] - gamma) < bound, (lp.stem, math.degrees(rms(run["gamma"]
                                                                             - gamma)))
        covered += t[-1] - t[0]
    # The gap (1.5 s) and the edges are all that is missing.
    assert truth["t"].iloc[-1] - 1.6 < covered < truth["t"].iloc[-1] - 1.5 + 0.05
    seg = metrics[metrics["segment"].str.contains("/")]
    pooled = metrics[metrics["segment"] == "pooled 2"]
    assert len(seg) == 2 and len(pooled) == 1 and pooled["status"].item() == "ok"
    assert pooled["log"].item() == path.stem
    # metrics.csv holds 6 significant digits
    assert pooled["s_max"].item() == pytest.approx(seg["s_max"].sum(), rel=1e-5)
    # Distance-weighted: the pooled RMS is the segments' RMS weighted by their distance.
    w = seg["s_max"] / seg["s_max"].sum()
    assert pooled["eps_y2"].item() == pytest.approx(
        math.sqrt(float(np.sum(w * seg["eps_y2"] ** 2))), rel=1e-5)
