"""Correct: a MultiThreadedExecutor, every timer in one ReentrantCallbackGroup, counters locked."""
import json
import threading

import rclpy
from geometry_msgs.msg import Twist
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import String


class MultiRateController(Node):

    def __init__(self):
        super().__init__('multi_rate_controller')
        self.declare_parameter('cruise_speed', 0.2)
        self.counts = {'control_ticks': 0, 'plans': 0}
        self.lock = threading.Lock()
        self.cmd_pub = self.create_publisher(Twist, 'cmd_vel', 10)
        self.status_pub = self.create_publisher(String, 'status', 10)
        self.plan_pub = self.create_publisher(String, 'plan', 10)
        group = ReentrantCallbackGroup()
        self.create_timer(0.1, self.on_control, callback_group=group)
        self.create_timer(1.0, self.on_status, callback_group=group)
        self.create_timer(10.0, self.on_planner, callback_group=group)

    def plan_route(self):
        """Provided: a slow planner that takes 2.0 s of ROS time."""
        self.get_clock().sleep_for(Duration(seconds=2.0))
        return 'waypoints: (1.0, 0.0) (2.0, 0.5) (3.0, 0.5)'

    def on_control(self):
        command = Twist()
        command.linear.x = self.get_parameter('cruise_speed').value
        self.cmd_pub.publish(command)
        with self.lock:
            self.counts['control_ticks'] += 1

    def on_status(self):
        with self.lock:
            report = json.dumps(self.counts)
        self.status_pub.publish(String(data=report))

    def on_planner(self):
        route = self.plan_route()
        with self.lock:
            self.counts['plans'] += 1
        self.plan_pub.publish(String(data=route))


def main(args=None):
    rclpy.init(args=args)
    node = MultiRateController()
    executor = MultiThreadedExecutor(num_threads=4)
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
