"""Correct: plain rclpy.spin; each planner run happens in a Python worker thread."""
import json
import threading

import rclpy
from geometry_msgs.msg import Twist
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class MultiRateController(Node):

    def __init__(self):
        super().__init__('multi_rate_controller')
        self.declare_parameter('cruise_speed', 0.2)
        self.control_ticks = 0
        self.plans = 0
        self.lock = threading.Lock()
        self.worker = None
        self.cmd_pub = self.create_publisher(Twist, 'cmd_vel', 10)
        self.status_pub = self.create_publisher(String, 'status', 10)
        self.plan_pub = self.create_publisher(String, 'plan', 10)
        self.create_timer(0.1, self.on_control)
        self.create_timer(1.0, self.on_status)
        self.create_timer(10.0, self.on_planner)

    def plan_route(self):
        """Provided: a slow planner that takes 2.0 s of ROS time."""
        self.get_clock().sleep_for(Duration(seconds=2.0))
        return 'waypoints: (1.0, 0.0) (2.0, 0.5) (3.0, 0.5)'

    def on_control(self):
        command = Twist()
        command.linear.x = self.get_parameter('cruise_speed').value
        self.cmd_pub.publish(command)
        self.control_ticks += 1

    def on_status(self):
        with self.lock:
            plans = self.plans
        report = {'control_ticks': self.control_ticks, 'plans': plans}
        self.status_pub.publish(String(data=json.dumps(report)))

    def on_planner(self):
        # The timer only starts the work; the executor's thread is free again at once
        # and keeps serving /clock, which the worker's sleep_for waits on.
        if self.worker is None or not self.worker.is_alive():
            self.worker = threading.Thread(target=self.plan_once, daemon=True)
            self.worker.start()

    def plan_once(self):
        try:
            route = self.plan_route()
        except Exception:  # the context shut down mid-plan
            return
        with self.lock:
            self.plans += 1
        self.plan_pub.publish(String(data=route))


def main(args=None):
    rclpy.init(args=args)
    node = MultiRateController()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
