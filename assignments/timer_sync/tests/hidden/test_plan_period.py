"""Hidden tests: started with -p cruise_speed:=0.35, the node is watched for two plans.

One run: 22.5 s of simulation time from the node's start, at ten times real time
(helpers.LONG_RTF): ticks of 0.1 s, on which the plans fall; half a second of it, before
the first plan, at half pace.
"""

import pytest
from helpers import (
    LONG_END_AT,
    LONG_RTF,
    PLAN_PERIOD,
    PLAN_TOLERANCE,
    no_plan_hint,
    observe,
    require_commands,
    require_sim_clock,
    wall_clock_hint,
)

from autograder.core.errors import StudentFailure
from autograder.i18n import _, ngettext

SPEED = 0.35

pytestmark = pytest.mark.parameters({"cruise_speed": SPEED})


# Half a second of sim time at half pace, SLOW_AT after the node's start (before its first
# plan): where a timer on the wall clock shows itself whatever the machine's load (see
# helpers.wall_clock_evidence), for about a second of wall time.
SLOW_AT = 2.0
SLOW_FOR = 0.5


@pytest.fixture(scope="module")
def run(probe, world, streams):
    """Watched to LONG_END_AT after the node's start, at LONG_RTF but for SLOW_FOR at half
    pace."""
    return observe(probe, world, streams, end_at=LONG_END_AT,
                   switch_at=streams.started + SLOW_AT, rtf=LONG_RTF, slow_for=SLOW_FOR)


@pytest.mark.points(1)
def test_cruise_speed_override(probe, streams):
    """Started with -p cruise_speed:=0.35, cmd_vel carries linear.x 0.35"""
    commands = streams.commands
    if not probe.wait_for(lambda: len(commands) >= 5, 5.0):
        raise StudentFailure(
            _("Nothing came on cmd_vel within 5 s of simulation time."),
            _("Create a 10 Hz timer whose callback publishes a Twist on cmd_vel."))
    wrong = [m.linear.x for m in commands.messages if abs(m.linear.x - SPEED) > 1e-6]
    if wrong:
        raise StudentFailure(
            _("Started with -p cruise_speed:=0.35, cmd_vel had `linear.x={got}`.").format(
                got=wrong[0]),
            _("Read the cruise_speed parameter (declare_parameter returns it) instead of a "
              "constant."))


@pytest.mark.points(1)
def test_plan_rate(run, evidence):
    """A plan is published every 10 s of simulation time"""
    require_commands(run)
    require_sim_clock(run, _("the plan period"))
    plans = run.plan_times()
    seconds = run.end - run.start
    evidence.intervals("plan", plans, PLAN_PERIOD + PLAN_TOLERANCE)
    if len(plans) < 2:
        raise StudentFailure(
            ngettext("{count} plan came in {seconds:.1f} s of simulation time; expected one "
                     "every 10 s.",
                     "{count} plans came in {seconds:.1f} s of simulation time; expected one "
                     "every 10 s.", len(plans)).format(count=len(plans), seconds=seconds),
            no_plan_hint(run))
    intervals = [b - a for a, b in zip(plans, plans[1:], strict=False)]
    wrong = [d for d in intervals if abs(d - PLAN_PERIOD) > PLAN_TOLERANCE]
    if wrong or len(plans) > seconds / PLAN_PERIOD + 1:
        raise StudentFailure(
            ngettext("Plans came {count} time in {seconds:.1f} s of simulation time, {apart} s "
                     "apart; expected every 10 s.",
                     "Plans came {count} times in {seconds:.1f} s of simulation time, {apart} "
                     "s apart; expected every 10 s.", len(plans)).format(
                count=len(plans), seconds=seconds,
                apart=", ".join(f"{d:.2f}" for d in intervals)),
            wall_clock_hint() if any(d < PLAN_PERIOD - PLAN_TOLERANCE for d in intervals) else
            _("Create the planner timer with a period of 10.0 s on the node's clock."))
