"""Exercise files (``assignments/<id>/exercise.yaml``) parsed into frozen dataclasses."""

from __future__ import annotations

import ast
import dataclasses
from fractions import Fraction
from pathlib import Path
from typing import Literal

from autograder.core.names import unknown_exercise
from autograder.i18n import _, content_text
from content import ContentError, FieldValueError, build, load_document
from content.course import course_root
from sim.pacing import DEFAULT_CLOCK_HZ, DEFAULT_CPU_BUDGET


def _doc(text: str) -> dict[str, str]:
    return {"doc": text}


@dataclasses.dataclass(frozen=True)
class Limits:
    """Resource limits for the student's process."""

    wall_seconds: float = dataclasses.field(default=120.0, metadata=_doc(
        "Wall time one student process may run before it is stopped."))
    cpu_seconds: int = dataclasses.field(default=60, metadata=_doc(
        "CPU seconds one student process may use (RLIMIT_CPU)."))
    memory_mb: int = dataclasses.field(default=2048, metadata=_doc(
        "Address space of the student process in MiB (RLIMIT_AS; an rclpy node maps ~650)."))
    processes: int = dataclasses.field(default=128, metadata=_doc(
        "Processes and threads the submission may hold at once (pids cgroup, RLIMIT_NPROC)."))
    open_files: int = dataclasses.field(default=256, metadata=_doc(
        "Open file descriptors (RLIMIT_NOFILE)."))
    file_size_mb: int = dataclasses.field(default=16, metadata=_doc(
        "Largest file the submission may write (RLIMIT_FSIZE)."))
    output_kb: int = dataclasses.field(default=512, metadata=_doc(
        "Output kept from the student's stdout and stderr; the rest is counted and dropped."))


@dataclasses.dataclass(frozen=True)
class Exercise:
    """One exercise: what the student writes and how it is graded."""

    id: str = dataclasses.field(metadata=_doc("Stable id, also the folder name."))
    title: str = dataclasses.field(metadata=_doc("Title a student reads (translated)."))
    file: str = dataclasses.field(metadata=_doc("File name the student submits."))
    node: str = dataclasses.field(metadata=_doc("Name of the node the file must create."))
    summary: str = dataclasses.field(default="", metadata=_doc("One-sentence summary."))
    points: int = dataclasses.field(default=0, metadata=_doc(
        "Total points; must equal the sum of the tests' points (0: not checked)."))
    pass_mark: float = dataclasses.field(default=0.7, metadata=_doc(
        "Fraction of the points needed to pass."))
    core: tuple[str, ...] = dataclasses.field(default=(), metadata=_doc(
        "Names of the core tests: the chapter's central idea and the robot's safety. A "
        "grading passes only with every one of them passed and the points at the pass mark."))
    world: str = dataclasses.field(default="empty_room", metadata=_doc(
        "World the tests run in: a name under sim/worlds or a path relative to the exercise."))
    cmd_vel_type: Literal["Twist", "TwistStamped"] | None = dataclasses.field(
        default=None, metadata=_doc(
            "Message type the robot takes on /cmd_vel, overriding the world's: Twist (the "
            "textbook's code) or TwistStamped (Jazzy's TurtleBot3 and its Gazebo bridge)."))
    real_time_factor: float = dataclasses.field(default=1.0, metadata=_doc(
        "Pace of simulation time against wall time (0: as fast as the graph keeps up)."))
    clock_hz: float = dataclasses.field(default=DEFAULT_CLOCK_HZ, metadata=_doc(
        "Most /clock messages per wall second. Jazzy's MultiThreadedExecutor keeps a 10 Hz "
        "sim-time timer exact at 20 Hz but stutters from about 50 Hz."))
    cpu_budget: float = dataclasses.field(default=DEFAULT_CPU_BUDGET, metadata=_doc(
        "CPU seconds the student's process may use after a clock tick before the world "
        "moves on without it, beyond which it draws on a reserve of up to 2 s that ticks "
        "it spends idle pay back. Jazzy's MultiThreadedExecutor spins while it hands "
        "callbacks to its threads (docs/students/exercises.md): raise this for "
        "multi-threaded nodes; a busy loop then slows the world by this much per tick."))
    startup_timeout: float = dataclasses.field(default=20.0, metadata=_doc(
        "Wall seconds the node has to appear on the ROS graph after its process starts."))
    time_limit: float = dataclasses.field(default=300.0, metadata=_doc(
        "Wall seconds for a whole grading run; past it the run is stopped."))
    hidden_visibility: Literal["hidden", "after_published"] = dataclasses.field(
        default="after_published", metadata=_doc(
            "How hidden tests show in Gradescope: 'after_published' or 'hidden'."))
    limits: Limits = dataclasses.field(default_factory=Limits, metadata=_doc(
        "Resource limits of the student's process."))
    folder: Path = dataclasses.field(default=Path("."), metadata=_doc(
        "Set by the loader: the exercise's folder."))

    def __post_init__(self) -> None:
        if not 0 < self.pass_mark <= 1:
            raise FieldValueError(_("pass_mark must be above 0 and at most 1"), "pass_mark")
        if len(set(self.core)) != len(self.core):
            raise FieldValueError(_("core names a test more than once"), "core")

    @property
    def localized_title(self) -> str:
        """The title in the active language (``content`` catalog, ``exercise:<id>:title``)."""
        return content_text(f"exercise:{self.id}:title", self.title)

    @property
    def pass_fraction(self) -> Fraction:
        return Fraction(str(self.pass_mark))

    @property
    def public_tests(self) -> Path:
        return self.folder / "tests" / "public"

    @property
    def hidden_tests(self) -> Path:
        return self.folder / "tests" / "hidden"

    @property
    def starter(self) -> Path:
        return self.folder / "starter" / self.file

    @property
    def solution(self) -> Path:
        return self.folder / "solution" / self.file


def test_names(exercise: Exercise) -> frozenset[str]:
    """The names of the exercise's test functions, public and hidden (read, not imported)."""
    names: set[str] = set()
    for path in sorted(exercise.folder.glob("tests/**/test_*.py")):
        try:
            tree = ast.parse(path.read_text(encoding="utf-8"))
        except SyntaxError:
            continue
        names.update(node.name for node in ast.walk(tree)
                     if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
                     and node.name.startswith("test"))
    return frozenset(names)


def assignments_dir() -> Path:
    return course_root() / "assignments"


def load_exercise(folder: Path) -> Exercise:
    """Load ``folder/exercise.yaml``; a malformed file is a ContentError naming file and line."""
    path = folder / "exercise.yaml"
    doc = load_document(path)
    if isinstance(doc.data, dict) and "folder" in doc.data:
        raise doc.error(_("set by the loader, not in the file"), "folder")
    exercise = build(Exercise, doc, doc.data)
    if exercise.id != folder.name:
        raise doc.error(_("must equal the folder name {folder!r}").format(folder=folder.name),
                        "id")
    return dataclasses.replace(exercise, folder=folder.resolve())


def list_exercises() -> list[Exercise]:
    root = assignments_dir()
    if not root.is_dir():
        return []
    return [load_exercise(p) for p in sorted(root.iterdir()) if (p / "exercise.yaml").exists()]


def load_each_exercise() -> tuple[list[Exercise], list[ContentError]]:
    """Every exercise that loads, and the error of each whose file does not: one bad file
    is one problem, not every exercise's."""
    root = assignments_dir()
    found, errors = [], []
    for folder in sorted(root.iterdir()) if root.is_dir() else []:
        if (folder / "exercise.yaml").exists():
            try:
                found.append(load_exercise(folder))
            except ContentError as exc:
                errors.append(exc)
    return found, errors


def find_exercise(name: str) -> Exercise:
    """An exercise by id, or by the path of its folder."""
    candidate = Path(name)
    if (candidate / "exercise.yaml").exists():
        return load_exercise(candidate)
    folder = assignments_dir() / name
    if not (folder / "exercise.yaml").exists():
        raise unknown_exercise(name, [e.id for e in list_exercises()], folder)
    return load_exercise(folder)
