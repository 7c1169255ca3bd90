"""The quiz in headless Chromium: the server end to end, and the Urdu page as rendered."""

from __future__ import annotations

import contextlib
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from browser import chromium_page, fonts_used, ink
from quiz_course import QUIZ_COURSE

from autograder.quiz.catalog import load_all
from autograder.quiz.model import Question, Quiz, load_quiz
from autograder.quiz.render import render_page
from autograder.quiz.scoring import check_answers, key_answers, score
from autograder.quiz.server import QuizServer

REPO = Path(__file__).resolve().parents[2]


pytestmark = pytest.mark.usefixtures("in_quiz_course")


def test_serve_pick_urdu_answer_submit_see_verdict(server: QuizServer) -> None:
    with chromium_page() as page:
        page.goto(server.url)
        page.click('a[hreflang="ur"]')
        page.wait_for_url("**/?lang=ur")
        page.click('a[href^="/quiz/rclpy-part2/"]')
        assert page.get_attribute("html", "lang") == "ur"
        assert page.get_attribute("html", "dir") == "rtl"
        # Radio buttons sit on the right of their text in RTL.
        label = page.locator('label.option:has(input[value="cpython-lock"])')
        radio = label.locator("input").bounding_box()
        text = label.locator("span").bounding_box()
        assert radio["x"] > text["x"] + text["width"] - 1
        for name, value in [("callback-groups-purpose", "concurrency"),
                            ("declare-parameters", "declare"), ("gil", "cpython-lock"),
                            ("shared-resources", "reentrant"), ("python-advantage", "rapid")]:
            page.check(f'input[name="q:{name}"][value="{value}"]')
        page.click("#submit")
        verdict = page.locator("#verdict")
        verdict.wait_for()
        assert "کامیاب" in verdict.inner_text() and "ابھی" not in verdict.inner_text()
        assert "5 میں سے 4 (80%)" in verdict.inner_text()
        feedback = page.locator("#feedback-shared-resources .status-failed").inner_text()
        assert feedback == "آپ کا جواب غلط ہے۔"
        assert page.get_attribute("html", "dir") == "rtl"


_LAYOUT_JS = """
() => {
  const rect = (el) => el.getBoundingClientRect();
  const textRect = (el) => { const r = document.createRange(); r.selectNodeContents(el);
                             return r.getBoundingClientRect(); };
  const out = [];
  const selector = "h1, .summary, .pass-mark, .question .text, label.option span";
  for (const el of document.querySelectorAll(selector)) {
    const c = rect(el), t = textRect(el);
    out.push({sel: el.id || el.className || el.tagName, cl: c.left, cr: c.right, ct: c.top,
              cb: c.bottom, tl: t.left, tr: t.right, tt: t.top, tb: t.bottom,
              overflow: el.scrollHeight - el.clientHeight});
  }
  const body = getComputedStyle(document.body);
  const code = document.querySelector(".question code");
  return {items: out, font: body.fontFamily, lineHeight: body.lineHeight,
          fontSize: body.fontSize, direction: body.direction,
          nastaliq: document.fonts.check('20px "Noto Nastaliq Urdu"', "کیا"),
          codeDirection: getComputedStyle(code).direction,
          codeUnicodeBidi: getComputedStyle(code).unicodeBidi};
}
"""


@contextlib.contextmanager
def urdu_page(tmp_path: Path, quiz_file: str) -> Iterator[Any]:
    """The Urdu page of ``quizzes/<quiz_file>.yaml`` (seed 7) open in Chromium, fonts
    loaded."""
    quiz = load_quiz(QUIZ_COURSE / "quizzes" / f"{quiz_file}.yaml").quiz
    html = tmp_path / f"{quiz_file}.ur.html"
    html.write_text(render_page(quiz, "ur", seed=7), encoding="utf-8")
    with chromium_page() as page:
        page.goto(html.as_uri())
        page.evaluate("document.fonts.ready")
        yield page


def test_urdu_page_renders_rtl_in_nastaliq_unclipped(tmp_path: Path) -> None:
    with urdu_page(tmp_path, "part2-rclpy") as page:
        layout = page.evaluate(_LAYOUT_JS)
        png = page.screenshot(full_page=True, path=str(tmp_path / "quiz-rclpy-part2-ur.png"))
        title = page.locator("h1").bounding_box()
        stats = ink(page, png)
        title_ink = ink(page, png, (0, int(title["y"]), 900, int(title["height"])))
    assert layout["direction"] == "rtl"
    assert layout["font"].startswith('"Noto Nastaliq Urdu"')
    assert layout["nastaliq"], "Noto Nastaliq Urdu is not available (fonts-noto-core)"
    assert (layout["codeDirection"], layout["codeUnicodeBidi"]) == ("ltr", "isolate")
    for item in layout["items"]:
        # Right-aligned: each line starts at its container's right edge.
        assert abs(item["cr"] - item["tr"]) < 3, item
        # Not clipped: the glyphs' box lies within the container's, nothing overflows.
        assert item["tt"] >= item["ct"] - 1 and item["tb"] <= item["cb"] + 1, item
        assert item["overflow"] <= 0, item
    # Not blank, and the title's ink hugs the right side of the page.
    assert stats["ink"] > 20_000
    assert title_ink["right"] > 900 * 0.85 and title_ink["left"] > 900 * 0.2


_APART_JS = """
(id) => {
  // The question's number ("5.") and the digits its text begins with ("50 Hz ...").
  const text = document.getElementById(id), number = text.querySelector(".number");
  const walker = document.createTreeWalker(text, NodeFilter.SHOW_TEXT);
  let node;
  while ((node = walker.nextNode()) && (number.contains(node) || !/\\d/.test(node.data))) {}
  const at = node.data.search(/\\d/), range = document.createRange();
  range.setStart(node, at); range.setEnd(node, at + node.data.slice(at).match(/\\d+/)[0].length);
  const n = number.getBoundingClientRect(), d = range.getBoundingClientRect();
  const holder = node.parentElement;
  return {number: [n.left, n.right, n.top, n.bottom], digits: [d.left, d.right, d.top, d.bottom],
          numberBidi: getComputedStyle(number).unicodeBidi,
          holder: holder.tagName, holderLang: holder.lang,
          holderBidi: getComputedStyle(holder).unicodeBidi};
}
"""


def test_question_beginning_with_a_number_keeps_its_number_apart(tmp_path: Path) -> None:
    # "50 Hz اور 10 Hz ..." numbered 5 once read "5.50 Hz": the bidi algorithm joined the
    # number's "5." and the text's "50" into one left-to-right number.
    with urdu_page(tmp_path, "timer-synchronization") as page:
        found = page.evaluate(_APART_JS, "q-keep-in-step-text")
        page.locator("#q-keep-in-step-text").screenshot(path=str(tmp_path / "q5-ur.png"))
    assert found["numberBidi"] == "isolate"
    assert (found["holder"], found["holderLang"], found["holderBidi"]) == ("BDI", "en", "isolate")
    (n_left, _, n_top, n_bottom), (_, d_right, d_top, d_bottom) = (
        found["number"], found["digits"])
    assert d_top < n_bottom and n_top < d_bottom, found  # on the same line
    # Right to left, the number comes first: on the right, with a gap before "50".
    assert n_left - d_right >= 3, found


def test_latin_runs_in_urdu_are_english_in_a_latin_face(tmp_path: Path) -> None:
    with urdu_page(tmp_path, "timer-synchronization") as page:
        family = page.evaluate(
            "getComputedStyle(document.querySelector('.question bdi:lang(en)')).fontFamily")
        runs = fonts_used(page, ".question bdi")
        unmarked = page.evaluate("document.querySelectorAll('.question bdi:not([lang])')"
                                 ".length")
    assert family.startswith('"Noto Sans"'), family
    assert len(runs) > 20 and unmarked == 0
    # Letters and digits of every run ("50 Hz", "timer callback") from one Latin font: no
    # serif fallback for the letters, no Nastaliq for the digits.
    for fonts in runs:
        assert set(fonts) == {"Noto Sans"}, fonts


def _enter_key(page: Any, question: Question) -> None:
    """Fill in the key of one question, as a student would, whatever its inputs."""
    qid, key = question.id, question.key()
    if question.type == "numeric":
        page.fill(f'input[name="q:{qid}"]', str(key))
    elif question.type == "ordering":
        for place, item in enumerate(key, 1):
            page.select_option(f'select[name="q:{qid}:{item}"]', str(place))
    else:
        for option in key if isinstance(key, list) else [key]:
            page.check(f'input[name="q:{qid}"][value="{option}"]')


def _comparable(quiz: Quiz, answers: dict[str, Any]) -> dict[str, Any]:
    """Choose-all answers list ids in page order, the key in file order: sort those."""
    return {q.id: sorted(answers[q.id]) if q.type == "multiple" else answers[q.id]
            for q in quiz.questions}


def test_saved_answers_file_scores_full_marks_for_every_type(tmp_path: Path) -> None:
    # Without a server, each question type's reader builds the answers file in the page.
    with chromium_page() as page:
        for qf in load_all(QUIZ_COURSE):
            quiz = qf.quiz
            html = tmp_path / f"{quiz.id}.en.html"
            html.write_text(render_page(quiz, "en", seed=5), encoding="utf-8")
            page.goto(html.as_uri())
            with page.expect_download() as blank:
                page.click("#save")
            assert json.loads(Path(blank.value.path()).read_text())["answers"] == {}
            for question in quiz.questions:
                _enter_key(page, question)
            with page.expect_download() as download:
                page.click("#save")
            saved = json.loads(Path(download.value.path()).read_text())
            assert (saved["quiz"], saved["seed"], saved["lang"]) == (quiz.id, "5", "en")
            assert (_comparable(quiz, saved["answers"])
                    == _comparable(quiz, key_answers(quiz)["answers"])), quiz.id
            result = score(quiz, check_answers("answers.json", quiz, saved))
            assert result.score == result.max_score, quiz.id


@pytest.mark.parametrize("lang", ["en", "ur"])
def test_the_saved_page_says_what_it_cannot_read_and_saves_nothing(tmp_path: Path,
                                                                   lang: str) -> None:
    """Without a server too: `five` in a number box, or two items in one place, is said at
    its question; Urdu digits read as a number, as the server reads them."""
    timers = load_quiz(QUIZ_COURSE / "quizzes" / "timer-synchronization.yaml").quiz
    errors = load_quiz(QUIZ_COURSE / "quizzes" / "error-handling.yaml").quiz
    said = {"en": ("is not a number", "Two items have the same place, 1"),
            "ur": ("کوئی عدد نہیں", "دو چیزوں کا مقام ایک ہی ہے")}[lang]
    with chromium_page() as page:
        for quiz, fill in ((timers, lambda: page.fill('input[name="q:calls-in-two-seconds"]',
                                                      "five")),
                           (errors, lambda: [page.select_option(
                               f'select[name="q:life-order:{item}"]', "1")
                               for item in ("init", "create")])):
            html = tmp_path / f"{quiz.id}.{lang}.html"
            html.write_text(render_page(quiz, lang, seed=5), encoding="utf-8")
            page.goto(html.as_uri())
            fill()
            downloads: list[Any] = []
            page.on("download", lambda d, into=downloads: into.append(d))
            page.click("#save")
            problem = page.locator("p.problem")
            problem.wait_for()
            assert said[quiz is errors] in problem.inner_text()
            assert downloads == []
        html = tmp_path / "timers.html"
        html.write_text(render_page(timers, lang, seed=5), encoding="utf-8")
        page.goto(html.as_uri())
        page.fill('input[name="q:calls-in-two-seconds"]', "۸")
        with page.expect_download() as download:
            page.click("#save")
        saved = json.loads(Path(download.value.path()).read_text())
        assert saved["answers"] == {"calls-in-two-seconds": 8}

