"""Text a reader sees in their language: :class:`Text` (a string and whether it fell back to
English), numbers formatted by Babel, bidi-safe markup and terminal text, and
:func:`using_language` for one block. Quiz pages and grading reports both use it.

A string with no translation falls back to English and says so (``Text.fallback``), so a
page can mark it ``lang="en" dir="ltr"`` instead of showing English silently in the middle
of Urdu.
"""

from __future__ import annotations

import contextlib
import dataclasses
import re
from collections.abc import Callable, Iterator
from decimal import Decimal
from fractions import Fraction

from babel import Locale, numbers
from markupsafe import Markup, escape

from autograder.i18n import get_language, is_rtl, set_language

CODE_SPAN = re.compile(r"`([^`]+)`")
# A run of Latin script inside right-to-left text: identifiers, English terms, numbers with
# their units ("50 Hz", "±0.5 rad/s", "default 0.5"), words joined by single spaces.  A
# sign that leads a word (±, +, -, −) belongs to the run: left outside the isolate, the
# bidi algorithm would place it on the wrong side.
# An empty call may come anywhere in a chain ("self.get_clock().now()"): cut at its
# parentheses, the chain's pieces would be laid out in the wrong order.
_WORD = r"[±∓+\u2212-]?[A-Za-z0-9_][\w./+=±°-]*(?:\(\)[\w./+=±°-]*)*"
LATIN_RUN = re.compile(rf"{_WORD}(?: {_WORD})*", re.ASCII)
# A bare number (digits and separators: 0.25, 4/5, 1,000): Urdu text holds those as they
# are, in its own digits' face.
BARE_NUMBER = re.compile(r"[\d.,/:%]+", re.ASCII)
# What is laid out left to right inside right-to-left text is everything between two
# right-to-left letters (or an Urdu comma or full stop): an expression, a call, a pair, an
# interval and ``name=value`` keep their operators, brackets and commas inside one run, so
# "range_min <= r <= range_max" never reads "range_max => r => range_min".
_RTL_TEXT = "\u0590-\u08ff\ufb1d-\ufdff\ufe70-\ufefc"
_BETWEEN_RTL = re.compile(rf"[^{_RTL_TEXT}\n]+")
_PAIRS = {"(": ")", "[": "]", "{": "}"}
_TRIM = " \t,.;:!?"
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


def _is_latin(run: str) -> bool:
    """A Latin run to isolate: anything the pattern finds but a bare number."""
    return BARE_NUMBER.fullmatch(run) is None


def _unbalanced(text: str, start: int, end: int) -> int | None:
    """The first bracket in ``text[start:end]`` that the stretch does not close (or that
    closes nothing), if any."""
    stack: list[int] = []
    closers = {c: o for o, c in _PAIRS.items()}
    for i in range(start, end):
        char = text[i]
        if char in _PAIRS:
            stack.append(i)
        elif char in closers:
            if not stack or text[stack[-1]] != closers[char]:
                return i
            stack.pop()
    return stack[0] if stack else None


def _trimmed(text: str, start: int, end: int) -> Iterator[tuple[int, int]]:
    """``text[start:end]`` without spaces, sentence punctuation and unpaired quotes at its
    ends, cut at a bracket it does not close, without one pair of brackets around all of
    it (in right-to-left text the pair mirrors around the run by itself)."""
    while start < end:
        first, last = text[start], text[end - 1]
        if first in _TRIM or (first in "'\"" and text.count(first, start, end) % 2):
            start += 1
        elif last in _TRIM or (last in "'\"" and text.count(last, start, end) % 2):
            end -= 1
        else:
            break
    if start >= end:
        return
    cut = _unbalanced(text, start, end)
    if cut is not None:
        yield from _trimmed(text, start, cut)
        yield from _trimmed(text, cut + 1, end)
        return
    if text[start] in _PAIRS and text[end - 1] == _PAIRS[text[start]] \
            and _unbalanced(text, start + 1, end - 1) is None:
        yield from _trimmed(text, start + 1, end - 1)
        return
    yield start, end


def ltr_runs(text: str) -> Iterator[tuple[int, int]]:
    """Where ``text`` (right to left) holds left-to-right runs: each stretch between
    right-to-left letters (:func:`_trimmed`) that holds a letter or a digit."""
    for match in _BETWEEN_RTL.finditer(text):
        for start, end in _trimmed(text, *match.span()):
            if re.search(r"[A-Za-z0-9]", text[start:end]):
                yield start, end


def _latin_runs(text: str, wrap: str, end: str, quote: Callable[[str], str] = str) -> str:
    """``text`` with each Latin run between ``wrap`` and ``end``, every piece passed through
    ``quote`` (an escape applied after the match could break an entity like ``&lt;``)."""
    parts, at = [], 0
    for start, stop in ltr_runs(text):
        if _is_latin(text[start:stop]):
            parts += [quote(text[at:start]), wrap, quote(text[start:stop]), end]
            at = stop
    parts.append(quote(text[at:]))
    return "".join(parts)


def isolate_runs(text: str) -> str:
    """``text`` with each left-to-right run (:func:`ltr_runs`) in Unicode isolates."""
    return _latin_runs(text, LRI, PDI)


def isolate_latin(text: str, lead: bool = False) -> Markup:
    """Escaped right-to-left text with each Latin run in ``<bdi lang="en" dir="ltr">`` (its
    own font stack comes from the page's ``:lang(en)`` rule).  With ``lead``, a bare number
    that begins the text is isolated too, so that what stands before it (a question's
    number, "5.") cannot run into it ("5.50")."""
    parts, at = [], 0
    for start, stop in ltr_runs(text):
        run = text[start:stop]
        if _is_latin(run):
            tag = Markup('<bdi lang="en" dir="ltr">{}</bdi>')
        elif lead and start == 0:
            tag = Markup('<bdi dir="ltr">{}</bdi>')
        else:
            continue
        parts += [escape(text[at:start]), tag.format(run)]
        at = stop
    parts.append(escape(text[at:]))
    return Markup("").join(parts)


def _paragraphs(text: str) -> str:
    return "\n\n".join(" ".join(p.split()) for p in re.split(r"\n\s*\n", text.strip()))


def rich(text: Text) -> Markup:
    """HTML for a string: `code` becomes ``<code dir="ltr">``; in right-to-left text, Latin
    runs are isolated in ``<bdi lang="en">`` and so is a number that begins the text; an
    English fallback is marked ``lang="en" dir="ltr"``."""
    parts = []
    for i, piece in enumerate(CODE_SPAN.split(_paragraphs(text.value))):
        if i % 2:
            parts.append(Markup('<code dir="ltr">{}</code>').format(piece))
            continue
        for j, chunk in enumerate(re.split(r"(\n\n)", piece)):
            if j % 2:
                parts.append(Markup("<br><br>"))
            elif text.rtl:
                parts.append(isolate_latin(chunk, lead=not parts))
            else:
                parts.append(escape(chunk))
    html = Markup("").join(parts)
    if text.fallback:
        return Markup('<span lang="en" dir="ltr" class="fallback">{}</span>').format(html)
    return html


def with_output(text: Text) -> Markup:
    """A test's message that may end with a program's output ("Last lines of its output:"
    and the lines after it): the sentences as :func:`rich` text, the output kept as the
    program wrote it, line by line and left to right, in ``<pre class="output">`` (in an
    Urdu report, a traceback folded into the right-to-left paragraph reads backwards)."""
    lines = text.value.split("\n")
    for i, line in enumerate(lines[:-1]):
        if line.rstrip().endswith(":"):
            head = Text("\n".join(lines[:i + 1]), text.lang, text.fallback)
            return Markup('{}<pre class="output" dir="ltr" lang="en">{}</pre>').format(
                rich(head), "\n".join(lines[i + 1:]))
    return rich(text)


_FIELD = re.compile(r"(\{[^{}]*\})")


def sentence(template: str, **values: object) -> Markup:
    """A platform message as HTML (``{{ _("...")|bidi(name=value) }}`` in templates): in a
    right-to-left language its Latin runs are isolated as in :func:`rich`; each ``{name}``
    is filled with its value, escaped, a :class:`Text` rendered by :func:`rich` and isolated
    in ``<bdi>`` (an English name keeps its own order inside the Urdu sentence)."""
    filled = {k: Markup("<bdi>{}</bdi>").format(rich(v)) if isinstance(v, Text) else v
              for k, v in values.items()}
    if not is_rtl():
        return escape(template).format(**filled) if values else escape(template)
    if not values:
        return isolate_latin(template)
    parts = []
    for i, piece in enumerate(_FIELD.split(template)):
        parts.append(Markup(piece).format(**filled) if i % 2 else isolate_latin(piece))
    return Markup("").join(parts)


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


def _mdx_escape(text: str) -> str:
    return "".join(_MDX_ESCAPES.get(c, c) for c in text)


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
        out.append(_latin_runs(piece, LRI, PDI, _mdx_escape) if rtl else _mdx_escape(piece))
    md = "".join(out)
    if text.fallback:
        return f'<span lang="en" dir="ltr">{md}</span>'
    return md
