"""Correct: requests in a MutuallyExclusiveCallbackGroup of their own, served one at a time."""
import math
import threading

import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float32
from std_srvs.srv import Trigger

SECTOR = math.radians(30.0)  # half-width of the sector straight ahead
CLEARANCE = 0.5              # metres the path must be clear for
FRESH_SCAN_TIMEOUT = 1.0     # seconds of ROS time a request waits for a new scan


def nearest_ahead(scan):
    """Smallest valid range within +-SECTOR of straight ahead, or None if there is none."""
    nearest = None
    for i, r in enumerate(scan.ranges):
        angle = scan.angle_min + i * scan.angle_increment
        angle = math.atan2(math.sin(angle), math.cos(angle))  # wrap into [-pi, pi]
        valid = math.isfinite(r) and scan.range_min <= r <= scan.range_max
        if valid and abs(angle) <= SECTOR and (nearest is None or r < nearest):
            nearest = r
    return nearest


class SafetySupervisor(Node):

    def __init__(self):
        super().__init__('safety_supervisor')
        # Shared between the scan callback and request callbacks running in other
        # threads: every access holds this condition's lock.
        self.scan_arrived = threading.Condition()
        self.latest_scan = None
        self.scans_received = 0   # since start: tells a request which scans are new
        self.scans_this_second = 0
        # Scans and the rate report share a mutually exclusive group (their counter
        # needs no other protection between them). Requests get a reentrant group of
        # their own: several may wait at once, each holding one executor thread, while
        # the sensor group keeps receiving the scan they are waiting for.
        sensor_group = MutuallyExclusiveCallbackGroup()
        request_group = MutuallyExclusiveCallbackGroup()
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10,
                                 callback_group=sensor_group)
        self.rate_pub = self.create_publisher(Float32, 'scans_per_second', 10)
        self.create_timer(1.0, self.on_rate_timer, callback_group=sensor_group)
        self.create_service(Trigger, 'check_path', self.on_check_path,
                            callback_group=request_group)

    def on_scan(self, scan):
        with self.scan_arrived:
            self.latest_scan = scan
            self.scans_received += 1
            self.scans_this_second += 1
            self.scan_arrived.notify_all()

    def on_rate_timer(self):
        with self.scan_arrived:
            count, self.scans_this_second = self.scans_this_second, 0
        self.rate_pub.publish(Float32(data=float(count)))

    def on_check_path(self, request, response):
        deadline = self.get_clock().now() + Duration(seconds=FRESH_SCAN_TIMEOUT)
        with self.scan_arrived:
            seen = self.scans_received
            # Short waits, because the deadline is in ROS time, which a wall-clock
            # timeout knows nothing about.
            while self.scans_received == seen and self.get_clock().now() < deadline:
                self.scan_arrived.wait(timeout=0.02)
            scan = self.latest_scan if self.scans_received != seen else None
        if scan is None:
            response.success = False
            response.message = f'no fresh scan within {FRESH_SCAN_TIMEOUT} s'
            return response
        nearest = nearest_ahead(scan)
        response.success = nearest is None or nearest >= CLEARANCE
        if nearest is None:
            response.message = 'no obstacle ahead within range'
        else:
            response.message = f'nearest obstacle ahead: {nearest:.2f} m'
        return response


def main(args=None):
    rclpy.init(args=args)
    node = SafetySupervisor()
    # One thread per group: requests, sensor, default (/clock).
    executor = MultiThreadedExecutor(num_threads=3)
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
