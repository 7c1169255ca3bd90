"""Recording the world's graph as a rosbag2 bag, the way ``ros2 bag record -s mcap`` on
ROS 2 Jazzy writes one: a folder holding ``metadata.yaml`` (format version 9) and
``<folder>_0.mcap`` (MCAP profile ``ros2``, ``ros2msg`` schemas, ``cdr`` messages, rosbag2's
channel metadata).  Foxglove and Lichtblick open the ``.mcap``; ``ros2 bag info`` and
``ros2 bag play`` take the folder.

:class:`BagWriter` writes topics and serialized messages.  :class:`BagRecorder` is the tap
the world's bridge (and the grader's probe) hand every message to, with its simulation
time, which becomes the message's log and publish time.  It also writes the transforms
rclpy's wheels cannot publish (tf2_msgs is not among them): ``odom -> base_footprint`` on
``/tf`` from each odometry message, and ``base_footprint -> base_scan`` (the lidar's
mount) once on ``/tf_static``.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from mcap.writer import CompressionType, Writer

from content.i18n import _, ngettext
from sim import msgdefs

# (topic, ROS type name, message, simulation time in seconds); a tap must not raise.
Tap = Callable[[str, str, Any, float], None]

VERSION = 9  # rosbag2's metadata format of ROS 2 Jazzy
LIBRARY = "rclpy-autograder sim.bag"
DEFAULT_MAX_BYTES = 512 * 1024 * 1024
_INFINITE = {"sec": 9223372036, "nsec": 854775807}  # RMW_DURATION_INFINITE


def qos(depth: int = 10, durability: str = "volatile") -> dict[str, Any]:
    """One offered QoS profile, as rosbag2 writes it from metadata version 9 on."""
    return {"history": "keep_last", "depth": depth, "reliability": "reliable",
            "durability": durability, "deadline": dict(_INFINITE),
            "lifespan": dict(_INFINITE), "liveliness": "automatic",
            "liveliness_lease_duration": dict(_INFINITE),
            "avoid_ros_namespace_conventions": False}


# What tf2's broadcasters offer: /tf_static is latched, so `ros2 bag play` republishes
# it transient-local and a node started late still gets it.
TF_QOS = qos(depth=100)
TF_STATIC_QOS = qos(depth=1, durability="transient_local")


class _Dumper(yaml.SafeDumper):
    """YAML as yaml-cpp writes it: a profile shared by two topics is written out twice,
    not as an anchor and an alias."""

    def ignore_aliases(self, data: Any) -> bool:
        return True


def _yaml(data: Any) -> str:
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False)


def nanoseconds(seconds: float) -> int:
    return max(0, round(seconds * 1e9))


@dataclass
class _Topic:
    name: str
    type: str
    qos: list[dict[str, Any]]
    channel: int
    count: int = 0

    def metadata(self) -> dict[str, Any]:
        return {"topic_metadata": {
            "name": self.name, "type": self.type, "serialization_format": "cdr",
            "offered_qos_profiles": self.qos,
            "type_description_hash": msgdefs.type_hash(self.type)},
            "message_count": self.count}


class BagWriter:
    """A rosbag2 folder with one MCAP file; an earlier recording in it is replaced."""

    def __init__(self, directory: Path, custom_data: Mapping[str, str] | None = None) -> None:
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        for old in (*self.directory.glob("*.mcap"), self.directory / "metadata.yaml"):
            old.unlink(missing_ok=True)
        self.file_name = f"{self.directory.name}_0.mcap"
        self.custom_data = dict(custom_data or {})
        self.topics: dict[str, _Topic] = {}
        self._schemas: dict[str, int] = {}
        self._times: list[int] = []  # first and last log time
        self._stream = (self.directory / self.file_name).open("wb")
        self._mcap = Writer(self._stream, compression=CompressionType.ZSTD)
        self._mcap.start(profile="ros2", library=LIBRARY)

    def add_topic(self, name: str, type_name: str, profile: dict[str, Any]) -> _Topic:
        """The topic's channel, made on first use (with its type's schema)."""
        topic = self.topics.get(name)
        if topic is not None:
            return topic
        schema = self._schemas.get(type_name)
        if schema is None:
            try:
                text = msgdefs.full_text(type_name)
            except msgdefs.DefinitionNotFound:
                schema = 0  # MCAP's "no schema": the messages stay, undecoded
            else:
                schema = self._mcap.register_schema(type_name, "ros2msg", text.encode())
            self._schemas[type_name] = schema
        profiles = [profile]
        channel = self._mcap.register_channel(name, "cdr", schema, {
            "offered_qos_profiles": _yaml(profiles),
            "topic_type_hash": msgdefs.type_hash(type_name)})
        topic = self.topics[name] = _Topic(name, type_name, profiles, channel)
        return topic

    def write(self, topic: _Topic, data: bytes, log_time: int) -> None:
        self._mcap.add_message(topic.channel, log_time=log_time, data=data,
                               publish_time=log_time)
        topic.count += 1
        self._times = [min(self._times[0], log_time), max(self._times[1], log_time)] \
            if self._times else [log_time, log_time]

    @property
    def message_count(self) -> int:
        return sum(t.count for t in self.topics.values())

    def metadata(self) -> dict[str, Any]:
        """``rosbag2_bagfile_information`` as rosbag2 Jazzy writes it."""
        start, end = self._times or [0, 0]
        span = {"starting_time": {"nanoseconds_since_epoch": start},
                "duration": {"nanoseconds": end - start}}
        return {
            "version": VERSION, "storage_identifier": "mcap",
            "duration": span["duration"], "starting_time": span["starting_time"],
            "message_count": self.message_count,
            "topics_with_message_count": [t.metadata() for t in self.topics.values()],
            "compression_format": "", "compression_mode": "",
            "relative_file_paths": [self.file_name],
            "files": [{"path": self.file_name, **span, "message_count": self.message_count}],
            "custom_data": self.custom_data or None, "ros_distro": "jazzy"}

    def close(self) -> Path:
        """Finish the MCAP file (with rosbag2's ``rosbag2`` metadata record, as its MCAP
        plugin writes it) and write ``metadata.yaml``; the folder's path."""
        info = self.metadata()
        try:
            self._mcap.add_metadata("rosbag2", {
                "serialized_metadata": _yaml(info)})
            self._mcap.finish()
        finally:
            self._stream.close()
        (self.directory / "metadata.yaml").write_text(
            _yaml({"rosbag2_bagfile_information": info}), encoding="utf-8")
        return self.directory


class BagRecorder:
    """A tap writing what it is handed into a :class:`BagWriter`, from any thread.

    It never raises into the world: the first failure stops the recording and is kept in
    ``problem``; past ``max_bytes`` of messages the rest are only counted (``dropped``).
    """

    def __init__(self, directory: Path, *, mount: tuple[float, float, float] = (0.0, 0.0, 0.0),
                 custom_data: Mapping[str, str] | None = None,
                 max_bytes: int = DEFAULT_MAX_BYTES) -> None:
        self._writer: BagWriter | None = BagWriter(directory, custom_data)
        self.directory = self._writer.directory
        self.mount = mount
        self.max_bytes = max_bytes
        self.problem: str | None = None
        self.dropped = 0
        self._bytes = 0
        self._lock = threading.Lock()
        self._tf_encoder: Callable[[Any], bytes] | None = None

    def __call__(self, topic: str, type_name: str, message: Any, sim_time: float) -> None:
        with self._lock:
            if self._writer is None or self.problem is not None:
                return
            try:
                self._record(self._writer, topic, type_name, message, nanoseconds(sim_time))
            except Exception as exc:  # a recording never stops the world
                self.problem = f"{type(exc).__name__}: {exc}"

    def counts(self) -> dict[str, int]:
        """Messages written so far, per topic."""
        with self._lock:
            writer = self._writer
            return {t.name: t.count for t in writer.topics.values()} if writer else {}

    def close(self) -> Path | None:
        """Finish the bag; its folder, or None if it was closed before or failed to close."""
        with self._lock:  # no write is under way once we hold it
            writer, self._writer = self._writer, None
        if writer is None:
            return None
        try:
            return writer.close()
        except Exception as exc:  # reported, never raised into a grading
            self.problem = self.problem or f"{type(exc).__name__}: {exc}"
            return None

    def warnings(self) -> list[str]:
        """What went wrong, for whoever asked for the recording (translated)."""
        found = []
        if self.problem is not None:
            found.append(_("The recording {path} is incomplete: {error}").format(
                path=self.directory, error=self.problem))
        if self.dropped:
            found.append(ngettext(
                "The recording {path} reached its size limit of {megabytes} MB; {count} "
                "later message is not in it.",
                "The recording {path} reached its size limit of {megabytes} MB; {count} "
                "later messages are not in it.", self.dropped).format(
                path=self.directory, megabytes=self.max_bytes // (1024 * 1024),
                count=self.dropped))
        return found

    # -- writing (under the lock) -------------------------------------------------------
    def _record(self, writer: BagWriter, topic: str, type_name: str, message: Any,
                stamp: int) -> None:
        if "/tf_static" not in writer.topics:
            self._write(writer, "/tf_static", msgdefs.TF_MESSAGE,
                        self._tf([self._mount_transform(stamp)]), stamp, TF_STATIC_QOS)
        data = message if isinstance(message, bytes) else _serialize(message)
        self._write(writer, topic, type_name, data, stamp, qos())
        if type_name == "nav_msgs/msg/Odometry":
            self._write(writer, "/tf", msgdefs.TF_MESSAGE,
                        self._tf([_odom_transform(message)]), stamp, TF_QOS)

    def _write(self, writer: BagWriter, topic: str, type_name: str, data: bytes, stamp: int,
               profile: dict[str, Any]) -> None:
        if self._bytes + len(data) > self.max_bytes:
            self.dropped += 1
            return
        self._bytes += len(data)
        writer.write(writer.add_topic(topic, type_name, profile), data, stamp)

    def _tf(self, transforms: list[dict[str, Any]]) -> bytes:
        if self._tf_encoder is None:
            # mcap_ros2's CDR encoder, made from the schema text (no tf2_msgs wheel).
            from mcap_ros2._dynamic import serialize_dynamic

            name = msgdefs.TF_MESSAGE
            self._tf_encoder = serialize_dynamic(name, msgdefs.full_text(name))[name]
        return self._tf_encoder({"transforms": transforms})

    def _mount_transform(self, stamp: int) -> dict[str, Any]:
        x, y, yaw = self.mount
        return _transform(stamp, "base_footprint", "base_scan", (x, y, 0.0),
                          (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))


def _serialize(message: Any) -> bytes:
    from rclpy.serialization import serialize_message

    return serialize_message(message)


def _transform(stamp: int, parent: str, child: str, xyz: tuple[float, float, float],
               rotation: tuple[float, float, float, float]) -> dict[str, Any]:
    return {"header": {"stamp": {"sec": stamp // 1_000_000_000,
                                 "nanosec": stamp % 1_000_000_000}, "frame_id": parent},
            "child_frame_id": child,
            "transform": {"translation": dict(zip("xyz", xyz, strict=True)),
                          "rotation": dict(zip("xyzw", rotation, strict=True))}}


def _odom_transform(odom: Any) -> dict[str, Any]:
    """The odometry's pose as the transform from its frame to its child frame."""
    stamp = odom.header.stamp
    p, q = odom.pose.pose.position, odom.pose.pose.orientation
    return _transform(stamp.sec * 1_000_000_000 + stamp.nanosec, odom.header.frame_id,
                      odom.child_frame_id, (p.x, p.y, p.z), (q.x, q.y, q.z, q.w))
