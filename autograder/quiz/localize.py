"""Quiz text in the student's language, numbers formatted by Babel, and bidi-safe markup.

Quiz strings come from the ``content`` gettext domain with a context per quiz, question
and field.  A string with no (or only a fuzzy) translation falls back to English and says
so (``Text.fallback``), so a page can mark it ``lang="en" dir="ltr"`` instead of showing
English silently in the middle of Urdu.
"""

from __future__ import annotations

import contextlib
import dataclasses
import re
from collections.abc import Iterator
from decimal import Decimal
from fractions import Fraction

from babel import Locale, numbers
from markupsafe import Markup, escape

from autograder.i18n import get_language, is_rtl, set_language, translations
from autograder.quiz import CONTENT_DOMAIN
from autograder.quiz.model import Option, Question, Quiz, context, is_code_only

CODE_SPAN = re.compile(r"`([^`]+)`")
# A run of Latin-script words (identifiers, English terms) inside right-to-left text.
_WORD = r"[\w./+=-]*(?:\(\))?"
LATIN_RUN = re.compile(rf"[A-Za-z_]{_WORD}(?: [A-Za-z0-9_]{_WORD})*", re.ASCII)
FSI, LRI, PDI = "\u2068", "\u2066", "\u2069"


@contextlib.contextmanager
def using_language(lang: str) -> Iterator[None]:
    """Platform messages in ``lang`` for the duration of a block (one request, one score)."""
    before = get_language()
    set_language(lang)
    try:
        yield
    finally:
        set_language(before)


@dataclasses.dataclass(frozen=True)
class Text:
    """A string shown to a student, and whether it fell back to English."""

    value: str
    lang: str
    fallback: bool = False

    @property
    def rtl(self) -> bool:
        return is_rtl(self.lang) and not self.fallback


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


def babel_locale(lang: str) -> Locale:
    return Locale.parse(lang)


def _decimal(value: Fraction | int) -> Decimal:
    value = Fraction(value)
    if value.denominator == 1:
        return Decimal(value.numerator)
    return (Decimal(value.numerator) / Decimal(value.denominator)).quantize(Decimal("0.01"))


def format_number(value: Fraction | int, lang: str) -> str:
    return numbers.format_decimal(_decimal(value), locale=babel_locale(lang))


def format_percent(value: Fraction, lang: str) -> str:
    return numbers.format_percent(_decimal(value), locale=babel_locale(lang),
                                  decimal_quantization=False)


def _latin_runs(text: str, wrap: str, end: str) -> str:
    return LATIN_RUN.sub(lambda m: f"{wrap}{m.group(0)}{end}", text)


def _paragraphs(text: str) -> str:
    return "\n\n".join(" ".join(p.split()) for p in re.split(r"\n\s*\n", text.strip()))


def rich(text: Text) -> Markup:
    """HTML for a string: `code` becomes ``<code dir="ltr">``; in right-to-left text, Latin
    runs are isolated in ``<bdi>``; an English fallback is marked ``lang="en" dir="ltr"``."""
    parts = []
    for i, piece in enumerate(CODE_SPAN.split(_paragraphs(text.value))):
        if i % 2:
            parts.append(Markup('<code dir="ltr">{}</code>').format(piece))
            continue
        for j, chunk in enumerate(re.split(r"(\n\n)", piece)):
            if j % 2:
                parts.append(Markup("<br><br>"))
            elif text.rtl:
                runs = LATIN_RUN.split(chunk)
                found = LATIN_RUN.findall(chunk)
                for k, run in enumerate(runs):
                    parts.append(escape(run))
                    if k < len(found):
                        parts.append(Markup('<bdi dir="ltr">{}</bdi>').format(found[k]))
            else:
                parts.append(escape(chunk))
    html = Markup("").join(parts)
    if text.fallback:
        return Markup('<span lang="en" dir="ltr" class="fallback">{}</span>').format(html)
    return html


def plain(text: Text, isolate: bool | None = None) -> str:
    """Text where markup cannot go (``<title>``, ``<option>``): code and Latin runs in
    Unicode isolates when the language is right-to-left."""
    value = _paragraphs(text.value)
    if isolate is None:
        isolate = is_rtl(text.lang)
    if not isolate:
        return CODE_SPAN.sub(r"\1", value)
    if text.fallback:
        return LRI + value.replace("`", "") + PDI
    pieces = CODE_SPAN.split(value)
    return "".join(f"{LRI}{p}{PDI}" if i % 2 else _latin_runs(p, LRI, PDI)
                   for i, p in enumerate(pieces))


def terminal(text: Text) -> str:
    """Text for a terminal: paragraphs on one line each (wrapping breaks bidi), code kept
    in backticks so it stands out."""
    return _paragraphs(text.value)


_MDX_ESCAPES = {"{": "\\{", "}": "\\}", "<": "&lt;", ">": "&gt;", "*": "\\*", "#": "\\#"}


def markdown_inline(text: Text) -> str:
    """Markdown/MDX for a string: code spans kept; in RTL text, code and Latin runs wrapped
    in Unicode isolates (markup cannot go inside every Markdown construct)."""
    rtl = is_rtl(text.lang) and not text.fallback
    out = []
    value = " ".join(text.value.split())
    for i, piece in enumerate(CODE_SPAN.split(value)):
        if i % 2:
            out.append(f"{LRI}`{piece}`{PDI}" if rtl else f"`{piece}`")
            continue
        escaped = "".join(_MDX_ESCAPES.get(c, c) for c in piece)
        out.append(LATIN_RUN.sub(lambda m: f"{LRI}{m.group(0)}{PDI}", escaped) if rtl
                   else escaped)
    md = "".join(out)
    if text.fallback:
        return f'<span lang="en" dir="ltr">{md}</span>'
    return md
