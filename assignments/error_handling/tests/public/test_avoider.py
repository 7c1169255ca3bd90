"""Public tests: the grader feeds made-up scans on /scan and reads cmd_vel.

The world's own lidar is switched off (a dropout with no end) so that only the grader's
scans reach the node.  Tests that may kill a careless node come last; a node that died
in one test is started afresh for the next.
"""

import math

import pytest
from helpers import (
    CLEAR,
    FORWARD,
    LATE,
    SILENT,
    TURN,
    ScanFeeder,
    alive,
    blocked,
    describe,
    is_forward,
    is_zero,
    make_scan,
    settle_forward,
    turn_of,
    wait_command,
    window,
)
from sensor_msgs.msg import LaserScan

from autograder.core.errors import StudentFailure
from autograder.i18n import _, ngettext
from sim.worldfile import Fault

pytestmark = pytest.mark.world("empty_room")


@pytest.fixture(scope="module")
def feeder(world, probe):
    """Silence the world's lidar; the grader's scans are all the node sees."""
    world.inject(Fault(kind="dropout", start=world.now))
    feeder = ScanFeeder(probe, world)
    yield feeder
    feeder.close()  # before the probe, whose publisher it sends with, goes


@pytest.fixture
def avoider(feeder, student, start_node, probe, commands):
    """The module's node, or a fresh one if an earlier test killed it."""
    feeder.feed(CLEAR)  # whatever an earlier test left on /scan, a new node starts sane
    node = student
    if node.running():
        probe.wait_sim(SILENT)
        probe.settle(commands)
    if node.running() and not (commands.times and commands.times[-1] >= probe.now - SILENT):
        node.stop()  # running but silent: an exception ended the thread that spins it
    if not node.running():
        node = start_node()
    if not probe.wait_for_subscriber(LaserScan, "/scan", 5.0):
        raise StudentFailure(
            _("Nothing subscribes to scan."),
            _("Create a subscription: `self.create_subscription(LaserScan, 'scan', ...)`."))
    return node


@pytest.mark.points(1)
def test_publishes_at_10_hz(avoider, feeder, probe, commands):
    """The node subscribes to scan and publishes cmd_vel from a 10 Hz timer"""
    feeder.feed(CLEAR)
    probe.wait_sim(0.5)
    start = probe.now
    probe.wait_sim(3.0)
    probe.settle(commands)
    count = len(window(commands, start, start + 3.0))
    if not 24 <= count <= 36:  # 10 Hz, give or take cycles a busy machine may cost
        raise StudentFailure(
            ngettext("In 3 s of simulation time cmd_vel was published {count} time; a 10 Hz "
                     "timer gives 30.",
                     "In 3 s of simulation time cmd_vel was published {count} times; a 10 Hz "
                     "timer gives 30.", count).format(count=count),
            _("That is more than once a cycle: publish only from the timer of "
              "`self.create_timer(0.1, ...)`, not from the scan callback as well.") if count > 36
            else _("That is less than once a cycle: publish on every cycle of "
                   "`self.create_timer(0.1, ...)`, a stop included, not only from the scan "
                   "callback or when something changes."))


@pytest.mark.points(1)
def test_drives_when_clear(avoider, feeder, probe, commands):
    """With a clear way ahead, it drives forward at 0.2 m/s"""
    start = settle_forward(probe, commands, feeder, avoider)
    probe.wait_sim(1.0)
    probe.settle(commands)
    wrong = [m for m in window(commands, start, probe.now) if not is_forward(m)]
    if wrong:
        raise StudentFailure(
            _("With a clear way ahead cmd_vel said {got}; expected "
              "`linear.x={v}, angular.z=0` on every cycle.").format(
                got=describe(wrong[0]), v=FORWARD),
            _("Nothing was nearer than 2 m: with no valid reading within ±30° of ahead at "
              "0.6 m or nearer, publish `linear.x=0.2, angular.z=0` on every cycle."))


@pytest.mark.points(2)
def test_turns_toward_room(avoider, feeder, probe, commands):
    """Blocked within 0.6 m ahead, it turns in place toward the side with more room"""
    for toward, side in ((1, _("left")), (-1, _("right"))):
        settle_forward(probe, commands, feeder, avoider)
        since = feeder.feed(blocked(toward))
        turned = wait_command(probe, commands, since, lambda m: not is_forward(m), 1.0)
        if turned is None or turn_of(turned) != toward:
            raise StudentFailure(
                _("An obstacle 0.4 to 0.55 m ahead, open space on the {side}: cmd_vel said {got}; "
                  "expected `linear.x=0, angular.z={z}`.").format(
                    side=side, got=describe(turned) if turned else _("nothing new"),
                    z=toward * TURN),
                _("It turned toward the nearer side: sum or average the valid readings on the "
                  "left (bearings 0 to 180°, `angular.z > 0`) and on the right, and turn toward "
                  "the larger.") if turned is not None and turn_of(turned) == -toward else
                _("Turn in place (`linear.x=0`) at ±0.5 rad/s, positive to the left, toward "
                  "the side whose valid readings are farther."))


@pytest.mark.points(2)
def test_watchdog_stops(avoider, feeder, probe, world, commands):
    """When scans stop for 0.5 s it publishes a stop every cycle, then moves when they return"""
    settle_forward(probe, commands, feeder, avoider)
    silent = feeder.feed(None)
    probe.wait_sim(2.5)
    probe.settle(commands)
    late = window(commands, silent + 0.5 + 0.2 + LATE, probe.now)
    moving = [m for m in late if not is_zero(m)]
    if moving:
        # Failed. For the hint only: a watchdog on the wall clock stops once WALL_WATCHDOG's
        # wall seconds have passed, which at a fast pace is past the 2.5 s of simulation
        # time (4 s at eight times real time); the world never runs faster than its pace,
        # so waiting that many seconds of simulation time waits at least as long in wall time.
        probe.wait_for(lambda: is_zero(commands.messages[-1]),
                       WALL_WATCHDOG[1] * world.real_time_factor - (probe.now - silent))
        probe.settle(commands)
        raise StudentFailure(
            ngettext("With no scan for 2.5 s of simulation time, {moving} of the {count} "
                     "cmd_vel messages from 0.85 s on was not a stop ({got}); expected a zero "
                     "Twist on every 10 Hz cycle once 0.5 s pass without a scan.",
                     "With no scan for 2.5 s of simulation time, {moving} of the {count} "
                     "cmd_vel messages from 0.85 s on were not a stop ({got}); expected a zero "
                     "Twist on every 10 Hz cycle once 0.5 s pass without a scan.",
                     len(moving)).format(count=len(late), moving=len(moving),
                                         got=describe(moving[0])),
            _late_watchdog_hint(commands, silent, feeder.last_sent_wall))
    if len(late) < 13:
        raise StudentFailure(
            ngettext("With no scan for 2.5 s of simulation time, cmd_vel was published {count} "
                     "time from 0.85 s on; expected a zero Twist on every 10 Hz cycle once "
                     "0.5 s pass without a scan.",
                     "With no scan for 2.5 s of simulation time, cmd_vel was published {count} "
                     "times from 0.85 s on; expected a zero Twist on every 10 Hz cycle once "
                     "0.5 s pass without a scan.", len(late)).format(count=len(late)),
            _("Publish the stop from the 10 Hz timer on every cycle while the last scan is "
              "more than 0.5 s old, not once and not from the scan callback."))
    settle_forward(probe, commands, feeder, avoider)


def _late_watchdog_hint(commands, silent: float, last_scan_wall: float | None) -> str:
    """The fix, by when the node stopped on its own: never, or late; and late by 0.5 s of
    wall time (a watchdog on the wall clock).  The wall time is read from the messages
    themselves: the last scan's send and the first stop's DDS source timestamp, so the
    verdict does not depend on how fast the world ran meanwhile (the load)."""
    items = commands.items  # first: the sent times taken after cover every one of them
    sent = [wall for _t, wall in commands.sent[:len(items)]]
    stops = [(t, wall) for (t, m), wall in zip(items, sent, strict=True)
             if t >= silent and is_zero(m)]
    if not stops or stops[-1][0] < silent + 0.5:
        return _("Remember when the last scan came (self.get_clock().now()); in the timer, "
                 "publish Twist() when it is more than 0.5 s old.")
    at, stop_wall = stops[0]
    after = at - silent
    wall = None if stop_wall is None or last_scan_wall is None else stop_wall - last_scan_wall
    if wall is not None and WALL_WATCHDOG[0] <= wall <= WALL_WATCHDOG[1]:
        return _("It stopped {after:.2f} s of simulation time after the last scan, but "
                 "{wall:.2f} s of wall time after it: 0.5 s of wall time and the next cycle, "
                 "however fast the world ran. The watchdog measures the wall clock "
                 "(time.time, time.monotonic); take the scan's age from "
                 "self.get_clock().now(), which follows /clock.").format(after=after, wall=wall)
    return _("It stopped {after:.2f} s after the last scan, not once the scan was 0.5 s "
             "old: compare the scan's age with 0.5 s on every 10 Hz cycle.").format(
        after=after)


# Wall seconds from the last scan's send to the first stop's that show a watchdog timed by
# the wall clock: 0.5 s (the node got the scan after it was sent, so never less), then up
# to a cycle and a tick's hold on a loaded machine, whatever the world's pace.  A watchdog
# in simulation time stops at a sim time, so its wall time follows the pace: one that is
# merely late (a threshold of 0.6 to 1 s, a check every few cycles) stops well under 0.48 s
# of wall time after the scan at three times real time or faster (0.13 s at the exercise's
# eight times).
WALL_WATCHDOG = (0.48, 1.0)


@pytest.mark.points(2)
def test_rejects_malformed_scans(avoider, feeder, probe, commands):
    """An empty scan, or one whose length disagrees with its angles, gives a stop"""
    hints = (_("An empty ranges list shows no obstacle, but no open way either: stop when "
               "`len(scan.ranges) == 0`."),
             _("Its angles say 360 beams and it held 180: before using a scan, check "
               "`len(ranges) == round((angle_max - angle_min) / angle_increment) + 1`, and stop "
               "when it differs."))
    for (bad, what), hint in zip(
            ((make_scan(count=0), _("an empty scan")),
             (make_scan(count=180), _("a scan of 180 ranges whose angles say 360"))),
            hints, strict=True):
        settle_forward(probe, commands, feeder, avoider)
        since = feeder.feed(bad)
        probe.wait_sim(1.0)
        alive(probe, commands, avoider, _("after it was sent {what}").format(what=what))
        stop = wait_command(probe, commands, since, is_zero, 0.1)
        going = [m for m in window(commands, since + 0.2 + LATE, probe.now) if not is_zero(m)]
        if stop is None or going:
            raise StudentFailure(
                _("After {what}, cmd_vel said {got}; expected a zero Twist for that "
                  "cycle.").format(what=what, got=describe(going[0]) if going else
                                   _("nothing")),
                hint if going else
                _("Before using a scan, check `len(ranges)` against "
                  "`(angle_max - angle_min) / angle_increment + 1`; reject an empty or mismatched "
                  "scan with a stop."))
    settle_forward(probe, commands, feeder, avoider)


RANGE_BELOW, RANGE_ABOVE = 0.05, 9.0


def _invalid(b: float) -> float:
    """Ahead: nothing but readings to ignore; elsewhere 2 m."""
    if abs(b) > 25:
        return 2.0
    return (math.nan, math.inf, -math.inf, RANGE_BELOW, RANGE_ABOVE)[int(b) % 5]


def _hidden_obstacle(b: float) -> float:
    """A real obstacle 0.45 m ahead among NaN readings."""
    if abs(b) <= 6:
        return 0.45
    return math.nan if abs(b) <= 25 else 2.0


@pytest.mark.points(2)
def test_ignores_invalid_readings(avoider, feeder, probe, commands):
    """NaN, ±inf and out-of-range readings are ignored; valid ones still count"""
    settle_forward(probe, commands, feeder, avoider)
    since = feeder.feed(make_scan(_invalid))
    probe.wait_sim(1.0)
    alive(probe, commands, avoider, _("after a scan with NaN and ±inf readings"))
    wrong = [m for m in window(commands, since + LATE, probe.now) if not is_forward(m)]
    if wrong:
        raise StudentFailure(
            _("Ahead were only NaN, inf, -inf, 0.05 m (below range_min) and 9 m (above "
              "range_max) readings, the rest 2 m away: cmd_vel said {got}; expected forward "
              "at {v} m/s.").format(got=describe(wrong[0]), v=FORWARD),
            _("Skip a reading unless `range_min <= r <= range_max` (false for NaN and inf)."))
    since = feeder.feed(make_scan(_hidden_obstacle))
    turned = wait_command(probe, commands, since, lambda m: turn_of(m) != 0, 1.0)
    alive(probe, commands, avoider, _("after a scan with NaN readings"))
    if turned is None:
        raise StudentFailure(
            _("An obstacle 0.45 m ahead, between NaN readings, did not make the robot turn "
              "in place within 1 s."),
            _("Ignore only the invalid readings: the valid ones ahead still decide."))
    settle_forward(probe, commands, feeder, avoider)


@pytest.mark.points(2)
def test_survives_exceptions(avoider, feeder, probe, commands):
    """A scan that makes a careless node raise gives a stop, and the node lives on"""
    for bad, what in ((make_scan(angle_increment=0.0), _("angle_increment 0")),
                      (make_scan(angle_increment=math.nan), _("angle_increment NaN"))):
        settle_forward(probe, commands, feeder, avoider)
        since = feeder.feed(bad)
        probe.wait_sim(1.0)
        alive(probe, commands, avoider, _("after a scan with {what}").format(what=what))
        stop = wait_command(probe, commands, since, is_zero, 0.1)
        going = [m for m in window(commands, since + 0.2 + LATE, probe.now) if not is_zero(m)]
        if stop is None or going:
            raise StudentFailure(
                _("After a scan with {what}, cmd_vel said {got}; expected a zero Twist.")
                .format(what=what, got=describe(going[0]) if going else _("nothing")),
                _("It carried on driving: a scan whose angle_increment is 0 or NaN gives no "
                  "directions to judge. Check angle_increment (and the length of ranges) "
                  "before use, and stop for that cycle.") if going else
                _("Wrap the work of each callback in try/except Exception: log the error "
                  "with `get_logger().error(...)` and publish Twist()."))
    settle_forward(probe, commands, feeder, avoider)
    alive(probe, commands, avoider, _("after the scans it could not use"))
