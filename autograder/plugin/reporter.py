"""The reporter: each test's outcome, points and message, in the raw report as the run
goes (registered by :mod:`autograder.plugin` only when an exercise is graded)."""

from __future__ import annotations

import resource
import threading
import time
import traceback
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from autograder.core import report
from autograder.core.errors import Disturbed, GraderError, StudentFailure
from autograder.core.output_budget import (
    DETAILS_BYTES,
    LOG_TAIL_BYTES,
    LOG_TAIL_LINES,
    MESSAGE_BYTES,
    clip_middle,
    message_tail,
)
from autograder.core.report import RawTest
from autograder.core.results import exact
from autograder.i18n import _
from autograder.plugin.markers import marker_problem
from autograder.plugin.msgtypes import type_note
from autograder.plugin.stash import credit_key, evidence_key, settings_key, world_key
from autograder.plugin.timing import Timing, module_of


def _label(item: pytest.Item) -> str:
    doc = getattr(getattr(item, "function", None), "__doc__", None) or item.name
    return _(doc.strip().splitlines()[0].strip())


def _reveal(item: pytest.Item, visibility: str) -> str:
    """What a student sees of a test: 'message' (all) or 'status' (label and pass/fail)."""
    marker = item.get_closest_marker("reveal")
    if marker and marker.args:
        return str(marker.args[0])
    return "message" if visibility == "visible" else "status"


def _visibility(item: pytest.Item, hidden_default: str) -> str:
    marker = item.get_closest_marker("visibility")
    if marker and marker.args:
        return str(marker.args[0])
    return hidden_default if "hidden" in Path(str(item.path)).parts else "visible"


class SpawnGate:
    """Student programs start through this gate (``StudentProcess.gate``), one at a time
    with their record. Closed once and for good when the run ends: a start in progress
    finishes and is recorded first, a later one fails."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._closed = False

    def __enter__(self) -> None:
        self._lock.acquire()
        if self._closed:
            self._lock.release()
            raise GraderError(_("The grading is ending: no program starts now."))

    def __exit__(self, *_exc: object) -> None:
        self._lock.release()

    def close(self) -> None:
        with self._lock:
            self._closed = True


class GradingReporter:
    """Collects each test's outcome, points and message; writes the raw report as it goes."""

    def __init__(self, path: str | None, exercise: str | None = None,
                 key: bytes = b"") -> None:
        self.path = Path(path) if path else None
        self.exercise = exercise
        self.key = key
        self.tests: dict[str, RawTest] = {}
        self.data: dict[str, Any] = {"logs": {}, "log_files": [], "recordings": {},
                                     "processes": []}
        self.hidden_default = "after_published"
        self.timing = Timing()
        self.spawn_gate = SpawnGate()
        self._sim_began = 0.0

    def write(self) -> None:
        if self.path is not None:
            report.write(self.path, list(self.tests.values()), self.data, self.key)

    def keep_log(self, nodeid: str, text: str) -> None:
        """Keep a stopped program's output: its end in the report, the whole of it (as the
        sandbox kept it) in a file of its own that the report names with its digest, so
        the report, re-written after every test, stays small."""
        self.data["logs"][nodeid] = message_tail(text, LOG_TAIL_LINES, LOG_TAIL_BYTES)
        if self.path is not None and text:
            report.keep_log(self.path, self.data, nodeid, text)
        self.write()

    def ending(self) -> list[dict[str, Any]]:
        """The run is ending (its grader is gone): no student program starts from now on,
        and one being started is recorded first. The records of every program started."""
        self.spawn_gate.close()
        return list(self.data["processes"])

    def note_process(self, pid: int, cgroups: list[str], bounds: dict[str, Any],
                     workdir: str | None = None, uid: int | None = None) -> None:
        """Record a student process so the parent can reap it if this run is killed (and
        remove its folder outside the run's, ``workdir``, and end every process of its own
        user, ``uid``), and say which bounds held it."""
        record = {"pid": pid, "cgroups": cgroups, "bounds": bounds}
        if workdir is not None:
            record["workdir"] = workdir
        if uid is not None:
            record["uid"] = uid
        self.data["processes"].append(record)
        self.write()

    @pytest.hookimpl(trylast=True)
    def pytest_collection_modifyitems(self, config: pytest.Config,
                                      items: list[pytest.Item]) -> None:
        core: tuple[str, ...] = ()
        if self.exercise:
            from autograder.core.exercise import find_exercise

            found = find_exercise(self.exercise)
            self.hidden_default, core = found.hidden_visibility, found.core
        settings = config.stash.get(settings_key, None)
        if settings is not None and settings.count_only:
            items[:] = self._count_only(config, items, settings.count_only)
        for item in items:
            points = _points(item)
            visibility = _visibility(item, self.hidden_default)
            self.tests[item.nodeid] = RawTest(
                nodeid=item.nodeid, name=item.name, label=_label(item),
                max_score=points,
                visibility=visibility, reveal=_reveal(item, visibility), core=item.name in core,
                message=_("Not run: the grading run ended before this test."))
        self.write()

    def _count_only(self, config: pytest.Config, items: list[pytest.Item],
                    folders: tuple[str, ...] | list[str]) -> list[pytest.Item]:
        """``items`` less those under ``folders``, which are counted (tests and points, in
        the report's ``not_run``) and deselected: what the grade runs beyond this run."""
        roots = [Path(f).resolve() for f in folders]
        kept: list[pytest.Item] = []
        counted: list[pytest.Item] = []
        for item in items:
            path = Path(str(item.path)).resolve()
            (counted if any(path.is_relative_to(r) for r in roots) else kept).append(item)
        if counted:
            config.hook.pytest_deselected(items=counted)
        total = sum((exact(_points(item)) for item in counted), Fraction(0))
        self.data["not_run"] = {"tests": len(counted), "points": str(total)}
        return kept

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_makereport(self, item: pytest.Item,
                                  call: pytest.CallInfo[None]) -> Iterator[None]:
        outcome = yield
        outcome_report = outcome.get_result()
        entry = self.tests.get(item.nodeid)
        if entry is None:
            return
        shown = item.stash.get(evidence_key, None)
        if shown is not None and call.when == "call":
            entry.charts = [chart.to_dict() for chart in shown.charts]
        if call.when == "setup" or call.when == "call":
            given = item.stash.get(credit_key, None)
            if outcome_report.passed and call.when == "call" and given \
                    and given.fraction is not None and given.fraction < 1:
                _update(entry, status="failed", fraction=given.fraction,
                        message=given.message, hint=given.hint)
            elif outcome_report.passed and call.when == "call":
                _update(entry, status="passed", message="", hint="")
            elif outcome_report.skipped:
                _update(entry, status="skipped", message=_skip_reason(outcome_report))
            elif outcome_report.failed:
                _update(entry, **_classify(call.excinfo))
        elif call.when == "teardown" and outcome_report.failed and entry.status == "passed":
            _update(entry, **_classify(call.excinfo))
        if call.when == "call":
            self._note_sim_seconds(item)
        if call.when == "teardown" and entry.status == "failed":
            _lead_with(entry, type_note(item))
        _bound(entry)

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(self, item: pytest.Item) -> Iterator[None]:
        """Time each test whole (setup, call, teardown) into its module's total; note the
        world's simulation time when it starts (0 when its setup starts the world)."""
        began = time.monotonic()
        self.data.setdefault("first_test_at", began)
        world = item.config.stash.get(world_key, None)
        self._sim_began = world.now if world is not None else 0.0
        yield
        self.timing.add(module_of(item.nodeid), "total", time.monotonic() - began)

    def _note_sim_seconds(self, item: pytest.Item) -> None:
        """The simulation seconds a test took to its verdict (its setup and call; time
        stands still while a node starts): ``sim_seconds`` by node id, for the benchmarks'
        floor (``benchmarks/bench_grading.py``)."""
        world = item.config.stash.get(world_key, None)
        if world is not None:
            self.data.setdefault("sim_seconds", {})[item.nodeid] = round(
                world.now - self._sim_began, 3)

    def pytest_sessionfinish(self) -> None:
        """The run's timing per module and its peak memory, into the report."""
        self.data["timing"] = self.timing.to_dict()
        self.data["memory"] = peak_memory()
        self.write()

    def pytest_runtest_logfinish(self, nodeid: str) -> None:
        if nodeid in self.tests:
            self.tests[nodeid].done = True
        self.write()


def peak_memory() -> dict[str, float]:
    """Peak resident memory in MB: this process (pytest, the world and the probe) and the
    largest student process it has waited for (each started program is, when stopped), or
    its zygote has (:func:`autograder.sandbox.process.forked_peak_mb`)."""
    from autograder.sandbox.process import forked_peak_mb

    grader = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)  # KB
    student = round(max(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
                        forked_peak_mb()), 1)
    return {"grader_mb": grader, "student_mb": student, "total_mb": round(grader + student, 1)}


def _points(item: pytest.Item) -> Any:
    """The points a test is worth (its ``points`` marker, else 1)."""
    if marker_problem(item) is not None:
        return 1  # the test errs at setup, naming the problem
    marker = item.get_closest_marker("points")
    return marker.args[0] if marker and marker.args else 1


def _update(entry: RawTest, **values: Any) -> None:
    for key, value in values.items():
        setattr(entry, key, value)


def _lead_with(entry: RawTest, note: str) -> None:
    """Put ``note`` (why messages never matched, say) once before a failed test's message:
    it is what the student must fix first."""
    if note and entry.status == "failed" and note not in entry.message:
        entry.message = f"{note}\n\n{entry.message}" if entry.message else note


def _bound(entry: RawTest) -> None:
    """Cut what a test reports to a few KB: every results format repeats it per test."""
    entry.message = clip_middle(entry.message, MESSAGE_BYTES)
    entry.hint = clip_middle(entry.hint, MESSAGE_BYTES)
    entry.details = clip_middle(entry.details, DETAILS_BYTES)


def _skip_reason(report: pytest.TestReport) -> str:
    longrepr = report.longrepr
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2]).removeprefix("Skipped: ")
    return str(longrepr)


def _classify(excinfo: pytest.ExceptionInfo[BaseException] | None) -> dict[str, Any]:
    """A failing test's status: the student's failure, or our error."""
    if excinfo is None:
        return {"status": "failed", "message": "", "hint": "", "details": ""}
    details = "".join(traceback.format_exception(excinfo.type, excinfo.value, excinfo.tb))
    error = excinfo.value
    if isinstance(error, StudentFailure):
        return {"status": "failed", "message": error.message, "hint": error.hint,
                "details": details}
    if isinstance(error, AssertionError):
        text = str(error).strip()
        return {"status": "failed", "message": text.split("\nassert")[0].strip() or
                _("A check failed."), "hint": "", "details": details}
    kind = "grader error" if isinstance(error, GraderError) else type(error).__name__
    return {"status": "error", "message": f"{kind}: {error}", "hint": "", "details": details,
            **({"strangers": list(error.uids)} if isinstance(error, Disturbed) else {})}
