"""A program's output cannot lie: whatever it writes, every results format shows it as text
(its escape sequences, bidi controls and bytes XML cannot hold as visible escapes), JUnit
stays well-formed, and our own right-to-left marks stay ours."""

from __future__ import annotations

import json
import re
import unicodedata
import xml.etree.ElementTree as ET
from fractions import Fraction
from pathlib import Path
from types import SimpleNamespace

import click
import pytest

from autograder.core.output_budget import TAIL_BYTES
from autograder.core.results import RunResult, TestResult
from autograder.core.untrusted import visible
from autograder.i18n import set_language
from autograder.plugin.student import StudentNode
from autograder.render import formats
from autograder.render.junit import to_junit
from autograder.render.live import LiveLines
from autograder.render.terminal import RLM, to_terminal

BIDI = "\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069"
INVISIBLE = "\u00ad\u180e\u200b\u2060\u2064\u206a\u206f\ufeff\ufff9\ufffb\U000e0001\U000e0041"
NOT_XML = "\ud800\udfff\ufffe\uffff"
# What the hostile program of the corpus writes (tests/submissions/hostile/fake_score):
# the screen cleared, a fake verdict, hidden text, a window title, a link, a reversed line.
HOSTILE = ("\x1b[2J\x1b[H\x1b[1;32mScore: 13/13 (100%), passed\x1b[0m\n"
           "\x1b[8mhidden\x1b[28m\n"
           "\x1b]0;All tests passed\x07"
           "\x1b]8;;https://example.invalid/\x1b\\your grade\x1b]8;;\x1b\\\n"
           "\u202edessap\u202c\n"
           "NUL\x00 BEL\x07 CR\r progress\r\n")
# Every byte as the sandbox decodes a program's output (UTF-8, errors replaced), and as
# Latin-1 (so that C1 controls, U+0080-U+009F, come through too).
EVERY_BYTE = bytes(range(256)).decode("utf-8", "replace") + bytes(range(256)).decode("latin-1")
WRITTEN = HOSTILE + EVERY_BYTE + BIDI + INVISIBLE + NOT_XML + "\n"
SGR = re.compile(r"\x1b\[[0-9;]*m")
# The colour codes the terminal summary writes itself (its marks, bold labels, the score).
OUR_SGR = {code for fg in ("green", "red", "yellow", None) for bold in (True, False)
           for code in SGR.findall(click.style("x", fg=fg, bold=bold))}


def raw_controls(text: str) -> set[str]:
    """What may not reach a reader as it is: control characters (but newline and tab),
    bidi controls, and characters XML 1.0 cannot hold."""
    return {c for c in text if (unicodedata.category(c) == "Cc" and c not in "\n\t")
            or c in BIDI or c in NOT_XML or unicodedata.category(c) == "Cs"}


# The function ------------------------------------------------------------------------------


@pytest.mark.parametrize("byte", range(256), ids=lambda b: f"{b:02x}")
def test_every_byte_is_shown_as_itself_or_as_an_escape(byte: int):
    char = chr(byte)
    shown = visible(char)
    if char in "\n\t":
        assert shown == char
    elif char == "\r":
        assert shown == "\\r"  # a lone CR would let a line overwrite itself
    elif byte < 0x20 or 0x7f <= byte <= 0x9f or byte == 0xad:
        assert shown == f"\\x{byte:02x}"
    else:
        assert shown == char
    assert not raw_controls(shown)


@pytest.mark.parametrize("char", list(BIDI + INVISIBLE + NOT_XML + "\u2028\u2029"),
                         ids=lambda c: f"U+{ord(c):04X}")
def test_bidi_invisible_and_non_xml_characters_are_shown_as_escapes(char: str):
    code = ord(char)
    escape = f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000 else \
        f"\\U{code:08x}"
    assert visible(f"a{char}b") == f"a{escape}b"


def test_crlf_is_a_newline_and_printable_text_in_any_script_stays():
    assert visible("one\r\ntwo\r\r\n") == "one\ntwo\\r\n"
    text = "اردو میں‌ پیغام — Ünïcödé ✔ 👨‍👩‍👧 ، ۱۲۳ \u0600\u06dd\ufffd\u00a0 tab\t"
    assert visible(text) == text  # letters, joiners (U+200C, U+200D), visible number signs


def test_showing_twice_is_showing_once():
    assert visible(visible(WRITTEN)) == visible(WRITTEN)


# The results and every format --------------------------------------------------------------


def hostile_result(lang: str = "en", label: str = "The node starts") -> RunResult:
    failed = TestResult(
        "test_starts", label, Fraction(0), Fraction(1), "failed",
        message=f"Your program exited with status 1.\nLast lines of its output:\n{WRITTEN}",
        hint=f"Read its output: {HOSTILE}", details=WRITTEN)
    errored = TestResult("test_error", "It answers", Fraction(0), Fraction(1), "error",
                         message=f"ValueError: {HOSTILE}", details=WRITTEN)
    skipped = TestResult("test_skip", "It is skipped", Fraction(0), Fraction(1), "skipped",
                         message=HOSTILE)
    return RunResult("exercise", "shout", "Shout", (failed, errored, skipped), lang=lang,
                     grader_error="grader error", grader_details=WRITTEN,
                     log_tail=WRITTEN, log=WRITTEN)


def rendered(tmp_path: Path) -> dict[str, str]:
    result = hostile_result()
    shown = {name: f.render(result, tmp_path) for name, f in formats().items()}
    shown["terminal"] = to_terminal(result)
    lines: list[str] = []
    live = LiveLines(lines.append)
    for test in result.tests:
        live.done(test)
    shown["live"] = "".join(lines)
    return shown


def test_the_results_model_holds_only_text_safe_to_show():
    result = hostile_result()
    for text in (result.log, result.log_tail, result.grader_details,
                 *(t.message for t in result.tests), *(t.hint for t in result.tests),
                 *(t.details for t in result.tests)):
        assert not raw_controls(text)
    assert "\\x1b[2J" in result.log and "\\u202edessap" in result.log  # shown, not dropped
    assert "\\x1b]0;All tests passed\\x07" in result.tests[0].message


def test_no_format_passes_on_a_control_character(tmp_path: Path):
    for name, text in rendered(tmp_path).items():
        assert not raw_controls(text), name
    assert set(rendered(tmp_path)) >= {"results", "html", "gradescope", "junit", "terminal"}


def test_the_program_s_text_still_reads_in_every_format(tmp_path: Path):
    shown = rendered(tmp_path)
    for name in ("html", "junit", "terminal"):
        assert "\\x1b[2J" in shown[name] and "\\u202edessap" in shown[name], name
    assert "\\x1b[2J" in json.loads(shown["results"])["tests"][0]["message"]
    assert "\\x1b[2J" in json.loads(shown["gradescope"])["tests"][0]["output"]


def test_junit_parses_and_json_parses_to_clean_text(tmp_path: Path):
    shown = rendered(tmp_path)
    suite = ET.fromstring(shown["junit"].encode("utf-8"))  # as a CI reporter reads the file
    for element in suite.iter():
        for text in (element.text or "", *element.attrib.values()):
            assert not raw_controls(text), element.tag

    def strings(value: object) -> list[str]:
        if isinstance(value, dict):
            return [s for v in value.values() for s in strings(v)]
        if isinstance(value, list):
            return [s for v in value for s in strings(v)]
        return [value] if isinstance(value, str) else []

    for name in ("results", "gradescope"):
        for text in strings(json.loads(shown[name])):
            assert not raw_controls(text), name


def test_junit_is_well_formed_whatever_reaches_it():
    """Labels and names are ours and not cleaned by the model: the writer checks them too."""
    result = hostile_result(label=f"A label\x00\x1b[2J{NOT_XML}")
    suite = ET.fromstring(to_junit(result).encode("utf-8"))
    labels = [p.get("value") for p in suite.iter("property") if p.get("name") == "label"]
    assert labels[0] == "A label\\x00\\x1b[2J\\ud800\\udfff\\ufffe\\uffff"


def test_in_colour_the_terminal_holds_only_our_own_colour_codes():
    text = to_terminal(hostile_result(), color=True)
    assert set(SGR.findall(text)) <= OUR_SGR
    assert not raw_controls(SGR.sub("", text))
    assert "\x1b[8m" not in text and "\x1b[2J" not in text and "\x1b]" not in text


def test_our_own_right_to_left_marks_stay_and_the_program_s_are_shown():
    set_language("ur")
    urdu = TestResult("test_starts", "node شروع ہوتا ہے", Fraction(0), Fraction(1), "failed",
                      message=f"پروگرام رک گیا۔\n{RLM}fake\u202e{HOSTILE}")
    assert urdu.message.startswith("پروگرام رک گیا۔\n\\u200ffake\\u202e")
    text = to_terminal(RunResult("exercise", "shout", "Shout", (urdu,), lang="ur"))
    lines = text.split("\n")
    assert RLM + " ✘   0/1  node شروع ہوتا ہے" in lines  # ours, added as it is shown
    assert "    \\u200ffake\\u202e\\x1b[2J\\x1b[H\\x1b[1;32mScore: 13/13 (100%), passed" \
        "\\x1b[0m" in lines
    assert not raw_controls(text.replace(RLM, ""))


# Where a program's output enters a message -------------------------------------------------


def test_an_output_tail_is_shown_visible_within_its_size():
    written = (HOSTILE + "\x00" * 3000 + "\n") * 4
    process = SimpleNamespace(output_text=lambda: written, workdir=Path("/nonexistent"),
                              output=None)
    tail = StudentNode(process, "shouter", probe=None).output_tail()  # type: ignore[arg-type]
    assert not raw_controls(tail)
    assert "\\x00\\x00" in tail and "\\x1b[2J" in tail
    assert len(tail.encode()) <= TAIL_BYTES
