"""One simulation run step by step: what falls due when, and a trajectory pinned bit for bit."""

from __future__ import annotations

from sim.engine import Simulation
from sim.physics import Contact, World
from sim.worldfile import load_world

COMMANDS = {0: (0.8, 0.0), 400: (-0.3, 2.0), 700: (1.0, -0.6), 1300: (0.6, 2.8)}


def test_odometry_every_fourth_step_and_a_scan_every_twentieth() -> None:
    sim = Simulation(World(load_world("obstacles")))
    sim.world.set_command(0.5, 0.5)
    outputs = [sim.step() for _ in range(100)]
    assert [i + 1 for i, o in enumerate(outputs) if o.odom] == list(range(4, 101, 4))
    assert [i + 1 for i, o in enumerate(outputs) if o.scan_due] == list(range(20, 101, 20))
    assert all(o.scan is not None for o in outputs if o.scan_due)
    assert all(o.scan is None for o in outputs if not o.scan_due)
    assert [s.t for s in sim.recording.samples] == [o.odom.t for o in outputs if o.odom]


def test_the_physics_is_the_same_bit_for_bit() -> None:
    """The figures this world gave before the step path was made lean (and since): any
    change to them is a change of the physics, not an optimisation."""
    sim = Simulation(World(load_world("obstacles")))
    for i in range(3000):
        if i in COMMANDS:
            sim.world.set_command(*COMMANDS[i])
        sim.step()
    assert sim.world.pose == (2.3555638303742388, 4.742607818527766, -0.873091228719095)
    assert sim.world.velocity == (0.5999412009603937, 2.8)
    assert len(sim.recording.samples) == 750
    assert sim.recording.collisions == [
        Contact(t=1.655, x=4.197999999999979, y=3.0, what="box 0"),
        Contact(t=3.535, x=4.195818436181828, y=2.7230244510485813, what="box 0")]
