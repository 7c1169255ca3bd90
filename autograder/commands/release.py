"""What students get, and what Gradescope runs.

``build_release``: the platform, each exercise's README, starter and public tests, and
the quizzes rendered as pages (their YAML holds the key) — nothing of the hidden tests or
the reference solutions.  ``build_gradescope_bundle``: a Gradescope autograder zip
(``setup.sh``, ``run_autograder``) holding the platform and one exercise, hidden tests
included, that grades ``/autograder/submission`` into ``/autograder/results/results.json``.
"""

from __future__ import annotations

import ast
import re
import shutil
import stat
import zipfile
from pathlib import Path

from autograder.core.errors import ContentError
from autograder.core.exercise import Exercise, list_exercises
from autograder.i18n import _, packaged_locales, translations
from content.course import course_root

# The platform itself: what `pip install .` needs and what runs the tests.
PLATFORM = ("pyproject.toml", "README.md", "tasks.py", "Makefile", "babel.cfg", "autograder",
            "content", "sim", "locales")
_IGNORE = shutil.ignore_patterns("__pycache__", "*.pyc", "*.mo", ".*")


def _copy(source: Path, dest: Path) -> None:
    if source.is_dir():
        shutil.copytree(source, dest, ignore=_IGNORE, dirs_exist_ok=True)
    elif source.exists():
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, dest)


def _copy_platform(root: Path, out: Path) -> None:
    for name in PLATFORM:
        if name != "README.md":  # the instructors'; the release gets a student README
            _copy(root / name, out / name)
    for catalog in sorted((out / "locales").rglob("*.po*")):
        _drop_hidden_entries(catalog)


def _drop_hidden_entries(path: Path) -> None:
    """Remove the messages only hidden tests use (their feedback is not for students)."""
    from babel.messages.pofile import read_po, write_po

    with path.open("rb") as fh:
        catalog = read_po(fh)
    def hidden(location: tuple[str, int | None]) -> bool:
        return "/tests/hidden/" in f"/{location[0]}"

    for message in list(catalog):
        if message.id and message.locations and all(map(hidden, message.locations)):
            catalog.delete(message.id, message.context)
        elif message.id:  # shared with public tests: keep it, not the hidden file's name
            message.locations = [loc for loc in message.locations if not hidden(loc)]
    with path.open("wb") as fh:
        # In the catalog's own order: a hand-appended entry may name a file with no line,
        # which sorting by file cannot compare.
        write_po(fh, catalog, width=88)


def student_files(exercise: Exercise) -> list[Path]:
    """An exercise's files a student may have: everything but solution/ and tests/hidden/."""
    hidden = {exercise.folder / "solution", exercise.hidden_tests}
    files = []
    for path in sorted(exercise.folder.rglob("*")):
        if not path.is_file() or "__pycache__" in path.parts:
            continue
        if any(path.is_relative_to(h) for h in hidden):
            continue
        files.append(path)
    return files


def hidden_test_names(exercise: Exercise) -> set[str]:
    """The names of the exercise's hidden test functions (read, not imported)."""
    names: set[str] = set()
    for path in sorted(exercise.hidden_tests.rglob("*.py")) if exercise.hidden_tests.is_dir() \
            else []:
        names |= {node.name for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
                  if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
                  and node.name.startswith("test")}
    return names


def without_hidden_names(text: str, hidden: set[str]) -> str:
    """exercise.yaml as a student gets it: no line that names a hidden test (its ``core``
    entries among them; a student's ``check`` runs the public tests only)."""
    kept = [line for line in text.splitlines(keepends=True)
            if not set(re.findall(r"\btest_\w+", line)) & hidden]
    return "".join(kept)


def build_release(out: Path, exercises: list[Exercise] | None = None) -> Path:
    """Write the student release to ``out`` (which must not exist yet)."""
    from autograder.quiz.catalog import load_all
    from autograder.quiz.render import render_markdown, render_page

    root = course_root()
    out.mkdir(parents=True)
    _copy_platform(root, out)
    for exercise in exercises or list_exercises():
        for path in student_files(exercise):
            _copy(path, out / "assignments" / exercise.id / path.relative_to(exercise.folder))
        released = out / "assignments" / exercise.id / "exercise.yaml"
        released.write_text(without_hidden_names(released.read_text(encoding="utf-8"),
                                                 hidden_test_names(exercise)), encoding="utf-8")
    pages = out / "quizzes-rendered"
    quizzes = load_all()
    _write_student_readmes(out, exercises or list_exercises(), [qf.quiz for qf in quizzes])
    for quiz_file in quizzes:
        quiz = quiz_file.quiz
        for lang in quiz.languages:
            pages.mkdir(parents=True, exist_ok=True)
            (pages / f"{quiz.id}.{lang}.html").write_text(render_page(quiz, lang),
                                                          encoding="utf-8")
            (pages / f"{quiz.id}.{lang}.mdx").write_text(render_markdown(quiz, lang),
                                                         encoding="utf-8")
    return out


def _write_student_readmes(out: Path, exercises: list[Exercise], quizzes: list) -> None:
    """README.md and README.ur.md: commands that work inside the release (set up, start,
    check; the quizzes as the pages it holds), none of which needs a solution or a key."""
    import jinja2

    from autograder.quiz.localize import Localizer

    content = translations("ur", "content")
    ordered = sorted(exercises, key=lambda e: (e.id != "parameter_validation", e.id))
    rows = [{"id": e.id, "file": e.file, "title": e.title,
             "title_ur": content.pgettext(f"exercise:{e.id}:title", e.title)}
            for e in sorted(exercises, key=lambda e: e.id)]
    quiz_rows = [{"id": q.id, "title": q.title, "ur": "ur" in q.languages,
                  "title_ur": Localizer(q, "ur").quiz_text("title").value}
                 for q in sorted(quizzes, key=lambda q: q.id)]
    env = jinja2.Environment(loader=jinja2.PackageLoader("autograder", "templates"),
                             autoescape=False, keep_trailing_newline=True,
                             undefined=jinja2.StrictUndefined)
    values = {"title": "rclpy exercises", "first": ordered[0], "exercises": rows,
              "quizzes": quiz_rows}
    for name in ("README.md", "README.ur.md"):
        text = env.get_template(f"release-{name}").render(**values)
        (out / name).write_text(text, encoding="utf-8")


SETUP_SH = """#!/usr/bin/env bash
# Gradescope runs this once when it builds the autograder image (Ubuntu, as root).
set -euo pipefail
ROOT="${AUTOGRADER_ROOT:-/autograder}"
if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv
fi
python3 -m venv "$ROOT/venv"
"$ROOT/venv/bin/pip" install -q --upgrade pip
"$ROOT/venv/bin/pip" install -q "$ROOT/source"
"""

RUN_AUTOGRADER = """#!/usr/bin/env bash
# Gradescope runs this for every submission; results go to results/results.json.
set -uo pipefail
ROOT="${{AUTOGRADER_ROOT:-/autograder}}"
VENV="${{AUTOGRADER_VENV:-$ROOT/venv}}"
mkdir -p "$ROOT/results"
cd "$ROOT/source"
AUTOGRADER_COURSE="$ROOT/source" "$VENV/bin/autograder" grade {exercise} "$ROOT/submission" \\
    --lang {lang} --require-official --gradescope "$ROOT/results/results.json" \\
    --results "$ROOT/results/ours.json"
status=$?
if [ ! -s "$ROOT/results/results.json" ]; then
  # The grader could not even start: say so rather than leave Gradescope without results.
  message="The autograder failed (status $status), tell your instructor."
  printf '{{"score": 0, "output": "%s", "tests": []}}\\n' "$message" \\
    > "$ROOT/results/results.json"
fi
exit 0
"""


def build_gradescope_bundle(exercise: Exercise, zip_path: Path, lang: str = "en") -> Path:
    """Write Gradescope's autograder zip for ``exercise``, grading in ``lang``; a course
    with no ``lang`` translation of the exercise is an error, never an English bundle."""
    root = course_root()
    if lang != "en":
        lookup = translations(lang, "content").pgettext
        title = lookup(f"exercise:{exercise.id}:title", exercise.title)
        if title == exercise.title:
            raise ContentError(exercise.folder, _(
                "no {lang} translation of the exercise {exercise!r} in the course's catalogs: "
                "a bundle in {lang} would grade in English").format(lang=lang,
                                                                   exercise=exercise.id))
    zip_path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(zip_path, "w", zipfile.ZIP_DEFLATED) as bundle:
        for name, text in (("setup.sh", SETUP_SH),
                           ("run_autograder", RUN_AUTOGRADER.format(exercise=exercise.id,
                                                                     lang=lang))):
            info = zipfile.ZipInfo(name)
            info.external_attr = (stat.S_IFREG | 0o755) << 16
            bundle.writestr(info, text)
        for name in PLATFORM:
            source = root / name
            if name == "locales" and not source.exists():
                source = packaged_locales()  # the platform's own, so it still speaks lang
            paths = [source] if source.is_file() else sorted(source.rglob("*"))
            for path in paths:
                if path.is_file() and "__pycache__" not in path.parts and path.suffix != ".mo" \
                        and not path.is_relative_to(root / "autograder" / "locales"):
                    bundle.write(path, f"source/{name}/{path.relative_to(source)}"
                                 if source.is_dir() else f"source/{name}")
        solution = exercise.folder / "solution"  # not needed to grade: never on the image
        for path in sorted(exercise.folder.rglob("*")):
            if path.is_file() and "__pycache__" not in path.parts \
                    and not path.is_relative_to(solution):
                bundle.write(path, f"source/assignments/{exercise.id}/"
                                   f"{path.relative_to(exercise.folder)}")
    return zip_path
