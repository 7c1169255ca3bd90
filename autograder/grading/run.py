"""Grade a submission: run the exercise's tests in child pytests, turn their reports into
a :class:`~autograder.core.results.RunResult`.

The tests (and the world and probe they use) run in child processes, so a crash there is
reported as a grader fault instead of taking the CLI down, and a run past its time limit
is stopped with everything it started.  Test modules run in several children at once,
each on a ROS domain of its own (:mod:`autograder.grading.module_groups`), so a grading takes
about as long as its slowest module.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from pathlib import Path
from typing import Any

from autograder.core.exercise import Exercise
from autograder.core.report import RawReport, RawTest
from autograder.core.results import (
    Containment,
    IntervalChart,
    MemoryUse,
    ModulePacing,
    NotRun,
    RunResult,
    RunTiming,
    StartedProcess,
    TestResult,
    exact,
)
from autograder.core.settings import RunSettings
from autograder.grading import children
from autograder.grading.capacity import machine_cores
from autograder.grading.children import Progress, Watchers
from autograder.grading.footprint import Footprint
from autograder.grading.module_groups import (
    ModuleJobs,
    children_for,
    find_modules,
    merge,
    share_out,
)
from autograder.i18n import _, get_language
from autograder.sandbox.domains import DomainLock, NoDomain, bound_on_domains, hold_domain
from autograder.sandbox.isolation import (
    Detection,
    Isolation,
    close_to_others,
    detect,
    detection,
    protected_paths,
    student_uid,
)
from sim.recorder import Recording

GRADER_FAULT = "the autograder failed, tell your instructor"
# A grading that other users' programs disturbed is done again once they are gone, at
# most this many times; then its grader fault stands.
REGRADES = 2



def grade(exercise: Exercise, submission: Path | None, *, hidden: bool = True,
          domain: int | None = None, real_time_factor: float | None = None,
          progress: Progress | None = None,
          running: Callable[[list[RawTest]], None] | None = None,
          record: Path | None = None, module_jobs: ModuleJobs = "auto") -> RunResult:
    """Run the exercise's public (and, with ``hidden``, hidden) tests on ``submission``.

    ``submission`` is the student's file or a folder holding it; None grades the reference
    solution.  Always returns a result: a broken submission scores what it showed, a fault
    of ours sets ``grader_error``.  ``progress`` gets each test as it finishes;
    ``running``, a few times a second, the tests that run now (one per child).
    With ``record``, each test module's graph is recorded as a rosbag2 bag in that folder
    (``bags``); a recording that fails is only a warning (``warnings``).
    ``module_jobs`` children run the test modules at once, each on a domain of its own
    (``auto``: one per module as far as the cores go); a given ``domain`` means one child.
    """
    disturbed: list[tuple[int, ...]] = []
    while True:
        result = _grade_once(exercise, submission, hidden=hidden, domain=domain,
                             real_time_factor=real_time_factor, progress=progress,
                             running=running, record=record, module_jobs=module_jobs)
        strangers = result.strangers
        if result.grader_error is None or not strangers or len(disturbed) >= REGRADES:
            break
        disturbed.append(strangers)  # what it saw proves nothing: again, once they left
        _wait_until_gone(strangers, result.domains, exercise.time_limit)
    if disturbed:
        result = dataclasses.replace(result, disturbed=tuple(disturbed))
    return result


def _wait_until_gone(uids: Sequence[int], domains: Sequence[int], seconds: float) -> None:
    """Wait (up to ``seconds``) until the strangers ``uids`` have no socket left on the
    grading's ``domains`` (another grading's student ends with its grading, within its
    time limit); the grading again takes a domain no one is on."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if not any(uid in uids and domain in domains
                   for domain, uid in bound_on_domains()):
            return
        time.sleep(0.2)


def _grade_once(exercise: Exercise, submission: Path | None, *, hidden: bool,
                domain: int | None, real_time_factor: float | None,
                progress: Progress | None,
                running: Callable[[list[RawTest]], None] | None,
                record: Path | None, module_jobs: ModuleJobs) -> RunResult:
    """One grading of ``submission`` (see :func:`grade`)."""
    started = time.monotonic()
    refusal = _refusal(exercise, submission)
    if refusal is not None:  # nothing to run: no world, no domain, no child
        return _refused(exercise, refusal, time.monotonic() - started)
    detecting = detection()  # its check runs while the children start
    record, warnings = record_folder(record)
    plan = _Plan.of(exercise, hidden)
    wanted = 1 if domain is not None else children_for(module_jobs, len(plan.modules),
                                                          machine_cores())
    try:
        with contextlib.ExitStack() as stack:
            locks = [stack.enter_context(hold_domain(domain))]
            locks += _more_domains(stack, wanted - 1)
            result, raw, isolation = _run(exercise, submission, plan, locks, detecting,
                                          real_time_factor, Watchers(progress, running),
                                          started, record)
    except NoDomain as exc:
        return _fault(exercise, str(exc), time.monotonic() - started)
    if warnings:
        result = dataclasses.replace(result, warnings=(*warnings, *result.warnings))
    # Where each ran on this machine (its folder) is the reaping's business, not the results'.
    processes = [StartedProcess.from_record(p) for p in raw.processes]
    bounds = raw.processes[0].get("bounds") if raw.processes else None
    # Each child's students run as the user of its domain.
    uids = [student_uid(lock.domain) for lock in locks] if isolation.own_user else None
    return dataclasses.replace(
        result, isolation=Containment.from_dict(
            {**isolation.to_dict(), "bounds": bounds, "student_uids": uids}),
        domains=tuple(lock.domain for lock in locks), processes=tuple(processes),
        student_uids=tuple(uids) if uids else None)


def _more_domains(stack: contextlib.ExitStack, count: int) -> list[DomainLock]:
    """Up to ``count`` more free domains, held until ``stack`` closes (fewer if the
    machine has fewer free: the modules then share fewer children)."""
    locks: list[DomainLock] = []
    for _index in range(count):
        try:
            locks.append(stack.enter_context(hold_domain()))
        except NoDomain:
            break
    return locks


@dataclasses.dataclass(frozen=True)
class _Plan:
    """What a grading runs: its test folders, the modules to share out among children and
    the folders only counted (``check``: the hidden tests)."""

    folders: tuple[Path, ...]
    modules: tuple[Path, ...]
    count_only: tuple[Path, ...]
    all_tests: bool  # the hidden tests run too (a grade, not a check)

    @classmethod
    def of(cls, exercise: Exercise, hidden: bool) -> _Plan:
        # A public run collects the hidden tests too, only to count them (see the reporter).
        folders = tuple(f for f in (exercise.public_tests, exercise.hidden_tests)
                        if f.is_dir())
        count_only = () if hidden else tuple(f for f in folders
                                             if f == exercise.hidden_tests)
        run = [f for f in folders if f not in count_only]
        return cls(folders, tuple(find_modules(run)), count_only, hidden)

    def targets(self, children: int) -> list[list[Path]]:
        """Each child's pytest arguments: the folders for one child (as pytest collects
        them), else groups of modules, the first child also counting ``count_only``."""
        if children <= 1 or len(self.modules) <= 1:
            return [list(self.folders)]
        groups = share_out(self.modules, children)
        return [group + (list(self.count_only) if i == 0 else [])
                for i, group in enumerate(groups)]

    def order(self, root: Path) -> list[str]:
        """The modules' node-id paths (relative to pytest's rootdir) in collection order."""
        return [Path(os.path.relpath(m, root)).as_posix() for m in self.modules]


def record_folder(record: Path | None) -> tuple[Path | None, list[str]]:
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


def _run(exercise: Exercise, submission: Path | None, plan: _Plan,
         locks: Sequence[DomainLock], detecting: Detection, real_time_factor: float | None,
         watchers: Watchers, started: float, record: Path | None = None,
         ) -> tuple[RunResult, RawReport, Isolation]:
    """One grading in child pytests, one per reserved domain; the result, the merged raw
    report and the isolation it ran in. Each child gets its
    :class:`~autograder.core.settings.RunSettings` as one document (see
    :mod:`autograder.grading.children`). Every child forks students' programs from a
    zygote of its own (in its own namespaces), so each start after the first is a fork,
    not an exec (docs/contributors/design.md, "Warm starts").

    The children start in the isolation the machine likely allows while its start-up
    check runs (``detecting``), and wait for their keys: they grade once the check has
    confirmed it, and are ended unused and started again in the isolation it found if it
    did not. So the check and the children's start share the wall time."""
    targets = plan.targets(len(locks))
    isolation = detecting.likely
    # A program left running where nothing ends it (basic isolation without a cgroup) may
    # still write here as it goes: what it keeps is left, never the grader's crash.
    with tempfile.TemporaryDirectory(prefix="autograder-", ignore_cleanup_errors=True) as tmp:
        running: list[children.Child] = []
        try:
            while True:
                settings = _settings(exercise, submission, locks, isolation,
                                     real_time_factor, record)
                with contextlib.ExitStack() as lifelines:
                    running = []
                    for index, (group, lock) in enumerate(zip(targets, locks, strict=False)):
                        count_only = tuple(str(f) for f in plan.count_only if f in group)
                        running.append(lifelines.enter_context(children.started(
                            isolation,
                            dataclasses.replace(settings, count_only=count_only),
                            [str(t) for t in group], Path(tmp) / f"child-{index}",
                            exercise.folder, lock, hold_key=True)))
                    confirmed = detecting.result()
                    if confirmed.mode != isolation.mode:
                        isolation = confirmed
                        continue  # leaving the block ends the children, keys unsent
                    isolation = confirmed
                    if isolation.mode == "user":  # no mount namespace hides them
                        close_to_others(protected_paths(exercise.folder.parent.parent))
                    for child in running:
                        child.release()
                    footprint = Footprint([child.process.pid for child in running],
                                          alone=children.forked_from(running))
                    children.wait(running, exercise.time_limit, watchers, footprint)
                break
        except BaseException:  # stopped (a signal, Ctrl-C): the children go before tmp
            children.abandon(running)
            raise
        ended = [children.end(child) for child in running]
    elapsed = time.monotonic() - started
    raw = merge(([e.raw for e in ended]), plan.order(exercise.folder))
    result = verdict(exercise, raw, ended, elapsed, all_tests=plan.all_tests)
    timing = _timing(raw.data, min(e.launched for e in ended), elapsed, len(ended))
    memory = MemoryUse.of(raw.data.get("memory"), footprint.peak_mb)
    return dataclasses.replace(result, timing=timing, memory=memory), raw, isolation


def _settings(exercise: Exercise, submission: Path | None, locks: Sequence[DomainLock],
              isolation: Isolation, real_time_factor: float | None,
              record: Path | None) -> RunSettings:
    """The settings every child of a grading shares (each then gets its own report, key,
    lifeline and domain)."""
    return RunSettings(
        domains=tuple(lock.domain for lock in locks),
        exercise=str(exercise.folder),
        submission=str(Path(submission).resolve()) if submission is not None else None,
        course=str(exercise.folder.parent.parent), real_time_factor=real_time_factor,
        isolation=isolation.mode, lang=get_language(),
        record=str(record) if record is not None else None,
        submission_name=_shown_name(exercise, submission))


def _timing(data: dict[str, Any], launched: float, elapsed: float,
            children: int) -> RunTiming:
    """The whole grading's wall seconds (:class:`~autograder.core.results.RunTiming`) from
    the merged raw report. ``launched`` is when the first child was started (the monotonic
    clock, the same in every process); the children's start runs from then to the first
    test (pytest, the plugin, collecting the tests)."""
    modules = data.get("timing", {})
    first = data.get("first_test_at")
    child_start = None if first is None else round(max(0.0, first - launched), 3)
    return RunTiming(child_start=child_start,
                     tests=round(sum(m.get("total", 0.0) for m in modules.values()), 3),
                     total=round(elapsed, 3), modules=modules,
                     sim_seconds=data.get("sim_seconds", {}), children=children)


def _fault(exercise: Exercise, details: str, elapsed: float) -> RunResult:
    """A grading that could not run at all: the grader's failure, said plainly."""
    return RunResult(kind="exercise", id=exercise.id, title=exercise.localized_title,
                     tests=(), pass_mark=exercise.pass_fraction, lang=get_language(),
                     grader_error=GRADER_FAULT, grader_details=details,
                     execution_time=elapsed)


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
        details=raw.details, core=raw.core, nodeid=raw.nodeid, charts=_charts(raw.charts))


def _charts(carried: Sequence[Mapping[str, Any]]) -> tuple[IntervalChart, ...]:
    """The charts a test drew, read back from the raw report
    (:meth:`~autograder.core.results.IntervalChart.to_dict`). One that cannot be read is
    left out, as a recording is: the report draws it not at all, and the grade does not
    change."""
    charts = []
    for data in carried:
        try:
            charts.append(IntervalChart.from_dict(data))
        except (AttributeError, KeyError, TypeError, ValueError):  # not a chart's shape
            continue
    return tuple(charts)


def _score(status: str, max_score: Fraction, fraction: float | None) -> Fraction:
    """Full points for a pass; a failed test's partial credit, rounded to 1/100 of a point."""
    if status == "passed":
        return max_score
    if fraction:
        return Fraction(round(fraction * max_score * 100), 100)
    return Fraction(0)


def _refusal(exercise: Exercise, submission: Path | None) -> str | None:
    """Why the student's file cannot be graded at all (a link, no file, not a node Python
    runs: :func:`autograder.core.submission.check`), or None."""
    from autograder.core.submission import SubmissionNotFound, check

    if submission is None:
        return None
    try:
        check(Path(submission), exercise.file)
    except SubmissionNotFound as exc:
        return str(exc)
    return None


def _refused(exercise: Exercise, message: str, elapsed: float) -> RunResult:
    """A file refused before any test ran (``grade-batch``): one failed test worth the
    exercise's points, saying why once, so the gradebook shows a 0 out of the whole."""
    test = TestResult(
        name="submission_runs", label=_("Your file is a ROS node that Python runs"),
        score=Fraction(0), max_score=Fraction(exercise.points or 1), status="failed",
        message=message,
        hint=_("Nothing was graded: fix this, then check again."))
    return RunResult(kind="exercise", id=exercise.id, title=exercise.localized_title,
                     tests=(test,), pass_mark=exercise.pass_fraction, lang=get_language(),
                     execution_time=elapsed, refused=True,
                     # nothing ran; the shape it would have run in:
                     isolation=Containment.from_dict(detect().to_dict()))


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
                     execution_time=elapsed, forged=True)


def verdict(exercise: Exercise, raw_report: RawReport, ended: Sequence[children.Ended],
            elapsed: float, all_tests: bool = True) -> RunResult:
    """The verdict on the merged report: each child's tests as that child ended (those of
    a child stopped at the time limit say so; a child that broke is the grader's fault)."""
    if raw_report.forged:
        return _forged(exercise, elapsed)
    stopped = {t.nodeid for e in ended if e.timed_out for t in e.raw.tests}
    tests = []
    errors = []
    for raw in raw_report.tests:
        test = result_of(raw)
        if raw.nodeid in stopped and raw.status == "error" and not raw.done:
            test = result_of(raw, "failed", _(
                "Not run: grading stopped at its time limit of {seconds:.0f} s.").format(
                seconds=exercise.time_limit))
        if test.status == "error":
            errors.append(f"{raw.name}: {test.message}\n{raw.details}")
        # exercise.yaml names the core tests: the grader marks them, not the child's report.
        tests.append(dataclasses.replace(test, core=raw.name in exercise.core))
    grader_error = None
    details = ""
    broken = [e for e in ended if e.broken]  # e.g. a test file that does not import
    if errors or not tests or broken:
        grader_error = GRADER_FAULT
        logs = [e.pytest_log[-4000:] for e in (broken or (ended if not tests else []))]
        details = "\n\n".join(errors + logs)
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
        grader_details=details,
        log_tail="\n".join(v for v in logs.values() if v.strip())[-4000:],
        log=raw_report.output_log, not_run=not_run,
        execution_time=elapsed, recordings=_recordings(data.get("recordings", {})),
        timed_out=any(e.timed_out for e in ended),
        startup_seconds=tuple(data.get("startup_seconds", ())),
        pacing={module: ModulePacing.from_dict(counts)
                for module, counts in data.get("pacing", {}).items()},
        bags=data.get("bags", {}),
        warnings=tuple(data.get("warnings", ())),
        strangers=tuple(sorted({uid for raw in raw_report.tests for uid in raw.strangers})),
        silent=bool(logs) and not any(v.strip() for v in logs.values()))


def _recordings(recorded: Mapping[str, Any]) -> dict[str, Recording]:
    """Each test module's recording, read back from what its child wrote
    (:meth:`~sim.recorder.Recording.to_dict`). One that cannot be read is left out, as
    before: the report then draws that run not at all, and the grade does not change."""
    recordings = {}
    for module, data in recorded.items():
        try:
            recordings[module] = Recording.from_dict(data)
        except (AttributeError, KeyError, TypeError, ValueError):  # not a recording's shape
            continue
    return recordings


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
