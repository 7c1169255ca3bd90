"""AI agent bridge: a Python navigation agent drives the robot through ROS topics.

Tier A: simulation.

Learning objectives: keep an AI agent free of ROS (observations in, actions out) and
bridge it to a robot with one node; turn odometry and lidar into an observation; turn
the agent's action into velocity commands; report the outcome on a topic.

Prerequisites: publishers, subscribers, timers and parameters in one node; NumPy arrays.

Expected output: started with `-p goal_x:=-1.5 -p goal_y:=1.8` in the open room (the goal
in the odom frame, which starts where the robot starts: 1.5 m behind it, 1.8 m to its
left), the robot turns, drives to the goal, stops within 0.3 m of it and publishes "goal
reached" on agent_status; it never touches an obstacle on the way.
"""
import math
import sys

import numpy as np
import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import String  # noqa: F401 - for agent_status

ARRIVED = 0.15  # m: stop this close to the goal (the task allows 0.3)


class NavigationAgent:
    """The AI: observation (pose, goal, obstacle points in the robot frame) to (v, w, done).

    No ROS in here: it can be tested, trained or swapped on its own.
    """

    def act(self, pose, goal, points):
        x, y, theta = pose
        distance = math.hypot(goal[0] - x, goal[1] - y)
        if distance < ARRIVED:
            return 0.0, 0.0, True
        heading = math.remainder(math.atan2(goal[1] - y, goal[0] - x) - theta, math.tau)
        # TODO: `points` holds what the lidar sees (x forward, y left, metres). Right now
        # the agent drives straight at the goal, through anything in the way: choose a
        # heading that is clear for the robot (radius 0.105 m) and as close as possible
        # to the goal's direction.
        if abs(heading) > 0.5:
            return 0.0, float(np.clip(1.5 * heading, -1.0, 1.0)), False  # turn first
        return min(0.4, 0.6 * distance + 0.05), 1.5 * heading, False


class AiAgentBridge(Node):
    """The bridge: ROS messages to observations, actions to Twist, outcome to a topic."""

    def __init__(self):
        super().__init__('ai_agent')
        self.goal = (self.declare_parameter('goal_x', 0.0).value,
                     self.declare_parameter('goal_y', 0.0).value)
        self.agent = NavigationAgent()
        self.pose, self.points = None, None
        self.cmd_vel = self.create_publisher(Twist, 'cmd_vel', 10)
        # TODO: a publisher for std_msgs/String on 'agent_status'.
        self.create_subscription(Odometry, 'odom', self.on_odom, 10)
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)
        self.create_timer(0.1, self.on_timer)

    def on_odom(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        self.pose = (p.x, p.y, 2.0 * math.atan2(q.z, q.w))  # yaw of a planar quaternion

    def on_scan(self, scan):
        # Obstacle points in the robot frame; NaN and inf (no return) are dropped.
        r = np.asarray(scan.ranges, dtype=float)
        a = scan.angle_min + scan.angle_increment * np.arange(len(r))
        ok = np.isfinite(r) & (r >= scan.range_min) & (r <= scan.range_max)
        self.points = np.column_stack((r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])))

    def on_timer(self):
        if self.pose is None or self.points is None:
            return  # nothing observed yet
        v, w, arrived = self.agent.act(self.pose, self.goal, self.points)
        command = Twist()
        command.linear.x, command.angular.z = v, w
        self.cmd_vel.publish(command)
        # TODO: once `arrived` and the robot has stopped (the odometry's
        # twist.twist.linear.x below 0.02 m/s), publish 'goal reached' on agent_status,
        # once.


def main(args=None):
    rclpy.init(args=args)
    node = AiAgentBridge()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
