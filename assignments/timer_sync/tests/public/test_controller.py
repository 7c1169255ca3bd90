"""Public tests: a 10 Hz control loop, 1 Hz status and the first plan, in simulation time.

One run: 11.75 s of simulation time at five times real time, then 0.5 s at half real time,
the first planner run in it.  The plan period (a second plan, 10 s later) is a hidden test.
"""

import pytest
from helpers import (
    CONTROL_HZ,
    MAX_GAP,
    PLAN_PERIOD,
    PLAN_SECONDS,
    PLAN_TOLERANCE,
    STATUS_PERIOD,
    biggest_gap,
    blocked_hint,
    freeze_hint,
    no_plan_hint,
    parse_status,
    rate_ok,
    require_commands,
    require_not_frozen,
    require_sim_clock,
    too_fast,
    wall_clock_hint,
)

from autograder.core.errors import StudentFailure
from autograder.i18n import _, ngettext

CRUISE = 0.2


@pytest.mark.points(1)
def test_node_starts(student, probe, streams):
    """The node starts as multi_rate_controller and publishes cmd_vel at cruise_speed 0.2"""
    commands = streams.commands
    if not probe.wait_for(lambda: len(commands) >= 3, 5.0):
        raise StudentFailure(
            _("Nothing came on cmd_vel within 5 s of simulation time."),
            _("Create a 10 Hz timer whose callback publishes a Twist on cmd_vel."))
    wrong = [m.linear.x for m in commands.messages if abs(m.linear.x - CRUISE) > 1e-6]
    if wrong:
        raise StudentFailure(
            _("cmd_vel had `linear.x={got}`; expected the cruise_speed parameter's default, "
              "{cruise}.").format(got=wrong[0], cruise=CRUISE),
            _("Declare cruise_speed with default 0.2 and publish its value as linear.x."))


@pytest.mark.points(3)
def test_control_rate(run, evidence):
    """cmd_vel keeps 10 Hz for 12 s of simulation time (count within 3%), no gap over 0.15 s"""
    require_commands(run)
    require_sim_clock(run, _("the control rate"))
    times = run.command_times()
    evidence.intervals("cmd_vel", times, MAX_GAP)
    seconds = run.end - run.start
    gap, where = biggest_gap(times, run.start, run.end)
    if run.frozen_at is not None:
        raise StudentFailure(
            _("cmd_vel stopped at t={t:.2f} s of simulation time, {after:.1f} s into the run, "
              "and never came back.").format(t=run.frozen_at, after=run.frozen_at - run.start),
            freeze_hint())
    if not rate_ok(len(times), seconds, CONTROL_HZ):
        raise StudentFailure(
            ngettext("cmd_vel came {count} time in {seconds:.1f} s of simulation time "
                     "({rate:.2f} Hz); expected 10 Hz.",
                     "cmd_vel came {count} times in {seconds:.1f} s of simulation time "
                     "({rate:.2f} Hz); expected 10 Hz.", len(times)).format(
                count=len(times), seconds=seconds, rate=len(times) / seconds),
            wall_clock_hint() if too_fast(len(times), seconds, CONTROL_HZ) else
            blocked_hint(run, gap, where) or
            _("Create the control timer with a period of 0.1 s on the node's clock "
              "(self.create_timer), which follows simulation time."))
    if gap > MAX_GAP:
        raise StudentFailure(
            _("cmd_vel went silent for {gap:.2f} s at t={t:.2f} s of simulation time; no gap "
              "may exceed 0.15 s.").format(gap=gap, t=where),
            blocked_hint(run, gap, where) or
            _("Something blocked the control timer. Is a slow callback sharing its callback "
              "group or the executor's only thread?"))


@pytest.mark.points(2)
def test_control_while_planning(run, evidence):
    """cmd_vel keeps 10 Hz while the planner runs"""
    require_commands(run)
    require_sim_clock(run, _("the control rate while the planner runs"))
    plans = run.plan_times()
    if run.frozen_at is not None:
        raise StudentFailure(
            _("cmd_vel stopped at t={t:.2f} s of simulation time and never came back{plans}.")
            .format(t=run.frozen_at, plans=_(", and no plan was published") if not plans
                    else ""),
            freeze_hint())
    # Each plan message ends a planner run that began PLAN_SECONDS before it.
    for done in plans:
        began = max(run.start, done - PLAN_SECONDS)
        times = run.command_times(began, done)
        evidence.intervals("cmd_vel", times, MAX_GAP)  # one plot per planner run
        gap, where = biggest_gap(times, began, done)
        if gap > MAX_GAP or not rate_ok(len(times), done - began, CONTROL_HZ):
            raise StudentFailure(
                _("While the planner ran (t={a:.2f} to {b:.2f} s of simulation time), cmd_vel "
                  "came {count} times, with a gap of {gap:.2f} s at t={t:.2f}; expected 10 Hz "
                  "throughout.").format(a=began, b=done, count=len(times), gap=gap, t=where),
                _("The plan came, so ROS time went on and a thread was free, but the control "
                  "timer waited for the planner: they share a callback group. Give the "
                  "planner timer a callback group of its own."))


@pytest.mark.points(1)
def test_status_rate(run, evidence):
    """status comes at 1 Hz as a JSON object with integer control_ticks and plans"""
    require_commands(run)
    require_sim_clock(run, _("the status rate"))
    items = run.status_items()
    seconds = run.end - run.start
    if not items:
        raise StudentFailure(
            _("Nothing came on status in {seconds:.1f} s of simulation time.").format(
                seconds=seconds),
            _("Create a 1 s timer that publishes a std_msgs/String on status."))
    bad = [m.data for _t, m in items if parse_status(m) is None]
    if bad:
        raise StudentFailure(
            _("A status message was {text!r}; expected a JSON object with integer "
              "control_ticks and plans, e.g. `{{\"control_ticks\": 120, \"plans\": 1}}`.")
            .format(text=bad[0][:200]),
            _("Build a dict and publish `json.dumps(it)` as the String's data."))
    require_not_frozen(run, _("the status rate"))
    times = [t for t, _m in items]
    evidence.intervals("status", times, STATUS_PERIOD + 0.1)
    gap, where = biggest_gap(times, run.start, run.end)
    if not rate_ok(len(items), seconds, 1.0 / STATUS_PERIOD) or gap > STATUS_PERIOD + 0.1 + 1e-6:
        raise StudentFailure(
            ngettext("status came {count} time in {seconds:.1f} s of simulation time, with a "
                     "gap of {gap:.2f} s at t={t:.2f}; expected 1 Hz.",
                     "status came {count} times in {seconds:.1f} s of simulation time, with a "
                     "gap of {gap:.2f} s at t={t:.2f}; expected 1 Hz.", len(items)).format(
                count=len(items), seconds=seconds, gap=gap, t=where),
            wall_clock_hint() if too_fast(len(items), seconds, 1.0 / STATUS_PERIOD) else
            blocked_hint(run, gap, where, status=True) or
            _("Create the status timer with a period of 1.0 s on the node's clock."))


@pytest.mark.points(2)
def test_status_counts(run):
    """status's control_ticks and plans agree with what the node published"""
    require_commands(run)
    command_times = [t for t, _m in run.commands]
    plan_times = [t for t, _m in run.plans]
    parsed = [(t, m, parse_status(m)) for t, m in run.status_items()]
    items = [(t, s) for t, _m, s in parsed if s is not None]
    if len(items) < 3:
        invalid = [m.data for _t, m, s in parsed if s is None]
        raise StudentFailure(
            _("No valid status message came; at least 3 are needed to compare counts.")
            if not items else
            ngettext("Only {count} valid status message came; at least 3 are needed to "
                     "compare counts.",
                     "Only {count} valid status messages came; at least 3 are needed to "
                     "compare counts.", len(items)).format(count=len(items)),
            _("A status such as {text!r} does not count: publish json.dumps of a dict with "
              "integer control_ticks and plans.").format(text=invalid[0][:200]) if invalid
            else _("Publish status every second as JSON with control_ticks and plans."))
    # control_ticks counts from the node's start; the probe may have missed the first
    # few, so what must hold is a constant difference (one message either side: stamps).
    offsets = [s["control_ticks"] - sum(1 for c in command_times if c <= t) for t, s in items]
    low, high = min(offsets), max(offsets)
    if high - low > 2 or low < -2:
        worst = max(range(len(items)), key=lambda i: abs(offsets[i] - offsets[0]))
        t, s = items[worst]
        seen = sum(1 for c in command_times if c <= t)
        raise StudentFailure(
            ngettext("At t={t:.2f} s status said `control_ticks={ticks}`, but cmd_vel had come "
                     "{seen} time by then; control_ticks must count every control callback "
                     "since the node started.",
                     "At t={t:.2f} s status said `control_ticks={ticks}`, but cmd_vel had come "
                     "{seen} times by then; control_ticks must count every control callback "
                     "since the node started.", seen).format(
                t=t, ticks=s["control_ticks"], seen=seen),
            _ticks_hint(items, command_times))
    if not plan_times:
        # No plan came: test_first_plan says so (and whether status counted one anyway).
        # Whether a status after the unpublished plan fell in the run depends on when the
        # node's clock began, so it is not judged here twice.
        return
    for t, s in items:
        if any(abs(t - p) <= 0.2 for p in plan_times):
            continue  # a status beside a plan may count it or not yet
        seen = sum(1 for p in plan_times if p <= t)
        if s["plans"] != seen:
            raise StudentFailure(
                ngettext("At t={t:.2f} s status said `plans={plans}`, but {seen} plan had been "
                         "published by then.",
                         "At t={t:.2f} s status said `plans={plans}`, but {seen} plans had been "
                         "published by then.", seen).format(t=t, plans=s["plans"], seen=seen),
                _early_count_hint(t, plan_times) if s["plans"] > seen else
                _("Count a plan when the planner finishes one and report the count."))


def _early_count_hint(t: float, plan_times: list[float]) -> str:
    """Counted ahead of plan: the plan came later (counted when the planner started), or
    never came."""
    later = [p for p in plan_times if p > t]
    if later:
        return _("The plan it counted came on plan only at t={came:.2f} s: count a plan once "
                 "the planner has finished and published it, not when it starts.").format(
            came=later[0])
    return _("The node counts plans that never came on plan: publish each route on plan "
             "(a std_msgs/String) when the planner finishes it, and count it then.")


def _ticks_hint(items: list[tuple[float, dict[str, int]]], command_times: list[float]) -> str:
    """A counter that does not grow with cmd_vel was reset; otherwise it counts something
    else than the control callbacks."""
    (first_t, first), (last_t, last) = items[0], items[-1]
    came = sum(1 for c in command_times if first_t < c <= last_t)
    grew = last["control_ticks"] - first["control_ticks"]
    if grew < came / 2:
        return ngettext(
            "control_ticks went from {first} at t={a:.2f} s to {last} at t={b:.2f} s while "
            "cmd_vel came {came} time: the counter is reset somewhere. Count every control "
            "callback since the node started, and never reset it.",
            "control_ticks went from {first} at t={a:.2f} s to {last} at t={b:.2f} s while "
            "cmd_vel came {came} times: the counter is reset somewhere. Count every control "
            "callback since the node started, and never reset it.", came).format(
            first=first["control_ticks"], a=first_t, last=last["control_ticks"], b=last_t,
            came=came)
    return _("Increment one counter in the control callback and report it as is; do not "
             "reset it.")


@pytest.mark.points(1)
def test_first_plan(run, streams):
    """The first plan comes 12 s after the node starts: its 10 s timer, then 2 s of planning"""
    require_commands(run)
    require_sim_clock(run, _("the first plan's time"))
    plans = run.plan_times()
    seconds = run.end - run.start
    if not plans:
        raise StudentFailure(
            ngettext("{count} plan came in {seconds:.1f} s of simulation time; expected one "
                     "every 10 s.",
                     "{count} plans came in {seconds:.1f} s of simulation time; expected one "
                     "every 10 s.", 0).format(count=0, seconds=seconds),
            no_plan_hint(run))
    # The node's clock began between sim time 0 and its appearing (see helpers.SWITCH_AT).
    earliest = PLAN_PERIOD + PLAN_SECONDS - PLAN_TOLERANCE
    latest = streams.started + PLAN_PERIOD + PLAN_SECONDS + PLAN_TOLERANCE
    if len(plans) > 1 or not earliest <= plans[0] <= latest:
        raise StudentFailure(
            ngettext("Plans came {count} time in {seconds:.1f} s of simulation time, the first "
                     "at t={t:.2f} s; expected one, between t={a:.2f} and {b:.2f} s: the "
                     "10 s timer, then 2 s of planning.",
                     "Plans came {count} times in {seconds:.1f} s of simulation time, the first "
                     "at t={t:.2f} s; expected one, between t={a:.2f} and {b:.2f} s: the "
                     "10 s timer, then 2 s of planning.", len(plans)).format(
                count=len(plans), seconds=seconds, t=plans[0], a=earliest, b=latest),
            _("Create the planner timer with a period of 10.0 s on the node's clock."))


@pytest.mark.points(2)
def test_rates_at_half_speed(run, evidence):
    """Rates hold in simulation time when the world runs at half speed"""
    require_commands(run)
    require_not_frozen(run, _("the rates at half speed"))
    seconds = run.end - run.switch
    commands = run.command_times(run.switch, run.end)
    evidence.intervals("cmd_vel", commands)  # the rates are judged here, not the gaps
    statuses = [t for t, _m in run.status_items() if t >= run.switch]
    if not rate_ok(len(commands), seconds, CONTROL_HZ) or \
            not rate_ok(len(statuses), seconds, 1.0 / STATUS_PERIOD):
        fast = too_fast(len(commands), seconds, CONTROL_HZ) or \
            too_fast(len(statuses), seconds, 1.0 / STATUS_PERIOD)
        gap, where = biggest_gap(commands, run.switch, run.end)
        raise StudentFailure(
            _("With the world at half speed, cmd_vel came at {control:.1f} Hz and status at "
              "{status:.1f} Hz in simulation time; expected 10 Hz and 1 Hz.").format(
                control=len(commands) / seconds, status=len(statuses) / seconds),
            wall_clock_hint() if fast else blocked_hint(run, gap, where) or
            _("Something blocked the control timer. Is a slow callback sharing its callback "
              "group or the executor's only thread?"))
