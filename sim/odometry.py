"""Wheel odometry in the ``odom`` frame (REP 105), and the frame's link to the world.

A robot does not know where it is in the world: its ``odom`` frame starts where it starts,
at (0, 0, 0), and its pose there is integrated from what its wheels did.  Here the wheels
turn at the velocities the drive produced each physics step (the command after
acceleration limiting), so odometry follows the robot while it rolls freely and drifts
from the truth where it does not: pushed against a wall the wheels still turn.  The world
frame, ground truth, stays with the grader (:class:`sim.recorder.Recording`).
"""

from __future__ import annotations

import math

from sim.worldfile import Pose


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


class WheelOdometry:
    """A differential drive's dead reckoning: (x, y, theta) in ``odom`` from (v, w) steps."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Back to the frame's origin: the robot's pose when it started."""
        self.x = self.y = self.theta = 0.0
        self.v = self.w = 0.0

    def step(self, v: float, w: float, dt: float) -> None:
        """Advance by ``dt`` at linear ``v`` and angular ``w`` (second-order Runge-Kutta,
        as ROS's diff_drive_controller integrates).  Runs every physics step, so it is kept
        lean: the heading is wrapped when read, not here."""
        self.v, self.w = v, w
        if v:
            heading = self.theta + w * dt / 2
            self.x += v * dt * math.cos(heading)
            self.y += v * dt * math.sin(heading)
        if w:
            self.theta += w * dt

    @property
    def pose(self) -> tuple[float, float, float]:
        """(x, y, theta) in ``odom``, theta wrapped to (-pi, pi]."""
        return self.x, self.y, _wrap(self.theta)


def to_odom(start: Pose, x: float, y: float) -> tuple[float, float]:
    """A world-frame point in the ``odom`` frame of a robot that started at ``start``."""
    dx, dy = x - start.x, y - start.y
    c, s = math.cos(start.theta), math.sin(start.theta)
    return c * dx + s * dy, -s * dx + c * dy


def to_world(start: Pose, x: float, y: float) -> tuple[float, float]:
    """An ``odom``-frame point in the world frame (the inverse of :func:`to_odom`)."""
    c, s = math.cos(start.theta), math.sin(start.theta)
    return start.x + c * x - s * y, start.y + s * x + c * y
