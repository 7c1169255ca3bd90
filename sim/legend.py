"""The legend and scale bar under a picture of the world (:mod:`sim.svg`): what each mark
means, in the active language, and how long a metre is.

Drawn in a band below the arena, in the picture's own units (metres, y down), so the
drawing above is untouched. Items flow in rows as wide as the picture: from the left, or
from the right in a right-to-left language, each a swatch drawn as the picture draws the
thing and its label. No class of the picture's own is reused (``path``, ``collision``...):
scripts and tests that look for those find the run, never the legend.
"""

from __future__ import annotations

from collections.abc import Callable

from content.i18n import _, get_language

FONT = 0.13  # m, unzoomed: 13 px at the picture's 100 px per metre
ROW = 0.3  # m between rows
SWATCH = 0.3  # m
GAP = 0.06  # m between a swatch and its label
SPACE = 0.22  # m between items
_CHAR = 0.072  # m: a label's width per character, a generous estimate for sans-serif
RTL = ("ur", "ar", "fa", "he")

Draw = Callable[[float, float], str]  # (left x, y of the row's middle) -> markup
Item = tuple[str, float, Draw]  # label, swatch width, swatch


def legend_height(width: float, goal: bool, runs: int, replay: bool) -> float:
    """The band's height for a picture ``width`` metres wide."""
    k = _zoom(width)
    return (len(_rows(_items(goal, runs, replay), width / k, k)) * ROW + 0.1) * k


def legend_svg(top: float, left: float, width: float, goal: bool, runs: int,
               replay: bool) -> str:
    """The legend's markup: rows from ``top``, within [``left``, ``left + width``]."""
    rtl = get_language() in RTL
    k = _zoom(width)
    room = width / k  # the legend is laid out unzoomed, then zoomed as a whole
    parts = [f'<g class="legend" transform="translate({_num(left)} {_num(top)}) '
             f'scale({_num(k)})" font-family="sans-serif" font-size="{_num(FONT)}" '
             'fill="#333">']
    for r, row in enumerate(_rows(_items(goal, runs, replay), room, k)):
        middle = ROW * r + ROW / 2 + 0.05
        x = room if rtl else 0.0
        for label, swatch, draw in row:
            if rtl:
                parts += [draw(x - swatch, middle),
                          _text(label, x - swatch - GAP, middle, "end")]
                x -= _width(label, swatch) + SPACE
            else:
                parts += [draw(x, middle), _text(label, x + swatch + GAP, middle, "start")]
                x += _width(label, swatch) + SPACE
    parts.append("</g>")
    return "".join(parts)


def _zoom(width: float) -> float:
    """How much larger than its own units the legend is drawn: a report shows every world
    at one width, so a wider world's legend grows with it and its text keeps its size."""
    return max(1.0, width / 4.2)


def scale_metres(width: float) -> float:
    """The scale bar's length: the longest of 2, 1 and 0.5 m within a third of the width."""
    return next((m for m in (2.0, 1.0) if m <= width / 3), 0.5)


def _items(goal: bool, runs: int, replay: bool) -> list[Item]:
    items: list[Item] = [(_("start"), SWATCH, _start)]
    if goal:
        items.append((_("goal"), SWATCH, _goal))
    items.append((_("path"), SWATCH, _path))
    if runs > 1:
        items.append((_("other runs"), SWATCH, _other))
    if replay:
        items.append((_("robot"), SWATCH, _robot))
    return [*items, (_("collision"), SWATCH, _cross)]


def _rows(items: list[Item], width: float, k: float) -> list[list[Item]]:
    """The items in rows no wider than ``width`` (unzoomed); the scale bar, true to the
    picture's metres once zoomed by ``k``, ends the last one."""
    metres = scale_metres(width * k)
    items = [*items,
             (_("{metres} m").format(metres=_num(metres)), metres / k, _scale(metres, k))]
    rows: list[list[Item]] = [[]]
    used = 0.0
    for item in items:
        size = _width(item[0], item[1])
        if rows[-1] and used + size > width:
            rows.append([])
            used = 0.0
        rows[-1].append(item)
        used += size + SPACE
    return rows


def _width(label: str, swatch: float) -> float:
    return swatch + GAP + len(label) * _CHAR


def _text(label: str, x: float, y: float, anchor: str) -> str:
    from html import escape

    return (f'<text x="{_num(x)}" y="{_num(y + FONT * 0.35)}" text-anchor="{anchor}">'
            f"{escape(label)}</text>")


def _num(v: float) -> str:
    return f"{v:.3f}".rstrip("0").rstrip(".")


def _start(x: float, y: float) -> str:
    r = SWATCH * 0.4
    return (f'<circle cx="{_num(x + SWATCH / 2)}" cy="{_num(y)}" r="{_num(r)}" fill="none" '
            f'stroke="#43a047" stroke-width="0.02"/><line x1="{_num(x + SWATCH / 2)}" '
            f'y1="{_num(y)}" x2="{_num(x + SWATCH / 2 + r)}" y2="{_num(y)}" stroke="#43a047" '
            'stroke-width="0.02"/>')


def _goal(x: float, y: float) -> str:
    return (f'<circle cx="{_num(x + SWATCH / 2)}" cy="{_num(y)}" r="{_num(SWATCH * 0.4)}" '
            'fill="#c8f7c5" stroke="#2e7d32" stroke-width="0.02"/>')


def _line(x: float, y: float, opacity: str) -> str:
    return (f'<line x1="{_num(x)}" y1="{_num(y)}" x2="{_num(x + SWATCH)}" y2="{_num(y)}" '
            f'stroke="#1565c0" stroke-width="0.03"{opacity}/>')


def _path(x: float, y: float) -> str:
    return _line(x, y, "")


def _other(x: float, y: float) -> str:
    return _line(x, y, ' stroke-opacity="0.3"')  # as the replay shows the runs not chosen


def _robot(x: float, y: float) -> str:
    return (f'<circle cx="{_num(x + SWATCH / 2)}" cy="{_num(y)}" r="{_num(SWATCH * 0.4)}" '
            'fill="#ffb74d" fill-opacity="0.55" stroke="#e65100" stroke-width="0.02"/>')


def _cross(x: float, y: float) -> str:
    d, cx = 0.06, x + SWATCH / 2
    return (f'<path d="M{_num(cx - d)},{_num(y - d)} L{_num(cx + d)},{_num(y + d)} '
            f'M{_num(cx - d)},{_num(y + d)} L{_num(cx + d)},{_num(y - d)}" stroke="#d32f2f" '
            'stroke-width="0.03"/>')


def _scale(metres: float, k: float) -> Draw:
    """A bar ``metres`` long in the picture (``metres / k`` in the zoomed legend), with
    end ticks."""

    def draw(x: float, y: float) -> str:
        t, x1 = 0.06, x + metres / k
        return (f'<path class="legend-scale" data-metres="{_num(metres)}" '
                f'd="M{_num(x)},{_num(y - t)} V{_num(y + t)} M{_num(x)},{_num(y)} '
                f'H{_num(x1)} M{_num(x1)},{_num(y - t)} V{_num(y + t)}" fill="none" '
                'stroke="#333" stroke-width="0.02"/>')

    return draw
