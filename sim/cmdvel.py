"""Velocity commands as a robot takes them: ``Twist`` or ``TwistStamped`` on ``cmd_vel``.

The textbook's nodes publish ``geometry_msgs/msg/Twist``; Jazzy's TurtleBot3 (bring-up and
Gazebo bridge) and the Nav2 it ships with take ``geometry_msgs/msg/TwistStamped``.  A
publisher of the other type never matches the robot's subscription and nothing says so,
so this module also finds such publishers on the graph, to name both types to a person.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from dataclasses import dataclass
from typing import Any

from geometry_msgs.msg import Twist, TwistStamped
from rclpy.node import Node

from content.i18n import _
from sim.msgdefs import type_name

CMD_VEL_TOPIC = "/cmd_vel"
MESSAGE_TYPES: dict[str, type] = {"Twist": Twist, "TwistStamped": TwistStamped}
"""The types a world may take on /cmd_vel, by the name world and exercise files use."""
# What the graph calls a node whose endpoints were discovered before its name was.
_UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"


def full_name(short: str) -> str:
    """``Twist`` -> ``geometry_msgs/msg/Twist``."""
    return type_name(MESSAGE_TYPES[short])


def twist_of(message: Any) -> Twist:
    """The velocities in a ``Twist`` or a ``TwistStamped``."""
    return message.twist if isinstance(message, TwistStamped) else message


@dataclass(frozen=True, order=True)
class Mismatch:
    """A node's endpoint on ``topic`` whose type is not the one the other side uses."""

    node: str
    topic: str
    found: str
    """Full type name of the node's endpoint (``geometry_msgs/msg/TwistStamped``)."""
    expected: str
    """Full type name the other side uses there."""
    publishes: bool = True
    """True for a publisher, False for a subscription."""


def mismatches(node: Node, expected: dict[str, str], *, publishers: bool = True,
               ignore: Collection[str] = ()) -> list[Mismatch]:
    """Endpoints on the graph (publishers, or subscriptions) of nodes not in ``ignore``
    whose type differs from ``expected[topic]`` (full type names by resolved topic).
    An endpoint whose node is not known yet is left for a later look."""
    found: list[Mismatch] = []
    for topic, wanted in expected.items():
        infos: Iterable[Any] = (node.get_publishers_info_by_topic(topic) if publishers
                                else node.get_subscriptions_info_by_topic(topic))
        for info in infos:
            if info.node_name not in (*ignore, _UNKNOWN_NODE) and info.topic_type != wanted:
                found.append(Mismatch(info.node_name, topic, info.topic_type, wanted,
                                      publishers))
    return sorted(set(found))


def short(full: str) -> str:
    """``geometry_msgs/msg/Twist`` -> ``Twist``."""
    return full.rsplit("/", 1)[-1]


def world_warning(mismatch: Mismatch) -> str:
    """What ``autograder sim run`` says of a publisher the robot cannot hear."""
    values = {"node": mismatch.node, "found_type": mismatch.found, "topic": mismatch.topic,
              "expected_type": mismatch.expected, "expected": short(mismatch.expected),
              "found": short(mismatch.found)}
    if short(mismatch.found) in MESSAGE_TYPES:
        return _("Warning: node '{node}' publishes {found_type} on {topic}, but this robot "
                 "takes {expected_type}: publish {expected}, or run the world with "
                 "--cmd-vel-type {found}.").format(**values)
    return _("Warning: node '{node}' publishes {found_type} on {topic}, but this robot "
             "takes {expected_type}: publish {expected}.").format(**values)
