"""Hidden tests: parameters are validated on set, and an accepted value takes effect."""

import pytest
from helpers import (
    DEFAULTS,
    RANGES,
    accepted_hint,
    answer,
    clamp,
    clamp_hint,
    close,
    example_reason,
    ready,
    twist,
)

from autograder.core.errors import StudentFailure
from autograder.i18n import _

NODE = "velocity_governor"


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
            accepted_hint(name, value))
    if not result.reason.strip():
        raise StudentFailure(
            _("Setting {name} to {value!r} was refused with an empty reason.").format(
                name=name, value=value),
            _("Say why in the reason, naming the parameter, e.g. "
              "`SetParametersResult(successful=False, reason='{example}')`.").format(
                example=example_reason(name, value)))
    kept = probe.get_parameters(NODE, [name])[name]
    if kept != DEFAULTS[name]:
        raise StudentFailure(
            _("After refusing {value!r}, {name} reads {kept!r}; the old value {old!r} must "
              "stay.").format(value=value, name=name, kept=kept, old=DEFAULTS[name]),
            _("A refusal from the on-set parameters callback keeps the old value by itself: "
              "do not set {name} yourself while refusing.").format(name=name))
    return result.reason


@pytest.mark.points(2)
def test_refuses_out_of_range(student, probe, commands):
    """Out-of-range speed limits are refused with a reason naming them, the old values kept"""
    tried = (("max_linear_speed", 3.0), ("max_linear_speed", -0.1),
             ("max_angular_speed", 2.6), ("max_angular_speed", -1.0))
    for name, value in tried:
        reason = refused(probe, name, value)
        if name not in reason:
            raise StudentFailure(
                _("Refusing `{name}={value}` said {reason!r}, which does not name {name}.")
                .format(name=name, value=value, reason=reason),
                _("Put the parameter's name in the reason, e.g. '{example}'.").format(
                    example=example_reason(name, value)))
    got = answer(probe, commands, twist(linear_x=3.0)).linear.x
    if not close(got, 0.5):
        raise StudentFailure(
            _("After refused sets, the agent's 3.0 m/s came out as {got}; the limit must "
              "still be 0.5.").format(got=got),
            _after_refusals_hint(got, [v for n, v in tried if n == "max_linear_speed"]))


def _after_refusals_hint(got: float, refused_values: list[float]) -> str:
    """Which limit the answer to 3.0 m/s fits: a refused value, or none (not clamped)."""
    if close(got, 3.0):
        return _("3.0 is what the agent asked for: either linear.x is not clamped, or the "
                 "refused `max_linear_speed=3.0` became the limit. Clamp with "
                 "`max(-limit, min(limit, value))`, and change the limits only once every "
                 "parameter of a set has passed.")
    taken = [v for v in refused_values if close(clamp(3.0, v), got)]
    if taken:
        return _("That fits `max_linear_speed={value}`, a value that was refused: change the "
                 "limits your callback uses only once every parameter of a set has "
                 "passed.").format(value=taken[0])
    return clamp_hint("linear.x", "max_linear_speed", 0.5, 3.0, got)


@pytest.mark.points(1)
def test_refuses_empty_robot_name(student, probe, commands):
    """An empty robot_name is refused with a reason naming it, the old value kept"""
    reason = refused(probe, "robot_name", "")
    if "robot_name" not in reason:
        raise StudentFailure(
            _("Refusing an empty robot_name said {reason!r}, which does not name "
              "robot_name.").format(reason=reason),
            _("Put the parameter's name in the reason, e.g. '{example}'.").format(
                example=example_reason("robot_name", "")))


@pytest.mark.points(1)
def test_refuses_wrong_type(student, probe, commands):
    """A value of the wrong type is refused and the old value kept"""
    refused(probe, "max_linear_speed", "fast")
    refused(probe, "robot_name", 7)


@pytest.mark.points(1)
def test_accepted_value_applies(student, probe, commands):
    """An accepted limit applies from the next agent command"""
    limits = dict(DEFAULTS)  # the values in force, as far as the sets said
    for name, value, wish, field in (
        ("max_linear_speed", 0.3, twist(linear_x=3.0), "linear.x"),
        ("max_linear_speed", 1.5, twist(linear_x=3.0), "linear.x"),
        ("max_angular_speed", 2.0, twist(angular_z=-5.0), "angular.z"),
    ):
        result = probe.set_parameters(NODE, {name: value})[0]
        if not result.successful:
            low, high = RANGES[name]
            raise StudentFailure(
                _("Setting {name} to {value}, inside its range, was refused: {reason}")
                .format(name=name, value=value, reason=result.reason),
                _("{value} lies within `[{low}, {high}]`, the bounds included: refuse only "
                  "values below {low} or above {high} (compare with `<` and `>`, not `<=` "
                  "and `>=`).").format(value=value, low=low, high=high))
        old, limits[name] = limits[name], value
        got = answer(probe, commands, wish)
        part, axis = field.split(".")
        seen = getattr(getattr(got, part), axis)
        asked = getattr(getattr(wish, part), axis)
        expected = clamp(asked, value)
        if not close(seen, expected):
            if close(seen, clamp(asked, old)) and not close(seen, asked):
                hint = _("cmd_vel still followed the old limit, {old}: update the limits "
                         "your agent/cmd_vel callback uses when a set succeeds, or read the "
                         "parameter with get_parameter on every message.").format(old=old)
            else:
                hint = clamp_hint(field, name, value, asked, seen)
            raise StudentFailure(
                _("After {name} was set to {value}, the next command came out as "
                  "`{field}={seen}`; expected {expected}.").format(
                    name=name, value=value, field=field, seen=seen, expected=expected),
                hint)
