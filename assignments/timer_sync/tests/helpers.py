"""The timer_sync run and what is measured on it, in simulation time.

The world holds each clock tick until the student's process is done with it, but under load
the probe may receive a message a tick or two late; so the streams are stamped with the
sim time they were *published* at (the tick in force when the student sent them, from
the DDS source timestamp).  A healthy 10 Hz timer then shows gaps of 0.1 s; a node one
tick slow to react shows 0.15 s (RTF 1) and still keeps its beat; 0.2 s is a lost beat.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

from autograder.core.errors import StudentFailure
from autograder.i18n import _
from autograder.plugin.probe import stall_cap

CONTROL_HZ = 10.0
STATUS_PERIOD = 1.0
PLAN_PERIOD = 10.0
PLAN_SECONDS = 2.0
# How far a plan may be from its expected time: a tick or two either side (sim seconds).
PLAN_TOLERANCE = 0.25
# The run: sim seconds at the exercise's pace (RTF 5, /clock at 100 Hz: ticks of 0.05 s of
# sim time, as at RTF 1 and 20 Hz), then at OTHER_RTF.  A node timed by the wall clock
# shows a fifth of its rates in sim time at RTF 5 and twice them at half pace.  Jazzy's
# MultiThreadedExecutor can spin for tenths of a second of CPU in a tick (rclpy issue
# 1452); the world holds time for it, and the pace is the one at which every proof keeps
# its exact set under load (benchmarks/RESULTS.md).  Ticks keep 0.05 s so that a node one
# tick slow to react keeps its beat (gaps of 0.15 s).
# The node's timers begin when its clock does: at sim time 0 if it made them before its
# first /clock (ROS time reads 0 until then), at the latest when it appeared on the graph
# (``Streams.started``).  A grading's world holds sim time at 0 from the module's start
# until the node is up and hears /clock (plugin/student.py), so both are 0 on any machine;
# the window still allows a clock begun up to ``started``, as a hand-started world may
# have run before.  The public run therefore goes at half pace from SWITCH_AT of
# sim time (the earliest such clock's first run still has 0.25 s to go) and closes END_AT
# after the node appeared (the latest clock's first plan is in): 12.25 s in all, at least
# 0.5 s of it at half pace.  That shows a wall-clock node's doubled rate (10 commands
# against 5; the tolerance is one), and a control timer that shares the planner's thread
# loses 0.25 s or more of it to the planner.  The plan period needs a second plan, 10 s
# later: the hidden run watches to LONG_END_AT at LONG_RTF, ticks of 0.1 s (the /clock
# rate is the exercise's 100 Hz): it judges only the cruise speed and the plans' times,
# which fall on ticks (the planner's timer and sleep_for start and end on them), so the
# intervals measure 10.0 s exactly; a 10 Hz timer runs once a tick there.  (One public
# run of 22.5 s for both plans would keep `check` waiting for both: each second at half
# pace costs two of wall time.)
SWITCH_AT = 11.75
END_AT = 12.25
LONG_END_AT = 22.5
LONG_RTF = 10.0
OTHER_RTF = 0.5
# Discovery may cost the first messages: the window opens this long after the first one.
SETTLE = 0.5
# cmd_vel silent this long (sim s): the node froze, stop watching.
FROZEN = 3.0
# cmd_vel silent this long when the run ends: it froze too.  A planner run that blocks
# control (2 s) ends 0.25 s or more before the public run does (see END_AT).
FROZEN_AT_END = 1.0
MAX_GAP = 0.15 + 1e-6
# Wall seconds between cmd_vel beats at half pace (median) under which the node keeps the
# wall clock: 0.1 s there, 0.2 s on /clock.
WALL_BEAT = 0.15
RATE_TOLERANCE = 0.03


@dataclass
class Streams:
    started: float
    commands: Any
    statuses: Any
    plans: Any


@dataclass
class Run:
    """What was seen in the window [start, end); the pace changed at ``switch``."""

    start: float | None
    switch: float | None
    end: float
    commands: list[tuple[float, Any]]
    statuses: list[tuple[float, Any]]
    plans: list[tuple[float, Any]]
    frozen_at: float | None = None
    # Each command's sim stamp and the wall time it was sent at (its DDS source stamp).
    sent: list[tuple[float, float | None]] = field(default_factory=list)
    # Where the half-pace phase ended (None: at ``end``; the hidden run's is a short one).
    slow_until: float | None = None

    @property
    def slow_end(self) -> float:
        return self.end if self.slow_until is None else min(self.slow_until, self.end)

    def command_times(self, a: float | None = None, b: float | None = None) -> list[float]:
        a = self.start if a is None else a
        b = self.end if b is None else b
        return [t for t, _m in self.commands if a <= t < b]

    def status_items(self) -> list[tuple[float, Any]]:
        return [(t, m) for t, m in self.statuses if self.start <= t < self.end]

    def plan_times(self) -> list[float]:
        return [t for t, _m in self.plans if self.start <= t < self.end]


def _watch(probe, streams: Streams, seconds: float, slowest: float) -> float | None:
    """Let ``seconds`` of sim time pass, at paces no slower than ``slowest`` (the world
    changes pace itself meanwhile); the time cmd_vel froze at, if it went silent."""
    end = probe.now + seconds
    while probe.now < end:
        times = streams.commands.times
        last = times[-1] if times else probe.now
        if probe.now - last > FROZEN:
            return last
        chunk = min(1.0, end - probe.now)
        target = probe.now + chunk
        probe.wait_for(lambda t=target: probe.now >= t, chunk + 0.5,
                       wall_timeout=stall_cap(chunk, slowest))
    return None


def observe(probe, world, streams: Streams, end_at: float = END_AT,
            switch_at: float | None = SWITCH_AT, rtf: float | None = None,
            slow_for: float | None = None) -> Run:
    """Watch the node to ``end_at`` after its start: at ``rtf`` (None: the world's pace)
    until ``switch_at`` of sim time, then at OTHER_RTF (``switch_at`` None: not at all)
    to the end, or for ``slow_for`` sim seconds and then at ``rtf`` again.  The world
    changes pace itself at those sim times (the grader's thread may wake late on a loaded
    machine), so the phases are the same in every run."""
    commands = streams.commands
    if not probe.wait_for(lambda: len(commands) > 0, 5.0):
        return Run(None, None, probe.now, [], streams.statuses.items, streams.plans.items)
    pace = world.real_time_factor
    if rtf is not None:
        world.set_real_time_factor(rtf)
    end = streams.started + end_at
    watched = rtf or pace
    slow_until = None
    if switch_at is not None:
        switch_at = max(switch_at, probe.now)
        world.schedule_real_time_factor(switch_at, OTHER_RTF)
        if slow_for is not None:
            slow_until = switch_at + slow_for
            world.schedule_real_time_factor(slow_until, watched)
        world.schedule_real_time_factor(end, pace)
    slowest = watched if switch_at is None else min(watched, OTHER_RTF)
    try:
        start = max(streams.started, commands.times[0]) + SETTLE
        probe.wait_for(lambda: probe.now >= start, SETTLE + 1.0)
        frozen = _watch(probe, streams, end - probe.now, slowest)
    finally:
        world.cancel_scheduled_pace()
        world.set_real_time_factor(pace)
    switched = [] if switch_at is None else [
        t for t, to in world.pace_changes if t >= switch_at - 1e-9 and to == OTHER_RTF]
    switch = switched[0] if switched else None
    if frozen is None:
        _let_in_flight_arrive(probe, commands, end)
        last = max((t for t in commands.times if t < end), default=start)
        if end - last > FROZEN_AT_END:
            frozen = last
    else:
        end = frozen + FROZEN
    if slow_until is not None:  # the first tick at or after it (see the world's log)
        back = [t for t, to in world.pace_changes if t >= slow_until - 1e-9 and to == watched]
        slow_until = back[0] if back else slow_until
    return Run(start, switch, end, commands.items, streams.statuses.items,
               streams.plans.items, frozen, commands.sent, slow_until)


def _let_in_flight_arrive(probe, commands, end: float) -> None:
    """Wait until what the node sent before ``end`` has reached us, not only been sent.

    On a loaded machine the probe may receive a message a tick or more after the node
    sent it; a window read at ``end`` would miss the last ones and show a gap at its edge
    that the node never had.  The node's messages reach us in the order it sent them (one
    reliable writer), so once a command it sent two beats after ``end`` is in, every
    earlier one is too, and the status and plans it sent before are taken by then (same
    socket, an earlier spin).  A node that stops right at ``end`` costs one second.
    """
    after = end + 2.0 / CONTROL_HZ
    probe.wait_for(lambda: bool(commands.times) and commands.times[-1] >= after - 1e-9, 1.0)


# -- checks --------------------------------------------------------------------------

def require_commands(run: Run) -> None:
    if run.start is None:
        raise StudentFailure(
            _("Nothing came on cmd_vel within 5 s of simulation time."),
            _("Create a 10 Hz timer whose callback publishes a Twist on cmd_vel."))


def require_not_frozen(run: Run, what: str) -> None:
    if run.frozen_at is not None:
        raise StudentFailure(
            _("cmd_vel stopped at t={t:.2f} s of simulation time ({after:.1f} s into the run) "
              "and never came back, so {what} could not be measured.").format(
                t=run.frozen_at, after=run.frozen_at - run.start, what=what),
            freeze_hint())


def freeze_hint() -> str:
    return _("The planner blocks for 2 s of ROS time. In a single-threaded executor that "
             "also blocks the /clock subscription which advances ROS time, so time itself "
             "stops. Spin a MultiThreadedExecutor and give the planner timer a callback "
             "group of its own.")


def no_plan_hint(run: Run) -> str:
    """Why too few plans came: the clock froze, the routes are counted but not published,
    or no planner timer."""
    if run.frozen_at is not None:
        return freeze_hint()
    counted = max((s["plans"] for s in map(parse_status, (m for _t, m in run.statuses))
                   if s is not None), default=0)
    if counted > len(run.plan_times()):
        return _("status reported `plans={counted}`, so the planner runs, but its routes do "
                 "not come on plan: publish each one there as a std_msgs/String.").format(
            counted=counted)
    return _("Create a 10 s timer that calls plan_route() and publishes the result on plan.")


def planner_run_during(run: Run, a: float, b: float) -> tuple[float, float] | None:
    """The planner run (its start and the plan that ended it) overlapping [a, b], if any:
    a gap there was the planner's doing."""
    for done in (t for t, _m in run.plans):
        began = done - PLAN_SECONDS
        if a < done + 0.1 and b > began:
            return began, done
    return None


def blocked_hint(run: Run, gap: float, where: float, status: bool = False) -> str | None:
    """The fix when the gap at ``where`` in cmd_vel (or status) fell on a planner run
    (None: it did not)."""
    during = planner_run_during(run, where, where + gap)
    if during is None:
        return None
    # The run ended in a plan, so ROS time went on meanwhile: a thread was free for
    # /clock, and the timer waited for the planner's group, not for a thread.
    if status:
        text = _("The gap fell on a planner run (t={a:.2f} to {b:.2f} s): while plan_route() "
                 "blocked, the status timer could not run, though ROS time went on (the plan "
                 "came), so a thread was free: it waited for the planner's callback group. "
                 "Give the planner timer a callback group of its own.")
    else:
        text = _("The gap fell on a planner run (t={a:.2f} to {b:.2f} s): while plan_route() "
                 "blocked, the control timer could not run, though ROS time went on (the "
                 "plan came), so a thread was free: it waited for the planner's callback "
                 "group. Give the planner timer a callback group of its own.")
    return text.format(a=during[0], b=during[1])


def too_fast(count: int, seconds: float, hz: float) -> bool:
    """More messages than the rate allows, as a timer on the wall clock gives when the
    world runs slower than real time."""
    return count > seconds * hz * (1 + RATE_TOLERANCE) + 1.0


def wall_clock_hint() -> str:
    return _("Make every timer with `self.create_timer(period, callback)` and no clock= "
             "argument, and read time with self.get_clock(): with use_sim_time they follow "
             "/clock, whatever its pace. A Clock() made by hand (ClockType.STEADY_TIME or "
             "SYSTEM_TIME), time.sleep and time.time keep the wall clock.")


def wall_clock_evidence(run: Run) -> str | None:
    """What shows that the node times cmd_vel by the wall clock, or None.

    At half pace a 10 Hz timer on the wall clock fires twice per 0.1 s of sim time, and
    more if the world lags; a timer on /clock cannot, as the world never runs faster
    than its pace.  So this finding holds whatever the load, where the rates the node
    showed at the exercise's pace depend on how fast the world kept up.
    """
    if run.start is None or run.switch is None:
        return None
    seconds = run.slow_end - run.switch
    count = len(run.command_times(run.switch, run.slow_end))
    if seconds <= 0 or not too_fast(count, seconds, CONTROL_HZ):
        return None
    # Counted in a short window, a tick at each edge can make one or two too many; the
    # same beats in wall time cannot lie: 0.1 s apart on the wall clock, 0.2 s and more
    # on /clock at half pace (the world never runs faster than its pace).
    sent = sorted(w for t, w in run.sent if w is not None and run.switch <= t < run.slow_end)
    apart = sorted(b - a for a, b in zip(sent, sent[1:], strict=False))
    if len(apart) < 3 or apart[len(apart) // 2] > WALL_BEAT:
        return None
    return _("With the world at half speed, cmd_vel came {count} times in {seconds:.2f} s of "
             "simulation time ({rate:.1f} Hz): the node's timers keep the wall clock, not "
             "/clock.").format(count=count, seconds=seconds, rate=count / seconds)


def require_sim_clock(run: Run, what: str) -> None:
    """Lose ``what`` for a node found timing by the wall clock: its rates in sim time
    would depend on how fast the world ran on the machine, so they are not measured."""
    evidence = wall_clock_evidence(run)
    if evidence is not None:
        raise StudentFailure(
            _("{evidence} So {what} in simulation time would depend on how fast the world "
              "ran on the grading machine: it is not measured, and this test is lost.")
            .format(evidence=evidence, what=what),
            wall_clock_hint())


def gaps(times: list[float], start: float, end: float) -> list[tuple[float, float]]:
    """(gap, where) for each interval between messages, the window's edges included."""
    points = [start, *times, end]
    return [(b - a, a) for a, b in zip(points, points[1:], strict=False)]


def biggest_gap(times: list[float], start: float, end: float) -> tuple[float, float]:
    return max(gaps(times, start, end), default=(0.0, start))


def rate_ok(count: int, seconds: float, hz: float) -> bool:
    expected = seconds * hz
    return abs(count - expected) <= max(1.0, RATE_TOLERANCE * expected)


def parse_status(message: Any) -> dict[str, int] | None:
    """The status's fields, or None if it is not a JSON object with two integer counts."""
    try:
        data = json.loads(message.data)
    except ValueError:
        return None
    if not isinstance(data, dict):
        return None
    fields = {}
    for key in ("control_ticks", "plans"):
        value = data.get(key)
        if not isinstance(value, int) or isinstance(value, bool):
            return None
        fields[key] = value
    return fields
