"""``autograder quiz lint``: every problem an instructor must fix before a release.

Quiz files load (ids unique, keys valid), settings a question's type doubts are reported
(a numeric tolerance that also accepts 0), and every string is translated, not fuzzy, with
its placeholders and code unchanged, in every language the quiz is offered in.  The
translations follow the language's glossary (``locales/<lang>/glossary.yaml``), and the
content catalog has no obsolete entries and no header left at template values.
"""

from __future__ import annotations

from pathlib import Path

from autograder.core.errors import ContentError
from autograder.i18n import locales_dir
from autograder.i18n.glossary import Glossary, as_problem, glossary_for, housekeeping
from autograder.i18n.tools import Problem, check_message, read_catalog
from autograder.quiz import CONTENT_DOMAIN
from autograder.quiz.catalog import quiz_paths
from autograder.quiz.model import QuizFile, check_ids_unique, load_quiz, strings
from autograder.quiz.types import question_type


def _problem(exc: ContentError) -> Problem:
    message = f"{exc.field}: {exc.message}" if exc.field else exc.message
    return Problem(exc.path, exc.line, message)


def _type_notes(qf: QuizFile) -> list[Problem]:
    """What each question's type finds doubtful in a question that loads."""
    return [Problem(qf.path, qf.line("questions", i, note.field), note.message)
            for i, q in enumerate(qf.quiz.questions)
            for note in question_type(q.type).lint_notes(q, i)]


def lint(root: Path | None = None, locales: Path | None = None) -> list[Problem]:
    """All problems in the course's quizzes, in file order."""
    locales = locales or locales_dir()
    problems: list[Problem] = []
    files: list[QuizFile] = []
    for path in quiz_paths(root):
        try:
            files.append(load_quiz(path))
        except ContentError as exc:
            problems.append(_problem(exc))
    problems += [_problem(e) for e in check_ids_unique(files)]
    catalogs: dict[str, object] = {}
    glossaries: dict[str, Glossary | None] = {}
    for qf in files:
        problems += _type_notes(qf)
        for lang in qf.quiz.languages:
            if lang == "en":
                continue
            po = locales / lang / "LC_MESSAGES" / f"{CONTENT_DOMAIN}.po"
            if lang not in catalogs:
                try:
                    catalogs[lang] = read_catalog(po, lang)
                except ContentError as exc:
                    catalogs[lang] = None
                    problems.append(Problem(exc.path, exc.line, exc.message))
                    continue
                problems += housekeeping(po)
                try:
                    glossaries[lang] = glossary_for(locales, lang)
                except ContentError as exc:
                    glossaries[lang] = None
                    problems.append(as_problem(exc))
            catalog = catalogs[lang]
            if catalog is None:
                continue
            glossary = glossaries.get(lang)
            lines = po.read_text(encoding="utf-8").splitlines() if glossary else []
            for s in strings(qf):
                found = catalog.get(s.text, context=s.context)  # type: ignore[attr-defined]
                problems += check_message(po, lang, found, s.context, at=(qf.path, s.line))
                if glossary is not None and found is not None and found.string:
                    problems += glossary.check_message(po, found, lines)
    return problems
