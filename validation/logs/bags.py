"""ROS 1 bags, ROS 2 bags (sqlite3 or MCAP storage) and MCAP files, read without ROS.

The reading is done by ``rosbags`` (``pip install artic[ros]``), a pure-Python
reader of every rosbag format with its own type store for the standard
messages: what ROS's own tools would need a ROS installation for. Only the
topics the channel map names are decoded; every other topic (images, custom
message types, ``/tf``) is skipped unread and listed in the import report.

A named topic decodes when its message type is standard (std_msgs,
geometry_msgs, nav_msgs, sensor_msgs, ...: the type store of ROS 1 Noetic
for a ``.bag``, of the latest ROS 2 release otherwise) or when the bag
carries its definition (ROS 1 bags and MCAP files always do, ROS 2 bags from
Iron on). The tested types: geometry_msgs Pose, PoseStamped, Twist,
TwistStamped; nav_msgs Odometry; sensor_msgs Imu, NavSatFix, JointState;
std_msgs Float32, Float64.

Each named (topic, time source) becomes one stream of samples
(:class:`artic.validation.logs.assemble.Stream`): the stamps [s] from the
first stamp read, and one array per channel, in the channel's SI unit after
``scale`` and ``offset``. A field path is dotted (``pose.pose.position.x``),
with ``[k]`` for an array element and ``[name]`` for the element of a
JointState (or any message with a ``name`` list) whose name is ``name``. A
``quaternion`` channel is the yaw ``atan2(2 (w z + x y), 1 - 2 (y**2 + z**2))``
of the quaternion at its path. A value that is missing in one message (a
joint not listed) is NaN, which the import interpolates over short runs or
refuses, naming the channel.

Every failure is one :class:`~artic.validation.logs.runfile.LogError` line
naming the file, the topic and the field: a missing or empty topic, a wrong
field path, a text field, a type that cannot be decoded, a truncated or
damaged file.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from artic.validation.logs.assemble import Stream
from artic.validation.logs.channelmap import ChannelMap, Entry
from artic.validation.logs.runfile import LogError

QUATERNION_TOL = 1e-3
"""Largest departure of a quaternion's norm from 1 taken as rounding [-]: a quaternion
stored as float32 and renormalised by its publisher is within 1e-6; one beyond 1e-3 was
scaled or built wrong, and is normalised with a line in the report."""

QUATERNION_MIN = 0.1
"""Least norm of a quaternion normalised [-]: below it (or beyond its inverse) the field is
no orientation but a value near zero or another quantity, and the log is refused."""

STAMP_RATIO = 10.0
"""Largest ratio of a topic's header-stamp span to its receive-time span (either way): a
replay at another rate or a recorder's buffering moves it by a factor of a few; header
stamps in another unit (milliseconds read as seconds) by a thousand."""

SUFFIXES = (".bag", ".mcap", ".db3")
"""File suffixes read as bags (and any folder with a ``metadata.yaml``)."""

_STEP = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[([^\]]+)\]")


def is_bag(path: Path) -> bool:
    """Whether ``path`` is a ROS 1 bag, a ROS 2 bag folder or file, or an MCAP file."""
    path = Path(path)
    return path.suffix in SUFFIXES or (path.is_dir() and (path / "metadata.yaml").is_file())


def _rosbags():
    try:
        import rosbags  # noqa: F401
    except ImportError as exc:  # pragma: no cover - the test extra installs it
        raise LogError("reading ROS bags and MCAP files needs the rosbags package: "
                       "pip install 'artic[ros]'") from exc
    from rosbags import rosbag1, rosbag2, typesys

    return rosbag1, rosbag2, typesys


def _repair_hint(path: Path) -> str:
    if path.suffix == ".bag":
        return "reindex it (rosbag reindex) or record it again"
    if path.suffix == ".mcap":
        return "recover it (mcap recover) or record it again"
    return "reindex it (ros2 bag reindex) or record it again"


def _parse(path: Path, entry: Entry, map_path: str) -> list[str | int]:
    steps: list[str | int] = []
    pos = 0
    text = entry.field or ""
    while pos < len(text):
        if text[pos] == "." and steps and pos + 1 < len(text):
            pos += 1
        m = _STEP.match(text, pos)
        if m is None:
            raise LogError(f"{path}: topic {entry.source}, field {text!r} (for {entry.channel} in "
                           f"{map_path}): not a field path; write it as pose.position.x, "
                           "position[0] or position[joint_name]")
        if m.group(1) is not None:
            steps.append(m.group(1))
        else:
            inner = m.group(2).strip()
            steps.append(int(inner) if re.fullmatch(r"-?\d+", inner) else f"[{inner}]")
        pos = m.end()
    return steps


def _wanted(chmap: ChannelMap) -> str:
    """The topics and fields a map reads, for messages about the whole file."""
    by: dict[str, list[str]] = {}
    for e in chmap.entries.values():
        by.setdefault(e.source, []).append(str(e.field))
    return ", ".join(f"topic {t} (field {', '.join(fs)})" for t, fs in by.items())


def _fields_of(obj: Any) -> str:
    names = [n for n in getattr(obj, "__dataclass_fields__", {}) if not n.startswith("__")]
    return ", ".join(names) if names else "none (it is a value)"


class _Field:
    """One channel's accessor into a decoded message."""

    def __init__(self, path: Path, entry: Entry, msgtype: str, map_path: str) -> None:
        self.path, self.entry, self.msgtype = path, entry, msgtype
        self.steps = _parse(path, entry, map_path)
        self.where = (f"{path}: topic {entry.source} ({msgtype}), field {entry.field} "
                      f"(for {entry.channel} in {map_path})")
        self.off_norm = (math.inf, 0.0, 0)  # quaternions off unit length: least, most norm, count

    def _walk(self, msg: Any, strict: bool) -> Any:
        node = msg
        for step in self.steps:
            if isinstance(step, str) and not step.startswith("["):
                if not hasattr(node, "__dataclass_fields__") or step.startswith("__") \
                        or step not in node.__dataclass_fields__:
                    raise LogError(f"{self.where}: no field {step!r} there; the message has "
                                   f"{_fields_of(node)}")
                node = getattr(node, step)
                continue
            if isinstance(step, str):  # [name]: by the message's name list
                names = list(getattr(msg, "name", []) or [])
                key = step[1:-1]
                if key not in names:
                    if strict:
                        raise LogError(f"{self.where}: no element named {key!r}; the message "
                                       f"names {', '.join(map(str, names)) or 'none'}")
                    return None
                step = names.index(key)
            try:
                node = node[step]
            except (IndexError, TypeError, KeyError):
                if strict:
                    raise LogError(f"{self.where}: no element {step} there ("
                                   f"{type(node).__name__} of length "
                                   f"{len(node) if hasattr(node, '__len__') else 0})") from None
                return None
        return node

    def value(self, msg: Any, strict: bool = False) -> float:
        """The channel's raw value in one message (yaw for a quaternion); NaN where absent."""
        node = self._walk(msg, strict)
        if node is None:
            return math.nan
        if self.entry.unit == "quaternion":
            try:
                x, y, z, w = (float(getattr(node, k)) for k in "xyzw")
            except (AttributeError, TypeError, ValueError):
                raise LogError(f"{self.where}: unit quaternion needs a geometry_msgs/Quaternion "
                               f"(x, y, z, w) there; it has {_fields_of(node)}") from None
            n2 = x * x + y * y + z * z + w * w
            if not math.isfinite(x * y * z * w) or n2 < 1e-12:
                return math.nan
            norm = math.sqrt(n2)
            if abs(norm - 1.0) > QUATERNION_TOL:
                self.off_norm = (min(self.off_norm[0], norm), max(self.off_norm[1], norm),
                                 self.off_norm[2] + 1)
            # the yaw of the normalised quaternion: each term carries the norm squared
            return math.atan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)
        if isinstance(node, str | bytes):
            raise LogError(f"{self.where}: is text ({str(node)[:20]!r}), not a number; name a "
                           "numeric field")
        if isinstance(node, bool | int | float | np.number):
            return float(node)
        if isinstance(node, np.ndarray) and node.size == 1:
            return float(node.reshape(-1)[0])
        raise LogError(f"{self.where}: is not a number but "
                       + (f"a message with {_fields_of(node)}" if hasattr(
                           node, "__dataclass_fields__") else f"{type(node).__name__}")
                       + "; extend the path to one of its numeric fields")


def _stamp(msg: Any) -> int | None:
    header = getattr(msg, "header", None)
    stamp = getattr(header, "stamp", None)
    if stamp is None:
        return None
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def read_bag(path: Path, chmap: ChannelMap) -> tuple[list, list[str]]:
    """The streams of the topics a channel map names, and the report's lines.

    Parameters
    ----------
    path : Path
        A ``.bag``, a ROS 2 bag folder (or its ``.db3``/``.mcap``), or an ``.mcap`` file.
    chmap : ChannelMap
        A bag map (topics and fields).

    Returns
    -------
    streams : list of Stream
        One per (topic, time source), times [s] from the earliest stamp read.
    lines : list of str
        What was left out or reordered.

    Raises
    ------
    LogError
        One line naming the file, the topic and the field.
    """
    rosbag1, rosbag2, typesys = _rosbags()
    path = Path(path)
    if not path.exists():
        raise LogError(f"{path}: no such file or folder")
    ros1 = path.suffix == ".bag"
    reader_errors = (rosbag1.ReaderError, rosbag2.ReaderError, typesys.TypesysError)
    try:
        reader = rosbag1.Reader(path) if ros1 else rosbag2.Reader(path)
        reader.open()
    except FileNotFoundError as exc:
        raise LogError(f"{path}: not a ROS bag ({exc}); give a .bag, an .mcap file or a ROS 2 "
                       "bag folder with its metadata.yaml") from exc
    except (*reader_errors, OSError, ValueError, KeyError, IndexError, EOFError) as exc:
        kind = "ROS 1 bag" if ros1 else "ROS 2 bag or MCAP file"
        raise LogError(f"{path}: not a readable {kind}; it may be truncated or damaged "
                       f"({' '.join(str(exc).split()) or type(exc).__name__}), so none of "
                       f"{_wanted(chmap)} can be read: {_repair_hint(path)}") from exc
    try:
        return _read(path, reader, chmap, ros1, typesys, reader_errors, Stream)
    finally:
        try:
            reader.close()
        except Exception:  # noqa: BLE001, S110 - closing a damaged reader; the error is raised
            pass


def _read(path, reader, chmap: ChannelMap, ros1: bool, typesys, reader_errors, Stream):
    by_topic: dict[str, list] = {}
    for c in reader.connections:
        by_topic.setdefault(c.topic, []).append(c)
    named: dict[str, list[Entry]] = {}
    for e in chmap.entries.values():
        named.setdefault(e.source, []).append(e)
    for topic, entries in named.items():
        if topic not in by_topic:
            have = ", ".join(f"{t} ({cs[0].msgtype})" for t, cs in sorted(by_topic.items()))
            raise LogError(f"{path}: topic {topic} (field {entries[0].field}, for "
                           f"{entries[0].channel} in {chmap.path}) is not in the bag; it has "
                           f"{have or 'no topics'}")
    lines = []
    skipped = [f"{t} ({cs[0].msgtype})" for t, cs in sorted(by_topic.items()) if t not in named]
    if skipped:
        lines.append(f"topic(s) not in the channel map, left out unread: {', '.join(skipped)}")
    base = typesys.get_typestore(typesys.Stores.ROS1_NOETIC if ros1 else typesys.Stores.LATEST)
    decoders = {}
    for topic in named:
        for conn in by_topic[topic]:
            decoders[conn.id] = _decoder(path, conn, base, ros1, typesys, named[topic])
    fields = {t: [(_Field(path, e, by_topic[t][0].msgtype, chmap.path)) for e in es]
              for t, es in named.items()}
    stamps: dict[str, list[int]] = {t: [] for t in named}
    receive: dict[str, list[int]] = {t: [] for t in named}
    values: dict[str, list[list[float]]] = {t: [[] for _ in named[t]] for t in named}
    conns = [c for t in named for c in by_topic[t]]
    count = dict.fromkeys(named, 0)
    last = None
    try:
        for conn, ts, raw in reader.messages(connections=conns):
            topic = conn.topic
            last = topic
            try:
                msg = decoders[conn.id](raw)
            except Exception as exc:  # noqa: BLE001 - rosbags raises several kinds here
                e = named[topic][0]
                raise LogError(f"{path}: topic {topic} ({conn.msgtype}), field {e.field}: "
                               f"message {count[topic]} cannot be decoded "
                               f"({' '.join(str(exc).split())}); the file may be damaged: "
                               f"{_repair_hint(path)}") from exc
            strict = count[topic] == 0
            for k, f in enumerate(fields[topic]):
                values[topic][k].append(f.value(msg, strict))
            stamps[topic].append(_stamp(msg) if msg is not None else None)
            receive[topic].append(int(ts))
            count[topic] += 1
    except LogError:
        raise
    except (*reader_errors, OSError, ValueError, KeyError, IndexError, EOFError,
            AssertionError) as exc:
        where = f" after {count[last]} message(s) of topic {last}" if last else ""
        raise LogError(f"{path}: truncated or damaged{where} "
                       f"({' '.join(str(exc).split()) or type(exc).__name__}) while reading "
                       f"{_wanted(chmap)}: {_repair_hint(path)}") from exc
    for topic, fs in fields.items():
        for f in fs:
            lo, hi, n = f.off_norm
            if not n:
                continue
            if lo < QUATERNION_MIN or hi > 1.0 / QUATERNION_MIN:
                raise LogError(f"{f.where}: quaternion check: {n} of {count[topic]} "
                               f"quaternions have a norm from {lo:.3g} to {hi:.3g}, not 1 "
                               f"(within {QUATERNION_TOL:g}); beyond {QUATERNION_MIN:g} to "
                               f"{1.0 / QUATERNION_MIN:g} the field is no orientation: name "
                               "the orientation quaternion")
            lines.append(f"topic {topic}, field {f.entry.field}: quaternion check: {n} of "
                         f"{count[topic]} quaternions have a norm from {lo:.4g} to {hi:.4g}, "
                         f"not 1 (within {QUATERNION_TOL:g}); normalised before their yaw "
                         "was taken")
    for topic, entries in named.items():
        if not count[topic]:
            raise LogError(f"{path}: topic {topic} ({by_topic[topic][0].msgtype}), field "
                           f"{entries[0].field} (for {entries[0].channel}): no messages; the "
                           "topic is empty in this bag")
    streams = []
    t_first = None
    raw_streams = []
    for topic, entries in named.items():
        for source in ("header", "receive"):
            idx = [k for k, e in enumerate(entries) if (e.time or chmap.time_source) == source]
            if not idx:
                continue
            if source == "header":
                if any(s is None for s in stamps[topic]):
                    e = entries[idx[0]]
                    raise LogError(
                        f"{path}: topic {topic} ({by_topic[topic][0].msgtype}), field "
                        f"{e.field}: its messages have no header stamp; give {e.channel} "
                        f'time = "receive" in {chmap.path}, or [time] source = "receive"')
                ns = np.asarray(stamps[topic], dtype=np.int64)
                if ns.size > 1 and np.all(ns == ns[0]):
                    e = entries[idx[0]]
                    raise LogError(
                        f"{path}: topic {topic} ({by_topic[topic][0].msgtype}), field "
                        f"{e.field}: every header stamp is {ns[0] * 1e-9:.9g} s, so its "
                        f'publisher does not set them; give {e.channel} time = "receive" in '
                        f"{chmap.path}")
                _check_stamps(path, topic, by_topic[topic][0].msgtype, entries[idx[0]], ns,
                              np.asarray(receive[topic], dtype=np.int64), chmap.path)
            else:
                ns = np.asarray(receive[topic], dtype=np.int64)
                if stamps[topic] and all(s is not None for s in stamps[topic]):
                    header = np.asarray(stamps[topic], dtype=np.int64)  # compared, unused
                    if header.size > 1 and not np.all(header == header[0]):
                        _check_order(path, topic, by_topic[topic][0].msgtype,
                                     entries[idx[0]], header, ns)
            raw_streams.append((topic, source, ns, [entries[k] for k in idx],
                                [np.asarray(values[topic][k], dtype=float) for k in idx]))
            m = int(ns.min())
            t_first = m if t_first is None else min(t_first, m)
    for topic, source, ns, entries, vals in raw_streams:
        order = np.argsort(ns, kind="stable")
        if np.any(order != np.arange(ns.size)):
            moved = int(np.sum(order != np.arange(ns.size)))
            lines.append(f"topic {topic}: {moved} message(s) out of order by their {source} "
                         "stamps, sorted by them")
        t = (ns[order] - t_first) * 1e-9
        streams.append(Stream(
            name=f"{topic} {source} stamps",
            t=t,
            raw={e.label: v[order] for e, v in zip(entries, vals, strict=True)},
            entries=entries))
    return streams, lines


STAMP_BACKWARDS = 0.25
"""Largest share of a topic's steps, in receive order, whose header stamp goes back: a bursty
link delivers some messages out of order (they are sorted by the stamps used), but receive
times that run against the header stamps for most steps are reversed."""


def _check_stamps(path: Path, topic: str, msgtype: str, e: Entry, header: np.ndarray,
                  receive: np.ndarray, map_path: str) -> None:
    """Refuse header stamps spread over another span than the receive times (another unit).

    Raises
    ------
    LogError
        Naming the topic, both spans and the factor.
    """
    if header.size < 3:
        return
    _check_order(path, topic, msgtype, e, header, receive)
    span_h = float(header.max() - header.min()) * 1e-9
    span_r = float(receive.max() - receive.min()) * 1e-9
    if span_r <= 0.0 or span_h <= 0.0:
        return
    ratio = span_h / span_r
    if 1.0 / STAMP_RATIO <= ratio <= STAMP_RATIO:
        return
    raise LogError(f"{path}: topic {topic} ({msgtype}), field {e.field}: stamp check: its "
                   f"{header.size} header stamps span {span_h:.6g} s but the bag received "
                   f"them over {span_r:.6g} s, {ratio:.3g} times as long (more than "
                   f"{STAMP_RATIO:g} either way); its publisher's stamps are in another unit "
                   f'or clock: give {e.channel} time = "receive" in {map_path}')


def _check_order(path: Path, topic: str, msgtype: str, e: Entry, header: np.ndarray,
                 receive: np.ndarray) -> None:
    """Refuse header stamps that run backwards against the receive times.

    Raises
    ------
    LogError
        Naming the topic and the share of its steps that go back
        (beyond :data:`STAMP_BACKWARDS`).
    """
    if header.size < 3:
        return
    back = float(np.mean(np.diff(header[np.argsort(receive, kind="stable")]) < 0))
    if back > STAMP_BACKWARDS:
        raise LogError(f"{path}: topic {topic} ({msgtype}), field {e.field}: stamp check: "
                       f"its header stamps run backwards against the bag's receive times in "
                       f"{100.0 * back:.0f} % of its {header.size - 1} steps (at most "
                       f"{100.0 * STAMP_BACKWARDS:.0f} % expected of a bursty link): one of "
                       "the two clocks runs backwards (a bag rewritten in reverse, a stamp's "
                       "sign); the log cannot say which runs forward: fix the bag's stamps")


def _decoder(path: Path, conn, base, ros1: bool, typesys, entries: list[Entry]) -> Callable:
    """A function decoding the raw messages of one connection.

    The bag's own definition of the type is preferred (the data were written
    with it); without one, the standard type store's.
    """
    msgtype = conn.msgtype
    data = getattr(conn.msgdef, "data", "") or ""
    store = None
    problem = "which the bag does not define and artic does not know"
    if data:
        try:
            store = typesys.get_typestore(typesys.Stores.EMPTY)
            sep = "=" * 80 + "\n"
            if data.startswith(sep + "IDL: "):
                for part in data.split(sep)[1:]:
                    store.register(typesys.get_types_from_idl(part.split("\n", 1)[1]))
            elif data.lstrip().startswith(("module ", "#include")):
                store.register(typesys.get_types_from_idl(data))
            else:
                store.register(typesys.get_types_from_msg(data, msgtype))
            if msgtype not in store.types:
                raise KeyError(msgtype)
        except Exception as exc:  # noqa: BLE001 - the parsers raise several kinds
            store = None
            problem = ("whose definition in the bag cannot be read "
                       f"({' '.join(str(exc).split())})")
    if store is None and msgtype in base.types:
        store = base
    if store is None:
        raise LogError(f"{path}: topic {conn.topic} is of type {msgtype} (field "
                       f"{entries[0].field}, for {entries[0].channel}), {problem}; name a "
                       "topic of a standard type")
    if ros1:
        return lambda raw: store.deserialize_ros1(raw, msgtype)
    return lambda raw: store.deserialize_cdr(raw, msgtype)
