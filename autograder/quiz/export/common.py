"""What both exports share: a quiz's text in each language, and the errors they raise.

A string whose translation is missing (or fuzzy) is left out of that language rather than
shown as English marked Urdu: Moodle then shows the English to everyone, as the served
page does, and lint reports the missing translation.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence

from autograder.core.errors import ContentError
from autograder.i18n import _
from autograder.i18n.text import Text, using_language
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Question, QuizFile

FORMATS = ("moodle-xml", "qti")


class Languages:
    """A quiz's strings, and the platform's messages, in each language of an export."""

    def __init__(self, qf: QuizFile, langs: Sequence[str]) -> None:
        self.qf, self.quiz, self.langs = qf, qf.quiz, tuple(langs)
        self.localizers = [Localizer(qf.quiz, lang) for lang in self.langs]

    def texts(self, get: Callable[[Localizer], Text]) -> list[Text]:
        """The string in each language that has it; the first language's if none does."""
        found = [get(loc) for loc in self.localizers]
        return [t for t in found if not t.fallback] or found[:1]

    def messages(self, message: Callable[[], str]) -> list[Text]:
        """A platform message (``message`` calls ``_``) in each language that translates it."""
        with using_language("en"):
            english = message()
        found = []
        for lang in self.langs:
            with using_language(lang):
                value = message()
            found.append(Text(value, lang, fallback=lang != "en" and value == english))
        return [t for t in found if not t.fallback] or [Text(english, "en")]

    def error(self, q: Question, message: str) -> ContentError:
        """A question that cannot be exported, named by its file and line."""
        index = self.quiz.questions.index(q)
        return ContentError(self.qf.path, message, self.qf.line("questions", index),
                            self.qf.doc.field("questions", index))

    def unsupported(self, q: Question, fmt: str) -> ContentError:
        return self.error(q, _("a {type} question cannot be exported to {format}").format(
            type=q.type, format=fmt))


def paragraphs(text: str) -> list[str]:
    """Paragraphs (split at blank lines), each on one line, as the pages show them."""
    return [" ".join(p.split()) for p in re.split(r"\n\s*\n", text.strip()) if p.strip()]
