"""Multi-rate controller: a 10 Hz control loop that keeps its beat while a slow planner runs.

Tier A: simulation.

Learning objectives: run timers of different rates in one node; keep a slow callback
from starving a fast one with a MultiThreadedExecutor and callback groups; see why the
/clock subscription that drives ROS time must never wait behind a blocked callback.

Prerequisites: publishers and timers in one Node; use_sim_time.

Expected output: cmd_vel at 10 Hz with linear.x 0.2; every second a status such as
{"control_ticks": 120, "plans": 1}; every 10 s a plan, 2 s after the planner starts,
and cmd_vel never misses a beat while it runs.
"""
import json  # noqa: F401 - for the status message

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
        self.cmd_pub = self.create_publisher(Twist, 'cmd_vel', 10)
        self.status_pub = self.create_publisher(String, 'status', 10)
        self.plan_pub = self.create_publisher(String, 'plan', 10)
        # Timers follow the node's clock: simulation time under use_sim_time:=true.
        # TODO: put the planner timer in a callback group of its own, so a running plan
        # cannot hold up the control timer (or the /clock subscription, which sits in
        # the node's default group).
        self.create_timer(0.1, self.on_control)
        self.create_timer(1.0, self.on_status)
        self.create_timer(10.0, self.on_planner)

    def plan_route(self):
        """Provided: a slow planner that takes 2.0 s of ROS time. Do not change it."""
        self.get_clock().sleep_for(Duration(seconds=2.0))
        return 'waypoints: (1.0, 0.0) (2.0, 0.5) (3.0, 0.5)'

    def on_control(self):
        command = Twist()
        command.linear.x = self.get_parameter('cruise_speed').value
        self.cmd_pub.publish(command)
        self.control_ticks += 1

    def on_status(self):
        # TODO: publish a JSON object with control_ticks and plans, e.g.
        # {"control_ticks": 120, "plans": 1}, as a std_msgs/String on status.
        pass

    def on_planner(self):
        route = self.plan_route()
        # TODO: count the finished plan and publish the route on plan.
        self.get_logger().info(route)


def main(args=None):
    rclpy.init(args=args)
    node = MultiRateController()
    try:
        # TODO: rclpy.spin runs every callback in one thread. While plan_route sleeps,
        # nothing else runs, not even the /clock callback its sleep is waiting for.
        # Spin a MultiThreadedExecutor instead.
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
