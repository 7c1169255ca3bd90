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
from std_msgs.msg import String

ARRIVED = 0.15          # m: stop this close to the goal (the task allows 0.3)
STOPPED = 0.02          # m/s: slower than this, the robot has stopped (report only then)
CLEARANCE = 0.25        # m: robot radius (0.105) plus a margin, each side of a path
LOOKAHEAD = 1.0         # m: a heading is fully open if this much of it is clear
SAFE = 0.35             # m: never head where less than this is clear
TOP_SPEED = 0.4         # m/s
STEP = math.radians(5)
HEADINGS = np.arange(-math.pi, math.pi, STEP)  # candidate headings, robot frame


class NavigationAgent:
    """The AI: from an observation (pose, goal, obstacle points) to an action (v, w).

    Pure Python and NumPy, no ROS: it can be tested, trained or swapped on its own.
    """

    def act(self, pose, goal, points):
        x, y, theta = pose
        dx, dy = goal[0] - x, goal[1] - y
        distance = math.hypot(dx, dy)
        if distance < ARRIVED:
            return 0.0, 0.0, True
        to_goal = math.remainder(math.atan2(dy, dx) - theta, math.tau)
        free = self.free_distance(points)
        gap = np.abs(np.remainder(HEADINGS - to_goal + np.pi, 2 * np.pi) - np.pi)
        need = min(distance, LOOKAHEAD)
        # Cost of a heading: off the goal's direction, a sharp turn, too little room ahead.
        cost = gap + 0.3 * np.abs(HEADINGS) + (1.0 - np.minimum(free / need, 1.0))
        cost[free < SAFE] = np.inf
        if np.isinf(cost).all():
            heading = HEADINGS[np.argmax(free)]  # boxed in: face the most room
        else:
            best = np.argmin(cost)
            aim = gap[best] <= STEP and free[best] >= need  # goal in sight: aim at it
            heading = to_goal if aim else HEADINGS[best]
        turn = float(np.clip(1.5 * heading, -1.0, 1.0))
        if abs(heading) > 0.5:
            return 0.0, turn, False  # turn in place before driving off
        ahead = free[np.argmin(np.abs(HEADINGS))]
        speed = min(TOP_SPEED, 0.6 * distance + 0.05, 0.5 * ahead) * math.cos(heading)
        return max(0.0, speed), turn, False

    @staticmethod
    def free_distance(points):
        """For each candidate heading, how far the robot could drive along it."""
        if len(points) == 0:
            return np.full(len(HEADINGS), np.inf)
        ux, uy = np.cos(HEADINGS)[:, None], np.sin(HEADINGS)[:, None]
        along = points[:, 0] * ux + points[:, 1] * uy
        across = np.abs(points[:, 1] * ux - points[:, 0] * uy)
        in_path = (along > 0) & (across < CLEARANCE)
        return np.where(in_path, along, np.inf).min(axis=1)


class AiAgentBridge(Node):
    """The bridge: ROS messages to observations, actions to Twist, outcome to a topic."""

    def __init__(self):
        super().__init__('ai_agent')
        self.goal = (self.declare_parameter('goal_x', 0.0).value,
                     self.declare_parameter('goal_y', 0.0).value)
        self.agent = NavigationAgent()
        self.pose = None
        self.points = None
        self.speed = 0.0
        self.reported = False
        self.cmd_vel = self.create_publisher(Twist, 'cmd_vel', 10)
        self.status = self.create_publisher(String, 'agent_status', 10)
        self.create_subscription(Odometry, 'odom', self.on_odom, 10)
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)
        self.create_timer(0.1, self.on_timer)

    def on_odom(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        self.pose = (p.x, p.y, 2.0 * math.atan2(q.z, q.w))  # yaw of a planar quaternion
        self.speed = abs(msg.twist.twist.linear.x)  # the wheels' speed, m/s

    def on_scan(self, scan):
        # Obstacle points in the robot frame; NaN and inf (no return) are dropped.
        r = np.asarray(scan.ranges, dtype=float)
        a = scan.angle_min + scan.angle_increment * np.arange(len(r))
        with np.errstate(invalid='ignore'):
            ok = np.isfinite(r) & (r >= scan.range_min) & (r <= scan.range_max)
        self.points = np.column_stack((r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])))

    def on_timer(self):
        if self.pose is None or self.points is None:
            return  # nothing observed yet
        v, w, arrived = self.agent.act(self.pose, self.goal, self.points)
        command = Twist()
        command.linear.x, command.angular.z = v, w
        self.cmd_vel.publish(command)
        # Arrived is not stopped: the robot brakes for a moment after the zero Twist, so
        # report once the odometry says it stands, and only once.
        if arrived and self.speed < STOPPED and not self.reported:
            self.reported = True
            self.status.publish(String(data='goal reached'))
            self.get_logger().info(f'goal reached at ({self.pose[0]:.2f}, {self.pose[1]:.2f})')


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
