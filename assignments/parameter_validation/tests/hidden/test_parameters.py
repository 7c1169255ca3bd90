"""Hidden tests: parameters are validated on set, and an accepted value takes effect."""

import pytest
from helpers import answer, close, ready, twist

from autograder.core.errors import StudentFailure
from autograder.i18n import _

NODE = "velocity_governor"
DEFAULTS = {"max_linear_speed": 0.5, "max_angular_speed": 1.0, "robot_name": "tb3"}


@pytest.fixture(autouse=True)
def defaults(student, probe, commands):
    """Every test starts from the default values (a wrong test must not spoil the next)."""
    ready(probe, commands)
    probe.set_parameters(NODE, DEFAULTS)
    yield


def refused(probe, name, value):
    """Set one parameter to a bad value; fail unless refused with a reason, value kept."""
    result = probe.set_parameters(NODE, {name: value})[0]
    if result.successful:
        raise StudentFailure(
            _("Setting {name} to {value!r} was accepted; it must be refused.").format(
                name=name, value=value),
            _("Return `SetParametersResult(successful=False, reason=...)` from an on-set "
              "parameters callback."))
    if not result.reason.strip():
        raise StudentFailure(
            _("Setting {name} to {value!r} was refused with an empty reason.").format(
                name=name, value=value),
            _("Say why in `SetParametersResult.reason`, naming the parameter."))
    kept = probe.get_parameters(NODE, [name])[name]
    if kept != DEFAULTS[name]:
        raise StudentFailure(
            _("After refusing {value!r}, {name} reads {kept!r}; the old value {old!r} must "
              "stay.").format(value=value, name=name, kept=kept, old=DEFAULTS[name]))
    return result.reason


@pytest.mark.points(2)
def test_refuses_out_of_range(student, probe, commands):
    """Out-of-range speed limits are refused with a reason naming the parameter"""
    for name, value in (("max_linear_speed", 3.0), ("max_linear_speed", -0.1),
                        ("max_angular_speed", 2.6), ("max_angular_speed", -1.0)):
        reason = refused(probe, name, value)
        if name not in reason:
            raise StudentFailure(
                _("Refusing {name}={value} said {reason!r}, which does not name {name}.")
                .format(name=name, value=value, reason=reason),
                _("Put the parameter's name in the reason, e.g. '{name} must be within "
                  "[0.0, 1.5]'.").format(name=name))
    got = answer(probe, commands, twist(linear_x=3.0)).linear.x
    if not close(got, 0.5):
        raise StudentFailure(_("After refused sets, the agent's 3.0 m/s came out as {got}; "
                               "the limit must still be 0.5.").format(got=got))


@pytest.mark.points(1)
def test_refuses_empty_robot_name(student, probe, commands):
    """An empty robot_name is refused with a reason naming it"""
    reason = refused(probe, "robot_name", "")
    if "robot_name" not in reason:
        raise StudentFailure(
            _("Refusing an empty robot_name said {reason!r}, which does not name "
              "robot_name.").format(reason=reason))


@pytest.mark.points(1)
def test_refuses_wrong_type(student, probe, commands):
    """A value of the wrong type is refused and the old value kept"""
    refused(probe, "max_linear_speed", "fast")
    refused(probe, "robot_name", 7)


@pytest.mark.points(1)
def test_accepted_value_applies(student, probe, commands):
    """An accepted limit applies from the next agent command"""
    for name, value, wish, field in (
        ("max_linear_speed", 0.3, twist(linear_x=3.0), "linear.x"),
        ("max_linear_speed", 1.5, twist(linear_x=3.0), "linear.x"),
        ("max_angular_speed", 2.0, twist(angular_z=-5.0), "angular.z"),
    ):
        result = probe.set_parameters(NODE, {name: value})[0]
        if not result.successful:
            raise StudentFailure(
                _("Setting {name} to {value}, inside its range, was refused: {reason}")
                .format(name=name, value=value, reason=result.reason))
        got = answer(probe, commands, wish)
        part, axis = field.split(".")
        seen = getattr(getattr(got, part), axis)
        expected = value if field == "linear.x" else -value
        if not close(seen, expected):
            raise StudentFailure(
                _("After {name} was set to {value}, the next command came out as {field}="
                  "{seen}; expected {expected}.").format(
                    name=name, value=value, field=field, seen=seen, expected=expected),
                _("Use the new value from the next message on: update what the callback "
                  "reads when a set succeeds, or read the parameter each time."))
