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
import json

import rclpy
from geometry_msgs.msg import Twist
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
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
        # Control and status share a mutually exclusive group, so they never run at the
        # same time and their counters need no lock. The planner gets a group of its own:
        # while it blocks, another executor thread keeps running control, status and
        # the /clock subscription (which sits in the node's default group).
        self.fast_group = MutuallyExclusiveCallbackGroup()
        self.planner_group = MutuallyExclusiveCallbackGroup()
        self.create_timer(0.1, self.on_control, callback_group=self.fast_group)
        self.create_timer(1.0, self.on_status, callback_group=self.fast_group)
        self.create_timer(10.0, self.on_planner, callback_group=self.planner_group)

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
        # self.plans is written by the planner thread; reading an int is atomic in Python.
        report = {'control_ticks': self.control_ticks, 'plans': self.plans}
        self.status_pub.publish(String(data=json.dumps(report)))

    def on_planner(self):
        route = self.plan_route()
        self.plans += 1  # counted before publishing: a status never lags a plan seen
        self.plan_pub.publish(String(data=route))


def main(args=None):
    rclpy.init(args=args)
    node = MultiRateController()
    # Threads for: control/status, planner, and the default group (/clock, parameters).
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
