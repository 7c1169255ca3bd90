"""The test API an exercise's tests use (autograder/testing.py) is importable, documented,
and what the instructors' guide shows: each fixture, marker and inbox accessor the guide
names exists, and each the plugin offers is in the guide."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import autograder.plugin
import autograder.testing
from autograder.plugin.probe import Inbox

GUIDE = Path(__file__).resolve().parent.parent / "docs" / "instructors" / "writing-exercises.md"


def test_every_public_name_is_documented() -> None:
    for name in autograder.testing.__all__:
        value = getattr(autograder.testing, name)
        assert name == "MARKERS" or inspect.getdoc(value), name


def test_the_guide_shows_every_fixture_and_marker_the_plugin_offers() -> None:
    guide = GUIDE.read_text(encoding="utf-8")
    fixtures = {n for n in autograder.plugin.__all__
                if not n.startswith("_") and n[0].islower()} - {"ros_context",
                                                              "submission_file", "exercise"}
    assert {f for f in fixtures if f"**`{f}`**" not in guide} == set()
    assert {m for m in autograder.plugin.MARKERS if f"pytest.mark.{m}(" not in guide} == set()
    assert {m for m in autograder.plugin.MARKERS
            if m not in (autograder.testing.__doc__ or "")} == set()


def test_the_inbox_accessors_the_guide_names_exist() -> None:
    guide = GUIDE.read_text(encoding="utf-8")
    named = set(re.findall(r"`(?:inbox|greetings)\.(\w+)", guide))
    assert {"messages", "items", "times", "since"} <= named
    assert {n for n in named if not hasattr(Inbox, n)} == set()
