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
from sim.recorder import Recording

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
class IntervalChart:
    """A test's message-interval plot (:meth:`autograder.plugin.credit.Evidence.intervals`):
    ``points``, each message's simulation time and the gap since the one before, in
    seconds; ``limit``, the largest gap allowed (None: no line drawn)."""

    title: str
    points: tuple[tuple[float, float], ...] = ()
    limit: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """As the child's raw report carries it (``kind`` names the chart's type)."""
        return {"kind": "intervals", "title": self.title,
                "points": [[t, gap] for t, gap in self.points], "limit": self.limit}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> IntervalChart:
        """Read what :meth:`to_dict` wrote; another shape is a KeyError, TypeError or
        ValueError here (a point that is not a pair of numbers), never later, in a drawing."""
        if data.get("kind", "intervals") != "intervals":
            raise ValueError(f"not an intervals chart: {data.get('kind')!r}")
        title, limit = data["title"], data.get("limit")
        if not isinstance(title, str):
            raise TypeError(f"a chart's title is text, not {title!r}")
        return cls(title=title,
                   points=tuple((_real(t), _real(gap)) for t, gap in data["points"]),
                   limit=None if limit is None else _real(limit))


def _real(value: Any) -> float:
    """``value`` if it is a number (an int as read from JSON stays one), else TypeError."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TypeError(f"not a number: {value!r}")
    return value


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
    # The charts the test drew (see ``autograder.plugin.credit``), for the HTML report only
    # (never in the JSON results).
    charts: tuple[IntervalChart, ...] = ()
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


@dataclasses.dataclass(frozen=True)
class ProcessBounds:
    """Which bounds held the student's programs
    (:func:`autograder.sandbox.cgroups.describe_bounds`): the cgroup hierarchy they ran in
    (``"v2"``, ``"v1"``, None) and, for processes, memory and CPU, ``"cgroup"``,
    ``"rlimit"`` or None (nothing)."""

    cgroup: str | None = None
    processes: str | None = None
    memory: str | None = None
    cpu: str | None = None

    def to_dict(self) -> dict[str, str | None]:
        return {"cgroup": self.cgroup, "processes": self.processes, "memory": self.memory,
                "cpu": self.cpu}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ProcessBounds:
        return cls(cgroup=data.get("cgroup"), processes=data.get("processes"),
                   memory=data.get("memory"), cpu=data.get("cpu"))


@dataclasses.dataclass(frozen=True)
class Containment:
    """How a grading contained the student's programs: the machine's isolation
    (:meth:`autograder.sandbox.isolation.Isolation.to_dict`, ``mode`` one of ``"strict"``,
    ``"user"``, ``"basic"``), the bounds that held the programs (None: no program
    started) and the users they ran as (None: the grader's own)."""

    mode: str
    official: bool
    separate_user: bool
    network: bool
    hidden_files_protected: bool
    reason: str = ""
    detail: str = ""
    bounds: ProcessBounds | None = None
    student_uids: tuple[int, ...] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"mode": self.mode, "official": self.official,
                "separate_user": self.separate_user, "network": self.network,
                "hidden_files_protected": self.hidden_files_protected,
                "reason": self.reason, "detail": self.detail,
                "bounds": None if self.bounds is None else self.bounds.to_dict(),
                "student_uids": None if self.student_uids is None else list(self.student_uids)}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Containment:
        """Read what :meth:`to_dict` wrote, or an ``Isolation.to_dict()`` with ``bounds``
        and ``student_uids`` beside it."""
        bounds, uids = data.get("bounds"), data.get("student_uids")
        return cls(mode=data["mode"], official=bool(data["official"]),
                   separate_user=bool(data["separate_user"]), network=bool(data["network"]),
                   hidden_files_protected=bool(data["hidden_files_protected"]),
                   reason=data.get("reason", ""), detail=data.get("detail", ""),
                   bounds=None if bounds is None else ProcessBounds.from_dict(bounds),
                   student_uids=None if uids is None else tuple(uids))


@dataclasses.dataclass(frozen=True)
class RunTiming:
    """Where a grading's wall seconds went: the children's start (from the first launch to
    the first test; None if no test started), the tests (summed over the modules, so more
    than ``total`` when modules run at once), the total from the grader's call, each
    module's phases (:meth:`autograder.plugin.timing.Timing.to_dict`), each test's
    simulation seconds to its verdict by node id, and how many child pytests ran."""

    child_start: float | None = None
    tests: float = 0.0
    total: float = 0.0
    modules: Mapping[str, Mapping[str, float]] = dataclasses.field(default_factory=dict)
    sim_seconds: Mapping[str, float] = dataclasses.field(default_factory=dict)
    children: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {"child_start": self.child_start, "tests": self.tests, "total": self.total,
                "modules": {module: dict(phases) for module, phases in self.modules.items()},
                "sim_seconds": dict(self.sim_seconds), "children": self.children}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunTiming:
        return cls(child_start=data.get("child_start"), tests=data.get("tests", 0.0),
                   total=data.get("total", 0.0), modules=data.get("modules", {}),
                   sim_seconds=data.get("sim_seconds", {}), children=data.get("children", 0))


@dataclasses.dataclass(frozen=True)
class ModulePacing:
    """How one test module's world paced itself: how many holds of simulation time ended
    each way (``outcomes``, by :data:`sim.pacing.HoldOutcome`: ``free``, ``idle``,
    ``budget``, ``cap``, ...; only those that happened, in the order they first did), the
    longest hold and all held, in wall seconds, and the bridge's counters (late deliveries
    and commands, bursts, receipts awaited, waits for a process blocked in the kernel, the
    latest command's lateness in sim seconds).
    A counter is None where the results did not carry it (an older file)."""

    outcomes: Mapping[str, int] = dataclasses.field(default_factory=dict)
    longest_hold: float | None = None
    held_seconds: float | None = None
    late_deliveries: int | None = None
    bursts: int | None = None
    receipts_awaited: int | None = None
    blocked_waits: int | None = None
    late_commands: int | None = None
    latest_command: float | None = None

    def count(self, outcome: str) -> int:
        return self.outcomes.get(outcome, 0)

    def to_dict(self) -> dict[str, Any]:
        return {**self.outcomes, **{field.name: value for field in dataclasses.fields(self)[1:]
                                    if (value := getattr(self, field.name)) is not None}}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ModulePacing:
        counters = {field.name for field in dataclasses.fields(cls)[1:]}
        return cls(outcomes={k: v for k, v in data.items() if k not in counters},
                   **{k: v for k, v in data.items() if k in counters})


@dataclasses.dataclass(frozen=True)
class StartedProcess:
    """A student program a grading started: its pid (also its process group), the cgroup
    folders it ran in, the bounds that held it and the user it ran as (None: the grader's)."""

    pid: int
    cgroups: tuple[str, ...] = ()
    bounds: ProcessBounds | None = None
    uid: int | None = None

    @classmethod
    def from_record(cls, record: Mapping[str, Any]) -> StartedProcess:
        """From the child's report (``GradingReporter.note_process``)."""
        bounds = record.get("bounds")
        return cls(pid=int(record["pid"]), cgroups=tuple(record.get("cgroups", ())),
                   bounds=ProcessBounds.from_dict(bounds) if bounds else None,
                   uid=record.get("uid"))


@dataclasses.dataclass(frozen=True)
class MemoryUse:
    """A grading's memory in MB: the children's peak resident sizes, summed (an upper bound,
    see :func:`autograder.grading.module_groups.merge`: ``grader_mb`` the child pytests,
    ``student_mb`` the largest student program of each, ``total_mb`` both), and
    ``footprint_mb``, the peak of the whole grading's summed PSS
    (:mod:`autograder.grading.footprint`). Each None where it was not measured."""

    grader_mb: float | None = None
    student_mb: float | None = None
    total_mb: float | None = None
    footprint_mb: float | None = None

    def to_dict(self) -> dict[str, float]:
        """The measured ones only."""
        return {field.name: value for field in dataclasses.fields(self)
                if (value := getattr(self, field.name)) is not None}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> MemoryUse:
        return cls(**{field.name: data.get(field.name) for field in dataclasses.fields(cls)})

    @classmethod
    def of(cls, children_peaks: Mapping[str, float] | None,
           footprint_mb: float | None) -> MemoryUse | None:
        """The children's merged peaks (the raw report's ``memory``) with the footprint
        beside them; None if neither was measured."""
        if not children_peaks and footprint_mb is None:
            return None
        return dataclasses.replace(cls.from_dict(children_peaks or {}),
                                   footprint_mb=footprint_mb)


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
    # How the student's program was contained; None when nothing was started (a fault
    # before the run).
    isolation: Containment | None = None
    # How the world paced itself, per test module: the counters ``sim.bridge`` keeps and
    # ``autograder.plugin.world`` adds to, whose names are theirs (left open here).
    pacing: Mapping[str, ModulePacing] = dataclasses.field(default_factory=dict)
    # ``--record DIR``: each test module's rosbag2 bag folder.
    bags: Mapping[str, str] = dataclasses.field(default_factory=dict)
    # What the student should know that is no test's verdict (a recording that failed).
    warnings: tuple[str, ...] = ()
    # Where the wall seconds went and the memory; None: not measured (no child ran).
    timing: RunTiming | None = None
    memory: MemoryUse | None = None
    # The other users whose programs disturbed each grading done again before this one.
    disturbed: tuple[tuple[int, ...], ...] = ()
    # -- for the grader and the reports only --
    # Each test module's run in the world, by module file name (``TestResult.module``).
    recordings: Mapping[str, Recording] = dataclasses.field(default_factory=dict)
    domains: tuple[int, ...] = ()
    processes: tuple[StartedProcess, ...] = ()
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
        isolation, timing, memory = (data.get(name) for name in ("isolation", "timing",
                                                                 "memory"))
        return cls(kind=kind, id=data[kind], title=data.get("title", ""), tests=tests,
                   pass_mark=exact(data.get("pass_mark", "0.7")), lang=data.get("lang", "en"),
                   grader_error=data.get("grader_error"),
                   execution_time=data.get("execution_time", 0.0),
                   isolation=Containment.from_dict(isolation) if isolation else None,
                   pacing={module: ModulePacing.from_dict(counts)
                           for module, counts in data.get("pacing", {}).items()},
                   bags=data.get("bags", {}), warnings=tuple(data.get("warnings", ())),
                   timing=RunTiming.from_dict(timing) if timing else None,
                   memory=MemoryUse.from_dict(memory) if memory else None,
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
            **({"isolation": self.isolation.to_dict()} if self.isolation is not None else {}),
            **({"pacing": {module: pacing.to_dict() for module, pacing in self.pacing.items()}}
               if self.pacing else {}),
            **({"bags": dict(self.bags)} if self.bags else {}),
            **({"warnings": list(self.warnings)} if self.warnings else {}),
            **({"disturbed": [list(uids) for uids in self.disturbed]}
               if self.disturbed else {}),
            **({"timing": self.timing.to_dict()} if self.timing is not None else {}),
            **({"memory": self.memory.to_dict()} if self.memory is not None else {}),
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
