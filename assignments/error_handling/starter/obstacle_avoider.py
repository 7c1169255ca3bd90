"""Obstacle avoider: the chapter's AI sensor processor, made robust.

Tier A: simulation.

Learning objectives: distrust sensor data (NaN, inf, out-of-range readings, empty and
malformed scans); stop when the sensor goes silent (a watchdog in ROS time); keep a node
alive when a callback raises; shut down cleanly on Ctrl-C or SIGTERM, leaving the robot
stopped.

Prerequisites: a node with a publisher, a subscriber and a timer; LaserScan's fields.

Expected output: the robot wanders among obstacles at 0.2 m/s, turning in place where
the way is blocked. With the lidar unplugged it stops and logs
"[WARN] [...] [obstacle_avoider]: no scan for 0.6 s: stopping" about once a second.
Ctrl-C publishes a zero Twist and exits with status 0.
"""
import math
import sys

import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan

FORWARD = 0.2     # m/s when the way ahead is clear
TURN = 0.5        # rad/s when it is not
CLEARANCE = 0.6   # m: nearer than this within the cone ahead means blocked
CONE = math.radians(30)
WATCHDOG = 0.5    # s of ROS time without a scan before the robot stops


class ObstacleAvoider(Node):

    def __init__(self):
        super().__init__('obstacle_avoider')
        self.publisher = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)
        self.create_timer(0.1, self.on_timer)
        self.command = Twist()  # what the latest scan asks for
        # TODO: remember when the last scan came (self.get_clock().now(): ROS time).

    def on_scan(self, scan):
        # TODO: an exception here ends the node. Catch it, log it at ERROR, and stop.
        # TODO: reject an empty scan, or one whose len(ranges) disagrees with
        # (angle_max - angle_min) / angle_increment + 1: stop for that cycle.
        ahead, left, right = [], [], []
        for i, r in enumerate(scan.ranges):
            # TODO: skip invalid readings: NaN, ±inf, below range_min, above range_max.
            angle = math.remainder(scan.angle_min + i * scan.angle_increment, math.tau)
            if abs(angle) <= CONE:
                ahead.append(r)
            (left if angle > 0 else right).append(r)
        command = Twist()
        if min(ahead) > CLEARANCE:
            command.linear.x = FORWARD
        else:  # turn in place toward the side whose readings are farther on average
            more_left = sum(left) / len(left) >= sum(right) / len(right)
            command.angular.z = TURN if more_left else -TURN
        self.command = command

    def on_timer(self):
        # TODO: a watchdog: with no scan for more than WATCHDOG seconds, publish
        # Twist() on every cycle and warn, at most once a second (throttle_duration_sec).
        self.publisher.publish(self.command)


def main(args=None):
    # TODO: this Ctrl-C handling leaves the robot driving. rclpy's own handler shuts
    # the context down before `finally` runs, so a publish there fails. The README
    # shows a pattern that stops the robot every time.
    rclpy.init(args=args)
    node = ObstacleAvoider()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
