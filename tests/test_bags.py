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
import re
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")
pytest.importorskip("mcap_ros2", reason="mcap-ros2-support (test extra) is not installed")

from artic.plant import Plant  # noqa: E402
from artic.validation.cli.commands import main  # noqa: E402
from artic.validation.harness.simulate import simulate  # noqa: E402
from artic.validation.logs.runfile import read_run  # noqa: E402
from artic.validation.synthetic.manoeuvres import make_profile  # noqa: E402
from tests import bag_logs  # noqa: E402

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


def t_all(log) -> np.ndarray:
    """A segment's samples on the plant's clock [s]."""
    return log.frame["t"].to_numpy() + log.meta["segment"]["t0"]


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
        # Bursty stamps invent no rates: the derived yaw rates stay within the
        # differentiator's noise of the plant's (heading noise 0.05 deg at 100 Hz gives
        # about 1 mrad/s; the hitch's 0.03 deg at 50 Hz about 1.5 mrad/s more on r_2),
        # where differencing the raw stamps would give up to 0.05 deg / 0.1 ms = 9 rad/s.
        for c in ("r_1", "r_2"):
            err = log.frame[c].to_numpy() - np.interp(t_all(log), truth["t"], truth[c])
            assert rms(err) < 0.003 and np.max(np.abs(err)) < 0.02, (c, rms(err))
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
    for c in ("eps_y2", "eps_gamma"):
        assert pooled[c].item() == pytest.approx(
            math.sqrt(float(np.sum(w * seg[c] ** 2))), rel=1e-5)
    assert pooled["eps_gamma"].item() < bound


def test_the_readme_example(tmp_path, truth, unloaded):
    """docs/channels-bag-example.toml on the rig it describes, as the README runs it."""
    path, _, metrics = run_format("example", tmp_path, truth, unloaded)
    assert path.suffix == ".mcap"
    assert (metrics["segment"] == "pooled 2").sum() == 1
    assert (metrics["status"] == "ok").all()


# ------------------------------------------------------------------ hostile bags and maps
@pytest.fixture(scope="module")
def short_truth():
    """A measured 12 s slalom of the STM (the hostile-input suite's), gap included."""
    from tests.hostile_logs import slalom

    return slalom().frame.iloc[:1200].reset_index(drop=True)


MCAP_MAP = bag_logs.channel_map("mcap")
POSE_X = 'x_1 = { topic = "/vive/pose", field = "pose.position.x", unit = "m" }'

HOSTILE_MAPS = {
    "missing topic": (MCAP_MAP.replace('topic = "/encoder/angle"', 'topic = "/encoder/hitch"'),
                      r"topic /encoder/hitch \(field data, for gamma in .*\) is not in the bag"),
    "wrong field path": (MCAP_MAP.replace("pose.position.x", "pose.positon.x"),
                         r"topic /vive/pose .*field pose\.positon\.x .*no field 'positon' there; "
                         r"the message has position, orientation"),
    "not a field path": (MCAP_MAP.replace("pose.position.x", "pose..x]"),
                         r"topic /vive/pose, field 'pose\.\.x\]' .*not a field path"),
    "a message, not a number": (MCAP_MAP.replace("pose.position.x", "pose.position"),
                                r"field pose\.position .*not a number but a message with x, y, z"),
    "index out of range": (MCAP_MAP.replace("pose.position.x", "pose.position[3]"),
                           r"field pose\.position\[3\] .*no element 3"),
    "quaternion of a number": (MCAP_MAP.replace("pose.orientation", "pose.position.z"),
                               r"field pose\.position\.z .*unit quaternion needs a "
                               r"geometry_msgs/Quaternion"),
    "custom type, text field": (MCAP_MAP.replace(
        'gamma = { topic = "/encoder/angle", field = "data", unit = "deg", scale = -1.0',
        'gamma = { topic = "/diagnostics/rig", field = "state", unit = "deg", scale = -1.0'),
        r"topic /diagnostics/rig \(my_rig/msg/Diagnostics\), field state .*is text \('ok'\)"),
    "no header": (MCAP_MAP.replace(', time = "receive" }', " }"),
                  r"topic /encoder/angle \(std_msgs/msg/Float32\), field data: its messages have "
                  r'no header stamp; give gamma time = "receive"'),
    "CSV map for a bag": ('[time]\ncolumn = "t"\nunit = "s"\n[channels]\n'
                          'x_1 = { column = "X", unit = "m" }\ny_1 = { column = "Y", unit = "m" }\n'
                          'psi_1 = { column = "h", unit = "rad" }\n'
                          'gamma = { column = "g", unit = "rad" }\n',
                          r"the map names CSV columns .* but the log is a ROS bag"),
}


def _one_line(code: int, err: str) -> str:
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("artic: error: ") and "Traceback" not in err
    return lines[0]


@pytest.mark.parametrize("case", list(HOSTILE_MAPS))
def test_hostile_maps_give_one_line_with_file_topic_and_field(case, tmp_path, short_truth):
    path, _ = bag_logs.write_log("mcap", tmp_path / "rig", short_truth)
    text, expected = HOSTILE_MAPS[case]
    chmap = tmp_path / "map.toml"
    chmap.write_text(text)
    line = _one_line(*artic("logs", "import", path, "--channels", chmap, "--out-dir",
                            tmp_path / "out")[::2])
    assert re.search(expected, line), line
    assert str(path) in line or str(chmap) in line
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


@pytest.mark.parametrize("fmt", bag_logs.FORMATS)
def test_truncated_bags_give_one_line(fmt, tmp_path, short_truth):
    path, text = bag_logs.write_log(fmt, tmp_path / "rig", short_truth)
    target = path if path.is_file() else next(p for p in path.iterdir()
                                              if p.suffix in (".db3", ".mcap"))
    data = target.read_bytes()
    target.write_bytes(data[: len(data) * 2 // 3])
    chmap = tmp_path / "map.toml"
    chmap.write_text(text)
    line = _one_line(*artic("logs", "import", path, "--channels", chmap, "--out-dir",
                            tmp_path / "out")[::2])
    assert str(path) in line and "truncated or damaged" in line
    assert "field pose" in line and "topic /" in line  # what could not be read


def test_empty_topic_and_nan_runs(tmp_path, short_truth):
    from rosbags.rosbag2 import StoragePlugin, Writer

    msgs = bag_logs.messages("sqlite3", short_truth)
    ts = bag_logs._stores(False)
    path = tmp_path / "rig"
    with Writer(path, version=9, storage_plugin=StoragePlugin.SQLITE3) as w:
        conns = {}
        for topic, typ, m, ns in msgs:
            if topic not in conns:
                conns[topic] = w.add_connection(topic, typ, typestore=ts)
            if topic == "/encoder/angle":
                continue  # announced, never published
            w.write(conns[topic], ns, ts.serialize_cdr(m, typ))
    chmap = tmp_path / "map.toml"
    chmap.write_text(bag_logs.channel_map("sqlite3"))
    line = _one_line(*artic("logs", "import", path, "--channels", chmap, "--out-dir",
                            tmp_path / "out")[::2])
    assert re.search(r"topic /encoder/angle \(std_msgs/msg/Float64\), field data \(for gamma\): "
                     "no messages", line), line
    # NaN in a field: short runs interpolated and reported, a long one refused with the topic
    for n, ok in ((3, True), (60, False)):  # 50 Hz: 3 NaN span 0.08 s, under 0.1 s
        nan_path = tmp_path / f"nan{n}"
        with Writer(nan_path, version=9, storage_plugin=StoragePlugin.SQLITE3) as w:
            conns = {}
            k = 0
            for topic, typ, m, ns in msgs:
                if topic not in conns:
                    conns[topic] = w.add_connection(topic, typ, typestore=ts)
                if topic == "/encoder/angle":
                    k += 1
                    if 100 <= k < 100 + n:
                        m.data = math.nan
                w.write(conns[topic], ns, ts.serialize_cdr(m, typ))
        code, out, err = artic("logs", "import", nan_path, "--channels", chmap, "--out-dir",
                               tmp_path / f"out{n}")
        if ok:
            assert code == 0, err
            assert re.search(rf"channel /encoder/angle \(field data\): interpolated {n} "
                             "missing value", out), out
        else:
            line = _one_line(code, err)
            assert re.search(r"channel /encoder/angle \(field data\): 60 missing value", line)
            assert str(nan_path) in line


def test_unset_header_stamps_are_named(tmp_path, short_truth):
    msgs = bag_logs.messages("mcap", short_truth)
    for topic, _, m, _ in msgs:
        if topic == "/vive/pose":
            m.header.stamp.sec, m.header.stamp.nanosec = 0, 0
    path = bag_logs.write_messages("mcap", tmp_path / "rig", msgs)
    chmap = tmp_path / "map.toml"
    chmap.write_text(bag_logs.channel_map("mcap"))
    line = _one_line(*artic("logs", "import", path, "--channels", chmap, "--out-dir",
                            tmp_path / "out")[::2])
    assert re.search(r"topic /vive/pose \(geometry_msgs/msg/PoseStamped\), field "
                     r"pose\.position\.x: every header stamp is 0 s.*time = \"receive\"", line)


def test_a_bag_without_a_map_is_refused_with_the_fix(tmp_path, short_truth):
    path, _ = bag_logs.write_log("ros1", tmp_path / "rig", short_truth)
    line = _one_line(*artic("logs", "import", path, "--out-dir", tmp_path / "out")[::2])
    assert str(path) in line and "--channels MAP.toml" in line


def test_a_custom_type_with_its_definition_decodes(tmp_path, short_truth, unloaded):
    """The bag carries my_rig/msg/Diagnostics' definition: a map may read it."""
    from artic.validation.logs.bags import read_bag
    from artic.validation.logs.channelmap import read_map

    path, text = bag_logs.write_log("ros1", tmp_path / "rig", short_truth)
    chmap = tmp_path / "map.toml"
    chmap.write_text(text.replace(
        'gamma = { topic = "/joint_states", field = "position[hitch]", unit = "rad", '
        'scale = -1.0 }',
        'gamma = { topic = "/diagnostics/rig", field = "counters[0]", unit = "rad", '
        'time = "receive" }'))
    streams, lines = read_bag(path, read_map(chmap))
    diag = next(s for s in streams if s.name.startswith("/diagnostics/rig"))
    assert list(diag.raw.values())[0][:3].tolist() == [0.0, 1.0, 2.0]
    assert any("/joint_states (sensor_msgs/msg/JointState)" in line for line in lines)


def test_the_standard_types_decode(tmp_path, short_truth, unloaded):
    """NavSatFix (latitude and longitude to the local plane), Imu, TwistStamped, and header-less
    Pose, Twist and Float64, in one ROS 2 bag: every channel back as it went in."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    from artic.validation.logs.importers import import_runs
    from artic.validation.logs.oxts import radii

    f = short_truth.iloc[:800].reset_index(drop=True)  # before the gap of bag_logs
    ts = bag_logs._stores(False)
    ty = ts.types
    lat0, lon0 = math.radians(51.45), math.radians(5.39)
    M, N = radii(lat0)
    V3 = ty["geometry_msgs/msg/Vector3"]
    path = tmp_path / "std"
    with Writer(path, version=9, storage_plugin=StoragePlugin.SQLITE3) as w:
        conns = {}

        def put(topic, typ, msg, ns):
            if topic not in conns:
                conns[topic] = w.add_connection(topic, typ, typestore=ts)
            w.write(conns[topic], ns, ts.serialize_cdr(msg, typ))

        for k, row in f.iterrows():
            ns = bag_logs.T0_NS + k * 10_000_000
            h = bag_logs._header(ts, ns, "base")
            put("/gps/fix", "sensor_msgs/msg/NavSatFix", ty["sensor_msgs/msg/NavSatFix"](
                header=h, status=ty["sensor_msgs/msg/NavSatStatus"](status=2, service=1),
                latitude=math.degrees(lat0 + row.y_1 / M),
                longitude=math.degrees(lon0 + row.x_1 / (N * math.cos(lat0))), altitude=0.0,
                position_covariance=np.zeros(9), position_covariance_type=0), ns)
            put("/imu", "sensor_msgs/msg/Imu", ty["sensor_msgs/msg/Imu"](
                header=h, orientation=bag_logs._quat(ts, row.psi_1),
                orientation_covariance=np.zeros(9),
                angular_velocity=V3(x=0.0, y=0.0, z=row.r_1),
                angular_velocity_covariance=np.zeros(9),
                linear_acceleration=V3(x=0.0, y=0.0, z=9.81),
                linear_acceleration_covariance=np.zeros(9)), ns)
            put("/vel", "geometry_msgs/msg/TwistStamped", ty["geometry_msgs/msg/TwistStamped"](
                header=h, twist=ty["geometry_msgs/msg/Twist"](
                    linear=V3(x=row.v_x_1, y=row.v_y_1, z=0.0), angular=V3(x=0.0, y=0.0, z=0.0))),
                ns)
            put("/trailer/pose", "geometry_msgs/msg/Pose",
                bag_logs._pose(ts, row.x_2, row.y_2, row.psi_2), ns)
            put("/trailer/twist", "geometry_msgs/msg/Twist", ty["geometry_msgs/msg/Twist"](
                linear=V3(x=row.v_x_2, y=row.v_y_2, z=0.0), angular=V3(x=0.0, y=0.0, z=row.r_2)),
                ns)
            put("/steer", "std_msgs/msg/Float64", ty["std_msgs/msg/Float64"](data=row.delta_h),
                ns)
    chmap = tmp_path / "map.toml"
    chmap.write_text("""[time]
source = "header"
[channels]
delta_h = { topic = "/steer", field = "data", unit = "rad", time = "receive" }
x_1 = { topic = "/gps/fix", field = "longitude", unit = "longitude" }
y_1 = { topic = "/gps/fix", field = "latitude", unit = "latitude" }
psi_1 = { topic = "/imu", field = "orientation", unit = "quaternion" }
r_1 = { topic = "/imu", field = "angular_velocity.z", unit = "rad/s" }
v_x_1 = { topic = "/vel", field = "twist.linear.x", unit = "m/s" }
v_y_1 = { topic = "/vel", field = "twist.linear.y", unit = "m/s" }
x_2 = { topic = "/trailer/pose", field = "position.x", unit = "m", time = "receive" }
y_2 = { topic = "/trailer/pose", field = "position.y", unit = "m", time = "receive" }
psi_2 = { topic = "/trailer/pose", field = "orientation", unit = "quaternion", time = "receive" }
v_x_2 = { topic = "/trailer/twist", field = "linear.x", unit = "m/s", time = "receive" }
v_y_2 = { topic = "/trailer/twist", field = "linear.y", unit = "m/s", time = "receive" }
r_2 = { topic = "/trailer/twist", field = "angular.z", unit = "rad/s", time = "receive" }
""")
    (run,), report = import_runs(path, vehicle=unloaded, channels=chmap)
    assert "derived" not in run.meta and any("local east/north plane" in r for r in report)
    g = run.frame
    n = len(g)
    assert n == len(f)  # header and receive stamps coincide here: nothing trimmed
    # The local plane is the fix's tangent plane at the first fix; the truth's starts at 0.
    for c, tol in (("x_1", 1e-6), ("y_1", 1e-6)):
        np.testing.assert_allclose(g[c], f[c] - f[c].iloc[0], atol=tol, err_msg=c)
    for c in ("psi_1", "r_1", "v_x_1", "v_y_1", "x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2",
              "delta_h", "gamma"):
        np.testing.assert_allclose(g[c], f[c], atol=1e-9, err_msg=c)
