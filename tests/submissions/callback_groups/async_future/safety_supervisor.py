"""Correct: one thread; each request awaits a future that the next scan, or a timer, completes."""
import math

import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.task import Future
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float32
from std_srvs.srv import Trigger

SECTOR = math.radians(30.0)
CLEARANCE = 0.5
FRESH_SCAN_TIMEOUT = 1.0


def nearest_ahead(scan):
    ahead = []
    for i, r in enumerate(scan.ranges):
        angle = scan.angle_min + i * scan.angle_increment
        angle = math.atan2(math.sin(angle), math.cos(angle))
        if abs(angle) <= SECTOR and math.isfinite(r) and scan.range_min <= r <= scan.range_max:
            ahead.append(r)
    return min(ahead) if ahead else None


class SafetySupervisor(Node):

    def __init__(self):
        super().__init__('safety_supervisor')
        # Everything runs in the executor's one thread: no locks. A request awaits its
        # future, which hands the thread back until the future is done.
        self.waiting = []
        self.count = 0
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)
        self.rate_pub = self.create_publisher(Float32, 'scans_per_second', 10)
        self.create_timer(1.0, self.on_rate_timer)
        self.create_service(Trigger, 'check_path', self.on_check_path,
                            callback_group=ReentrantCallbackGroup())

    def on_scan(self, scan):
        self.count += 1
        waiting, self.waiting = self.waiting, []
        for future in waiting:
            if not future.done():
                future.set_result(scan)

    def on_rate_timer(self):
        self.rate_pub.publish(Float32(data=float(self.count)))
        self.count = 0

    async def on_check_path(self, request, response):
        fresh = Future()
        self.waiting.append(fresh)

        def give_up():
            if not fresh.done():
                fresh.set_result(None)

        timer = self.create_timer(FRESH_SCAN_TIMEOUT, give_up)  # ROS time
        try:
            scan = await fresh
        finally:
            self.destroy_timer(timer)
        if scan is None:
            response.success = False
            response.message = 'no fresh scan within 1.0 s'
            return response
        nearest = nearest_ahead(scan)
        response.success = nearest is None or nearest >= CLEARANCE
        response.message = ('nothing ahead within range' if nearest is None
                            else f'nearest obstacle ahead: {nearest:.2f} m')
        return response


def main(args=None):
    rclpy.init(args=args)
    node = SafetySupervisor()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
