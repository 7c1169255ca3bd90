"""Rays from one point against segments and circles, all beams at once, in NumPy.

The lidar's geometry core.  Per geometry change, :func:`prepare` turns the shapes into one
matrix; per scan, one small product with the pose gives every shape's coefficients, and
one product with the beam directions gives, for every shape and beam, the inverse of the
distance along the beam.  What is left is a few element-wise passes over a (shapes x
beams) array and a reduction along its long axis.

Why the inverse distance: for a segment A->B (edge E) seen from P, with C = (A-P) x E,
a beam d meets the segment's line at t = C / (d x E), i.e. at 1/t = (d x E) / C, which
is linear in d.  So is u = (2 (A-P) x d - d x E) / C, and the beam hits the segment
itself (0 <= s <= 1 along it) exactly when |u| <= 1/t.  For a circle (centre Q, radius r)
with b = d.(P-Q) and c = |P-Q|^2 - r^2, the first hit ahead is at 1/t = sqrt(beta^2 -
1/c) - beta with beta = b / c, from outside (c > 0) and from inside (c < 0) alike; no
hit gives NaN or a negative value.  The nearest hit is then the largest 1/t, and "no hit
at all" is 0, so no infinities travel through the arrays.

Boxes and thick walls are closed convex loops of edges; seen from outside one, only the
edges facing the point can be hit first, so the others are left out of the scan (about
half of them).  Edges reach a relative 1e-10 past their ends, so no beam slips through a
loop's corner by rounding.

A pose exactly on a segment's line (C = 0) or on a circle's rim (c = 0) is degenerate:
that shape is left out of the scan (a slightly moved pose sees it at range ~0 or not at
all).  Otherwise ranges equal the plain beams x shapes computation up to rounding (about
1e-11 m), except for a beam exactly through a corner, which that computation may miss.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

# The pose enters through these ten numbers; every shape's coefficients are linear in them.
_C, _S, _CX, _CY, _SX, _SY, _ONE, _X, _Y, _R2 = range(10)
_SLACK = 1e-10


@dataclass(frozen=True)
class Targets:
    """Segments and circles prepared for casting (see :func:`prepare`)."""

    segments: int
    circles: int
    matrix: np.ndarray
    """(10, 3 * rows): per pose term, each row's two beam coefficients, then its divisor."""
    sides: np.ndarray | None = None
    """Per segment: +1 or -1 on a closed convex loop (counter-clockwise or not), else 0;
    None when no segment is on one."""
    groups: np.ndarray | None = None
    """Index of the first segment of each loop and of each segment on none."""

    @property
    def rows(self) -> int:
        """Segments take two rows (1/t and u), circles one (beta)."""
        return 2 * self.segments + self.circles


def _loops(segments: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed convex loops among consecutive segments (the edges of boxes and thick walls,
    as :class:`sim.physics.World` lists them): each segment's side and the groups."""
    sides = np.zeros(len(segments))
    groups: list[int] = []
    i = 0
    while i < len(segments):
        j = i  # follow the chain while each edge starts where the last one ended
        while (j + 1 < len(segments) and tuple(segments[j, 2:]) != tuple(segments[i, :2])
               and tuple(segments[j, 2:]) == tuple(segments[j + 1, :2])):
            j += 1
        loop = segments[i:j + 1]
        side = _convex_side(loop) if tuple(loop[-1, 2:]) == tuple(loop[0, :2]) else 0.0
        if side:
            sides[i:j + 1] = side
            groups.append(i)
        else:
            groups.extend(range(i, j + 1))
        i = j + 1
    return sides, np.array(groups, dtype=np.intp)


def _convex_side(loop: np.ndarray) -> float:
    """+1 or -1 if the closed ``loop`` bounds a convex polygon counter-clockwise or
    clockwise, else 0."""
    if len(loop) < 3:
        return 0.0
    ex, ey = loop[:, 2] - loop[:, 0], loop[:, 3] - loop[:, 1]
    turns = ex * np.roll(ey, -1) - ey * np.roll(ex, -1)
    turning = np.arctan2(turns, ex * np.roll(ex, -1) + ey * np.roll(ey, -1)).sum()
    if (turns > 0).all() and math.isclose(turning, 2 * math.pi):
        return 1.0
    if (turns < 0).all() and math.isclose(turning, -2 * math.pi):
        return -1.0
    return 0.0


def prepare(segments: np.ndarray, circles: np.ndarray) -> Targets:
    """The matrix of ``segments`` (N, 4) [x1 y1 x2 y2] and ``circles`` (M, 3) [x y r]."""
    k, m = len(segments), len(circles)
    rows = 2 * k + m
    ax, ay = segments[:, 0], segments[:, 1]
    ex, ey = segments[:, 2] - ax, segments[:, 3] - ay
    cx, cy, r = circles[:, 0], circles[:, 1], circles[:, 2]
    coef = np.zeros((10, rows, 2))
    div = np.zeros((10, rows))
    inv_t, u, beta = slice(0, k), slice(k, 2 * k), slice(2 * k, rows)
    # 1/t numerator, d x E, with d the beam rotated by the heading.
    coef[_C, inv_t, 0], coef[_S, inv_t, 0] = ey, -ex
    coef[_C, inv_t, 1], coef[_S, inv_t, 1] = -ex, -ey
    # u numerator, 2 (A-P) x d - d x E.
    coef[_S, u, 0], coef[_C, u, 0] = 2 * ax + ex, -2 * ay - ey
    coef[_SX, u, 0], coef[_CY, u, 0] = -2.0, 2.0
    coef[_C, u, 1], coef[_S, u, 1] = 2 * ax + ex, 2 * ay + ey
    coef[_CX, u, 1], coef[_SY, u, 1] = -2.0, -2.0
    # beta numerator, d . (P-Q).
    coef[_C, beta, 0], coef[_S, beta, 0], coef[_CX, beta, 0], coef[_SY, beta, 0] = -cx, -cy, 1, 1
    coef[_S, beta, 1], coef[_C, beta, 1], coef[_SX, beta, 1], coef[_CY, beta, 1] = cx, -cy, -1, 1
    # Every edge reaches a relative 1e-10 past its ends, so a beam through the corner
    # of a loop meets the edge facing it, whatever the rounding (see cast's culling).
    coef[:, u, :] /= 1.0 + _SLACK
    # Divisors: C = (A-P) x E for both segment rows, c = |P-Q|^2 - r^2 for circles.
    for rows_of in (inv_t, u):
        div[_ONE, rows_of], div[_X, rows_of], div[_Y, rows_of] = ax * ey - ay * ex, -ey, ex
    div[_ONE, beta], div[_X, beta], div[_Y, beta] = cx * cx + cy * cy - r * r, -2 * cx, -2 * cy
    div[_R2, beta] = 1.0
    matrix = np.concatenate([coef.reshape(10, 2 * rows), div], axis=1)
    matrix.flags.writeable = False
    sides, groups = _loops(segments)
    if not sides.any():
        return Targets(k, m, matrix)
    return Targets(k, m, matrix, sides, groups)


_cache: dict[tuple[int, int], tuple[weakref.ref, weakref.ref, Targets]] = {}
CACHED_AT_MOST = 32


def cached() -> int:
    """How many prepared geometries :func:`prepared` keeps now (at most CACHED_AT_MOST)."""
    return len(_cache)


def prepared(segments: np.ndarray, circles: np.ndarray) -> Targets:
    """:func:`prepare`, done once for read-only arrays (as :attr:`World.geometry` gives)."""
    if segments.flags.writeable or circles.flags.writeable:
        return prepare(segments, circles)  # the caller may change them: nothing to reuse
    key = id(segments), id(circles)
    hit = _cache.get(key)
    if hit is not None and hit[0]() is segments and hit[1]() is circles:
        return hit[2]
    if len(_cache) >= CACHED_AT_MOST:  # forget geometry that is gone (the bridge's thread
        # may scan too)
        for old, (s, c, _t) in list(_cache.items()):
            if s() is None or c() is None:
                _cache.pop(old, None)
        if len(_cache) >= CACHED_AT_MOST:
            _cache.clear()
    targets = prepare(segments, circles)
    _cache[key] = (weakref.ref(segments), weakref.ref(circles), targets)
    return targets


def directions(angles: np.ndarray) -> np.ndarray:
    """(2, beams) read-only unit vectors of beam angles in the sensor frame."""
    out = np.stack([np.cos(angles), np.sin(angles)])
    out.flags.writeable = False
    return out


def _inverse(distance: float) -> float:
    return 1.0 / distance if distance > 0 else math.inf


def cast(x: float, y: float, theta: float, targets: Targets, beams: np.ndarray,
         range_min: float, range_max: float) -> np.ndarray:
    """Ranges (float64) from (x, y) with heading ``theta`` along ``beams`` (from
    :func:`directions`): +inf for nothing within ``range_max``, -inf under ``range_min``."""
    c, s = math.cos(theta), math.sin(theta)
    pose = np.array((c, s, c * x, c * y, s * x, s * y, 1.0, x, y, x * x + y * y))
    rows, k = targets.rows, targets.segments
    terms = pose @ targets.matrix
    coef, divisor = terms[:2 * rows].reshape(rows, 2), terms[2 * rows:]
    if targets.sides is not None:
        # Seen from outside a convex loop, a beam meets an edge facing it first: the
        # others can be left out, unless the point is inside a loop (all its edges face
        # away).  The divisor of a segment's rows, C, is what tells which side it is on.
        facing = targets.sides * divisor[:k] <= 0
        if np.logical_or.reduceat(facing, targets.groups).all():
            kept = np.concatenate((facing, facing, np.ones(targets.circles, dtype=bool)))
            coef, divisor = coef[kept], divisor[kept]
            k = int(np.count_nonzero(facing))
            rows = len(divisor)
    scale = np.divide(1.0, divisor, out=np.zeros(rows), where=divisor != 0)
    coef *= scale[:, None]
    per_beam = coef @ beams  # (rows, beams): 1/t and u of segments, beta of circles
    inverse = np.empty((k + targets.circles, beams.shape[1]))
    inv_t, u, beta = per_beam[:k], per_beam[k:2 * k], per_beam[2 * k:]
    with np.errstate(invalid="ignore", divide="ignore"):
        np.abs(u, out=u)
        np.subtract(inv_t, u, out=u)
        np.copysign(inv_t, u, out=inverse[:k])  # negative unless the beam hits
        ahead = inverse[k:]
        np.multiply(beta, beta, out=ahead)
        ahead -= scale[2 * k:, None]
        np.sqrt(ahead, out=ahead)  # NaN where the beam misses the circle
        ahead -= beta
        nearest = np.fmax.reduce(inverse, axis=0, initial=0.0)  # 0: nothing hit
        beyond = nearest < _inverse(range_max)
        too_close = nearest > _inverse(range_min)
        ranges = np.divide(1.0, nearest, out=nearest)
    ranges[beyond] = np.inf
    ranges[too_close] = -np.inf
    return ranges
