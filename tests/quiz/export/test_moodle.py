"""``autograder quiz export --format moodle-xml`` (autograder.quiz.export.moodle): the
Moodle XML file, parsed and held against the platform's own key and scoring, and against
the parts of Moodle's import and multilang filter it relies on, restated here from
Moodle's (PHP) source: its list of grades, the filter's two regular expressions."""

from __future__ import annotations

import html
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from decimal import Decimal
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest
from quiz_exports import FILES, expected, subsets

from autograder.core.errors import ContentError
from autograder.quiz.export import export_moodle_xml, export_qti
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Question, Quiz, QuizFile, load_quiz
from autograder.quiz.scoring import key_answers, pass_summary
from autograder.quiz.types import question_type

MOODLE_TYPE = {"single": "multichoice", "multiple": "multichoice", "true_false": "truefalse",
               "numeric": "numerical", "ordering": "ordering"}

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


@pytest.fixture(scope="module")
def moodle() -> ET.Element:
    return ET.fromstring(export_moodle_xml(FILES))



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
