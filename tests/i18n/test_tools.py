"""Extracting, updating, compiling and checking the catalogs (through ``autograder i18n
extract | update | compile | check``). The Babel extractors themselves:
tests/quiz/test_extract.py; the command's own output and errors: tests/cli/test_i18n.py."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from babel.messages.pofile import read_po
from click.testing import CliRunner
from quiz_course import QUIZ_COURSE

from autograder.cli.i18n import i18n_cli
from autograder.i18n import translations

REPO = Path(__file__).resolve().parents[2]


def test_identical_strings_in_different_questions_stay_separate(tmp_path: Path) -> None:
    out = tmp_path / "locales"
    from autograder.i18n.tools import extract

    extract(QUIZ_COURSE, out, REPO / "babel.cfg")
    with (out / "content.pot").open("rb") as fh:
        catalog = read_po(fh)
    contexts = sorted(m.context for m in catalog if m.id == "None of the above")
    assert contexts == ["quiz:callback-groups:gil-effect:options.none",
                        "quiz:parameter-validation:range:options.none",
                        "quiz:rclpy-part2:shared-resources:options.none"]


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A small course: one quiz, one exercise, one Python module, one template."""
    shutil.copy(REPO / "babel.cfg", tmp_path / "babel.cfg")
    (tmp_path / "quizzes").mkdir()
    shutil.copy(QUIZ_COURSE / "quizzes" / "part2-rclpy.yaml", tmp_path / "quizzes")
    (tmp_path / "assignments" / "timers").mkdir(parents=True)
    (tmp_path / "assignments" / "timers" / "exercise.yaml").write_text(
        "id: timers\ntitle: Timers\nsummary: Two timers.\n")
    (tmp_path / "autograder" / "templates").mkdir(parents=True)
    (tmp_path / "autograder" / "mod.py").write_text(
        "from autograder.i18n import _, N_\n"
        "LABEL = N_('Lazy label')\n"
        "def f(p):\n    return _('{path} not found').format(path=p)\n")
    (tmp_path / "autograder" / "templates" / "page.html").write_text(
        "<p>{{ _('Submit answers') }}</p>\n")
    monkeypatch.setenv("AUTOGRADER_COURSE", str(tmp_path))
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(tmp_path / "locales"))
    monkeypatch.chdir(tmp_path)
    translations.cache_clear()
    yield tmp_path
    translations.cache_clear()


def _run(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(i18n_cli, list(args))
    assert "Traceback" not in result.output, result.output
    return result.exit_code, result.output


def test_extract_update_compile_check(course: Path) -> None:
    assert _run("extract")[0] == 0
    locales = course / "locales"
    with (locales / "messages.pot").open("rb") as fh:
        platform = {m.id: m for m in read_po(fh) if m.id}
    assert set(platform) == {"Lazy label", "{path} not found", "Submit answers"}
    # The platform's locations name the file only: an edit elsewhere moves no entry.
    assert platform["{path} not found"].locations == [("autograder/mod.py", None)]
    with (locales / "content.pot").open("rb") as fh:
        content = {m.context for m in read_po(fh) if m.id}
    assert "exercise:timers:title" in content and "quiz:rclpy-part2:gil:text" in content

    assert _run("update")[0] == 0
    po = locales / "ur" / "LC_MESSAGES" / "messages.po"
    assert po.exists() and (locales / "ur" / "LC_MESSAGES" / "content.po").exists()

    code, output = _run("check")
    assert code == 1 and "ur: no translation of 'Lazy label'" in output

    text = po.read_text()
    text = text.replace('msgid "Lazy label"\nmsgstr ""', 'msgid "Lazy label"\nmsgstr "لیبل"')
    text = text.replace('msgid "{path} not found"\nmsgstr ""',
                        'msgid "{path} not found"\nmsgstr "{file} نہیں ملی"')
    po.write_text(text)
    code, output = _run("check", "--lang", "ur")
    assert "changes its placeholders or code: {path} became {file}" in output

    assert _run("compile")[0] == 0
    mo = po.with_suffix(".mo")
    assert mo.exists()
    translations.cache_clear()
    assert translations("ur").gettext("Lazy label") == "لیبل"


def test_update_keeps_translations_and_marks_changed_strings_fuzzy(course: Path) -> None:
    _run("extract")
    _run("update")
    po = course / "locales" / "ur" / "LC_MESSAGES" / "messages.po"
    po.write_text(po.read_text().replace('msgid "Submit answers"\nmsgstr ""',
                                         'msgid "Submit answers"\nmsgstr "جوابات جمع کرائیں"'))
    page = course / "autograder" / "templates" / "page.html"
    page.write_text("<p>{{ _('Submit your answers') }}</p>\n")
    _run("extract")
    _run("update")
    with po.open("rb") as fh:
        entry = read_po(fh).get("Submit your answers")
    assert entry is not None and entry.fuzzy  # lint fails until a translator checks it
    code, output = _run("check")
    assert code == 1 and "is fuzzy" in output


def test_extracting_after_a_content_change_touches_only_what_changed(course: Path) -> None:
    """Adding a quiz (and lines above a platform string) leaves the platform's template
    and catalogs byte for byte as they were; the content template gains the quiz only."""
    locales = course / "locales"
    assert _run("extract")[0] == 0 and _run("update")[0] == 0
    platform = [locales / "messages.pot", locales / "ur" / "LC_MESSAGES" / "messages.po"]
    before = [p.read_bytes() for p in platform]
    content = (locales / "content.pot").read_text()
    mod = course / "autograder" / "mod.py"
    mod.write_text("# a comment that moves every line below it\n" + mod.read_text())
    (course / "quizzes" / "extra.yaml").write_text(
        "id: extra\ntitle: Extra\nquestions:\n  - id: sure\n    type: true_false\n"
        "    text: Yes?\n    answer: true\n")
    assert _run("extract")[0] == 0 and _run("update")[0] == 0
    assert [p.read_bytes() for p in platform] == before
    after = (locales / "content.pot").read_text().splitlines()
    added, removed = set(after) - set(content.splitlines()), set(content.splitlines()) - set(after)
    assert {line for line in added if line.startswith("msgctxt")} == {
        'msgctxt "quiz:extra:title"', 'msgctxt "quiz:extra:sure:text"'}
    assert not [line for line in added if line.startswith("#: quizzes/part2")]
    assert [line for line in removed if not line.startswith('"POT-Creation-Date')] == []



def test_no_entry_reads_as_a_percent_format() -> None:
    """Our strings use named ``{placeholders}`` only. Babel flags any "% x" as a %-directive
    ("15% of" is the directive "% o"), and GNU msgfmt --check then refuses a translation
    that moves the "%" ("15% beams": "% b"), so the catalogs would not compile with gettext's
    own tools: write "percent" instead."""
    root = Path(__file__).resolve().parents[2] / "locales"
    for template in sorted(root.glob("*.pot")):
        with template.open("rb") as fh:
            flagged = [m.id for m in read_po(fh) if m.id and "python-format" in m.flags]
        assert flagged == [], f"{template}: {flagged}"


@pytest.mark.slow  # about 30 s: every source file extracted, every rule checked
def test_the_platforms_own_catalogs_are_current_and_complete(tmp_path: Path) -> None:
    """What the code and the content say now is what the templates hold (a message added
    without `i18n extract` reaches no translator: an Urdu grading then shows English),
    and `i18n check` finds nothing in the course's own catalogs."""
    from autograder.i18n.glossary import check_all
    from autograder.i18n.tools import extract

    root = Path(__file__).resolve().parents[2]
    for fresh in extract(root, tmp_path):
        with fresh.open("rb") as fh:
            now = {(m.context, m.id) for m in read_po(fh) if m.id}
        with (root / "locales" / fresh.name).open("rb") as fh:
            kept = {(m.context, m.id) for m in read_po(fh) if m.id}
        assert now - kept == set(), f"not in locales/{fresh.name}: run autograder i18n extract"
        assert kept - now == set(), f"no longer said, still in locales/{fresh.name}"
    problems = check_all(root / "locales", root=root)
    assert problems == [], "\n".join(str(p) for p in problems[:20])
