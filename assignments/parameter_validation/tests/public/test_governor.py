"""Public tests: the node starts, clamps what the agent asks for, answers each input once."""

import pytest
from helpers import answer, clamp_hint, close, exchange, ready, twist

from autograder.core.errors import StudentFailure
from autograder.i18n import _, ngettext


@pytest.mark.points(1)
def test_node_starts(student, probe, commands):
    """The node starts as velocity_governor, listens on agent/cmd_vel, publishes cmd_vel"""
    ready(probe, commands)


@pytest.mark.points(1)
def test_clamps_linear(student, probe, commands):
    """linear.x is clamped to ±max_linear_speed (default 0.5)"""
    ready(probe, commands)
    for asked, expected in ((3.0, 0.5), (-3.0, -0.5), (0.3, 0.3), (0.5, 0.5), (-0.2, -0.2)):
        got = answer(probe, commands, twist(linear_x=asked)).linear.x
        if not close(got, expected):
            raise StudentFailure(
                _("The agent asked for `linear.x={asked}`; cmd_vel had `linear.x={got}`, "
                  "expected {expected} (max_linear_speed is 0.5).").format(
                    asked=asked, got=got, expected=expected),
                clamp_hint("linear.x", "max_linear_speed", 0.5, asked, got))


@pytest.mark.points(1)
def test_clamps_angular(student, probe, commands):
    """angular.z is clamped to ±max_angular_speed (default 1.0)"""
    ready(probe, commands)
    for asked, expected in ((5.0, 1.0), (-5.0, -1.0), (0.7, 0.7), (-1.0, -1.0)):
        got = answer(probe, commands, twist(angular_z=asked)).angular.z
        if not close(got, expected):
            raise StudentFailure(
                _("The agent asked for `angular.z={asked}`; cmd_vel had `angular.z={got}`, "
                  "expected {expected} (max_angular_speed is 1.0).").format(
                    asked=asked, got=got, expected=expected),
                clamp_hint("angular.z", "max_angular_speed", 1.0, asked, got))


@pytest.mark.points(1)
def test_one_output_per_input(student, probe, commands):
    """Each agent command gives exactly one cmd_vel message"""
    ready(probe, commands)
    for asked in (0.1, 0.2, -0.1):
        answers = exchange(probe, commands, twist(linear_x=asked))
        if len(answers) != 1:
            raise StudentFailure(
                ngettext("The agent's `linear.x={asked}` gave {count} cmd_vel message; "
                         "expected exactly one.",
                         "The agent's `linear.x={asked}` gave {count} cmd_vel messages; "
                         "expected exactly one.", len(answers)).format(
                    asked=asked, count=len(answers)),
                _("Call publish() once per agent/cmd_vel message, from its callback only: "
                  "not twice in it, and not from a timer as well."))


@pytest.mark.points(1)
def test_other_fields_zero(student, probe, commands):
    """Fields a differential-drive base cannot follow are zero in cmd_vel"""
    ready(probe, commands)
    wish = twist(linear_x=0.1, angular_z=0.2, linear_y=0.4, linear_z=0.5, angular_x=0.6,
                 angular_y=0.7)
    got = answer(probe, commands, wish)
    others = {"linear.y": got.linear.y, "linear.z": got.linear.z,
              "angular.x": got.angular.x, "angular.y": got.angular.y}
    wrong = {k: v for k, v in others.items() if v != 0.0}
    if wrong:
        asked = {"linear.y": wish.linear.y, "linear.z": wish.linear.z,
                 "angular.x": wish.angular.x, "angular.y": wish.angular.y}
        relayed = all(close(v, asked[k]) for k, v in wrong.items())
        raise StudentFailure(
            _("cmd_vel passed on fields the robot cannot follow: {fields}.").format(
                fields=", ".join(f"{k}={v}" for k, v in wrong.items())),
            _("These are the agent's own values: its Twist was changed and passed on. "
              "Build a fresh `Twist()` and set only `linear.x` and `angular.z`.") if relayed
            else _("Build a fresh `Twist()` and set only `linear.x` and `angular.z`."))
