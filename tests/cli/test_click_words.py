"""click's own words in the active language: a usage error of an Urdu run is Urdu ("Error:",
"Missing argument", "No such option"), an English one stays click's English, and every word
marked for the catalogs is one click really says."""

from __future__ import annotations

import inspect
from collections.abc import Iterator

import click
import click.core
import click.exceptions
import click.formatting
import click.parser
import click.types
import pytest
from click.testing import CliRunner

from autograder.cli import click_words, main
from autograder.i18n import set_language, translations

# click's modules that print its words.
CLICKS = (click.core, click.exceptions, click.formatting, click.parser, click.types)


@pytest.fixture(autouse=True)
def english_after() -> Iterator[None]:
    yield
    set_language("en")


def _usage_error(*args: str) -> str:
    result = CliRunner().invoke(main, list(args))
    assert result.exit_code == 2, result.output
    return result.output


def test_an_urdu_usage_error_is_urdu():
    output = _usage_error("--lang", "ur", "check", "parameter_validation")
    assert "خرابی: " in output and "Error:" not in output  # "Error: {message}"
    assert "یہ argument موجود نہیں:" in output  # "Missing argument"
    assert "استعمال:" in output  # "Usage:"
    output = _usage_error("--lang", "ur", "check", "--no-such-flag")
    assert "'--no-such-flag' نام کا کوئی option نہیں۔" in output


def test_an_english_usage_error_stays_clicks_english():
    output = _usage_error("--lang", "en", "check", "parameter_validation")
    assert "Error: Missing argument" in output and "Usage:" in output


def test_speak_is_idempotent_and_points_click_at_our_catalogs():
    click_words.speak()
    click_words.speak()
    from autograder.i18n import _ as ours

    for module in CLICKS:
        assert module._ is ours, module.__name__


def test_every_word_is_clicks_own_and_translated_into_urdu():
    source = "".join(inspect.getsource(module) for module in (*CLICKS, click.decorators))
    urdu = translations("ur")
    for word in click_words.WORDS:
        forms = word if isinstance(word, tuple) else (word,)
        for form in forms:
            assert repr(form)[1:-1] in source or form in source, form
        if isinstance(word, tuple):
            assert urdu.ngettext(*word, 1) != word[0] and urdu.ngettext(*word, 2) != word[1]
        else:
            assert urdu.gettext(word) != word, word
