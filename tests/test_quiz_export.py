"""``autograder quiz export``: the Moodle XML file and the QTI 2.1 package, parsed and held
against the formats' published structure and against the platform's own key and scoring.

No XSD of QTI 2.1 or IMS CP ships in a Python package, so the structure is checked here
by hand, against the elements, attributes and child order the 2.1 schema gives.  Moodle's
import and its multilang filter are PHP; the parts the export relies on are restated here
(its list of grades, the filter's two regular expressions) from Moodle's source.
"""

from __future__ import annotations

import html
import itertools
import re
import xml.etree.ElementTree as ET
import zipfile
from collections.abc import Iterator
from decimal import Decimal
from fractions import Fraction
from io import BytesIO
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from autograder.cli.quiz import quiz_cli
from autograder.core.errors import ContentError
from autograder.i18n import _
from autograder.i18n.text import CODE_SPAN, LRI, PDI, Text, using_language
from autograder.quiz.catalog import load_all
from autograder.quiz.export import export_moodle_xml, export_qti
from autograder.quiz.export.xml import CData, el, to_xml
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Question, Quiz, QuizFile, load_quiz
from autograder.quiz.scoring import key_answers, pass_summary
from autograder.quiz.types import question_type, registry
from autograder.quiz.types.single import SingleChoice

REPO = Path(__file__).resolve().parent.parent
FILES = load_all(REPO)
QTI = "http://www.imsglobal.org/xsd/imsqti_v2p1"
CP = "http://www.imsglobal.org/xsd/imscp_v1p1"
QTI_MD = "http://www.imsglobal.org/xsd/imsqti_metadata_v2p1"
XML_LANG = "{http://www.w3.org/XML/1998/namespace}lang"
NCNAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.-]*$")

MOODLE_TYPE = {"single": "multichoice", "multiple": "multichoice", "true_false": "truefalse",
               "numeric": "numerical", "ordering": "ordering"}
QTI_INTERACTION = {"single": "choiceInteraction", "multiple": "choiceInteraction",
                   "true_false": "choiceInteraction", "numeric": "textEntryInteraction",
                   "ordering": "orderInteraction"}
QTI_CARDINALITY = {"single": "single", "multiple": "multiple", "true_false": "single",
                   "numeric": "single", "ordering": "ordered"}

# question_bank::fraction_options_full(): the grades Moodle's import accepts (to 1e-5).
MOODLE_GRADES = [Decimal(v) for v in (
    "1.0", "0.9", "0.8333333", "0.8", "0.75", "0.7", "0.6666667", "0.6", "0.5", "0.4",
    "0.3333333", "0.3", "0.25", "0.2", "0.1666667", "0.1428571", "0.125", "0.1111111", "0.1",
    "0.05")]
MOODLE_GRADES = [Decimal(0), *MOODLE_GRADES, *(-g for g in MOODLE_GRADES)]

# filter_multilang (Moodle 4.x, new syntax): a run of two or more spans, each up to the first
# </span>; the reader's language is kept, else its parent (for ur: en), else the first.
_BLOCK = (r'<span(?:\s+lang="[a-zA-Z0-9_-]+"|\s+class="multilang"){2}\s*>.*?</span>')
MULTILANG_BLOCK = re.compile(rf"({_BLOCK})(\s*{_BLOCK})+", re.I | re.S)
MULTILANG_SPLIT = re.compile(r'<(?:lang|span)[^>]+lang="([a-zA-Z0-9_-]+)"[^>]*>(.*?)'
                             r"</(?:lang|span)>", re.I | re.S)

EDGE = """\
id: 9-edge
title: "Edge: `<tags>` & more"
pass_mark: 0.6
questions:
  - id: with-code
    type: single
    text: "What does `x < 2` give?"
    code: |
      if x < 2 and y > 1:
          print("]]>")
    options:
      - {id: 1st, text: The first}
      - {id: other, text: Another}
      - {id: none, text: None of these, pin: true}
    answer: 1st
    points: 2
  - id: four-right
    type: multiple
    partial_credit: true
    text: Pick the even numbers.
    options: [{id: a, text: "2"}, {id: b, text: "4"}, {id: c, text: "6"}, {id: d, text: "8"},
              {id: e, text: "9"}]
    answer: [a, b, c, d]
  - id: ratio
    type: numeric
    text: What is 1/3, to two places?
    answer: 0.33
    tolerance: 0.005
"""


# -- helpers -----------------------------------------------------------------------------


def multilang_filter(text: str, lang: str) -> str:
    """What Moodle shows a reader of ``lang`` once its multilang filter has run."""
    def keep(block: re.Match[str]) -> str:
        found = {code.lower().replace("-", "_"): body
                 for code, body in MULTILANG_SPLIT.findall(block.group(0))}
        return found.get(lang) or found.get("en") or next(iter(found.values()))
    return MULTILANG_BLOCK.sub(keep, text)


def visible(markup: str) -> str:
    """The text a reader sees in HTML: inline tags dropped, the others a space, entities
    decoded, spaces collapsed."""
    markup = re.sub(r"</?(?:code|bdi|span|strong)\b[^>]*>", "", markup)
    return " ".join(html.unescape(re.sub(r"<[^>]+>", " ", markup)).split())


def expected(text: Text) -> str:
    """The text of a quiz string as shown: code without backticks, spaces collapsed."""
    return " ".join(CODE_SPAN.sub(r"\1", text.value).split())


def strings(quiz: Quiz, q: Question) -> dict[str, Any]:
    """Every string of a question, as a function of its Localizer."""
    out: dict[str, Any] = {"text": lambda loc: loc.text(q, "text")}
    if q.explanation:
        out["explanation"] = lambda loc: loc.text(q, "explanation")
    for o in q.options:
        out[f"options.{o.id}"] = lambda loc, o=o: loc.option(q, o)
    return out


def moodle_questions(root: ET.Element) -> Iterator[tuple[QuizFile, ET.Element, list[ET.Element]]]:
    """Each quiz's category element and its questions, in file order."""
    elements = list(root)
    for qf in FILES:
        start = next(i for i, e in enumerate(elements) if e.get("type") == "category"
                     and e.findtext("idnumber") == qf.quiz.id)
        yield qf, elements[start], elements[start + 1:start + 2 + len(qf.quiz.questions)]


def cdata(question: ET.Element, path: str) -> str:
    return question.findtext(path) or ""


def answer_ids(q: Question, question: ET.Element) -> list[tuple[str, Fraction]]:
    """Each Moodle answer as (option id, fraction of the marks), found by its English text."""
    loc = Localizer(load_quiz_of(q), "en")
    by_text = {expected(loc.option(q, o)): o.id for o in q.options}
    out = []
    for answer in question.findall("answer"):
        shown = visible(multilang_filter(answer.findtext("text") or "", "en"))
        out.append((by_text[shown], Fraction(answer.get("fraction", "")) / 100))
    return out


def load_quiz_of(q: Question) -> Quiz:
    return next(qf.quiz for qf in FILES if q in qf.quiz.questions)


def subsets(ids: list[str]) -> Iterator[list[str]]:
    for n in range(len(ids) + 1):
        yield from (list(c) for c in itertools.combinations(ids, n))


@pytest.fixture(scope="module")
def moodle() -> ET.Element:
    return ET.fromstring(export_moodle_xml(FILES))


@pytest.fixture(scope="module")
def edge(tmp_path_factory: pytest.TempPathFactory) -> QuizFile:
    path = tmp_path_factory.mktemp("edge") / "edge.yaml"
    path.write_text(EDGE)
    return load_quiz(path)


def package(files: list[QuizFile], lang: str) -> dict[str, ET.Element]:
    """A QTI package's files, parsed, by name (checking each is well-formed UTF-8 XML)."""
    with zipfile.ZipFile(BytesIO(export_qti(files, lang))) as zf:
        return {name: ET.fromstring(zf.read(name).decode("utf-8")) for name in zf.namelist()}


@pytest.fixture(scope="module")
def qti_en() -> dict[str, ET.Element]:
    return package(FILES, "en")


@pytest.fixture(scope="module")
def qti_ur() -> dict[str, ET.Element]:
    return package(FILES, "ur")


def q_(tag: str) -> str:
    return f"{{{QTI}}}{tag}"


def item_of(pkg: dict[str, ET.Element], quiz: Quiz, q: Question) -> ET.Element:
    return pkg[f"{quiz.id}/items/{q.id}.xml"]


def qti_value(q: Question, text: str) -> Any:
    return float(text) if q.type == "numeric" else text


# -- the XML writer ----------------------------------------------------------------------


def test_writer_escapes_text_and_splits_cdata_that_holds_its_end() -> None:
    doc = to_xml(el("a", {"b": 'x"<'}, el("t", {}, "1 < 2 & 3"), el("h", {}, CData("x]]>y"))))
    root = ET.fromstring(doc)
    assert root.get("b") == 'x"<' and root.findtext("t") == "1 < 2 & 3"
    assert root.findtext("h") == "x]]>y"


# -- Moodle XML --------------------------------------------------------------------------


def test_moodle_has_every_question_of_every_quiz_with_its_type(moodle: ET.Element) -> None:
    assert moodle.tag == "quiz"
    for qf, category, questions in moodle_questions(moodle):
        title = qf.quiz.title.replace("`", "")
        assert category.findtext("category/text") == f"$course$/top/{title}"
        about, *rest = questions
        assert about.get("type") == "description" and about.findtext("defaultgrade") == "0"
        assert [(e.get("type"), e.findtext("name/text"), e.findtext("idnumber"))
                for e in rest] == [(MOODLE_TYPE[q.type], f"{n:02d} {q.id}", q.id)
                                   for n, q in enumerate(qf.quiz.questions, 1)]
        for q, e in zip(qf.quiz.questions, rest, strict=True):
            assert e.findtext("defaultgrade") == str(q.points)
            assert e.find("questiontext").get("format") == "html"


def test_moodle_keys_match_the_answer_key(moodle: ET.Element) -> None:
    for qf, _category, questions in moodle_questions(moodle):
        key = key_answers(qf.quiz)["answers"]
        for q, e in zip(qf.quiz.questions, questions[1:], strict=True):
            if q.type in ("single", "multiple"):
                assert e.findtext("single") == ("true" if q.type == "single" else "false")
                right = {i for i, f in answer_ids(q, e) if f > 0}
                assert right == ({key[q.id]} if q.type == "single" else set(key[q.id]))
            elif q.type == "true_false":
                fractions = {a.findtext("text"): a.get("fraction") for a in e.findall("answer")}
                assert fractions == {key[q.id]: "100",
                                     "false" if key[q.id] == "true" else "true": "0"}
            elif q.type == "numeric":
                answer = e.find("answer")
                assert float(answer.findtext("text")) == key[q.id]
                assert float(answer.findtext("tolerance")) == q.tolerance
                assert answer.get("fraction") == "100"
                assert e.findtext("units/unit/unit_name") == q.unit
                assert e.findtext("showunits") == "3"  # only the number is graded
            else:
                assert [i for i, _f in answer_ids(q, e)] == key[q.id]
                assert [a.get("fraction") for a in e.findall("answer")] == [
                    str(n) for n in range(1, len(q.options) + 1)]
                assert (e.findtext("gradingtype"), e.findtext("selecttype"),
                        e.findtext("selectcount")) == ("ALL_OR_NOTHING", "ALL",
                                                       str(len(q.options)))


def test_moodle_fractions_are_moodle_grades_and_score_as_the_platform(
        moodle: ET.Element) -> None:
    """Moodle adds the picked answers' fractions and keeps the sum within 0..1; every pick
    of every choice question scores as here, except the documented all-or-nothing case."""
    differ = []
    for qf, _category, questions in moodle_questions(moodle):
        for q, e in zip(qf.quiz.questions, questions[1:], strict=True):
            if q.type not in ("single", "multiple"):
                continue
            for answer in e.findall("answer"):
                value = Decimal(answer.get("fraction", "")) / 100
                assert any(abs(value - g) < Decimal("0.00001") for g in MOODLE_GRADES), value
            fractions = dict(answer_ids(q, e))
            kind = question_type(q.type)
            picks = subsets(list(fractions)) if q.type == "multiple" else (
                [o] for o in fractions)
            for pick in picks:
                moodle_grade = min(1, max(0, sum(fractions[i] for i in pick)))
                ours = kind.credit(q, pick if q.type == "multiple" else pick[0])
                if abs(moodle_grade - ours) > Fraction(1, 10**5):
                    differ.append((q.id, q.partial_credit, sorted(pick)))
    # Only an all-or-nothing question, picked with some right options and no wrong one.
    for qid, partial, pick in differ:
        q = next(q for qf in FILES for q in qf.quiz.questions if q.id == qid)
        assert not partial and set(pick) < set(q.answer) and pick, (qid, pick)
    assert differ, "the shipped quizzes have an all-or-nothing choose-all question"


def test_moodle_carries_both_languages_through_the_multilang_filter(moodle: ET.Element) -> None:
    spans = 0
    for qf, _category, questions in moodle_questions(moodle):
        en, ur = Localizer(qf.quiz, "en"), Localizer(qf.quiz, "ur")
        for q, e in zip(qf.quiz.questions, questions[1:], strict=True):
            shown: dict[str, str] = {
                "text": cdata(e, "questiontext/text"),
                "explanation": cdata(e, "generalfeedback/text")}
            if q.type in ("single", "multiple", "ordering"):
                for option_id, answer in zip(
                        [i for i, _f in answer_ids(q, e)], e.findall("answer"), strict=True):
                    shown[f"options.{option_id}"] = answer.findtext("text") or ""
            for name, get in strings(qf.quiz, q).items():
                markup = shown[name]
                english, urdu = get(en), get(ur)
                for lang, text in (("en", english), ("ur", urdu)):
                    filtered = multilang_filter(markup, lang)
                    assert "multilang" not in filtered, (q.id, name)
                    want = expected(english if text.fallback else text)
                    assert visible(filtered).startswith(want), (q.id, name, lang)
                if not urdu.fallback and urdu.value != english.value:
                    spans += 1
                    assert '<span lang="en" class="multilang">' in markup
                    assert '<span lang="ur" class="multilang"><div dir="rtl" lang="ur">' in markup
    assert spans > 100  # the shipped quizzes are translated


def test_moodle_states_the_pass_mark_where_it_is_seen(moodle: ET.Element) -> None:
    for qf, category, questions in moodle_questions(moodle):
        info = category.findtext("info/text") or ""
        about = questions[0].findtext("questiontext/text") or ""
        for lang in ("en", "ur"):
            for markup in (info, about):
                assert pass_summary(qf.quiz, lang) in visible(multilang_filter(markup, lang))
        assert "Grade to pass" in info and "70%" in info
        strict = [f"Question {n} ({q.id}) is all or nothing here"
                  for n, q in enumerate(qf.quiz.questions, 1)
                  if q.type == "multiple" and not q.partial_credit]
        assert info.count("all or nothing") == len(strict)
        assert all(note in info for note in strict)


def test_moodle_with_one_language_has_no_spans_and_urdu_reads_right_to_left() -> None:
    root = ET.fromstring(export_moodle_xml(FILES[:1], ["ur"]))
    text = root.findall("question")[2].findtext("questiontext/text") or ""
    assert "multilang" not in text and text.startswith('<div dir="rtl" lang="ur">')


def test_moodle_code_pins_fallbacks_and_numbers(edge: QuizFile) -> None:
    root = ET.fromstring(export_moodle_xml([edge]))
    with_code, four, ratio = root.findall("question")[2:]
    text = with_code.findtext("questiontext/text") or ""
    # No Urdu translation: the English alone, no spans; the code block escaped, left to right.
    assert text == ('What does <code dir="ltr">x &lt; 2</code> give?<pre dir="ltr"><code>'
                    'if x &lt; 2 and y &gt; 1:\n    print(&quot;]]&gt;&quot;)</code></pre>')
    assert with_code.findtext("shuffleanswers") == "false"  # a pinned option stays last
    assert with_code.findtext("defaultgrade") == "2"
    assert [a.get("fraction") for a in four.findall("answer")] == ["25"] * 4 + ["-25"]
    assert ratio.findtext("answer/text") == "0.33"
    assert ratio.findtext("answer/tolerance") == "0.005"


def test_moodle_refuses_a_share_it_has_no_grade_for(tmp_path: Path) -> None:
    options = ", ".join(f"{{id: o{i}, text: Option {i}}}" for i in range(12))
    right = ", ".join(f"o{i}" for i in range(11))
    path = tmp_path / "wide.yaml"
    path.write_text(f"id: wide\ntitle: Wide\nquestions:\n  - id: many\n    type: multiple\n"
                    f"    partial_credit: true\n    text: Pick.\n    options: [{options}]\n"
                    f"    answer: [{right}]\n")
    with pytest.raises(ContentError, match=r"wide.yaml:4: questions\[many\]: Moodle has no "
                                           r"grade of 1/11 of the marks for one answer"):
        export_moodle_xml([load_quiz(path)])
    export_qti([load_quiz(path)])  # QTI maps any share


# -- QTI 2.1 -----------------------------------------------------------------------------


def test_qti_manifest_lists_every_file_in_the_package(qti_en: dict[str, ET.Element]) -> None:
    manifest = qti_en["imsmanifest.xml"]
    assert manifest.tag == f"{{{CP}}}manifest"
    assert [c.tag for c in manifest] == [f"{{{CP}}}{t}" for t in
                                         ("metadata", "organizations", "resources")]
    assert manifest.findtext(f"{{{CP}}}metadata/{{{CP}}}schema") == "QTIv2.1 Package"
    resources = manifest.findall(f"{{{CP}}}resources/{{{CP}}}resource")
    ids = [r.get("identifier") for r in resources]
    assert len(set(ids)) == len(ids) and all(NCNAME.match(i or "") for i in ids)
    files = {f.get("href") for r in resources for f in r.findall(f"{{{CP}}}file")}
    assert files == set(qti_en) - {"imsmanifest.xml"}
    for r in resources:
        assert r.get("href") in files
        for dep in r.findall(f"{{{CP}}}dependency"):
            assert dep.get("identifierref") in ids
    tests = [r for r in resources if r.get("type") == "imsqti_test_xmlv2p1"]
    items = [r for r in resources if r.get("type") == "imsqti_item_xmlv2p1"]
    assert len(tests) == len(FILES)
    assert len(items) == sum(len(qf.quiz.questions) for qf in FILES)
    for r in items:
        kind = r.findtext(f"{{{CP}}}metadata/{{{QTI_MD}}}qtiMetadata/{{{QTI_MD}}}interactionType")
        assert kind == qti_en[r.get("href", "")].find(f".//{q_(kind or '')}").tag.split("}")[1]


def test_qti_items_have_the_interaction_and_the_key_of_their_type(
        qti_en: dict[str, ET.Element]) -> None:
    item_order = [q_(t) for t in ("responseDeclaration", "outcomeDeclaration", "itemBody",
                                  "responseProcessing", "modalFeedback")]
    for qf in FILES:
        key = key_answers(qf.quiz)["answers"]
        for q in qf.quiz.questions:
            item = item_of(qti_en, qf.quiz, q)
            assert item.tag == q_("assessmentItem")
            assert item.get("identifier") == f"{qf.quiz.id}.{q.id}"
            assert item.get(XML_LANG) == "en"
            assert (item.get("adaptive"), item.get("timeDependent")) == ("false", "false")
            tags = [c.tag for c in item]
            assert tags == sorted(tags, key=item_order.index)  # the schema's sequence
            response = item.find(q_("responseDeclaration"))
            assert response.get("cardinality") == QTI_CARDINALITY[q.type]
            assert response.get("baseType") == ("float" if q.type == "numeric"
                                                else "identifier")
            correct = [qti_value(q, v.text or "")
                       for v in response.findall(f"{q_('correctResponse')}/{q_('value')}")]
            assert correct == (key[q.id] if isinstance(key[q.id], list) else [key[q.id]])
            interaction = item.find(f"{q_('itemBody')}//{q_(QTI_INTERACTION[q.type])}")
            assert interaction is not None and interaction.get("responseIdentifier") == "RESPONSE"
            choices = interaction.findall(q_("simpleChoice"))
            assert {c.get("identifier") for c in choices} == set(q.option_ids) or not choices
            if q.type == "single":
                assert interaction.get("maxChoices") == "1"
            if q.type == "multiple":
                assert interaction.get("maxChoices") == "0"
            if q.type == "true_false":
                assert [c.text for c in choices] == ["True", "False"]
                assert interaction.get("shuffle") == "false"
            for c in choices:
                pinned = next((o.pin for o in q.options if o.id == c.get("identifier")), False)
                assert (c.get("fixed") == "true") == pinned
            if q.explanation:
                feedback = item.find(q_("modalFeedback"))
                assert " ".join("".join(feedback.itertext()).split()) == expected(
                    Localizer(qf.quiz, "en").text(q, "explanation"))


def _qti_score(q: Question, item: ET.Element, pick: list[str]) -> float:
    """What a QTI 2.1 engine computes for a response, by the item's processing."""
    processing = item.find(q_("responseProcessing"))
    response = item.find(q_("responseDeclaration"))
    correct = [v.text for v in response.iter(q_("value"))]
    template = processing.get("template", "")
    if template.endswith("/match_correct"):
        return float(sorted(pick) == sorted(correct))
    assert template.endswith("/map_response")
    mapping = response.find(q_("mapping"))
    values = {e.get("mapKey"): float(e.get("mappedValue", "")) for e in mapping}
    total = sum(values.get(p, float(mapping.get("defaultValue", "0"))) for p in pick)
    return min(float(mapping.get("upperBound", "inf")),
               max(float(mapping.get("lowerBound", "-inf")), total))


def test_qti_choice_items_score_every_pick_as_the_platform(
        qti_en: dict[str, ET.Element]) -> None:
    for qf in FILES:
        for q in qf.quiz.questions:
            if q.type not in ("single", "multiple"):
                continue
            item = item_of(qti_en, qf.quiz, q)
            kind = question_type(q.type)
            picks = subsets(list(q.option_ids)) if q.type == "multiple" else (
                [o] for o in q.option_ids)
            for pick in picks:
                ours = kind.credit(q, pick if q.type == "multiple" else pick[0])
                theirs = _qti_score(q, item, pick)
                assert theirs >= ours and theirs - float(ours) < 1e-8, (q.id, pick)


def test_qti_numeric_item_compares_within_the_tolerance(qti_en: dict[str, ET.Element]) -> None:
    quiz = next(qf.quiz for qf in FILES if qf.quiz.id == "timer-synchronization")
    q = quiz.question("calls-in-two-seconds")
    item = item_of(qti_en, quiz, q)
    equal = item.find(f".//{q_('responseIf')}/{q_('equal')}")
    assert (equal.get("toleranceMode"), float(equal.get("tolerance", ""))) == (
        "absolute", q.tolerance)
    assert [c.tag for c in equal] == [q_("variable"), q_("correct")]
    assert item.find(f".//{q_('responseIf')}//{q_('baseValue')}").text == "1"
    box = item.find(f"{q_('itemBody')}/{q_('p')}")
    assert box.find(q_("textEntryInteraction")) is not None and "calls" in "".join(box.itertext())


def test_qti_tests_weight_points_and_carry_the_pass_mark(qti_en: dict[str, ET.Element]) -> None:
    for qf in FILES:
        quiz = qf.quiz
        test = qti_en[f"{quiz.id}/test.xml"]
        assert test.tag == q_("assessmentTest") and test.get("identifier") == quiz.id
        assert [c.tag for c in test] == [q_("outcomeDeclaration")] * 4 + [
            q_("testPart"), q_("outcomeProcessing")]
        outcomes = {o.get("identifier"): o for o in test.findall(q_("outcomeDeclaration"))}
        default = {k: o.findtext(f"{q_('defaultValue')}/{q_('value')}")
                   for k, o in outcomes.items()}
        assert Fraction(default["PASS_MARK"]) == quiz.exact_pass_mark
        assert int(default["MAXSCORE"]) == quiz.max_score and default["PASS"] == "false"
        cut = quiz.exact_pass_mark * quiz.max_score
        assert Fraction(outcomes["SCORE"].get("masteryValue")) == cut
        assert outcomes["SCORE"].get("interpretation") == pass_summary(quiz, "en")
        gte = test.find(f"{q_('outcomeProcessing')}/{q_('setOutcomeValue')}[@identifier="
                        f"'PASS']/{q_('gte')}")
        assert Fraction(gte.find(q_("baseValue")).text) == cut
        assert gte.find(q_("variable")).get("identifier") == "SCORE"
        summed = test.find(f".//{q_('sum')}/{q_('testVariables')}")
        assert (summed.get("variableIdentifier"), summed.get("weightIdentifier")) == (
            "SCORE", "W")
        refs = test.findall(f".//{q_('assessmentItemRef')}")
        for q, ref in zip(quiz.questions, refs, strict=True):
            item = qti_en[f"{quiz.id}/{ref.get('href')}"]  # relative to the test's folder
            assert ref.get("identifier") == item.get("identifier")
            assert ref.find(q_("weight")).get("value") == str(q.points)
        rubric = test.find(f".//{q_('rubricBlock')}")
        assert pass_summary(quiz, "en") in "".join(rubric.itertext())


def test_qti_english_package_stays_within_the_2_1_schema(qti_en: dict[str, ET.Element]) -> None:
    for name, root in qti_en.items():
        for node in root.iter():
            assert "dir" not in node.attrib, name  # dir arrived in QTI 2.2
            for attr in ("identifier", "responseIdentifier", "mapKey"):
                assert NCNAME.match(node.get(attr, "x")), (name, node.get(attr))


def test_qti_urdu_package_is_urdu_and_right_to_left(qti_ur: dict[str, ET.Element]) -> None:
    with using_language("ur"):
        labels = [_("True"), _("False")]
    assert labels != ["True", "False"]  # the platform's catalog translates them
    for qf in FILES:
        ur = Localizer(qf.quiz, "ur")
        for q in qf.quiz.questions:
            item = item_of(qti_ur, qf.quiz, q)
            assert item.get(XML_LANG) == "ur"
            body = item.find(q_("itemBody"))
            assert body.get("dir") == "rtl"
            text = "".join(body.find(q_("div")).itertext()).replace(LRI, "").replace(PDI, "")
            assert " ".join(text.split()) == expected(ur.text(q, "text"))
            if q.type == "true_false":
                assert [c.text for c in body.iter(q_("simpleChoice"))] == [
                    f"{LRI}{v}{PDI}" if v.isascii() else v for v in labels]
        test = qti_ur[f"{qf.quiz.id}/test.xml"]
        assert pass_summary(qf.quiz, "ur") in "".join(test.find(f".//{q_('rubricBlock')}")
                                                      .itertext())


def test_qti_ids_starting_with_a_digit_and_fallbacks(edge: QuizFile) -> None:
    pkg = package([edge], "ur")
    item = pkg["9-edge/items/with-code.xml"]
    assert item.get("identifier") == "_9-edge.with-code"
    assert [v.text for v in item.iter(q_("value"))][:1] == ["_1st"]
    choice = {c.get("identifier"): c for c in item.iter(q_("simpleChoice"))}
    assert choice["none"].get("fixed") == "true" and choice["_1st"].get("fixed") is None
    question = item.find(f"{q_('itemBody')}/{q_('div')}")
    assert question.get(XML_LANG) == "en" and question.get("dir") is None  # not translated
    assert question.find(q_("pre")).get("dir") == "ltr"
    assert question.findtext(f"{q_('pre')}/{q_('code')}") == edge.quiz.questions[0].code.rstrip()
    four = pkg["9-edge/items/four-right.xml"]
    values = [e.get("mappedValue") for e in four.iter(q_("mapEntry"))]
    assert values == ["0.25"] * 4 + ["-0.25"]
    test = pkg["9-edge/test.xml"]
    assert test.find(f".//{q_('assessmentItemRef')}/{q_('weight')}").get("value") == "2"
    assert Fraction(test.find(f".//{q_('gte')}/{q_('baseValue')}").text) == Fraction(24, 10)


def test_qti_package_is_the_same_bytes_each_time() -> None:
    assert export_qti(FILES, "ur") == export_qti(FILES, "ur")


# -- the command -------------------------------------------------------------------------


class NoExport(SingleChoice):
    """A type that has no LMS form: the export must name the question, not crash."""

    name = "no_export"

    def moodle_question(self, q: Question, moodle: Any) -> Any:
        return super(SingleChoice, self).moodle_question(q, moodle)

    def qti_item(self, q: Question, qti: Any) -> Any:
        return super(SingleChoice, self).qti_item(q, qti)


def test_export_command_writes_both_formats(tmp_path: Path) -> None:
    runner = CliRunner()
    out = tmp_path / "part2.xml"
    result = runner.invoke(quiz_cli, ["export", "rclpy-part2", "--format", "moodle-xml",
                                      "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output.strip() == str(out)
    root = ET.fromstring(out.read_text(encoding="utf-8"))
    assert len(root.findall("question")) == 2 + 5
    out = tmp_path / "all.zip"
    result = runner.invoke(quiz_cli, ["export", "--format", "qti", "--lang", "ur",
                                      "--out", str(out)])
    assert result.exit_code == 0, result.output
    with zipfile.ZipFile(out) as zf:
        assert {n.split("/")[0] for n in zf.namelist()} == {
            "imsmanifest.xml", *(qf.quiz.id for qf in FILES)}


def test_export_command_bad_input_exits_2(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    runner = CliRunner()
    result = runner.invoke(quiz_cli, ["export", "nope", "--format", "qti"])
    assert result.exit_code == 2 and "No quiz named nope" in result.output
    result = runner.invoke(quiz_cli, ["export", "rclpy-part2", "--format", "pdf"])
    assert result.exit_code == 2
    blocker = tmp_path / "file"
    blocker.write_text("")
    result = runner.invoke(quiz_cli, ["export", "rclpy-part2", "--format", "moodle-xml",
                                      "--out", str(blocker / "x.xml")])
    assert result.exit_code == 2 and "cannot write" in result.output

    monkeypatch.setitem(registry(), "no_export", NoExport())
    path = tmp_path / "toy.yaml"
    path.write_text("id: toy\ntitle: Toy\nlanguages: [en]\n"  # English: no catalog needed
                    "questions:\n  - id: pick\n    type: no_export\n"
                    "    text: Pick.\n    options: [{id: a, text: A}, {id: b, text: B}]\n"
                    "    answer: a\n")
    for fmt in ("moodle-xml", "qti"):
        result = runner.invoke(quiz_cli, ["export", str(path), "--format", fmt,
                                          "--out", str(tmp_path / "x")])
        assert result.exit_code == 2, result.output
        assert f"toy.yaml:5: questions[pick]: a no_export question cannot be exported to {fmt}" \
            in result.output
