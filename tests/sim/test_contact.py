"""A contact is a plain record (sim/contact.py): what physics reports and a recording
keeps, named for people in the active language."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

import pytest

from autograder.i18n import set_language
from sim.contact import Contact
from sim.physics import World
from sim.recorder import Recording
from sim.worldfile import load_world


@pytest.fixture(autouse=True)
def _english() -> Iterator[None]:
    set_language("en")
    yield
    set_language("en")


def test_a_contact_names_what_it_hit_and_keeps_a_label_as_is() -> None:
    assert Contact(1.0, 4.2, 3.0, "added box 7").description == "added box 7"
    assert Contact(1.0, 4.2, 3.0, "wall 3").hit_name == "wall 3"
    assert Contact(1.0, 0.0, 0.0, "the dock").description == "the dock"  # a test's label


def test_a_contact_is_frozen_and_compares_by_value() -> None:
    contact = Contact(1.0, 4.2, 3.0, "box 0")
    assert contact == Contact(1.0, 4.2, 3.0, "box 0")
    with pytest.raises(dataclasses.FrozenInstanceError):
        contact.t = 2.0  # type: ignore[misc]


def test_physics_reports_the_contacts_a_recording_reads_back() -> None:
    world = World(load_world("wall_ahead"))
    world.set_command(0.5, 0.0)
    contacts = []
    for _ in range(2000):
        world.step()
        contacts += world.drain_contacts()
        if contacts:
            break
    assert contacts and all(type(c) is Contact for c in contacts)
    recording = Recording(world="wall_ahead", collisions=contacts)
    assert Recording.from_dict(recording.to_dict()).collisions == contacts
