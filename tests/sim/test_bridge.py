"""The bridge end to end: a probe node in sim time sees /odom, /scan and /clock, drives
the robot through /cmd_vel, and the bridge pauses, steps and resets.  The pacing's rules
are tested without ROS in test_sim_pacing.py; here a real busy process and a real student
node check that the bridge is paced by them."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field

import pytest
import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from sim.bridge import SimBridge
from sim.pacing import PacingPolicy
from sim.physics import World
from sim.worldfile import Box, Fault, load_world

WALL = 20.0  # generous wall-clock deadline for any one condition


@dataclass
class Probe:
    """A use_sim_time node that records what it receives with its own clock reading."""

    node: Node
    odom: list[tuple[float, float]] = field(default_factory=list)
    scans: list[tuple[float, int]] = field(default_factory=list)
    clocks: list[float] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.node.create_subscription(Odometry, "/odom", self._odom, 50)
        self.node.create_subscription(LaserScan, "/scan", self._scan, 50)
        self.node.create_subscription(Clock, "/clock", self._clock, 50)
        self.cmd = self.node.create_publisher(Twist, "/cmd_vel", 10)

    @staticmethod
    def _t(stamp: object) -> float:
        return stamp.sec + stamp.nanosec * 1e-9  # type: ignore[attr-defined]

    def _odom(self, msg: Odometry) -> None:
        self.odom.append((self._t(msg.header.stamp), msg.pose.pose.position.x))

    def _scan(self, msg: LaserScan) -> None:
        self.scans.append((self._t(msg.header.stamp), len(msg.ranges)))

    def _clock(self, msg: Clock) -> None:
        self.clocks.append(self._t(msg.clock))


@pytest.fixture(scope="module")
def graph(ros_domain: int) -> Iterator[tuple[SimBridge, Probe]]:
    domain = ros_domain
    ctx = Context()
    rclpy.init(context=ctx, domain_id=domain)
    # 50 Hz, not the graded 20: a tick (0.02 s at RTF 1) is then shorter than a busy
    # process's CPU budget (0.05 s), so holding for it visibly slows the world.
    bridge = SimBridge(World(load_world("empty_room")), ctx, real_time_factor=2.0,
                       policy=PacingPolicy(clock_hz=50.0))
    probe = Probe(Node("probe", context=ctx,
                       parameter_overrides=[Parameter("use_sim_time", value=True)]))
    executor = SingleThreadedExecutor(context=ctx)
    executor.add_node(probe.node)
    running = True

    def spin() -> None:
        while running and ctx.ok():
            executor.spin_once(timeout_sec=0.05)

    thread = threading.Thread(target=spin, daemon=True)
    thread.start()
    # Wait until the probe is matched with the bridge before time starts.
    bridge.node.get_clock()
    deadline = threading.Event()
    for _ in range(int(WALL / 0.05)):
        if probe.cmd.get_subscription_count() and probe.node.count_publishers("/odom"):
            break
        deadline.wait(0.05)
    bridge.start()
    try:
        yield bridge, probe
    finally:
        bridge.stop()
        running = False
        thread.join()
        executor.shutdown()
        probe.node.destroy_node()
        rclpy.try_shutdown(context=ctx)


def test_topics_at_sim_time_rates(graph: tuple[SimBridge, Probe]) -> None:
    bridge, probe = graph
    assert bridge.wait_for(lambda: len(probe.scans) >= 15, sim_timeout=5.0, wall_timeout=WALL)
    odom_stamps = [t for t, _ in probe.odom]
    scan_stamps = [t for t, _ in probe.scans]
    assert all(c > 0 for c in probe.clocks), "a /clock of 0 was published"
    assert probe.clocks == sorted(probe.clocks)
    gaps = {round(b - a, 6) for a, b in zip(odom_stamps, odom_stamps[1:], strict=False)}
    assert gaps == {0.02}, "odometry must come every 0.02 s of sim time (50 Hz)"
    gaps = {round(b - a, 6) for a, b in zip(scan_stamps, scan_stamps[1:], strict=False)}
    assert gaps == {0.1}, "scans must come every 0.1 s of sim time (10 Hz)"
    assert all(n == 360 for _, n in probe.scans)
    # REP 105: odom starts where the robot starts, not at its world pose (3, 3).
    assert probe.odom[0][1] == 0.0
    assert probe.node.get_clock().now().nanoseconds > 0


def test_cmd_vel_moves_robot(graph: tuple[SimBridge, Probe]) -> None:
    bridge, probe = graph
    x0, odom_x0 = bridge.world.pose[0], probe.odom[-1][1]
    msg = Twist()
    msg.linear.x = 0.5
    probe.cmd.publish(msg)
    assert bridge.wait_for(lambda: bridge.world.pose[0] > x0 + 0.3, sim_timeout=3.0,
                           wall_timeout=WALL)
    assert bridge.wait_for(lambda: probe.odom[-1][1] > odom_x0 + 0.3, sim_timeout=1.0,
                           wall_timeout=WALL)
    assert math.isclose(bridge.world.velocity[0], 0.5, abs_tol=1e-3)
    # The recording keeps the command, for the report's replay.
    assert (0.5, 0.0) in [(c.linear, c.angular) for c in bridge.recording.commands]
    probe.cmd.publish(Twist())


def test_pause_step_reset(graph: tuple[SimBridge, Probe]) -> None:
    bridge, probe = graph
    bridge.pause()
    t0 = bridge.now
    assert not bridge.wait_until(t0 + 0.1, wall_timeout=0.3)  # frozen while paused
    bridge.step(10)
    assert bridge.now == pytest.approx(t0 + 0.05)
    assert bridge.wait_for(lambda: probe.clocks and probe.clocks[-1] == pytest.approx(t0 + 0.05),
                           sim_timeout=1.0, wall_timeout=WALL)
    bridge.reset()
    assert bridge.now == 0.0
    assert bridge.world.pose == (3.0, 3.0, 0.0)
    bridge.resume()
    assert bridge.wait_until(0.5, wall_timeout=WALL)  # running again (not its pace: load)


def test_the_world_takes_commands_at_each_tick(graph: tuple[SimBridge, Probe]) -> None:
    """No executor takes /cmd_vel: the world's thread takes every command that has arrived
    before it steps, and the last of them drives that tick (while paused nothing takes
    them, so they wait in the middleware)."""
    bridge, probe = graph
    bridge.pause()
    try:
        taken: list[int] = []
        for speed in (0.1, 0.2):
            msg = Twist()
            msg.linear.x = speed
            probe.cmd.publish(msg)
        assert bridge.wait_for(lambda: taken.append(bridge.take_commands()) or sum(taken) == 2,
                               sim_timeout=1.0, wall_timeout=WALL)
        assert bridge.take_commands() == 0
        bridge.step(1)
        assert bridge.recording.commands[-1].linear == 0.2
        assert bridge.late_commands == 0  # sent while paused, taken before the next tick
        # One sent after the last tick went out, and taken only after the next, was late
        # by that tick.
        sent = (bridge.last_tick_sent_ns or 0) + 1
        bridge.step(1)
        bridge.note_lateness({"source_timestamp": sent})
        assert bridge.late_commands == 1
        assert bridge.latest_command == pytest.approx(0.005)  # one tick of one 5 ms step
    finally:
        probe.cmd.publish(Twist())
        bridge.resume()


def test_waits_are_told_to_on_wait(graph: tuple[SimBridge, Probe]) -> None:
    """Each wait on sim time tells the grader's timing how long it blocked and how much
    of that the world was held (none here: no process is watched)."""
    bridge, _probe = graph
    told: list[tuple[float, float]] = []
    bridge.on_wait = lambda seconds, held: told.append((seconds, held))
    try:
        assert bridge.wait_until(bridge.now + 0.1, wall_timeout=WALL)
        assert bridge.wait_for(lambda: True, sim_timeout=1.0, wall_timeout=WALL)
    finally:
        bridge.on_wait = None
    assert len(told) == 2
    assert all(seconds >= 0 and held == 0 for seconds, held in told)


def test_scheduled_pace_lands_on_its_sim_time(graph: tuple[SimBridge, Probe]) -> None:
    """A pace change scheduled for a sim time is made by the world at the first tick from
    that time, not when the caller's thread next looks; cancelled ones are not made."""
    bridge, _probe = graph
    pace, tick = bridge.real_time_factor, 2.0 / 50.0  # this world's tick, in sim seconds
    start = bridge.now
    bridge.schedule_real_time_factor(start + 0.5, 1.0)
    bridge.schedule_real_time_factor(start + 0.3, 0.5)  # out of order: made first
    bridge.schedule_real_time_factor(start + 5.0, 3.0)
    try:
        assert bridge.wait_until(start + 0.6, wall_timeout=WALL)
        made = [(t, rtf) for t, rtf in bridge.pace_changes if t >= start]
        assert [rtf for _t, rtf in made] == [0.5, 1.0]
        for (t, _rtf), at in zip(made, (start + 0.3, start + 0.5), strict=True):
            # At the tick from `at` on (its length: 0.04 s at RTF 2, 0.01 s at 0.5).
            assert at - 1e-9 <= t < at + tick
        assert bridge.real_time_factor == 1.0
        bridge.cancel_scheduled_pace()
    finally:
        bridge.cancel_scheduled_pace()
        bridge.set_real_time_factor(pace)
    assert [rtf for t, rtf in bridge.pace_changes if t >= start] == [0.5, 1.0]


def _rtf_over(bridge: SimBridge, sim_seconds: float) -> float:
    """Measured RTF over the next ``sim_seconds`` of sim time."""
    assert bridge.wait_until(bridge.now + 0.1, wall_timeout=WALL)  # fresh window
    assert bridge.wait_until(bridge.now + sim_seconds, wall_timeout=WALL)
    return bridge.effective_rtf


def _holds_after_it_is_found_deaf(bridge: SimBridge, pid: int) -> dict[str, int]:
    """Watch ``pid``, which hears no ticks: the first tick is held ``hear_timeout`` for it
    (wait for that); then how the holds of the next 0.4 s of sim time ended."""
    unheard = bridge.pacing.get("unheard", 0)
    bridge.watch_pid(pid)
    assert bridge.wait_for(lambda: bridge.pacing.get("unheard", 0) > unheard, 5.0, WALL)
    before = dict(bridge.pacing)
    assert bridge.wait_until(bridge.now + 0.4, wall_timeout=WALL)
    return {k: bridge.pacing.get(k, 0) - before.get(k, 0) for k in set(bridge.pacing)}


def test_watched_process_paces_sim_time(graph: tuple[SimBridge, Probe]) -> None:
    """A busy student process holds sim time back; an idle one that hears no ticks does
    not, once it has been waited for to hear one."""
    bridge, _ = graph
    bridge.set_real_time_factor(1.0)
    busy = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    idle = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        bridge.watch_pid(busy.pid)
        before = dict(bridge.pacing)
        slowed = _rtf_over(bridge, 0.4)
        let_go = bridge.pacing["budget"] - before.get("budget", 0)
        bridge.unwatch_pid(busy.pid)
        ended = _holds_after_it_is_found_deaf(bridge, idle.pid)  # it has no node
    finally:
        bridge.watch_pid(None)
        for proc in (busy, idle):
            proc.kill()
            proc.wait()
    # A tick is 0.02 s of sim time; a busy process gets 0.05 s of CPU before it passes.
    assert slowed < 0.6, slowed
    assert let_go > 0, bridge.pacing  # what the results report
    # The idle one held no tick for its CPU share or to hear it again: each hold ended as
    # soon as it was seen idle. (Not the pace measured on the wall clock: on a loaded
    # machine the world's own thread runs late, whoever it watches; 0.60 was seen with
    # four test workers on 2 cores.)
    assert ended.get("idle", 0) > 0, ended
    assert not any(ended.get(k, 0) for k in ("budget", "unheard", "cap")), ended


POSING_AS_MIDDLEWARE = """
import os, rclpy
from rclpy.node import Node
rclpy.init()
node = Node("posing", parameter_overrides=[
    rclpy.parameter.Parameter("use_sim_time", value=True)])
for tid in os.listdir("/proc/self/task"):  # every thread named as Fast DDS names its own
    with open(f"/proc/self/task/{tid}/comm", "w") as fh:
        fh.write("dds.posing")
print("posing", flush=True)
rclpy.spin(node)
"""


def test_a_node_posing_as_its_middleware_is_only_deaf(graph: tuple[SimBridge, Probe]) -> None:
    """Heard is read from a program's own threads, not those named as Fast DDS names its
    threads (``dds.*``). A program that names every thread so hears nothing the pacing
    can see: it is waited for once, as a node without ``/clock`` is, then the world goes
    on at its pace; it gains no hold."""
    bridge, _ = graph
    bridge.set_real_time_factor(1.0)
    env = {**os.environ, "ROS_DOMAIN_ID": str(bridge.node.context.get_domain_id())}
    posing = subprocess.Popen([sys.executable, "-c", POSING_AS_MIDDLEWARE], env=env,
                              stdout=subprocess.PIPE, text=True)
    try:
        assert posing.stdout is not None and posing.stdout.readline() == "posing\n"
        ended = _holds_after_it_is_found_deaf(bridge, posing.pid)
    finally:
        bridge.watch_pid(None)
        posing.kill()
        posing.wait()
        posing.stdout.close()
    assert ended.get("idle", 0) > 0, ended
    assert not any(ended.get(k, 0) for k in ("budget", "unheard", "cap")), ended


STUDENT = """
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from sensor_msgs.msg import LaserScan

class StopBeforeWall(Node):
    def __init__(self):
        super().__init__("student", parameter_overrides=[
            rclpy.parameter.Parameter("use_sim_time", value=True)])
        self.pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(LaserScan, "/scan", self.on_scan, 10)

    def on_scan(self, msg):
        cmd = Twist()
        cmd.linear.x = 0.3 if msg.ranges[0] > 0.5 else 0.0
        self.pub.publish(cmd)

rclpy.init()
rclpy.spin(StopBeforeWall())
"""


def test_student_process_stops_before_wall(tmp_path, graph: tuple[SimBridge, Probe]) -> None:
    """A separate use_sim_time process drives on /scan; paced by its holds it stops in
    time, in the wall_ahead geometry rebuilt by a run-time obstacle."""
    bridge, probe = graph
    bridge.pause()
    bridge.reset()
    bridge.world.add_obstacle(Box(center=(4.025, 3.0), size=(0.05, 4.0)))  # face at x = 4
    script = tmp_path / "student.py"
    script.write_text(STUDENT)
    env = {**os.environ, "ROS_DOMAIN_ID": str(bridge.node.context.get_domain_id())}
    student = subprocess.Popen([sys.executable, str(script)], env=env)
    try:
        bridge.watch_pid(student.pid)
        assert bridge.wait_for(lambda: bridge.node.count_publishers("/cmd_vel") >= 2,
                               sim_timeout=math.inf, wall_timeout=WALL)
        bridge.resume()
        assert bridge.wait_for(lambda: bridge.world.velocity[0] > 0.29, sim_timeout=3.0,
                               wall_timeout=WALL)
        assert bridge.wait_for(lambda: abs(bridge.world.velocity[0]) < 1e-3, sim_timeout=5.0,
                               wall_timeout=WALL)
        assert bridge.wait_until(bridge.now + 0.5, wall_timeout=WALL)
        x = bridge.world.pose[0]
        # The scanner, 3.2 cm behind the centre, reads 0.5 m at x = 3.532 (give or take
        # 3 sigma of noise, 0.03 m); then <= 1 scan + 1 tick + braking (0.054 m).
        assert 3.5 <= x < 3.62, x
        assert bridge.recording.collisions == []
    finally:
        bridge.watch_pid(None)
        student.terminate()
        student.wait(timeout=WALL)


def test_a_hook_runs_in_step_with_every_tick(graph: tuple[SimBridge, Probe]) -> None:
    """after_each_tick calls its hook in the world's thread once per tick, with the sim time
    of the /clock that tick just sent (what a grader standing in for a sensor publishes
    then goes out with that tick), until it is removed; between_ticks runs an action while
    no tick is under way, so the sim time it reads is the last /clock's, never one a tick
    has stepped to and not yet published."""
    bridge, _probe = graph
    clocks: list[float] = []
    calls: list[tuple[float, str]] = []
    bridge.add_tap(lambda topic, _type, _msg, t: clocks.append(t) if topic == "/clock" else None)
    remove = bridge.after_each_tick(
        lambda t: calls.append((t, threading.current_thread().name)))
    assert bridge.wait_for(lambda: len(calls) >= 30, sim_timeout=5.0, wall_timeout=WALL)
    remove()
    bridge.pause()  # no tick goes while the two lists are compared
    try:
        ended = len(calls)
        assert [t for t, _thread in calls] == clocks[-ended:]
        assert {thread for _t, thread in calls} == {"sim-physics"}
    finally:
        bridge.resume()
    assert bridge.wait_until(bridge.now + 0.5, wall_timeout=WALL)
    assert len(calls) == ended  # removed: no more calls though the world ran on

    def read() -> tuple[float, float]:
        return bridge.now, clocks[-1]

    start, readings = bridge.now, []
    while bridge.now < start + 0.5:  # read as often as we can while ticks go on
        readings.append(bridge.between_ticks(read))
    assert all(now == last_clock for now, last_clock in readings)


def test_inject_says_from_when_messages_show_the_fault(
        graph: tuple[SimBridge, Probe]) -> None:
    """A fault added while a tick is under way (here by a tap, between that tick's /clock
    and its /scan, which was computed before) shows from the next tick on: inject()
    returns the sim time after which every message has it, not the one read before.
    Last in the module: the box stays in the bridge's world (faults are never removed)."""
    bridge, _probe = graph
    bridge.reset()  # in the open room, away from the wall an earlier test drove to
    x, y, theta = bridge.world.pose
    box = Box(center=(x + 0.4 * math.cos(theta), y + 0.4 * math.sin(theta)), size=(0.1, 0.6))
    armed = False
    added: list[float] = []
    scans: list[tuple[float, float]] = []  # (sim time, nearest reading)

    def tap(topic: str, _type: str, message: object, t: float) -> None:
        nonlocal armed
        if topic == "/clock" and armed:
            armed = False
            added.append(bridge.inject(Fault(kind="obstacle", start=t - 0.05, end=t + 0.5,
                                             box=box)))
        elif topic == "/scan" and added:
            scans.append((t, min(message.ranges)))  # type: ignore[attr-defined]

    bridge.add_tap(tap)
    bridge.pause()
    try:
        armed = True
        bridge.step(20)  # 0.1 s: one scan, taken before the tap adds the box
        bridge.step(20)
    finally:
        bridge.resume()
    assert added == [pytest.approx(bridge.now - 0.1)]
    (before, nearest_before), (after, nearest_after) = scans[:2]
    assert before <= added[0] < after
    assert nearest_before > 1.0  # the open room: the box was added after this scan
    assert nearest_after == pytest.approx(0.35, abs=0.03)  # its near face
