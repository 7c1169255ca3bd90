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
    """A differential drive's dead reckoning: (x, y, theta) in ``odom`` from (v, w) steps.

    Steps at the same (v, w) are integrated together in closed form (:func:`_arc`), the
    same as step by step to float rounding: a robot holds its command for hundreds of
    physics steps, and this runs at every one of them.  Consecutive runs at the same
    velocities are merged before integrating, and reading the pose does not integrate, so
    the result depends only on the velocities step by step, not on how they were handed
    in nor when the pose was read.
    """

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Back to the frame's origin: the robot's pose when it started."""
        self._x = self._y = self._theta = 0.0  # where the run in progress began
        self.v = self.w = 0.0
        self._dt = 0.0
        self._steps = 0  # of the run in progress, at (v, w) for dt each

    def step(self, v: float, w: float, dt: float) -> None:
        """Advance by ``dt`` at linear ``v`` and angular ``w`` (second-order Runge-Kutta,
        as ROS's diff_drive_controller integrates)."""
        self.run(v, w, dt, 1)

    def run(self, v: float, w: float, dt: float, steps: int) -> None:
        """Advance by ``steps`` steps of ``dt``, each as :meth:`step` would."""
        if steps <= 0:
            return
        if (v, w, dt) != (self.v, self.w, self._dt):
            self._x, self._y, self._theta = self._integrated()
            self.v, self.w, self._dt, self._steps = v, w, dt, 0
        self._steps += steps

    def _integrated(self) -> tuple[float, float, float]:
        n = self._steps
        if not n:
            return self._x, self._y, self._theta
        return _arc(self._x, self._y, self._theta, self.v, self.w, self._dt, n)

    @property
    def pose(self) -> tuple[float, float, float]:
        """(x, y, theta) in ``odom``, theta wrapped to (-pi, pi]."""
        x, y, theta = self._integrated()
        return x, y, _wrap(theta)


def _arc(x: float, y: float, theta: float, v: float, w: float, dt: float,
         n: int) -> tuple[float, float, float]:
    """``n`` second-order Runge-Kutta steps of ``dt`` at constant (v, w), in closed form.

    Step k moves ``v dt`` along ``theta + (k + 1/2) w dt``; the sum of those cosines (and
    sines) over k < n is ``sin(n d/2) / sin(d/2)`` times the cosine (sine) of the mean
    heading ``theta + n d/2``, with ``d = w dt``.
    """
    d = w * dt
    if not d:  # straight on (or w dt too small to turn, as step by step)
        if v:
            x += n * (v * dt) * math.cos(theta)
            y += n * (v * dt) * math.sin(theta)
        return x, y, theta
    if v:
        chord = v * dt * (math.sin(n * d / 2) / math.sin(d / 2) if n > 1 else 1.0)
        heading = theta + n * d / 2
        x += chord * math.cos(heading)
        y += chord * math.sin(heading)
    return x, y, theta + n * d


def to_odom(start: Pose, x: float, y: float) -> tuple[float, float]:
    """A world-frame point in the ``odom`` frame of a robot that started at ``start``."""
    dx, dy = x - start.x, y - start.y
    c, s = math.cos(start.theta), math.sin(start.theta)
    return c * dx + s * dy, -s * dx + c * dy


def to_world(start: Pose, x: float, y: float) -> tuple[float, float]:
    """An ``odom``-frame point in the world frame (the inverse of :func:`to_odom`)."""
    c, s = math.cos(start.theta), math.sin(start.theta)
    return start.x + c * x - s * y, start.y + s * x + c * y
