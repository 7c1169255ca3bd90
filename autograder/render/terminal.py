"""The terminal summary: a line per test with a mark, points and a one-line reason.

Also what every command printing a right-to-left language needs (:func:`for_terminal`,
:func:`rtl_notice`): a terminal that lays out bidi text takes each line's direction from
its first strong character, so an Urdu line that starts with a Latin word (or a mark, then
an English identifier) is laid out left to right and scrambled; most terminals lay out
nothing and show the characters in memory order.  Each such line starts with a
RIGHT-TO-LEFT MARK, and the command says once where the text reads laid out.
"""

from __future__ import annotations

import re
import unicodedata
from pathlib import Path

from babel.numbers import format_percent

from autograder.core.results import RunResult, TestResult, as_decimal, number
from autograder.i18n import _, get_language, is_rtl

RLM = "\u200f"
_ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


def _first_strong(line: str) -> str | None:
    """``"L"`` or ``"R"``: the bidi class of the line's first strong character, if any."""
    for char in _ANSI.sub("", line):
        kind = unicodedata.bidirectional(char)
        if kind == "L":
            return "L"
        if kind in ("R", "AL"):
            return "R"
    return None


def for_terminal(text: str, lang: str | None = None) -> str:
    """``text`` for a terminal in ``lang`` (default: the active language).  In a
    right-to-left language, a line holding right-to-left text whose first strong character
    is left to right starts with U+200F RIGHT-TO-LEFT MARK; lines wholly in Latin script
    (a program's output, a path) are left as they are.  Idempotent."""
    if not is_rtl(lang or get_language()):
        return text
    lines = text.split("\n")
    for i, line in enumerate(lines):
        if _first_strong(line) == "L" and any(
                unicodedata.bidirectional(c) in ("R", "AL") for c in line):
            lines[i] = RLM + line
    return "\n".join(lines)


def rtl_notice(lang: str | None = None, html: Path | None = None,
               serve: bool = False) -> str | None:
    """What a command printing a right-to-left language says once, first: that terminals
    cannot lay it out, and where it reads laid out (``html``: the report it writes;
    ``serve``: the quiz server; else: how to ask for a report).  None in other languages."""
    lang = lang or get_language()
    if not is_rtl(lang):
        return None
    if serve:
        text = _("Most terminals cannot lay out right-to-left text. For the laid-out page "
                 "run: autograder quiz serve")
    elif html is not None:
        text = _("Most terminals cannot lay out right-to-left text. The laid-out report is "
                 "in {path}: open it in a browser.").format(path=html)
    else:
        text = _("Most terminals cannot lay out right-to-left text. For a laid-out report, "
                 "run the command again with --html report.html and open that file in a "
                 "browser.")
    return for_terminal(text, lang)

_MARKS = {"passed": ("✔", "green"), "failed": ("✘", "red"), "error": ("!", "yellow"),
          "skipped": ("-", "yellow")}


def _style(text: str, color: str | None, enabled: bool, bold: bool = False) -> str:
    if not enabled:
        return text
    import click

    return click.style(text, fg=color, bold=bold)


def test_line(test: TestResult, color: bool = False, reveal: bool = True) -> str:
    mark, tint = _MARKS[test.status]
    points = f"{number(test.score)}/{number(test.max_score)}"
    line = f" {_style(mark, tint, color)} {points:>5}  {test.label}"
    if test.status != "passed" and reveal and test.message:
        first = test.message.strip().splitlines()[0]
        line += "\n" + " " * 10 + _style(first, None, color)
    return for_terminal(line)


def _bound(kind: str | None, cgroup: str | None, controller: str, rlimit: str) -> str:
    if kind == "cgroup":
        return _("the {version} {controller} cgroup").format(version=cgroup,
                                                             controller=controller)
    if kind == "rlimit":
        return rlimit
    return _("nothing (no writable cgroup, no user of its own)")


def isolation_line(isolation: dict) -> str:
    """How the student's program was contained, and what bounded it, in one line."""
    bounds = isolation.get("bounds") or {}
    limits = _("processes bounded by {processes}, memory by {memory}").format(
        processes=_bound(bounds.get("processes"), bounds.get("cgroup"), "pids", "RLIMIT_NPROC"),
        memory=_bound(bounds.get("memory"), bounds.get("cgroup"), "memory", "RLIMIT_AS"))
    if isolation.get("mode") == "strict":
        return _("Isolation: strict (a user of its own, no network, the course hidden); "
                 "{limits}.").format(limits=limits)
    return _("Isolation: basic, {reason}; the program ran as the grader's user; "
             "{limits}.").format(reason=_(isolation.get("reason", "")), limits=limits)


def to_terminal(result: RunResult, color: bool = False, show_details: bool = True) -> str:
    """The whole summary. ``show_details`` adds every failure's full message and hint."""
    lines = [_style(f"{result.id} — {result.title}", None, color, bold=True), ""]
    for test in result.tests:
        reveal = test.visibility == "visible" or show_details
        lines.append(test_line(test, color, reveal))
    lines.append("")
    percent = format_percent(as_decimal(result.fraction), locale=result.lang)
    mark = format_percent(as_decimal(result.pass_mark), locale=result.lang)
    verdict = _("passed") if result.passed else _("not passed")
    lines.append(_style(_("Score: {score}/{max_score} ({percent}), {verdict} (pass mark {mark})")
                        .format(score=number(result.score), max_score=number(result.max_score),
                                percent=percent, verdict=verdict, mark=mark),
                        "green" if result.passed else "red", color, bold=True))
    isolation = result.data.get("isolation", {})
    if isolation:
        lines.append(isolation_line(isolation))
    if result.grader_error:
        lines.append(_style(_("The autograder failed, tell your instructor."), "yellow", color,
                            bold=True))
        if show_details and result.grader_details:
            lines.append(result.grader_details.strip()[-2000:])
    if show_details:
        failures = [t for t in result.tests if t.status == "failed" and
                    (t.visibility == "visible" or show_details)]
        for test in failures:
            lines += ["", _style(f"✘ {test.label}", "red", color, bold=True), test.message]
            if test.hint:
                lines.append(_("Hint: {hint}").format(hint=test.hint))
    return for_terminal("\n".join(lines), result.lang)
