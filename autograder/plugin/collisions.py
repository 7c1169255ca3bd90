"""Feedback on a collision: did the robot drive into something straight ahead?

The textbook's obstacle-avoidance nodes take ``ranges[len(ranges)//2]`` as "front". With
REP 103 scans (beam 0 straight ahead, angles counter-clockwise, as on TurtleBot3 and in
our world) that beam points backwards, and such a node drives into whatever is ahead. An
exercise's collision message calls :func:`front_beam_note` so that every exercise gives
the same advice when it sees that sign.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np

from autograder.i18n import _
from sim.physics import Contact
from sim.recorder import Sample

# Half-width of "ahead": the front sector the exercise READMEs teach a node to watch
# (their `front_sector`, ±30 degrees).  A node that watched it would have seen what the
# robot touched there, so a touch within it says the node watched another beam; a
# glancing touch of a wall beside the path is further off.
AHEAD = math.radians(30)

Geometry = tuple[np.ndarray, np.ndarray]
"""``World.geometry``: segments (N, 4) [x1 y1 x2 y2] and circles (M, 3) [x y r]."""


def touch_point(x: float, y: float, geometry: Geometry) -> tuple[float, float] | None:
    """The point of the world's shapes nearest to (x, y): where a disc centred there
    touches them.  None for a world with no shapes."""
    segments, circles = geometry
    best: tuple[float, float, float] | None = None  # (distance, x, y)
    if len(segments):
        ax, ay, bx, by = segments.T
        ex, ey = bx - ax, by - ay
        length2 = np.where(ex * ex + ey * ey > 0, ex * ex + ey * ey, 1.0)
        t = np.clip(((x - ax) * ex + (y - ay) * ey) / length2, 0.0, 1.0)
        qx, qy = ax + t * ex, ay + t * ey
        d = np.hypot(qx - x, qy - y)
        i = int(np.argmin(d))
        best = (float(d[i]), float(qx[i]), float(qy[i]))
    if len(circles):
        cx, cy, r = circles.T
        away = np.hypot(x - cx, y - cy)
        d = away - r
        i = int(np.argmin(d))
        if best is None or d[i] < best[0]:
            scale = r[i] / away[i] if away[i] > 0 else 0.0
            best = (float(d[i]), float(cx[i] + (x - cx[i]) * scale),
                    float(cy[i] + (y - cy[i]) * scale))
    return None if best is None else (best[1], best[2])


def heading_at(samples: Sequence[Sample], t: float) -> float | None:
    """The robot's heading at sim time ``t``: the last sample at or before it (else the
    first one); None without samples."""
    before = [s for s in samples if s.t <= t + 1e-9]
    if before:
        return before[-1].theta
    return samples[0].theta if samples else None


def bearing(contact: Contact, samples: Sequence[Sample], geometry: Geometry) -> float | None:
    """Where the robot touched, in radians from straight ahead (counter-clockwise
    positive, within [-pi, pi]); None when it cannot be told."""
    theta = heading_at(samples, contact.t)
    point = touch_point(contact.x, contact.y, geometry)
    if theta is None or point is None:
        return None
    return math.remainder(math.atan2(point[1] - contact.y, point[0] - contact.x) - theta,
                          math.tau)


def front_beam_note(contacts: Iterable[Contact], samples: Sequence[Sample],
                    geometry: Geometry, *, since: float = -math.inf,
                    until: float = math.inf) -> str:
    """A note for the first contact straight ahead between ``since`` and ``until`` (while
    the student's node ran): which beam is "front" on this robot.  "" when there is none.
    """
    for contact in contacts:
        if not since <= contact.t <= until:
            continue
        angle = bearing(contact, samples, geometry)
        if angle is not None and abs(angle) <= AHEAD:
            return _("The robot drove into {what} straight ahead. On this robot beam 0 of "
                     "/scan is straight ahead (angles run counter-clockwise); check which "
                     "beam your node treats as \"front\" (`ranges[len(ranges)//2]` is "
                     "straight behind).").format(what=contact.hit_name)
    return ""


def with_front_beam_note(message: str, contacts: Iterable[Contact],
                         samples: Sequence[Sample], geometry: Geometry, *,
                         since: float = -math.inf, until: float = math.inf) -> str:
    """``message``, followed on a line of its own by :func:`front_beam_note` if it has one."""
    note = front_beam_note(contacts, samples, geometry, since=since, until=until)
    return f"{message}\n{note}" if note else message
