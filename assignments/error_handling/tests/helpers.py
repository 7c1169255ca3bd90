"""Shared steps of the error_handling tests: scans made to order, and what cmd_vel says."""

from __future__ import annotations

import math
import re
import time
from collections.abc import Callable
from typing import Any

from geometry_msgs.msg import Twist
from rclpy.time import Time
from sensor_msgs.msg import LaserScan

from autograder.core.errors import StudentFailure
from autograder.i18n import _

# The simulated lidar: 360 beams counter-clockwise from straight ahead, 0.12 to 3.5 m.
BEAMS = 360
INCREMENT = 2 * math.pi / BEAMS
RANGE_MIN, RANGE_MAX = 0.12, 3.5
FORWARD, TURN = 0.2, 0.5
# A command published at a tick can be stamped by the probe one tick (0.1 s) late.
LATE = 0.15
# No cmd_vel for this long (five cycles) means the node no longer runs.
SILENT = 0.5


def bearing(beam: int) -> float:
    """The beam's direction in degrees, -180..180, positive to the left."""
    return (beam + 180) % 360 - 180


def make_scan(reading: Callable[[float], float] | float = 2.0, *, count: int = BEAMS,
              angle_increment: float = INCREMENT, angle_max: float | None = None) -> LaserScan:
    """A scan shaped like the world's; ``reading(bearing_degrees)`` gives each range."""
    scan = LaserScan()
    scan.header.frame_id = "base_scan"
    scan.angle_min = 0.0
    scan.angle_increment = angle_increment
    scan.angle_max = (BEAMS - 1) * INCREMENT if angle_max is None else angle_max
    scan.scan_time = 0.1
    scan.range_min, scan.range_max = RANGE_MIN, RANGE_MAX
    value = reading if callable(reading) else (lambda _b: float(reading))
    scan.ranges = [float(value(bearing(i % BEAMS))) for i in range(count)]
    return scan


def blocked(toward: int) -> LaserScan:
    """An obstacle 0.4 to 0.55 m ahead; open on the side ``toward`` (+1 left, -1 right), near
    on the other, so every sensible measure of room (mean, minimum, count) agrees."""
    def reading(b: float) -> float:
        if abs(b) <= 35:
            return 0.55 if b * toward > 0 else 0.4
        return 3.0 if b * toward > 0 else 0.5
    return make_scan(reading)


CLEAR = make_scan(2.0)


class ScanFeeder:
    """Publishes one scan on /scan every 0.1 s of simulation time, as the lidar would.

    Each goes out from the world's own thread, right after a tick's /clock
    (``world.after_each_tick``), so the world holds its next tick until the node has taken
    the scan in, whatever the load. A thread of the grader's own, which the world does not
    wait for, ran ticks late on a loaded machine: at eight times real time a 0.5 s watchdog
    is 62 ms of wall time, and a correct node stopped for want of scans (CI, a known-bad
    variant that lost ``test_drives_when_clear`` as well). A new scan goes out at once,
    between two ticks, when it is fed: a node is judged from a time it could have had it."""

    def __init__(self, probe: Any, world: Any) -> None:
        self.probe = probe
        self.world = world
        self.scan: LaserScan | None = None
        # Wall time (epoch seconds, as DDS source timestamps) the last scan was sent by.
        self.last_sent_wall: float | None = None
        self._due = 0.0  # the simulation time the next repeat is due at
        probe.publish(LaserScan, "/scan", CLEAR)  # creates the publisher; nobody listens yet
        self.close = world.after_each_tick(self._tick)

    def _send(self, scan: LaserScan, now: float) -> None:
        scan.header.stamp = Time(nanoseconds=round(now * 1e9)).to_msg()
        self.probe.publish(LaserScan, "/scan", scan)
        self.last_sent_wall = time.time()  # after the publish: the node got it later
        self._due = now + 0.1 - 1e-6  # sim time is steps * dt: 0.1 may read 0.0999...

    def _tick(self, now: float) -> None:
        if self.scan is not None and now >= self._due:
            self._send(self.scan, now)

    def feed(self, scan: LaserScan | None) -> float:
        """From now on publish ``scan`` (None: nothing), the first at once; the simulation
        time it changed (nothing else is sent after this returns)."""
        def change() -> float:
            self.scan = scan
            now = float(self.world.now)
            if scan is not None:
                self._send(scan, now)
            return now
        return self.world.between_ticks(change)


def is_zero(t: Twist) -> bool:
    return all(v == 0.0 for v in (t.linear.x, t.linear.y, t.linear.z,
                                  t.angular.x, t.angular.y, t.angular.z))


def is_forward(t: Twist) -> bool:
    return abs(t.linear.x - FORWARD) < 1e-3 and abs(t.angular.z) < 1e-3


def turn_of(t: Twist) -> int:
    """+1 turning left in place at TURN, -1 right, 0 otherwise."""
    if abs(t.linear.x) > 1e-3 or abs(abs(t.angular.z) - TURN) > 1e-3:
        return 0
    return 1 if t.angular.z > 0 else -1


def describe(t: Twist) -> str:
    return f"linear.x={t.linear.x:.3g}, angular.z={t.angular.z:.3g}"


# The last line of a Python traceback: "ValueError: cannot convert float NaN to integer".
RAISED = re.compile(r"^(?:[A-Za-z_][\w.]*\.)?([A-Z]\w*(?:Error|Exception))\b(?::.*)?$",
                    re.MULTILINE)


def raised(output: str) -> str | None:
    """The name of the exception the last traceback in ``output`` ended with, if any."""
    if "Traceback" not in output:
        return None
    found = RAISED.findall(output[output.rindex("Traceback"):])
    return found[-1] if found else None


def exception_hint(output: str) -> str:
    """Catch exceptions in callbacks; name the one the node raised, when it shows."""
    error = raised(output)
    if error:
        return _("It raised {error}: catch exceptions inside your callbacks, log them with "
                 "`get_logger().error(...)`, publish a stop and carry on.").format(error=error)
    return _("Catch exceptions inside your callbacks: log them with `get_logger().error(...)`, "
             "publish a stop and carry on.")


def alive(probe: Any, inbox: Any, node: Any, when: str) -> None:
    """Fail with the node's last words if its process ended or it stopped publishing."""
    probe.settle(inbox)
    if not node.running():
        raise StudentFailure(
            _("The node's process ended {when} (exit status {code}). Its last lines:\n{tail}")
            .format(when=when, code=node.returncode, tail=node.output_tail(12)),
            exception_hint(node.output()))
    stamps = inbox.times
    if not stamps or stamps[-1] < probe.now - SILENT:
        raise StudentFailure(
            _("The node stopped publishing on cmd_vel {when}, though its process still runs "
              "(did an exception end the thread that spins?). Its last lines:\n{tail}")
            .format(when=when, tail=node.output_tail(12)),
            exception_hint(node.output()))


def wait_command(probe: Any, inbox: Any, since: float, wanted: Callable[[Twist], bool],
                 sim_timeout: float) -> Twist | None:
    """The first cmd_vel stamped at or after ``since`` that is ``wanted``, or None."""
    def found() -> Twist | None:
        return next((m for t, m in inbox.items if t >= since and wanted(m)), None)
    probe.wait_for(lambda: found() is not None, sim_timeout)
    return found()


def window(inbox: Any, start: float, end: float) -> list[Twist]:
    return [m for t, m in inbox.items if start <= t <= end]


def settle_forward(probe: Any, inbox: Any, feeder: ScanFeeder, node: Any) -> float:
    """Feed a clear view until the node drives forward; the simulation time it did."""
    since = feeder.feed(CLEAR)
    if wait_command(probe, inbox, since, is_forward, 2.0) is None:
        alive(probe, inbox, node, _("while it was shown a clear way ahead"))
        last = inbox.messages[-1:] or None
        raise StudentFailure(
            _("With nothing nearer than 2 m, cmd_vel never said `linear.x={v}, angular.z=0` "
              "within 2 s (last command: {last}).").format(
                v=FORWARD, last=describe(last[0]) if last else _("none")),
            _("Publish from a 10 Hz timer: forward at 0.2 m/s when the nearest valid reading "
              "within ±30° of ahead is over 0.6 m."))
    return probe.now


WARN_LINE = re.compile(r"^\[WARN\] \[(\d+(?:\.\d+)?)\]", re.MULTILINE)


def warnings_between(output: str, start_wall: float, end_wall: float) -> int:
    """WARN lines logged (wall-clock stamps, as rclpy writes them) within the span."""
    return sum(1 for m in WARN_LINE.finditer(output)
               if start_wall <= float(m.group(1)) <= end_wall)
