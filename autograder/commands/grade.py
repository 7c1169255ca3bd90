"""``check``, ``grade`` and ``grade-batch``: find the exercise, grade, write the outputs, say
what happened. Bad input is a :class:`~autograder.core.errors.UsageError` and our own
failure a :class:`~autograder.core.errors.GraderError`; the CLI turns them into exit codes.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import click

from autograder.core.errors import ContentError, GraderError, UsageError
from autograder.i18n import _, get_language, ngettext

if TYPE_CHECKING:
    from autograder.core.exercise import Exercise
    from autograder.core.results import RunResult

GradeOne = Callable[[Path], "RunResult"]
"""Grades (or scores) one student's entry: their folder or file."""
Extra = Callable[["RunResult", Path], None]
"""Writes a student's files beside the batch's ``results.json``."""


def exercise(name: str) -> Exercise:
    """The exercise ``name`` (an id or a folder); a UsageError naming the file otherwise."""
    from autograder.core.exercise import find_exercise

    try:
        return find_exercise(name)
    except ContentError as exc:
        raise UsageError(str(exc)) from None


def exercise_or_none(item: str) -> Exercise | None:
    """The exercise ``item`` names, or None (a quiz, or nothing)."""
    try:
        return exercise(item)
    except UsageError:
        return None


def refuse_unofficial(option: str) -> None:
    """A grader error, naming why, where this machine cannot give an official grade (the
    student's program would run as the grader's user): recipes that produce grades for a
    gradebook never hand out a grade a program could have changed."""
    from autograder.sandbox.isolation import detect

    isolation = detect()
    if not isolation.official:
        raise GraderError(_(
            "This machine cannot give official grades ({reason}): a student's program would "
            "run as the grader's user and could change its result. Grade as root (see "
            "docs/operators/security.md), or pass {option} to grade anyway, unofficially.").format(
            reason=_(isolation.reason), option=option))


def check_or_grade(exercise_id: str, submission: Path, hidden: bool,
                   outputs: dict[str, Path | None], rtf: float | None, domain: int | None,
                   record: Path | None = None, module_jobs: int | str = "auto",
                   require_official: bool = False, verbose: bool = False) -> None:
    """Grade ``submission`` (with the hidden tests when ``hidden``), printing each test as it
    ends, then the summary; write each requested output format (``outputs``)."""
    from autograder.commands.ending import Stopped
    from autograder.commands.written import say_written
    from autograder.core.report import RawTest
    from autograder.core.submission import SubmissionNotFound, check
    from autograder.grading.run import grade, result_of
    from autograder.render.live import LiveLines, terminal_style
    from autograder.render.terminal import for_terminal, heading, rtl_notice, to_terminal

    found = exercise(exercise_id)
    try:  # a link, a FIFO, not a node Python runs: the student's error, said first
        check(submission, found.file)
    except SubmissionNotFound as exc:
        raise UsageError(str(exc)) from None
    if require_official:
        refuse_unofficial("--no-require-official")
    color, in_place = terminal_style(sys.stdout)
    # Every test line once, on stdout as the tests end; the summary after them adds the
    # failures and the score (and the lines of tests that never ended).
    live = LiveLines(lambda text: click.echo(text, nl=False), color, in_place)

    def running(now: list[RawTest]) -> None:
        live.running_now([(raw.nodeid, raw.label) for raw in now])

    notice = rtl_notice(html=outputs.get("html"))
    if notice:
        click.echo(notice, err=True)
    click.echo(for_terminal(_("Grading {file} for {exercise} in the simulator...").format(
        file=submission, exercise=found.id)), err=True)
    click.echo(heading(found.id, found.localized_title, color) + "\n")
    try:
        result = grade(found, submission, hidden=hidden, domain=domain, real_time_factor=rtf,
                       progress=lambda raw: live.done(result_of(raw)), running=running,
                       record=record, module_jobs=module_jobs)
    except Stopped as exc:  # what the grading started is stopped and removed by now
        live.close()
        click.echo(for_terminal(_("The grading was stopped ({signal}) before it finished: "
                                  "no score, and no file written.").format(signal=exc.name)),
                   err=True)
        raise
    finally:
        live.close()
    # The files first: whatever happens to stdout (a pipe closed early), they are written.
    written = write_outputs(result, outputs, found.folder)
    click.echo(to_terminal(result, color=color, shown=live.shown, with_heading=False,
                           verbose=verbose))
    _say_recorded(result, record)
    say_written(written)
    if result.grader_error:
        raise GraderError(result.grader_error)


def _say_recorded(result: RunResult, record: Path | None) -> None:
    """Where ``--record`` put the bags, and any warning about them (on stderr)."""
    from autograder.render.terminal import for_terminal

    bags = result.bags
    if record is not None and bags:
        click.echo(for_terminal(ngettext(
            "{count} recording (rosbag2, MCAP) written to {path}",
            "{count} recordings (rosbag2, MCAP) written to {path}", len(bags)).format(
            count=len(bags), path=record)), err=True)
    for warning in result.warnings:
        click.echo(for_terminal(_("Warning: {message}").format(message=warning)), err=True)


def write_outputs(result: RunResult, outputs: dict[str, Path | None],
                  folder: Path) -> list[tuple[str, Path]]:
    """Write each requested output format of ``result`` (``--results``, ``--html``, ...:
    see :mod:`autograder.render`); with ``--results FILE``, the programs' whole output goes
    to FILE with suffix ``.log`` (``log`` names another file for it). Each (format, path)
    written, in order."""
    from autograder.core.files import write_atomically
    from autograder.core.output_budget import log_beside
    from autograder.render import formats

    outputs = dict(outputs)
    results = outputs.get("results")
    if results is not None and result.kind == "exercise":
        outputs.setdefault("log", log_beside(results))
    written = []
    for name, path in outputs.items():
        if path is None:
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        text = result.log if name == "log" else formats()[name].render(result, folder)
        write_atomically(path, text)
        written.append((name, path))
    return written


def grade_batch(item: str, submissions: Path, jobs: int | str, csv_path: Path,
                out: Path | None, shard: str | None, record: Path | None,
                module_jobs: int | str | None, allow_unofficial: bool) -> None:
    """Grade every student's submission for an exercise, or score every answers file for a
    quiz, into ``out`` and the gradebook ``csv_path`` (see ``grade-batch --help``)."""
    from autograder.commands.batch import parse_shard, run_batch, students
    from autograder.core.results import number

    if exercise_or_none(item) is not None:
        if not allow_unofficial:
            refuse_unofficial("--allow-unofficial")
        _close_class(submissions, out or Path("grades") / item)

    try:
        share = parse_shard(shard) if shard else None
    except ValueError:
        raise UsageError(_("--shard must be I/N with `1 <= I <= N`, got {value}").format(
            value=shard)) from None
    out = out or Path("grades") / item
    if jobs == "auto" and exercise_or_none(item) is None:
        jobs = 1  # a quiz scores in milliseconds, in this process: nothing to share
    if module_jobs is None:  # several gradings at once already keep the cores busy
        module_jobs = "auto" if jobs == 1 else 1
    grade_one, suffix, extra = batch_item(item, record, module_jobs)

    def progress(student: str, result: RunResult | None) -> None:
        if result is None:
            click.echo(_("{student}: already graded").format(student=student), err=True)
        else:
            # Decimals, as the gradebook has them (20/3 points is 6.6667, not "20/3").
            click.echo(f"{student}: {number(result.score)}/{number(result.max_score)}",
                       err=True)

    if jobs == "auto":
        from autograder.grading.capacity import auto_chooser

        jobs = auto_chooser(lambda line: click.echo(line, err=True))
    rows = run_batch(students(submissions, suffix), grade_one, out, csv_path, jobs=jobs,
                     shard=share, extra=extra, progress=progress)
    click.echo(ngettext("{count} row in {path}", "{count} rows in {path}", len(rows)).format(
        count=len(rows), path=csv_path))


def _close_class(submissions: Path, out: Path) -> None:
    """Isolation by user: no namespace hides the other students' submissions and reports
    from a student's program, so their folders are closed to other users."""
    from autograder.sandbox.isolation import close_to_others, detect

    if detect().mode == "user":
        out.mkdir(parents=True, exist_ok=True)
        close_to_others([submissions, out])


def batch_item(item: str, record: Path | None = None, module_jobs: int | str = "auto",
               ) -> tuple[GradeOne, str | None, Extra | None]:
    """How to grade one student's entry for an exercise or a quiz: the grading function,
    the suffix of an entry's file (None: any), and what else to write per student
    (``record``: a folder for each student's bags, exercises only; ``module_jobs``: see
    :func:`autograder.grading.run.grade`)."""
    from autograder.core.names import UnknownName, unknown_item
    from autograder.grading.run import grade
    from autograder.quiz.catalog import find_quiz
    from autograder.quiz.scoring import read_answers, score
    from autograder.render import formats

    found = exercise_or_none(item)
    if found is not None:
        graded = found

        def extra(result: RunResult, folder: Path) -> None:
            # Every format with a file per student; results.json is the batch's own
            # (written last: it marks the student done).
            files: dict[str, Path | None] = {
                f.name: folder / f.batch_file for f in formats().values()
                if f.batch_file and f.name != "results"}
            write_outputs(result, {**files, "log": folder / "output.log"}, graded.folder)

        def grade_one(path: Path) -> RunResult:
            # The student's name as `students()` gives it: a folder's name, a file's stem.
            student = path.name if path.is_dir() else path.stem
            return grade(graded, path, record=record / student if record else None,
                         module_jobs=module_jobs)  # type: ignore[arg-type]

        return grade_one, None, extra
    if record is not None:
        raise UsageError(_("--record records exercise gradings, not quizzes"))
    try:
        quiz = find_quiz(item).quiz
    except UnknownName as exc:  # neither: the one meant among both kinds
        from autograder.core.exercise import list_exercises
        from autograder.quiz.catalog import load_all

        raise UsageError(str(unknown_item(
            item, [e.id for e in list_exercises()], [q.quiz.id for q in load_all()],
            exc.path))) from None
    except ContentError as exc:
        raise UsageError(str(exc)) from None

    def score_one(path: Path) -> RunResult:
        try:
            return score(quiz, read_answers(path, quiz), get_language())
        except ContentError:
            return score(quiz, {}, get_language())  # an unreadable answers file scores 0

    return score_one, ".json", None
