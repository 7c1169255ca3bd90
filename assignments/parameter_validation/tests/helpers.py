"""Shared steps of the parameter_validation tests: one agent command in, what came out."""

from __future__ import annotations

from geometry_msgs.msg import Twist

from autograder.core.errors import StudentFailure
from autograder.i18n import _

# After an answer arrives, this much simulation time is watched for a second one.
SETTLE = 0.3


def twist(linear_x: float = 0.0, angular_z: float = 0.0, **others: float) -> Twist:
    message = Twist()
    message.linear.x, message.angular.z = float(linear_x), float(angular_z)
    for name, value in others.items():
        part, axis = name.split("_")
        setattr(getattr(message, part), axis, float(value))
    return message


def ready(probe, inbox) -> None:
    """Wait until the node listens on agent/cmd_vel and we hear its cmd_vel."""
    if not probe.wait_for_subscriber(Twist, "agent/cmd_vel", 5.0):
        raise StudentFailure(
            _("Nothing subscribes to agent/cmd_vel."),
            _("Create a subscription: `self.create_subscription(Twist, 'agent/cmd_vel', ...)`."))
    if not probe.wait_for(lambda: inbox.publisher_count() > 0, 5.0):
        raise StudentFailure(
            _("Nothing publishes on cmd_vel."),
            _("Create a publisher: `self.create_publisher(Twist, 'cmd_vel', 10)`."))


def exchange(probe, inbox, wish: Twist) -> list[Twist]:
    """Publish one agent command; return every cmd_vel message that answered it."""
    before = len(inbox)
    probe.publish(Twist, "agent/cmd_vel", wish)
    if not probe.wait_for(lambda: len(inbox) > before, 2.0):
        raise StudentFailure(
            _("The agent asked for linear.x={x}, angular.z={z} on agent/cmd_vel, and nothing "
              "came on cmd_vel within 2 s of simulation time.").format(
                x=wish.linear.x, z=wish.angular.z),
            _("Publish one cmd_vel message from the agent/cmd_vel callback. Is the node "
              "spinning?"))
    probe.wait_sim(SETTLE)
    return inbox.messages[before:]


def answer(probe, inbox, wish: Twist) -> Twist:
    return exchange(probe, inbox, wish)[0]


def close(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-6
