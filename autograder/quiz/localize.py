"""A quiz's strings in the student's language, from the ``content`` gettext domain with a
context per quiz, question and field (a missing translation falls back to English and says
so: :class:`~autograder.i18n.text.Text`)."""

from __future__ import annotations

from autograder.core.errors import ContentError
from autograder.i18n import _, translations
from autograder.i18n.text import Text
from autograder.quiz import CONTENT_DOMAIN
from autograder.quiz.model import (
    Option,
    Question,
    Quiz,
    QuizFile,
    context,
    is_code_only,
    strings,
)


class Localizer:
    """Looks up a quiz's strings in one language."""

    def __init__(self, quiz: Quiz, lang: str) -> None:
        self.quiz, self.lang = quiz, lang
        self._t = translations(lang, CONTENT_DOMAIN)

    def _lookup(self, ctx: str, text: str) -> Text:
        if self.lang == "en" or is_code_only(text):
            return Text(text, "en" if self.lang == "en" else self.lang)
        found = self._t.pgettext(ctx, text)
        if found == text:
            return Text(text, "en", fallback=True)
        return Text(found, self.lang)

    def quiz_text(self, name: str) -> Text:
        return self._lookup(context(self.quiz.id, name), getattr(self.quiz, name))

    def text(self, q: Question, name: str) -> Text:
        return self._lookup(context(self.quiz.id, q.id, name), getattr(q, name))

    def option(self, q: Question, o: Option) -> Text:
        return self._lookup(context(self.quiz.id, q.id, f"options.{o.id}"), o.text)


def require_translation(qf: QuizFile, lang: str) -> None:
    """Every string of a quiz translated into ``lang``, or a ContentError naming the first
    one that is not (its file and line): a page or an export for ``lang`` is never English
    where a translation is missing."""
    if lang == "en":
        return
    catalog = translations(lang, CONTENT_DOMAIN)
    for s in strings(qf):
        if not is_code_only(s.text) and catalog.pgettext(s.context, s.text) == s.text:
            raise ContentError(qf.path, _(
                "no {lang} translation of {context} in the course's content catalog: "
                "run autograder quiz lint").format(lang=lang, context=s.context), s.line)
