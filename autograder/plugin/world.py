"""The fixtures of the graph a test runs on: the exercise, the student's staged file, the
run's rclpy context, the simulated world and the grader's probe node."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from autograder.core.errors import StudentFailure
from autograder.plugin.bag import attach_probe, close_bag, open_bag
from autograder.plugin.guard import GraphWatch, Wire, graph_watch_key
from autograder.plugin.probe import WORLD_NODE_NAME
from autograder.plugin.stash import reporter_key, settings_key, type_watch_key, world_key
from autograder.plugin.timing import Timing

if TYPE_CHECKING:
    from rclpy.context import Context

    from autograder.core.exercise import Exercise
    from autograder.core.settings import RunSettings
    from autograder.plugin.probe import Probe
    from sim.bridge import SimBridge
    from sim.worldfile import WorldSpec


@pytest.fixture(scope="session")
def exercise(pytestconfig: pytest.Config) -> Exercise:
    """The exercise under test (from the run's settings, or ``--exercise``)."""
    from autograder.core.exercise import find_exercise

    settings = pytestconfig.stash.get(settings_key, None)
    if settings is None:
        pytest.skip("run with --exercise to use the autograder fixtures")
    return find_exercise(settings.exercise)


@pytest.fixture(scope="session")
def submission_file(pytestconfig: pytest.Config, exercise: Exercise,
                    tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A private copy of the student's file (the reference solution when none is given)."""
    from autograder.core.submission import SubmissionNotFound, locate, stage

    given = pytestconfig.stash[settings_key].submission
    try:
        source = locate(Path(given), exercise.file) if given else exercise.solution
    except SubmissionNotFound as exc:
        raise StudentFailure(str(exc)) from None
    return stage(source, exercise.file, tmp_path_factory.mktemp("submission"))


@pytest.fixture(scope="session")
def ros_context(pytestconfig: pytest.Config) -> Iterator[Context]:
    """An rclpy context on this run's own ROS domain (the grader's, or one reserved here),
    with the middleware set for the run's isolation."""
    import rclpy
    from rclpy.context import Context

    from autograder.sandbox.domains import reserve_domain
    from autograder.sandbox.isolation import Isolation, bring_up_loopback, dds_env

    settings = pytestconfig.stash[settings_key]
    if settings.strict:
        bring_up_loopback()  # the run's own network namespace starts with lo down
    for key, value in dds_env(Isolation(settings.isolation)).items():
        if value is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = value
    given = settings.domain
    with reserve_domain(None) if given is None else contextlib.nullcontext(given) as domain:
        os.environ["ROS_DOMAIN_ID"] = str(domain)
        context = Context()
        rclpy.init(context=context, domain_id=domain)
        try:
            yield context
        finally:
            rclpy.try_shutdown(context=context)


@pytest.fixture(scope="module")
def world(request: pytest.FixtureRequest, exercise: Exercise,
          ros_context: Context) -> Iterator[SimBridge]:
    """The simulated world for this test module (``@pytest.mark.world`` picks it), its sim
    time held at 0 until the student's node is up or a test first waits for sim time."""
    from sim.worldfile import load_world

    marker = request.node.get_closest_marker("world")
    name = marker.args[0] if marker and marker.args else exercise.world
    local = exercise.folder / name
    spec = load_world(local if local.suffix in (".yaml", ".yml") and local.exists() else name)
    rtf = request.config.stash[settings_key].real_time_factor
    timing = _timing(request)
    with timing.phase(request.node.nodeid, "world_start"):
        bridge = _make_world(exercise, spec, ros_context, rtf)
        bag = open_bag(request, bridge, spec.name)
        bridge.start()
    bridge.on_wait = lambda seconds, held: timing.waited(request.node.nodeid, seconds, held)
    request.config.stash[world_key] = bridge
    try:
        yield bridge
    finally:
        request.config.stash[world_key] = None
        bridge.on_wait = None
        with timing.phase(request.node.nodeid, "world_start"):
            bridge.stop()
        close_bag(request, bag)
        reporter = request.config.stash.get(reporter_key, None)
        if reporter is not None:
            reporter.data["recordings"][request.node.name] = bridge.recording.to_dict()
            reporter.data.setdefault("pacing", {})[request.node.name] = {
                **bridge.pacing, "longest_hold": round(bridge.longest_hold, 3),
                "held_seconds": round(bridge.pacer.held_seconds, 3),
                "late_deliveries": bridge.pacer.late_deliveries,
                "bursts": bridge.pacer.bursts,
                "receipts_awaited": bridge.pacer.receipts_awaited,
                "blocked_waits": bridge.pacer.blocked_waits,
                "late_commands": bridge.late_commands,
                "latest_command": round(bridge.latest_command, 3)}


def _timing(request: pytest.FixtureRequest) -> Timing:
    """The run's timing (a throwaway one when the tests run without the reporter)."""
    reporter = request.config.stash.get(reporter_key, None)
    return reporter.timing if reporter is not None else Timing()


def _make_world(exercise: Exercise, spec: WorldSpec, ros_context: Context,
                rtf: float | None) -> SimBridge:
    """The world for ``spec`` on the run's context, not yet started."""
    from sim.bridge import SimBridge
    from sim.pacing import PacingPolicy
    from sim.physics import World

    return SimBridge(World(spec), ros_context, node_name=WORLD_NODE_NAME,
                     policy=PacingPolicy(clock_hz=exercise.clock_hz,
                                         cpu_budget=exercise.cpu_budget),
                     real_time_factor=exercise.real_time_factor if rtf is None else rtf,
                     cmd_vel_type=exercise.cmd_vel_type,
                     # Sim time stays at 0 while the module sets up (probe, student's
                     # program): the node's clock begins there on any machine.
                     gated=True)


def _wire(settings: RunSettings) -> Wire | None:
    """Who may be on this grading's domain, where runs share the network; None in strict
    isolation (a network namespace of its own: nobody else is there)."""
    from autograder.sandbox.domains import bound_on_domains
    from autograder.sandbox.isolation import student_uid

    domain = int(os.environ["ROS_DOMAIN_ID"])
    if settings.strict:
        return None
    if not settings.own_user:  # the student is the grader's user
        return Wire(domain, frozenset({os.getuid(), os.geteuid()}), os.getuid(),
                    bound_on_domains)
    return Wire(domain, frozenset({os.getuid(), os.geteuid()}), student_uid(domain),
                bound_on_domains, frozenset(student_uid(d) for d in settings.domains))


@pytest.fixture(scope="module")
def probe(request: pytest.FixtureRequest, ros_context: Context,
          world: SimBridge) -> Iterator[Probe]:
    """The grader's own node on the graph: publish, subscribe, call, set parameters."""
    from autograder.plugin.probe import Probe

    timing = _timing(request)
    with timing.phase(request.node.nodeid, "world_start"):
        node = Probe(ros_context, world)
        attach_probe(request, node)
    # For the reporter: what the graph showed of types that never match (msgtypes.py).
    request.node.stash[type_watch_key] = node.types
    # For the tampering guard: the graph, watched from now until the probe goes.
    watch = GraphWatch(node, wire=_wire(request.config.stash[settings_key]))
    watch.start()
    request.node.stash[graph_watch_key] = watch
    try:
        yield node
    finally:
        watch.stop()
        with timing.phase(request.node.nodeid, "world_start"):
            node.close()
