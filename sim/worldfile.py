"""World files: the arena, its walls and obstacles, the robot's start and limits, as YAML.

Each world is a small YAML file parsed into the frozen :class:`WorldSpec`, so instructors
write data, not code.  The outer walls of the arena are always present; ``walls`` lists the
inner ones.  A malformed file raises :class:`ContentError` naming the file, line and field.

Every field of :class:`WorldSpec` has a default, so the smallest world file is empty of
choices; inside list items, what cannot be guessed (a circle's centre and radius, a box's
centre and size, a goal's position, a fault's kind) is required.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Literal

from content import ContentError, Document, build, load_document
from content.i18n import _, pgettext
from sim.faultkinds import KINDS, kind_names

WORLDS_DIR = Path(__file__).resolve().parent / "worlds"
TITLE_CONTEXT = "world"
"""The gettext context of world titles (``messages`` domain, see :func:`extract_world`)."""
ROBOT_RADIUS = 0.105
"""TurtleBot3-like footprint radius (m): the robot is a disc of this size."""
LIDAR_NOISE_SIGMA = 0.01
"""m: the Gaussian range noise of TurtleBot3's Gazebo LDS model."""
LIDAR_MOUNT = (-0.032, 0.0, 0.0)
"""(x, y, yaw) of ``base_scan`` in ``base_footprint``: TurtleBot3 Burger's scan joint."""
CmdVelType = Literal["Twist", "TwistStamped"]

Point = tuple[float, float]
Segment = tuple[Point, Point]


def _f(default: object, doc: str) -> object:
    """A dataclass field with a default and the description shown in docs."""
    if isinstance(default, (list, dict)) or callable(default):
        factory = default if callable(default) else (lambda: type(default)(default))
        return field(default_factory=factory, metadata={"doc": doc})
    return field(default=default, metadata={"doc": doc})


@dataclass(frozen=True)
class Pose:
    """A planar pose in the world frame (metres, radians, counter-clockwise from +x)."""

    x: float = _f(0.0, "x position (m)")
    y: float = _f(0.0, "y position (m)")
    theta: float = _f(0.0, "heading (rad, 0 faces +x)")


@dataclass(frozen=True)
class Goal:
    """A target region the exercise may ask the robot to reach."""

    x: float = field(metadata={"doc": "x of the goal centre (m)"})
    y: float = field(metadata={"doc": "y of the goal centre (m)"})
    tolerance: float = _f(0.2, "radius around the centre that counts as reached (m)")


@dataclass(frozen=True)
class Box:
    """A static rectangular obstacle."""

    center: Point = field(metadata={"doc": "centre [x, y] (m)"})
    size: Point = field(metadata={"doc": "[width, height] before rotation (m)"})
    angle: float = _f(0.0, "rotation (rad)")


@dataclass(frozen=True)
class Circle:
    """A static round obstacle (a pillar, a bin)."""

    center: Point = field(metadata={"doc": "centre [x, y] (m)"})
    radius: float = field(metadata={"doc": "radius (m)"})


@dataclass(frozen=True)
class Obstacles:
    """Static obstacles besides walls."""

    boxes: tuple[Box, ...] = _f((), "rectangular obstacles")
    circles: tuple[Circle, ...] = _f((), "round obstacles")


@dataclass(frozen=True)
class RobotLimits:
    """What the robot's motors can do; commands beyond these are clamped (TurtleBot3-like)."""

    max_linear_speed: float = _f(1.0, "largest |linear velocity| (m/s)")
    max_angular_speed: float = _f(2.84, "largest |angular velocity| (rad/s)")
    max_linear_accel: float = _f(2.5, "largest linear acceleration (m/s^2)")
    max_angular_accel: float = _f(6.0, "largest angular acceleration (rad/s^2)")


@dataclass(frozen=True)
class LidarSpec:
    """The laser scanner: where it sits on the robot, its range and its noise (LDS-01-like)."""

    beams: int = _f(360, "readings per turn, counter-clockwise from straight ahead")
    range_min: float = _f(0.12, "nearest reading (m); closer hits read -inf (REP 117)")
    range_max: float = _f(3.5, "farthest reading (m); nothing within it reads +inf (REP 117)")
    noise_sigma: float = _f(LIDAR_NOISE_SIGMA, "standard deviation of the Gaussian noise "
                            "on each reading in range (m), drawn from the world's seed")
    mount: tuple[float, float, float] = _f(LIDAR_MOUNT, "[x, y, yaw] of base_scan in "
                                           "base_footprint (m, m, rad)")


@dataclass(frozen=True)
class Fault:
    """A fault to inject: a corrupted or missing scan for a time span, or a new obstacle."""

    kind: str = field(metadata={"doc": kind_names() + " (sim/faultkinds.py)"})
    start: float = _f(0.0, "sim time the fault begins (s)")
    end: float | None = _f(None, "sim time the fault ends (s); none means never")
    fraction: float = _f(0.1, "share of beams affected, for the per-beam kinds (0..1)")
    length: int = _f(180, "number of ranges sent, for wrong_length")
    box: Box | None = _f(None, "the obstacle to place, for kind obstacle")
    circle: Circle | None = _f(None, "the obstacle to place, for kind obstacle")


@dataclass(frozen=True)
class WorldSpec:
    """A whole world: arena, walls, obstacles, the robot's start and limits, faults."""

    name: str = _f("world", "short identifier, the file's stem for shipped worlds")
    title: str = _f("", "one line shown to students")
    size: Point = _f((6.0, 6.0), "[width, height] of the arena (m); it spans [0, w] x [0, h]")
    walls: tuple[Segment, ...] = _f((), "inner walls as [[x1, y1], [x2, y2]] segments")
    wall_thickness: float = _f(0.05, "thickness of every wall, outer ones included (m)")
    obstacles: Obstacles = _f(Obstacles, "static boxes and circles")
    start: Pose = _f(None, "the robot's start pose (default: the arena's centre, facing +x)")
    goal: Goal | None = _f(None, "optional goal region")
    limits: RobotLimits = _f(RobotLimits, "the robot's speed and acceleration limits")
    lidar: LidarSpec = _f(LidarSpec, "the laser scanner on /scan")
    cmd_vel_type: CmdVelType = _f("Twist", "message type the robot takes on /cmd_vel: "
                                  "Twist (the textbook's) or TwistStamped (Jazzy's "
                                  "TurtleBot3 and its Gazebo bridge)")
    faults: tuple[Fault, ...] = _f((), "faults injected during the run")
    seed: int = _f(0, "seed for everything random (faults that pick beams, lidar noise)")

    def __post_init__(self) -> None:
        if self.start is None:  # the centre of whatever size was given
            object.__setattr__(self, "start", Pose(self.size[0] / 2, self.size[1] / 2, 0.0))

    def all_walls(self) -> tuple[Segment, ...]:
        """Outer walls around the arena followed by the inner walls."""
        w, h = self.size
        outer: tuple[Segment, ...] = (((0.0, 0.0), (w, 0.0)), ((w, 0.0), (w, h)),
                                      ((w, h), (0.0, h)), ((0.0, h), (0.0, 0.0)))
        return outer + tuple(self.walls)


def _point_segment_distance(p: Point, a: Point, b: Point) -> float:
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy)
                                              / length2))
    return math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy)


def _box_distance(p: Point, box: Box) -> float:
    """Distance from ``p`` to a rotated box (0 inside)."""
    c, s = math.cos(-box.angle), math.sin(-box.angle)
    x, y = p[0] - box.center[0], p[1] - box.center[1]
    lx, ly = abs(c * x - s * y) - box.size[0] / 2, abs(s * x + c * y) - box.size[1] / 2
    return math.hypot(max(lx, 0.0), max(ly, 0.0))


def _positive(doc: Document, value: float, *where: str | int) -> None:
    if not value > 0:
        raise doc.error(_("{field} must be positive, found {value}").format(
            field=str(where[-1]), value=value), *where)


def _validate_fault_kind(doc: Document, fault: Fault, i: int) -> None:
    """The kind is in the table, and the file gives only the fields that kind reads."""
    kind = KINDS.get(fault.kind)
    if kind is None:
        raise doc.error(_("must be one of {allowed}, found {value!r}").format(
            allowed=", ".join(repr(k) for k in KINDS), value=fault.kind), "faults", i, "kind")
    given = doc.data["faults"][i]  # what the file says, not the defaults filled in
    extra = sorted(set(given) - {"kind", *kind.fields})
    if extra:
        raise doc.error(_("unknown field (expected one of: {known})").format(
            known=", ".join(("kind", *kind.fields))), "faults", i, extra[0])
    problem = kind.check(fault) if kind.check else None
    if problem:
        raise doc.error(problem, "faults", i, "kind")


def _validate_lidar(doc: Document, lidar: LidarSpec) -> None:
    _positive(doc, lidar.beams, "lidar", "beams")
    _positive(doc, lidar.range_min, "lidar", "range_min")
    if not lidar.range_max > lidar.range_min:
        raise doc.error(_("range_max must be above range_min, found {value}").format(
            value=lidar.range_max), "lidar", "range_max")
    if not lidar.noise_sigma >= 0:
        raise doc.error(_("noise_sigma must not be negative, found {value}").format(
            value=lidar.noise_sigma), "lidar", "noise_sigma")


def _validate(doc: Document, spec: WorldSpec) -> None:
    """Checks the types alone cannot express, each naming the offending field."""
    w, h = spec.size
    _positive(doc, w, "size", 0)
    _positive(doc, h, "size", 1)
    _positive(doc, spec.wall_thickness, "wall_thickness")
    for name in ("max_linear_speed", "max_angular_speed", "max_linear_accel",
                 "max_angular_accel"):
        _positive(doc, getattr(spec.limits, name), "limits", name)
    _validate_lidar(doc, spec.lidar)
    for i, box in enumerate(spec.obstacles.boxes):
        _positive(doc, box.size[0], "obstacles", "boxes", i, "size", 0)
        _positive(doc, box.size[1], "obstacles", "boxes", i, "size", 1)
    for i, circle in enumerate(spec.obstacles.circles):
        _positive(doc, circle.radius, "obstacles", "circles", i, "radius")
    for i, fault in enumerate(spec.faults):
        _validate_fault_kind(doc, fault, i)
        if not 0.0 <= fault.fraction <= 1.0:
            raise doc.error(_("fraction must be between 0 and 1, found {value}").format(
                value=fault.fraction), "faults", i, "fraction")
        if fault.end is not None and fault.end < fault.start:
            raise doc.error(_("end must not be before start"), "faults", i, "end")
        if fault.length < 0:
            raise doc.error(_("length must not be negative"), "faults", i, "length")
    if spec.goal is not None:
        _positive(doc, spec.goal.tolerance, "goal", "tolerance")
        if not (0 < spec.goal.x < w and 0 < spec.goal.y < h):
            raise doc.error(_("the goal is outside the arena"), "goal")
    p = (spec.start.x, spec.start.y)
    margin = ROBOT_RADIUS + spec.wall_thickness / 2
    if not (margin <= p[0] <= w - margin and margin <= p[1] <= h - margin):
        raise doc.error(_("the start pose is outside the arena"), "start")
    for i, (a, b) in enumerate(spec.walls):
        if _point_segment_distance(p, a, b) < margin:
            raise doc.error(_("the start pose is inside wall {index}").format(index=i),
                            "start")
    for i, box in enumerate(spec.obstacles.boxes):
        if _box_distance(p, box) < ROBOT_RADIUS:
            raise doc.error(_("the start pose is inside box {index}").format(index=i), "start")
    for i, circle in enumerate(spec.obstacles.circles):
        if math.dist(p, circle.center) < ROBOT_RADIUS + circle.radius:
            raise doc.error(_("the start pose is inside circle {index}").format(index=i),
                            "start")


def parse_world(doc: Document) -> WorldSpec:
    """Build and check a :class:`WorldSpec` from a loaded document."""
    data = doc.data
    if isinstance(data, dict) and "name" not in data:
        data = {**data, "name": doc.path.stem}
    spec = build(WorldSpec, doc, data)
    _validate(doc, spec)
    return spec


def world_path(name_or_path: str | Path) -> Path:
    """A shipped world's file for a bare name, else the path itself."""
    text = str(name_or_path)
    if isinstance(name_or_path, Path) or text.endswith((".yaml", ".yml")) or "/" in text:
        return Path(name_or_path)
    return WORLDS_DIR / f"{text}.yaml"


def load_world(name_or_path: str | Path) -> WorldSpec:
    """Load a world by bare name (``sim/worlds/<name>.yaml``) or by path."""
    path = world_path(name_or_path)
    if not path.exists() and path.parent == WORLDS_DIR:
        raise ContentError(path, _("unknown world {name!r} (known: {known})").format(
            name=str(name_or_path), known=", ".join(world_names())))
    return parse_world(load_document(path))


def world_names() -> list[str]:
    """Names of the shipped worlds."""
    return sorted(p.stem for p in WORLDS_DIR.glob("*.yaml"))


def title_of(spec: WorldSpec) -> str:
    """The world's title in the active language (its name when it has none)."""
    return pgettext(TITLE_CONTEXT, spec.title) if spec.title else spec.name


def extract_world(fileobj: IO[bytes], keywords: Mapping[str, Any],
                  comment_tags: Collection[str],
                  options: Mapping[str, Any]) -> Iterator[tuple[int, str, tuple[str, str],
                                                            list[str]]]:
    """Babel extractor: a world file's ``title``, context ``world``, into the ``messages``
    catalog beside the simulator's other messages (babel.cfg names it for the shipped
    worlds and the worlds beside each exercise).  An exercise's own ``exercise.yaml`` is
    not a world and yields nothing."""
    path = Path(getattr(fileobj, "name", "world.yaml"))
    if path.name == "exercise.yaml":
        return
    doc = load_document(path, fileobj.read().decode("utf-8"))
    title = doc.data.get("title") if isinstance(doc.data, dict) else None
    if isinstance(title, str) and title.strip():
        yield doc.line("title") or 1, "pgettext", (TITLE_CONTEXT, title), ["world title"]
