"""The test lines a grading prints while it runs (autograder.render.live): in place on a
terminal that allows it, plain lines everywhere else, each test's line once."""

from __future__ import annotations

import io
from fractions import Fraction

import pytest

from autograder.core.results import TestResult
from autograder.render.live import LiveLines, terminal_style

CLEAR = "\r\x1b[2K"


def passed(name: str, label: str) -> TestResult:
    return TestResult(name, label, Fraction(1), Fraction(1), "passed",
                      nodeid=f"t.py::{name}")


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_plain_lines_only_as_tests_end():
    """A pipe or a CI log gets each test's line when it ends, and nothing in between."""
    out: list[str] = []
    live = LiveLines(out.append)
    live.running("t.py::test_a", "The node starts")
    live.done(passed("test_a", "The node starts"))
    live.running("t.py::test_b", "It turns")
    live.close()
    assert out == [" ✔   1/1  The node starts\n"]
    assert live.shown == {"t.py::test_a"}


def test_in_place_the_running_test_is_redrawn_then_replaced_by_its_line():
    out: list[str] = []
    clock = Clock()
    live = LiveLines(out.append, in_place=True, clock=clock, width=lambda: 80)
    live.running("t.py::test_a", "The node starts")
    live.running("t.py::test_a", "The node starts")  # nothing changed: nothing written
    clock.now += 3.2
    live.running("t.py::test_a", "The node starts")
    live.done(passed("test_a", "The node starts"))
    live.close()  # nothing running: nothing to erase
    assert out == [CLEAR + " …   0 s  The node starts", CLEAR + " …   3 s  The node starts",
                   CLEAR, " ✔   1/1  The node starts\n"]


def test_in_place_a_long_label_is_cut_to_the_terminal_width():
    out: list[str] = []
    live = LiveLines(out.append, in_place=True, clock=Clock(), width=lambda: 30)
    live.running("t.py::test_a", "A label much longer than the terminal is wide")
    assert out == [CLEAR + " …   0 s  A label much longe…"]
    assert len(out[0]) - len(CLEAR) == 29
    live.close()
    assert out[-1] == CLEAR


class Stream(io.StringIO):
    def __init__(self, tty: bool) -> None:
        super().__init__()
        self.tty = tty

    def isatty(self) -> bool:
        return self.tty


@pytest.mark.parametrize(("tty", "env", "style"), [
    (True, {"TERM": "xterm-256color"}, (True, True)),
    (False, {"TERM": "xterm-256color"}, (False, False)),
    (True, {"TERM": "dumb"}, (False, False)),
    (True, {}, (False, False)),
    (True, {"TERM": "xterm", "NO_COLOR": "1"}, (False, False)),
], ids=["terminal", "pipe", "dumb", "no-term", "no-color"])
def test_color_and_redrawing_only_on_a_terminal_that_allows_them(
        monkeypatch: pytest.MonkeyPatch, tty, env, style):
    monkeypatch.delenv("TERM", raising=False)
    monkeypatch.delenv("NO_COLOR", raising=False)
    for key, value in env.items():
        monkeypatch.setenv(key, value)
    assert terminal_style(Stream(tty)) == style


def test_modules_at_once_are_all_on_the_line_so_the_one_that_ends_was_named():
    """Two test modules run at once: the line names both tests, each with its own time,
    and whichever ends next (here the second) was on it (issue 31)."""
    out: list[str] = []
    clock = Clock()
    live = LiveLines(out.append, in_place=True, clock=clock, width=lambda: 80)
    live.running_now([("a.py::test_a", "The node starts")])
    clock.now += 2.0
    live.running_now([("a.py::test_a", "The node starts"), ("b.py::test_b", "It turns")])
    assert out[-1] == CLEAR + " …   2 s  The node starts  ·    0 s  It turns"
    live.done(TestResult("test_b", "It turns", Fraction(1), Fraction(1), "passed",
                         nodeid="b.py::test_b"))
    clock.now += 1.0
    live.running_now([("a.py::test_a", "The node starts")])  # its time kept, not restarted
    assert out[-2:] == [" ✔   1/1  It turns\n", CLEAR + " …   3 s  The node starts"]


def test_several_running_tests_share_the_width():
    out: list[str] = []
    live = LiveLines(out.append, in_place=True, clock=Clock(), width=lambda: 40)
    live.running_now([("a.py::a", "A label much longer than its share"),
                      ("b.py::b", "Another long label here")])
    line = out[-1][len(CLEAR):]
    assert len(line) <= 39 and line.count("…") == 3  # the mark, and both labels cut
    assert "A label" in line and "Another" in line
