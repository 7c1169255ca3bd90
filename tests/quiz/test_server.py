"""``autograder quiz serve`` over HTTP (no browser): pages, submit, errors, no key."""

from __future__ import annotations

import re
import urllib.error
import urllib.parse
import urllib.request
from pathlib import Path

import pytest

from autograder.quiz.server import QuizServer

REPO = Path(__file__).resolve().parents[2]


def _get(url: str) -> str:
    with urllib.request.urlopen(url, timeout=5) as resp:
        return resp.read().decode()


def _post(url: str, fields: list[tuple[str, str]]) -> tuple[int, str]:
    data = urllib.parse.urlencode(fields).encode()
    try:
        with urllib.request.urlopen(url, data=data, timeout=5) as resp:
            return resp.status, resp.read().decode()
    except urllib.error.HTTPError as exc:
        return exc.code, exc.read().decode()


def test_binds_loopback_on_a_free_port(server: QuizServer) -> None:
    host, port = server.server_address[:2]
    assert host == "127.0.0.1" and port > 0
    assert "rclpy-part2" in _get(server.url)


def test_urdu_page_and_submit(server: QuizServer) -> None:
    page = _get(server.url + "quiz/rclpy-part2/?lang=ur")
    assert '<html lang="ur" dir="rtl">' in page
    assert 'action="/quiz/rclpy-part2/submit"' in page
    assert "cpython-lock" in page  # option ids are there, which one is right is not
    fields = [("lang", "ur"), ("seed", "3"), ("q:callback-groups-purpose", "concurrency"),
              ("q:declare-parameters", "declare"), ("q:gil", "cpython-lock"),
              ("q:shared-resources", "mutually-exclusive"), ("q:python-advantage", "faster")]
    status, result = _post(server.url + "quiz/rclpy-part2/submit", fields)
    assert status == 200
    assert 'id="verdict"' in result and "کامیاب" in result and "ابھی کامیاب نہیں" not in result
    assert "5 میں سے 4 (80%)" in result
    assert "کامیابی کے لیے درکار اسکور: 70% (4/5 سوالات)" in result
    assert "download=\"answers.json\"" in result


def test_ordering_numeric_and_multiple_from_the_form(server: QuizServer) -> None:
    fields = [("lang", "en"), ("q:period-units", "seconds"), ("q:calls-in-two-seconds", "۸"),
              ("q:keep-in-step", "same-group"), ("q:keep-in-step", "lock")]
    status, page = _post(server.url + "quiz/timer-synchronization/submit", fields)
    assert status == 200 and page.count("Correct.") == 2  # Urdu digits parse as numbers
    assert "Partly correct: 0.67 of 1 point." in page
    order = [("q:life-order:init", "1"), ("q:life-order:create", "2"),
             ("q:life-order:spin", "3"), ("q:life-order:destroy", "4"),
             ("q:life-order:shutdown", "5")]
    status, page = _post(server.url + "quiz/error-handling/submit", order)
    assert status == 200 and page.count("Correct.") == 1


def test_bad_form_is_a_400_naming_the_problem(server: QuizServer) -> None:
    status, page = _post(server.url + "quiz/rclpy-part2/submit", [("q:gil", "gvl")])
    assert status == 400 and "question &#39;gil&#39; has no option &#39;gvl&#39;" in page
    with pytest.raises(urllib.error.HTTPError) as info:
        _get(server.url + "quiz/nope/")
    assert info.value.code == 404


URDU_ANSWER = 'آپ نے جواب دیا: <bdi><bdi dir="ltr">8</bdi> بار</bdi>'


@pytest.mark.parametrize(("lang", "said"), [("en", "Your answer: <bdi>8 calls</bdi>"),
                                            ("ur", URDU_ANSWER)])
def test_the_result_page_shows_the_students_own_answer(server: QuizServer, lang: str,
                                                       said: str) -> None:
    """As the terminal does: the options chosen, the number given; nothing for a question
    left unanswered (issue 31)."""
    fields = [("lang", lang), ("q:calls-in-two-seconds", "۸"),
              ("q:keep-in-step", "same-group"), ("q:keep-in-step", "lock")]
    status, page = _post(server.url + "quiz/timer-synchronization/submit", fields)
    assert status == 200

    def section(question: str) -> str:
        return page.split(f'id="feedback-{question}"')[1].split("</section>")[0]

    assert f'<p class="answer">{said}</p>' in section("calls-in-two-seconds")
    assert section("keep-in-step").count("<code") == 2  # both options, their code as code
    assert 'class="answer"' not in section("period-units")


@pytest.mark.parametrize("path", ["quiz/rclpy-part2?lang=en", "quiz/rclpy-part2/?lang=en",
                                  "quiz/rclpy-part2"])
def test_the_form_posts_to_its_quiz_from_any_url_form(server: QuizServer, path: str) -> None:
    """A browser resolves the form's action against the page's own URL: with or without
    the trailing slash, it is the quiz's submit."""
    url = server.url + path
    action = re.search(r'<form id="quiz" method="post" action="([^"]+)"', _get(url))
    assert action
    status, page = _post(urllib.parse.urljoin(url, action.group(1)),
                         [("lang", "en"), ("q:gil", "cpython-lock")])
    assert status == 200 and 'id="verdict"' in page


UNREADABLE = {"en": ("“five” is not a number", "Two items have the same place, 1",
                     "Some answers could not be read"),
              "ur": ("کوئی عدد نہیں", "دو چیزوں کا مقام ایک ہی ہے",
                     "کچھ جوابات پڑھے نہیں جا سکے")}


@pytest.mark.parametrize("lang", ["en", "ur"])
def test_unreadable_answers_come_back_with_a_message_and_the_rest_kept(
        server: QuizServer, lang: str) -> None:
    number, places, summary = UNREADABLE[lang]
    fields = [("lang", lang), ("seed", "3"), ("q:calls-in-two-seconds", "five"),
              ("q:period-units", "seconds")]
    status, page = _post(server.url + "quiz/timer-synchronization/submit", fields)
    assert status == 400 and summary in page and 'id="verdict"' not in page
    problem = page.split('id="q-calls-in-two-seconds-problem"')[1].split("</p>")[0]
    assert number in problem and "five" in problem
    assert 'value="five"' in page  # what was typed is there to correct
    assert re.search(r'name="q:period-units" value="seconds" checked', page)
    order = [("lang", lang), ("q:life-order:init", "1"), ("q:life-order:create", "1"),
             ("q:life-order:spin", "3")]
    status, page = _post(server.url + "quiz/error-handling/submit", order)
    assert status == 400
    assert places in page.split('id="q-life-order-problem"')[1].split("</p>")[0]
    assert re.search(r'name="q:life-order:spin".*?<option value="3" selected>', page)
