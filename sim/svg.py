"""A picture of a run (or of several in one world): the arena, walls, obstacles, the path,
start, end, goal, collisions.

A pure function of data returning a self-contained inline SVG (no scripts, no external
references), so reports can embed it as is.  Its tooltips (the world's title, what each
collision hit) are in the active language.  World y points up; SVG y points down, so
everything is drawn inside a group that flips the y axis.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from html import escape

from content.i18n import _
from sim.legend import legend_height, legend_svg
from sim.physics import box_corners, describe
from sim.recorder import Recording
from sim.worldfile import ROBOT_RADIUS, Goal, WorldSpec, title_of

_PX_PER_M = 100.0


def _num(v: float) -> str:
    return f"{v:.3f}".rstrip("0").rstrip(".")


def _points(points: list[tuple[float, float]]) -> str:
    return " ".join(f"{_num(x)},{_num(y)}" for x, y in points)


def trajectory_svg(spec: WorldSpec, recording: Recording, goal: Goal | None = None) -> str:
    """The SVG text for ``recording`` in ``spec``'s arena (``goal`` overrides the spec's)."""
    return scene_svg(spec, [recording], goal)


def scene_svg(spec: WorldSpec, recordings: Sequence[Recording], goal: Goal | None = None,
              overlay: str = "") -> str:
    """The SVG text for several runs in one arena: each run's path, end pose and
    collisions in a group ``<g class="run" data-run="i">``, collisions carrying their time
    (``data-t``); ``overlay`` is markup drawn on top, in world coordinates (a replay's
    moving parts). Below the arena, a legend and a scale bar (:mod:`sim.legend`)."""
    w, h = spec.size
    goal = goal or spec.goal
    margin = 0.1
    band = legend_height(w + 2 * margin - 0.1, goal is not None, len(recordings), bool(overlay))
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" class="sim-trajectory" '
        f'width="{_num((w + 2 * margin) * _PX_PER_M)}" '
        f'height="{_num((h + 2 * margin + band) * _PX_PER_M)}" '
        f'viewBox="{_num(-margin)} {_num(-margin)} {_num(w + 2 * margin)} '
        f'{_num(h + 2 * margin + band)}" role="img">',
        f"<title>{escape(title_of(spec))}</title>",
        f'<g transform="translate(0 {_num(h)}) scale(1 -1)">',
        f'<rect x="0" y="0" width="{_num(w)}" height="{_num(h)}" fill="#fafafa"/>',
    ]
    if goal is not None:
        parts.append(f'<circle class="goal" cx="{_num(goal.x)}" cy="{_num(goal.y)}" '
                     f'r="{_num(goal.tolerance)}" fill="#c8f7c5" stroke="#2e7d32" '
                     f'stroke-width="0.02"/>')
    for (x1, y1), (x2, y2) in spec.all_walls():
        parts.append(f'<line class="wall" x1="{_num(x1)}" y1="{_num(y1)}" x2="{_num(x2)}" '
                     f'y2="{_num(y2)}" stroke="#333" stroke-width="{_num(spec.wall_thickness)}"'
                     f' stroke-linecap="square"/>')
    for box in spec.obstacles.boxes:
        parts.append(f'<polygon class="box" points="{_points(box_corners(box))}" '
                     f'fill="#9e9e9e"/>')
    for circle in spec.obstacles.circles:
        parts.append(f'<circle class="obstacle" cx="{_num(circle.center[0])}" '
                     f'cy="{_num(circle.center[1])}" r="{_num(circle.radius)}" fill="#9e9e9e"/>')
    start = spec.start
    parts.append(_robot("start", start.x, start.y, start.theta, "#43a047"))
    for i, recording in enumerate(recordings):
        parts += _run(spec, recording, i if len(recordings) > 1 else None)
    if overlay:
        parts.append(overlay)
    parts.append("</g>")
    parts.append(legend_svg(h + margin, -margin + 0.05, w + 2 * margin - 0.1,
                            goal is not None, len(recordings), bool(overlay)))
    parts.append("</svg>")
    return "\n".join(parts)


def _run(spec: WorldSpec, recording: Recording, index: int | None) -> list[str]:
    """One run's path, end pose and collisions (in a group of its own when ``index``)."""
    samples, collisions = recording.snapshot()
    parts = [] if index is None else [f'<g class="run" data-run="{index}">']
    if samples:
        path = [(spec.start.x, spec.start.y)] + [(s.x, s.y) for s in samples]
        parts.append(f'<polyline class="path" points="{_points(path)}" fill="none" '
                     f'stroke="#1565c0" stroke-width="0.02" stroke-linejoin="round"/>')
        end = samples[-1]
        parts.append(_robot("end", end.x, end.y, end.theta, "#1565c0"))
    for c in collisions:
        d = 0.06
        tooltip = _("{seconds:.2f} s: {what}").format(seconds=c.t, what=describe(c.what))
        parts.append(f'<path class="collision" data-t="{_num(c.t)}" '
                     f'd="M{_num(c.x - d)},{_num(c.y - d)} '
                     f'L{_num(c.x + d)},{_num(c.y + d)} M{_num(c.x - d)},{_num(c.y + d)} '
                     f'L{_num(c.x + d)},{_num(c.y - d)}" stroke="#d32f2f" stroke-width="0.03">'
                     f"<title>{escape(tooltip)}</title></path>")
    if index is not None:
        parts.append("</g>")
    return parts


def _robot(name: str, x: float, y: float, theta: float, colour: str) -> str:
    """The robot's footprint with a line showing its heading."""
    hx, hy = x + ROBOT_RADIUS * math.cos(theta), y + ROBOT_RADIUS * math.sin(theta)
    return (f'<g class="{name}"><circle cx="{_num(x)}" cy="{_num(y)}" r="{_num(ROBOT_RADIUS)}"'
            f' fill="none" stroke="{colour}" stroke-width="0.02"/>'
            f'<line x1="{_num(x)}" y1="{_num(y)}" x2="{_num(hx)}" y2="{_num(hy)}" '
            f'stroke="{colour}" stroke-width="0.02"/></g>')
