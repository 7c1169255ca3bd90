"""Recording to JSON and the trajectory picture."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

from sim.engine import Simulation
from sim.physics import World
from sim.recorder import Recording
from sim.svg import trajectory_svg
from sim.worldfile import Goal, load_world


def _run(world: str, steps: int = 800) -> Simulation:
    sim = Simulation(World(load_world(world)))
    sim.world.set_command(0.5, 0.0)
    for _ in range(steps):
        sim.step()
    return sim


def test_recording_samples_every_odom_and_collisions() -> None:
    sim = _run("wall_ahead")
    data = json.loads(json.dumps(sim.recording.to_dict()))
    assert len(data["trajectory"]) == 800 // 4  # 50 Hz at dt 0.005
    assert data["trajectory"][0][0] == 0.02
    assert [c["what"] for c in data["collisions"]] == ["wall 4"]
    again = Recording.from_dict(data)
    assert again.samples == sim.recording.samples
    assert again.collisions == sim.recording.collisions
    assert 0.85 < sim.recording.distance() < 0.9


def test_svg_shows_path_start_end_goal_and_collisions() -> None:
    sim = _run("wall_ahead")
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
