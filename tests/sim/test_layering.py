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


def _python(code: str) -> subprocess.CompletedProcess[str]:
    """``code`` run by a fresh interpreter, with this checkout first on its path."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))}
    return subprocess.run([sys.executable, "-c", code], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=60)


def test_sim_imports_nothing_of_autograder() -> None:
    code = ("import sys, sim.bridge, sim.cli, sim.worldfile, content, sim.faults, "
            "sim.engine, sim.svg, sim.recorder, sim.pacing, sim.procstate, sim.bag\n"
            "leaked = sorted(m for m in sys.modules if m.split('.')[0] == 'autograder')\n"
            "assert not leaked, leaked\n")
    result = _python(code)
    assert result.returncode == 0, result.stderr


@pytest.mark.parametrize("code", [
    "import sim.recorder",
    # The grader's process: its command line, the results, and every grading's recordings
    # read back (a collision among them), as the grading does for every submission.
    "import autograder.cli, autograder.core.results, autograder.grading.run\n"
    "from sim.recorder import Recording\n"
    "Recording.from_dict({'world': 'obstacles', 'trajectory': [[0.1, 3, 3, 0, 0.2, 0]],\n"
    "    'collisions': [{'t': 0.1, 'x': 3, 'y': 3, 'what': 'box 0'}],\n"
    "    'commands': [[0, 0.2, 0]], 'scans': [[0.1, [1.5, None]]]})",
], ids=["recorder", "grader"])
def test_reading_a_recording_loads_neither_numpy_nor_pymunk(code: str) -> None:
    """The grader reads a recording for every grading: numpy and pymunk would cost it
    0.1 CPU seconds each time (issue 36); only the world's own processes load them."""
    result = _python(code + "\nimport sys\n"
                     "heavy = sorted({m.split('.')[0] for m in sys.modules} & {'numpy', 'pymunk'})"
                     "\nassert not heavy, heavy\n")
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
