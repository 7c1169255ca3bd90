"""What ``autograder validate`` requires of an exercise beyond loading: both READMEs with
their hand-run section and a grading table that is the tests' own, test modules pytest can
collect together, the title translated, and (in a course that keeps proofs in ``tests/``)
its proof. Each problem names the file and the line; docs/instructors/writing-exercises.md
says how to meet each."""

from __future__ import annotations

import ast
import dataclasses
import re
from collections.abc import Callable
from pathlib import Path

import yaml

from autograder.commands.scan_readme import check_scan_readme
from autograder.core.errors import ContentError
from autograder.core.exercise import Exercise
from autograder.i18n import _, translations
from autograder.i18n.tools import Problem

# Each README, in its language: the heading of the section on running the node by hand.
READMES = {"README.md": ("en", "### Trying your node by hand", "**core**"),
           "README.ur.md": ("ur", "### اپنے نوڈ کو ہاتھ سے آزمانا", "**بنیادی**")}
# A grading table's simulation seconds for a test timed on the wall clock (a process's
# exit), in every README's language: the words the Urdu READMEs use too.
WALL_TIME = "wall time"
_RUN = re.compile(r"autograder sim run --world (\S+) --node (\S+)")
_TEST_WORLD = re.compile(r'mark\.world\("([\w.]+)"\)|^WORLD = "([\w.]+)"', re.M)


@dataclasses.dataclass(frozen=True)
class GradedTest:
    """A test as a student sees it graded, read from its file (not imported)."""

    name: str
    label: str
    points: int | None
    visibility: str  # public | hidden
    path: Path
    line: int


def graded_tests(exercise: Exercise) -> list[GradedTest]:
    found = []
    for path in sorted(exercise.folder.glob("tests/*/test_*.py")):
        try:
            tree = ast.parse(path.read_text(encoding="utf-8"))
        except SyntaxError:
            continue  # the grading names it
        for node in tree.body:
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) \
                    and node.name.startswith("test"):
                points = next((d.args[0].value for d in node.decorator_list
                               if isinstance(d, ast.Call) and d.args
                               and getattr(d.func, "attr", "") == "points"
                               and isinstance(d.args[0], ast.Constant)), None)
                label = ((ast.get_docstring(node) or "").strip().splitlines() or [""])[0]
                found.append(GradedTest(node.name, label.strip(), points,
                                        "public" if path.parent.name == "public" else "hidden",
                                        path, node.lineno))
    return found


def check_exercise(exercise: Exercise, root: Path) -> list[Problem]:
    """Every problem of this kind in one exercise."""
    problems = _modules(exercise)
    if exercise.public_tests.is_dir() and not any(exercise.public_tests.glob("test_*.py")):
        problems.append(Problem(exercise.public_tests, None, _(
            "no public test: students get the `test_*.py` files here, and `autograder check` "
            "runs them")))
    tests = graded_tests(exercise)
    for name, (lang, heading, core_mark) in READMES.items():
        path = exercise.folder / name
        if not path.exists():
            problems.append(Problem(exercise.folder / "exercise.yaml", None, _(
                "{readme} is missing: every exercise has a README in each language "
                "({languages})").format(readme=path, languages=", ".join(READMES))))
            continue
        lines = path.read_text(encoding="utf-8").splitlines()
        problems += _hand_run(exercise, path, lines, heading)
        problems += _table(exercise, tests, path, lines, core_mark, _translator(root, lang))
        problems += check_scan_readme(exercise, path, "\n".join(lines))
    problems += _translated(exercise, root) + _labels_translated(tests, root)
    if (root / "tests").is_dir():
        problems += _proof(exercise, root)
    return problems


def _modules(exercise: Exercise) -> list[Problem]:
    """Test module names unique across tests/: pytest imports each by its base name."""
    seen: dict[str, Path] = {}
    problems = []
    for path in sorted(exercise.folder.glob("tests/**/*.py")):
        if path.name in ("conftest.py", "__init__.py"):
            continue
        if path.name in seen:
            problems.append(Problem(path, None, _(
                "{name} is also {other}: pytest cannot collect two test modules of one "
                "name; rename one").format(name=path.name, other=seen[path.name])))
        seen.setdefault(path.name, path)
    return problems


def _graded_worlds(exercise: Exercise) -> set[str]:
    named = {exercise.world}
    for module in (exercise.folder / "tests").rglob("test_*.py"):
        named |= {a or b for a, b in _TEST_WORLD.findall(module.read_text(encoding="utf-8"))}
    return {f"mydir/{w}" if (exercise.folder / w).is_file() else w for w in named}


def _hand_run(exercise: Exercise, path: Path, lines: list[str],
              heading: str) -> list[Problem]:
    problems = []
    if heading not in lines:
        problems.append(Problem(path, None, _(
            "no section {heading!r}: say how to run the node by hand").format(
            heading=heading)))
    runs = [(n, m) for n, line in enumerate(lines, 1) for m in _RUN.finditer(line)]
    if not runs:
        problems.append(Problem(path, None, _(
            "no hand run: show `autograder sim run --world {world} --node mydir/{file}`"
            ).format(world=exercise.world, file=exercise.file)))
    worlds = _graded_worlds(exercise)
    for line, match in runs:
        world, node = match.groups()
        if node != f"mydir/{exercise.file}" or world not in worlds:
            problems.append(Problem(path, line, _(
                "the hand run names {world} and {node}: it runs `mydir/{file}` in a world the "
                "exercise is graded in ({worlds})").format(
                world=world, node=node, file=exercise.file,
                worlds=", ".join(sorted(worlds)))))
    return problems


def _translator(root: Path, lang: str) -> Callable[[str], str]:
    """Labels in ``lang`` as the course ``root`` translates them (its catalog, else the
    package's), whichever course is in use."""
    from autograder.i18n.tools import read_catalog

    po = root / "locales" / lang / "LC_MESSAGES" / "messages.po"
    if lang == "en" or not po.exists():
        return translations(lang).gettext
    try:
        catalog = read_catalog(po, lang)
    except ContentError:
        return translations(lang).gettext

    def gettext(text: str) -> str:
        found = catalog.get(text)
        return str(found.string) if found is not None and found.string and not found.fuzzy \
            else text

    return gettext


def _rows(lines: list[str]) -> tuple[int | None, dict[str, tuple[int, tuple[str, ...]]]]:
    """The grading table (headed ``| test |``): the line it starts on, and its rows by
    label (backticks dropped): each row's line number and its other cells."""
    start = next((n for n, line in enumerate(lines) if line.startswith("| test |")), None)
    rows: dict[str, tuple[int, tuple[str, ...]]] = {}
    if start is None:
        return None, rows
    for n in range(start + 2, len(lines)):
        if not lines[n].startswith("|"):
            break
        cells = tuple(c.strip() for c in lines[n].strip().strip("|").split("|"))
        rows[cells[0].replace("`", "")] = (n + 1, cells[1:])
    return start, rows


def _label(test: GradedTest, gettext: Callable[[str], str]) -> str:
    return gettext(test.label).replace("`", "") if test.label else test.name


def _table(exercise: Exercise, tests: list[GradedTest], path: Path, lines: list[str],
           core_mark: str, gettext: Callable[[str], str]) -> list[Problem]:
    """The grading table (headed ``| test |``) is each test's label in the README's
    language, its points, public or hidden, and its core mark; one row per test. A fifth
    column, if the table has one, gives the simulation seconds the test takes to its
    verdict (the exercise's proofs hold it to the reference's gradings), or ``wall time``
    for one timed on the wall clock."""
    start, rows = _rows(lines)
    if start is None:
        return [Problem(path, None, _(
            "no grading table: a table headed `| test |` with a row per test (its label, "
            "points, public or hidden, core)"))]
    problems = []
    for test in tests:
        label = _label(test, gettext)
        wanted = (str(test.points), test.visibility,
                  core_mark if test.name in exercise.core else "")
        line, cells = rows.pop(label, (None, None))
        if cells is None:
            problems.append(Problem(path, start + 1, _(
                "the grading table has no row for {test} ({label!r})").format(
                test=test.name, label=label)))
        elif cells[:3] != wanted:
            problems.append(Problem(path, line, _(
                "the row of {test} says {found}; its test says {wanted}").format(
                test=test.name, found=" | ".join(cells[:3]), wanted=" | ".join(wanted))))
        elif len(cells) > 3 and not _seconds(cells[3]) and cells[3] != WALL_TIME:
            problems.append(Problem(path, line, _(
                "the row of {test} gives {found!r} as its simulation seconds: a number, "
                "such as 2.5, or {wall!r} for a test timed on the wall clock").format(
                test=test.name, found=cells[3], wall=WALL_TIME)))
    for label, (line, _cells) in rows.items():
        problems.append(Problem(path, line, _(
            "the grading table's row {label!r} is no test's label").format(label=label)))
    return problems


def _seconds(cell: str) -> bool:
    return re.fullmatch(r"\d+(\.\d+)?", cell) is not None


def simulation_seconds(exercise: Exercise,
                       root: Path) -> dict[str, dict[str, float | str | None]]:
    """What each README's grading table gives as each test's simulation seconds, by README
    and test name: a number, :data:`WALL_TIME`, or None (no such cell, or neither)."""
    tests = graded_tests(exercise)
    given: dict[str, dict[str, float | str | None]] = {}
    for name, (lang, _heading, _core) in READMES.items():
        path = exercise.folder / name
        if not path.exists():
            continue
        gettext = _translator(root, lang)
        _start, rows = _rows(path.read_text(encoding="utf-8").splitlines())
        given[name] = {}
        for test in tests:
            cells = rows.get(_label(test, gettext), (0, ()))[1]
            seconds = cells[3] if len(cells) > 3 else ""
            given[name][test.name] = float(seconds) if _seconds(seconds) else (
                WALL_TIME if seconds == WALL_TIME else None)
    return given


def _translated(exercise: Exercise, root: Path) -> list[Problem]:
    """The title has its translation in each content catalog the course keeps."""
    from autograder.i18n.tools import read_catalog

    problems = []
    for po in sorted((root / "locales").glob("*/LC_MESSAGES/content.po")):
        lang = po.parent.parent.name
        try:
            catalog = read_catalog(po, lang)
        except Exception:  # a malformed catalog is the lint's to report
            continue
        for field in ("title", "summary"):
            text = getattr(exercise, field)
            found = catalog.get(text, context=f"exercise:{exercise.id}:{field}")
            if text and (found is None or not found.string or found.fuzzy):
                problems.append(Problem(po, found.lineno if found else None, _(
                    "{lang}: no translation of the {field} of {exercise} ({text!r})").format(
                    lang=lang, field=field, exercise=exercise.id, text=text)))
    return problems


def _labels_translated(tests: list[GradedTest], root: Path) -> list[Problem]:
    """Each test's label has its translation in each messages catalog the course keeps: a
    student grading in Urdu reads it (``i18n extract`` adds new labels to the catalogs
    only when it is run; this says so before)."""
    from autograder.i18n.tools import read_catalog

    problems = []
    for po in sorted((root / "locales").glob("*/LC_MESSAGES/messages.po")):
        lang = po.parent.parent.name
        try:
            catalog = read_catalog(po, lang)
        except Exception:  # a malformed catalog is i18n check's to report
            continue
        for test in tests:
            found = catalog.get(test.label) if test.label else None
            if test.label and (found is None or not found.string or found.fuzzy):
                problems.append(Problem(test.path, test.line, _(
                    "{lang}: the label of {test} has no translation in {catalog}").format(
                    lang=lang, test=test.name, catalog=po)))
    return problems


def _proof(exercise: Exercise, root: Path) -> list[Problem]:
    """tests/test_grading_<id>.py declares the proof; tests/submissions/<id>/ holds a
    known-bad variant for each core test (tests/proving.py checks the rest)."""
    module = root / "tests" / f"test_grading_{exercise.id}.py"
    problems = []
    if not module.exists() or f'PROOF = Proof("{exercise.id}"' not in module.read_text(
            encoding="utf-8"):
        problems.append(Problem(module, None, _(
            "no proof: this module declares `PROOF = Proof({id!r})` (`autograder new "
            "exercise` writes one)").format(id=exercise.id)))
    folder = root / "tests" / "submissions" / exercise.id
    lost: set[str] = set()
    for expect in sorted(folder.glob("*/expect.yaml")):
        try:
            data = yaml.safe_load(expect.read_text(encoding="utf-8"))
        except yaml.YAMLError:
            continue  # the proof's own checks name it
        if isinstance(data, dict) and data.get("kind") in ("mutant", "broken"):
            lost |= set(data.get("loses") or ())
    if not lost:
        problems.append(Problem(folder, None, _(
            "no known-bad submission: a folder here with `expect.yaml` (`kind: mutant`, "
            "`loses: [...]`) and a patch of the solution")))
    for name in exercise.core:
        if lost and name not in lost:
            problems.append(Problem(folder, None, _(
                "no known-bad submission loses the core test {test}").format(test=name)))
    return problems
