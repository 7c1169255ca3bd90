"""Multi-rate controller: one callback group per timer, callbacks bound with functools.partial.

Tier A: simulation. Written from the README alone. The counters live in a small dataclass
behind a lock (the control and status timers are in different groups here, so they may
run at once); the planner's group is its own, so plan_route() blocks only its thread.
"""
import json
import sys
import threading
from dataclasses import dataclass, field
from functools import partial

import rclpy
from geometry_msgs.msg import Twist
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import String

RATES = {'control': 0.1, 'status': 1.0, 'planner': 10.0}  # periods in seconds of ROS time


@dataclass
class Counters:
    control_ticks: int = 0
    plans: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)

    def bump(self, name):
        with self.lock:
            setattr(self, name, getattr(self, name) + 1)

    def snapshot(self):
        with self.lock:
            return {'control_ticks': self.control_ticks, 'plans': self.plans}


class MultiRateController(Node):

    def __init__(self):
        super().__init__('multi_rate_controller')
        self.declare_parameter('cruise_speed', 0.2)
        self.counters = Counters()
        publishers = {'control': self.create_publisher(Twist, 'cmd_vel', 10),
                      'status': self.create_publisher(String, 'status', 10),
                      'planner': self.create_publisher(String, 'plan', 10)}
        callbacks = {'control': self.control, 'status': self.status, 'planner': self.planner}
        for name, period in RATES.items():
            self.create_timer(period, partial(callbacks[name], publishers[name]),
                              callback_group=MutuallyExclusiveCallbackGroup())

    def plan_route(self):
        """Provided: a slow planner that takes 2.0 s of ROS time. Do not change it."""
        self.get_clock().sleep_for(Duration(seconds=2.0))
        return 'waypoints: (1.0, 0.0) (2.0, 0.5) (3.0, 0.5)'

    def control(self, publisher):
        command = Twist()
        command.linear.x = self.get_parameter('cruise_speed').value
        publisher.publish(command)
        self.counters.bump('control_ticks')

    def status(self, publisher):
        publisher.publish(String(data=json.dumps(self.counters.snapshot())))

    def planner(self, publisher):
        route = self.plan_route()
        publisher.publish(String(data=route))
        self.counters.bump('plans')


def main(args=None):
    rclpy.init(args=args)
    node = MultiRateController()
    executor = MultiThreadedExecutor(num_threads=4)  # three timers and /clock
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
