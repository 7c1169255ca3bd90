"""Headless pymunk physics of the arena and the differential-drive robot.

The robot is a dynamic disc steered like pymunk's "tank" example: a kinematic control
body carries the commanded velocities, and a PivotJoint and a GearJoint with limited
force drag the robot along.  Contacts with walls and obstacles are therefore solved by
pymunk, not faked: a robot driven into a wall stops at it.  Time advances only in whole
steps of ``dt`` and ``time`` is ``steps * dt``, so the same spec and command sequence give
the same trajectory bit for bit.  Nothing here knows about ROS.
"""

from __future__ import annotations

import math

import numpy as np
import pymunk

from content.i18n import N_, NP_, _, pgettext
from sim.contact import Contact
from sim.worldfile import ROBOT_RADIUS, Box, Circle, WorldSpec

ROBOT_MASS = 1.0
"""kg, about a TurtleBot3 Burger."""
_DRIVE_FORCE = 40.0
"""N the drive may exert: enough for the acceleration limits, finite so contacts win."""
_DRIVE_TORQUE = 2.0
_ROBOT = 1
_STATIC = 2
# The bodies' property setters, called without the __setattr__ hook pymunk adds for type
# checkers: the same C calls, a third of the Python cost, 200 times a simulated second.
_set_velocity = pymunk.Body.velocity.fset
_set_angular_velocity = pymunk.Body.angular_velocity.fset
# Space.step's work besides the C step: adds, removals and callbacks deferred during a
# step, and bodies to check.  While none is pending (every step but the first, here) the
# world calls the C step through pymunk's own binding, as Space.step does, without the
# wrapper's Python (a fifth of a step's cost); otherwise, or if pymunk's internals are
# not the ones expected, it calls Space.step.
_SPACE_PENDING = ("_bodies_to_check", "_add_later", "_remove_later", "_post_step_callbacks",
                  "_removed_shapes")
try:
    from pymunk._chipmunk_cffi import lib as _chipmunk
except ImportError:  # pragma: no cover - another pymunk layout: the public API only
    _chipmunk = None


# What a contact names.  ``Contact.what`` is data ("wall 3"): recordings keep it as is in
# the results, whatever the language; people are shown :func:`describe`.
_THINGS = {"wall": N_("wall {number}"), "box": N_("box {number}"),
           "circle": N_("circle {number}"), "added box": N_("added box {number}"),
           "added circle": N_("added circle {number}")}
# The same names where a postposition follows ("hit {what}": Urdu "ڈبے 2 سے", never the
# direct "ڈبہ 2 سے"); the same words in English.
_OBLIQUE = "before a postposition"
_THINGS_OBLIQUE = {"wall": NP_("before a postposition", "wall {number}"),
                   "box": NP_("before a postposition", "box {number}"),
                   "circle": NP_("before a postposition", "circle {number}"),
                   "added box": NP_("before a postposition", "added box {number}"),
                   "added circle": NP_("before a postposition", "added circle {number}")}


def describe(what: str, oblique: bool = False) -> str:
    """``what`` a contact names ("wall 3", "added box 7"), in the active language; with
    ``oblique``, in the form a name takes before a postposition (what a robot hits)."""
    kind, _sep, number = what.rpartition(" ")
    template = (_THINGS_OBLIQUE if oblique else _THINGS).get(kind)
    if template is None or not number.isdigit():
        return what  # "?" or a label a test chose
    text = pgettext(_OBLIQUE, template) if oblique else _(template)
    return text.format(number=number)


def _approach(current: float, target: float, max_delta: float) -> float:
    return current + max(-max_delta, min(max_delta, target - current))


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


def box_corners(box: Box) -> list[tuple[float, float]]:
    """The four corners of a rotated box, counter-clockwise."""
    c, s = math.cos(box.angle), math.sin(box.angle)
    hw, hh = box.size[0] / 2, box.size[1] / 2
    return [(box.center[0] + c * x - s * y, box.center[1] + s * x + c * y)
            for x, y in ((-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh))]


def _wall_corners(a: tuple[float, float], b: tuple[float, float],
                  thickness: float) -> list[tuple[float, float]]:
    """A thick wall as the rectangle around its centre line (for ray casting)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length = math.hypot(dx, dy) or 1.0
    nx, ny = -dy / length * thickness / 2, dx / length * thickness / 2
    return [(a[0] + nx, a[1] + ny), (b[0] + nx, b[1] + ny),
            (b[0] - nx, b[1] - ny), (a[0] - nx, a[1] - ny)]


class World:
    """The pymunk world of one :class:`WorldSpec`, stepped at a fixed ``dt``."""

    def __init__(self, spec: WorldSpec, seed: int | None = None, dt: float = 0.005,
                 direct_step: bool = True) -> None:
        self.spec = spec
        self.seed = spec.seed if seed is None else seed
        self.dt = dt
        self.direct_step = direct_step
        self.reset()

    # -- building -----------------------------------------------------------------
    def reset(self) -> None:
        """Rebuild the world from its spec: time 0, robot at start, run-time obstacles gone."""
        self.space = pymunk.Space()
        self.space.iterations = 20
        self.steps = 0
        self._target = (0.0, 0.0)
        self._command = (0.0, 0.0)
        self._contacts: list[Contact] = []
        self._labels: dict[pymunk.Shape, str] = {}
        self._segments: list[tuple[float, float, float, float]] = []
        self._circles: list[tuple[float, float, float]] = []
        self._geometry: tuple[np.ndarray, np.ndarray] | None = None
        for i, (a, b) in enumerate(self.spec.all_walls()):
            shape = pymunk.Segment(self.space.static_body, a, b, self.spec.wall_thickness / 2)
            self._add_static(shape, f"wall {i}")
            self._add_polygon(_wall_corners(a, b, self.spec.wall_thickness))
        for i, box in enumerate(self.spec.obstacles.boxes):
            self._add_box(box, f"box {i}")
        for i, circle in enumerate(self.spec.obstacles.circles):
            self._add_circle(circle, f"circle {i}")
        self._build_robot()
        self.space.on_collision(_ROBOT, _STATIC, begin=self._on_begin)
        self._c_space = self._c_robot = self._c_control = None
        if (self.direct_step and _chipmunk is not None and not self.space.threaded
                and all(hasattr(self.space, name) for name in _SPACE_PENDING)):
            self._c_space = self.space._space
            self._c_robot, self._c_control = self.robot._body, self.control._body

    @property
    def steps_directly(self) -> bool:
        """Whether a step calls Chipmunk itself (without ``Space.step``'s Python) when
        nothing is pending; ``direct_step=False`` always takes pymunk's public path."""
        return self._c_space is not None

    def _build_robot(self) -> None:
        start = self.spec.start
        self.control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        self.control.position = (start.x, start.y)
        self.control.angle = start.theta
        moment = pymunk.moment_for_circle(ROBOT_MASS, 0, ROBOT_RADIUS)
        self.robot = pymunk.Body(ROBOT_MASS, moment)
        self.robot.position = (start.x, start.y)
        self.robot.angle = start.theta
        shape = pymunk.Circle(self.robot, ROBOT_RADIUS)
        shape.friction, shape.elasticity = 0.3, 0.0
        shape.collision_type = _ROBOT
        pivot = pymunk.PivotJoint(self.control, self.robot, (0, 0), (0, 0))
        pivot.max_bias, pivot.max_force = 0.0, _DRIVE_FORCE  # match velocity only
        gear = pymunk.GearJoint(self.control, self.robot, 0.0, 1.0)
        gear.max_bias, gear.max_force = 0.0, _DRIVE_TORQUE
        self.space.add(self.control, self.robot, shape, pivot, gear)

    def _add_static(self, shape: pymunk.Shape, label: str) -> None:
        shape.friction, shape.elasticity = 0.3, 0.0
        shape.collision_type = _STATIC
        self._labels[shape] = label
        self.space.add(shape)
        self._geometry = None

    def _add_polygon(self, corners: list[tuple[float, float]]) -> None:
        for i, (x1, y1) in enumerate(corners):
            x2, y2 = corners[(i + 1) % len(corners)]
            self._segments.append((x1, y1, x2, y2))

    def _add_box(self, box: Box, label: str) -> None:
        corners = box_corners(box)
        self._add_static(pymunk.Poly(self.space.static_body, corners), label)
        self._add_polygon(corners)

    def _add_circle(self, circle: Circle, label: str) -> None:
        shape = pymunk.Circle(self.space.static_body, circle.radius, circle.center)
        self._add_static(shape, label)
        self._circles.append((*circle.center, circle.radius))

    def add_obstacle(self, obstacle: Box | Circle, label: str | None = None) -> None:
        """Place a static obstacle now (a fault, or a test changing the world mid-run)."""
        label = label or f"added {type(obstacle).__name__.lower()} {len(self._labels)}"
        if isinstance(obstacle, Box):
            self._add_box(obstacle, label)
        else:
            self._add_circle(obstacle, label)

    def _on_begin(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        other = next((s for s in arbiter.shapes if s.collision_type == _STATIC), None)
        x, y = self.robot.position
        self._contacts.append(Contact(self.time, float(x), float(y),
                                      self._labels.get(other, "?")))

    # -- driving ------------------------------------------------------------------
    def set_command(self, linear: float, angular: float) -> None:
        """Ask for body-frame velocities; clamped to the speed limits now, and reached
        within the acceleration limits over the next steps."""
        lim = self.spec.limits
        linear = 0.0 if math.isnan(linear) else linear
        angular = 0.0 if math.isnan(angular) else angular
        self._target = (_clamp(linear, lim.max_linear_speed),
                        _clamp(angular, lim.max_angular_speed))

    @property
    def command(self) -> tuple[float, float]:
        """The velocities currently driven (after acceleration limiting)."""
        return self._command

    def step(self) -> None:
        """Advance exactly ``dt``."""
        v, w = self._command
        if self._command != self._target:  # once reached, approaching adds exactly 0.0
            lim = self.spec.limits
            v = _approach(v, self._target[0], lim.max_linear_accel * self.dt)
            w = _approach(w, self._target[1], lim.max_angular_accel * self.dt)
            self._command = (v, w)
        space = self.space
        if self._c_space is None or (
                space._bodies_to_check or space._add_later or space._remove_later
                or space._post_step_callbacks or space._removed_shapes):
            heading = self.robot.rotation_vector
            _set_velocity(self.control, (heading.x * v, heading.y * v))
            _set_angular_velocity(self.control, w)
            space.step(self.dt)
        else:  # the same C calls, without pymunk's Python around them
            heading = _chipmunk.cpBodyGetRotation(self._c_robot)
            _chipmunk.cpBodySetVelocity(self._c_control, (heading.x * v, heading.y * v))
            _chipmunk.cpBodySetAngularVelocity(self._c_control, w)
            space._locked = True  # as in Space.step (this world's callback defers nothing)
            _chipmunk.cpSpaceStep(self._c_space, self.dt)
            space._locked = False
        self.steps += 1

    @property
    def has_contacts(self) -> bool:
        """Whether contacts began since :meth:`drain_contacts` was last called."""
        return bool(self._contacts)

    def drain_contacts(self) -> list[Contact]:
        """Contacts that began since the last call."""
        out, self._contacts = self._contacts, []
        return out

    # -- observing ----------------------------------------------------------------
    @property
    def time(self) -> float:
        """Sim seconds since start (or the last reset)."""
        return self.steps * self.dt

    @property
    def pose(self) -> tuple[float, float, float]:
        """(x, y, theta) of the robot in the world frame, theta wrapped to (-pi, pi]."""
        x, y = self.robot.position
        angle = self.robot.angle
        return float(x), float(y), math.atan2(math.sin(angle), math.cos(angle))

    @property
    def velocity(self) -> tuple[float, float]:
        """(linear along the heading, angular) as measured on the robot body."""
        vel = self.robot.velocity
        heading = self.robot.rotation_vector
        return float(vel.x * heading.x + vel.y * heading.y), float(self.robot.angular_velocity)

    @property
    def lateral_velocity(self) -> float:
        """Body-frame sideways velocity (non-zero only when something pushes the robot)."""
        vel = self.robot.velocity
        heading = self.robot.rotation_vector
        return float(-vel.x * heading.y + vel.y * heading.x)

    @property
    def geometry(self) -> tuple[np.ndarray, np.ndarray]:
        """Everything a ray can hit: segments (N, 4) [x1 y1 x2 y2] and circles (M, 3).

        The same read-only arrays until an obstacle is added or the world is reset, so
        the lidar prepares them for casting once per change (:func:`sim.raycast.prepared`).
        """
        if self._geometry is None:
            segments = np.array(self._segments, dtype=float).reshape(-1, 4)
            circles = np.array(self._circles, dtype=float).reshape(-1, 3)
            segments.flags.writeable = circles.flags.writeable = False
            self._geometry = (segments, circles)
        return self._geometry
