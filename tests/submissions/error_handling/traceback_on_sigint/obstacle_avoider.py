"""Known bad: rclpy.spin with rclpy's handlers, publish in finally: RCLError traceback."""
import math
import sys

import rclpy
from geometry_msgs.msg import Twist
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
        self.command = Twist()                   # what the latest good scan asks for
        self.last_scan = self.get_clock().now()  # no scan yet: the watchdog stops us
        self.turn = 0.0                          # keep one direction while blocked

    def on_scan(self, scan):
        self.last_scan = self.get_clock().now()
        try:
            self.command = self.decide(scan)
        except Exception as error:  # a bad message must not end the node
            self.get_logger().error(f'cannot use this scan ({error!r}): stopping')
            self.command = Twist()
            self.publisher.publish(Twist())

    def decide(self, scan):
        # The check divides by angle_increment: a zero there raises, and on_scan stops.
        expected = round((scan.angle_max - scan.angle_min) / scan.angle_increment) + 1
        if len(scan.ranges) == 0 or len(scan.ranges) != expected:
            return Twist()  # rejected: stop for this cycle
        nearest, room = math.inf, {1.0: [], -1.0: []}
        for i, r in enumerate(scan.ranges):
            if not scan.range_min <= r <= scan.range_max:  # False for NaN and ±inf too
                continue
            angle = math.remainder(scan.angle_min + i * scan.angle_increment, math.tau)
            if abs(angle) <= CONE:
                nearest = min(nearest, r)
            if 0.0 < abs(angle) < math.pi / 2:  # the quarter ahead on each side
                room[math.copysign(1.0, angle)].append(r)
        command = Twist()
        if nearest > CLEARANCE:
            self.turn = 0.0
            command.linear.x = FORWARD
        else:
            if not self.turn:  # nothing seen on a side: open space, the most room
                left, right = (sum(v) / len(v) if v else scan.range_max
                               for v in (room[1.0], room[-1.0]))
                self.turn = 1.0 if left >= right else -1.0
            command.angular.z = self.turn * TURN
        return command

    def on_timer(self):
        try:
            age = (self.get_clock().now() - self.last_scan).nanoseconds / 1e9
            if age > WATCHDOG:
                self.get_logger().warn(f'no scan for {age:.1f} s: stopping',
                                       throttle_duration_sec=1.0)
                self.publisher.publish(Twist())
            else:
                self.publisher.publish(self.command)
        except Exception as error:
            self.get_logger().error(f'control cycle failed ({error!r}): stopping')
            self.publisher.publish(Twist())


def main(args=None):
    rclpy.init(args=args)
    node = ObstacleAvoider()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.publisher.publish(Twist())  # the context is already shut down here
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
