"""The gettext binding of the simulator and the content files: the platform's language and
``messages`` catalogs without importing the autograder, the folder asked for only when a
message is translated (``AUTOGRADER_LOCALES`` first), a compiled ``.mo`` only while it is as
new as its ``.po``, English the source language. (That ``sim`` follows the autograder's
language: tests/sim/test_layering.py.)"""

from __future__ import annotations

import gettext
import os
from collections.abc import Iterator
from pathlib import Path

import pytest
from babel.messages.catalog import Catalog
from babel.messages.mofile import write_mo

import content.i18n
from content.i18n import N_, NP_, load_catalog

HEADER = 'msgid ""\nmsgstr "Content-Type: text/plain; charset=UTF-8\\n"\n\n'


@pytest.fixture(autouse=True)
def language() -> Iterator[None]:
    """Afterwards, the language and the catalogs' folder the autograder set (as it sets
    them whenever its language changes)."""
    yield
    from autograder.i18n import get_language, set_language

    set_language(get_language())


def _po(folder: Path, entries: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    po = folder / "messages.po"
    po.write_text(HEADER + entries, encoding="utf-8")
    return po


def test_sim_alone_honours_autograder_locales(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """Without the autograder, ``AUTOGRADER_LOCALES`` still says where the catalogs are."""
    folder = tmp_path / "ur" / "LC_MESSAGES"
    folder.mkdir(parents=True)
    folder.joinpath("messages.po").write_text(
        'msgid ""\nmsgstr "Content-Type: text/plain; charset=UTF-8\\n"\n\n'
        'msgid "the file is empty"\nmsgstr "خالی"\n', encoding="utf-8")
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(tmp_path))
    before = content.i18n.get_language()
    content.i18n.set_language("ur")
    try:
        assert content.i18n._("the file is empty") == "خالی"
        assert content.i18n._("the goal is outside the arena") == "the goal is outside the arena"
    finally:
        content.i18n.set_language(before)


def test_the_folder_is_asked_for_only_when_a_message_is_translated(tmp_path, monkeypatch):
    monkeypatch.delenv("AUTOGRADER_LOCALES", raising=False)
    asked = []

    def locales() -> Path:
        asked.append(True)
        return tmp_path

    _po(tmp_path / "ur" / "LC_MESSAGES", 'msgid "the file is empty"\nmsgstr "خالی"\n')
    content.i18n.set_language("ur", locales)
    assert asked == [] and content.i18n.get_language() == "ur"
    assert content.i18n._("the file is empty") == "خالی"
    assert asked == [True]
    content.i18n.set_language("en")  # English: the source, no catalog read
    assert content.i18n._("the file is empty") == "the file is empty"
    assert asked == [True]
    assert content.i18n.locales_dir() == tmp_path  # the lookup given before is kept
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(tmp_path / "elsewhere"))
    assert content.i18n.locales_dir() == tmp_path / "elsewhere"


def test_plurals_contexts_and_marks(tmp_path, monkeypatch):
    _po(tmp_path / "ur" / "LC_MESSAGES",
        'msgid "{n} beam"\nmsgid_plural "{n} beams"\nmsgstr[0] "{n} شعاع"\n'
        'msgstr[1] "{n} شعاعیں"\n\n'
        'msgctxt "world"\nmsgid "Corridor"\nmsgstr "راہداری"\n')
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(tmp_path))
    content.i18n.set_language("ur")
    assert content.i18n.ngettext("{n} beam", "{n} beams", 1) == "{n} شعاع"
    assert content.i18n.ngettext("{n} beam", "{n} beams", 5) == "{n} شعاعیں"
    assert content.i18n.pgettext("world", "Corridor") == "راہداری"
    assert content.i18n.pgettext("other", "Corridor") == "Corridor"
    assert N_("Corridor") == "Corridor" and NP_("world", "Corridor") == "Corridor"


def test_a_mo_is_used_only_while_it_is_as_new_as_its_po(tmp_path):
    folder = tmp_path / "ur" / "LC_MESSAGES"
    po = _po(folder, 'msgid "ready"\nmsgstr "from the po"\n')
    catalog = Catalog(locale="ur")
    catalog.add("ready", "from the mo")
    with (folder / "messages.mo").open("wb") as fh:
        write_mo(fh, catalog)
    os.utime(po, (1_000_000, 1_000_000))
    os.utime(folder / "messages.mo", (2_000_000, 2_000_000))
    assert load_catalog(folder, "ur").gettext("ready") == "from the mo"
    os.utime(po, (3_000_000, 3_000_000))  # the po edited since: compiled in memory
    assert load_catalog(folder, "ur").gettext("ready") == "from the po"
    po.write_text(HEADER + 'msgid "ready"\nmsgstr "edited"\n', encoding="utf-8")
    os.utime(po, (4_000_000, 4_000_000))  # read again when it changes
    assert load_catalog(folder, "ur").gettext("ready") == "edited"


def test_fuzzy_and_missing_catalogs_translate_nothing(tmp_path):
    folder = tmp_path / "ur" / "LC_MESSAGES"
    assert type(load_catalog(folder, "ur")) is gettext.NullTranslations
    _po(folder, '#, fuzzy\nmsgid "ready"\nmsgstr "unchecked"\n')
    assert load_catalog(folder, "ur").gettext("ready") == "ready"
