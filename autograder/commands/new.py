"""``autograder new exercise ID`` and ``autograder new quiz ID``: scaffolds with every file an
exercise or a quiz needs, which pass ``autograder validate`` as they are generated.

An exercise gets ``exercise.yaml``, both READMEs with the sections the checks read (the
hand run, the grading table), a starter and a solution in the ros2/examples form, public
and hidden tests on the platform's fixtures, the Urdu of its title and summary in the
content catalog and, in a course that keeps its proofs in ``tests/``, the proof module and
a first known-bad variant. A quiz gets each question type once and its Urdu. The templates
are in ``autograder/templates/new/``; the walk-through is docs/instructors/writing-exercises.md.
"""

from __future__ import annotations

import dataclasses
import difflib
import re
from importlib import resources
from pathlib import Path

import yaml
from babel.messages.pofile import normalize

from autograder.core.errors import ContentError
from autograder.i18n import _
from content.course import course_root

EXERCISE_ID = re.compile(r"^[a-z][a-z0-9_]*$")
QUIZ_ID = re.compile(r"^[a-z][a-z0-9-]*$")
# The first known-bad variant: it greets wrongly, so it loses the core test and only that.
VARIANT = "wrong_greeting"
_RIGHT, _WRONG = "f'Hello, {msg.data}!'", "f'Hi {msg.data}'"


@dataclasses.dataclass(frozen=True)
class Scaffold:
    """What a scaffold wrote, and what its author fills in next."""

    written: tuple[Path, ...]
    next_steps: tuple[str, ...]


def _template(*parts: str) -> str:
    return (resources.files("autograder") / "templates" / "new").joinpath(*parts).read_text(
        encoding="utf-8")


def _fill(text: str, values: dict[str, str]) -> str:
    for token, value in values.items():
        text = text.replace(token, value)
    return text


def _write(path: Path, text: str, written: list[Path]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    written.append(path)


def _entry(context: str | None, english: str, urdu: str, comment: str, where: str) -> str:
    """One catalog entry, laid out as Babel writes them."""
    return (f"\n#. {comment}\n" if comment else "\n") + f"#: {where}\n" + (
            f"msgctxt {normalize(context, width=88)}\n" if context else "") + (
            f"msgid {normalize(english, width=88)}\n"
            f"msgstr {normalize(urdu, width=88)}\n")


def _catalog(root: Path, domain: str) -> Path | None:
    """The course's Urdu catalog of ``domain``: in its ``locales/``, else (a checkout of the
    platform) the package's own; None when it keeps none."""
    for folder in (root / "locales", root / "autograder" / "locales"):
        po = folder / "ur" / "LC_MESSAGES" / f"{domain}.po"
        if po.exists():
            return po
    return None


def _add_translations(root: Path, domain: str,
                      entries: list[tuple[str | None, str, str, str, str]],
                      written: list[Path]) -> None:
    """Append Urdu entries (context, English, Urdu, comment, file:line) to the course's
    catalog of ``domain``, at its end, skipping those it has."""
    po = _catalog(root, domain)
    if po is None:
        return
    text = po.read_text(encoding="utf-8")
    new = [_entry(*e) for e in entries
           if (f"msgctxt {normalize(e[0], width=88)}\n" if e[0] else
               f"\nmsgid {normalize(e[1], width=88)}\n") not in text]
    if new:
        po.write_text(text.rstrip("\n") + "\n" + "".join(new), encoding="utf-8")
        written.append(po)


def _test_strings(folder: Path, root: Path) -> list[tuple[int, str, str, str]]:
    """(line, English, comment, relative path) of every label and message of the exercise's
    tests, read by the extractor ``i18n extract`` uses."""
    from babel.messages.extract import DEFAULT_KEYWORDS

    from autograder.i18n.label_extract import extract_tests

    found = []
    for path in sorted(folder.glob("tests/**/*.py")):
        with path.open("rb") as fh:
            for line, _func, message, comments in extract_tests(
                    fh, DEFAULT_KEYWORDS, ("TRANSLATORS:",), {}):
                if isinstance(message, str):
                    found.append((line, message, ", ".join(comments),
                                  path.relative_to(root).as_posix()))
    return found


def _camel(name: str) -> str:
    return "".join(part.capitalize() for part in name.split("_"))


def new_exercise(exercise_id: str, root: Path | None = None) -> Scaffold:
    """Scaffold ``assignments/<id>/`` (and its proof) in the course ``root``."""
    root = root or course_root()
    folder = root / "assignments" / exercise_id
    if not EXERCISE_ID.match(exercise_id):
        raise ContentError(folder, _(
            "an exercise id is lower-case letters, digits and `_`, starting with a letter "
            "(it names the folder, the file and the node): {id!r}").format(id=exercise_id))
    if folder.exists():
        raise ContentError(folder, _("already exists: pick another id"))
    file = f"{exercise_id}.py"
    values = {"__TITLE_UR__": f"ہر نام کو سلام: {exercise_id}",
              "__TITLE__": f"{exercise_id}: greet every name", "__ID__": exercise_id,
              "__FILE__": file, "__NODE__": exercise_id, "__CLASS__": _camel(exercise_id)}
    written: list[Path] = []
    # Test basenames unique across tests/: pytest imports both folders' modules by name.
    public, hidden = f"test_{exercise_id}_public.py", f"test_{exercise_id}_hidden.py"
    for template, target in (("exercise.yaml.tmpl", "exercise.yaml"),
                             ("README.md.tmpl", "README.md"),
                             ("README.ur.md.tmpl", "README.ur.md"),
                             ("starter.py.tmpl", f"starter/{file}"),
                             ("solution.py.tmpl", f"solution/{file}"),
                             ("conftest.py.tmpl", "tests/conftest.py"),
                             ("test_public.py.tmpl", f"tests/public/{public}"),
                             ("test_hidden.py.tmpl", f"tests/hidden/{hidden}")):
        _write(folder / target, _fill(_template("exercise", template), values), written)
    where = f"assignments/{exercise_id}/exercise.yaml"
    document = yaml.safe_load((folder / "exercise.yaml").read_text(encoding="utf-8"))
    _add_translations(root, "content", [
        (f"exercise:{exercise_id}:title", document["title"], values["__TITLE_UR__"],
         "exercise title", f"{where}:4"),
        (f"exercise:{exercise_id}:summary", document["summary"],
         "کسی ٹاپک پر سنے گئے ہر نام کا جواب ایک سلام سے دیں۔", "exercise summary",
         f"{where}:5")], written)
    urdu = yaml.safe_load(_template("exercise", "messages.ur.yaml"))
    _add_translations(root, "messages", [
        (None, text, urdu[text], comment, f"{path}:{line}")
        for line, text, comment, path in _test_strings(folder, root)], written)
    steps = [_("Write the task in {readme} and {urdu}: the task, the topics, the hand run "
               "and the grading table (one row per test).").format(
        readme=folder / "README.md", urdu=folder / "README.ur.md"),
        _("Write the reference solution {solution}, then the starter {starter} from it, "
          "with `TODO` comments where the student's work goes.").format(
        solution=folder / "solution" / file, starter=folder / "starter" / file),
        _("Write the tests in {tests}: a docstring label, `@pytest.mark.points` and a "
          "`StudentFailure` with a hint for each; name the core tests in `exercise.yaml`.").format(
        tests=folder / "tests")]
    proofs = root / "tests"
    if proofs.is_dir():
        solution = (folder / "solution" / file).read_text(encoding="utf-8")
        variant = proofs / "submissions" / exercise_id / VARIANT
        patch = "".join(difflib.unified_diff(
            solution.splitlines(keepends=True),
            solution.replace(_RIGHT, _WRONG).splitlines(keepends=True),
            f"solution/{file}", f"{VARIANT}/{file}"))
        _write(variant / f"{file}.patch", patch, written)
        _write(variant / "expect.yaml", (
            "kind: mutant\nwhy: greets with the wrong words\nloses: [test_greets]\nsays:\n"
            "  test_greets: [\"Hello, Ada!\"]\n"), written)
        _write(proofs / f"test_grading_{exercise_id}.py", _fill(_template(
            "exercise", "test_grading.py.tmpl"), values), written)
        steps.append(_("Prove the tests: a folder in {submissions} for each known-bad "
                       "variant (`expect.yaml` and a patch: `python tests/proving.py patch "
                       "FOLDER`), then `python -m pytest {proof}`.").format(
            submissions=variant.parent, proof=proofs / f"test_grading_{exercise_id}.py"))
    steps.append(_("Check it all: `autograder validate` (the Urdu of a changed title or "
                   "label goes in `locales/ur/LC_MESSAGES/`)."))
    return Scaffold(tuple(written), tuple(steps))


def new_quiz(quiz_id: str, root: Path | None = None) -> Scaffold:
    """Scaffold ``quizzes/<id>.yaml`` (every question type once) and its Urdu."""
    from autograder.quiz.model import load_quiz, strings

    root = root or course_root()
    path = root / "quizzes" / f"{quiz_id}.yaml"
    if not QUIZ_ID.match(quiz_id):
        raise ContentError(path, _(
            "a quiz id is lower-case letters, digits and `-`, starting with a letter: "
            "{id!r}").format(id=quiz_id))
    if path.exists() or (root / "quizzes" / f"{quiz_id}.yml").exists():
        raise ContentError(path, _("already exists: pick another id"))
    written: list[Path] = []
    _write(path, _fill(_template("quiz", "quiz.yaml.tmpl"), {"__ID__": quiz_id}), written)
    urdu = yaml.safe_load(_fill(_template("quiz", "quiz.ur.yaml"), {"__ID__": quiz_id}))
    quiz = load_quiz(path)
    prefix = f"quiz:{quiz_id}:"
    relative = path.relative_to(root).as_posix()
    _add_translations(root, "content", [(s.context, s.text, urdu[s.context.removeprefix(prefix)],
                              s.comment, f"{relative}:{s.line}")
                             for s in strings(quiz)], written)
    steps = (_("Write your questions in {path}: edit or delete the examples (each type is "
               "there once), keeping each id unique.").format(path=path),
             _("Translate each changed string in `locales/ur/LC_MESSAGES/content.po`, then "
               "check it all: `autograder validate`."))
    return Scaffold(tuple(written), steps)
