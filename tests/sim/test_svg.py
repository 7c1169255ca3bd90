"""The picture of a run, or of several in one world: a well-formed, self-contained SVG with
the arena, walls and obstacles, each run's path, end pose and collisions (their time and
what they hit), the start and the goal, in world coordinates with y flipped."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Iterator

import pytest
from recorded_runs import driven

from autograder.i18n import set_language
from sim.recorder import Contact, Recording, Sample
from sim.svg import scene_svg, trajectory_svg
from sim.worldfile import Goal, load_world

SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(autouse=True)
def _english() -> Iterator[None]:
    set_language("en")  # the tooltips are in the active language
    yield


def test_svg_shows_path_start_end_goal_and_collisions() -> None:
    sim = driven("wall_ahead")
    svg = trajectory_svg(sim.world.spec, sim.recording, goal=Goal(x=5.0, y=5.0))
    root = ET.fromstring(svg)  # well-formed, self-contained
    classes = {el.get("class") for el in root.iter()}
    assert {"path", "start", "end", "goal", "collision", "wall"} <= classes
    path = next(el for el in root.iter() if el.get("class") == "path")
    points = path.get("points").split()
    assert points[0] == "3,3" and points[-1] == "3.896,3" and len(points) == 201
    assert "<script" not in svg and "href" not in svg


def test_svg_of_obstacles_world_without_motion() -> None:
    spec = load_world("obstacles")
    svg = trajectory_svg(spec, Recording())
    assert svg.count('class="box"') == 3 and svg.count('class="obstacle"') == 3
    assert 'class="path"' not in svg


def _recording(y: float, hit_at: float | None = None) -> Recording:
    samples = [Sample(t * 0.1, 3 + 0.1 * t, y, 0.0, 1.0, 0.0) for t in range(1, 6)]
    hits = [] if hit_at is None else [Contact(hit_at, 3.5, y, "box 0")]
    return Recording(world="obstacles", samples=samples, collisions=hits)


def test_several_runs_each_in_a_group_of_their_own_with_timed_collisions() -> None:
    spec = load_world("obstacles")
    root = ET.fromstring(scene_svg(spec, [_recording(2.0, 0.5), _recording(4.0)],
                                   overlay='<circle class="replay-robot" cx="1" cy="1" r="0.1"/>'))
    flipped = next(g for g in root.iter(f"{SVG}g") if g.get("transform"))
    assert flipped.get("transform") == "translate(0 6) scale(1 -1)"  # world y up
    runs = [g for g in flipped.iter(f"{SVG}g") if g.get("class") == "run"]
    assert [g.get("data-run") for g in runs] == ["0", "1"]
    first_path = next(el for el in runs[0] if el.get("class") == "path")
    assert first_path.get("points").split()[:2] == ["3,3", "3.1,2"]  # from the start
    (hit,) = [el for el in runs[0] if el.get("class") == "collision"]
    assert hit.get("data-t") == "0.5"
    assert hit.find(f"{SVG}title").text == "0.50 s: box 0"
    assert not [el for el in runs[1] if el.get("class") == "collision"]
    # The overlay is drawn last, on top, in world coordinates.
    assert list(flipped)[-1].get("class") == "replay-robot"


def test_one_run_has_no_group_and_the_robot_points_its_heading() -> None:
    spec = load_world("obstacles")
    recording = Recording(world="obstacles", samples=[Sample(1.0, 4.0, 2.0, math.pi / 2, 0, 0)])
    root = ET.fromstring(trajectory_svg(spec, recording))
    assert not [g for g in root.iter(f"{SVG}g") if g.get("class") == "run"]
    end = next(g for g in root.iter(f"{SVG}g") if g.get("class") == "end")
    heading = end.find(f"{SVG}line")
    assert (heading.get("x1"), heading.get("y1")) == ("4", "2")
    assert heading.get("x2") == "4" and float(heading.get("y2")) > 2  # straight up: +y
    width, height = float(root.get("width")), float(root.get("height"))
    assert width == (6 + 0.2) * 100 and height > width  # the legend below the arena


def test_the_goal_given_replaces_the_worlds() -> None:
    spec = load_world("obstacles")
    goals = [el for el in ET.fromstring(trajectory_svg(spec, Recording(), Goal(1.0, 2.0, 0.25)))
             .iter() if el.get("class") == "goal"]
    assert [(g.get("cx"), g.get("cy"), g.get("r")) for g in goals] == [("1", "2", "0.25")]
