"""Hidden tests: 43 s of simulation time among obstacles, with the lidar misbehaving.

The faults are injected relative to the moment the node first drives, between scans (a
fault span starts and ends 0.05 s after a scan), so the same scans are affected in
every run.  Speeds are the world's own measurements (ground truth, recorded at 50 Hz,
not the wheel odometry on /odom).
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import pytest
from helpers import LATE, describe, is_zero, raised, warnings_between, window

from autograder.core.errors import StudentFailure
from autograder.i18n import _, ngettext
from autograder.plugin.collisions import with_front_beam_note
from sim.worldfile import Fault

pytestmark = pytest.mark.world("obstacles")

RUN = 43.0
# Faults, with start and end counted from the start of the run: every kind the public tests
# feed one by one, and three dropouts, each fault 1.5 s after the one before ended (a
# dropout's end leaves the 1 s the robot has to move again).  It was 60 s with gaps of 2 to
# 3.5 s; the shorter gaps changed no proof's verdict but that no_watchdog, driving blind,
# may now also hit a wall: test_stops_during_dropout says so, test_never_collides leaves
# such a hit to it (tests/submissions/error_handling/no_watchdog/expect.yaml).
SCHEDULE = (
    Fault(kind="nan", start=3.0, end=5.0, fraction=0.3),
    Fault(kind="empty", start=6.5, end=7.0),
    Fault(kind="dropout", start=8.5, end=12.5),
    Fault(kind="wrong_length", start=14.0, end=14.5, length=180),
    Fault(kind="inf", start=16.0, end=18.0, fraction=0.2),
    Fault(kind="neg_inf", start=16.0, end=18.0, fraction=0.1),
    Fault(kind="below_min", start=19.5, end=21.5, fraction=0.1),
    Fault(kind="above_max", start=19.5, end=21.5, fraction=0.1),
    Fault(kind="nan", start=23.0, end=24.0, fraction=0.5),
    Fault(kind="dropout", start=25.5, end=28.5),
    Fault(kind="empty", start=30.0, end=30.3),
    Fault(kind="wrong_length", start=31.8, end=32.3, length=400),
    Fault(kind="nan", start=33.8, end=36.8, fraction=0.2),
    Fault(kind="dropout", start=38.3, end=40.3),
)
# Stopped within the 0.5 s watchdog, one control cycle, braking (< 0.1 s at the world's
# 2.5 m/s^2 and 6 rad/s^2) and a tick of message delay.
STOP_WITHIN = 0.5 + 0.1 + 0.1 + LATE
STILL_LINEAR, STILL_ANGULAR = 0.01, 0.02
MOVE_WITHIN = 1.0
# A gap in cmd_vel longer than this (ten cycles) means the control loop stopped ...
GAP = 1.0
# ... and one this long ends the run: nothing more can be judged.
GONE = 2.0


@dataclasses.dataclass
class Dropout:
    start: float
    end: float
    wall_start: float = 0.0
    wall_end: float = 0.0


@dataclasses.dataclass
class Run:
    """What happened in the run, for the tests to judge."""

    start: float
    end: float
    dropouts: list[Dropout]
    died_at: float | None
    commands: Any
    output: str


@pytest.fixture(scope="module")
def run(world, probe, student, commands) -> Run:
    """Drive through the faults for RUN seconds of simulation time (or until the node dies)."""
    if not probe.wait_for(lambda: any(not is_zero(m) for m in commands.messages), 5.0):
        raise StudentFailure(
            _("In the world with obstacles the node never published a moving command on "
              "cmd_vel within 5 s."),
            _("Publish forward or turning commands from a 10 Hz timer."))
    t0 = math.floor(probe.now * 10 + 1e-6) / 10 + 0.05
    for fault in SCHEDULE:
        world.inject(dataclasses.replace(fault, start=t0 + fault.start, end=t0 + fault.end))
    dropouts = [Dropout(t0 + f.start, t0 + f.end) for f in SCHEDULE if f.kind == "dropout"]
    marks = sorted([(d.start, d, "wall_start") for d in dropouts] +
                   [(d.end, d, "wall_end") for d in dropouts], key=lambda m: m[0])
    died_at = None

    def gone() -> bool:  # the process ended, or it runs but publishes nothing any more
        stamps = commands.times
        return not student.running() or not stamps or stamps[-1] < probe.now - GONE

    for when, dropout, field in [*marks, (t0 + RUN, None, "")]:
        while died_at is None and probe.now < when - 1e-9:
            probe.wait_for(lambda w=when: probe.now >= w or gone(), when - probe.now)
            if gone():
                probe.settle(commands)  # silent, or only slow to reach us?
                died_at = probe.now if gone() else None
        if died_at is not None:
            break
        if dropout is not None:
            setattr(dropout, field, time.time())
    probe.wait_sim(0.3)
    probe.settle(commands)  # everything it sent is in
    return Run(t0, t0 + RUN, dropouts, died_at, commands, student.output())


def _died(run: Run, student) -> None:
    if run.died_at is None:
        return
    if student.returncode is not None:
        message = _("The node's process ended {seconds:.1f} s into the run (exit status "
                    "{code}), so the rest could not be judged. Its last lines:\n{tail}")
    else:
        message = _("The node stopped publishing on cmd_vel {seconds:.1f} s into the run, "
                    "though its process still ran (did an exception end the thread that "
                    "spins?), so the rest could not be judged. Its last lines:\n{tail}")
    error = raised(run.output)
    raise StudentFailure(
        message.format(seconds=run.died_at - run.start, code=student.returncode,
                       tail=student.output_tail(12)),
        _("It raised {error} on a faulty scan: catch exceptions in your callbacks and "
          "ignore invalid readings; the public tests show which scans hurt.").format(
            error=error) if error else
        _("Catch exceptions in your callbacks and ignore invalid readings; the public "
          "tests show which scans hurt."))


@pytest.mark.points(2)
def test_stays_alive(run, student):
    """Through 43 s of faulty scans the node stays alive and keeps publishing"""
    _died(run, student)
    stamps = [t for t in run.commands.times if run.start <= t <= run.end] + [run.end]
    gaps = [(b - a, a) for a, b in zip([run.start, *stamps], stamps, strict=False)]
    gap, since = max(gaps)
    if gap > GAP:
        raise StudentFailure(
            _("The node published nothing on cmd_vel for {gap:.1f} s of simulation time from "
              "{since:.1f} s into the run, though its process still ran (did an exception end "
              "the thread that spins?).").format(gap=gap, since=since - run.start),
            _("Keep the 10 Hz timer publishing whatever the scans look like; catch "
              "exceptions inside callbacks."))


def _blind(run: Run, t: float) -> bool:
    """Whether sim time ``t`` fell in a dropout after the robot should have stopped, or
    within the same STOP_WITHIN after the scans came back (the least time a node needs to
    react to the first one): a robot that hits something then drove on blind, which
    test_stops_during_dropout judges (a robot that stopped in time is still there)."""
    return any(d.start + STOP_WITHIN <= t <= d.end + STOP_WITHIN for d in run.dropouts)


@pytest.mark.points(2)
def test_never_collides(run, world, student):
    """The robot never touches an obstacle or a wall while the lidar works"""
    _died(run, student)
    samples, collisions = world.recording.snapshot()
    # Where a robot driving on blind ends up depends on a tick's difference in its path:
    # its collisions are the dropout test's, so that one submission gets one score.
    collisions = [c for c in collisions if not _blind(run, c.t)]
    if collisions:
        first = collisions[0]
        raise StudentFailure(
            with_front_beam_note(
                _("The robot hit {what} at `({x:.2f}, {y:.2f})`, {seconds:.1f} s into the run.")
                .format(what=first.hit_name, x=first.x, y=first.y,
                        seconds=first.t - run.start),
                collisions, samples, world.world.geometry),
            _("Stop going forward when the nearest valid reading within ±30° of ahead is "
              "0.6 m or nearer; do not let invalid readings hide an obstacle."))


@pytest.mark.points(2)
def test_stops_during_dropout(run, world, student):
    """When the lidar goes silent the robot stops within 0.5 s plus braking"""
    _died(run, student)
    samples, collisions = world.recording.snapshot()
    for d in run.dropouts:
        moving = [s for s in samples if d.start + STOP_WITHIN <= s.t < d.end
                  and (abs(s.v) > STILL_LINEAR or abs(s.w) > STILL_ANGULAR)]
        sent = window(run.commands, d.start + STOP_WITHIN, d.end)
        going = [m for m in sent if not is_zero(m)]
        cycles = (d.end - d.start - STOP_WITHIN) * 10
        if moving or going:
            first = moving[0] if moving else None
            hit = next((c for c in collisions if d.start <= c.t <= d.end + STOP_WITHIN),
                       None)
            message = _("The lidar went silent {start:.1f} s into the run; {after:.2f} s "
                        "later the robot still moved ({how}).").format(
                start=d.start - run.start,
                after=(first.t if first else d.start + STOP_WITHIN) - d.start,
                how=(_("v={v:.2f} m/s, w={w:.2f} rad/s").format(v=first.v, w=first.w)
                     if first else describe(going[0])))
            if hit is not None:
                message += "\n" + _("Driving on blind, it hit {what} {after:.1f} s after the "
                                    "last scan.").format(what=hit.hit_name,
                                                         after=hit.t - d.start)
            raise StudentFailure(
                message,
                _("A watchdog: remember when the last scan came and publish Twist() on every "
                  "cycle once it is more than 0.5 s old (in ROS time)."))
        if len(sent) < cycles / 2:  # every cycle, less what a busy machine may cost
            raise StudentFailure(
                ngettext("While the lidar was silent ({seconds:.1f} s into the run) cmd_vel "
                         "was published {count} time in {span:.1f} s; a stop is due on every "
                         "10 Hz cycle.",
                         "While the lidar was silent ({seconds:.1f} s into the run) cmd_vel "
                         "was published {count} times in {span:.1f} s; a stop is due on every "
                         "10 Hz cycle.", len(sent)).format(
                    seconds=d.start - run.start, count=len(sent),
                    span=d.end - d.start - STOP_WITHIN),
                _("Publish from the timer, not from the scan callback."))


@pytest.mark.points(1)
def test_moves_after_dropout(run, world, student):
    """When scans come back the robot moves again"""
    _died(run, student)
    samples, collisions = world.recording.snapshot()
    for d in run.dropouts:
        if not any(d.end <= s.t <= d.end + MOVE_WITHIN and (abs(s.v) > 0.05 or abs(s.w) > 0.2)
                   for s in samples):
            raise StudentFailure(
                _("Scans came back {seconds:.1f} s into the run, but the robot did not move "
                  "within {within} s.").format(seconds=d.end - run.start, within=MOVE_WITHIN),
                _("The watchdog must let go as soon as a scan arrives."))


@pytest.mark.points(1)
def test_log_not_flooded(run, student):
    """A dropout is reported with a warning, at most about one a second"""
    _died(run, student)
    for d in run.dropouts:
        count = warnings_between(run.output, d.wall_start, d.wall_end)
        # Throttled by wall or by ROS time, whichever is longer: both are fair.
        allowed = math.ceil(max(d.end - d.start, d.wall_end - d.wall_start)) + 1
        # A warning is due once the watchdog acts (a stop sent in the dropout, a tick
        # before its end at the latest: logged by then). One that never acted, or acted
        # only at its end or after (a late watchdog, whose lateness in simulation time
        # depends on the machine's load), is the stop tests' to judge.
        acted = any(is_zero(m) for m in window(run.commands, d.start, d.end - LATE))
        if count == 0 and acted:
            raise StudentFailure(
                _("The lidar was silent for {span:.0f} s ({seconds:.1f} s into the run) and "
                  "the node logged no warning.").format(
                    span=d.end - d.start, seconds=d.start - run.start),
                _("Log it: `self.get_logger().warn('no scan ...', throttle_duration_sec=1.0)`."))
        if count > allowed:
            raise StudentFailure(
                ngettext("The lidar was silent for {span:.0f} s and the node logged {count} "
                         "warning; at most about one a second ({allowed}) is useful.",
                         "The lidar was silent for {span:.0f} s and the node logged {count} "
                         "warnings; at most about one a second ({allowed}) is useful.",
                         count).format(span=d.end - d.start, count=count, allowed=allowed),
                _("Throttle the warning: `get_logger().warn(..., throttle_duration_sec=1.0)`."))
