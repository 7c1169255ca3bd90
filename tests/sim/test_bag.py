"""A short headless world recorded as a rosbag2 bag, read back with the MCAP libraries:
schemas, channels, counts per topic in simulation time, the transforms, metadata.yaml."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
import rclpy
import yaml
from geometry_msgs.msg import Twist
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rclpy.context import Context
from rclpy.node import Node
from std_msgs.msg import String

from sim import msgdefs
from sim.bag import BagRecorder
from sim.bridge import SimBridge
from sim.pacing import PacingPolicy
from sim.physics import World
from sim.worldfile import load_world

WALL = 20.0
TICKS, STEPS = 20, 20  # 20 ticks of 20 physics steps of 5 ms: 2 s of sim time
RECORDED = {"/clock": TICKS, "/odom": 100, "/tf": 100, "/scan": 20, "/tf_static": 1,
            "/cmd_vel": 1}


def _read(folder: Path) -> tuple[Any, list[tuple[str, Any, Any]], list[Any]]:
    """The summary, every (topic, message record, decoded message), the metadata records."""
    (path,) = folder.glob("*.mcap")
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        messages = [(channel.topic, message, decoded) for _, channel, message, decoded
                    in reader.iter_decoded_messages(log_time_order=True)]
        return reader.get_summary(), messages, list(reader.iter_metadata())


@pytest.fixture(scope="module")
def recorded(ros_domain: int, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """2 s of empty_room, stepped tick by tick, and one command on /cmd_vel."""
    folder = tmp_path_factory.mktemp("bags") / "run"
    context = Context()
    rclpy.init(context=context, domain_id=ros_domain)
    bridge = SimBridge(World(load_world("empty_room")), context,
                       policy=PacingPolicy(clock_hz=50.0))
    recorder = BagRecorder(folder, mount=(0.05, 0.0, math.pi / 2),
                           custom_data={"world": "empty_room"})
    bridge.add_tap(recorder)
    sender = Node("sender", context=context)
    publisher = sender.create_publisher(Twist, "/cmd_vel", 10)
    bridge.pause()
    bridge.start()
    try:
        assert bridge.wait_for(lambda: publisher.get_subscription_count() > 0, 1.0, WALL)
        command = Twist()
        command.linear.x = 0.2
        publisher.publish(command)
        assert bridge.wait_for(lambda: bridge.take_commands() > 0, 1.0, WALL)
        for _ in range(TICKS):
            bridge.step(STEPS)
    finally:
        bridge.stop()
        sender.destroy_node()
        rclpy.try_shutdown(context=context)
    assert recorder.close() == folder
    assert recorder.warnings() == []
    return folder


def test_schemas_are_ros2msg_with_their_dependencies(recorded: Path) -> None:
    summary, _, _ = _read(recorded)
    schemas = {s.name: s for s in summary.schemas.values()}
    assert set(schemas) == {"rosgraph_msgs/msg/Clock", "nav_msgs/msg/Odometry",
                            "sensor_msgs/msg/LaserScan", "geometry_msgs/msg/Twist",
                            msgdefs.TF_MESSAGE}
    assert {s.encoding for s in schemas.values()} == {"ros2msg"}
    tf_text = schemas[msgdefs.TF_MESSAGE].data.decode()
    assert tf_text.startswith("geometry_msgs/TransformStamped[] transforms\n")
    assert "=" * 80 + "\nMSG: geometry_msgs/TransformStamped\n" in tf_text
    assert "\nMSG: builtin_interfaces/Time\n" in schemas["nav_msgs/msg/Odometry"].data.decode()


def test_channels_carry_rosbag2_metadata(recorded: Path) -> None:
    summary, _, _ = _read(recorded)
    channels = {c.topic: c for c in summary.channels.values()}
    assert set(channels) == set(RECORDED)
    assert {c.message_encoding for c in channels.values()} == {"cdr"}
    odom = channels["/odom"]
    assert odom.metadata["topic_type_hash"] == msgdefs.type_hash("nav_msgs/msg/Odometry")
    assert odom.metadata["topic_type_hash"].startswith("RIHS01_")
    static = yaml.safe_load(channels["/tf_static"].metadata["offered_qos_profiles"])
    assert static[0]["durability"] == "transient_local"
    counts = {topic: summary.statistics.channel_message_counts[channel.id]
              for topic, channel in channels.items()}
    assert counts == RECORDED


def test_messages_are_stamped_in_sim_time(recorded: Path) -> None:
    _, messages, _ = _read(recorded)
    clocks = [m for topic, _, m in messages if topic == "/clock"]
    assert [c.clock.sec * 10**9 + c.clock.nanosec for c in clocks] == \
        [round(0.1 * 10**9) * (i + 1) for i in range(TICKS)]
    for topic, record, decoded in messages:
        assert record.log_time == record.publish_time
        if topic == "/scan":
            stamp = decoded.header.stamp
            assert record.log_time == stamp.sec * 10**9 + stamp.nanosec
            assert len(decoded.ranges) == 360
    (command,) = [m for topic, _, m in messages if topic == "/cmd_vel"]
    assert command.linear.x == pytest.approx(0.2)


def test_transforms_chain_odom_base_footprint_base_scan(recorded: Path) -> None:
    _, messages, _ = _read(recorded)
    (static,) = [m for topic, _, m in messages if topic == "/tf_static"]
    (mount,) = static.transforms
    assert (mount.header.frame_id, mount.child_frame_id) == ("base_footprint", "base_scan")
    assert mount.transform.translation.x == pytest.approx(0.05)
    assert mount.transform.rotation.z == pytest.approx(math.sin(math.pi / 4))
    odoms = [m for topic, _, m in messages if topic == "/odom"]
    tfs = [m.transforms[0] for topic, _, m in messages if topic == "/tf"]
    assert len(tfs) == len(odoms)
    for odom, tf in zip(odoms, tfs, strict=True):
        assert (tf.header.frame_id, tf.child_frame_id) == ("odom", "base_footprint")
        assert (tf.header.stamp.sec, tf.header.stamp.nanosec) == \
            (odom.header.stamp.sec, odom.header.stamp.nanosec)
        assert tf.transform.translation.x == odom.pose.pose.position.x
        assert tf.transform.rotation.w == odom.pose.pose.orientation.w


def test_metadata_yaml_matches_the_mcap(recorded: Path) -> None:
    summary, messages, records = _read(recorded)
    text = (recorded / "metadata.yaml").read_text()
    assert "&" not in text and "*" not in text  # no YAML anchors or aliases
    info = yaml.safe_load(text)["rosbag2_bagfile_information"]
    assert (info["version"], info["storage_identifier"], info["ros_distro"]) == (9, "mcap", "jazzy")
    assert info["relative_file_paths"] == ["run_0.mcap"]
    assert (recorded / "run_0.mcap").is_file()
    counts = {t["topic_metadata"]["name"]: t["message_count"]
              for t in info["topics_with_message_count"]}
    assert counts == RECORDED
    assert info["message_count"] == len(messages) == sum(RECORDED.values())
    times = [record.log_time for _, record, _ in messages]
    assert info["starting_time"]["nanoseconds_since_epoch"] == min(times)
    assert info["duration"]["nanoseconds"] == max(times) - min(times)
    assert info["files"][0]["message_count"] == info["message_count"]
    assert info["custom_data"] == {"world": "empty_room"}
    for topic in info["topics_with_message_count"]:
        meta = topic["topic_metadata"]
        assert meta["serialization_format"] == "cdr"
        assert meta["type_description_hash"].startswith("RIHS01_")
        assert meta["offered_qos_profiles"][0]["reliability"] == "reliable"
    (rosbag2,) = [r for r in records if r.name == "rosbag2"]
    assert yaml.safe_load(rosbag2.metadata["serialized_metadata"]) == info
    assert summary.statistics.message_count == info["message_count"]


def test_a_failing_message_stops_the_recording_not_the_caller(tmp_path: Path) -> None:
    recorder = BagRecorder(tmp_path / "bad")
    recorder("/chatter", "std_msgs/msg/String", String(data="kept"), 0.5)
    recorder("/chatter", "std_msgs/msg/String", object(), 0.6)  # cannot be serialized
    recorder("/chatter", "std_msgs/msg/String", String(data="after"), 0.7)
    assert recorder.problem is not None
    assert recorder.close() == tmp_path / "bad"
    (warning,) = recorder.warnings()
    assert "incomplete" in warning
    _, messages, _ = _read(tmp_path / "bad")
    assert [m.data for topic, _, m in messages if topic == "/chatter"] == ["kept"]


def test_past_its_size_limit_messages_are_counted_not_written(tmp_path: Path) -> None:
    recorder = BagRecorder(tmp_path / "big", max_bytes=4096)
    for i in range(100):
        recorder("/chatter", "std_msgs/msg/String", String(data="x" * 100), i * 0.1)
    recorder.close()
    assert 0 < recorder.dropped < 100
    (warning,) = recorder.warnings()
    assert str(recorder.dropped) in warning
    info = yaml.safe_load((tmp_path / "big" / "metadata.yaml").read_text())
    counts = Counter({t["topic_metadata"]["name"]: t["message_count"]
                      for t in info["rosbag2_bagfile_information"]["topics_with_message_count"]})
    assert counts["/chatter"] == 100 - recorder.dropped


def test_a_new_recording_replaces_the_old_one_in_its_folder(tmp_path: Path) -> None:
    for text in ("first", "second"):
        recorder = BagRecorder(tmp_path / "again")
        recorder("/chatter", "std_msgs/msg/String", String(data=text), 1.0)
        recorder.close()
    _, messages, _ = _read(tmp_path / "again")
    assert [m.data for topic, _, m in messages if topic == "/chatter"] == ["second"]


def test_a_command_after_the_last_tick_still_ends_the_recording(
        ros_domain: int, tmp_path: Path) -> None:
    """A node's stop sent as its run ends comes after the world's last tick: the bag and
    the replay's commands end with it, not with the command before (issue 31)."""
    from rclpy.duration import Duration

    context = Context()
    rclpy.init(context=context, domain_id=ros_domain)
    bridge = SimBridge(World(load_world("empty_room")), context,
                       policy=PacingPolicy(clock_hz=50.0))
    recorder = BagRecorder(tmp_path / "run", mount=(0.0, 0.0, 0.0))
    bridge.add_tap(recorder)
    sender = Node("sender", context=context)
    publisher = sender.create_publisher(Twist, "/cmd_vel", 10)
    bridge.pause()
    bridge.start()
    try:
        assert bridge.wait_for(lambda: publisher.get_subscription_count() > 0, 1.0, WALL)
        go = Twist()
        go.linear.x = 0.5
        publisher.publish(go)
        assert bridge.wait_for(lambda: bridge.take_commands() > 0, 1.0, WALL)
        bridge.step(STEPS)
        publisher.publish(Twist())  # the stop, after the last tick
        # Reliable: acknowledged means it is in the world's reader, untaken by any tick.
        assert publisher.wait_for_all_acked(Duration(seconds=WALL))
        stopped_at = bridge.now
    finally:
        bridge.stop()
        sender.destroy_node()
        rclpy.try_shutdown(context=context)
    assert recorder.close() == tmp_path / "run"
    _summary, messages, _metadata = _read(tmp_path / "run")
    commands = [(m.log_time, d.linear.x) for topic, m, d in messages if topic == "/cmd_vel"]
    assert commands[-1] == (round(stopped_at * 1e9), 0.0) and len(commands) == 2
    last = bridge.recording.commands[-1]
    assert (last.t, last.linear) == (stopped_at, 0.0)
