"""One results model for every grading run (an exercise or a quiz).

Scores are exact (``Fraction``), so 7 of 10 passes a 70% mark with no float error.
Renderers are pure functions of a :class:`RunResult`; see ``autograder.render``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from decimal import Decimal
from fractions import Fraction
from typing import Any, Literal

from autograder.core.untrusted import visible
from autograder.i18n import _, ngettext

Status = Literal["passed", "failed", "error", "skipped"]
Visibility = Literal["visible", "hidden", "after_published"]
Kind = Literal["exercise", "quiz"]
# What a student is shown of a test: its label and pass/fail only, or also the message.
Reveal = Literal["status", "message"]

DEFAULT_PASS_MARK = Fraction(7, 10)


def exact(value: float | int | str | Fraction) -> Fraction:
    """A score as an exact fraction; floats go through their shortest decimal text."""
    if isinstance(value, float):
        return Fraction(repr(value))
    return Fraction(value)


def as_decimal(value: Fraction, places: int = 6) -> Decimal:
    """A Fraction as a Decimal (for Babel's number formatting), rounded to ``places``."""
    return (Decimal(value.numerator) / Decimal(value.denominator)).quantize(
        Decimal(1).scaleb(-places))


def number(value: Fraction) -> int | float:
    """A Fraction as a JSON number: whole numbers stay ints."""
    return int(value) if value.denominator == 1 else round(float(value), 4)


@dataclasses.dataclass(frozen=True)
class TestResult:
    """The outcome of one test (or one quiz question)."""

    __test__ = False  # not a pytest test class, despite its name

    name: str
    label: str
    score: Fraction
    max_score: Fraction
    status: Status
    message: str = ""
    hint: str = ""
    visibility: Visibility = "visible"
    reveal: Reveal = "message"
    details: str = ""
    # A core test (exercise.yaml's ``core``): without it passed, the grading does not pass.
    core: bool = False
    # pytest's id of the test (``tests/public/test_x.py::test_y``); empty for a question.
    nodeid: str = ""
    # The charts the test drew (see ``autograder.plugin.credit``), for the HTML report.
    charts: tuple[Mapping[str, Any], ...] = ()
    # A quiz question's answer as the student gave it (None: not answered).
    answer: Any = None

    def __post_init__(self) -> None:
        # What a test says may quote a program's output: every format shows it harmless.
        _show_visible(self, "message", "hint", "details")

    @property
    def passed(self) -> bool:
        return self.status == "passed"

    @property
    def module(self) -> str:
        """The test module's file name, as the world's recordings are keyed
        (``tests/public/test_governor.py::test_clamps`` -> ``test_governor.py``)."""
        return self.nodeid.partition("::")[0].rpartition("/")[2]

    @property
    def student_message(self) -> str:
        """The message as a student may see it (hidden tests may reveal only pass/fail)."""
        return self.message if self.reveal == "message" else ""

    @property
    def student_hint(self) -> str:
        return self.hint if self.reveal == "message" else ""


@dataclasses.dataclass(frozen=True)
class NotRun:
    """What a partial run (``check``: the public tests) left for the grade: how many tests
    and how many points, each None when not known (a student's copy has no hidden tests)."""

    tests: int | None = None
    points: Fraction | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"tests": self.tests,
                "points": None if self.points is None else number(self.points)}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> NotRun:
        points = data.get("points")
        return cls(tests=data.get("tests"), points=None if points is None else exact(points))

    def describe(self) -> str:
        """What the grade runs beyond the partial run, as far as it is known, in the active
        language ("The grade also runs 7 hidden tests (12 points).")."""
        points = None
        if self.points is not None:
            # ngettext takes a whole count: a fractional number of points reads as plural.
            count = self.points.numerator if self.points.denominator == 1 else 2
            points = ngettext("{points} point", "{points} points", count).format(
                points=number(self.points))
        if self.tests is not None and points is not None:
            return ngettext("The grade also runs {count} hidden test ({points}).",
                            "The grade also runs {count} hidden tests ({points}).",
                            self.tests).format(count=self.tests, points=points)
        if points is not None:
            return _("The grade also runs hidden tests ({points}).").format(points=points)
        return _("The grade also runs hidden tests.")


def _show_visible(result: object, *fields: str) -> None:
    """Make a result's ``fields`` (text a program may have written) safe to show anywhere:
    a program's escape sequences and bidi controls as visible escapes
    (:func:`autograder.core.untrusted.visible`). Our own messages hold none of these; the
    right-to-left marks a terminal needs are added later, by the terminal renderer."""
    for name in fields:
        value = getattr(result, name)
        if isinstance(value, str):
            object.__setattr__(result, name, visible(value))


@dataclasses.dataclass(frozen=True)
class RunResult:
    """A whole grading run: what every renderer is a pure function of. The fields after
    ``not_run`` say how an exercise's grading ran; a quiz leaves them empty."""

    kind: Kind
    id: str
    title: str
    tests: tuple[TestResult, ...]
    pass_mark: Fraction = DEFAULT_PASS_MARK
    lang: str = "en"
    grader_error: str | None = None
    grader_details: str = ""
    log_tail: str = ""
    execution_time: float = 0.0
    # Every student program's output as the sandbox kept it (up to its output budget
    # each): for the HTML report and the log file beside the results, never in the JSON.
    log: str = ""
    # Set for a partial run (``check``): what the grade runs beyond it. A partial run
    # proves nothing about passing, so it never says passed.
    not_run: NotRun | None = None
    # -- in the JSON results (see to_dict) --
    # How the student's program was contained: ``Isolation.to_dict()`` with its ``bounds``
    # and ``student_uids``; None when nothing was started (a fault before the run).
    isolation: Mapping[str, Any] | None = None
    # How the world paced itself, per test module (``sim.bridge``).
    pacing: Mapping[str, Mapping[str, Any]] = dataclasses.field(default_factory=dict)
    # ``--record DIR``: each test module's rosbag2 bag folder.
    bags: Mapping[str, str] = dataclasses.field(default_factory=dict)
    # What the student should know that is no test's verdict (a recording that failed).
    warnings: tuple[str, ...] = ()
    # Where the wall seconds went (``autograder.plugin.timing``) and the memory.
    timing: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    memory: Mapping[str, float] = dataclasses.field(default_factory=dict)
    # The other users whose programs disturbed each grading done again before this one.
    disturbed: tuple[tuple[int, ...], ...] = ()
    # -- for the grader and the reports only --
    recordings: Mapping[str, Mapping[str, Any]] = dataclasses.field(default_factory=dict)
    domains: tuple[int, ...] = ()
    processes: tuple[Mapping[str, Any], ...] = ()
    student_uids: tuple[int, ...] | None = None
    strangers: tuple[int, ...] = ()  # other users' programs seen on the grading's domains
    startup_seconds: tuple[float, ...] = ()
    timed_out: bool = False
    silent: bool = False  # the student's programs ran and printed nothing at all
    refused: bool = False  # the file was refused before any test ran
    forged: bool = False  # the report was overwritten during the run
    pass_summary: str = ""  # a quiz's: what passing takes, in the student's language

    def __post_init__(self) -> None:
        _show_visible(self, "log", "log_tail", "grader_details")

    @property
    def domain(self) -> int | None:
        """The ROS domain of the grading (its first child's), None if none was taken."""
        return self.domains[0] if self.domains else None

    @property
    def student_uid(self) -> int | None:
        """The user the student's programs ran as (the first child's), None: the grader's."""
        return self.student_uids[0] if self.student_uids else None

    @property
    def complete(self) -> bool:
        """Every test of the exercise ran: the score is the grade."""
        return self.not_run is None

    @property
    def score(self) -> Fraction:
        return sum((t.score for t in self.tests), Fraction(0))

    @property
    def max_score(self) -> Fraction:
        return sum((t.max_score for t in self.tests), Fraction(0))

    @property
    def fraction(self) -> Fraction:
        return self.score / self.max_score if self.max_score else Fraction(0)

    @property
    def core_missed(self) -> tuple[TestResult, ...]:
        """The core tests that did not pass: each alone keeps the grading from passing,
        whatever the points."""
        return tuple(t for t in self.tests if t.core and not t.passed)

    @property
    def passed(self) -> bool:
        """At or above the pass mark, compared exactly, with every core test passed; never
        when the grader failed, nor for a partial run (see :attr:`complete`)."""
        return self.complete and self.grader_error is None and self.max_score > 0 and \
            self.fraction >= self.pass_mark and not self.core_missed

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> RunResult:
        """Read back what :meth:`to_dict` wrote (a batch resuming from its reports)."""
        kind: Kind = "exercise" if "exercise" in data else "quiz"
        tests = tuple(
            TestResult(name=t["name"], label=t.get("label", t["name"]),
                       score=exact(t["score"]), max_score=exact(t["max_score"]),
                       status=t["status"], message=t.get("message", ""),
                       hint=t.get("hint", ""), visibility=t.get("visibility", "visible"),
                       reveal=t.get("reveal", "message"), core=t.get("core", False))
            for t in data["tests"])
        isolation = data.get("isolation")
        return cls(kind=kind, id=data[kind], title=data.get("title", ""), tests=tests,
                   pass_mark=exact(data.get("pass_mark", "0.7")), lang=data.get("lang", "en"),
                   grader_error=data.get("grader_error"),
                   execution_time=data.get("execution_time", 0.0),
                   isolation=isolation, pacing=data.get("pacing", {}),
                   bags=data.get("bags", {}), warnings=tuple(data.get("warnings", ())),
                   timing=data.get("timing", {}), memory=data.get("memory", {}),
                   disturbed=tuple(tuple(uids) for uids in data.get("disturbed", ())),
                   not_run=NotRun.from_dict(data["not_run"]) if data.get("not_run") else None)

    def to_dict(self) -> dict[str, Any]:
        """Our JSON results shape (``--results``)."""
        return {
            self.kind: self.id,
            "title": self.title,
            "score": number(self.score),
            "max_score": number(self.max_score),
            # A partial run (check) has no verdict: null, and what the grade adds.
            "passed": self.passed if self.complete else None,
            **({"not_run": self.not_run.to_dict()} if self.not_run is not None else {}),
            "pass_mark": number(self.pass_mark),
            # The core tests that did not pass (each keeps the grading from passing).
            "core_missed": [t.name for t in self.core_missed],
            "lang": self.lang,
            "grader_error": self.grader_error,
            "execution_time": round(self.execution_time, 3),
            **({"isolation": dict(self.isolation)} if self.isolation is not None else {}),
            **({"pacing": dict(self.pacing)} if self.pacing else {}),
            **({"bags": dict(self.bags)} if self.bags else {}),
            **({"warnings": list(self.warnings)} if self.warnings else {}),
            **({"disturbed": [list(uids) for uids in self.disturbed]}
               if self.disturbed else {}),
            **({"timing": dict(self.timing)} if self.timing else {}),
            **({"memory": dict(self.memory)} if self.memory else {}),
            "tests": [
                {
                    "name": t.name,
                    "label": t.label,
                    "score": number(t.score),
                    "max_score": number(t.max_score),
                    "status": t.status,
                    "message": t.message,
                    "hint": t.hint,
                    "visibility": t.visibility,
                    "reveal": t.reveal,
                    "core": t.core,
                }
                for t in self.tests
            ],
        }
