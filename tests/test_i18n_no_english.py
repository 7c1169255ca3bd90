"""Urdu never silently turns English (issue 32): a course tree without ``locales/`` still
speaks Urdu; a quiz or exercise with a translation missing is an error in ``quiz render``,
``quiz export`` and ``bundle gradescope``; ``validate`` fails where ``i18n check`` does;
and ``--lang ur`` runs of list, check, quiz take and quiz score print no English word
outside code, names and the glossary's Latin terms.  Each command runs as its own
process, as a student runs it, so no catalog is cached between them."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from student_runs import Spec, StudentRuns, starter

from autograder.i18n.glossary import load_glossary

REPO = Path(__file__).resolve().parent.parent
EXERCISE = "parameter_validation"
STARTER = REPO / "assignments" / EXERCISE / "starter" / "velocity_governor.py"


def _run(*args: str, course: Path = REPO, stdin: str = "",
         locales: Path | None = None) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items()
           if k not in ("AUTOGRADER_LANG", "AUTOGRADER_LOCALES", "NO_COLOR")}
    env.update(AUTOGRADER_COURSE=str(course), PYTHONPATH=str(REPO))
    if locales is not None:
        env["AUTOGRADER_LOCALES"] = str(locales)
    return subprocess.run([sys.executable, "-m", "autograder.cli", *args], cwd=course,
                          env=env, input=stdin, capture_output=True, text=True, timeout=600)


# --- English words outside code ----------------------------------------------------------
_CODE = re.compile(r"`[^`\n]*`|\u2066[^\u2069]*\u2069|«[^»]*»|'[^'\n]*'|\"[^\"\n]*\"")
_IDENTIFIER = re.compile(r"[^\s\u0600-\u06ff]*[_/\\.=<>()\[\]{}-][^\s\u0600-\u06ff]*")
# Latin words joined by spaces or commas: a phrase, English unless a compound.
_PHRASE = re.compile(r"[A-Za-z]+(?:[ ,]+[A-Za-z]+)+")
# Words of the platform's own fixed strings that would show one untranslated alone.
_FIXED = {"error", "usage", "try", "warning", "hint", "score", "isolation", "stopped",
          "wrote", "passed", "failed", "exercises", "quizzes", "answer"}
# Names an Urdu sentence writes in Latin besides the glossary's terms.
_NAMES = {"hz", "ros", "jazzy", "json", "nan", "inf", "enter", "ctrl", "sigint", "sigterm",
          "github", "gradescope", "moodle", "ai", "readme", "twist", "python"}


def allowed_words() -> tuple[set[str], set[str]]:
    """The glossary's Latin terms (single words) and its compounds, lower case."""
    glossary = load_glossary(REPO / "locales" / "ur" / "glossary.yaml")
    words = set(_NAMES) | set(glossary.verbs)
    for term in glossary.terms:
        if term.latin:
            words.update(w.lower() for w in re.findall(r"[A-Za-z]+", f"{term.ur} {term.plural}"))
    compounds = {" ".join(re.findall(r"[a-z]+", c.lower())) for c in glossary.compounds}
    return words, compounds


def english_outside_code(output: str, allowed: tuple[set[str], set[str]]) -> list[str]:
    """English in the Urdu lines of ``output`` (a line with no Urdu is a program's output,
    a path or a name), outside code, quotes and isolates: a phrase of Latin words that is
    no compound of the glossary and not all its terms, or a word of a fixed string."""
    words, compounds = allowed
    found = []
    for line in output.splitlines():
        if not re.search(r"[\u0600-\u06ff]", line):
            continue
        prose = _IDENTIFIER.sub("¦", _CODE.sub("¦", line))
        prose = re.sub(r"\b[A-Z][A-Z0-9]+\b", "¦", prose)  # a metavar or an acronym: a name
        for phrase in _PHRASE.findall(prose):
            parts = re.findall(r"[A-Za-z]+", phrase.lower())
            plain = " ".join(p[:-1] if p.endswith("s") and len(p) > 3 else p for p in parts)
            if " ".join(parts) not in compounds and plain not in compounds \
                    and not all(p in words or p.rstrip("s") in words for p in parts):
                found.append(phrase)
        found += [w for w in re.findall(r"[A-Za-z]+", _PHRASE.sub(" ", prose))
                  if w.lower() in _FIXED]
    return found


@pytest.fixture(scope="module")
def allowed() -> tuple[set[str], set[str]]:
    return allowed_words()


def test_the_english_finder_finds_english(allowed: tuple[set[str], set[str]]) -> None:
    planted = "Isolation: strict (الگ user، network نہیں)؛ Error: کوئی فائل نہیں"
    assert english_outside_code(planted, allowed) == ["Isolation", "Error"]
    assert english_outside_code("جانچ ہو رہی ہے: not translated yet", allowed) == [
        "not translated yet"]
    assert english_outside_code("[INFO] started\nیہ `self.get_clock().now()` ہے", allowed) == []


def test_list_and_quizzes_in_urdu_have_no_english(allowed: tuple[set[str], set[str]],
                                                  tmp_path: Path) -> None:
    listed = _run("--lang", "ur", "list")
    key = _run("quiz", "key", "timer-synchronization")
    answers = tmp_path / "answers.json"
    answers.write_text(key.stdout, encoding="utf-8")
    scored = _run("quiz", "score", "timer-synchronization", str(answers), "--lang", "ur")
    taken = _run("quiz", "take", "timer-synchronization", "--lang", "ur", stdin="\n" * 20)
    for run in (listed, scored, taken):
        assert run.returncode == 0, run.stderr
        assert english_outside_code(run.stdout + run.stderr, allowed) == [], run.stdout


@pytest.mark.slow
@pytest.mark.parametrize("command", ["check", "grade"])
def test_check_and_grade_in_urdu_have_no_english(allowed: tuple[set[str], set[str]],
                                                 command: str,
                                                 student_runs: StudentRuns) -> None:
    """The starter's failures, messages and hints in Urdu (the run is shared with
    tests/test_cli_output.py and tests/test_report_code_order.py)."""
    [run] = student_runs.get(Spec(command, EXERCISE, starter(EXERCISE), "ur"))
    assert run.code == 0, run.stderr
    assert "جانچ" in run.stdout + run.stderr
    assert english_outside_code(run.stdout + run.stderr, allowed) == [], run.stdout


def test_a_usage_error_in_urdu_has_no_english_prefix(allowed: tuple[set[str], set[str]]) -> None:
    run = _run("--lang", "ur", "check", "no_such_exercise", str(STARTER))
    assert run.returncode == 2
    assert "Error:" not in run.stderr and "خرابی:" in run.stderr, run.stderr
    # click's own usage errors: a missing argument, an unknown option
    for args in (("check", EXERCISE), ("check", EXERCISE, str(STARTER), "--bogus")):
        run = _run("--lang", "ur", *args)
        assert run.returncode == 2, run.stderr
        assert "خرابی:" in run.stderr and "استعمال:" in run.stderr, run.stderr
        assert english_outside_code(run.stderr, allowed) == [], run.stderr


# --- no silent English ---------------------------------------------------------------------
def test_a_course_without_locales_still_speaks_urdu(tmp_path: Path) -> None:
    shutil.copytree(REPO / "assignments", tmp_path / "assignments",
                    ignore=shutil.ignore_patterns("__pycache__"))
    run = _run("--lang", "ur", "list", course=tmp_path)
    assert run.returncode == 0, run.stderr
    assert "مشقیں" in run.stdout and "Exercises" not in run.stdout, run.stdout


def _without(locales: Path, context: str, tmp_path: Path) -> Path:
    """A copy of ``locales`` whose content catalog lacks the translation of ``context``."""
    copy = tmp_path / "locales"
    shutil.copytree(locales, copy)
    po = copy / "ur" / "LC_MESSAGES" / "content.po"
    text = po.read_text(encoding="utf-8")
    at = text.index(f'msgctxt "{context}"')
    start = text.index("msgstr", at)
    end = text.find("\n\n", start)
    po.write_text(text[:start] + 'msgstr ""' + text[end:], encoding="utf-8")
    return copy


def test_an_untranslated_quiz_string_stops_render_and_export(tmp_path: Path) -> None:
    context = "quiz:timer-synchronization:sim-time:text"
    locales = _without(REPO / "locales", context, tmp_path)
    for args in (("quiz", "render", "timer-synchronization", "--lang", "ur", "--out",
                  str(tmp_path / "out")),
                 ("quiz", "export", "timer-synchronization", "--format", "qti", "--lang", "ur",
                  "--out", str(tmp_path / "q.zip"))):
        run = _run(*args, locales=locales)
        assert run.returncode == 2, (args, run.stdout, run.stderr)
        assert context in run.stderr and "timer-synchronization.yaml:" in run.stderr
    assert not (tmp_path / "q.zip").exists()
    assert not list((tmp_path / "out").glob("*.ur.*"))


def test_the_gradescope_bundle_grades_in_its_language(tmp_path: Path) -> None:
    run = _run("bundle", "gradescope", "timer_sync", str(tmp_path / "ur.zip"), "--lang", "ur")
    assert run.returncode == 0, run.stderr
    script = zipfile.ZipFile(tmp_path / "ur.zip").read("run_autograder").decode()
    assert "--lang ur" in script
    locales = _without(REPO / "locales", "exercise:timer_sync:title", tmp_path)
    run = _run("bundle", "gradescope", "timer_sync", str(tmp_path / "no.zip"), "--lang", "ur",
               locales=locales)
    assert run.returncode == 2 and "timer_sync" in run.stderr, run.stderr
    assert not (tmp_path / "no.zip").exists()


def test_validate_fails_where_i18n_check_does(tmp_path: Path) -> None:
    course = tmp_path / "course"
    for name in ("assignments", "quizzes", "locales"):
        shutil.copytree(REPO / name, course / name, ignore=shutil.ignore_patterns("__pycache__"))
    readme = course / "assignments" / "timer_sync" / "README.ur.md"
    readme.write_text(readme.read_text(encoding="utf-8").replace(
        "اب public tests چلائیں", "public tests چلائیے"), encoding="utf-8")
    run = _run("validate", "--no-grade", "--course", str(course), course=course)
    assert run.returncode == 1, run.stdout + run.stderr
    assert "README.ur.md" in run.stderr and "چلائیے" in run.stderr, run.stderr


def test_true_false_feedback_never_contradicts_itself(tmp_path: Path) -> None:
    """A right "False" read back: the feedback speaks of the answer, the option chosen is
    quoted, so the line never reads "your answer is right; your answer: wrong"."""
    key = _run("quiz", "key", "timer-synchronization")
    answers = tmp_path / "answers.json"
    answers.write_text(key.stdout, encoding="utf-8")
    run = _run("quiz", "score", "timer-synchronization", str(answers), "--lang", "ur")
    assert run.returncode == 0, run.stderr
    assert "آپ کا جواب درست ہے۔ آپ نے جواب دیا: «غلط»" in run.stdout, run.stdout
    assert "آپ کا جواب: غلط" not in run.stdout
