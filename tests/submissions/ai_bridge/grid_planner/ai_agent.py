"""Correct: maps the lidar into an occupancy grid and follows an A* path, replanned often."""
import heapq
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

CELL = 0.1          # m per grid cell
SIZE = 160          # cells a side: 16 m, centred on the first pose seen
INFLATE = 0.3       # m: robot radius plus margin, kept clear of every obstacle cell
REPLAN_EVERY = 5    # control cycles
STEPS = [(dx, dy, math.hypot(dx, dy)) for dx in (-1, 0, 1) for dy in (-1, 0, 1) if dx or dy]
DISC = [(dx, dy) for dx in range(-3, 4) for dy in range(-3, 4)
        if math.hypot(dx, dy) * CELL <= INFLATE]


class NavigationAgent:
    """Map, plan, follow: no ROS in here."""

    def __init__(self):
        self.origin = None
        self.blocked = np.zeros((SIZE, SIZE), dtype=bool)
        self.path = []
        self.cycle = 0

    def cell(self, x, y):
        return (int(round((x - self.origin[0]) / CELL)) + SIZE // 2,
                int(round((y - self.origin[1]) / CELL)) + SIZE // 2)

    def centre(self, c):
        return ((c[0] - SIZE // 2) * CELL + self.origin[0],
                (c[1] - SIZE // 2) * CELL + self.origin[1])

    def mark(self, pose, points):
        x, y, theta = pose
        c, s = math.cos(theta), math.sin(theta)
        wx = x + c * points[:, 0] - s * points[:, 1]
        wy = y + s * points[:, 0] + c * points[:, 1]
        ix = np.round((wx - self.origin[0]) / CELL).astype(int) + SIZE // 2
        iy = np.round((wy - self.origin[1]) / CELL).astype(int) + SIZE // 2
        for dx, dy in DISC:
            jx, jy = ix + dx, iy + dy
            ok = (jx >= 0) & (jx < SIZE) & (jy >= 0) & (jy < SIZE)
            self.blocked[jx[ok], jy[ok]] = True

    def plan(self, start, goal):
        """A* over free cells (unknown counts as free); [] when there is no way."""
        blocked = self.blocked.copy()
        blocked[start] = False  # never plan out of a cell we are already in
        frontier, came, cost = [(0.0, start)], {start: None}, {start: 0.0}
        while frontier:
            _, here = heapq.heappop(frontier)
            if here == goal:
                path = []
                while here is not None:
                    path.append(here)
                    here = came[here]
                return path[::-1]
            for dx, dy, step in STEPS:
                there = (here[0] + dx, here[1] + dy)
                if not (0 <= there[0] < SIZE and 0 <= there[1] < SIZE) or blocked[there]:
                    continue
                new = cost[here] + step
                if new < cost.get(there, math.inf):
                    cost[there], came[there] = new, here
                    heapq.heappush(frontier, (new + math.dist(there, goal), there))
        return []

    def act(self, pose, goal, points):
        x, y, theta = pose
        if self.origin is None:
            self.origin = (x, y)
        distance = math.hypot(goal[0] - x, goal[1] - y)
        if distance < 0.15:
            return 0.0, 0.0, True
        self.mark(pose, points)
        here = self.cell(x, y)
        if self.cycle % REPLAN_EVERY == 0 or any(self.blocked[c] for c in self.path[1:]):
            self.path = self.plan(here, self.cell(*goal))
        self.cycle += 1
        if not self.path:
            return 0.0, 0.5, False  # no way known: look around
        # Pure pursuit: the first path point at least 0.3 m away (or the goal).
        target = goal
        for c in self.path:
            px, py = self.centre(c)
            if math.hypot(px - x, py - y) >= 0.3:
                target = (px, py)
                break
        bearing = math.remainder(math.atan2(target[1] - y, target[0] - x) - theta, math.tau)
        turn = max(-1.0, min(1.0, 1.8 * bearing))
        if abs(bearing) > 0.6:
            return 0.0, turn, False
        return min(0.35, 0.6 * distance + 0.05) * math.cos(bearing), turn, False


class AiAgentBridge(Node):

    def __init__(self):
        super().__init__('ai_agent')
        self.goal = (self.declare_parameter('goal_x', 0.0).value,
                     self.declare_parameter('goal_y', 0.0).value)
        self.agent = NavigationAgent()
        self.pose = self.points = None
        self.moving = True  # the odometry's speed is 0.02 m/s or more
        self.done = False
        self.cmd_vel = self.create_publisher(Twist, 'cmd_vel', 10)
        self.status = self.create_publisher(String, 'agent_status', 10)
        self.create_subscription(Odometry, 'odom', self.on_odom, 10)
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)
        self.create_timer(0.1, self.on_timer)

    def on_odom(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        self.pose = (p.x, p.y, math.atan2(2 * q.w * q.z, 1 - 2 * q.z * q.z))
        self.moving = abs(msg.twist.twist.linear.x) >= 0.02

    def on_scan(self, scan):
        r = np.array(scan.ranges, dtype=float)
        a = scan.angle_min + scan.angle_increment * np.arange(r.size)
        keep = np.isfinite(r) & (r > scan.range_min) & (r < scan.range_max)
        self.points = np.stack([r[keep] * np.cos(a[keep]), r[keep] * np.sin(a[keep])], axis=1)

    def on_timer(self):
        if self.pose is None or self.points is None:
            return
        v, w, done = self.agent.act(self.pose, self.goal, self.points)
        twist = Twist()
        twist.linear.x, twist.angular.z = float(v), float(w)
        self.cmd_vel.publish(twist)
        if done and not self.moving and not self.done:  # stopped there, not only stopping
            self.done = True
            self.status.publish(String(data=f'reached ({self.goal[0]}, {self.goal[1]})'))


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
