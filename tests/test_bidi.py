"""Urdu that reads in order: Latin runs isolated as English in HTML and Markdown."""

from __future__ import annotations

from autograder.quiz.localize import LRI, PDI, Text, markdown_inline, plain, rich


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
