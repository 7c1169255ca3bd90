"""The grader's settings for one pytest child (autograder.core.settings): one JSON document
that reads back as it was written."""

from __future__ import annotations

import json

from autograder.core.settings import RunSettings


def test_settings_read_back_equal_tuples_and_all() -> None:
    settings = RunSettings(exercise="/c/assignments/shout", submission="/s/shout.py",
                           domains=(11, 12), isolation="strict", lang="ur",
                           count_only=("/c/assignments/shout/tests/hidden",), key_fd=5)
    again = RunSettings.from_json(settings.to_json())
    assert again == settings
    assert isinstance(again.domains, tuple) and isinstance(again.count_only, tuple)


def test_a_key_of_no_field_is_left_out() -> None:
    text = json.dumps({"exercise": "shout", "from_a_newer_grader": True})
    assert RunSettings.from_json(text) == RunSettings(exercise="shout")


def test_the_isolation_says_who_the_program_runs_as() -> None:
    assert RunSettings("x", isolation="strict").strict
    assert RunSettings("x", isolation="user").own_user
    assert not RunSettings("x", isolation="user").strict
    assert not RunSettings("x").own_user  # basic: the grader's own user
