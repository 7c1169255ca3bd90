"""Shared steps of the parameter_validation tests: one agent command in, what came out."""

from __future__ import annotations

from geometry_msgs.msg import Twist

from autograder.core.errors import StudentFailure
from autograder.i18n import _

# After an answer arrives, this much simulation time is watched for a second one.
SETTLE = 0.3
# What the README accepts for each speed limit, and the starting values.
RANGES = {"max_linear_speed": (0.0, 1.5), "max_angular_speed": (0.0, 2.5)}
DEFAULTS = {"max_linear_speed": 0.5, "max_angular_speed": 1.0, "robot_name": "tb3"}


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
            _("The agent asked for `linear.x={x}, angular.z={z}` on agent/cmd_vel, and nothing "
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


# -- hints: the fix for the case that was observed ---------------------------------------

def clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


def example_reason(name: str, value: object) -> str:
    """A reason the README would accept for refusing ``value`` (the student's own text)."""
    if name in RANGES and isinstance(value, float):
        low, high = RANGES[name]
        return f"{name} must be within [{low}, {high}], got {value}"
    if name == "robot_name" and value == "":
        return "robot_name must not be empty"
    return f"{name} must be a {'string' if name == 'robot_name' else 'double'}"


def accepted_hint(name: str, value: object) -> str:
    """Why a bad value got through, by what was wrong with it, and the fix for that."""
    default = DEFAULTS[name]
    if type(value) is not type(default):
        return _("rclpy refuses a value of another type by itself unless the parameter was "
                 "declared to take any type. Declare it with a default of its own type, "
                 "`declare_parameter('{name}', {default!r})`, without "
                 "`dynamic_typing=True`.").format(name=name, default=default)
    if name in RANGES:
        low, high = RANGES[name]
        if value < low:
            return _("Check the lower bound too: in your on-set parameters callback, refuse "
                     "{name} below {low} with `SetParametersResult(successful=False, "
                     "reason=...)`. With a negative limit, `max(-limit, min(limit, v))` "
                     "gives {speed} whatever the agent asks: the robot moves on its "
                     "own.").format(name=name, low=low, speed=-value)
        return _("Check the upper bound: in your on-set parameters callback, refuse {name} "
                 "above {high} with `SetParametersResult(successful=False, "
                 "reason=...)`.").format(name=name, high=high)
    return _("Check for the empty string in your on-set parameters callback (`if not "
             "param.value`) and refuse it with `SetParametersResult(successful=False, "
             "reason=...)`.")


def clamp_hint(field: str, name: str, limit: float, asked: float, got: float) -> str:
    """The fix for a clamp that gave ``got`` for ``asked`` under ``limit``."""
    if close(got, asked):
        return _("`{field}={asked}` was passed on unclamped: clamp it with "
                 "`max(-limit, min(limit, value))`, where limit is {name}.").format(
            field=field, asked=asked, name=name)
    if close(got, -clamp(asked, limit)):
        return _("The sign was lost: clamp with `max(-limit, min(limit, value))`, which keeps "
                 "it, not with `abs()`.")
    return _("Clamp {field} with `max(-limit, min(limit, value))`, where limit is {name} "
             "({limit}).").format(field=field, name=name, limit=limit)
