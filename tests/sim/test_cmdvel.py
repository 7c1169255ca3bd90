"""/cmd_vel as Jazzy robots take it: a TwistStamped world drives on TwistStamped, names a
Twist publisher it cannot hear, and ``sim run`` says so once."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import rclpy
from click.testing import CliRunner
from geometry_msgs.msg import Twist, TwistStamped
from rclpy.context import Context
from rclpy.node import Node

import sim.cli
from sim.bridge import SimBridge
from sim.cmdvel import Mismatch, full_name, twist_of, type_name, world_warning
from sim.pacing import PacingPolicy
from sim.physics import World
from sim.worldfile import load_world

WALL = 20.0  # generous wall-clock deadline for any one condition


@dataclass
class Graph:
    bridge: SimBridge
    driver: Node


@pytest.fixture(scope="module")
def world(ros_domain: int) -> Iterator[SimBridge]:
    ctx = Context()
    rclpy.init(context=ctx, domain_id=ros_domain)
    bridge = SimBridge(World(load_world("empty_room")), ctx, real_time_factor=2.0,
                       policy=PacingPolicy(clock_hz=50.0), cmd_vel_type="TwistStamped")
    bridge.start()
    try:
        yield bridge
    finally:
        bridge.stop()
        rclpy.try_shutdown(context=ctx)


@pytest.fixture
def graph(world: SimBridge, ros_domain: int) -> Iterator[Graph]:
    """The world and a node in a participant of its own, as a student's process is (one
    participant cannot hold a topic with two types, even one after the other)."""
    ctx = Context()
    rclpy.init(context=ctx, domain_id=ros_domain)
    driver = Node("driver", context=ctx)
    try:
        yield Graph(world, driver)
    finally:
        driver.destroy_node()
        rclpy.try_shutdown(context=ctx)


def test_type_names_are_the_graphs() -> None:
    assert type_name(Twist) == full_name("Twist") == "geometry_msgs/msg/Twist"
    assert full_name("TwistStamped") == "geometry_msgs/msg/TwistStamped"
    stamped = TwistStamped()
    stamped.twist.linear.x = 0.2
    assert twist_of(stamped).linear.x == 0.2
    plain = Twist()
    assert twist_of(plain) is plain


def test_the_world_file_sets_the_type_and_the_bridge_can_override_it(graph: Graph) -> None:
    assert load_world("empty_room").cmd_vel_type == "Twist"
    assert graph.bridge.cmd_vel_type == "TwistStamped"
    types = dict(graph.bridge.node.get_subscriber_names_and_types_by_node("sim_world", "/"))
    assert types["/cmd_vel"] == ["geometry_msgs/msg/TwistStamped"]


def test_a_twist_stamped_drives_the_robot(graph: Graph) -> None:
    bridge = graph.bridge
    publisher = graph.driver.create_publisher(TwistStamped, "/cmd_vel", 10)
    assert bridge.wait_for(lambda: publisher.get_subscription_count() > 0,
                           sim_timeout=float("inf"), wall_timeout=WALL)
    x0 = bridge.world.pose[0]
    message = TwistStamped()
    message.twist.linear.x = 0.5
    publisher.publish(message)
    assert bridge.wait_for(lambda: bridge.world.pose[0] > x0 + 0.3, sim_timeout=3.0,
                           wall_timeout=WALL)
    assert bridge.cmd_vel_mismatches() == []  # the right type is named nowhere
    publisher.publish(TwistStamped())
    assert bridge.wait_for(lambda: bridge.world.command == (0.0, 0.0), sim_timeout=3.0,
                           wall_timeout=WALL)  # stopped: the next test starts still


def test_a_twist_publisher_is_named_with_both_types(graph: Graph) -> None:
    bridge = graph.bridge
    publisher = graph.driver.create_publisher(Twist, "cmd_vel", 10)
    assert bridge.wait_for(lambda: bool(bridge.cmd_vel_mismatches()),
                           sim_timeout=float("inf"), wall_timeout=WALL)
    assert bridge.cmd_vel_mismatches() == [Mismatch(
        "driver", "/cmd_vel", "geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped")]
    assert bridge.world.command == (0.0, 0.0)
    x0 = bridge.world.pose[0]
    message = Twist()
    message.linear.x = 0.5
    publisher.publish(message)
    assert bridge.wait_until(bridge.now + 1.0, wall_timeout=WALL)
    assert bridge.world.pose[0] == pytest.approx(x0, abs=0.01)  # never heard


def test_the_warning_names_both_types_and_both_fixes() -> None:
    text = world_warning(Mismatch("teleop", "/cmd_vel", "geometry_msgs/msg/Twist",
                                  "geometry_msgs/msg/TwistStamped"))
    assert text == ("Warning: node 'teleop' publishes geometry_msgs/msg/Twist on /cmd_vel, but "
                    "this robot takes geometry_msgs/msg/TwistStamped: publish TwistStamped, or "
                    "run the world with --cmd-vel-type Twist.")
    other = world_warning(Mismatch("chatter", "/cmd_vel", "std_msgs/msg/String",
                                   "geometry_msgs/msg/Twist"))
    assert "--cmd-vel-type" not in other and "std_msgs/msg/String" in other


class _Bridge:
    def __init__(self, found: list[Mismatch]) -> None:
        self.found = found

    def cmd_vel_mismatches(self) -> list[Mismatch]:
        return self.found


def test_sim_run_warns_once_per_publisher(capsys: pytest.CaptureFixture[str]) -> None:
    teleop = Mismatch("teleop", "/cmd_vel", "geometry_msgs/msg/TwistStamped",
                      "geometry_msgs/msg/Twist")
    warned: set[object] = set()
    for _ in range(3):
        sim.cli.warn_mismatches(_Bridge([teleop]), warned)
    assert capsys.readouterr().err.count("node 'teleop' publishes") == 1


def test_sim_run_takes_cmd_vel_type(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    seen = []
    monkeypatch.setattr(sim.cli, "run_world", lambda spec, **kw: seen.append(spec) or "done")
    runner = CliRunner()
    assert runner.invoke(sim.cli.sim_cli, ["run", "--cmd-vel-type", "TwistStamped"]).exit_code == 0
    assert runner.invoke(sim.cli.sim_cli, ["run"]).exit_code == 0
    assert [s.cmd_vel_type for s in seen] == ["TwistStamped", "Twist"]
    bad = runner.invoke(sim.cli.sim_cli, ["run", "--cmd-vel-type", "Twst"])
    assert bad.exit_code == 2
