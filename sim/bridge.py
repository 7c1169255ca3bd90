"""The ROS side of the world: /cmd_vel in; /odom, /scan and /clock out, in sim time.

Pacing design (what keeps verdicts independent of machine load)
----------------------------------------------------------------
The world advances in *clock ticks*.  A tick is a whole number of physics steps; after
it the bridge publishes ``/clock`` (the tick's end time) and then the odometry and scans
that fell due inside it, so a subscriber's clock has already reached a message's stamp.
Commands received on ``/cmd_vel`` take effect at the start of the next tick.

* **Tick length.**  ``/clock`` goes out at most ``max_clock_hz`` times per *wall* second:
  Jazzy's executors follow a 50-100 Hz clock well but stutter at 133 Hz and above.  At a
  real-time factor ``r > 0`` a tick is ``r / max_clock_hz`` of sim time (0.02 s at RTF 1
  and 50 Hz).  At ``r == 0`` ("as fast as the graph keeps up") the tick length adapts so
  that one tick's work fills ``1 / max_clock_hz`` of wall time, up to ``max_tick`` (2 s):
  the clock cap means 50x real time needs 1 s ticks, so at RTF 0 a node sees its clock
  jump by up to ``max_tick`` at once.  Graders who care about timer granularity should
  pick a finite RTF instead.
* **Wall deadline.**  After publishing, the bridge waits for the tick's wall deadline.
  There is no catch-up: a late tick moves the schedule, so sim time just runs slower.
* **Quiescence.**  With a watched process (``watch_pid``, the student's node), the bridge
  then waits until none of its threads is running or runnable (state ``R`` in
  ``/proc/<pid>/task/*/stat``), or until it has used ``cpu_budget`` (50 ms) of CPU time
  since the tick (``/proc/<pid>/task/*/schedstat``), polling every ``poll_interval``, with
  ``quiescence_cap`` (2 s) of wall time as the last resort.  A student process that
  cannot get a CPU on a busy machine thus holds sim time back however long it waits,
  while one that busy-loops has had its share after 50 ms of CPU and only slows the
  world down.  (A wall-time cap alone, tried first, let sim time run on while a starved
  process waited for a CPU, and a correct node then failed under load.)
* ``effective_rtf`` reports the measured sim seconds per wall second of the last ticks.

Physics runs in one thread and the executor (for /cmd_vel) in another; the world is
only touched under the bridge's lock, and waiters are woken by a Condition each tick.
"""

from __future__ import annotations

import array
import bisect
import collections
import contextlib
import math
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from sim.engine import SCAN_HZ, Outputs, Simulation
from sim.faults import Scan
from sim.physics import World
from sim.recorder import Recording, Sample
from sim.worldfile import Fault


def _stamp(t: float) -> tuple[int, int]:
    ns = round(t * 1e9)
    return ns // 1_000_000_000, ns % 1_000_000_000


def process_busy(pid: int) -> bool:
    """True if any thread of ``pid`` is running or runnable; False if idle or gone."""
    return process_state(pid)[0]


def process_state(pid: int) -> tuple[bool, int]:
    """(any thread running or runnable, CPU nanoseconds used by all its threads so far).

    CPU time comes from ``/proc/<pid>/task/*/schedstat`` (nanoseconds on the CPU), so a
    thread that is runnable but starved of a CPU is told apart from one that computes.
    """
    try:
        tasks = list(Path(f"/proc/{pid}/task").iterdir())
    except OSError:
        return False, 0
    busy, cpu = False, 0
    for task in tasks:
        try:
            stat = (task / "stat").read_bytes()
            cpu += int((task / "schedstat").read_bytes().split()[0])
        except (OSError, ValueError, IndexError):
            continue
        if stat[stat.rindex(b")") + 2:stat.rindex(b")") + 3] == b"R":
            busy = True
    return busy, cpu


class SimBridge:
    """Runs a :class:`World` as a ROS 2 robot in the given rclpy context."""

    def __init__(self, world: World, context: Context, *, real_time_factor: float = 1.0,
                 max_clock_hz: float = 50.0, node_name: str = "sim_world",
                 quiescence_cap: float = 2.0, cpu_budget: float = 0.05,
                 poll_interval: float = 0.0005,
                 settle: float = 0.001, max_tick: float = 2.0) -> None:
        if real_time_factor < 0 or max_clock_hz <= 0:
            raise ValueError("real_time_factor must be >= 0 and max_clock_hz > 0")
        self.sim = Simulation(world)
        self.world = world
        self.max_clock_hz = max_clock_hz
        self.quiescence_cap = quiescence_cap
        self.cpu_budget = cpu_budget
        self.poll_interval = poll_interval
        self.settle = settle
        self.max_tick = max_tick
        self.recheck = 0.01
        self._rtf = real_time_factor
        self._adaptive_tick = 1.0 / max_clock_hz
        self._cond = threading.Condition(threading.RLock())
        self._paused = False
        self._running = False
        self._pids: set[int] = set()
        self._cmd: tuple[float, float] | None = None
        self._window: collections.deque[tuple[float, float]] = collections.deque(maxlen=100)
        # (time.time_ns() just before a tick's /clock went out, that tick's sim time)
        self._clock_log: list[tuple[int, float]] = []
        self._threads: list[threading.Thread] = []
        # How each tick's hold for the watched processes ended: no process watched
        # ("free"), all idle ("idle"), CPU share used ("budget"), or the wall cap ("cap").
        self.pacing: collections.Counter[str] = collections.Counter()
        self.longest_hold = 0.0  # wall seconds of the longest such hold
        self.node = Node(node_name, context=context)
        qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self._clock_pub = self.node.create_publisher(Clock, "/clock", qos)
        self._odom_pub = self.node.create_publisher(Odometry, "/odom", qos)
        self._scan_pub = self.node.create_publisher(LaserScan, "/scan", qos)
        self.node.create_subscription(Twist, "/cmd_vel", self._on_cmd_vel, 10)
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._context = context

    # -- life cycle -----------------------------------------------------------------
    def start(self) -> None:
        """Start the executor and physics threads (the world runs unless paused)."""
        self._running = True
        self._threads = [threading.Thread(target=self._spin, name="sim-executor", daemon=True),
                         threading.Thread(target=self._run, name="sim-physics", daemon=True)]
        for thread in self._threads:
            thread.start()

    def stop(self) -> None:
        """Stop both threads, wait for them, and destroy the node."""
        with self._cond:
            self._running = False
            self._cond.notify_all()
        for thread in self._threads:
            thread.join()
        self._threads = []
        self._executor.remove_node(self.node)
        self._executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()

    def pause(self) -> None:
        """Freeze sim time; no tick starts after this returns."""
        with self._cond:
            self._paused = True

    def resume(self) -> None:
        with self._cond:
            self._paused = False
            self._window.clear()
            self._cond.notify_all()

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        """Sim time stands still inside the block; afterwards the world runs again, unless it
        was paused before."""
        with self._cond:
            was_paused, self._paused = self._paused, True
        try:
            yield
        finally:
            if not was_paused:
                self.resume()

    def step(self, n: int = 1) -> None:
        """While paused, advance ``n`` physics steps as one tick and publish it."""
        with self._cond:
            if not self._paused:
                raise RuntimeError("step() is only allowed while paused")
            self._tick(n)

    def reset(self) -> None:
        """Back to time 0 and the start pose; no clock is published until the next tick."""
        with self._cond:
            self.sim.reset()
            self._cmd = None
            self._window.clear()
            self._cond.notify_all()

    def set_real_time_factor(self, rtf: float) -> None:
        """Sim seconds per wall second; 0 runs as fast as the graph keeps up."""
        if rtf < 0:
            raise ValueError("real_time_factor must be >= 0")
        with self._cond:
            self._rtf = rtf
            self._window.clear()

    def inject(self, fault: Fault) -> None:
        """Add a fault at run time."""
        with self._cond:
            self.sim.inject(fault)

    def watch_pid(self, pid: int | None) -> None:
        """Also hold sim time back while process ``pid`` has work (None: watch nothing)."""
        with self._cond:
            if pid is None:
                self._pids.clear()
            else:
                self._pids.add(pid)
            self._window.clear()

    def unwatch_pid(self, pid: int) -> None:
        """Stop watching process ``pid``."""
        with self._cond:
            self._pids.discard(pid)

    # -- observing ------------------------------------------------------------------
    @property
    def now(self) -> float:
        """Sim seconds since start (or the last reset)."""
        return self.world.time

    @property
    def real_time_factor(self) -> float:
        return self._rtf

    @property
    def recording(self) -> Recording:
        return self.sim.recording

    @property
    def effective_rtf(self) -> float:
        """Measured sim seconds per wall second over the last ticks (0 before any)."""
        with self._cond:
            if len(self._window) < 2:
                return 0.0
            (w0, s0), (w1, s1) = self._window[0], self._window[-1]
        return (s1 - s0) / (w1 - w0) if w1 > w0 else 0.0

    def sim_time_at(self, wall_ns: int) -> float:
        """Sim time of the last /clock published at or before system time ``wall_ns``.

        A message whose DDS source timestamp is ``wall_ns`` was sent while its publisher's
        clock read at most this: a stamp that does not depend on how late we receive it.
        """
        log = self._clock_log
        i = bisect.bisect_right(log, wall_ns, key=lambda entry: entry[0]) - 1
        return log[i][1] if i >= 0 else 0.0

    def wait_until(self, sim_time: float, wall_timeout: float) -> bool:
        """Block until sim time reaches ``sim_time``; False if ``wall_timeout`` passes first."""
        with self._cond:
            return self._cond.wait_for(lambda: self.world.time >= sim_time - 1e-9,
                                       timeout=wall_timeout)

    def wait_for(self, predicate: Callable[[], bool], sim_timeout: float,
                 wall_timeout: float) -> bool:
        """Block until ``predicate()`` holds; False if ``sim_timeout`` of sim time or
        ``wall_timeout`` of wall time passes first.

        The predicate is checked at every tick, and also every ``recheck`` wall seconds
        so that one watching another thread (a probe's messages) is seen while paused.
        """
        end = time.monotonic() + wall_timeout
        with self._cond:
            limit = self.world.time + sim_timeout
            while not predicate():
                left = end - time.monotonic()
                if self.world.time >= limit or left <= 0:
                    return bool(predicate())
                self._cond.wait(min(left, self.recheck))
            return True

    # -- threads --------------------------------------------------------------------
    def _on_cmd_vel(self, msg: Twist) -> None:
        self._cmd = (msg.linear.x, msg.angular.z)

    def _spin(self) -> None:
        while self._running and self._context.ok():
            self._executor.spin_once(timeout_sec=0.05)

    def _tick_steps(self) -> int:
        length = self._rtf / self.max_clock_hz if self._rtf > 0 else self._adaptive_tick
        return max(1, round(length / self.world.dt))

    def _run(self) -> None:
        start = time.monotonic()
        while True:
            with self._cond:
                while self._running and self._paused:
                    self._cond.wait()
                    start = time.monotonic()
                if not self._running:
                    return
                steps = self._tick_steps()
                rtf = self._rtf
                self._tick(steps)
            published = time.monotonic()
            period = steps * self.world.dt / rtf if rtf > 0 else 1.0 / self.max_clock_hz
            deadline = start + period
            self._wait_quiescent(published, deadline)
            busy = time.monotonic() - start
            if rtf == 0 and busy > 0:
                ratio = min(2.0, max(0.5, period / busy))
                self._adaptive_tick = min(self.max_tick, max(self.world.dt,
                                                             self._adaptive_tick * ratio))
            now = time.monotonic()
            if now < deadline:
                time.sleep(deadline - now)
                start = deadline  # on schedule: keep it exact
            else:
                start = now  # late: no catch-up burst, sim time just runs slower

    def _wait_quiescent(self, published: float, deadline: float) -> None:
        """Hold the next tick until every watched process is idle or has had its CPU share.

        A process that keeps computing is let go once it has used ``cpu_budget`` seconds of
        CPU since the tick (it is busy, not slow); one that is runnable but gets no CPU (a
        busy machine) holds sim time back, up to ``quiescence_cap`` of wall time.
        """
        pids = tuple(self._pids)
        if not pids:
            self.pacing["free"] += 1
            return
        first = published + self.settle
        now = time.monotonic()
        if now < min(first, deadline):
            time.sleep(min(first, deadline) - now)
        start = {pid: process_state(pid)[1] for pid in pids}
        budget = int(self.cpu_budget * 1e9)
        cap = published + self.quiescence_cap
        outcome = "cap"
        while time.monotonic() < cap:
            states = {pid: process_state(pid) for pid in pids}
            if not any(busy and cpu - start[pid] < budget
                       for pid, (busy, cpu) in states.items()):
                outcome = "budget" if any(busy for busy, _ in states.values()) else "idle"
                break
            time.sleep(self.poll_interval)
        self.pacing[outcome] += 1
        self.longest_hold = max(self.longest_hold, time.monotonic() - published)

    def _tick(self, steps: int) -> None:
        """Advance ``steps`` physics steps and publish clock, odometry and scans."""
        cmd, self._cmd = self._cmd, None
        if cmd is not None:
            self.world.set_command(*cmd)
        outputs: list[Outputs] = [self.sim.step() for _ in range(steps)]
        sec, nanosec = _stamp(self.world.time)
        clock = Clock()
        clock.clock.sec, clock.clock.nanosec = sec, nanosec
        self._clock_log.append((time.time_ns(), self.world.time))
        self._clock_pub.publish(clock)
        for out in outputs:
            if out.odom is not None:
                self._odom_pub.publish(self._odometry(out.odom))
            if out.scan is not None:
                self._scan_pub.publish(self._laser_scan(out.scan))
        self._window.append((time.monotonic(), self.world.time))
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
