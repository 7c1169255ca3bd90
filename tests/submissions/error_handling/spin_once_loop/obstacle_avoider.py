"""Correct: spins with spin_once in the main thread until its signal handler sets a flag."""
import math
import signal
import sys

import rclpy
from geometry_msgs.msg import Twist
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import LaserScan

SECTOR = math.radians(30)


class ObstacleAvoider(Node):

    def __init__(self):
        super().__init__('obstacle_avoider')
        self.publisher = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)
        self.create_timer(0.1, self.on_timer)
        self.scan = None
        self.scan_time = self.get_clock().now()

    def on_scan(self, scan):
        self.scan, self.scan_time = scan, self.get_clock().now()

    def on_timer(self):
        # All the work happens here, once a cycle, on the latest scan.
        try:
            age = self.get_clock().now() - self.scan_time
            if self.scan is None or age > Duration(seconds=0.5):
                self.get_logger().warn('no lidar data, holding still', throttle_duration_sec=1.0)
                command = Twist()
            else:
                command = self.steer(self.scan)
        except Exception:  # any failure means: stop, say why, go on
            self.get_logger().error('control cycle failed; stopping')
            command = Twist()
        self.publisher.publish(command)

    def steer(self, scan):
        n = len(scan.ranges)
        if n == 0 or n != int(round((scan.angle_max - scan.angle_min) / scan.angle_increment)) + 1:
            return Twist()
        ahead, left, right = [], 0.0, 0.0
        for i, r in enumerate(scan.ranges):
            if math.isnan(r) or math.isinf(r) or r < scan.range_min or r > scan.range_max:
                continue
            a = math.atan2(math.sin(scan.angle_min + i * scan.angle_increment),
                           math.cos(scan.angle_min + i * scan.angle_increment))
            if -SECTOR <= a <= SECTOR:
                ahead.append(r)
            if 0 < a < math.pi:  # room: the sum of free distance on each side
                left += r
            elif a < 0:
                right += r
        command = Twist()
        if not ahead or min(ahead) > 0.6:
            command.linear.x = 0.2
        else:
            command.angular.z = 0.5 if left >= right else -0.5
        return command


def main(args=None):
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = ObstacleAvoider()
    asked = []
    signal.signal(signal.SIGINT, lambda *_: asked.append('SIGINT'))
    signal.signal(signal.SIGTERM, lambda *_: asked.append('SIGTERM'))
    try:
        while not asked:
            rclpy.spin_once(node, timeout_sec=0.1)  # a handler only sets the flag
        node.get_logger().info(f'{asked[0]}: stopping the robot')
        node.publisher.publish(Twist())
        node.publisher.wait_for_all_acked(Duration(seconds=1.0))
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
