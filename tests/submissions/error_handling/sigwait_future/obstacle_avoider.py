"""Correct: blocks SIGINT/SIGTERM, takes them with sigwait; the spinner ends on a Future."""
import math
import signal
import sys
import threading

import rclpy
from geometry_msgs.msg import Twist
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.task import Future
from sensor_msgs.msg import LaserScan


class ObstacleAvoider(Node):

    def __init__(self):
        super().__init__('obstacle_avoider')
        self.publisher = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)
        self.create_timer(0.1, self.on_timer)
        self.command = Twist()
        self.heard = None
        self.turning = 0

    def on_scan(self, scan):
        self.heard = self.get_clock().now()
        try:
            self.command = self.react(scan)
        except Exception as error:
            self.get_logger().error(f'bad scan: {error}')
            self.command = Twist()
            self.publisher.publish(self.command)

    def react(self, scan):
        beams = (scan.angle_max - scan.angle_min) / scan.angle_increment + 1
        if not scan.ranges or not abs(len(scan.ranges) - beams) <= 0.5:  # NaN fails too
            return Twist()
        nearest, left, right = math.inf, 0, 0
        for i, r in enumerate(scan.ranges):
            if not (math.isfinite(r) and scan.range_min <= r <= scan.range_max):
                continue
            bearing = math.degrees(scan.angle_min + i * scan.angle_increment) % 360
            if bearing <= 30 or bearing >= 330:
                nearest = min(nearest, r)
            # room: how many beams on each side see farther than a metre
            if 0 < bearing < 180 and r > 1.0:
                left += 1
            elif 180 < bearing < 360 and r > 1.0:
                right += 1
        command = Twist()
        if nearest > 0.6:
            self.turning = 0
            command.linear.x = 0.2
        else:
            self.turning = self.turning or (1 if left >= right else -1)
            command.angular.z = 0.5 * self.turning
        return command

    def on_timer(self):
        if self.heard is None or (self.get_clock().now() - self.heard).nanoseconds > 5e8:
            self.get_logger().warn('watchdog: no scan, stopped', throttle_duration_sec=1.0)
            self.publisher.publish(Twist())
        else:
            self.publisher.publish(self.command)


def main(args=None):
    # Blocked before any thread exists, so every thread inherits the mask: the signals
    # wait for sigwait() below instead of interrupting whatever code is running.
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = ObstacleAvoider()
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    done = Future()
    spinner = threading.Thread(target=executor.spin_until_future_complete, args=(done,))
    spinner.start()
    signal.sigwait({signal.SIGINT, signal.SIGTERM})
    done.set_result(True)  # wakes the executor; spin_until_future_complete returns
    spinner.join()
    try:
        node.publisher.publish(Twist())
        node.publisher.wait_for_all_acked(Duration(seconds=1.0))
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
