"""Safety supervisor: answers "is the path ahead clear?" from a laser scan taken after the question.

Tier A: simulation.

Learning objectives: wait inside a service callback for data that another callback
delivers, without deadlocking the node; choose callback groups and a
MultiThreadedExecutor so both can run; guard state shared between threads with a lock.

Prerequisites: subscriptions, services (std_srvs/Trigger) and timers in one Node.

Expected output: `check_path` facing open floor answers success=True, "nearest
obstacle ahead: 2.97 m"; with a box 0.4 m ahead, success=False, "nearest obstacle
ahead: 0.40 m". scans_per_second reads 10.0 every second, also while requests wait.
"""
import math  # noqa: F401 - for the sector test
import threading

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float32
from std_srvs.srv import Trigger


def nearest_ahead(scan):
    """Smallest valid range within +-30 degrees of straight ahead, or None if there is none."""
    # TODO: a reading is valid when it is finite and within [range_min, range_max]. Beam i
    # points at angle_min + i * angle_increment; wrap it into [-pi, pi] before comparing.
    return None


class SafetySupervisor(Node):

    def __init__(self):
        super().__init__('safety_supervisor')
        self.lock = threading.Lock()  # callbacks in other threads share what it guards
        self.latest_scan = None
        self.scans_this_second = 0
        # TODO: create callback groups: one for the scan subscription and the rate timer,
        # another for the service, so a request can wait while scans keep arriving.
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)
        self.rate_pub = self.create_publisher(Float32, 'scans_per_second', 10)
        self.create_timer(1.0, self.on_rate_timer)
        self.create_service(Trigger, 'check_path', self.on_check_path)

    def on_scan(self, scan):
        with self.lock:
            self.latest_scan = scan
            self.scans_this_second += 1

    def on_rate_timer(self):
        with self.lock:
            count, self.scans_this_second = self.scans_this_second, 0
        self.rate_pub.publish(Float32(data=float(count)))

    def on_check_path(self, request, response):
        # TODO: wait (up to 1.0 s of ROS time: self.get_clock().now()) for the first scan
        # that arrives after this request, then answer from it: success when every valid
        # reading ahead is at least 0.5 m, the nearest distance in the message. With no
        # fresh scan, answer success=False and say so. self.latest_scan is older than
        # the request: a box may have appeared since.
        response.success = False
        response.message = 'not implemented yet'
        return response


def main(args=None):
    rclpy.init(args=args)
    node = SafetySupervisor()
    try:
        # TODO: rclpy.spin runs one callback at a time: a request that waits here stops
        # the scans (and /clock) it waits for. Spin a MultiThreadedExecutor instead.
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
