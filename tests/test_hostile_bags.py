"""Bags that lie: each is refused in one line naming the check and its evidence, or repaired
with a line saying so.

The logs are the rig's bags of ``bag_logs`` (a motion tracker's pose of one
unit and a hitch encoder, written with the readers' own writers) of a slalom
measured through the campaign's sensors, with one lie each, built here: a
flipped articulation sign or an encoder in radians declared as degrees with
either unit tracked, quaternions off unit length, mirrored tracks, positions in
millimetres declared as metres, header stamps a thousand times too far apart,
and a topic that dropped most of its messages.
"""

from __future__ import annotations

import io
import math
import re
from contextlib import redirect_stderr, redirect_stdout

import numpy as np
import pytest

pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")
pytest.importorskip("mcap_ros2", reason="mcap-ros2-support (test extra) is not installed")

from artic.validation.cli.commands import main  # noqa: E402
from artic.validation.logs.bags import QUATERNION_TOL  # noqa: E402
from artic.validation.logs.runfile import read_run  # noqa: E402
from tests import bag_logs  # noqa: E402


@pytest.fixture(scope="module")
def truth():
    """A measured 24 s slalom at 8 km/h (the hostile-input suite's), the bags' gap included."""
    from tests.hostile_logs import slalom

    return slalom().frame.iloc[:2400].reset_index(drop=True)


def artic(*argv) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def refused(tmp_path, path, text: str) -> str:
    """Import ``path`` through the map ``text``: one line, exit 2, nothing written."""
    chmap = tmp_path / "map.toml"
    chmap.write_text(text)
    out = tmp_path / "out"
    code, _, err = artic("logs", "import", path, "--channels", chmap, "--out-dir", out)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("artic: error: ") and "Traceback" not in err
    assert not out.exists() or not any(out.iterdir())
    return lines[0]


def imported(tmp_path, path, text: str) -> tuple[list, str]:
    chmap = tmp_path / "map.toml"
    chmap.write_text(text)
    out = tmp_path / "imported"
    code, so, err = artic("logs", "import", path, "--channels", chmap, "--out-dir", out)
    assert code == 0, err
    return [read_run(p) for p in sorted(out.glob("*.parquet"))], so


# ------------------------------------------------------------------ the articulation
@pytest.mark.parametrize("fmt", ["mcap", "ros2-mcap"])  # the tractor tracked; the semitrailer
def test_a_flipped_articulation_is_refused_whichever_unit_is_tracked(tmp_path, truth, fmt):
    path, text = bag_logs.write_log(fmt, tmp_path / "rig", truth)
    assert "scale = -1.0" in text
    line = refused(tmp_path, path, text.replace("scale = -1.0", "scale = 1.0"))
    assert "field data (for gamma" not in line  # the channel, not a neighbour
    assert re.search(r"channel .*/encoder/angle \(field data\), t = .*with the opposite sign "
                     r"\(RMS misfit .* rad as logged, .* rad mirrored", line), line
    assert "likely has its sign flipped" in line and "--accept articulation" in line
    unit = "semitrailer" if fmt == "ros2-mcap" else "tractor"
    assert f"driven by the {unit}'s speed and yaw rate" in line


def test_an_encoder_in_radians_declared_in_degrees_is_refused(tmp_path, truth):
    """The semitrailer tracked: the derived tractor's drive axle would slide sideways."""
    path, text = bag_logs.write_log("ros2-mcap", tmp_path / "rig", truth)
    assert 'field = "data", unit = "rad"' in text
    line = refused(tmp_path, path, text.replace('field = "data", unit = "rad"',
                                                'field = "data", unit = "deg"'))
    assert "the tractor's drive axle rolling along its heading" in line, line
    assert "/encoder/angle (field data) looks like radians where degrees are expected" in line


def test_an_encoder_writing_radians_to_a_degrees_map_is_refused_with_the_tractor_tracked(
        tmp_path, truth):
    """The mcap rig's map says degrees; its encoder writes radians: gamma 57 times small."""
    msgs = bag_logs.messages("mcap", truth)
    for topic, _, m, _ in msgs:
        if topic == "/encoder/angle":
            m.data = np.float32(math.radians(float(m.data)))
    path = bag_logs.write_messages("mcap", tmp_path / "rig", msgs)
    line = refused(tmp_path, path, bag_logs.channel_map("mcap"))
    assert "the kinematic trailer equation driven by the tractor's speed" in line, line
    assert "/encoder/angle (field data) looks like radians where degrees are expected" in line


# ------------------------------------------------------------------ quaternions
def _scaled_quaternions(truth, factor) -> list:
    msgs = bag_logs.messages("mcap", truth)
    for topic, _, m, _ in msgs:
        if topic == "/vive/pose":
            q = m.pose.orientation
            q.x, q.y, q.z, q.w = (factor * q.x, factor * q.y, factor * q.z, factor * q.w)
    return msgs


def test_quaternions_off_unit_length_are_normalised_with_a_line(tmp_path, truth):
    path = bag_logs.write_messages("mcap", tmp_path / "rig", _scaled_quaternions(truth, 2.0))
    runs, out = imported(tmp_path, path, bag_logs.channel_map("mcap"))
    assert re.search(r"topic /vive/pose, field pose\.orientation: quaternion check: 2\d{3} of "
                     r"2\d{3} quaternions have a norm from 2 to 2, not 1 \(within 0\.001\); "
                     "normalised", out), out
    # The heading is the truth's (within the tracker's noise), not 22.7 deg RMS off.
    run = runs[0]
    t = run.frame["t"].to_numpy() + run.meta["segment"]["t0"]
    err = run.frame["psi_1"] - np.interp(t, truth["t"], truth["psi_1"])
    assert float(np.sqrt(np.mean(err ** 2))) < math.radians(0.5)
    assert QUATERNION_TOL == 1e-3


def test_a_field_of_near_zero_quaternions_is_refused(tmp_path, truth):
    path = bag_logs.write_messages("mcap", tmp_path / "rig", _scaled_quaternions(truth, 0.01))
    line = refused(tmp_path, path, bag_logs.channel_map("mcap"))
    assert "topic /vive/pose (geometry_msgs/msg/PoseStamped), field pose.orientation" in line
    assert "quaternion check" in line and "norm from 0.01 to 0.01" in line, line
    assert "km/h" not in line  # the cause, not a consequence


# ------------------------------------------------------------------ mirrored tracks, units
MCAP = bag_logs.channel_map("mcap")
X = 'x_1 = { topic = "/vive/pose", field = "pose.position.x", unit = "m" }'
Y = 'y_1 = { topic = "/vive/pose", field = "pose.position.y", unit = "m" }'


SWAPPED = MCAP.replace(X, X.replace("position.x", "position.y")).replace(
    Y, Y.replace("position.y", "position.x"))
Y_FLIPPED = MCAP.replace(Y, Y.replace(" }", ", scale = -1.0 }"))


@pytest.mark.parametrize("fmt", ["mcap", "ros2-mcap"])  # the tractor tracked; the semitrailer
@pytest.mark.parametrize("case, text", [
    ("latitude and longitude (or x and y) swapped", SWAPPED),
    ("y (or latitude) with its sign flipped", Y_FLIPPED),
])
def test_a_mirrored_track_is_refused(tmp_path, truth, case, text, fmt):
    path, theirs = bag_logs.write_log(fmt, tmp_path / "rig", truth)
    if fmt == "ros2-mcap":  # the same lie in the semitrailer's map
        text = theirs.replace(X.replace("x_1", "x_2").replace("/vive", "/trailer"),
                              X.replace("x_1", "x_2").replace("/vive", "/trailer").replace(
                                  "position.x", "position.y") if "swapped" in case else
                              X.replace("x_1", "x_2").replace("/vive", "/trailer"))
        y2 = Y.replace("y_1", "y_2").replace("/vive", "/trailer")
        text = text.replace(y2, y2.replace("position.y", "position.x") if "swapped" in case
                            else y2.replace(" }", ", scale = -1.0 }"))
        assert text != theirs
    line = refused(tmp_path, path, text)
    where = "semitrailer's axle travels" if fmt == "ros2-mcap" else "tractor's drive axle travels"
    assert where in line and "off the direction its heading points" in line, line
    assert f"with {case.split(' (')[0]} undone, " in line, line
    assert f"{case} (a mirrored track)" in line, line
    assert "--accept axes" in line


def test_positions_in_millimetres_declared_as_metres_are_refused(tmp_path, truth):
    msgs = bag_logs.messages("mcap", truth)
    for topic, _, m, _ in msgs:
        if topic == "/vive/pose":  # the tracker writes millimetres
            m.pose.position.x *= 1000.0
            m.pose.position.y *= 1000.0
    path = bag_logs.write_messages("mcap", tmp_path / "rig_mm", msgs)
    in_mm = MCAP.replace(X, X.replace('"m"', '"mm"')).replace(Y, Y.replace('"m"', '"mm"'))
    runs, _ = imported(tmp_path, path, in_mm)  # declared as what they are: imported
    assert len(runs) == 2
    # A tracker writing metres, declared as millimetres: the tractor would turn on the spot.
    path, _ = bag_logs.write_log("mcap", tmp_path / "rig_m", truth)
    line = refused(tmp_path, path, in_mm)
    assert re.search(r"the tractor turns [\d.]+ rad while its sensor travels [\d.]+ m, "
                     r"[\d.]+ times tighter than its geometry allows \(a radius of", line)
    assert "look at least" in line and "times too small (millimetres or centimetres declared " \
        "as metres)" in line and "--accept turning" in line


@pytest.mark.parametrize("axis", ["x_1", "y_1"])
def test_one_coordinate_in_metres_declared_as_millimetres_is_refused(tmp_path, axis):
    """Issue 46, item 6(b): a docking log whose odometry x (in metres) was declared in
    millimetres was imported, the unit crawling along y at a third of its speed: it moves
    too little per window for the axes check to judge. The map is refused before reading."""
    from tests.hostile_logs import docking

    path, text = bag_logs.write_log("sqlite3", tmp_path / "rig", docking().frame)
    line = next(ln for ln in text.splitlines() if ln.startswith(axis + " "))
    line = refused(tmp_path, path, text.replace(line, line.replace('"m"', '"mm"')))
    first, second = ("mm", "m") if axis == "x_1" else ("m", "mm")
    assert f"channels.x_1 is in {first} and channels.y_1 in {second}: the two components " \
        "of one vector come in one unit" in line, line
    ratio = "0.001" if axis == "x_1" else "1000"
    assert f"(a {ratio} times larger x_1" in line, line
    assert "give x_1 and y_1 the unit the source writes" in line, line


# ------------------------------------------------------------------ stamps and rates
def test_header_stamps_a_thousand_times_apart_are_refused(tmp_path, truth):
    msgs = bag_logs.messages("mcap", truth)
    for topic, _, m, _ in msgs:
        if topic == "/vive/pose":  # stamps in microseconds written as nanoseconds ... x1000
            ns = (m.header.stamp.sec * 10 ** 9 + m.header.stamp.nanosec - bag_logs.T0_NS) * 1000
            ns += bag_logs.T0_NS
            m.header.stamp.sec, m.header.stamp.nanosec = ns // 10 ** 9, ns % 10 ** 9
    path = bag_logs.write_messages("mcap", tmp_path / "rig", msgs)
    line = refused(tmp_path, path, MCAP)
    assert re.search(r"topic /vive/pose \(geometry_msgs/msg/PoseStamped\), field "
                     r"pose\.position\.x: stamp check: its \d+ header stamps span 2\d{4} s "
                     r"but the bag received them over 2\d\.\d+ s, 1e\+03 times as long", line), line


def test_a_topic_that_dropped_most_messages_is_refused(tmp_path, truth):
    msgs = bag_logs.messages("mcap", truth)
    kept, k = [], 0
    for msg in msgs:
        if msg[0] == "/encoder/angle":
            k += 1
            if k % 200:  # 50 Hz: one message in 4 s is left
                continue
        kept.append(msg)
    path = bag_logs.write_messages("mcap", tmp_path / "rig", kept)
    line = refused(tmp_path, path, MCAP)
    assert re.search(r"/encoder/angle receive stamps: sample check: \d sample\(s\) over the "
                     r"[\d.]+ s from t = .* one per [\d.]+ s, where interpolation needs one per "
                     r"1 s at most", line), line


@pytest.mark.parametrize("source", ["header", "receive"])
def test_receive_stamps_reversed_against_the_header_stamps_are_refused(tmp_path, truth, source):
    # They were accepted (issue 46, item 6): with time = "receive" the log ran backwards.
    msgs = bag_logs.messages("mcap", truth)
    rx = [ns for topic, _, _, ns in msgs if topic == "/vive/pose"]
    first, last = min(rx), max(rx)
    msgs = sorted(((topic, typ, m, first + last - ns if topic == "/vive/pose" else ns)
                   for topic, typ, m, ns in msgs), key=lambda x: x[3])
    path = bag_logs.write_messages("mcap", tmp_path / "rig", msgs)
    text = MCAP if source == "header" else MCAP.replace('source = "header"',
                                                        'source = "receive"')
    assert f'source = "{source}"' in text
    line = refused(tmp_path, path, text)
    assert re.search(r"topic /vive/pose \(geometry_msgs/msg/PoseStamped\), field "
                     r"pose\.position\.[xy]: stamp check: its header stamps run backwards "
                     r"against the bag's receive times in 100 % of its \d+ steps", line), line
    assert "fix the bag's stamps" in line
