"""A grading's test lines while it runs: one line per test, and on a terminal that allows
it the test that runs now, in place, with the seconds it has taken.

Where a terminal cannot redraw a line (a pipe, a CI log, ``TERM=dumb``, ``NO_COLOR``),
each test is one plain line printed when it ends, and nothing else: a log reads the same
as the summary. The lines printed here are not printed again by
:func:`autograder.render.terminal.to_terminal` (its ``shown``).
"""

from __future__ import annotations

import os
import shutil
import time
from collections.abc import Callable, Sequence
from typing import TextIO

from autograder.core.results import TestResult
from autograder.i18n import _
from autograder.render.terminal import for_terminal, line_key, test_line

_CLEAR = "\r\x1b[2K"  # back to the line's start, and erase it


def terminal_style(stream: TextIO) -> tuple[bool, bool]:
    """``(color, in_place)`` for ``stream``: both only on a terminal that is not ``dumb``
    and without ``NO_COLOR`` (https://no-color.org)."""
    try:
        tty = stream.isatty()
    except (AttributeError, ValueError):
        tty = False
    able = tty and os.environ.get("TERM", "dumb") != "dumb" and not os.environ.get("NO_COLOR")
    return able, able


class LiveLines:
    """Prints each test's line as it ends; with ``in_place``, also the running test's."""

    def __init__(self, write: Callable[[str], None], color: bool = False,
                 in_place: bool = False, clock: Callable[[], float] = time.monotonic,
                 width: Callable[[], int] = lambda: shutil.get_terminal_size().columns) -> None:
        self._write = write
        self.color = color
        self.in_place = in_place
        self._clock = clock
        self._width = width
        self.shown: set[str] = set()  # line_key of every line printed
        self._since: dict[str, float] = {}  # each running test, since when
        self._drawn = ""  # what the running line shows now ("" if none)

    def running(self, nodeid: str | None, label: str = "") -> None:
        """The test that runs now (None: none); redrawn in place when its text changes."""
        self.running_now([(nodeid, label)] if nodeid is not None else [])

    def running_now(self, tests: Sequence[tuple[str, str]]) -> None:
        """The tests that run now, as ``(node id, label)``, one per test module running at
        once: all are named, so the one that ends next is always on the line (each gets
        an equal share of the width)."""
        if not self.in_place:
            return
        now = self._clock()
        self._since = {nodeid: self._since.get(nodeid, now) for nodeid, _label in tests}
        if not tests:
            self._draw("")
            return
        width = max(self._width() - 1, 10)
        share = max((width - 2) // len(tests) - 3, 12)
        parts = [f"{_took(now - self._since[nodeid]):>5}  {label}" for nodeid, label in tests]
        if len(parts) == 1:
            self._draw(for_terminal(f" … {parts[0]}"))
        else:
            self._draw(" … " + "  ·  ".join(_clip(for_terminal(part), share) for part in parts))

    def done(self, test: TestResult) -> None:
        """A test ended: its line, for good (replacing the running line)."""
        self._draw("")
        self._since.pop(line_key(test), None)
        self._write(test_line(test, self.color) + "\n")
        self.shown.add(line_key(test))

    def close(self) -> None:
        """Erase the running line, if any, before the summary."""
        self._draw("")

    def _draw(self, text: str) -> None:
        if not self.in_place:
            return
        width = max(self._width() - 1, 10)
        text = text if len(text) <= width else text[:width - 1] + "…"
        if text != self._drawn:
            self._write(_CLEAR + text)
            self._drawn = text


def _clip(text: str, width: int) -> str:
    return text if len(text) <= width else text[:width - 1] + "…"


def _took(seconds: float) -> str:
    return _("{seconds} s").format(seconds=int(seconds))
