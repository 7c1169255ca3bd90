"""The collision note (autograder/plugin/collisions.py) on real physics: a robot driven
head on into a box gets it; one that grazes a wall, backs into a box or hits while its
node was not running does not."""

from __future__ import annotations

import math

import pytest

from autograder.i18n import set_language
from autograder.plugin.collisions import bearing, front_beam_note, with_front_beam_note
from sim.engine import Simulation
from sim.physics import World
from sim.worldfile import Box, load_world


@pytest.fixture(autouse=True)
def english():
    set_language("en")


def drive(world: World, linear: float, angular: float = 0.0, limit: float = 20.0
          ) -> Simulation:
    """Drive at a fixed command until the first contact (or ``limit`` sim seconds)."""
    sim = Simulation(world)
    world.set_command(linear, angular)
    while not sim.recording.collisions and world.time < limit:
        sim.step()
    assert sim.recording.collisions, "the robot never touched anything"
    return sim


def box_world(theta: float = 0.0) -> World:
    """The empty room, the robot turned to ``theta``, a box 0.6 m ahead of it."""
    world = World(load_world("empty_room"))
    world.robot.angle = world.control.angle = theta
    ahead = (3.0 + 0.75 * math.cos(theta), 3.0 + 0.75 * math.sin(theta))
    world.add_obstacle(Box(center=ahead, size=(0.3, 0.8), angle=theta))
    return world


@pytest.mark.parametrize("theta", [0.0, 2.0, -2.5], ids=["east", "north-west", "south-west"])
def test_driving_head_on_into_a_box_gets_the_note(theta):
    world = box_world(theta)
    sim = drive(world, 0.3)
    samples, contacts = sim.recording.snapshot()
    assert abs(bearing(contacts[0], samples, world.geometry)) < math.radians(2)
    note = front_beam_note(contacts, samples, world.geometry)
    assert note.startswith("The robot drove into added box 4 straight ahead.")  # 4 walls first
    assert "beam 0 of /scan is straight ahead" in note
    assert "`ranges[len(ranges)//2]` is straight behind" in note


def test_the_note_comes_once_on_a_line_of_its_own():
    world = box_world()
    sim = drive(world, 0.3)
    samples, contacts = sim.recording.snapshot()
    message = with_front_beam_note("The robot hit a box.", contacts * 2, samples,
                                   world.geometry)
    first, note = message.split("\n")
    assert first == "The robot hit a box." and note.count("straight ahead.") == 1


def test_backing_into_a_box_behind_gets_no_note():
    world = box_world(math.pi)  # the box is behind a robot facing +x again after a turn
    world.robot.angle = world.control.angle = 0.0
    sim = drive(world, -0.3)
    samples, contacts = sim.recording.snapshot()
    assert abs(bearing(contacts[0], samples, world.geometry)) > math.radians(170)
    assert front_beam_note(contacts, samples, world.geometry) == ""


def test_grazing_a_wall_at_a_slant_gets_no_note():
    """A touch 40 degrees off the heading is outside the ±30 degree front sector the
    READMEs teach: a node that watched it would not have seen the wall there."""
    world = World(load_world("empty_room"))
    world.robot.angle = world.control.angle = math.radians(50)  # toward the top wall
    sim = drive(world, 0.3)
    samples, contacts = sim.recording.snapshot()
    assert contacts[0].what.startswith("wall")
    assert bearing(contacts[0], samples, world.geometry) == pytest.approx(
        math.radians(40), abs=math.radians(2))
    assert front_beam_note(contacts, samples, world.geometry) == ""


@pytest.mark.parametrize("start,turn,expected", [(14, 0.0, 14), (10, -0.175, 25)],
                         ids=["straight", "turning"])
def test_driving_into_a_wall_inside_the_front_sector_gets_the_note(start, turn, expected):
    """ai_bridge's corridor, as gap_follower_middle_beam meets it: the robot drives back
    west into the end wall, turning, and touches it some 25 degrees off the heading it has
    at that moment (14 when it goes straight): inside the front sector, so the note comes
    (issue 30)."""
    world = World(load_world("corridor"))
    world.robot.position = world.control.position = (0.6, 1.0)
    world.robot.angle = world.control.angle = math.radians(180 - start)
    sim = drive(world, 0.35, turn)
    samples, contacts = sim.recording.snapshot()
    assert contacts[0].what == "wall 3"  # the room's west wall, the corridor's end
    assert math.degrees(abs(bearing(contacts[0], samples, world.geometry))) == \
        pytest.approx(expected, abs=1)
    assert front_beam_note(contacts, samples, world.geometry).startswith(
        "The robot drove into wall 3 straight ahead.")


def test_a_hit_outside_the_nodes_run_gets_no_note():
    world = box_world()
    sim = drive(world, 0.3)
    samples, contacts = sim.recording.snapshot()
    t = contacts[0].t
    assert front_beam_note(contacts, samples, world.geometry, since=t + 0.1) == ""
    assert front_beam_note(contacts, samples, world.geometry, until=t - 0.1) == ""
    assert front_beam_note(contacts, samples, world.geometry, since=t, until=t) != ""


def test_no_samples_or_shapes_is_no_note():
    world = box_world()
    sim = drive(world, 0.3)
    samples, contacts = sim.recording.snapshot()
    assert front_beam_note(contacts, [], world.geometry) == ""
    empty = (world.geometry[0][:0], world.geometry[1][:0])
    assert front_beam_note(contacts, samples, empty) == ""



def test_a_robot_that_turns_into_a_box_is_judged_by_its_heading_at_contact():
    """Arcing left, the robot meets a box some 10 degrees off the heading it has at that
    moment, 76 degrees from the one it started with: the note comes (issue 30)."""
    world = World(load_world("empty_room"))
    world.robot.angle = world.control.angle = 0.0
    turned = 1.0  # where the arc (0.3 m/s, 0.5 rad/s) heads after 2 s
    x, y = 3 + 0.6 * math.sin(turned), 3 + 0.6 * (1 - math.cos(turned))
    face = turned + 0.15
    world.add_obstacle(Box(center=(x + 0.35 * math.cos(face), y + 0.35 * math.sin(face)),
                           size=(0.1, 0.8), angle=face))
    sim = drive(world, 0.3, 0.5)
    samples, contacts = sim.recording.snapshot()
    assert abs(samples[-1].theta) > math.radians(60)  # far from where it started
    assert abs(bearing(contacts[0], samples, world.geometry)) < math.radians(20)
    assert front_beam_note(contacts, samples, world.geometry).startswith(
        "The robot drove into added box 4 straight ahead.")
