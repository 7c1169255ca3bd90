"""``sim drive``: publish velocity commands, so a node can be tried without writing a
publisher of one's own.

Commands go out at a fixed rate on the driver's clock: simulation time when a ``/clock``
is on the graph (a world is running), else wall time. A timed drive lasts its seconds
from the first clock reading and ends with a zero command, as does Ctrl-C.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from geometry_msgs.msg import Twist, TwistStamped
from rclpy.context import Context
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy

from sim.keyboard import Command

DRIVER_NODE_NAME = "sim_drive"
# Wall seconds to let discovery show a /clock publisher and the topic's subscribers.
DISCOVERY_WAIT = 3.0
# Wall seconds the last (zero) command has to be acknowledged by its subscribers.
ACK_WAIT = 2.0


class Driver:
    """A node that publishes one velocity command at a rate, on ``topic``."""

    def __init__(self, context: Context, topic: str, *, rate: float = 10.0,
                 stamped: bool = False, frame_id: str = "base_link",
                 discovery_wait: float = DISCOVERY_WAIT) -> None:
        self.node = Node(DRIVER_NODE_NAME, context=context)
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self.sim_time = self._wait_until(lambda: self.node.count_publishers("/clock") > 0,
                                         discovery_wait)
        if self.sim_time:
            self.node.set_parameters([Parameter("use_sim_time", value=True)])
        self.stamped, self.frame_id = stamped, frame_id
        qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self._publisher = self.node.create_publisher(TwistStamped if stamped else Twist,
                                                     topic, qos)
        self.subscribed = self._wait_until(
            lambda: self._publisher.get_subscription_count() > 0, discovery_wait)
        self.command = Command()
        self._seconds: float | None = None
        self._start: int | None = None  # clock nanoseconds of the first reading
        self._active = self.done = False
        self._timer = self.node.create_timer(1.0 / rate, self._on_timer)

    def _wait_until(self, condition: Callable[[], bool], wall_seconds: float) -> bool:
        """Spin until ``condition()`` holds or ``wall_seconds`` pass (discovery is wall
        time's business); whether it held."""
        deadline = time.monotonic() + wall_seconds
        while not condition():
            if time.monotonic() > deadline:
                return False
            self._executor.spin_once(timeout_sec=0.05)
        return True

    def _now(self) -> int:
        return self.node.get_clock().now().nanoseconds

    @property
    def elapsed(self) -> float:
        """Seconds on the driver's clock since the drive began (0 before)."""
        return 0.0 if self._start is None else (self._now() - self._start) / 1e9

    def begin(self, command: Command, seconds: float | None = None) -> None:
        """Publish ``command`` from now on; after ``seconds`` (None: never) stop, with a
        zero command. In simulation time the drive begins with the first ``/clock``."""
        self.command, self._seconds, self._active = command, seconds, True
        self._on_timer()

    def _on_timer(self) -> None:
        if not self._active or self.done:
            return
        if self._start is None:
            now = self._now()
            if now == 0:  # simulation time before the first /clock: not begun yet
                return
            self._start = now
        if self._seconds is not None and self.elapsed >= self._seconds - 1e-9:
            self.finish()
            return
        self._publish(self.command)

    def spin_once(self, timeout: float) -> None:
        """Handle the node's timer and clock for at most ``timeout`` wall seconds."""
        self._executor.spin_once(timeout_sec=timeout)

    def run(self) -> None:
        """Spin until the timed drive is done (forever without ``seconds``)."""
        while not self.done:
            self.spin_once(0.1)

    def finish(self) -> None:
        """Publish a zero command and wait for its subscribers to have it."""
        if self.done:
            return
        self.done = True
        self.command = Command()
        self._publish(self.command)
        self._publisher.wait_for_all_acked(_duration(ACK_WAIT))

    def close(self) -> None:
        """Stop (with a zero command) and destroy the node."""
        try:
            if self._active:
                self.finish()
        finally:
            self._executor.remove_node(self.node)
            self._executor.shutdown(timeout_sec=1.0)
            self.node.destroy_node()

    def _publish(self, command: Command) -> None:
        twist = Twist()
        twist.linear.x, twist.angular.z = float(command.linear), float(command.angular)
        if not self.stamped:
            self._publisher.publish(twist)
            return
        msg = TwistStamped()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.header.frame_id = self.frame_id
        msg.twist = twist
        self._publisher.publish(msg)


def _duration(seconds: float) -> Duration:
    return Duration(nanoseconds=int(seconds * 1e9))
