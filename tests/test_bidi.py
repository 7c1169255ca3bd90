"""Urdu that reads in order: Latin runs isolated as English in HTML and Markdown."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from autograder.i18n import set_language
from autograder.quiz.localize import LRI, PDI, Text, markdown_inline, plain, rich, sentence


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
    assert '<bdi lang="en" dir="ltr">±max_linear_speed</bdi> (' in html  # ± inside
    assert '(<bdi lang="en" dir="ltr">default 0.5</bdi>)' in html
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
    assert md == f"اگر {LRI}a{PDI} &lt; {LRI}b{PDI} ہو"  # the entity is not split


def test_sentence_isolates_latin_runs_and_english_values() -> None:
    template = "{world} میں روبوٹ کا راستہ (dashed line) ({count})"
    world = Text("Empty room, 6 x 6 m", "en", fallback=True)
    set_language("ur")
    html = sentence(template, world=world, count=3)
    assert html.startswith('<bdi><span lang="en" dir="ltr" class="fallback">Empty room, 6 x 6 m'
                           "</span></bdi> میں")
    assert '(<bdi lang="en" dir="ltr">dashed line</bdi>) (3)' in html
    assert sentence("<b> {x}", x="<i>") == '&lt;<bdi lang="en" dir="ltr">b</bdi>&gt; &lt;i&gt;'
    set_language("en")
    assert sentence("<b> {x}", x="<i>") == "&lt;b&gt; &lt;i&gt;"  # escaped, both parts
    assert sentence(template, world=world, count=3).startswith(
        '<bdi><span lang="en" dir="ltr" class="fallback">Empty room')
