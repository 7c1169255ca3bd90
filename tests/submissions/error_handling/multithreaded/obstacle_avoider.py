"""Correct: MultiThreadedExecutor, NumPy, a watchdog timer of its own, a lock and a flag."""
import signal
import sys
import threading

import numpy as np
import rclpy
from geometry_msgs.msg import Twist
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.duration import Duration
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import LaserScan


def twist(linear=0.0, angular=0.0):
    command = Twist()
    command.linear.x, command.angular.z = linear, angular
    return command


class ObstacleAvoider(Node):

    def __init__(self):
        super().__init__('obstacle_avoider')
        group = ReentrantCallbackGroup()  # callbacks may overlap: state is under a lock
        self.lock = threading.Lock()
        self.stopped = False
        self.publisher = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10, callback_group=group)
        self.create_timer(0.1, self.on_control, callback_group=group)
        self.command = twist()
        self.fresh = False
        self.last_scan = None

    def on_scan(self, scan):
        try:
            command = self.decide(scan)
        except Exception as error:
            self.get_logger().error(f'scan rejected by an exception: {error}')
            command = twist()
        with self.lock:
            self.command, self.last_scan = command, self.get_clock().now()

    def decide(self, scan):
        ranges = np.asarray(scan.ranges, dtype=float)
        count = (scan.angle_max - scan.angle_min) / scan.angle_increment + 1
        if ranges.size == 0 or not np.isclose(ranges.size, count, atol=0.5):
            return twist()
        angles = np.angle(np.exp(1j * (scan.angle_min + np.arange(ranges.size)
                                       * scan.angle_increment)))
        with np.errstate(invalid='ignore'):
            valid = np.isfinite(ranges) & (ranges >= scan.range_min) & (
                ranges <= scan.range_max)
        ahead = valid & (np.abs(angles) <= np.radians(30))
        if not ahead.any() or ranges[ahead].min() > 0.6:
            return twist(linear=0.2)
        side = valid & (np.abs(angles) < np.pi / 2)
        left = ranges[side & (angles > 0)]
        right = ranges[side & (angles < 0)]
        room_left = left.mean() if left.size else scan.range_max
        room_right = right.mean() if right.size else scan.range_max
        return twist(angular=0.5 if room_left >= room_right else -0.5)

    def on_control(self):
        with self.lock:
            if self.stopped:
                return
            now = self.get_clock().now()
            stale = self.last_scan is None or now - self.last_scan > Duration(seconds=0.5)
            if stale:  # throttled in ROS time, like the watchdog itself
                self.get_logger().warn('lidar silent: stopping', throttle_duration_sec=1.0,
                                       throttle_time_source_type=self.get_clock())
            self.publisher.publish(twist() if stale else self.command)

    def stop(self):
        """Publish the last word; no control cycle publishes after it."""
        with self.lock:
            self.stopped = True
            self.publisher.publish(twist())
        self.publisher.wait_for_all_acked(Duration(seconds=1.0))


def main(args=None):
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = ObstacleAvoider()
    executor = MultiThreadedExecutor(num_threads=2)
    executor.add_node(node)
    quit_requested = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: quit_requested.set())

    def spin():
        while not quit_requested.is_set():
            executor.spin_once(timeout_sec=0.1)

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    quit_requested.wait()
    spinner.join()
    try:
        node.stop()
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
