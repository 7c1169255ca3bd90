"""Grade a submission: run the exercise's tests in a child pytest, turn its report into a
:class:`~autograder.core.results.RunResult`.

The tests (and the world and probe they use) run in a child process, so a crash there is
reported as a grader fault instead of taking the CLI down, and a run past its time limit
is stopped with everything it started.
"""

from __future__ import annotations

import dataclasses
import os
import secrets
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path
from typing import Any

from autograder.core import report
from autograder.core.exercise import Exercise
from autograder.core.report import RawReport, RawTest
from autograder.core.results import NotRun, RunResult, TestResult, exact
from autograder.core.settings import RunSettings
from autograder.i18n import _, get_language
from autograder.sandbox.domains import DomainLock, NoDomain, hold_domain
from autograder.sandbox.isolation import Isolation, detect, run_prefix, student_uid
from autograder.sandbox.process import reap_recorded

GRADER_FAULT = "the autograder failed, tell your instructor"


Progress = Callable[[RawTest], None]


def grade(exercise: Exercise, submission: Path | None, *, hidden: bool = True,
          domain: int | None = None, real_time_factor: float | None = None,
          progress: Progress | None = None,
          running: Callable[[RawTest | None], None] | None = None,
          record: Path | None = None) -> RunResult:
    """Run the exercise's public (and, with ``hidden``, hidden) tests on ``submission``.

    ``submission`` is the student's file or a folder holding it; None grades the reference
    solution.  Always returns a result: a broken submission scores what it showed, a fault
    of ours sets ``grader_error``.  ``progress`` gets each test as it finishes;
    ``running``, a few times a second, the test that runs now (None between tests).
    With ``record``, each test module's graph is recorded as a rosbag2 bag in that folder
    (``data["bags"]``); a recording that fails is only a warning (``data["warnings"]``).
    """
    started = time.monotonic()
    isolation = detect()
    record, warnings = _record_folder(record)
    try:
        with hold_domain(domain) as lock:
            result, raw = _run(exercise, submission, hidden, lock, isolation,
                               real_time_factor, _Watchers(progress, running), started,
                               record)
    except NoDomain as exc:
        return _fault(exercise, str(exc), time.monotonic() - started)
    if warnings:
        result = dataclasses.replace(result, data={
            **result.data, "warnings": warnings + result.data.get("warnings", [])})
    processes = raw.processes
    bounds = processes[0].get("bounds") if processes else None
    return dataclasses.replace(result, data={
        **result.data, "isolation": {**isolation.to_dict(), "bounds": bounds},
        "domain": lock.domain, "processes": processes,
        "student_uid": student_uid(lock.domain) if isolation.strict else None})


def _record_folder(record: Path | None) -> tuple[Path | None, list[str]]:
    """The recordings' folder, made and absolute; None and a warning if it cannot be made
    (the grading goes on without recording)."""
    if record is None:
        return None, []
    try:
        record = Path(record).resolve()
        record.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        return None, [_("The run could not be recorded in {path}: {error}").format(
            path=record, error=exc)]
    return record, []


@dataclasses.dataclass(frozen=True)
class _Watchers:
    """Who is told how the run goes (see :func:`grade`)."""

    progress: Progress | None = None
    running: Callable[[RawTest | None], None] | None = None


def _shown_name(exercise: Exercise, submission: Path | None) -> str:
    """The student's file as they named it, for messages: the path they gave (or the file
    in the folder they gave), else the exercise's file name."""
    from autograder.core.submission import SubmissionNotFound, locate

    if submission is None:
        return exercise.file
    try:
        return str(locate(Path(submission), exercise.file))
    except SubmissionNotFound:
        return exercise.file


def _run(exercise: Exercise, submission: Path | None, hidden: bool, lock: DomainLock,
         isolation: Isolation, real_time_factor: float | None, watchers: _Watchers,
         started: float, record: Path | None = None) -> tuple[RunResult, RawReport]:
    """One grading in a child pytest on the reserved domain; the result and raw report.

    The child gets its :class:`~autograder.core.settings.RunSettings` as one document. It
    inherits the domain's lock (it holds the domain as long as it lives) and the read end
    of a *lifeline* pipe whose write end only this process holds: when this process dies,
    however it dies, the child sees the pipe close and ends itself and every student
    process it started (see ``autograder.plugin``)."""
    # A public run collects the hidden tests too, only to count them (see the reporter).
    folders = [f for f in (exercise.public_tests, exercise.hidden_tests) if f.is_dir()]
    count_only = () if hidden else tuple(str(f) for f in folders
                                         if f == exercise.hidden_tests)
    with tempfile.TemporaryDirectory(prefix="autograder-") as tmp:
        report_path = Path(tmp) / "report.json"
        key = secrets.token_bytes(32)
        key_read, key_write = os.pipe()
        life_read, life_write = os.pipe()
        settings = RunSettings(
            exercise=str(exercise.folder),
            submission=str(Path(submission).resolve()) if submission is not None else None,
            course=str(exercise.folder.parent.parent), report=str(report_path),
            key_fd=key_read, lifeline_fd=life_read, domain=lock.domain,
            real_time_factor=real_time_factor, isolation=isolation.mode, lang=get_language(),
            record=str(record) if record is not None else None,
            submission_name=_shown_name(exercise, submission), count_only=count_only)
        command = [
            *run_prefix(isolation), sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
            "--rootdir", str(exercise.folder), "--basetemp", str(Path(tmp) / "pytest"),
            "--autograder-settings", settings.to_json(), *(str(f) for f in folders),
        ]
        env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
        log_path = Path(tmp) / "pytest.log"
        try:
            with log_path.open("wb") as log:
                launched = time.monotonic()
                child = subprocess.Popen(command, cwd=tmp, env=env, stdout=log,
                                         stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                         start_new_session=True,
                                         pass_fds=(key_read, life_read, *lock.fds))
                os.close(key_read)
                os.close(life_read)
                with os.fdopen(key_write, "wb") as pipe:
                    pipe.write(key)
                timed_out = _wait(child, exercise.time_limit, report_path, key, watchers)
        finally:
            os.close(life_write)
        raw = report.read(report_path, key, with_logs=True)
        _reap(child, raw)
        pytest_log = log_path.read_text(errors="replace")
    elapsed = time.monotonic() - started
    result = _result(exercise, raw, child.returncode, timed_out, pytest_log, elapsed,
                     all_tests=hidden)
    return dataclasses.replace(result, data={
        **result.data, "timing": _timing(raw.data, launched, elapsed),
        **({"memory": raw.data["memory"]} if raw.data.get("memory") else {})}), raw


def _timing(data: dict[str, Any], launched: float, elapsed: float) -> dict[str, Any]:
    """The whole grading's wall seconds: the child's start (from its launch to its first
    test: pytest, the plugin, collecting the tests), the tests (per module, see
    :mod:`autograder.plugin.timing`) and the total, from the grader's call. ``launched``
    is when the child was started (the monotonic clock, the same in both processes)."""
    modules = data.get("timing", {})
    first = data.get("first_test_at")
    child_start = None if first is None else round(max(0.0, first - launched), 3)
    return {"child_start": child_start,
            "tests": round(sum(m.get("total", 0.0) for m in modules.values()), 3),
            "total": round(elapsed, 3), "modules": modules}


def _fault(exercise: Exercise, details: str, elapsed: float) -> RunResult:
    """A grading that could not run at all: the grader's failure, said plainly."""
    return RunResult(kind="exercise", id=exercise.id, title=exercise.localized_title,
                     tests=(), pass_mark=exercise.pass_fraction, lang=get_language(),
                     grader_error=GRADER_FAULT, grader_details=details,
                     execution_time=elapsed)


def _wait(child: subprocess.Popen[bytes], limit: float, report_path: Path, key: bytes,
          watchers: _Watchers) -> bool:
    """Wait for the pytest child, telling ``watchers`` as tests run and finish; True if it
    ran over its time limit."""
    deadline = time.monotonic() + limit
    reported: set[str] = set()
    while True:
        try:
            child.wait(timeout=0.25)
            finished = True
        except subprocess.TimeoutExpired:
            finished = False
        if watchers.progress is not None or watchers.running is not None:
            tests = report.read(report_path, key).tests
            for test in tests:
                if test.done and test.nodeid not in reported:
                    reported.add(test.nodeid)
                    if watchers.progress is not None:
                        watchers.progress(test)
            if watchers.running is not None:
                # Tests run in the order they were collected: the first not done runs now.
                watchers.running(None if finished else
                                 next((t for t in tests if not t.done), None))
        if finished:
            return False
        if time.monotonic() > deadline:
            os.killpg(child.pid, signal.SIGKILL)
            child.wait()
            return True


def _reap(child: subprocess.Popen[bytes], raw: RawReport) -> None:
    """Make sure nothing the run started outlives it (the child's group, students' cgroups)."""
    try:
        os.killpg(child.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    for process in raw.processes:
        reap_recorded(process)


def result_of(raw: RawTest, status: str | None = None,
                message: str | None = None) -> TestResult:
    """A test of the raw report as the results model holds it (``status`` and ``message``
    override the child's: a test the time limit stopped)."""
    status = status or raw.status
    max_score = exact(raw.max_score)
    return TestResult(
        name=raw.name, label=raw.label, score=_score(status, max_score, raw.fraction),
        max_score=max_score, status=status,  # type: ignore[arg-type]
        message=raw.message if message is None else message, hint=raw.hint,
        visibility=raw.visibility, reveal=raw.reveal,  # type: ignore[arg-type]
        details=raw.details,
        # The test module names the world's recording it ran in (report pictures).
        data={"charts": raw.charts, "nodeid": raw.nodeid, "module": _module_of(raw.nodeid)})


def _score(status: str, max_score: Fraction, fraction: float | None) -> Fraction:
    """Full points for a pass; a failed test's partial credit, rounded to 1/100 of a point."""
    if status == "passed":
        return max_score
    if fraction:
        return Fraction(round(fraction * max_score * 100), 100)
    return Fraction(0)


def _forged(exercise: Exercise, elapsed: float) -> RunResult:
    """The report was overwritten during the run: nothing in it can be trusted."""
    test = TestResult(
        name="report_integrity", label=_("The grading report was left alone"),
        score=Fraction(0), max_score=Fraction(exercise.points or 1), status="failed",
        message=_("The grading report was overwritten while your program ran; nothing in "
                  "it can be graded."),
        hint=_("A program must not write outside its working directory."))
    return RunResult(kind="exercise", id=exercise.id, title=exercise.localized_title,
                     tests=(test,), pass_mark=exercise.pass_fraction, lang=get_language(),
                     execution_time=elapsed, data={"forged": True})


def _module_of(nodeid: str) -> str:
    """The test module's file name, as the world's recordings are keyed
    ("tests/public/test_governor.py::test_clamps" -> "test_governor.py")."""
    return nodeid.partition("::")[0].rpartition("/")[2]


def _result(exercise: Exercise, raw_report: RawReport, returncode: int | None,
            timed_out: bool, pytest_log: str, elapsed: float,
            all_tests: bool = True) -> RunResult:
    if raw_report.forged:
        return _forged(exercise, elapsed)
    tests = []
    errors = []
    for raw in raw_report.tests:
        test = result_of(raw)
        if timed_out and raw.status == "error" and not raw.done:
            test = result_of(raw, "failed", _(
                "Not run: grading stopped at its time limit of {seconds:.0f} s.").format(
                seconds=exercise.time_limit))
        if test.status == "error":
            errors.append(f"{raw.name}: {test.message}\n{raw.details}")
        tests.append(test)
    grader_error = None
    details = ""
    broken_run = returncode not in (0, 1) and not timed_out  # e.g. a test file that
    if errors or not tests or broken_run:                    # does not import
        grader_error = GRADER_FAULT
        details = "\n\n".join(errors + ([pytest_log[-4000:]] if broken_run or not tests
                                          else []))
    total = sum((t.max_score for t in tests), Fraction(0))
    # Only a run of every test can check the total (`check` runs the public ones alone).
    if exercise.points and tests and all_tests and total != exercise.points \
            and grader_error is None:
        grader_error = GRADER_FAULT
        details = (f"{exercise.folder / 'exercise.yaml'}: points is {exercise.points} but the "
                   f"tests add up to {total}")
    data = raw_report.data
    logs = data.get("logs", {})
    not_run = None if all_tests else _not_run(exercise, data.get("not_run"), total)
    return RunResult(
        kind="exercise", id=exercise.id, title=exercise.localized_title, tests=tuple(tests),
        pass_mark=exercise.pass_fraction, lang=get_language(), grader_error=grader_error,
        grader_details=details, log_tail="\n".join(logs.values())[-4000:],
        log=raw_report.output_log, not_run=not_run,
        execution_time=elapsed,
        data={"recordings": data.get("recordings", {}), "timed_out": timed_out,
              "startup_seconds": data.get("startup_seconds", []),
              "pacing": data.get("pacing", {}), "bags": data.get("bags", {}),
              "warnings": data.get("warnings", [])})


def _not_run(exercise: Exercise, counted: dict[str, Any] | None,
             run_points: Fraction) -> NotRun | None:
    """What a public run left for the grade: the hidden tests the child counted, else (a
    student's copy holds none) the points exercise.yaml says are left; None if nothing is."""
    if counted is not None:
        tests, points = int(counted["tests"]), exact(counted["points"])
        return NotRun(tests, points) if tests else None
    if exercise.points:
        left = Fraction(exercise.points) - run_points
        return NotRun(None, left) if left > 0 else None
    return NotRun()
