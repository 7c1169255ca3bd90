"""The terminal summary: a line per test with a mark, points and label; then each failure
once (message, the program's last lines, hint); then the score and what it proves.

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
from collections.abc import Collection, Iterable
from pathlib import Path

from babel.numbers import format_percent

from autograder.core.results import (
    Containment,
    ProcessBounds,
    RunResult,
    TestResult,
    as_decimal,
    number,
)
from autograder.i18n import _, get_language, is_rtl, ngettext
from autograder.i18n.text import CODE_SPAN, LRI, PDI, ltr_runs
from autograder.render.verdict import core_label, core_lines

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
    right-to-left language, a line holding right-to-left text has each piece of code (a
    `code span`, or Latin words joined by operators, brackets or commas) in Unicode
    isolates, so a terminal that lays out bidi text keeps it in its written order; a line
    whose first strong character is left to right starts with U+200F RIGHT-TO-LEFT MARK.
    Lines wholly in Latin script (a program's output, a path) are left as they are.
    Idempotent."""
    if not is_rtl(lang or get_language()):
        return text
    lines = text.split("\n")
    for i, line in enumerate(lines):
        if not any(unicodedata.bidirectional(c) in ("R", "AL") for c in line):
            continue
        if LRI not in line:
            line = _isolate_code(line)
        lines[i] = RLM + line if _first_strong(line) == "L" else line
    return "\n".join(lines)


_CODE_MARKS = re.compile(r"[=<>()\[\]{},*+]| [-/%] ")


def _isolate_code(line: str) -> str:
    """``line`` with its code spans, and its runs of Latin words joined by more than
    spaces, between LRI and PDI (a single word or words joined by spaces need none)."""
    out = []
    for i, piece in enumerate(CODE_SPAN.split(line)):
        if i % 2:
            out.append(f"{LRI}`{piece}`{PDI}")
            continue
        at = 0
        for start, end in ltr_runs(piece):
            run = piece[start:end]
            if _CODE_MARKS.search(run) and re.match(r"[\w(\[{'\"+-]", run) \
                    and re.search(r"[A-Za-z_]", run):
                out += [piece[at:start], LRI, piece[start:end], PDI]
                at = end
        out.append(piece[at:])
    return "".join(out)


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
                 "run: `autograder quiz serve`")
    elif html is not None:
        text = _("Most terminals cannot lay out right-to-left text. The laid-out report is "
                 "in {path}: open it in a browser.").format(path=html)
    else:
        text = _("Most terminals cannot lay out right-to-left text. For a laid-out report, "
                 "run the command again with `--html report.html` and open that file in a "
                 "browser.")
    return for_terminal(text, lang)


_MARKS = {"passed": ("✔", "green"), "failed": ("✘", "red"), "error": ("!", "yellow"),
          "skipped": ("-", "yellow")}
_INDENT = "    "


def _style(text: str, color: str | None, enabled: bool, bold: bool = False) -> str:
    if not enabled:
        return text
    import click

    return click.style(text, fg=color, bold=bold)


def heading(exercise: str, title: str, color: bool = False) -> str:
    """The first line of a grading's output: the exercise and its title."""
    return for_terminal(_style(f"{exercise} — {title}", None, color, bold=True))


def test_line(test: TestResult, color: bool = False) -> str:
    """A test in one line: its mark, its points and its label (what went wrong comes once,
    in :func:`failure_blocks`)."""
    mark, tint = _MARKS[test.status]
    points = f"{number(test.score)}/{number(test.max_score)}"
    return for_terminal(f" {_style(mark, tint, color)} {points:>5}  {core_label(test)}")


def _indented(text: str) -> list[str]:
    return [(_INDENT + line).rstrip() for line in text.strip("\n").splitlines()]


def failure_blocks(tests: Iterable[TestResult], color: bool = False) -> list[str]:
    """What the failed (and skipped) tests say, each once: its label and its message (the
    program's last lines within it), as far as the test reveals them. Failures with the
    same hint stand together, in the order of the first, under that hint said once: one
    cause, several symptoms."""
    groups: dict[str, list[TestResult]] = {}
    for test in tests:
        message, hint = test.student_message.strip(), test.student_hint.strip()
        if test.status in ("failed", "skipped") and (message or hint):
            groups.setdefault(hint or f"\0{line_key(test)}", []).append(test)
    blocks = []
    for hint, group in groups.items():
        lines = []
        for test in group:
            mark, tint = _MARKS[test.status]
            lines += [_style(f"{mark} {test.label}", tint, color, bold=True),
                      *_indented(test.student_message)]
        if not hint.startswith("\0"):
            said = _("Hint: {hint}") if len(group) == 1 else ngettext(
                "Hint for the failure above: {hint}", "Hint for the {count} failures above: "
                "{hint}", len(group))
            lines += _indented(said.format(hint=hint, count=len(group)))
        blocks.append("\n".join(lines))
    return blocks


def score_lines(result: RunResult, color: bool = False) -> list[str]:
    """The score and what it proves: the verdict of a whole grading, or for a partial run
    (``check``) the public tests' score and what the grade adds, never a verdict."""
    score, max_score = number(result.score), number(result.max_score)
    percent = format_percent(as_decimal(result.fraction), locale=result.lang)
    if result.not_run is not None:
        line = _("Public tests: {score}/{max_score} ({percent}).").format(
            score=score, max_score=max_score, percent=percent)
        return [_style(line, None, color, bold=True), result.not_run.describe(),
                *_core_missed(result, color)]
    mark = format_percent(as_decimal(result.pass_mark), locale=result.lang)
    verdict = _("passed") if result.passed else _("not passed")
    line = _("Score: {score}/{max_score} ({percent}), {verdict} (pass mark {mark})").format(
        score=score, max_score=max_score, percent=percent, verdict=verdict, mark=mark)
    return [_style(line, "green" if result.passed else "red", color, bold=True),
            *_core_missed(result, color)]


def _core_missed(result: RunResult, color: bool) -> list[str]:
    """The core tests that kept the grading from passing, under a line saying so."""
    lines = core_lines(result)
    return [_style(lines[0], "red", color, bold=True), *lines[1:]] if lines else []


def _bound(kind: str | None, cgroup: str | None, controller: str, rlimit: str) -> str:
    if kind == "cgroup":
        return _("the {version} {controller} cgroup").format(version=cgroup,
                                                             controller=controller)
    if kind == "rlimit":
        return rlimit
    return _("nothing (no writable cgroup, no user of its own)")


def isolation_line(isolation: Containment) -> str:
    """How the student's program was contained, and what bounded it, in one line."""
    bounds = isolation.bounds or ProcessBounds()
    limits = _("processes bounded by {processes}, memory by {memory}").format(
        processes=_bound(bounds.processes, bounds.cgroup, "pids", "RLIMIT_NPROC"),
        memory=_bound(bounds.memory, bounds.cgroup, "memory", "RLIMIT_AS"))
    mode = isolation.mode
    if mode == "strict":
        return _("Isolation: strict (a user of its own, no network, the course hidden); "
                 "{limits}.").format(limits=limits)
    if mode == "user":
        return _("Isolation: by user, {reason}: a user of its own, the course closed to it, "
                 "but the network and the machine's processes in its reach; {limits}."
                 ).format(reason=_(isolation.reason), limits=limits)
    return "\n".join((
        _("Isolation: basic, {reason}; the program ran as the grader's user; {limits}."
          ).format(reason=_(isolation.reason), limits=limits),
        _("Not an official grade: a program run as the grader's user could read the hidden "
          "tests and change these results.")))


def containment_sentence(isolation: Containment) -> str:
    """For students: in one sentence, whether their program was contained and why that
    matters (the grade stands for what their node did, and only that). The technical
    line (:func:`isolation_line`) is for instructors: ``--verbose`` and the JSON."""
    if isolation.mode in ("strict", "user"):
        return _("Your program ran contained, as a user of its own, so this grade stands for "
                 "what your node did and nothing else.")
    return _("Your program was not contained (it ran as the grader's own user), so it could "
             "have changed this result: this grade is not official.")


def to_terminal(result: RunResult, color: bool = False, shown: Collection[str] = (),
                with_heading: bool = True, verbose: bool = False) -> str:
    """The whole summary: a line per test (but those in ``shown``, already printed as
    they ran: see :mod:`autograder.render.live`), each failure once with its message and
    hint, then the score and what it proves; how the program was contained in a sentence
    (``verbose``: the technical line)."""
    lines = [heading(result.id, result.title, color), ""] if with_heading else []
    lines += [test_line(t, color) for t in result.tests if line_key(t) not in shown]
    for block in failure_blocks(result.tests, color):
        lines += ["", block]
    lines += ["", *score_lines(result, color)]
    isolation = result.isolation
    if isolation is not None:
        lines.append(isolation_line(isolation) if verbose else containment_sentence(isolation))
    if result.grader_error:
        lines.append(_style(_("The autograder failed, tell your instructor."), "yellow", color,
                            bold=True))
        if result.grader_details:
            lines.append(result.grader_details.strip()[-2000:])
    return for_terminal("\n".join(lines), result.lang)


def line_key(test: TestResult) -> str:
    """What tells a test from the others in a run (its node id when the run knows it)."""
    return test.nodeid or test.name
