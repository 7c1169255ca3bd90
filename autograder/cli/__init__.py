"""The ``autograder`` command: a thin click layer over plain functions (``commands/``).

Exit codes: 0 when the command completed (a grading, whatever the score); 1 when a check
found problems; 2 for bad input (a missing file, an unknown exercise, a malformed content
file); 3 when the autograder itself failed (:mod:`autograder.cli.exits`).
"""

from __future__ import annotations

import json
import signal
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import click

from autograder import __version__
from autograder.cli import click_words
from autograder.cli.exits import GraderFault, UsageProblem, report_problems
from autograder.core.dumpable import not_dumpable
from autograder.core.errors import ContentError, GraderError, UsageError
from autograder.core.pid1 import reap_as_init
from autograder.i18n import LANGUAGES, _, ngettext, set_language

if TYPE_CHECKING:
    from autograder.core.exercise import Exercise

click_words.speak()  # click's own words (usage errors) in the active language, from here on

F = TypeVar("F", bound=Callable[..., Any])


def _sim_cli() -> click.Command:
    from autograder.cli.sim_node import add_node_options
    from autograder.commands.ending import until_stopped
    from sim.cli import sim_cli

    add_node_options(sim_cli.commands["run"])  # sim knows nothing of students' nodes
    # Run until stopped: a closed pipe stops them as Ctrl-C does (commands.ending).
    until_stopped(sim_cli.commands["run"], lambda options: options["duration"] is None)
    until_stopped(sim_cli.commands["drive"], lambda options: options["seconds"] is None)
    return sim_cli


def _quiz_cli() -> click.Command:
    from autograder.cli.quiz import quiz_cli
    from autograder.commands.ending import until_stopped

    until_stopped(quiz_cli.commands["serve"], lambda options: True)
    return quiz_cli


def _i18n_cli() -> click.Command:
    from autograder.cli.i18n import i18n_cli

    return i18n_cli


class LazyGroup(click.Group):
    """A group whose sub-groups are imported when they are called: ``sim`` brings numpy,
    pymunk and the world, ``quiz`` and ``i18n`` Babel, and ``grade`` and ``check`` need none
    of it, in time or in the grader's memory held all through a grading."""

    lazy = {"sim": _sim_cli, "quiz": _quiz_cli, "i18n": _i18n_cli}

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted([*super().list_commands(ctx), *self.lazy])

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name in self.lazy and cmd_name not in self.commands:
            self.add_command(self.lazy[cmd_name](), cmd_name)
        return super().get_command(ctx, cmd_name)

    def main(self, *args: Any, **kwargs: Any) -> Any:
        """Every command ends cleanly however it is stopped: a signal, a dead parent, a
        closed pipe (:mod:`autograder.commands.ending`)."""
        from autograder.commands import ending

        with ending.handled() as state:
            try:
                return super().main(*args, **kwargs)
            except SystemExit as exc:
                if state.signum in ending.ENDING_SIGNALS:
                    click.echo(_("Stopped by {signal}.").format(
                        signal=signal.Signals(state.signum).name), err=True)
                raise SystemExit(state.exit_status(exc.code)) from None

    def invoke(self, ctx: click.Context) -> Any:
        """The exit status of each exception family (:mod:`autograder.cli.exits`)."""
        from autograder.commands.ending import Stopped

        try:
            return super().invoke(ctx)
        except Stopped:  # not Ctrl-C: the status says which signal, not "Aborted!"
            ctx.exit(1)
        except (UsageError, ContentError) as exc:
            raise UsageProblem(str(exc)) from None
        except GraderError as exc:
            raise GraderFault(str(exc)) from None


@click.group(cls=LazyGroup)
@click.version_option(__version__, prog_name="autograder")
@click.option("--lang", type=click.Choice(LANGUAGES), default=None, envvar="AUTOGRADER_LANG",
              help="Language of what the platform prints (en, ur).")
def main(lang: str | None) -> None:
    """Grade rclpy exercises in a simulated ROS 2 world, and take quizzes."""
    not_dumpable()  # no program of our user traces (and so stops) or reads the grader
    reap_as_init()  # a container's first process reaps its orphans (core/pid1.py)
    if lang:
        set_language(lang)


def _exercise(name: str) -> Exercise:
    from autograder.commands.grade import exercise

    return exercise(name)


def _lang_option(func: F) -> F:
    """``--lang`` on a subcommand too (``autograder grade ... --lang ur``)."""

    def set_lang(ctx: click.Context, param: click.Parameter, value: str | None) -> None:
        if value:
            set_language(value)

    return click.option("--lang", type=click.Choice(LANGUAGES), default=None,
                        expose_value=False, is_eager=True, callback=set_lang,
                        help="Language of the feedback (en, ur).")(func)


VERBOSE = "autograder.verbose"
"""``ctx.meta`` key: ``--verbose`` was given (see :func:`_verbose_option`)."""


def _verbose_option(func: F) -> F:
    """``--verbose``: the instructor's technical lines (how the program was contained and
    bounded) instead of the student's sentence."""

    def remember(ctx: click.Context, param: click.Parameter, value: bool) -> None:
        ctx.meta[VERBOSE] = value

    return click.option("--verbose", "-v", is_flag=True, default=False, expose_value=False,
                        callback=remember,
                        help="Say how the program was contained in technical terms "
                             "(for instructors).")(func)


@main.command("list")
@click.option("--json", "as_json", is_flag=True, help="Print JSON for tools.")
def list_command(as_json: bool) -> None:
    """List the exercises and quizzes."""
    from autograder.core.exercise import load_each_exercise

    exercises, broken = load_each_exercise()  # a broken file is listed, the others too
    quizzes = _quizzes()
    if as_json:
        click.echo(json.dumps({
            "exercises": [{"id": e.id, "title": e.title, "file": e.file, "node": e.node,
                           "languages": list(LANGUAGES)} for e in exercises]
                         + [{"id": exc.path.parent.name, "error": str(exc)} for exc in broken],
            "quizzes": [{"id": q.id, "title": q.title, "languages": list(q.languages),
                         **({"error": q.error} if q.error else {})} for q in quizzes],
        }, ensure_ascii=False, indent=2))
        return
    click.echo(_("Exercises:"))
    for e in exercises:
        click.echo(f"  {e.id:<24} {e.localized_title}")
    for exc in broken:
        click.echo(f"  {exc.path.parent.name:<24} " + _("not loaded: {error}").format(
            error=exc))
    if quizzes:
        click.echo(_("Quizzes:"))
        for q in quizzes:
            click.echo(f"  {q.id:<24} " + (q.title if not q.error else _(
                "not loaded: {error}").format(error=q.error)))


def _quizzes() -> list:
    from autograder.quiz.catalog import list_quizzes

    try:
        return list_quizzes()
    except ContentError as exc:
        raise UsageProblem(str(exc)) from None


@main.command()
@click.argument("exercise")
@click.argument("directory", required=False, type=click.Path(path_type=Path))
def start(exercise: str, directory: Path | None) -> None:
    """Copy an exercise's starter code, README and own world file into DIRECTORY (default:
    the exercise id)."""
    from autograder.commands.start import start as copy_starter

    found, target, copied = copy_starter(exercise, directory)
    for path in copied:
        click.echo(_("created {path}").format(path=path))
    click.echo(_("Next: edit {file}, then run `autograder check {exercise} {file}`").format(
        file=target / found.file, exercise=found.id))


def _formats(func: F) -> F:
    """A ``--NAME FILE`` option per output format (autograder.render)."""
    from autograder.render import formats

    for found in reversed(formats().values()):
        func = click.option(f"--{found.name}", type=click.Path(path_type=Path, dir_okay=False),
                            help=found.help)(func)
    return func


_submission = click.argument("submission", type=click.Path(path_type=Path))
_rtf = click.option("--real-time-factor", "rtf", type=float, default=None,
                    help="Override the exercise's simulation pace.")
_domain = click.option("--domain", type=click.IntRange(0, 232), default=None,
                       help="ROS domain id (default: a free one, reserved for the run).")


class _CountOrAuto(click.ParamType):
    """``--jobs``, ``--module-jobs``: a number of things at once (1 to 64), or ``auto``;
    ``error`` gives the message for anything else (a function: translated when used)."""

    name = "N|auto"

    def __init__(self, error: Callable[[], str]) -> None:
        self._error = error

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> int | str:
        if isinstance(value, int) or value == "auto":
            return value
        try:
            jobs = int(value)
        except ValueError:
            jobs = 0
        if not 1 <= jobs <= 64:
            self.fail(self._error().format(value=value), param, ctx)
        return jobs


_MODULE_JOBS = _CountOrAuto(
    lambda: _("--module-jobs must be a number from 1 to 64 or auto, got {value}"))
_JOBS = _CountOrAuto(lambda: _("--jobs must be a number from 1 to 64 or auto, got {value}"))


_module_jobs = click.option(
    "--module-jobs", type=_MODULE_JOBS, default="auto", show_default=True,
    help="Test modules run at the same time within the grading, each in a child of its "
         "own on its own ROS domain; 'auto': one per module as far as the cores go. "
         "--domain means 1.")
_record = click.option("--record", type=click.Path(path_type=Path, file_okay=False),
                       default=None, help="Record each test module's ROS graph as a rosbag2 "
                       "bag (MCAP) in this folder.")


@main.command()
@click.argument("exercise")
@_submission
@_formats
@_rtf
@_domain
@_module_jobs
@_record
@_verbose_option
@_lang_option
def check(exercise: str, submission: Path, rtf: float | None, domain: int | None,
          module_jobs: int | str, record: Path | None, **outputs: Path | None) -> None:
    """Run the public tests of EXERCISE on SUBMISSION (for students)."""
    from autograder.commands.grade import check_or_grade

    check_or_grade(exercise, submission, False, outputs, rtf, domain, record, module_jobs,
                   verbose=click.get_current_context().meta.get(VERBOSE, False))


@main.command("grade")
@click.argument("exercise")
@_submission
@_formats
@_rtf
@_domain
@_module_jobs
@_record
@click.option("--require-official/--no-require-official", default=False, show_default=True,
              help="Refuse to grade (a grader fault, exit 3) where the grade could not be "
                   "official: the student's program would run as the grader's user. The "
                   "Gradescope bundle grades with it.")
@_verbose_option
@_lang_option
def grade_command(exercise: str, submission: Path, rtf: float | None, domain: int | None,
                  module_jobs: int | str, record: Path | None, require_official: bool,
                  **outputs: Path | None) -> None:
    """Run the public and hidden tests of EXERCISE on SUBMISSION (the student's .py file or a
    folder holding it)."""
    from autograder.commands.grade import check_or_grade

    check_or_grade(exercise, submission, True, outputs, rtf, domain, record, module_jobs,
                   require_official, verbose=click.get_current_context().meta.get(VERBOSE, False))


@main.command()
@click.argument("out", type=click.Path(path_type=Path, file_okay=False))
def release(out: Path) -> None:
    """Build what students get in OUT: starter code, READMEs, public tests and the tools to
    run them, quizzes as pages; no hidden tests, no solutions, no quiz keys."""
    from autograder.commands.release import build_release

    if out.exists():
        raise UsageProblem(_("{path} already exists").format(path=out))
    try:
        build_release(out)
    except ContentError as exc:
        raise UsageProblem(str(exc)) from None
    click.echo(_("release written to {path}").format(path=out))


@main.group()
def bundle() -> None:
    """Package an exercise's autograder for a grading service."""


@bundle.command("gradescope")
@click.argument("exercise")
@click.argument("zip_path", metavar="OUT.zip", type=click.Path(path_type=Path, dir_okay=False))
@click.option("--lang", "grade_lang", type=click.Choice(LANGUAGES), default="en",
              show_default=True, help="The language its feedback is given in.")
def bundle_gradescope(exercise: str, zip_path: Path, grade_lang: str) -> None:
    """A Gradescope autograder zip (setup.sh, run_autograder) for EXERCISE."""
    from autograder.commands.release import build_gradescope_bundle

    try:
        build_gradescope_bundle(_exercise(exercise), zip_path, grade_lang)
    except ContentError as exc:
        raise UsageProblem(str(exc)) from None
    click.echo(_("Gradescope autograder written to {path}; it grades in {language}.").format(
        path=zip_path, language=grade_lang))




@main.command("grade-batch")
@click.argument("item", metavar="EXERCISE_OR_QUIZ")
@click.argument("submissions", type=click.Path(path_type=Path, file_okay=False, exists=True))
@click.option("--jobs", type=_JOBS, default="auto", show_default=True,
              help="Gradings run at the same time (each on its own ROS domain), or 'auto': "
                   "grade the first student alone and choose from its CPU use and the "
                   "machine's cores and memory (quizzes: one at a time).")
@click.option("--csv", "csv_path", type=click.Path(path_type=Path, dir_okay=False),
              required=True, help="The gradebook CSV (merged into if it exists).")
@click.option("--out", type=click.Path(path_type=Path, file_okay=False), default=None,
              help="Folder of each student's reports (default: grades/EXERCISE).")
@click.option("--shard", default=None, metavar="I/N",
              help="Grade only share I of N (stable: by a hash of the student's name).")
@click.option("--record", type=click.Path(path_type=Path, file_okay=False), default=None,
              help="Record each student's grading as rosbag2 bags (MCAP) in RECORD/<student>.")
@click.option("--module-jobs", type=_MODULE_JOBS, default=None,
              help="Test modules run at the same time within each grading (default: auto "
                   "with --jobs 1, else 1: the gradings share the cores).")
@click.option("--allow-unofficial", is_flag=True, default=False,
              help="Grade exercises even where the grades cannot be official (the students' "
                   "programs would run as the grader's user); they say so.")
@_lang_option
def grade_batch(item: str, submissions: Path, jobs: int | str, csv_path: Path, out: Path | None,
                shard: str | None, record: Path | None, module_jobs: int | str | None,
                allow_unofficial: bool) -> None:
    """Grade every submission in SUBMISSIONS (one sub-folder or file per student), or score
    every answers file for a quiz. Resumable: graded students are skipped. Exercises are
    graded only where the grades are official, unless --allow-unofficial."""
    from autograder.commands.grade import grade_batch as run

    run(item, submissions, jobs, csv_path, out, shard, record, module_jobs, allow_unofficial)


@main.group("gradebook")
def gradebook_group() -> None:
    """Work with gradebook CSV files."""


@gradebook_group.command("merge")
@click.argument("out", type=click.Path(path_type=Path, dir_okay=False))
@click.argument("inputs", nargs=-1, required=True,
                type=click.Path(path_type=Path, dir_okay=False, exists=True))
def gradebook_merge(out: Path, inputs: tuple[Path, ...]) -> None:
    """Merge gradebooks (e.g. from shards) into OUT; a later file wins a duplicate row."""
    from autograder.commands import gradebook

    try:
        rows = gradebook.merge(*(gradebook.read(p) for p in inputs))
    except ContentError as exc:
        raise UsageProblem(str(exc)) from None
    gradebook.write(out, rows)
    click.echo(ngettext("{count} row in {path}", "{count} rows in {path}", len(rows)).format(
        count=len(rows), path=out))


@gradebook_group.command("export")
@click.option("--format", "fmt", type=click.Choice(["moodle", "canvas"]), required=True,
              help="The LMS gradebook layout: one row per student, a column per item.")
@click.argument("out", type=click.Path(path_type=Path, dir_okay=False))
@click.argument("inputs", nargs=-1, required=True,
                type=click.Path(path_type=Path, dir_okay=False, exists=True))
def gradebook_export(fmt: str, out: Path, inputs: tuple[Path, ...]) -> None:
    """Write OUT, the gradebooks INPUTS merged, as the CSV Moodle's or Canvas's gradebook
    imports (students named by their submission's folder: their LMS login)."""
    from autograder.commands import gradebook
    from autograder.commands.lms_export import export

    try:
        rows = gradebook.merge(*(gradebook.read(p) for p in inputs))
    except ContentError as exc:
        raise UsageProblem(str(exc)) from None
    count = export(out, rows, fmt)
    click.echo(ngettext("{count} student in {path}", "{count} students in {path}",
                        count).format(count=count, path=out))


@main.command()
@click.argument("kind", type=click.Choice(["github-student", "github-shards", "k8s-shards"]))
@click.option("--exercise", default="parameter_validation", show_default=True)
@click.option("--submission", default=".", show_default=True,
              help="Where the student's file is in their repository.")
@click.option("--shards", type=click.IntRange(1, 256), default=4, show_default=True)
@click.option("--platform-repo", default="https://github.com/COURSE/rclpy-autograder-release",
              show_default=True, help="Git URL pip installs the platform from.")
@click.option("--hidden-repo", default="COURSE/rclpy-hidden-tests", show_default=True,
              help="Private repository holding the course tree with hidden tests "
                   "(github-shards, k8s-shards).")
@click.option("--claim", default="grading-data", show_default=True,
              help="Kubernetes volume claim with submissions/ and out/.")
def workflow(kind: str, exercise: str, submission: str, shards: int, platform_repo: str,
             hidden_repo: str, claim: str) -> None:
    """Print a CI workflow: a student repository's grade-on-push (github-student), or a
    course's sharded batch grading (github-shards, k8s-shards).

    github-student runs the public tests only and names no secret: students can edit their
    repository's workflows. Hidden tests run in the course's private repository
    (github-shards, which pulls in the submissions), on Gradescope or on Kubernetes
    (k8s-shards)."""
    from autograder.commands.workflows import render_workflow

    click.echo(render_workflow(kind, exercise=exercise, submission=submission, shards=shards,
                               platform_repo=platform_repo, hidden_repo=hidden_repo,
                               claim=claim), nl=False)


@main.command()
@click.option("--grade/--no-grade", "run_gradings", default=True, show_default=True,
              help="Also grade every reference solution and starter.")
@click.option("--jobs", type=click.IntRange(1, 16), default=2, show_default=True)
@click.option("--course", type=click.Path(path_type=Path, file_okay=False, exists=True),
              default=None, help="The course tree (default: the one in use).")
def validate(run_gradings: bool, jobs: int, course: Path | None) -> None:
    """Check a whole course: exercise files, starters and solutions, worlds, quizzes and
    catalogs; the reference solutions score 100% and the starters below the pass mark."""
    from autograder.commands.validate import validate as check_course

    problems = check_course(course, run_gradings=run_gradings, jobs=jobs,
                            progress=lambda e: click.echo(_("grading {exercise}...").format(
                                exercise=e), err=True))
    report_problems(problems)
    click.echo(_("The course is valid."))


@main.group("new")
def new_group() -> None:
    """Scaffold an exercise or a quiz that validates as generated."""


def _scaffolded(make: Callable[[], Any]) -> None:
    try:
        scaffold = make()
    except ContentError as exc:
        raise UsageProblem(str(exc)) from None
    for path in scaffold.written:
        click.echo(_("wrote {path}").format(path=path))
    click.echo(_("Next:"))
    for number, step in enumerate(scaffold.next_steps, 1):
        click.echo(f"  {number}. {step}")


@new_group.command("exercise")
@click.argument("exercise_id", metavar="ID")
def new_exercise_command(exercise_id: str) -> None:
    """Scaffold assignments/ID/: exercise.yaml, both READMEs, starter, solution, public and
    hidden tests, and the proof in tests/ (docs/instructors/writing-exercises.md)."""
    from autograder.commands.new import new_exercise

    _scaffolded(lambda: new_exercise(exercise_id))


@new_group.command("quiz")
@click.argument("quiz_id", metavar="ID")
def new_quiz_command(quiz_id: str) -> None:
    """Scaffold quizzes/ID.yaml with each question type once, in English and Urdu."""
    from autograder.commands.new import new_quiz

    _scaffolded(lambda: new_quiz(quiz_id))


if __name__ == "__main__":
    main()
