"""``autograder quiz export --format qti`` (autograder.quiz.export.qti): the QTI 2.1 package,
parsed and held against the format's published structure and the platform's own key and
scoring. No XSD of QTI 2.1 or IMS CP ships in a Python package, so the structure is checked
here by hand, against the elements, attributes and child order the 2.1 schema gives."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
import zipfile
from fractions import Fraction
from io import BytesIO
from typing import Any

import pytest
from quiz_exports import FILES, expected, subsets

from autograder.i18n import _
from autograder.i18n.text import LRI, PDI, using_language
from autograder.quiz.export import export_qti
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Question, Quiz, QuizFile
from autograder.quiz.scoring import key_answers, pass_summary
from autograder.quiz.types import question_type

QTI = "http://www.imsglobal.org/xsd/imsqti_v2p1"
CP = "http://www.imsglobal.org/xsd/imscp_v1p1"
QTI_MD = "http://www.imsglobal.org/xsd/imsqti_metadata_v2p1"
XML_LANG = "{http://www.w3.org/XML/1998/namespace}lang"
NCNAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.-]*$")

QTI_INTERACTION = {"single": "choiceInteraction", "multiple": "choiceInteraction",
                   "true_false": "choiceInteraction", "numeric": "textEntryInteraction",
                   "ordering": "orderInteraction"}
QTI_CARDINALITY = {"single": "single", "multiple": "multiple", "true_false": "single",
                   "numeric": "single", "ordering": "ordered"}



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
