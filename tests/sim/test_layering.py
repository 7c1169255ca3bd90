"""``sim`` is the lowest layer: it imports nothing of ``autograder``, yet its messages
follow the language the autograder was set to."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

import content.i18n
from autograder.i18n import set_language
from content import ContentError
from sim.worldfile import load_world

REPO = Path(__file__).resolve().parents[2]


def test_sim_imports_nothing_of_autograder() -> None:
    code = ("import sys, sim.bridge, sim.cli, sim.worldfile, content, sim.faults, "
            "sim.engine, sim.svg, sim.recorder, sim.pacing, sim.procstate, sim.bag\n"
            "leaked = sorted(m for m in sys.modules if m.split('.')[0] == 'autograder')\n"
            "assert not leaked, leaked\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))}
    result = subprocess.run([sys.executable, "-c", code], cwd=REPO, env=env,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr


@pytest.fixture
def urdu() -> Iterator[None]:
    set_language("ur")
    try:
        yield
    finally:
        set_language("en")


def test_sim_messages_follow_the_autograder_language(urdu: None, tmp_path: Path) -> None:
    assert content.i18n.get_language() == "ur"
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    with pytest.raises(ContentError, match="فائل خالی ہے"):  # "the file is empty"
        load_world(empty)
    outside = tmp_path / "outside.yaml"
    outside.write_text("goal: {x: 9, y: 1}\n")
    with pytest.raises(ContentError, match="منزل احاطے سے باہر ہے"):  # the goal is outside
        load_world(outside)


def test_english_is_the_source_language(tmp_path: Path) -> None:
    set_language("en")
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    with pytest.raises(ContentError, match="the file is empty"):
        load_world(empty)
