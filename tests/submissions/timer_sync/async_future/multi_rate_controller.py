"""Correct: the planner is a coroutine that awaits a future a one-shot ROS-time timer completes."""
import json

import rclpy
from geometry_msgs.msg import Twist
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.task import Future
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
        self.create_timer(0.1, self.on_control)
        self.create_timer(1.0, self.on_status)
        # Awaiting yields the executor's only thread back, so nothing else waits for us.
        self.create_timer(10.0, self.on_planner, callback_group=ReentrantCallbackGroup())

    async def plan_route(self):
        """The planner's 2.0 s of ROS time, awaited instead of slept."""
        done = Future()
        timer = self.create_timer(2.0, lambda: done.set_result(True))
        try:
            await done
        finally:
            self.destroy_timer(timer)
        return 'waypoints: (1.0, 0.0) (2.0, 0.5) (3.0, 0.5)'

    def on_control(self):
        command = Twist()
        command.linear.x = self.get_parameter('cruise_speed').value
        self.cmd_pub.publish(command)
        self.control_ticks += 1

    def on_status(self):
        report = {'control_ticks': self.control_ticks, 'plans': self.plans}
        self.status_pub.publish(String(data=json.dumps(report)))

    async def on_planner(self):
        route = await self.plan_route()
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
