"""Shuffling, the HTML page and the Markdown export: Urdu is RTL, code LTR, no key leaks."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from quiz_course import QUIZ_COURSE

from autograder.cli.quiz import quiz_cli
from autograder.i18n import translations
from autograder.quiz.model import load_quiz
from autograder.quiz.render import render_markdown, render_page
from autograder.quiz.scoring import score
from autograder.quiz.shuffle import option_order

REPO = Path(__file__).resolve().parents[2]
PART2 = load_quiz(QUIZ_COURSE / "quizzes" / "part2-rclpy.yaml").quiz
ERRORS = load_quiz(QUIZ_COURSE / "quizzes" / "error-handling.yaml").quiz


def _ids(quiz: object, question_id: str, seed: object) -> list[str]:
    q = quiz.question(question_id)  # type: ignore[attr-defined]
    return [o.id for o in option_order(quiz, q, seed)]  # type: ignore[arg-type]


def test_same_seed_same_order_and_seeds_differ() -> None:
    assert _ids(PART2, "gil", 42) == _ids(PART2, "gil", 42)
    orders = {tuple(_ids(PART2, "gil", seed)) for seed in range(20)}
    assert len(orders) > 3
    assert _ids(PART2, "gil", None) == [o.id for o in PART2.question("gil").options]


def test_pinned_option_stays_last() -> None:
    for seed in range(30):
        assert _ids(PART2, "shared-resources", seed)[-1] == "none"


def test_ordering_items_are_never_shown_in_key_order() -> None:
    key = ERRORS.question("life-order").answer
    for seed in (None, *range(30)):
        assert _ids(ERRORS, "life-order", seed) != list(key)


def test_key_survives_shuffling() -> None:
    # The answer is an id: whatever the order shown, the same id scores.
    for seed in range(10):
        assert "cpython-lock" in _ids(PART2, "gil", seed)
        assert score(PART2, {"gil": "cpython-lock"}).tests[2].score == 1


@pytest.fixture
def urdu_page() -> str:
    return render_page(PART2, "ur", seed=7)


def test_urdu_page_is_rtl_with_lang_on_the_root(urdu_page: str) -> None:
    assert re.search(r'<html lang="ur" dir="rtl">', urdu_page)
    assert '"Noto Nastaliq Urdu"' in urdu_page
    assert "line-height: 2.6" in urdu_page
    assert "کامیابی کے لیے درکار اسکور: 70% (4/5 سوالات)" in urdu_page
    assert "rclpy میں" not in urdu_page  # Latin runs are isolated, not bare
    assert '<bdi lang="en" dir="ltr">rclpy</bdi> میں' in urdu_page


def test_code_stays_ltr_in_urdu(urdu_page: str) -> None:
    assert ('<code dir="ltr">self.declare_parameter(&#39;max_speed&#39;, 1.0)</code>'
            in urdu_page)
    assert '<code dir="ltr">&lt;parameter&gt;</code>' in urdu_page  # escaped, not a tag
    assert "pre { direction: ltr;" in urdu_page
    # The <title> cannot hold markup: Latin runs there sit in Unicode isolates.
    assert "<title>حصہ 2 کا کوئز: \u2066rclpy\u2069" in urdu_page


def test_page_never_contains_the_key(urdu_page: str) -> None:
    # Changing every key must not change the page at all.
    rekeyed = dataclasses.replace(PART2, questions=tuple(
        dataclasses.replace(q, answer=q.options[-1].id) for q in PART2.questions))
    assert render_page(rekeyed, "ur", seed=7) == urdu_page
    assert render_page(rekeyed, "en", seed=7) == render_page(PART2, "en", seed=7)
    english = render_page(PART2, "en", seed=7)
    for q in PART2.questions:  # explanations give answers away: feedback only
        assert q.explanation[:40] not in english


def test_english_page_is_ltr() -> None:
    page = render_page(PART2, "en")
    assert '<html lang="en" dir="ltr">' in page
    assert "Passing score: 70% (4/5 questions)" in page


@pytest.fixture
def missing_translation(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Catalogs where the Part 2 title has no Urdu translation."""
    import shutil

    shutil.copytree(QUIZ_COURSE / "locales", tmp_path / "locales")
    po = tmp_path / "locales" / "ur" / "LC_MESSAGES" / "content.po"
    text = po.read_text()
    text = re.sub(r'(msgctxt "quiz:rclpy-part2:title"\nmsgid "[^"]*"\nmsgstr )"[^"]*"',
                  r'\1""', text)
    po.write_text(text)
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(tmp_path / "locales"))
    translations.cache_clear()
    yield po
    translations.cache_clear()


def test_missing_translation_falls_back_marked_as_english(missing_translation: Path) -> None:
    page = render_page(PART2, "ur")
    assert ('<h1 id="title"><span lang="en" dir="ltr" class="fallback">'
            "Part 2 quiz: Python and ROS 2 with rclpy</span></h1>") in page
    md = render_markdown(PART2, "ur")
    assert '# <span lang="en" dir="ltr">Part 2 quiz: Python and ROS 2 with rclpy</span>' in md


def test_markdown_export_for_docusaurus() -> None:
    md = render_markdown(PART2, "ur", seed=1)
    assert md.startswith('---\ntitle: "حصہ 2 کا کوئز')
    assert '<div dir="rtl" lang="ur">' in md and md.rstrip().endswith("</div>")
    assert "\u2066`MutuallyExclusiveCallbackGroup`\u2069" in md
    assert "\u2066`<parameter>`\u2069" in md  # inside a code span: no MDX escaping needed
    en = render_markdown(ERRORS, "en")
    assert "dir=" not in en and "- [ ] `rclpy.spin(node)`" in en
    for q in ERRORS.questions:
        assert q.explanation[:40] not in en


def test_render_cli_writes_every_quiz_and_language(tmp_path: Path) -> None:
    result = CliRunner().invoke(quiz_cli, ["render", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    names = sorted(p.name for p in tmp_path.iterdir())
    assert len(names) == 5 * 2 * 2
    assert "rclpy-part2.ur.html" in names and "rclpy-part2.ur.mdx" in names
