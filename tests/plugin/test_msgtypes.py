"""The probe's watch on message types (autograder/plugin/msgtypes.py): a student's node
that publishes or subscribes another type than the grader's on a topic is named, with both
types, and stays named after it exits."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator

import pytest
import rclpy
from geometry_msgs.msg import Twist, TwistStamped
from rclpy.context import Context
from rclpy.node import Node
from std_msgs.msg import String

from autograder.plugin.msgtypes import TypeWatch, describe, note, watch_world_cmd_vel
from autograder.plugin.probe import GRADER_NODES, PROBE_NODE_NAME
from sim.cmdvel import Mismatch

WALL = 20.0
TWIST, STAMPED = "geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped"


def _eventually(condition: Callable[[], bool], timeout: float = WALL) -> bool:
    """Whether ``condition`` holds within ``timeout`` wall seconds (discovery takes some)."""
    tick = threading.Event()
    for _ in range(int(timeout / 0.02)):
        if condition():
            return True
        tick.wait(0.02)
    return condition()


def _node(domain: int, name: str) -> tuple[Context, Node]:
    """A node in a participant of its own, as the grader's and the student's processes are."""
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    return context, Node(name, context=context)


@pytest.fixture
def grader(ros_domain: int) -> Iterator[TypeWatch]:
    context, node = _node(ros_domain, PROBE_NODE_NAME)
    watch = TypeWatch(node, GRADER_NODES)
    watch_world_cmd_vel(watch, "Twist")  # the world takes Twist on /cmd_vel
    node.create_subscription(String, "/agent_status", lambda m: None, 10)
    watch.takes("/agent_status", "std_msgs/msg/String")
    node.create_publisher(Twist, "/agent/cmd_vel", 10)
    watch.sends("/agent/cmd_vel", TWIST)
    try:
        yield watch
    finally:
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def test_a_stamped_node_is_named_with_both_types_until_the_end(grader: TypeWatch,
                                                                ros_domain: int) -> None:
    context, student = _node(ros_domain, "velocity_governor")
    student.create_publisher(TwistStamped, "cmd_vel", 10)
    student.create_subscription(TwistStamped, "agent/cmd_vel", lambda m: None, 10)
    student.create_publisher(String, "agent_status", 10)  # the grader's type: fine

    def both() -> bool:
        grader.check()
        return len(grader.seen) == 2

    try:
        assert _eventually(both), grader.seen
    finally:
        student.destroy_node()
        rclpy.try_shutdown(context=context)
    assert grader.seen == [
        Mismatch("velocity_governor", "/agent/cmd_vel", STAMPED, TWIST, publishes=False),
        Mismatch("velocity_governor", "/cmd_vel", STAMPED, TWIST)]
    grader.check()  # the node is gone from the graph; what it did is still known
    assert len(grader.seen) == 2
    text = note(grader.seen)
    assert text.splitlines() == [
        "Your node 'velocity_governor' subscribes to /agent/cmd_vel as "
        "geometry_msgs/msg/TwistStamped, but geometry_msgs/msg/Twist is published there, so "
        "its callback never runs: subscribe with Twist.",
        "Your node 'velocity_governor' publishes geometry_msgs/msg/TwistStamped on /cmd_vel, "
        "but this exercise's robot takes geometry_msgs/msg/Twist (its cmd_vel_type), so the "
        "robot never hears it: publish Twist."]


def test_a_node_of_the_right_types_is_not_named(grader: TypeWatch, ros_domain: int) -> None:
    context, student = _node(ros_domain, "ai_agent")
    student.create_publisher(Twist, "cmd_vel", 10)
    try:
        assert _eventually(lambda: [i.node_name for i in
                                    grader.node.get_publishers_info_by_topic("/cmd_vel")]
                           == ["ai_agent"])
        grader.check()
        assert grader.seen == [] and note(grader.seen) == ""
    finally:
        student.destroy_node()
        rclpy.try_shutdown(context=context)


def test_another_topic_of_the_graders_says_what_it_takes() -> None:
    text = describe(Mismatch("ai_agent", "/agent_status", "std_msgs/msg/Int32",
                             "std_msgs/msg/String"))
    assert text == ("Your node 'ai_agent' publishes std_msgs/msg/Int32 on /agent_status, but "
                    "the grader takes std_msgs/msg/String there, so nothing it publishes "
                    "arrives: publish String.")
