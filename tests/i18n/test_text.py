"""Urdu that reads in order: Latin runs isolated as English in HTML and Markdown, marks
for terminals, and the simulator's English (collisions, world titles) translated."""

from __future__ import annotations

import dataclasses
import math
import unicodedata
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path

import pytest
from click.testing import CliRunner

from autograder.cli import main
from autograder.cli.quiz import quiz_cli
from autograder.core.results import RunResult, TestResult
from autograder.i18n import get_language, set_language, translations
from autograder.i18n.text import LRI, PDI, Text, markdown_inline, plain, rich, sentence
from autograder.render.html import to_html
from autograder.render.terminal import RLM, for_terminal, rtl_notice, to_terminal
from sim.physics import Contact, describe
from sim.recorder import Recording, Sample
from sim.svg import trajectory_svg
from sim.worldfile import extract_world, load_world, title_of

REPO = Path(__file__).resolve().parents[2]
NOTICE = "Most terminals cannot lay out right-to-left text."


@pytest.fixture(autouse=True)
def english() -> Iterator[None]:
    set_language("en")
    yield
    set_language("en")


def ur(text: str) -> Text:
    return Text(text, "ur")


# HTML and Markdown ---------------------------------------------------------------------------


def test_every_latin_run_is_an_english_isolate_with_its_sign() -> None:
    html = rich(ur("linear.x کو ±max_linear_speed (default 0.5) تک محدود کیا جاتا ہے"))
    assert '<bdi lang="en" dir="ltr">linear.x</bdi> کو ' in html
    # ± inside; the English parenthesis beside the name is read with it, in its order
    assert '<bdi lang="en" dir="ltr">±max_linear_speed (default 0.5)</bdi> تک' in html
    html = rich(ur("NaN، ±inf اور ±30° کے اندر 0.6 m یا ±0.5 rad/s"))
    for run in ("NaN", "±inf", "±30°", "0.6 m", "±0.5 rad/s"):
        assert f'<bdi lang="en" dir="ltr">{run}</bdi>' in html, run
    assert "<bdi" not in rich(ur("ایک 2 سیکنڈ اور 4/5 سوالات"))  # bare numbers stay Urdu


def test_a_number_that_begins_the_text_is_isolated() -> None:
    assert str(rich(ur("50 Hz اور 10 Hz"))).startswith('<bdi lang="en" dir="ltr">50 Hz</bdi>')
    assert str(rich(ur("2 سیکنڈ میں 2 بار"))) == '<bdi dir="ltr">2</bdi> سیکنڈ میں 2 بار'
    assert str(rich(Text("2 seconds", "en"))) == "2 seconds"  # left to right: nothing to do


def test_plain_and_markdown_isolate_the_same_runs() -> None:
    assert plain(ur("حد ±0.5 rad/s ہے")) == f"حد {LRI}±0.5 rad/s{PDI} ہے"
    md = markdown_inline(ur("اگر a < b ہو"))
    assert md == f"اگر {LRI}a &lt; b{PDI} ہو"  # one expression; the entity is not split


def test_sentence_isolates_latin_runs_and_english_values() -> None:
    template = "{world} میں روبوٹ کا راستہ (dashed line) ({count})"
    world = Text("Empty room, 6 x 6 m", "en", fallback=True)
    set_language("ur")
    html = sentence(template, world=world, count=3)
    assert html.startswith('<bdi><span lang="en" dir="ltr" class="fallback">Empty room, 6 x 6 m'
                           "</span></bdi> میں")
    assert '(<bdi lang="en" dir="ltr">dashed line</bdi>) (3)' in html
    assert sentence("<b> {x}", x="<i>") == '<bdi lang="en" dir="ltr">&lt;b&gt;</bdi> &lt;i&gt;'
    set_language("en")
    assert sentence("<b> {x}", x="<i>") == "&lt;b&gt; &lt;i&gt;"  # escaped, both parts
    assert sentence(template, world=world, count=3).startswith(
        '<bdi><span lang="en" dir="ltr" class="fallback">Empty room')


# Terminals ---------------------------------------------------------------------------------


def test_for_terminal_marks_urdu_lines_that_start_left_to_right() -> None:
    text = (" ✔     1/1  node شروع ہوتا ہے\nاسکور: 1/3\n[INFO] started\n"
            "\x1b[1mtimer_sync — ایک\x1b[0m")
    lines = for_terminal(text, "ur").split("\n")
    assert lines[0] == RLM + " ✔     1/1  node شروع ہوتا ہے"  # a mark, then a Latin word
    assert lines[1] == "اسکور: 1/3"  # starts right to left already
    assert lines[2] == "[INFO] started"  # no Urdu in it: the program's own output
    assert lines[3].startswith(RLM + "\x1b[1m")  # colour codes are not text
    assert for_terminal(text, "en") == text
    assert for_terminal(for_terminal(text, "ur"), "ur") == for_terminal(text, "ur")


def test_rtl_notice_says_where_the_text_reads_laid_out() -> None:
    assert rtl_notice("en") is None
    assert "--html report.html" in rtl_notice("ur")
    assert "out/report.html" in rtl_notice("ur", html=Path("out/report.html"))
    assert "autograder quiz serve" in rtl_notice("ur", serve=True)


def _urdu_run() -> RunResult:
    tests = (TestResult("test_starts", "node شروع ہوتا ہے", Fraction(1), Fraction(1), "passed"),
             TestResult("test_rate", "cmd_vel دس Hz پر رہتا ہے", Fraction(0), Fraction(2),
                        "failed", message="Traceback (most recent call last):"))
    return RunResult("exercise", "parameter_validation", "Parameter validation: ایک governor",
                     tests, lang="ur")


def test_urdu_summary_lines_start_right_to_left() -> None:
    lines = to_terminal(_urdu_run()).split("\n")
    assert lines[0] == RLM + "parameter_validation — Parameter validation: ایک governor"
    assert lines[2].startswith(RLM + " ✔") and lines[3].startswith(RLM + " ✘")
    # The failure's block: its label, then the program's output as it is, left to right.
    assert lines[5] == RLM + "✘ cmd_vel دس Hz پر رہتا ہے"
    assert lines[6] == "    Traceback (most recent call last):"


def test_check_in_urdu_marks_lines_and_points_to_the_report(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from autograder.core.report import RawTest

    def fake_grade(exercise, submission, *, progress=None, **_kw):
        progress(RawTest("t.py::test_starts", "test_starts", "node شروع ہوتا ہے", 1,
                         "visible", "all", True, "passed"))
        run = _urdu_run()
        started = dataclasses.replace(run.tests[0], nodeid="t.py::test_starts")
        return dataclasses.replace(run, lang=get_language(), tests=(started, *run.tests[1:]))

    monkeypatch.setattr("autograder.grading.run.grade", fake_grade)
    starter = REPO / "assignments" / "parameter_validation" / "starter" / "velocity_governor.py"
    report = tmp_path / "report.html"
    result = CliRunner().invoke(main, ["check", "parameter_validation", str(starter),
                                       "--lang", "ur", "--html", str(report)])
    assert result.exit_code == 0, result.output
    assert result.stderr.split("\n")[0].count(str(report)) == 1  # the notice, first
    assert result.stdout.startswith(RLM + "parameter_validation — ")
    assert result.stdout.count(RLM + " ✔") == 1  # the test's line, printed as it ended
    assert report.read_text().startswith("<!doctype html>")
    english = CliRunner().invoke(main, ["check", "parameter_validation", str(starter),
                                        "--lang", "en"])
    assert RLM not in english.output and NOTICE not in english.output


def _first_strong(line: str) -> str | None:
    return next((kind for kind in map(unicodedata.bidirectional, line)
                 if kind in ("L", "R", "AL")), None)


def test_quiz_score_in_urdu_marks_lines_and_writes_the_page(tmp_path: Path) -> None:
    answers = tmp_path / "answers.json"
    answers.write_text('{"quiz": "rclpy-part2", "answers": {"gil": "cpython-lock"}}')
    page = tmp_path / "result.html"
    result = CliRunner().invoke(quiz_cli, ["score", "rclpy-part2", str(answers), "--lang", "ur",
                                           "--html", str(page)])
    assert result.exit_code == 0, result.output
    assert str(page) in result.stderr.split("\n")[0]
    urdu = [line for line in result.stdout.split("\n")
            if any(unicodedata.bidirectional(c) == "AL" for c in line)]
    assert len(urdu) > 10
    for line in urdu:  # each reads right to left in a terminal that lays out bidi text
        assert _first_strong(line) != "L", line
    assert sum(line.startswith(RLM) for line in urdu) >= 2  # "1. rclpy ...", "   node ..."
    assert '<html lang="ur" dir="rtl">' in page.read_text()
    assert "Take the quiz again" not in page.read_text()  # no server to take it on
    as_json = CliRunner().invoke(quiz_cli, ["score", "rclpy-part2", str(answers), "--lang",
                                            "ur", "--json"])
    assert RLM not in as_json.output and as_json.output.startswith("{")


# The simulator's English, translated ------------------------------------------------------

@pytest.fixture
def urdu_catalog(monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """The course's own Urdu catalog, read afresh."""
    monkeypatch.delenv("AUTOGRADER_LOCALES", raising=False)
    translations.cache_clear()
    yield REPO / "locales"
    set_language("en")
    translations.cache_clear()


def test_world_titles_are_extracted_for_the_catalog() -> None:
    def titles(path: Path) -> list:
        with path.open("rb") as fh:
            return list(extract_world(fh, {}, (), {}))

    found = titles(REPO / "sim" / "worlds" / "empty_room.yaml")
    assert found == [(2, "pgettext", ("world", "Empty room, 6 x 6 m"), ["world title"])]
    assert titles(REPO / "assignments" / "timer_sync" / "long_hall.yaml")[0][2] == (
        "world", "Long hall")
    assert titles(REPO / "assignments" / "timer_sync" / "exercise.yaml") == []


def test_collisions_and_world_titles_come_out_translated(urdu_catalog: Path) -> None:
    spec = load_world("obstacles")
    assert (title_of(spec), describe("wall 3")) == ("Room with obstacles", "wall 3")
    set_language("ur")
    assert title_of(spec) == "چند رکاوٹوں والا کمرہ"
    assert describe("wall 3") == "دیوار 3"
    assert describe("added box 7") == "بعد میں رکھا گیا ڈبہ 7"
    assert Contact(1.0, 2.0, 3.0, "box 1").description == "ڈبہ 1"
    assert describe("?") == "?"
    svg = trajectory_svg(spec, Recording(world="obstacles", samples=[
        Sample(1.0, 3.0, 3.0, 0.0, 0.2, 0.0)], collisions=[Contact(1.0, 4.2, 3.0, "box 0")]))
    assert "<title>چند رکاوٹوں والا کمرہ</title>" in svg and "1.00 سیکنڈ پر: ڈبہ 0" in svg


def test_urdu_report_has_no_english_collisions_or_world_names(urdu_catalog: Path) -> None:
    samples = [Sample(t=i * 0.1, x=3 + 0.05 * i, y=3 + math.sin(i / 10) / 5, theta=0.0, v=0.5,
                      w=0.0) for i in range(30)]
    hits = [Contact(1.2, 4.2, 3.0, "box 0"), Contact(2.0, 4.4, 3.1, "box 1"),
            Contact(2.9, 5.9, 3.0, "wall 3"), Contact(3.0, 1.2, 2.6, "circle 2")]
    run = _urdu_run()
    recordings = {
        "test_a.py": Recording("obstacles", samples, hits),
        "test_b.py": Recording("empty_room", samples, []),
    }
    page = to_html(RunResult(run.kind, run.id, run.title, run.tests, lang="ur",
                             recordings=recordings))
    for english in ("wall 3", "box 0", "box 1", "circle 2", "Room with obstacles",
                    "Empty room"):
        assert english not in page, english
    assert page.count('<path class="collision"') == 4
    for urdu in ("دیوار 3", "ڈبہ 1", "دائرہ 2", "<title>خالی کمرہ، 6 x 6 m</title>",
                 "<bdi>چند رکاوٹوں والا کمرہ</bdi>: روبوٹ کا راستہ"):
        assert urdu in page, urdu


def test_a_programs_output_in_a_message_stays_left_to_right_line_by_line() -> None:
    """An Urdu message that ends with the program's output: the sentence is right to left,
    the traceback is kept line by line in a left-to-right block (folded into the sentence
    it read backwards)."""
    from autograder.i18n.text import with_output

    message = ("نوڈ کا پروسیس ختم ہو گیا۔ اس کی آخری سطریں:\n"
               'Traceback (most recent call last):\n  File "avoider.py", line 55\n'
               "ValueError: min() arg is an empty sequence")
    html = str(with_output(ur(message)))
    head, _sep, block = html.partition('<pre class="output" dir="ltr" lang="en">')
    assert "اس کی آخری سطریں:" in head and "Traceback" not in head
    assert block.startswith("Traceback (most recent call last):\n  File &#34;avoider.py&#34;, "
                            "line 55\nValueError") and block.endswith("</pre>")
    assert "<pre" not in str(with_output(ur("ایک جملہ: بس یہی")))  # nothing follows the colon


def test_a_chain_of_calls_is_one_latin_run() -> None:
    html = str(rich(ur("یاد رکھیں کہ آخری scan کب آیا (self.get_clock().now()) میں")))
    assert '<bdi lang="en" dir="ltr">self.get_clock().now()</bdi>' in html


def test_code_is_one_isolate_in_the_terminal_too() -> None:
    line = for_terminal("جو reading شرط `range_min <= r <= range_max` پوری نہ کرے؛ cmd_vel پر "
                        "linear.x=0.2, angular.z=0 آیا", "ur")
    assert f"{LRI}`range_min <= r <= range_max`{PDI}" in line
    assert f"{LRI}linear.x=0.2, angular.z=0{PDI}" in line
    assert for_terminal("[INFO] a, b", "ur") == "[INFO] a, b"  # a program's own line


def test_an_expression_is_one_run_in_html() -> None:
    html = str(rich(ur("جو شرط range_min <= r <= range_max پوری نہ کرے، (goal_x, goal_y) "
                       "سے دور اور [-pi, pi] میں")))
    assert '<bdi lang="en" dir="ltr">range_min &lt;= r &lt;= range_max</bdi>' in html
    assert '(<bdi lang="en" dir="ltr">goal_x, goal_y</bdi>)' in html  # the pair mirrors
    assert '[<bdi lang="en" dir="ltr">-pi, pi</bdi>]' in html
