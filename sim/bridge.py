"""The ROS side of the world: /cmd_vel in; /odom, /scan and /clock out, in sim time.

The world advances in *clock ticks*.  A tick is a whole number of physics steps; after it
the bridge publishes ``/clock`` (the tick's end time) and then the odometry and scans that
fell due inside it, so a subscriber's clock has already reached a message's stamp.
Commands on ``/cmd_vel`` are taken by the world's own thread at the start of each tick, not
by an executor: every command the node's middleware has handed to the bridge by then drives
that tick, however long an executor thread would wait for a CPU.

What goes out is what a TurtleBot3 on Jazzy gives (REP 105 frames): ``/odom`` is wheel
odometry in the ``odom`` frame, which starts at (0, 0, 0) where the robot starts, with
child frame ``base_footprint`` and the wheel speeds as its twist; the world-frame ground
truth stays in :attr:`SimBridge.recording`.  ``/scan`` is in ``base_scan``, the scanner's
frame (mounted as the world file's ``lidar.mount`` says), with seeded Gaussian noise and
REP 117's -inf/+inf.  ``/cmd_vel`` is taken as the world's ``cmd_vel_type``, ``Twist`` or
``TwistStamped`` (whose ``twist`` drives); :meth:`SimBridge.cmd_vel_mismatches` names the
publishers of the other type, which the robot cannot hear.

How long a tick is and when the next may go (the real-time factor, at most ``clock_hz``
ticks per wall second, holding for a busy student process, the start-up hold) is decided
by :class:`sim.pacing.Pacer` under a :class:`sim.pacing.PacingPolicy`; the bridge only
steps the world and publishes.
``effective_rtf`` reports the measured sim seconds per wall second of the last ticks.

Physics runs in one thread and an executor in another (the node serves no parameter
services: another node must not set its ``use_sim_time``); the world is only touched
under the bridge's lock (the pacer's condition), and waiters are woken on it each tick.
Taps (:meth:`SimBridge.add_tap`, e.g. a :class:`sim.bag.BagRecorder`) see every message
the bridge publishes or receives, with its simulation time.  A grader that stands in for a
sensor publishes from :meth:`SimBridge.after_each_tick`, in the world's thread, so that
its messages keep step with ``/clock`` as the lidar's do (a thread of its own can run
ticks late on a loaded machine), and changes what it publishes in
:meth:`SimBridge.between_ticks`.
"""

from __future__ import annotations

import array
import bisect
import contextlib
import math
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from contextlib import AbstractContextManager
from typing import Any, TypeVar

from nav_msgs.msg import Odometry
from rclpy.callback_groups import CallbackGroup
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from sim.cmdvel import CMD_VEL_TOPIC, MESSAGE_TYPES, Mismatch, full_name, mismatches, twist_of
from sim.engine import SCAN_HZ, Outputs, Simulation
from sim.faults import Scan
from sim.msgdefs import type_name
from sim.pacing import HoldOutcome, Pacer, PacingPolicy
from sim.physics import World
from sim.procstate import Receiving, backlog
from sim.recorder import Recording, Sample
from sim.worldfile import CmdVelType, Fault


class _TakenByTheWorld(CallbackGroup):
    """A callback group no executor runs: its subscription is never in an executor's wait
    set, and the world's thread takes its messages itself (:meth:`SimBridge.take_commands`)."""

    def can_execute(self, entity: object) -> bool:
        return False

    def beginning_execution(self, entity: object) -> bool:
        return False

    def ending_execution(self, entity: object) -> None:
        pass


T = TypeVar("T")


def _stamp(t: float) -> tuple[int, int]:
    ns = round(t * 1e9)
    return ns // 1_000_000_000, ns % 1_000_000_000


class SimBridge:
    """Runs a :class:`World` as a ROS 2 robot in the given rclpy context."""

    PUBLISHES = ("/clock", "/odom", "/scan")
    SUBSCRIBES = ("/cmd_vel",)

    def __init__(self, world: World, context: Context, *, real_time_factor: float = 1.0,
                 policy: PacingPolicy | None = None, node_name: str = "sim_world",
                 cmd_vel_type: CmdVelType | None = None, gated: bool = False) -> None:
        self.sim = Simulation(world)
        self.cmd_vel_type: CmdVelType = cmd_vel_type or world.spec.cmd_vel_type
        self.world = world
        self.recheck = 0.01
        # Before the node: bad settings (a negative RTF, no clock rate) raise ValueError here.
        # A hold for the student's node ends once our middleware has taken in what it sent.
        self._receiving = Receiving()
        # gated: sim time stays at 0 until a wait for sim time (or for a node to come up)
        # opens the gate, however long the grader takes to set a module up.
        self.pacer = Pacer(world.dt, real_time_factor, policy, receiving=self._receiving,
                           delivering=lambda: backlog() > 0, gated=gated)
        self._cond = self.pacer.condition
        # The watched programs' families (see watch_pid): pid -> their pids now.
        self._families: dict[int, Callable[[], Iterable[int]]] = {}
        self._cmd: tuple[float, float] | None = None
        # Commands taken in a later tick than the one they were sent in, and the most sim
        # seconds one was late: the world's own check that no tick overtook a command.
        self.late_commands = 0
        self.latest_command = 0.0
        # (time.time_ns() just before a tick's /clock went out, that tick's sim time)
        self._clock_log: list[tuple[int, float]] = []
        self._threads: list[threading.Thread] = []
        self._taps: list[Callable[[str, str, Any, float], None]] = []
        self._after_tick: list[Callable[[float], None]] = []
        self._listened: dict[str, object] = {}  # topic -> its subscription (see listen)
        # Pace changes due at a sim time (schedule_real_time_factor), soonest first, and
        # those made so far as (sim time, rtf).
        self._pace_due: list[tuple[float, float]] = []
        self.pace_changes: list[tuple[float, float]] = []
        # No parameter services: no other node may change the world's (use_sim_time).
        self.node = Node(node_name, context=context, start_parameter_services=False)
        qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self._clock_pub = self.node.create_publisher(Clock, "/clock", qos)
        self._odom_pub = self.node.create_publisher(Odometry, "/odom", qos)
        self._scan_pub = self.node.create_publisher(LaserScan, "/scan", qos)
        self._cmd_sub = self.node.create_subscription(
            MESSAGE_TYPES[self.cmd_vel_type], CMD_VEL_TOPIC, self._on_cmd_vel, 10,
            callback_group=_TakenByTheWorld())
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._context = context
        self._spinning = False
        # Told, after each wait_until/wait_for, the wall seconds it blocked and how many of
        # them the world was held for a busy watched process (the grader's timing).
        self.on_wait: Callable[[float, float], None] | None = None

    # -- life cycle -----------------------------------------------------------------
    def start(self) -> None:
        """Start the executor and physics threads (the world runs unless paused)."""
        self._spinning = True
        self._threads = [threading.Thread(target=self._spin, name="sim-executor", daemon=True),
                         threading.Thread(target=self._run, name="sim-physics", daemon=True)]
        for thread in self._threads:
            thread.start()

    def stop(self) -> None:
        """Stop both threads, wait for them, and destroy the node."""
        self._spinning = False
        self.pacer.stop()
        for thread in self._threads:
            thread.join()
        self._threads = []
        self._take_last_commands()
        self._receiving.close()
        self._executor.remove_node(self.node)
        self._executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()

    def pause(self) -> None:
        """Freeze sim time; no tick starts after this returns."""
        self.pacer.pause()

    def resume(self) -> None:
        self.pacer.resume()

    def held(self) -> AbstractContextManager[None]:
        """Sim time stands still inside the block; afterwards the world runs again, unless it
        was paused before."""
        return self.pacer.held()

    def step(self, n: int = 1) -> None:
        """While paused, advance ``n`` physics steps as one tick and publish it."""
        with self._cond:
            if not self.pacer.paused:
                raise RuntimeError("step() is only allowed while paused")
            self._tick(n)

    def reset(self) -> None:
        """Back to time 0 and the start pose; no clock is published until the next tick."""
        with self._cond:
            self.take_commands()  # those sent before the reset are dropped with it
            self.sim.reset()
            self._cmd = None
            self.pacer.forget_rate()
            self._cond.notify_all()

    def set_real_time_factor(self, rtf: float) -> None:
        """Sim seconds per wall second; 0 runs as fast as the graph keeps up."""
        self.pacer.set_real_time_factor(rtf)

    def schedule_real_time_factor(self, at: float, rtf: float) -> None:
        """Run at ``rtf`` from the first tick that starts at or after sim time ``at``.

        The world makes the change itself, so it lands on that sim time however late the
        caller's thread runs (on a loaded machine a grader waiting for the moment may wake
        a few ticks after it).  Each change made is logged in :attr:`pace_changes`.
        """
        if rtf < 0:
            raise ValueError("real_time_factor must be >= 0")
        with self._cond:
            self._pace_due.append((at, rtf))
            self._pace_due.sort(key=lambda due: due[0])

    def cancel_scheduled_pace(self) -> None:
        """Drop the pace changes not made yet."""
        with self._cond:
            self._pace_due.clear()

    def _make_due_pace_changes(self) -> None:
        now = self.world.time
        while self._pace_due and self._pace_due[0][0] <= now + 1e-9:
            _at, rtf = self._pace_due.pop(0)
            self.pacer.set_real_time_factor(rtf)
            self.pace_changes.append((now, rtf))

    def inject(self, fault: Fault) -> float:
        """Add a fault at run time; return the sim time it was added at, between ticks.

        Every message published at a later sim time reflects the fault (from its
        ``start``). Sim time read before the call does not say that: a tick may be under
        way (its steps advance :attr:`now` before it publishes), and it finishes first.
        """
        with self._cond:
            self.sim.inject(fault)
            return self.world.time

    def add_tap(self, tap: Callable[[str, str, Any, float], None]) -> None:
        """Hand every message published or received to ``tap(topic, type name, message,
        sim time)`` (add taps before :meth:`start`; a tap must not raise)."""
        self._taps.append(tap)

    def after_each_tick(self, hook: Callable[[float], None]) -> Callable[[], None]:
        """Call ``hook(sim time)`` in the world's thread after each tick's messages went out
        and before the pacing holds for the watched processes, so what it publishes reaches
        them with that tick's ``/clock``, as the lidar's scans do, however late the caller's
        threads run.  Return a function that removes the hook (call it before what the hook
        publishes with is destroyed).  A hook runs under the world's lock: it must be quick,
        must not raise, and must not wait for sim time."""
        with self._cond:
            self._after_tick.append(hook)

        def remove() -> None:
            with self._cond:
                if hook in self._after_tick:
                    self._after_tick.remove(hook)
        return remove

    def between_ticks(self, action: Callable[[], T]) -> T:
        """Run ``action()`` while no tick is under way and return what it returns: :attr:`now`
        stays at the last tick's end throughout, and no tick hook runs meanwhile."""
        with self._cond:
            return action()

    def listen(self, topic: str, msg_type: type) -> None:
        """Also hand taps what goes out on ``topic``, a topic the world does not use (a
        command for another node, to record a hand run), at the sim time it arrives.
        Once per topic; the executor's thread takes the messages."""
        if topic in self._listened or topic == CMD_VEL_TOPIC:
            return
        self._listened[topic] = self.node.create_subscription(
            msg_type, topic, lambda msg: self._tap(topic, msg, self.world.time), 10)

    def _tap(self, topic: str, message: Any, t: float) -> None:
        for tap in self._taps:
            tap(topic, type_name(type(message)), message, t)

    def watch_pid(self, pid: int | None,
                  family: Callable[[], Iterable[int]] | None = None) -> None:
        """Also hold sim time back while process ``pid`` has work (None: watch nothing).
        ``family()``: the pids of every process of the program now (its children and
        daemons too), whose CPU says whether a stalled world was the program's doing
        (:meth:`watched_family`); by default ``pid`` alone."""
        with self._cond:
            if pid is None:
                self._families.clear()
            else:
                self._families[pid] = family or (lambda: (pid,))
        self.pacer.watch(pid)

    def closing_pid(self, pid: int) -> None:
        """Process ``pid`` is being stopped: still hold ticks while it has work, but do not
        wait for it to hear them."""
        self.pacer.closing(pid)

    def unwatch_pid(self, pid: int) -> None:
        """Stop watching process ``pid``."""
        with self._cond:
            self._families.pop(pid, None)
        self.pacer.unwatch(pid)

    def watched_family(self) -> set[int]:
        """The pids of every process of the watched programs now (see :meth:`watch_pid`)."""
        with self._cond:
            families = list(self._families.values())
        return {pid for family in families for pid in family()}

    # -- observing ------------------------------------------------------------------
    @property
    def now(self) -> float:
        """Sim seconds since start (or the last reset)."""
        return self.world.time

    @property
    def real_time_factor(self) -> float:
        return self.pacer.real_time_factor

    @property
    def clock_hz(self) -> float:
        """Most ``/clock`` messages per wall second."""
        return self.pacer.policy.clock_hz

    @property
    def pacing(self) -> Counter[HoldOutcome]:
        """How each tick's hold for the watched processes ended (see
        :data:`sim.pacing.HoldOutcome`)."""
        return self.pacer.counts

    @property
    def longest_hold(self) -> float:
        """Wall seconds of the longest such hold."""
        return self.pacer.longest_hold

    @property
    def recording(self) -> Recording:
        return self.sim.recording

    @property
    def effective_rtf(self) -> float:
        """Measured sim seconds per wall second over the last ticks (0 before any)."""
        return self.pacer.effective_rtf

    def sim_time_at(self, wall_ns: int) -> float:
        """Sim time of the last /clock published at or before system time ``wall_ns``.

        A message whose DDS source timestamp is ``wall_ns`` was sent while its publisher's
        clock read at most this: a stamp that does not depend on how late we receive it.
        """
        log = self._clock_log
        i = bisect.bisect_right(log, wall_ns, key=lambda entry: entry[0]) - 1
        return log[i][1] if i >= 0 else 0.0

    @property
    def last_tick_sent_ns(self) -> int | None:
        """System time (ns) the last /clock went out at; None before the first."""
        log = self._clock_log
        return log[-1][0] if log else None

    def cmd_vel_mismatches(self) -> list[Mismatch]:
        """Publishers on /cmd_vel whose type is not the one this robot takes."""
        return mismatches(self.node, {CMD_VEL_TOPIC: full_name(self.cmd_vel_type)},
                          ignore=(self.node.get_name(),))

    def clock_listeners(self) -> int:
        """Subscriptions our /clock publisher has matched (the probe's among them)."""
        return self._clock_pub.get_subscription_count()

    def scan_listeners(self) -> int:
        """Subscriptions our /scan publisher has matched."""
        return self._scan_pub.get_subscription_count()

    def wait_until(self, sim_time: float, wall_timeout: float) -> bool:
        """Block until sim time reaches ``sim_time``; False if ``wall_timeout`` passes first.
        A gated world's first wait opens its gate."""
        self.pacer.open_gate()
        with self._timed_wait(), self._cond:
            return self._cond.wait_for(lambda: self.world.time >= sim_time - 1e-9,
                                       timeout=wall_timeout)

    @contextlib.contextmanager
    def _timed_wait(self) -> Iterator[None]:
        """Tell :attr:`on_wait` how long the block took and how much of it was held."""
        told = self.on_wait
        if told is None:
            yield
            return
        began, held = time.monotonic(), self.pacer.held_seconds
        try:
            yield
        finally:
            told(time.monotonic() - began, self.pacer.held_seconds - held)

    def wait_for(self, predicate: Callable[[], bool], sim_timeout: float,
                 wall_timeout: float) -> bool:
        """Block until ``predicate()`` holds; False if ``sim_timeout`` of sim time or
        ``wall_timeout`` of wall time passes first.

        The predicate is checked at every tick, and also every ``recheck`` wall seconds
        so that one watching another thread (a probe's messages) is seen while paused.
        A gated world's first wait opens its gate: sim time is wanted from now on.
        """
        self.pacer.open_gate()
        end = time.monotonic() + wall_timeout
        with self._timed_wait(), self._cond:
            limit = self.world.time + sim_timeout
            while not predicate():
                left = end - time.monotonic()
                if self.world.time >= limit or left <= 0:
                    return bool(predicate())
                self._cond.wait(min(left, self.recheck))
            return True

    # -- threads --------------------------------------------------------------------
    def _on_cmd_vel(self, msg: object) -> None:
        twist = twist_of(msg)
        self._cmd = (twist.linear.x, twist.angular.z)
        self._tap("/cmd_vel", msg, self.world.time)

    def receiving(self) -> bool:
        """Whether this process's middleware still has messages to take in: a receive
        thread runs or waits for a CPU, or the kernel holds packets for no socket yet
        (:class:`sim.procstate.Receiving`; the probe's participant is in this process too)."""
        return self._receiving()

    def take_commands(self) -> int:
        """Take every /cmd_vel message our middleware holds, oldest first, as each tick
        does before it steps (no executor takes them); return how many there were.  The
        last one drives the next tick."""
        sub, count = self._cmd_sub, 0
        with self._cond, sub.handle:
            while (taken := sub.handle.take_message(sub.msg_type, sub.raw)) is not None:
                self.note_lateness(taken[1])
                self._on_cmd_vel(taken[0])
                count += 1
        return count

    def _take_last_commands(self) -> None:
        """The commands that came after the last tick (a node's stop as its run ends): no
        tick will drive them, but the recording and the taps (a bag) end with them, at
        the sim time the world stopped."""
        sub = self._cmd_sub
        with self._cond, contextlib.suppress(RuntimeError), sub.handle:
            # RuntimeError: rclpy's RCLError or InvalidHandle, the context already shut
            # down (Ctrl-C in a hand run): nothing more can be taken, nothing is lost.
            while (taken := sub.handle.take_message(sub.msg_type, sub.raw)) is not None:
                twist = twist_of(taken[0])
                self.sim.recording.add_command(self.world.time, twist.linear.x,
                                               twist.angular.z)
                self._tap("/cmd_vel", taken[0], self.world.time)

    def note_lateness(self, info: object) -> None:
        """Count a command sent before the tick now due: ticks went on without it.  When it
        was sent is its DDS source timestamp, read as the sim time of the last /clock out
        by then (the clock is the machine's, the sender's and ours)."""
        source = info.get("source_timestamp") if isinstance(info, dict) else None
        if not source or not self._clock_log:
            return
        late = self.world.time - self.sim_time_at(source)
        if late > 1e-9:
            self.late_commands += 1
            self.latest_command = max(self.latest_command, late)

    def _spin(self) -> None:
        while self._spinning and self._context.ok():
            self._executor.spin_once(timeout_sec=0.05)

    def _run(self) -> None:
        while True:
            with self._cond:
                self._make_due_pace_changes()
                tick = self.pacer.next_tick()
                if tick is None:
                    return
                self._tick(tick.steps)
            self.pacer.pace(tick)

    def _tick(self, steps: int) -> None:
        """Advance ``steps`` physics steps and publish clock, odometry and scans."""
        self.take_commands()
        cmd, self._cmd = self._cmd, None
        if cmd is not None:
            self.sim.set_command(*cmd)
        outputs: list[Outputs] = [self.sim.step() for _ in range(steps)]
        sec, nanosec = _stamp(self.world.time)
        clock = Clock()
        clock.clock.sec, clock.clock.nanosec = sec, nanosec
        self.pacer.about_to_publish()
        self._clock_log.append((time.time_ns(), self.world.time))
        self._clock_pub.publish(clock)
        self._tap("/clock", clock, self.world.time)
        for out in outputs:
            if out.wheel_odom is not None:
                odom = self._odometry(out.wheel_odom)
                self._odom_pub.publish(odom)
                self._tap("/odom", odom, out.wheel_odom.t)
            if out.scan is not None:
                scan = self._laser_scan(out.scan)
                self._scan_pub.publish(scan)
                self._tap("/scan", scan, out.scan.t)
        for hook in list(self._after_tick):
            hook(self.world.time)
        self.pacer.note_tick(self.world.time)
        self._cond.notify_all()

    # -- messages -------------------------------------------------------------------
    def _odometry(self, s: Sample) -> Odometry:
        msg = Odometry()
        msg.header.stamp.sec, msg.header.stamp.nanosec = _stamp(s.t)
        msg.header.frame_id, msg.child_frame_id = "odom", "base_footprint"
        msg.pose.pose.position.x, msg.pose.pose.position.y = s.x, s.y
        msg.pose.pose.orientation.z = math.sin(s.theta / 2)
        msg.pose.pose.orientation.w = math.cos(s.theta / 2)
        msg.twist.twist.linear.x, msg.twist.twist.angular.z = s.v, s.w
        return msg

    def _laser_scan(self, scan: Scan) -> LaserScan:
        lidar = self.sim.lidar
        msg = LaserScan()
        msg.header.stamp.sec, msg.header.stamp.nanosec = _stamp(scan.t)
        msg.header.frame_id = "base_scan"
        msg.angle_min, msg.angle_max = lidar.angle_min, lidar.angle_max
        msg.angle_increment = lidar.angle_increment
        msg.time_increment = 0.0
        msg.scan_time = 1.0 / SCAN_HZ
        msg.range_min, msg.range_max = lidar.range_min, lidar.range_max
        msg.ranges = array.array("f", scan.ranges.tobytes())
        msg.intensities = array.array("f", scan.intensities.tobytes())
        return msg
