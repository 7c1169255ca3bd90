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

A pose exactly on a segment's line (C = 0) or on a circle's rim (c = 0) is degenerate:
that shape is left out of the scan (a slightly moved pose sees it at range ~0 or not at
all).  Results equal the plain beams x shapes computation up to rounding (~1e-12 m).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

# The pose enters through these ten numbers; every shape's coefficients are linear in them.
_C, _S, _CX, _CY, _SX, _SY, _ONE, _X, _Y, _R2 = range(10)


@dataclass(frozen=True)
class Targets:
    """Segments and circles prepared for casting (see :func:`prepare`)."""

    segments: int
    circles: int
    matrix: np.ndarray
    """(10, 3 * rows): per pose term, each row's two beam coefficients, then its divisor."""

    @property
    def rows(self) -> int:
        """Segments take two rows (1/t and u), circles one (beta)."""
        return 2 * self.segments + self.circles


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
    # Divisors: C = (A-P) x E for both segment rows, c = |P-Q|^2 - r^2 for circles.
    for rows_of in (inv_t, u):
        div[_ONE, rows_of], div[_X, rows_of], div[_Y, rows_of] = ax * ey - ay * ex, -ey, ex
    div[_ONE, beta], div[_X, beta], div[_Y, beta] = cx * cx + cy * cy - r * r, -2 * cx, -2 * cy
    div[_R2, beta] = 1.0
    matrix = np.concatenate([coef.reshape(10, 2 * rows), div], axis=1)
    matrix.flags.writeable = False
    return Targets(k, m, matrix)


_cache: dict[tuple[int, int], tuple[weakref.ref, weakref.ref, Targets]] = {}


def prepared(segments: np.ndarray, circles: np.ndarray) -> Targets:
    """:func:`prepare`, done once for read-only arrays (as :attr:`World.geometry` gives)."""
    if segments.flags.writeable or circles.flags.writeable:
        return prepare(segments, circles)  # the caller may change them: nothing to reuse
    key = id(segments), id(circles)
    hit = _cache.get(key)
    if hit is not None and hit[0]() is segments and hit[1]() is circles:
        return hit[2]
    if len(_cache) >= 32:
        for old in [k for k, (s, c, _t) in _cache.items() if s() is None or c() is None]:
            del _cache[old]
        if len(_cache) >= 32:
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
    divisor = terms[2 * rows:]
    scale = np.divide(1.0, divisor, out=np.zeros(rows), where=divisor != 0)
    coef = terms[:2 * rows].reshape(rows, 2)
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
