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

from autograder.core.exercise import Exercise
from autograder.core.output import digest, log_folder
from autograder.core.results import RunResult, TestResult, exact
from autograder.core.signing import Forged, verify
from autograder.i18n import _, get_language
from autograder.sandbox.domains import DomainLock, NoDomain, hold_domain
from autograder.sandbox.isolation import Isolation, dds_env, detect, run_prefix, student_uid
from autograder.sandbox.process import reap_recorded

GRADER_FAULT = "the autograder failed, tell your instructor"


def grade(exercise: Exercise, submission: Path | None, *, hidden: bool = True,
          domain: int | None = None, real_time_factor: float | None = None,
          progress: Callable[[dict[str, Any]], None] | None = None) -> RunResult:
    """Run the exercise's public (and, with ``hidden``, hidden) tests on ``submission``.

    ``submission`` is the student's file or a folder holding it; None grades the reference
    solution.  Always returns a result: a broken submission scores what it showed, a fault
    of ours sets ``grader_error``.
    """
    started = time.monotonic()
    isolation = detect()
    try:
        with hold_domain(domain) as lock:
            result, report = _run(exercise, submission, hidden, lock, isolation,
                                  real_time_factor, progress, started)
    except NoDomain as exc:
        return _fault(exercise, str(exc), time.monotonic() - started)
    processes = report.get("data", {}).get("processes", [])
    bounds = processes[0].get("bounds") if processes else None
    return dataclasses.replace(result, data={
        **result.data, "isolation": {**isolation.to_dict(), "bounds": bounds},
        "domain": lock.domain, "processes": processes,
        "student_uid": student_uid(lock.domain) if isolation.strict else None})


def _run(exercise: Exercise, submission: Path | None, hidden: bool, lock: DomainLock,
         isolation: Isolation, real_time_factor: float | None,
         progress: Callable[[dict[str, Any]], None] | None,
         started: float) -> tuple[RunResult, dict[str, Any]]:
    """One grading in a child pytest on the reserved domain; the result and raw report.

    The child inherits the domain's lock (it holds the domain as long as it lives) and the
    read end of a *lifeline* pipe whose write end only this process holds: when this
    process dies, however it dies, the child sees the pipe close and ends itself and every
    student process it started (see ``autograder.plugin``)."""
    folders = [exercise.public_tests] + ([exercise.hidden_tests] if hidden else [])
    folders = [f for f in folders if f.is_dir()]
    ros_domain = lock.domain
    with tempfile.TemporaryDirectory(prefix="autograder-") as tmp:
        report_path = Path(tmp) / "report.json"
        command = [
            *run_prefix(isolation), sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
            "--rootdir", str(exercise.folder), "--basetemp", str(Path(tmp) / "pytest"),
            "--exercise", str(exercise.folder), "--autograder-report", str(report_path),
            "--ros-domain", str(ros_domain), *(str(f) for f in folders),
        ]
        if submission is not None:
            command += ["--submission", str(Path(submission).resolve())]
        if real_time_factor is not None:
            command += ["--real-time-factor", str(real_time_factor)]
        env = dict(os.environ, AUTOGRADER_LANG=get_language(), ROS_DOMAIN_ID=str(ros_domain),
                   AUTOGRADER_COURSE=str(exercise.folder.parent.parent),
                   AUTOGRADER_RUN_ISOLATION=isolation.mode, PYTHONDONTWRITEBYTECODE="1")
        for key, value in dds_env(isolation).items():
            if value is None:
                env.pop(key, None)
            else:
                env[key] = value
        log_path = Path(tmp) / "pytest.log"
        key = secrets.token_bytes(32)
        key_read, key_write = os.pipe()
        life_read, life_write = os.pipe()
        command += ["--autograder-report-key-fd", str(key_read),
                    "--autograder-lifeline-fd", str(life_read)]
        try:
            with log_path.open("wb") as log:
                child = subprocess.Popen(command, cwd=tmp, env=env, stdout=log,
                                         stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                         start_new_session=True,
                                         pass_fds=(key_read, life_read, *lock.fds))
                os.close(key_read)
                os.close(life_read)
                with os.fdopen(key_write, "wb") as pipe:
                    pipe.write(key)
                timed_out = _wait(child, exercise.time_limit, report_path, key, progress)
        finally:
            os.close(life_write)
        report = _read_report(report_path, key)
        report = _with_output_log(report, report_path)
        _reap(child, report)
        pytest_log = log_path.read_text(errors="replace")
    result = _result(exercise, report, child.returncode, timed_out, pytest_log,
                     time.monotonic() - started, all_tests=hidden)
    return result, report


def _fault(exercise: Exercise, details: str, elapsed: float) -> RunResult:
    """A grading that could not run at all: the grader's failure, said plainly."""
    return RunResult(kind="exercise", id=exercise.id, title=exercise.localized_title,
                     tests=(), pass_mark=exercise.pass_fraction, lang=get_language(),
                     grader_error=GRADER_FAULT, grader_details=details,
                     execution_time=elapsed)


def _wait(child: subprocess.Popen[bytes], limit: float, report_path: Path, key: bytes,
          progress: Callable[[dict[str, Any]], None] | None) -> bool:
    """Wait for the pytest child, calling ``progress`` as tests finish; True if it ran over."""
    deadline = time.monotonic() + limit
    reported: set[str] = set()
    while True:
        try:
            child.wait(timeout=0.25)
            finished = True
        except subprocess.TimeoutExpired:
            finished = False
        if progress is not None:
            for test in _read_report(report_path, key).get("tests", []):
                if test.get("done") and test["nodeid"] not in reported:
                    reported.add(test["nodeid"])
                    progress(test)
        if finished:
            return False
        if time.monotonic() > deadline:
            os.killpg(child.pid, signal.SIGKILL)
            child.wait()
            return True


def _read_report(path: Path, key: bytes) -> dict[str, Any]:
    """The signed report; ``{"forged": True}`` if someone else wrote it."""
    try:
        text = path.read_text()
    except OSError:
        return {}
    try:
        return verify(text, key)
    except Forged:
        return {"forged": True}


def _with_output_log(report: dict[str, Any], report_path: Path) -> dict[str, Any]:
    """The report with ``output_log``: every program's kept output, from the files the
    signed report names (read here, before the run's folder goes)."""
    entries = report.get("data", {}).get("log_files", [])
    if not entries:
        return report
    folder = log_folder(report_path)
    parts = [f"==> {entry['test']} <==\n{_read_log(folder, entry)}" for entry in entries]
    return {**report, "output_log": "\n\n".join(parts)}


def _read_log(folder: Path, entry: dict[str, Any]) -> str:
    """One program's kept output, if the file is the one the report vouches for."""
    path = folder / Path(entry["file"]).name
    try:  # the size first: a file swapped for a huge one is not read
        raw = path.read_bytes() if path.stat().st_size == entry["bytes"] else b""
    except OSError:
        raw = b""
    if digest(raw) != entry["sha256"]:
        return _("(This output was changed after your program ran, so it is left out.)")
    return raw.decode("utf-8", "replace")


def _reap(child: subprocess.Popen[bytes], report: dict[str, Any]) -> None:
    """Make sure nothing the run started outlives it (the child's group, students' cgroups)."""
    try:
        os.killpg(child.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    for process in report.get("data", {}).get("processes", []):
        reap_recorded(process)


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


def _result(exercise: Exercise, report: dict[str, Any], returncode: int | None,
            timed_out: bool, pytest_log: str, elapsed: float,
            all_tests: bool = True) -> RunResult:
    if report.get("forged"):
        return _forged(exercise, elapsed)
    tests = []
    errors = []
    for raw in report.get("tests", []):
        status = raw["status"]
        max_score = exact(raw["max_score"])
        message = raw["message"]
        if timed_out and status == "error" and not raw.get("done"):
            status, message = "failed", _(
                "Not run: grading stopped at its time limit of {seconds:.0f} s.").format(
                seconds=exercise.time_limit)
        if status == "error":
            errors.append(f"{raw['name']}: {message}\n{raw.get('details', '')}")
        tests.append(TestResult(
            name=raw["name"], label=raw["label"],
            score=_score(status, max_score, raw.get("fraction")), max_score=max_score,
            status=status, message=message, hint=raw.get("hint", ""),
            visibility=raw["visibility"], reveal=raw.get("reveal", "message"),
            details=raw.get("details", ""), data={"charts": raw.get("charts", [])}))
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
    data = report.get("data", {})
    logs = data.get("logs", {})
    return RunResult(
        kind="exercise", id=exercise.id, title=exercise.localized_title, tests=tuple(tests),
        pass_mark=exercise.pass_fraction, lang=get_language(), grader_error=grader_error,
        grader_details=details, log_tail="\n".join(logs.values())[-4000:],
        log=report.get("output_log", ""),
        execution_time=elapsed,
        data={"recordings": data.get("recordings", {}), "timed_out": timed_out,
              "startup_seconds": data.get("startup_seconds", []),
              "pacing": data.get("pacing", {})})
