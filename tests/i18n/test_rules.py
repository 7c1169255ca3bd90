"""The language rules of ``i18n check`` (issue 32): each class of defect a reader of the
Urdu caught, planted in a small catalog or README and caught at its line, and the real
glossary holding each term the catalogs once rendered two ways."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from autograder.i18n import rules
from autograder.i18n.glossary import Glossary, check_language, load_glossary

REPO = Path(__file__).resolve().parents[2]
HEADER = """\
msgid ""
msgstr ""
"Project-Id-Version: course 1.0\\n"
"PO-Revision-Date: 2026-11-24 23:00+0000\\n"
"Last-Translator: the maintainers\\n"
"Language: ur\\n"
"Language-Team: Urdu, the maintainers\\n"
"Plural-Forms: nplurals=2; plural=(n != 1);\\n"
"Content-Type: text/plain; charset=utf-8\\n"

"""


@pytest.fixture(scope="module")
def real() -> Glossary:
    return load_glossary(REPO / "locales" / "ur" / "glossary.yaml")


def _course(tmp_path: Path, entries: str = "", readme: str | None = None) -> Path:
    """A course with the real glossary, one catalog and, if given, one README."""
    folder = tmp_path / "locales" / "ur" / "LC_MESSAGES"
    folder.mkdir(parents=True)
    glossary = (REPO / "locales" / "ur" / "glossary.yaml").read_text(encoding="utf-8")
    (tmp_path / "locales" / "ur" / "glossary.yaml").write_text(glossary, encoding="utf-8")
    (folder / "messages.po").write_text(HEADER + entries, encoding="utf-8")
    if readme is not None:
        (tmp_path / "assignments" / "demo").mkdir(parents=True)
        (tmp_path / "assignments" / "demo" / "README.ur.md").write_text(
            '<div dir="rtl" lang="ur">\n\n' + readme + "\n</div>\n", encoding="utf-8")
    return tmp_path


def _found(course: Path) -> list[str]:
    return [str(p).split("/")[-1] for p in check_language(course / "locales", "ur", course)]


def _said(real: Glossary, urdu: str, english: str | None = None) -> list[str]:
    return [p.message for p in real.problems(urdu, (Path("x.po"), 1), english)]


# 1. Code outside a code span ----------------------------------------------------------
@pytest.mark.parametrize(("text", "code"), [
    ("Skip a reading unless range_min <= r <= range_max.", "range_min <= r"),
    ("check len(ranges) first", "len(ranges)"),
    ("within 0.3 m of (goal_x, goal_y)", "(goal_x, goal_y)"),
    ("outside [{low}, {high}] m", "[{low}, {high}]"),
    ("cmd_vel said angular.z=0", "angular.z=0"),
    ("Create it with self.create_service(Trigger, 'check_path', callback).",
     "self.create_service(Trigger, 'check_path', callback)"),
])
def test_code_outside_a_span_is_caught_in_english_and_urdu(text: str, code: str) -> None:
    assert [found for found, _m in rules.code_outside_spans(text, translated=False)] == [code]
    marked = text.replace(code, f"`{code}`")
    assert not list(rules.code_outside_spans(marked, translated=False))
    # Urdu joins Latin words with its own comma; a Latin one between them is code.
    assert list(rules.code_outside_spans("cmd_vel پر linear.x 0.2, angular.z 0 آیا", True))
    assert not list(rules.code_outside_spans("NaN، inf اور (rosbag2, MCAP) یا 10 Hz", False))


def test_a_catalog_entry_with_code_outside_a_span_fails_at_its_line(tmp_path: Path) -> None:
    course = _course(tmp_path, (
        'msgid "Skip a reading unless `range_min <= r <= range_max`."\n'
        'msgstr "جو reading شرط range_min <= r <= range_max پوری نہ کرے اسے چھوڑ دیں۔"\n\n'
        'msgid "Check len(ranges)."\n'
        'msgstr "`len(ranges)` جانچیں۔"\n'))
    found = _found(course)
    assert any(f.startswith("messages.po:12: ur: code outside a code span: write "
                            "'range_min <= r'") for f in found), found
    assert any(f.startswith("messages.po:14: the English: code outside a code span: write "
                            "'len(ranges)'") for f in found), found


# 3. Grammar the glossary holds --------------------------------------------------------
@pytest.mark.parametrize("urdu", [
    # rclpy is feminine, however many words stand between it and its verb
    "rclpy کسی اور قسم کی قدر خود ہی رد کر دیتا ہے، سوائے اس کے کہ parameter ہر قسم لے",
    # a service, and a service named by its name, is feminine
    "جب سامنے ڈبہ ہو تو check_path فاصلے کے ساتھ success=false جواب دیتا ہے",
    "{where}، check_path جواب نہیں دے سکا۔",
    # a genitive agrees with the gendered noun after it
    "/scan کا beam 0 سیدھا آگے ہے",
    "نوڈ کا clock چلتی ہے",
])
def test_gender_agreement_within_the_clause(real: Glossary, urdu: str) -> None:
    assert any("in the glossary, and" in m for m in _said(real, urdu)), urdu


@pytest.mark.parametrize("urdu", [
    "rclpy کسی اور قسم کی قدر خود ہی رد کر دیتی ہے",
    "check_path فاصلے کے ساتھ success=false جواب دیتی ہے",
    "اس بات کی حد کہ ایک Python پروسیس کتنے نوڈز بنا سکتا ہے",  # Python qualifies پروسیس
    "`use_sim_time` (باب کا clock والا حصہ)",  # کا agrees with حصہ
    "جانچ شروع ہونے کے 3 سیکنڈ بعد نوڈ نے publish کرنا بند کر دیا",
])
def test_agreement_leaves_right_sentences_alone(real: Glossary, urdu: str) -> None:
    assert not any("in the glossary, and" in m for m in _said(real, urdu)), _said(real, urdu)


@pytest.mark.parametrize(("urdu", "oblique"), [
    ("روبوٹ سیدھا آگے ڈبہ 2 سے جا ٹکرایا", "ڈبے 2 سے"),
    ("دائرہ {number} سے ٹکراؤ", "دائرے 0 سے"),
    ("کمرہ میں", "کمرے میں"),
    ("پروسیسز کی حد v1 کا pids cgroup نے لگائی", "کے pids cgroup نے"),
])
def test_the_oblique_case_before_a_postposition(real: Glossary, urdu: str,
                                                oblique: str) -> None:
    assert any("oblique case" in m and oblique in m for m in _said(real, urdu)), _said(real, urdu)
    assert not any("oblique" in m for m in _said(real, "ڈبے 2 سے ٹکرایا؛ ایک ڈبہ نمودار ہوا"))


# 4. Terms once rendered two ways, and the book's own words ----------------------------
@pytest.mark.parametrize(("urdu", "term"), [
    ("`sys.exit(main())` کو call کریں", "call"),
    ("declare_parameter اسے لوٹاتا ہے", "return"),
    ("±30 درجے کے اندر", "degree"),
    ("غلط readings راستہ بند نہیں کرتیں", "invalid"),
    ("زیادہ تر ٹرمینل دائیں سے بائیں نہیں دکھاتے", "terminal"),
    ("حد میموری نے مقرر کی", "memory"),
    ("parameters کی توثیق", "validation"),
    ("| test | نمبر | نمائش |", "visibility"),
])
def test_each_term_has_one_rendering(real: Glossary, urdu: str, term: str) -> None:
    assert any(re.search(f"glossary's ['\"]{term}", m) for m in _said(real, urdu)), urdu


def test_invalid_is_required_where_the_english_says_it(real: Glossary) -> None:
    said = _said(real, "صرف غلطی والی readings چھوڑ دیں۔", "Ignore only the invalid readings.")
    assert any("the English says 'invalid" in m for m in said), said


@pytest.mark.parametrize("urdu", [
    "جب پیغامات آتے ہیں تو callback کو کال کرتا ہے",  # the book's own sentence
    "# پیغام پروسیس کریں",
    "حقیقی سینسر کے رویے کو simulate کریں",
    "آپ کا جواب غلط ہے۔",
    "غلط قسم کی قدر رد کی جاتی ہے",  # wrong, not invalid
])
def test_the_book_s_words_pass(real: Glossary, urdu: str) -> None:
    assert not _said(real, urdu), _said(real, urdu)


def test_every_gendered_term_of_the_issue_has_its_gender(real: Glossary) -> None:
    genders = {t.en.split(" (")[0]: t.gender for t in real.terms}
    assert genders["rclpy"] == "f" and genders["service"] == "f"
    assert genders["beam"] == "f" and genders["field"] == "f"
    assert "check_path" in next(t for t in real.terms if t.en == "service").names


@pytest.mark.parametrize("urdu", [
    "جب سامنے 0.40 m پر ایک ڈبہ ہو، تو راستہ صاف نہیں تھا۔",
    "جب scan پرانا ہو تو جواب غلط تھا",
])
def test_a_present_when_clause_with_a_past_main_verb_is_caught(real: Glossary,
                                                                urdu: str) -> None:
    assert any("tense clash" in m for m in _said(real, urdu))


def test_one_tense_in_a_sentence_passes(real: Glossary) -> None:
    for urdu in ("جب سامنے 0.40 m پر ایک ڈبہ ہو، تو راستہ صاف نہیں ہے۔",
                 "جب سامنے ایک ڈبہ تھا، تو راستہ صاف نہیں تھا۔"):
        assert not any("tense clash" in m for m in _said(real, urdu))


# 5. Register ----------------------------------------------------------------------------
@pytest.mark.parametrize(("urdu", "plain"), [
    ("public tests چلائیے", "چلائیں"), ("دنیا کو اکیلے شروع کیجیے", "کریں"),
    ("ایسا `message` دیجیے", "دیں"), ("اسے `main()` میں لکھیے۔", "لکھیں"),
])
def test_the_polite_imperative_is_caught(real: Glossary, urdu: str, plain: str) -> None:
    assert any("polite imperative" in m and f"({plain})" in m for m in _said(real, urdu))


def test_words_ending_like_an_imperative_are_not_one(real: Glossary) -> None:
    urdu = "اس کے لیے یہ چاہیے کہ زاویے درست کیے جائیں، جو وہ چلائے"
    assert not any("imperative" in m for m in _said(real, urdu))


# 6. README blocks on GitHub ----------------------------------------------------------
def test_a_readme_block_that_starts_with_a_latin_word_fails(tmp_path: Path) -> None:
    course = _course(tmp_path, readme=(
        "# ایک نوڈ: timers\n\n"
        "public tests چلائیں۔\n\n"                   # line 5: a paragraph
        "- `cmd_vel` پر ایک حکم\n"                   # line 7: a list item
        "- ہر حکم `cmd_vel` پر\n\n"
        "**`check_path`۔** جواب دیں۔\n\n"          # line 10: bold code first
        "| `cmd_vel` | ایک ٹاپک |\n"))             # a table cell: no dir=auto
    found = [f for f in _found(course) if "starts with a Latin word" in f]
    assert [f.split(":")[1] for f in found] == ["5", "7", "10"], found


def test_the_real_readmes_start_every_block_right_to_left() -> None:
    for readme in sorted((REPO / "assignments").glob("*/README.ur.md")):
        lines = readme.read_text(encoding="utf-8").splitlines()
        heads = [line for line in lines if line.startswith("# ")]
        assert heads and rules.first_strong(heads[0][2:]) == "R", readme


def test_what_a_robot_hits_is_named_in_the_oblique(real: Glossary) -> None:
    """The collision messages put the obstacle's name before سے: the name it is given
    there is oblique ("ڈبے 2 سے"), which the rule passes and the direct name fails."""
    from autograder.i18n import _, set_language, translations
    from sim.physics import Contact

    translations.cache_clear()
    set_language("ur")
    try:
        # the message test_faulty_world gives, as the catalog translates it
        template = _("The robot hit {what} at `({x:.2f}, {y:.2f})`, {seconds:.1f} s into the "
                     "run.")
        said = [(template.format(what=contact.hit_name, x=0.5, y=0.5, seconds=1.0),
                 template.format(what=contact.description, x=0.5, y=0.5, seconds=1.0))
                for contact in (Contact(t=1.0, x=0.5, y=0.5, what=what)
                                for what in ("box 2", "circle 1", "added box 3"))]
    finally:
        set_language("en")
    for right, wrong in said:
        assert not [m for m in _said(real, right) if "oblique" in m], right
        assert [m for m in _said(real, wrong) if "oblique" in m], wrong


def test_a_rendering_split_over_two_readme_lines_is_caught(tmp_path: Path) -> None:
    course = _course(tmp_path, readme=(
        "# ایک نوڈ: timers\n\n"
        "یہ timer `plan_route()` کو call\n"       # line 5: "call" ends the line
        "کرتا ہے۔\n"))
    found = [str(p) for p in check_language(course / "locales", "ur", course)
             if "'call کر'" in str(p)]
    assert [re.search(r"README\.ur\.md:(\d+):", f)[1] for f in found] == ["5"], found
