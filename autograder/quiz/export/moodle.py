"""Moodle XML: one file, a question category per quiz, every language in multilang spans.

Each language's text is a ``<span lang=".." class="multilang">`` for Moodle's
"Multi-language content" filter, which shows the reader's language.  The filter matches a
span up to the first ``</span>``, so nothing inside one is a span: right-to-left text is
wrapped in ``<div dir="rtl">`` (``<bdi>`` inline), code in ``<code dir="ltr">``.  Code
blocks are not translated and sit outside the spans, in ``<pre><code>``.

What the format cannot carry, it says where an instructor sees it: a question file holds
no quiz settings, so the pass mark is in the category's description (with how to set
"Grade to pass") and in a zero-mark description question students can be shown; a
question Moodle scores differently from the platform is named there too.

Each question type writes its own question (``QuestionType.moodle_question``) with the
builders here: ``multichoice``, ``truefalse``, ``numerical`` and ``ordering``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from decimal import Decimal
from fractions import Fraction
from html import escape

from autograder.core.errors import ContentError
from autograder.i18n import _, get_language
from autograder.i18n.text import Text, format_number, format_percent, rich
from autograder.quiz.export.common import Languages
from autograder.quiz.export.xml import CData, El, el, to_xml
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Question, QuizFile
from autograder.quiz.scoring import pass_summary
from autograder.quiz.types import question_type

FORMAT = "moodle-xml"

# Moodle's grades for one answer (question_bank::fraction_options_full): an imported
# fraction must be one of these (to 1e-5), or the import stops with "invalid grade".
_POSITIVE = ("1.0", "0.9", "0.8333333", "0.8", "0.75", "0.7", "0.6666667", "0.6", "0.5",
             "0.4", "0.3333333", "0.3", "0.25", "0.2", "0.1666667", "0.1428571", "0.125",
             "0.1111111", "0.1", "0.05")
MOODLE_FRACTIONS = (Decimal(0), *(Decimal(v) for v in _POSITIVE),
                    *(-Decimal(v) for v in _POSITIVE))


def moodle_fraction(value: Fraction) -> Decimal | None:
    """The Moodle grade equal to ``value`` (within Moodle's 1e-5), or None."""
    for grade in MOODLE_FRACTIONS:
        if abs(value - Fraction(grade)) < Fraction(1, 100000):
            return grade
    return None


def percent(grade: Decimal) -> str:
    """A grade as the ``fraction`` attribute states it: a percentage, "33.33333"."""
    text = f"{grade * 100:.5f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def number(value: float | int) -> str:
    """A number as Moodle reads it: shortest decimal text, no exponent."""
    return format(Decimal(repr(value)) if isinstance(value, float) else Decimal(value), "f")


class MoodleWriter:
    """Writes one quiz's category and questions; types call the builders."""

    def __init__(self, qf: QuizFile, langs: Sequence[str]) -> None:
        self.text = Languages(qf, langs)
        self.quiz = qf.quiz
        self.notes: list[Callable[[], str]] = []

    def unsupported(self, q: Question) -> ContentError:
        """The error for a question whose type has no Moodle question."""
        return self.text.unsupported(q, FORMAT)

    # HTML in every language -------------------------------------------------------------

    def html(self, get: Callable[[Localizer], Text], inline: bool = False) -> str:
        return multilang(self.text.texts(get), inline)

    def _question_html(self, q: Question, extra: str = "") -> CData:
        html = self.html(lambda loc: loc.text(q, "text"))
        if q.code.strip():
            html += f'<pre dir="ltr"><code>{escape(q.code.rstrip())}</code></pre>'
        return CData(html + extra)

    def _option_html(self, q: Question, option_id: str) -> CData:
        option = next(o for o in q.options if o.id == option_id)
        return CData(self.html(lambda loc: loc.option(q, option)))

    def _question(self, q: Question, qtype: str, *body: El, text_extra: str = "") -> El:
        n = self.quiz.questions.index(q) + 1
        feedback = self.html(lambda loc: loc.text(q, "explanation")) if q.explanation else ""
        return el("question", {"type": qtype},
                  el("name", {}, el("text", {}, f"{n:02d} {q.id}")),
                  el("questiontext", {"format": "html"},
                     el("text", {}, self._question_html(q, text_extra))),
                  el("generalfeedback", {"format": "html"}, el("text", {}, CData(feedback))),
                  el("defaultgrade", {}, str(q.points)),
                  el("penalty", {}, "0"),
                  el("hidden", {}, "0"),
                  el("idnumber", {}, q.id),
                  *body)

    # The builders the question types call -----------------------------------------------

    def grade(self, q: Question, value: Fraction) -> str:
        """The ``fraction`` attribute for ``value`` of the marks; an export error if
        Moodle's list of grades does not have it."""
        grade = moodle_fraction(value)
        if grade is None:
            raise self.text.error(q, _(
                "Moodle has no grade of {fraction} of the marks for one answer (its list has "
                "1/2 to 1/10, 1/20 and a few others)").format(fraction=abs(value)))
        return percent(grade)

    def multichoice(self, q: Question, fractions: Mapping[str, Fraction], single: bool) -> El:
        """A ``multichoice`` question: ``fractions`` gives each option id its share of the
        marks (negative for a wrong pick of several); pinned options keep the file's order."""
        answers = [el("answer", {"fraction": self.grade(q, fractions[o.id]), "format": "html"},
                      el("text", {}, self._option_html(q, o.id)),
                      el("feedback", {"format": "html"}, el("text", {}, "")))
                   for o in q.options]
        shuffle = not any(o.pin for o in q.options)
        return self._question(q, "multichoice",
                              el("single", {}, "true" if single else "false"),
                              el("shuffleanswers", {}, "true" if shuffle else "false"),
                              el("answernumbering", {}, "abc"),
                              el("showstandardinstruction", {}, "1"),
                              *answers)

    def truefalse(self, q: Question, answer: bool) -> El:
        """A ``truefalse`` question (answers named "true" and "false", as Moodle reads them)."""
        return self._question(
            q, "truefalse",
            *(el("answer", {"fraction": "100" if answer is value else "0",
                            "format": "moodle_auto_format"},
                 el("text", {}, "true" if value else "false"),
                 el("feedback", {"format": "html"}, el("text", {}, "")))
              for value in (True, False)))

    def numerical(self, q: Question, answer: float | int, tolerance: float | int,
                  unit: str) -> El:
        """A ``numerical`` question: the key ± ``tolerance``; units are not graded (as here)
        and the unit is shown after the box: ``_____`` in the text is where Moodle puts it."""
        extra = ""
        units: list[El] = []
        if unit:
            extra = f"<p>_____ {self.html(lambda loc: loc.text(q, 'unit'), inline=True)}</p>"
            units = [el("units", {}, el("unit", {}, el("multiplier", {}, "1"),
                                        el("unit_name", {}, unit)))]
        return self._question(
            q, "numerical",
            el("answer", {"fraction": "100", "format": "moodle_auto_format"},
               el("text", {}, number(answer)),
               el("feedback", {"format": "html"}, el("text", {}, "")),
               el("tolerance", {}, number(tolerance))),
            *units,
            el("unitgradingtype", {}, "0"),
            el("unitpenalty", {}, "0"),
            el("showunits", {}, "3"),  # UNITNONE: only the number is read and graded
            el("unitsleft", {}, "0"),
            text_extra=extra)

    def ordering(self, q: Question, order: Sequence[str]) -> El:
        """An ``ordering`` question (qtype_ordering): items in the right order, every item
        shown, vertical, all or nothing as here."""
        return self._question(
            q, "ordering",
            el("layouttype", {}, "VERTICAL"),
            el("selecttype", {}, "ALL"),
            el("selectcount", {}, str(len(order))),
            el("gradingtype", {}, "ALL_OR_NOTHING"),
            el("showgrading", {}, "SHOW"),
            el("numberingstyle", {}, "none"),
            *(el("answer", {"fraction": f"{i}", "format": "html"},
                 el("text", {}, self._option_html(q, option_id)))
              for i, option_id in enumerate(order, 1)))

    def note(self, message: Callable[[], str]) -> None:
        """A difference from the platform's scoring, for the category's description
        (``message`` calls ``_``, so it is given in each language)."""
        self.notes.append(message)

    # The quiz ---------------------------------------------------------------------------

    def _about(self) -> str:
        """Title, summary and pass mark in every language: what the quiz page opens with."""
        quiz, text = self.quiz, self.text
        html = f"<h3>{self.html(lambda loc: loc.quiz_text('title'), inline=True)}</h3>"
        if quiz.summary:
            html += f"<p>{self.html(lambda loc: loc.quiz_text('summary'), inline=True)}</p>"
        passing = text.messages(lambda: pass_summary(quiz, get_language()))
        return html + f"<p><strong>{multilang(passing, inline=True)}</strong></p>"

    def _instructions(self) -> str:
        quiz, total = self.quiz, self.quiz.max_score
        pass_mark = quiz.exact_pass_mark

        def grade_to_pass() -> str:
            lang = get_language()
            return _("Moodle question files carry no quiz settings: set the quiz's Grade to "
                     "pass to {percent} of its Maximum grade, {at_ten} when that is 10.00 "
                     "(Moodle's default) or {at_total} when it is {total}, the sum of these "
                     "questions' marks.").format(
                percent=format_percent(pass_mark, lang),
                at_ten=format_number(pass_mark * 10, lang),
                at_total=format_number(pass_mark * total, lang),
                total=format_number(total, lang))

        paragraphs = [grade_to_pass, *self.notes]
        return "".join(f"<p>{multilang(self.text.messages(p), inline=True)}</p>"
                       for p in paragraphs)

    def category(self) -> list[El]:
        """The category (its description holds the pass mark) and the description question."""
        title = self.quiz.title.replace("`", "").replace("/", "//")
        category = el("question", {"type": "category"},
                      el("category", {}, el("text", {}, f"$course$/top/{title}")),
                      el("info", {"format": "html"},
                         el("text", {}, CData(self._about() + self._instructions()))),
                      el("idnumber", {}, self.quiz.id))
        about = el("question", {"type": "description"},
                   el("name", {}, el("text", {}, f"00 {self.quiz.id}")),
                   el("questiontext", {"format": "html"}, el("text", {}, CData(self._about()))),
                   el("generalfeedback", {"format": "html"}, el("text", {}, "")),
                   el("defaultgrade", {}, "0"),
                   el("penalty", {}, "0"),
                   el("hidden", {}, "0"),
                   el("idnumber", {}, f"{self.quiz.id}-about"))
        return [category, about]

    def questions(self) -> list[El]:
        return [question_type(q.type).moodle_question(q, self) for q in self.quiz.questions]


def multilang(texts: Sequence[Text], inline: bool = False) -> str:
    """HTML for a string in one or more languages: one language as it is, several in
    multilang spans; right-to-left text wrapped with its direction.  A string that reads
    the same in every language (code, a number) is written once."""
    if len({t.value for t in texts}) == 1:
        texts = texts[:1]
    if len(texts) == 1:
        return _directed(texts[0], inline)
    return "".join(f'<span lang="{t.lang}" class="multilang">{_directed(t, inline)}</span>'
                   for t in texts)


def _directed(text: Text, inline: bool) -> str:
    html = str(rich(text))
    if not text.rtl:
        return html
    tag = "bdi" if inline else "div"
    return f'<{tag} dir="rtl" lang="{text.lang}">{html}</{tag}>'


def export_moodle_xml(files: Sequence[QuizFile], langs: Sequence[str] | None = None) -> str:
    """One Moodle XML file for ``files``: each quiz's category, then its questions, with
    every language the quiz is offered in (or ``langs``)."""
    root = el("quiz", {})
    for qf in files:
        writer = MoodleWriter(qf, langs or qf.quiz.languages)
        questions = writer.questions()  # first: the types add their notes to the category
        root.add(*writer.category(), *questions)
    return to_xml(root)
