"""Plant runs written as ROS bags and MCAP files by the readers' own writers, as rigs record them.

``write_log(fmt, path, truth)`` samples a run of the plant as a rig's
topics: a motion tracker's pose of one unit (no velocities, no yaw rate),
a hitch encoder, and a diagnostics topic of a custom message type, with no
steering channel. The messages carry small sensor noise; a stretch of
:data:`GAP` seconds is missing from every topic; the receive stamps are
bursty (:data:`BURST_SHARE` of the intervals under 1 ms: messages delivered
late, together with the next). Formats:

- ``"ros1"``: a ROS 1 ``.bag`` (rosbags' writer): tractor ``PoseStamped`` at
  100 Hz, a ``JointState`` hitch at 50 Hz, header stamps;
- ``"sqlite3"``: a ROS 2 bag with sqlite3 storage: tractor ``nav_msgs/Odometry``
  (pose only; its twist left at zero, unmapped) at 100 Hz and a
  ``Float64`` encoder, receive stamps throughout (the bursty ones);
- ``"ros2-mcap"``: a ROS 2 bag with MCAP storage tracking the *semitrailer*
  (``PoseStamped``) and a ``Float64`` encoder at its receive time;
- ``"mcap"``: a bare ``.mcap`` file (the ``mcap`` library's ROS 2 writer):
  tractor ``PoseStamped`` and a ``Float32`` encoder in degrees;
- ``"example"``: the same with a ``Float64`` encoder in radians, the layout of
  ``docs/channels-bag-example.toml``.

Each comes with its channel map (TOML text).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

T0_NS = 1_700_000_000 * 10 ** 9
"""The rig's clock at the run's start [ns]."""

GAP = (9.0, 10.5)
"""Seconds of the run missing from every topic (1.5 s)."""

BURST_SHARE = 0.09
"""Share of the receive intervals under 1 ms."""

POS_SIGMA = 0.002
"""Motion-tracker position noise [m]."""

YAW_SIGMA = math.radians(0.05)
"""Motion-tracker heading noise [rad] (an optical tracker's)."""

HITCH_SIGMA = math.radians(0.03)
"""Hitch-encoder noise [rad]: a 12-bit absolute encoder's quantisation (0.088 deg steps)."""

CUSTOM = "float64 battery\nstring state\nuint32[] counters\n"
"""The definition of the rig's own diagnostics message, my_rig/msg/Diagnostics."""

FORMATS = ("ros1", "sqlite3", "ros2-mcap", "mcap")


def _stores(ros1: bool):
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.LATEST)
    ts.register(get_types_from_msg(CUSTOM, "my_rig/msg/Diagnostics"))
    return ts


def _sample(truth: pd.DataFrame, rate: float, rng) -> np.ndarray:
    """True sample times [s] at ``rate``, without the gap."""
    t = np.arange(0.0, float(truth["t"].iloc[-1]) + 1e-9, 1.0 / rate)
    return t[(t < GAP[0]) | (t > GAP[1])]


def bursty(t: np.ndarray, rng, latency: float = 0.003) -> np.ndarray:
    """Receive stamps [s]: a latency, and :data:`BURST_SHARE` of the messages held back
    and delivered within 1 ms after the next one's predecessor."""
    rx = t + latency
    k = rng.choice(np.arange(1, t.size), size=int(round(BURST_SHARE * (t.size - 1))),
                   replace=False)
    k.sort()
    for i in k:  # delivered just after the previous one: an interval under 1 ms
        rx[i] = rx[i - 1] + rng.uniform(1e-4, 9e-4)
    return rx


def _quat(ts, yaw: float):
    Q = ts.types["geometry_msgs/msg/Quaternion"]
    return Q(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def _header(ts, ns: int, frame: str):
    H, T = ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    stamp = T(sec=ns // 10 ** 9, nanosec=ns % 10 ** 9)
    if "seq" in H.__dataclass_fields__:
        return H(seq=0, stamp=stamp, frame_id=frame)
    return H(stamp=stamp, frame_id=frame)


def _pose(ts, x: float, y: float, yaw: float):
    P, Pt = ts.types["geometry_msgs/msg/Pose"], ts.types["geometry_msgs/msg/Point"]
    return P(position=Pt(x=x, y=y, z=0.0), orientation=_quat(ts, yaw))


def messages(fmt: str, truth: pd.DataFrame, seed: int = 0):
    """The rig's messages: (topic, type, message, receive time [ns]), in receive order."""
    rng = np.random.default_rng(seed)
    ts = _stores(fmt == "ros1")
    unit = 2 if fmt == "ros2-mcap" else 1
    out = []
    tp = _sample(truth, 100.0, rng)
    rx = bursty(tp, rng)
    tt = truth["t"].to_numpy()
    x = np.interp(tp, tt, truth[f"x_{unit}"]) + rng.normal(0, POS_SIGMA, tp.size)
    y = np.interp(tp, tt, truth[f"y_{unit}"]) + rng.normal(0, POS_SIGMA, tp.size)
    yaw = np.interp(tp, tt, truth[f"psi_{unit}"]) + rng.normal(0, YAW_SIGMA, tp.size)
    for k in range(tp.size):
        ns_true, ns_rx = T0_NS + int(tp[k] * 1e9), T0_NS + int(rx[k] * 1e9)
        if fmt == "sqlite3":
            g = ts.types
            Odo, PwC = g["nav_msgs/msg/Odometry"], g["geometry_msgs/msg/PoseWithCovariance"]
            TwC, Tw = g["geometry_msgs/msg/TwistWithCovariance"], g["geometry_msgs/msg/Twist"]
            V3 = g["geometry_msgs/msg/Vector3"]
            m = Odo(header=_header(ts, ns_true, "odom"), child_frame_id="base_link",
                  pose=PwC(pose=_pose(ts, x[k], y[k], yaw[k]), covariance=np.zeros(36)),
                  twist=TwC(twist=Tw(linear=V3(x=0.0, y=0.0, z=0.0),
                                     angular=V3(x=0.0, y=0.0, z=0.0)), covariance=np.zeros(36)))
            out.append(("/odom", "nav_msgs/msg/Odometry", m, ns_rx))
        else:
            PS = ts.types["geometry_msgs/msg/PoseStamped"]
            topic = "/trailer/pose" if unit == 2 else "/vive/pose"
            m = PS(header=_header(ts, ns_true, "map"), pose=_pose(ts, x[k], y[k], yaw[k]))
            out.append((topic, "geometry_msgs/msg/PoseStamped", m, ns_rx))
    te = _sample(truth, 50.0, rng)
    rxe = bursty(te, rng, latency=0.001)
    g = np.interp(te, tt, truth["gamma"]) + rng.normal(0, HITCH_SIGMA, te.size)
    for k in range(te.size):
        ns_true, ns_rx = T0_NS + int(te[k] * 1e9), T0_NS + int(rxe[k] * 1e9)
        if fmt == "ros1":
            J = ts.types["sensor_msgs/msg/JointState"]
            m = J(header=_header(ts, ns_true, "hitch"), name=["steer_dummy", "hitch"],
                  position=np.array([0.0, -g[k]]), velocity=np.zeros(2), effort=np.zeros(2))
            out.append(("/joint_states", "sensor_msgs/msg/JointState", m, ns_rx))
        elif fmt == "mcap":  # Float32 in degrees
            F = ts.types["std_msgs/msg/Float32"]
            out.append(("/encoder/angle", "std_msgs/msg/Float32", F(data=-math.degrees(g[k])),
                        ns_rx))
        else:
            F = ts.types["std_msgs/msg/Float64"]
            out.append(("/encoder/angle", "std_msgs/msg/Float64", F(data=-g[k]), ns_rx))
    D = ts.types["my_rig/msg/Diagnostics"]
    for k, t in enumerate(_sample(truth, 5.0, rng)):
        out.append(("/diagnostics/rig", "my_rig/msg/Diagnostics",
                    D(battery=12.0 - 0.01 * k, state="ok",
                      counters=[k] if fmt in ("mcap", "example") else np.array([k], np.uint32)),
                    T0_NS + int(t * 1e9)))
    out.sort(key=lambda m: m[3])
    return out


def write_log(fmt: str, path: Path, truth: pd.DataFrame, seed: int = 0) -> tuple[Path, str]:
    """Write the rig's log of ``truth`` in ``fmt``; returns the log's path and its map."""
    return write_messages(fmt, path, messages(fmt, truth, seed)), channel_map(fmt)


def write_messages(fmt: str, path: Path, msgs: list) -> Path:
    """Write ``messages(fmt, ...)`` (or an edited copy) as ``fmt``; returns the path."""
    ts = _stores(fmt == "ros1")
    path = Path(path)
    if fmt == "ros1":
        from rosbags.rosbag1 import Writer

        path = path.with_suffix(".bag")
        with Writer(path) as w:
            conns = {}
            for topic, typ, m, ns in msgs:
                if topic not in conns:
                    conns[topic] = w.add_connection(topic, typ, typestore=ts)
                w.write(conns[topic], ns, ts.serialize_ros1(m, typ))
    elif fmt in ("sqlite3", "ros2-mcap"):
        from rosbags.rosbag2 import StoragePlugin, Writer

        plugin = StoragePlugin.SQLITE3 if fmt == "sqlite3" else StoragePlugin.MCAP
        with Writer(path, version=9, storage_plugin=plugin) as w:
            conns = {}
            for topic, typ, m, ns in msgs:
                if topic not in conns:
                    conns[topic] = w.add_connection(topic, typ, typestore=ts)
                w.write(conns[topic], ns, ts.serialize_cdr(m, typ))
    else:
        from mcap_ros2.writer import Writer

        path = path.with_suffix(".mcap")  # "mcap" and "example"
        with path.open("wb") as f:
            w = Writer(f)
            schemas = {}
            for topic, typ, m, ns in msgs:
                if typ not in schemas:
                    text, _ = ts.generate_msgdef(typ, ros_version=2)
                    schemas[typ] = w.register_msgdef(typ, text)
                w.write_message(topic, schemas[typ], m, log_time=ns, publish_time=ns)
            w.finish()
    return path


def channel_map(fmt: str) -> str:
    """The channel map of ``fmt``'s log (TOML)."""
    if fmt == "example":
        return (Path(__file__).resolve().parents[1] / "docs"
                / "channels-bag-example.toml").read_text()
    if fmt == "ros1":
        return """[time]
source = "header"
max_gap = 0.3

[channels]
x_1 = { topic = "/vive/pose", field = "pose.position.x", unit = "m" }
y_1 = { topic = "/vive/pose", field = "pose.position.y", unit = "m" }
psi_1 = { topic = "/vive/pose", field = "pose.orientation", unit = "quaternion" }
gamma = { topic = "/joint_states", field = "position[hitch]", unit = "rad", scale = -1.0 }
"""
    if fmt == "sqlite3":
        return """[time]
source = "receive"

[derive]
window = 0.5

[channels]
x_1 = { topic = "/odom", field = "pose.pose.position.x", unit = "m" }
y_1 = { topic = "/odom", field = "pose.pose.position.y", unit = "m" }
psi_1 = { topic = "/odom", field = "pose.pose.orientation", unit = "quaternion" }
gamma = { topic = "/encoder/angle", field = "data", unit = "rad", scale = -1.0 }
"""
    if fmt == "ros2-mcap":
        return """[time]
source = "header"

[channels]
x_2 = { topic = "/trailer/pose", field = "pose.position.x", unit = "m" }
y_2 = { topic = "/trailer/pose", field = "pose.position.y", unit = "m" }
psi_2 = { topic = "/trailer/pose", field = "pose.orientation", unit = "quaternion" }
gamma = { topic = "/encoder/angle", field = "data", unit = "rad", scale = -1.0, time = "receive" }
"""
    return """[time]
source = "header"

[channels]
x_1 = { topic = "/vive/pose", field = "pose.position.x", unit = "m" }
y_1 = { topic = "/vive/pose", field = "pose.position.y", unit = "m" }
psi_1 = { topic = "/vive/pose", field = "pose.orientation", unit = "quaternion" }
gamma = { topic = "/encoder/angle", field = "data", unit = "deg", scale = -1.0, time = "receive" }
"""
