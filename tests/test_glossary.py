"""The Urdu glossary: its checker on small fake catalogs and READMEs (each problem at
file:line), the housekeeping checks, and the real course held to the real glossary."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from autograder.cli.i18n import i18n_cli
from autograder.cli.quiz import quiz_cli
from autograder.i18n import translations
from autograder.i18n.glossary import Glossary, check_language, housekeeping, load_glossary

REPO = Path(__file__).resolve().parent.parent
REAL = REPO / "locales" / "ur" / "glossary.yaml"

GLOSSARY = """\
language: ur
terms:
  - en: node
    ur: نوڈ
    plural: نوڈز
    gender: m
    forbid: ['(?i)\\bnodes?\\b']
    why: the book writes نوڈ
  - en: s (seconds)
    ur: سیکنڈ
    forbid: ['\\d ?s\\b(?!/)']
    require: '\\d ?s\\b(?!/)'
    why: the book writes سیکنڈ
  - en: box
    ur: ڈبہ
    forbid: ['(?i)\\bbox\\b']
    why: one word
compounds: [callback group]
latin_verbs: [publish]
"""

HEADER = """\
# Urdu translations for a course.
# Copyright (C) 2026 the maintainers
#
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


def _course(tmp_path: Path, entries: str, readme: str | None = None,
            title: str = "ایک نوڈ: timers") -> Path:
    """locales/ur/{glossary.yaml, LC_MESSAGES/messages.po, content.po} and one README."""
    folder = tmp_path / "locales" / "ur" / "LC_MESSAGES"
    folder.mkdir(parents=True)
    (tmp_path / "locales" / "ur" / "glossary.yaml").write_text(GLOSSARY, encoding="utf-8")
    (folder / "messages.po").write_text(HEADER + entries, encoding="utf-8")
    (folder / "content.po").write_text(
        HEADER + 'msgctxt "exercise:timers:title"\nmsgid "Timers: a node"\n'
        f'msgstr "{title}"\n', encoding="utf-8")
    if readme is not None:
        (tmp_path / "assignments" / "timers").mkdir(parents=True)
        (tmp_path / "assignments" / "timers" / "README.ur.md").write_text(readme,
                                                                           encoding="utf-8")
    return tmp_path


def _check(course: Path) -> list[str]:
    return [str(p) for p in check_language(course / "locales", "ur", course)]


def test_a_term_rendered_another_way_is_a_problem_at_the_msgstr_line(tmp_path: Path) -> None:
    course = _course(tmp_path, (
        'msgid "The node stopped."\n'
        'msgstr "نوڈ رک گیا۔"\n\n'
        'msgid "The node started {node}."\n'        # the placeholder {node} is not prose
        'msgstr "node شروع ہوا {node}۔"\n\n'         # line 18: Latin node in prose
        'msgid "It waited {seconds} s."\n'
        'msgstr "اس نے {seconds} s انتظار کیا۔"\n\n'  # line 21: "s" after a number
        'msgid "Wait 2 s."\n'
        'msgstr "کچھ دیر انتظار کریں۔"\n'))           # line 24: the unit is missing
    po = course / "locales" / "ur" / "LC_MESSAGES" / "messages.po"
    found = _check(course)
    assert found[0].startswith(f"{po}:18: ur: 'node' goes against the glossary's 'node'")
    assert "glossary.yaml:3): write نوڈ" in found[0]
    assert found[1].startswith(f"{po}:21: ur: '0 s' goes against the glossary's 's (seconds)'")
    assert found[2].startswith(f"{po}:21: ur: the English says 's (seconds)'")
    assert found[3].startswith(f"{po}:24: ur: the English says 's (seconds)' but the "
                               "translation has none of سیکنڈ")
    assert len(found) == 4


def test_latin_words_running_together_and_keep_comments(tmp_path: Path) -> None:
    course = _course(tmp_path, (
        'msgid "Pre-set callbacks may change the parameters."\n'
        'msgstr "pre-set callbacks parameters کو بدل سکتے ہیں۔"\n\n'     # line 15
        'msgid "Put it in its callback group and publish it."\n'
        'msgstr "اسے اس کے callback group میں رکھیں اور message publish کریں۔"\n\n'
        '# glossary: keep box (the YAML key)\n'
        'msgid "needs a box"\n'
        'msgstr "box ہونا چاہیے"\n'))
    po = course / "locales" / "ur" / "LC_MESSAGES" / "messages.po"
    found = _check(course)
    assert found == [f"{po}:15: ur: Latin words run together into one left-to-right run: "
                     f"'pre-set callbacks parameters'; put an Urdu word between them, or list "
                     f"the term under compounds in {course / 'locales/ur/glossary.yaml'}"]


def test_readme_prose_comments_and_title(tmp_path: Path) -> None:
    readme = (
        '<div dir="rtl" lang="ur">\n'
        "\n"
        "# ایک کوڈ: timers\n"                                       # line 3: not the title
        "\n"
        "یہ `node` کوڈ ہے، مگر یہ node نہیں۔\n"                       # line 3
        "\n"
        "```bash\n"
        "autograder start timers mydir     # copies the starter\n"   # line 6
        "autograder check timers f.py      # پہلے tests چلائیں\n"
        "python f.py --ros-args -p x:=1    # ایک node\n"             # line 8
        "```\n"
        "\n"
        "جو callback\n"
        "group رکا ہو وہ ٹھیک ہے، مگر یہ callback\n"
        "parameter غلط ہے۔\n"                                        # line 15
        "\n</div>\n")
    course = _course(tmp_path, "", readme)
    path = course / "assignments" / "timers" / "README.ur.md"
    found = _check(course)
    assert found[0] == (f"{path}:3: ur: the title 'ایک کوڈ: timers' is not the catalog's title "
                        "of the exercise, 'ایک نوڈ: timers'")
    assert found[1].startswith(f"{path}:5: ur: 'node' goes against")
    assert found[2] == f"{path}:8: ur: a comment in a code block is not translated: " \
                       "'copies the starter'"
    assert found[3].startswith(f"{path}:10: ur: 'node' goes against")
    assert found[4].startswith(f"{path}:15: ur: Latin words run together into one "
                               "left-to-right run: 'callback parameter'")
    assert len(found) == 5


def test_an_urdu_readme_is_wrapped_right_to_left(tmp_path: Path) -> None:
    """GitHub lays a README out paragraph by paragraph, left to right where a paragraph
    starts with a Latin word: an Urdu README is wrapped in <div dir="rtl">."""
    wrapped = '<div dir="rtl" lang="ur">\n\n# ایک نوڈ: timers\n\nیہ ایک نوڈ ہے۔\n\n</div>\n'
    course = _course(tmp_path, "", wrapped)
    assert _check(course) == []
    bare = wrapped.replace('<div dir="rtl" lang="ur">\n\n', "").replace("\n\n</div>", "")
    (course / "assignments" / "timers" / "README.ur.md").write_text(bare, encoding="utf-8")
    (found,) = _check(course)
    assert "README.ur.md:1: a right-to-left README is wrapped in" in found


def test_obsolete_entries_and_template_headers_fail(tmp_path: Path) -> None:
    po = tmp_path / "messages.po"
    po.write_text(
        "# FIRST AUTHOR <EMAIL@ADDRESS>, 2026.\n"
        'msgid ""\nmsgstr ""\n'
        '"Project-Id-Version: course VERSION\\n"\n'
        '"PO-Revision-Date: YEAR-MO-DA HO:MI+ZONE\\n"\n'
        '"Last-Translator: FULL NAME <EMAIL@ADDRESS>\\n"\n\n'
        'msgid "kept"\nmsgstr "رکھا"\n\n'
        '#~ msgid "gone"\n#~ msgstr "گیا"\n', encoding="utf-8")
    found = [str(p) for p in housekeeping(po)]
    assert found == [
        f"{po}:1: the header still holds the template value 'EMAIL@ADDRESS': fill it in",
        f"{po}:4: the header still holds the template value 'VERSION': fill it in",
        f"{po}:5: the header still holds the template value 'YEAR-MO-DA': fill it in",
        f"{po}:6: the header still holds the template value 'FULL NAME': fill it in",
        f"{po}:11: obsolete entry (#~): its English is no longer in the template; delete it"]


@pytest.mark.parametrize(("change", "where"), [
    (("    why: one word\n", ""), ":14: terms.2.why: required field is missing"),
    (("['(?i)\\bbox\\b']", "['(box']"), ":16: terms.2.forbid.0: not a regular expression"),
    (("    ur: ڈبہ\n", "    ur: ڈبہ\n    colour: red\n"), ":16: terms.2.colour: unknown field"),
])
def test_a_malformed_glossary_names_file_and_line(tmp_path: Path, change: tuple[str, str],
                                                  where: str) -> None:
    course = _course(tmp_path, "")
    path = course / "locales" / "ur" / "glossary.yaml"
    assert change[0] in GLOSSARY
    path.write_text(GLOSSARY.replace(*change), encoding="utf-8")
    found = _check(course)
    assert len(found) == 1 and found[0].startswith(f"{path}{where}"), found


# --- the real glossary --------------------------------------------------------------------
@pytest.fixture(scope="module")
def real() -> Glossary:
    return load_glossary(REAL)


@pytest.mark.parametrize(("urdu", "english"), [
    ("node شروع ہوا", None),
    ("روبوٹ 5 s بعد رکا", None),
    ("سیکنڈز میں period", None),
    ("روبوٹ goal تک پہنچا", None),
    ("ہدف تک پہنچا", None),
    ("کشادہ ہال میں", None),
    ("رکاوٹوں والا کمرا", None),
    ("rclpy فوراً ایک exception دے گا", None),
    ("rclpy حد سے باہر کی قدریں قبول نہیں کرتا", None),
    ("یہ `ParameterNotDeclaredException` دیتا ہے، یعنی exception دیتا ہے", None),
    ("یہ ایک دوڑ ہے، قاعدہ نہیں", None),
    ("وہ CPU گھماتا رہتا ہے", None),
    ("وہ ٹکراؤ گنواتا ہے", None),
    ("دیوار کی گھڑی ایسا نہیں کرتی", None),
    ("نوڈ کا clock چلتا ہے", None),
    ("پانچ درخواستیں ایک ساتھ", None),
    ("ایک box نمودار ہوا", None),
    ("پاسنگ اسکور: 70%", None),
    ("پاس ہونے کے لیے درکار: 70%", None),
    ("cmd_vel کی rate 10 Hz", None),
    ("درست۔", "Correct."),
    ("pre-set callbacks parameters کی فہرست میں ترمیم کر سکتے ہیں", None),
    ("rclpy executor threads کے لیے GIL بند کر دیتا ہے", None),
    ("callback \u200f10 Hz پر", None),
    ("انہیں رکنا چاہئیں", None),
    ("روبوٹ رکا", "The robot stopped within 2 s."),
    ("روبوٹ پہنچا", "The robot reached the goal."),
    ("کھلا", "open room"),
])
def test_the_real_glossary_catches_what_the_issue_saw(real: Glossary, urdu: str,
                                                      english: str | None) -> None:
    assert list(real.problems(urdu, (Path("x.po"), 1), english)), urdu


@pytest.mark.parametrize("urdu", [
    "نوڈ `node` کو spin کریں",
    "`ParameterNotDeclaredException` raise کرتا ہے",
    "rclpy اپنے executor کے threads کے لیے GIL بند کر دیتی ہے",
    "CPython کا ایک lock جو ایک وقت میں صرف ایک thread کو Python bytecode چلانے دیتا ہے",
    "lidar کی 360 beams، سیدھا آگے سے شروع ہو کر گھڑی کی سوئیوں کے الٹ",
    "`use_sim_time` (باب کا clock والا حصہ)",
    "جب `ros2 param set` کسی parameter کو بدلتا ہے",
    "آپ کا جواب درست ہے۔",
])
def test_the_real_glossary_lets_the_right_renderings_pass(real: Glossary, urdu: str) -> None:
    assert not list(real.problems(urdu, (Path("x.po"), 1))), urdu


def test_feedback_never_reads_as_an_option(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(REPO / "locales"))
    translations.cache_clear()
    try:
        ur = translations("ur")
        options = {ur.gettext("True"), ur.gettext("False")}
        for feedback in ("Correct.", "Incorrect.", "Not answered."):
            text = ur.gettext(feedback)
            assert text.startswith("آپ") and text.rstrip("۔") not in options, text
        assert ur.gettext("Pass mark: {mark}").startswith("کامیابی کے لیے درکار اسکور")
        assert ur.gettext("Passing score: {percent} ({counted})").startswith(
            "کامیابی کے لیے درکار اسکور")
    finally:
        translations.cache_clear()


@pytest.fixture
def real_course(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("AUTOGRADER_COURSE", str(REPO))
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(REPO / "locales"))
    translations.cache_clear()
    yield
    translations.cache_clear()


def test_the_course_follows_its_glossary(real_course: None) -> None:
    result = CliRunner().invoke(i18n_cli, ["check"])
    assert result.exit_code == 0, result.output
    result = CliRunner().invoke(quiz_cli, ["lint"])
    assert result.exit_code == 0, result.output


def test_the_readme_answers_file_scores(real_course: None, tmp_path: Path) -> None:
    """The students' quiz guide's sample answers file is one `quiz score` accepts."""
    text = (REPO / "docs" / "students" / "quizzes.md").read_text()
    sample = re.search(r'An answers file looks\s+like `(\{"quiz".*?\}\})`', text, re.S)
    assert sample, "docs/students/quizzes.md has no sample answers file"
    answers = json.loads(sample.group(1).replace("\n", " "))
    path = tmp_path / "answers.json"
    path.write_text(json.dumps(answers))
    result = CliRunner().invoke(quiz_cli, ["score", answers["quiz"], str(path)])
    assert result.exit_code == 0, result.output
