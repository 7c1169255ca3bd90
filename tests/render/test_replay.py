"""The report's pictures: one figure per world, labelled with its tests, with a replay of
each run drawn from the recording's data (autograder/render/replay.py)."""

from __future__ import annotations

import base64
import hashlib
import json
import math
import re
import xml.etree.ElementTree as ET

import pytest
from recorded_runs import a_test, recorded

from autograder.core.results import RunResult
from autograder.render.html import to_html
from autograder.render.replay import figures
from sim.recorder import Recording
from sim.worldfile import load_world


@pytest.fixture(scope="module")
def result() -> RunResult:
    """Three modules in the empty room (one of them never moves), one among obstacles."""
    tests = (a_test("test_governor.py", "test_clamps", "linear.x is clamped"),
             a_test("test_governor.py", "test_one_output", "One output per input"),
             a_test("test_world.py", "test_speed", "The measured speed stays under"),
             a_test("test_startup.py", "test_exits", "Exits on an invalid override"),
             a_test("test_faulty.py", "test_no_collision", "No collision among boxes"))
    recordings = {"test_governor.py": recorded("empty_room", 6),
                  "test_world.py": recorded("empty_room", 8, turn=-0.8),
                  "test_startup.py": recorded("empty_room", 3, linear=0.0, turn=0.0),
                  "test_faulty.py": recorded("obstacles", 10)}
    return RunResult("exercise", "parameter_validation", "A velocity governor", tests,
                     recordings=recordings)


def _figures(page: str) -> list[str]:
    return re.findall(r'<figure class="world">.*?</figure>', page, re.S)


def _data(figure: str) -> list[dict]:
    text = re.search(r'<script type="application/json" class="replay-data">(.*?)</script>',
                     figure, re.S)[1]
    return json.loads(text)


def test_one_figure_per_world_listing_the_tests_that_ran_in_it(result: RunResult) -> None:
    page = to_html(result)
    room, obstacles = _figures(page)  # the room first: its run came first
    assert "Empty room" in room and "Room with obstacles" in obstacles
    # Both moving runs of the room are in its figure, each with its tests; the run that
    # never moved is left out, as before.
    assert re.findall(r'<option value="\d">(.*?)</option>', room) == ["test_governor.py",
                                                                   "test_world.py"]
    items = re.findall(r'<li data-run="(\d)"><code dir="ltr">(.*?)</code>\s*<ul>(.*?)</ul>',
                       room, re.S)
    assert [(i, module, re.findall(r"<li>(.*?)</li>", labels))
            for i, module, labels in items] == [
        ("0", "test_governor.py", ["linear.x is clamped", "One output per input"]),
        ("1", "test_world.py", ["The measured speed stays under"])]
    assert "Tests that ran in this world (2 test files):" in room
    assert "Exits on an invalid override" not in page.split('<h2>What the robot did')[1]
    # One run, no picker; its figure names its test.
    assert "<select" not in obstacles
    assert "Tests that ran in this world (one test file):" in obstacles
    assert "No collision among boxes" in obstacles


def test_each_run_is_drawn_and_replayable(result: RunResult) -> None:
    room = figures(result, None)[0]
    svg = ET.fromstring(str(room.svg))
    ns = {"s": "http://www.w3.org/2000/svg"}
    runs = svg.findall(".//s:g[@class='run']", ns)
    assert [g.get("data-run") for g in runs] == ["0", "1"]
    assert all(g.find("s:polyline[@class='path']", ns) is not None for g in runs)
    overlay = svg.find(".//s:g[@class='replay']", ns)
    assert overlay.get("visibility") == "hidden"  # shown by the script only
    assert {el.get("class") for el in overlay.iter()} >= {
        "replay-robot", "replay-scan", "replay-rays", "replay-command"}
    data = _data(next(f for f in _figures(to_html(result)) if "Empty room" in f))
    assert len(data) == 2
    first = data[0]
    spec = load_world("empty_room")
    assert first["poses"][0] == [0.0, spec.start.x, spec.start.y, spec.start.theta]
    assert first["end"] == pytest.approx(6.0)
    assert first["commands"][0] == [0.0, 0.4, 0.0]
    assert [t for t, _r in first["scans"]][:3] == pytest.approx([0.1, 0.6, 1.1])
    assert len(first["scans"][0][1]) == 360
    assert first["scan"]["angle_increment"] == pytest.approx(2 * math.pi / 360)
    assert first["scan_every"] == pytest.approx(0.5)  # older scans are not drawn


def test_replay_data_carries_no_english_words(result: RunResult) -> None:
    # What a collision hit is in the drawing's tooltips, translated; the data has times.
    page = to_html(result)
    for figure in _figures(page):
        for run in _data(figure):
            assert all(isinstance(t, float) for t in run["collisions"])
            values = json.dumps([v for k, v in run.items() if k != "scan"])
            assert not re.search(r"[A-Za-z]{2,}", values.replace("null", ""))


def test_the_page_allows_only_its_own_script(result: RunResult) -> None:
    page = to_html(result)
    policy = re.search(r'http-equiv="Content-Security-Policy" content="([^"]+)"', page)[1]
    policy = policy.replace("&#39;", "'")
    assert "default-src 'none'" in policy
    scripts = re.findall(r"<script>(.*?)</script>", page, re.S)
    assert len(scripts) == 1  # once for the page, whatever the number of figures
    digest = base64.b64encode(hashlib.sha256(scripts[0].encode()).digest()).decode()
    assert f"script-src 'sha256-{digest}'" in policy
    assert "http" not in scripts[0]  # nothing fetched


def test_an_old_results_file_gives_the_static_picture() -> None:
    """Recordings written before commands and scans were kept: the picture as before."""
    old = recorded("empty_room", 6).to_dict()
    for key in ("commands", "scans", "scan"):
        del old[key]
    result = RunResult("exercise", "parameter_validation", "A velocity governor",
                       (a_test("test_governor.py", "test_clamps", "Clamped"),),
                       recordings={"test_governor.py": Recording.from_dict(old)})
    page = to_html(result)
    (figure,) = _figures(page)
    assert 'class="path"' in figure and "test_governor.py" in figure
    assert "replay" not in figure and "<script" not in page
    assert "script-src &#39;none&#39;" in page


def test_urdu_page_keeps_the_picture_and_controls_left_to_right(result: RunResult) -> None:
    page = to_html(RunResult(result.kind, result.id, result.title, result.tests, lang="ur",
                             recordings=result.recordings))
    assert '<html lang="ur" dir="rtl">' in page
    assert page.count('<div class="scene" dir="ltr">') == 2
