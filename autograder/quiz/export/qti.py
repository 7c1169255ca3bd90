"""IMS QTI 2.1: a content package (zip) of one ``assessmentItem`` per question and an
``assessmentTest`` per quiz, listed in ``imsmanifest.xml``; one language per package.

Each item scores 0 to 1 in ``SCORE`` (the share of the question's points the platform
gives); the test weights each item by its points (``weight``, which importers such as
Canvas read as the question's points), sums them into ``SCORE`` and sets ``PASS`` when the
sum reaches the pass mark, which it also states as ``PASS_MARK`` (a fraction of
``MAXSCORE``) and as the ``masteryValue`` of ``SCORE``.

Right-to-left text: QTI 2.1 has ``xml:lang`` on every body element but no ``dir``
(added in QTI 2.2), so an Urdu item carries ``dir="rtl"`` on its ``itemBody`` and text
blocks as the one attribute outside the 2.1 schema; code spans and Latin words inside
Urdu are isolated with Unicode isolates (U+2066..U+2069), which need no markup.  English
packages use the 2.1 schema only.

Each question type builds its own item (``QuestionType.qti_item``) with the builders here:
``choice``, ``order`` and ``numeric``.
"""

from __future__ import annotations

import dataclasses
import io
import math
import re
import zipfile
from collections.abc import Mapping, Sequence
from decimal import Decimal, localcontext
from fractions import Fraction

from autograder.core.errors import ContentError
from autograder.core.results import exact
from autograder.i18n import is_rtl
from autograder.i18n.text import CODE_SPAN, LRI, PDI, Text, isolate_runs, plain, using_language
from autograder.quiz.export.common import Languages, paragraphs
from autograder.quiz.export.xml import El, el, to_xml
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Question, QuizFile
from autograder.quiz.scoring import pass_summary
from autograder.quiz.types import question_type

FORMAT = "qti"
QTI_NS = "http://www.imsglobal.org/xsd/imsqti_v2p1"
QTI_XSD = "http://www.imsglobal.org/xsd/qti/qtiv2p1/imsqti_v2p1.xsd"
CP_NS = "http://www.imsglobal.org/xsd/imscp_v1p1"
CP_XSD = "http://www.imsglobal.org/xsd/qti/qtiv2p1/qtiv2p1_imscpv1p2_v1p0.xsd"
QTI_MD_NS = "http://www.imsglobal.org/xsd/imsqti_metadata_v2p1"
QTI_MD_XSD = "http://www.imsglobal.org/xsd/qti/qtiv2p1/imsqti_metadata_v2p1.xsd"
XSI_NS = "http://www.w3.org/2001/XMLSchema-instance"
TEMPLATES = "http://www.imsglobal.org/question/qti_v2p1/rptemplates/"
MATCH_CORRECT = TEMPLATES + "match_correct"
MAP_RESPONSE = TEMPLATES + "map_response"
ITEM_TYPE, TEST_TYPE = "imsqti_item_xmlv2p1", "imsqti_test_xmlv2p1"
_DATE = (1980, 1, 1, 0, 0, 0)  # zip entries carry no build time: the same quiz, the same bytes


def qti_id(value: str) -> str:
    """An id as a QTI identifier (an XML NCName): one starting with a digit gets "_"."""
    return value if value[:1].isalpha() else "_" + value


def decimal(value: Fraction | float | int) -> str:
    """A number as XML Schema's ``double`` text: exact when it ends, else 15 digits."""
    value = exact(value) if isinstance(value, float) else Fraction(value)
    with localcontext() as ctx:
        ctx.prec = 15
        text = format((Decimal(value.numerator) / Decimal(value.denominator)).normalize(), "f")
    return "0" if text == "-0" else text


def _away_from_zero(value: Fraction, places: int = 9) -> Fraction:
    """``value`` rounded away from zero at ``places`` decimals."""
    scale = 10 ** places
    return (1 if value >= 0 else -1) * Fraction(math.ceil(abs(value) * scale), scale)


@dataclasses.dataclass(frozen=True)
class QtiItem:
    """One question as an ``assessmentItem``: its identifier, the interaction it uses (for
    the manifest's metadata) and the element."""

    identifier: str
    interaction: str
    element: El
    feedback: bool


class QtiWriter:
    """Writes one quiz's items and test in one language; types call the builders."""

    def __init__(self, qf: QuizFile, lang: str) -> None:
        self.qf, self.quiz, self.lang = qf, qf.quiz, lang
        self.loc = Localizer(qf.quiz, lang)
        self.rtl = is_rtl(lang)
        self.text = Languages(qf, (lang,))

    def unsupported(self, q: Question) -> ContentError:
        """The error for a question whose type has no QTI item."""
        return self.text.unsupported(q, FORMAT)

    # Text -------------------------------------------------------------------------------

    def _inline(self, text: str, rtl: bool) -> list[El | str]:
        """One paragraph: `code` as ``<code>``; in right-to-left text, code and Latin
        runs are isolated (LRI...PDI)."""
        out: list[El | str] = []
        for i, piece in enumerate(CODE_SPAN.split(text)):
            if i % 2:
                out.append(el("code", {}, f"{LRI}{piece}{PDI}" if rtl else piece))
            elif piece:
                out.append(isolate_runs(piece) if rtl else piece)
        return out

    def flow(self, text: Text, cls: str | None = None) -> El:
        """A string as a ``div`` of paragraphs (an English fallback marked ``xml:lang``)."""
        div = el("div", {"class": cls, "xml:lang": "en" if text.fallback else None,
                         "dir": "rtl" if text.rtl else None})
        for p in paragraphs(text.value):
            div.add(el("p", {}, *self._inline(p, text.rtl)))
        return div

    def inline(self, text: Text) -> list[El | str]:
        return self._inline(" ".join(text.value.split()), text.rtl)

    def _question_text(self, q: Question) -> El:
        div = self.flow(self.loc.text(q, "text"), "question")
        if q.code.strip():
            div.add(el("pre", {"dir": "ltr" if self.rtl else None},
                       el("code", {}, q.code.rstrip())))
        return div

    # The item ---------------------------------------------------------------------------

    def _item(self, q: Question, interaction: str, response: El, body: list[El],
              processing: El) -> QtiItem:
        identifier = qti_id(f"{self.quiz.id}.{q.id}")
        n = self.quiz.questions.index(q) + 1
        item = el("assessmentItem", {
            "xmlns": QTI_NS, "xmlns:xsi": XSI_NS,
            "xsi:schemaLocation": f"{QTI_NS} {QTI_XSD}",
            "identifier": identifier, "title": f"{n:02d} {q.id}",
            "adaptive": "false", "timeDependent": "false", "xml:lang": self.lang})
        item.add(response,
                 _outcome("SCORE", "float", "0"),
                 _outcome("MAXSCORE", "float", "1"))
        if q.explanation:
            item.add(_outcome("FEEDBACK", "identifier", "general_explanation"))
        item.add(el("itemBody", {"dir": "rtl" if self.rtl else None},
                    self._question_text(q), *body),
                 processing)
        if q.explanation:
            item.add(el("modalFeedback", {"outcomeIdentifier": "FEEDBACK",
                                          "identifier": "general_explanation",
                                          "showHide": "show"},
                        self.flow(self.loc.text(q, "explanation"), "explanation")))
        return QtiItem(identifier, interaction, item, bool(q.explanation))

    def _choices(self, q: Question, shuffle: bool) -> list[El]:
        pinned = {o.id for o in q.options if o.pin}
        views = question_type(q.type).option_views(self.quiz, q, None, self.loc)
        return [el("simpleChoice", {"identifier": qti_id(v.id),
                                    "fixed": "true" if shuffle and v.id in pinned else None},
                   *self.inline(v.text))
                for v in views]

    # The builders the question types call -----------------------------------------------

    def choice(self, q: Question, correct: Sequence[str], max_choices: int,
               mapping: Mapping[str, Fraction] | None = None, shuffle: bool = True) -> QtiItem:
        """A ``choiceInteraction`` over the question's options (as its type lists them):
        one pick (``max_choices=1``) or several (0: no limit); scored by ``match_correct``,
        or with ``mapping`` (each id's share, negative for a wrong pick) by
        ``map_response``, clipped to 0..1.  Shares are rounded away from zero in the 9th
        decimal, so every right pick of several makes exactly 1 and no partial score
        falls below the platform's."""
        cardinality = "single" if max_choices == 1 else "multiple"
        response = el("responseDeclaration", {"identifier": "RESPONSE",
                                              "cardinality": cardinality,
                                              "baseType": "identifier"},
                      el("correctResponse", {}, *(el("value", {}, qti_id(c)) for c in correct)))
        if mapping is None:
            processing = el("responseProcessing", {"template": MATCH_CORRECT})
        else:
            response.add(el("mapping", {"lowerBound": "0", "upperBound": "1",
                                        "defaultValue": "0"},
                            *(el("mapEntry", {"mapKey": qti_id(k),
                                              "mappedValue": decimal(_away_from_zero(v))})
                              for k, v in mapping.items())))
            processing = el("responseProcessing", {"template": MAP_RESPONSE})
        interaction = el("choiceInteraction", {"responseIdentifier": "RESPONSE",
                                               "shuffle": "true" if shuffle else "false",
                                               "maxChoices": str(max_choices)},
                         *self._choices(q, shuffle))
        return self._item(q, "choiceInteraction", response, [interaction], processing)

    def order(self, q: Question, order: Sequence[str]) -> QtiItem:
        """An ``orderInteraction`` of the items, shuffled; right only in ``order``."""
        response = el("responseDeclaration", {"identifier": "RESPONSE", "cardinality": "ordered",
                                              "baseType": "identifier"},
                      el("correctResponse", {}, *(el("value", {}, qti_id(c)) for c in order)))
        interaction = el("orderInteraction", {"responseIdentifier": "RESPONSE",
                                              "shuffle": "true"}, *self._choices(q, True))
        return self._item(q, "orderInteraction", response, [interaction],
                          el("responseProcessing", {"template": MATCH_CORRECT}))

    def numeric(self, q: Question, answer: float | int, tolerance: float | int,
                unit: str) -> QtiItem:
        """A ``textEntryInteraction`` read as a float, right within ``tolerance`` of the
        key (``equal`` with ``toleranceMode="absolute"``), the unit after the box."""
        response = el("responseDeclaration", {"identifier": "RESPONSE", "cardinality": "single",
                                              "baseType": "float"},
                      el("correctResponse", {}, el("value", {}, decimal(answer))))
        box = el("p", {"class": "answer"},
                 el("textEntryInteraction", {"responseIdentifier": "RESPONSE",
                                             "expectedLength": "12"}))
        if unit:
            box.add(" ", *self.inline(self.loc.text(q, "unit")))
        right = el("equal", {"toleranceMode": "absolute", "tolerance": decimal(tolerance),
                             "includeLowerBound": "true", "includeUpperBound": "true"},
                   el("variable", {"identifier": "RESPONSE"}),
                   el("correct", {"identifier": "RESPONSE"}))
        processing = el("responseProcessing", {},
                        el("responseCondition", {},
                           el("responseIf", {}, right, _set_score("1")),
                           el("responseElse", {}, _set_score("0"))))
        return self._item(q, "textEntryInteraction", response, [box], processing)

    # The test ---------------------------------------------------------------------------

    def items(self) -> list[QtiItem]:
        return [question_type(q.type).qti_item(q, self) for q in self.quiz.questions]

    def test(self, items: Sequence[QtiItem], hrefs: Sequence[str]) -> El:
        """The ``assessmentTest``: every item weighted by its points, the pass mark as
        ``PASS_MARK``, ``SCORE``'s ``masteryValue`` and the ``PASS`` rule."""
        quiz, loc = self.quiz, self.loc
        total = quiz.max_score
        cut = quiz.exact_pass_mark * total
        title = plain(loc.quiz_text("title"))
        about: list[El] = [el("h2", {}, *self.inline(loc.quiz_text("title")))]
        if quiz.summary:
            about.append(el("p", {}, *self.inline(loc.quiz_text("summary"))))
        about.append(el("p", {}, el("strong", {}, pass_summary(quiz, self.lang))))
        section = el("assessmentSection", {"identifier": "questions", "title": title,
                                           "visible": "false"},
                     el("rubricBlock", {"view": "candidate",
                                        "dir": "rtl" if self.rtl else None}, *about))
        for q, item, href in zip(quiz.questions, items, hrefs, strict=True):
            section.add(el("assessmentItemRef", {"identifier": item.identifier, "href": href},
                           el("weight", {"identifier": "W", "value": str(q.points)})))
        score = el("outcomeDeclaration", {"identifier": "SCORE", "cardinality": "single",
                                          "baseType": "float", "normalMinimum": "0",
                                          "normalMaximum": str(total),
                                          "masteryValue": decimal(cut),
                                          "interpretation": pass_summary(quiz, self.lang)},
                   el("defaultValue", {}, el("value", {}, "0")))
        return el("assessmentTest", {
            "xmlns": QTI_NS, "xmlns:xsi": XSI_NS,
            "xsi:schemaLocation": f"{QTI_NS} {QTI_XSD}",
            "identifier": qti_id(quiz.id), "title": title},
            score,
            _outcome("MAXSCORE", "float", str(total)),
            _outcome("PASS_MARK", "float", decimal(quiz.exact_pass_mark)),
            _outcome("PASS", "boolean", "false"),
            el("testPart", {"identifier": "part", "navigationMode": "nonlinear",
                            "submissionMode": "simultaneous"}, section),
            el("outcomeProcessing", {},
               el("setOutcomeValue", {"identifier": "SCORE"},
                  el("sum", {}, el("testVariables", {"variableIdentifier": "SCORE",
                                                     "weightIdentifier": "W"}))),
               el("setOutcomeValue", {"identifier": "PASS"},
                  el("gte", {}, el("variable", {"identifier": "SCORE"}),
                     el("baseValue", {"baseType": "float"}, decimal(cut))))))


def _outcome(identifier: str, base_type: str, default: str) -> El:
    return el("outcomeDeclaration", {"identifier": identifier, "cardinality": "single",
                                     "baseType": base_type},
              el("defaultValue", {}, el("value", {}, default)))


def _set_score(value: str) -> El:
    return el("setOutcomeValue", {"identifier": "SCORE"},
              el("baseValue", {"baseType": "float"}, value))


def _safe_name(value: str) -> str:
    return re.sub(r"[^a-z0-9_.-]", "_", value)


def export_qti(files: Sequence[QuizFile], lang: str = "en") -> bytes:
    """A QTI 2.1 content package (zip bytes): per quiz, ``<quiz>/test.xml`` and
    ``<quiz>/items/<question>.xml``, all listed in ``imsmanifest.xml``."""
    entries: dict[str, str] = {}
    resources = el("resources", {})
    for qf in files:
        writer = QtiWriter(qf, lang)
        folder = _safe_name(qf.quiz.id)
        hrefs = [f"{folder}/items/{_safe_name(q.id)}.xml" for q in qf.quiz.questions]
        test_href = f"{folder}/test.xml"
        with using_language(lang):  # the platform's words in items (True, False) too
            items = writer.items()
            # an item's href in the test is relative to the test's own folder
            test_xml = to_xml(writer.test(items, [h.split("/", 1)[1] for h in hrefs]))
        entries[test_href] = test_xml
        test = el("resource", {"identifier": f"test-{folder}", "type": TEST_TYPE,
                               "href": test_href}, el("file", {"href": test_href}))
        item_resources = []
        for item, href in zip(items, hrefs, strict=True):
            entries[href] = to_xml(item.element)
            resource_id = f"item-{item.identifier}"
            test.add(el("dependency", {"identifierref": resource_id}))
            item_resources.append(el(
                "resource", {"identifier": resource_id, "type": ITEM_TYPE, "href": href},
                el("metadata", {},
                   el("imsqti:qtiMetadata", {},
                      el("imsqti:timeDependent", {}, "false"),
                      el("imsqti:interactionType", {}, item.interaction),
                      el("imsqti:feedbackType", {},
                         "nonadaptive" if item.feedback else "none"),
                      el("imsqti:solutionAvailable", {}, "true"))),
                el("file", {"href": href})))
        resources.add(test, *item_resources)
    manifest = el("manifest", {
        "xmlns": CP_NS, "xmlns:imsqti": QTI_MD_NS, "xmlns:xsi": XSI_NS,
        "xsi:schemaLocation": f"{CP_NS} {CP_XSD} {QTI_MD_NS} {QTI_MD_XSD}",
        "identifier": "manifest-" + "-".join(_safe_name(qf.quiz.id) for qf in files)},
        el("metadata", {}, el("schema", {}, "QTIv2.1 Package"),
           el("schemaversion", {}, "1.0.0")),
        el("organizations", {}),
        resources)
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, text in [("imsmanifest.xml", to_xml(manifest)), *entries.items()]:
            info = zipfile.ZipInfo(name, _DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            zf.writestr(info, text.encode("utf-8"))
    return buffer.getvalue()
