"""Obstacle avoider without a Node subclass: closures over a dataclass of state.

Tier A: simulation. Written from the README alone: each scan is reduced to a verdict
(forward, turn left or right, or stop) by a pure function; the 10 Hz timer publishes the
latest verdict unless the watchdog says the lidar has gone quiet. Signals are blocked and
taken with signal.sigwait in the main thread while a worker thread spins.
"""
import math
import signal
import sys
import threading
from dataclasses import dataclass

import rclpy
from geometry_msgs.msg import Twist
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import LaserScan

FORWARD, TURN = 0.2, 0.5
SECTOR, BLOCKED, WATCHDOG = math.radians(30.0), 0.6, 0.5


@dataclass
class State:
    verdict: tuple = (0.0, 0.0)   # (linear, angular) from the last good scan
    last_scan_ns: int = 0
    turning: float = 0.0          # the direction kept while the way ahead is blocked


def valid(scan, r):
    return scan.range_min <= r <= scan.range_max   # false for NaN and both infinities


def decide(scan, turning):
    """(linear, angular, turning) for one scan; (0, 0, 0) for a malformed one."""
    n = len(scan.ranges)
    if n == 0 or not scan.angle_increment > 0:
        return 0.0, 0.0, 0.0
    expected = (scan.angle_max - scan.angle_min) / scan.angle_increment + 1
    if not abs(n - expected) <= 0.5:
        return 0.0, 0.0, 0.0
    ahead, left, right = [], [], []
    for i, r in enumerate(scan.ranges):
        if not valid(scan, r):
            continue
        a = math.remainder(scan.angle_min + i * scan.angle_increment, math.tau)
        if abs(a) <= SECTOR:
            ahead.append(r)
        elif 0 < a < math.pi / 2:
            left.append(r)
        elif -math.pi / 2 < a < 0:
            right.append(r)
    if min(ahead, default=math.inf) > BLOCKED:
        return FORWARD, 0.0, 0.0
    if not turning:
        room = (sum(left) / len(left) if left else math.inf,
                sum(right) / len(right) if right else math.inf)
        turning = TURN if room[0] >= room[1] else -TURN
    return 0.0, turning, turning


def build(node):
    state = State(last_scan_ns=node.get_clock().now().nanoseconds)
    publisher = node.create_publisher(Twist, 'cmd_vel', 10)

    def on_scan(scan):
        state.last_scan_ns = node.get_clock().now().nanoseconds
        try:
            linear, angular, state.turning = decide(scan, state.turning)
        except Exception as exc:  # a bad scan must not end the node
            node.get_logger().error(f'could not use a scan: {exc!r}')
            linear = angular = 0.0
        state.verdict = (linear, angular)

    def on_timer():
        msg = Twist()
        age = (node.get_clock().now().nanoseconds - state.last_scan_ns) / 1e9
        if age > WATCHDOG:
            node.get_logger().warn(f'no scan for {age:.1f} s: stopping',
                                   throttle_duration_sec=1.0)
        else:
            msg.linear.x, msg.angular.z = state.verdict
        publisher.publish(msg)

    node.create_subscription(LaserScan, 'scan', on_scan, 10)
    node.create_timer(0.1, on_timer)
    return publisher


def main(args=None):
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node('obstacle_avoider')
    publisher = build(node)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.1)

    spinner = threading.Thread(target=spin)   # inherits the blocked signals
    spinner.start()
    signal.sigwait({signal.SIGINT, signal.SIGTERM})
    stop.set()
    spinner.join()
    try:
        publisher.publish(Twist())
        publisher.wait_for_all_acked(Duration(seconds=1.0))
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
