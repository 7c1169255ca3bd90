"""``autograder sim``: run a world standalone, list worlds, check a world file, drive.

A thin click layer: each command calls plain functions of the ``sim`` package. ``sim run``
can also start a program with the world (a :class:`Companion`, put in the click context's
``meta`` under :data:`COMPANION`): ``autograder sim run --node`` starts a student's node
that way, while ``sim`` itself knows nothing of the autograder.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import click
from click.core import ParameterSource

from content import ContentError
from content.i18n import _
from sim.keyboard import Command
from sim.pacing import DEFAULT_CLOCK_HZ, PacingPolicy
from sim.worldfile import load_world, title_of, world_names, world_path

if TYPE_CHECKING:
    from sim.bag import BagRecorder
    from sim.bridge import SimBridge
    from sim.drive import Driver
    from sim.worldfile import WorldSpec

COMPANION = "sim.run.companion"
"""Key of the :class:`Companion` ``sim run`` starts with the world, in ``ctx.meta``."""


class Companion(Protocol):
    """A program run with the world: started once the world exists, with simulation time
    held until it is up, and stopped before the world."""

    def pacing_options(self) -> dict[str, Any]:
        """Fields of the world's :class:`sim.pacing.PacingPolicy` it needs (``cpu_budget``,
        ...)."""
        ...

    def start(self, bridge: SimBridge) -> None:
        """Start, and return once up (no tick goes meanwhile)."""
        ...

    def running(self) -> bool:
        """Whether it still runs (the world stops when it ends)."""
        ...

    def stop(self) -> list[str]:
        """Stop everything it started; lines for the run's summary."""
        ...


class WorldFileError(click.ClickException):
    """A world file is malformed (exit code 2, like a usage error)."""

    exit_code = 2


def _load(name_or_path: str) -> WorldSpec:
    try:
        return load_world(name_or_path)
    except ContentError as exc:
        raise WorldFileError(str(exc)) from None


@click.group("sim")
def sim_cli() -> None:
    """The simulated robot world the exercises run in."""


@sim_cli.command("worlds")
def worlds_command() -> None:
    """List the shipped worlds."""
    names = world_names()
    width = max((len(name) for name in names), default=0)
    for name in names:
        click.echo(f"{name:<{width}}  {title_of(_load(name))}")


@sim_cli.command("check")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
def check_command(file: Path) -> None:
    """Validate a world file; report the file, line and field of the first mistake."""
    spec = _load(str(file) if file.suffix else str(file) + ".yaml")
    click.echo(_("{path}: ok ({title})").format(path=file, title=title_of(spec)))


@sim_cli.command("run")
@click.option("--world", "world_name", default="empty_room", show_default=True,
              help="A shipped world's name or a world file's path.")
@click.option("--rtf", type=click.FloatRange(min=0.0), default=1.0, show_default=True,
              help="Real-time factor; 0 runs as fast as the graph keeps up.")
@click.option("--duration", type=click.FloatRange(min=0.0, min_open=True), default=None,
              help="Stop after this many sim seconds (default: run until Ctrl-C).")
@click.option("--domain", type=click.IntRange(0, 232), default=None,
              help="ROS domain id (default: $ROS_DOMAIN_ID or 0).")
@click.option("--record", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the trajectory and collisions as JSON here.")
@click.option("--svg", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write a picture of the trajectory here.")
@click.option("--record-bag", "bag", type=click.Path(file_okay=False, path_type=Path),
              default=None, help="Record the world's topics as a rosbag2 bag (MCAP) here.")
@click.option("--seed", type=int, default=None, help="Override the world's seed.")
@click.option("--clock-hz", type=click.FloatRange(min=1.0), default=DEFAULT_CLOCK_HZ,
              show_default=True,
              help="Most /clock messages per wall second (as graded: Jazzy's "
                   "MultiThreadedExecutor stutters from about 50 Hz).")
@click.option("--cmd-vel-type", type=click.Choice(["Twist", "TwistStamped"]), default=None,
              help="Message type the robot takes on /cmd_vel (default: the world's, "
                   "usually Twist; Jazzy's TurtleBot3 takes TwistStamped).")
def run_command(world_name: str, rtf: float, duration: float | None, domain: int | None,
                record: Path | None, svg: Path | None, bag: Path | None, seed: int | None,
                clock_hz: float, cmd_vel_type: str | None) -> None:
    """Run a world on a ROS domain so a node can drive the robot.

    Start your node in another terminal with the same ROS_DOMAIN_ID:

    \b
        python my_node.py --ros-args -p use_sim_time:=true
    """
    spec = _load(world_name)
    if cmd_vel_type is not None:
        spec = dataclasses.replace(spec, cmd_vel_type=cmd_vel_type)
    summary = run_world(spec, rtf=rtf, duration=duration, domain=_domain(domain), seed=seed,
                        record=record, svg=svg, clock_hz=clock_hz, bag=bag,
                        companion=click.get_current_context().meta.get(COMPANION))
    click.echo(summary)


def _domain(given: int | None) -> int:
    return int(os.environ.get("ROS_DOMAIN_ID", "0")) if given is None else given


def run_world(spec: WorldSpec, *, rtf: float, duration: float | None, domain: int,
              seed: int | None = None, record: Path | None = None,
              svg: Path | None = None, clock_hz: float = DEFAULT_CLOCK_HZ,
              bag: Path | None = None, companion: Companion | None = None) -> str:
    """Run ``spec`` on ``domain`` until ``duration`` sim seconds, Ctrl-C, or the end of
    ``companion`` (started with simulation time held until it is up); return a summary.
    With ``bag``, the world's topics are recorded there as a rosbag2 bag."""
    import rclpy
    from rclpy.context import Context

    from sim.bridge import SimBridge
    from sim.physics import World
    from sim.svg import trajectory_svg

    ctx = Context()
    rclpy.init(context=ctx, domain_id=domain)
    options = companion.pacing_options() if companion is not None else {}
    bridge = SimBridge(World(spec, seed=seed), ctx, real_time_factor=rtf,
                       policy=PacingPolicy(clock_hz=clock_hz, **options))
    recorder = _recorder(bag, bridge, spec.name) if bag else None
    notes: list[str] = []
    warned: set[object] = set()
    try:  # a stop while saying so (a closed pipe) also ends the run as Ctrl-C would
        click.echo(_("World {name} on ROS domain {domain}, RTF {rtf}. Ctrl-C stops.").format(
            name=spec.name, domain=domain, rtf=rtf or _("max")))
        if companion is not None:
            bridge.pause()  # simulation time starts only once the companion is up
        bridge.start()
        if companion is not None:
            companion.start(bridge)
            bridge.resume()

        def over() -> bool:
            return ((duration is not None and bridge.now >= duration - 1e-9)
                    or (companion is not None and not companion.running()))

        while not over():
            if recorder is not None:
                _record_drivers(bridge)
            bridge.wait_for(over, sim_timeout=math.inf, wall_timeout=0.5)
            warn_mismatches(bridge, warned)
    except KeyboardInterrupt:
        pass
    finally:
        try:
            if companion is not None:
                bridge.pause()  # the world ends where the run did, not while it stops
                notes = companion.stop()
        finally:
            effective = bridge.effective_rtf
            bridge.stop()
            rclpy.try_shutdown(context=ctx)
    if recorder is not None:
        written = recorder.close()
        for warning in recorder.warnings():
            click.echo(_("Warning: {message}").format(message=warning), err=True)
        if written is not None:
            click.echo(_("Recording (rosbag2, MCAP) written to {path}").format(path=written),
                       err=True)
    recording = bridge.recording
    if record:
        record.write_text(json.dumps(recording.to_dict(), indent=1), encoding="utf-8")
        click.echo(_("Wrote {path} (--{option}).").format(path=record, option="record"),
                   err=True)
    if svg:
        svg.write_text(trajectory_svg(spec, recording), encoding="utf-8")
        click.echo(_("Wrote {path} (--{option}).").format(path=svg, option="svg"), err=True)
    return "\n".join([*notes, _summary(spec, bridge, effective)])


class NoTerminal(click.ClickException):
    """``--keys`` without a terminal to read them from (exit code 2, a usage error)."""

    exit_code = 2


@sim_cli.command("drive")
@click.option("--topic", default="/cmd_vel", show_default=True,
              help="Topic the velocity commands go to.")
@click.option("--linear", type=float, default=0.0, show_default=True,
              help="Forward velocity in m/s.")
@click.option("--angular", type=float, default=0.0, show_default=True,
              help="Turn rate in rad/s (positive: counter-clockwise).")
@click.option("--for", "seconds", type=click.FloatRange(min=0.0, min_open=True), default=None,
              help="Drive this many seconds, then stop (default: until Ctrl-C).")
@click.option("--rate", type=click.FloatRange(min=0.1, max=1000.0), default=10.0,
              show_default=True, help="Commands per second.")
@click.option("--stamped", is_flag=True,
              help="Publish geometry_msgs/TwistStamped instead of Twist.")
@click.option("--keys", is_flag=True,
              help="Drive with the keyboard: w/x or up/down arrows faster/slower, a/d or "
                   "left/right arrows turn, s or space stop, q quit.")
@click.option("--domain", type=click.IntRange(0, 232), default=None,
              help="ROS domain id (default: $ROS_DOMAIN_ID or 0).")
def drive_command(topic: str, linear: float, angular: float, seconds: float | None,
                  rate: float, stamped: bool, keys: bool, domain: int | None) -> None:
    """Publish velocity commands, so you can try a node without writing a publisher.

    Commands go out on simulation time when a world is running (its /clock is on the
    graph), else on wall time, and end with a zero command. Start the world first.
    """
    import sys

    if keys and not sys.stdin.isatty():
        raise NoTerminal(_("--keys needs a terminal: standard input is not one."))
    if click.get_current_context().get_parameter_source("topic") is ParameterSource.DEFAULT:
        click.echo(_("Warning: without --topic this drives {topic}, the robot's own "
                     "topic, past any node of yours in between; to drive through your node, "
                     "give its input, e.g. `--topic /agent/cmd_vel`.").format(topic=topic),
                   err=True)
    drive(topic, Command(linear, angular), seconds=seconds, rate=rate, stamped=stamped,
          keys=keys, domain=_domain(domain))


def drive(topic: str, command: Command, *, seconds: float | None, rate: float = 10.0,
          stamped: bool = False, keys: bool = False, domain: int = 0) -> None:
    """Publish ``command`` (with ``keys``, the keyboard's) on ``topic`` for ``seconds`` or
    until Ctrl-C, then a zero command."""
    import rclpy
    from rclpy.context import Context

    from sim.drive import Driver

    ctx = Context()
    rclpy.init(context=ctx, domain_id=domain)
    driver = None
    try:
        driver = Driver(ctx, topic, rate=rate, stamped=stamped)
        clock = (_("Driving on {topic} in simulation time (a world's /clock is on the graph).")
                 if driver.sim_time else
                 _("Driving on {topic} in wall time (no /clock on the graph)."))
        click.echo(clock.format(topic=topic), err=True)
        if not driver.subscribed:
            click.echo(_("Nobody subscribes to {topic} yet; publishing anyway.").format(
                topic=topic), err=True)
        if keys:
            _drive_by_keys(driver, seconds)
        else:
            driver.begin(command, seconds)
            driver.run()
    except KeyboardInterrupt:
        pass
    finally:
        if driver is not None:
            elapsed = driver.elapsed
            driver.close()
            click.echo(_("Stopped after {seconds:.2f} s with a zero command on {topic}.").format(
                seconds=elapsed, topic=topic), err=True)
        rclpy.try_shutdown(context=ctx)


def _drive_by_keys(driver: Driver, seconds: float | None) -> None:
    import sys

    from sim.keyboard import apply_key, raw_terminal, read_keys

    click.echo(_("Keys: w or up arrow faster, x or down arrow slower, a or left arrow turn "
                 "left, d or right arrow turn right, s or space stop, q quit."), err=True)
    fd = sys.stdin.fileno()
    driver.begin(Command(), seconds)
    try:
        with raw_terminal(fd):
            while not driver.done:
                for key in read_keys(fd, 0.02):
                    command = apply_key(driver.command, key)
                    if command is None:
                        return
                    driver.command = command
                    click.echo("\r" + _("linear {linear:+.2f} m/s, angular {angular:+.2f} "
                                         "rad/s").format(linear=command.linear,
                                                         angular=command.angular) + "   ",
                               nl=False, err=True)
                driver.spin_once(0.0)
    finally:
        click.echo(err=True)  # off the status line


def _recorder(folder: Path, bridge: SimBridge, world: str) -> BagRecorder:
    """A bag recorder tapping ``bridge``; None (and a warning) if the bag cannot be made."""
    from sim.bag import BagRecorder

    try:
        recorder = BagRecorder(folder, mount=getattr(bridge.sim.lidar, "mount", (0.0, 0.0, 0.0)),
                               custom_data={"world": world})
    except OSError as exc:
        problem = _("The run could not be recorded in {path}: {error}").format(
            path=folder, error=exc)
        click.echo(_("Warning: {message}").format(message=problem), err=True)
        return None
    bridge.add_tap(recorder)
    return recorder


def _record_drivers(bridge: SimBridge) -> None:
    """A recorded hand run also records the velocity commands sent to other nodes: what
    ``sim drive --topic /agent/cmd_vel`` gives the student's node, beside the /cmd_vel
    that node sends on (every Twist or TwistStamped topic on the graph, found as it
    appears)."""
    from sim.cmdvel import MESSAGE_TYPES, full_name

    types = {full_name(kind): message for kind, message in MESSAGE_TYPES.items()}
    for topic, names in bridge.node.get_topic_names_and_types():
        found = next((types[name] for name in names if name in types), None)
        if found is not None:
            bridge.listen(topic, found)


def warn_mismatches(bridge: SimBridge, warned: set[object]) -> None:
    """Say once of each publisher on /cmd_vel whose type the robot does not take."""
    from sim.cmdvel import world_warning

    for mismatch in bridge.cmd_vel_mismatches():
        if mismatch not in warned:
            warned.add(mismatch)
            click.echo(world_warning(mismatch), err=True)


def _summary(spec: WorldSpec, bridge: SimBridge, effective: float) -> str:
    samples, collisions = bridge.recording.snapshot()
    x, y, theta = bridge.world.pose
    ox, oy, otheta = bridge.sim.odometry.pose
    lines = [
        _("Sim time: {t:.2f} s (measured RTF {rtf:.2f})").format(t=bridge.now, rtf=effective),
        _("Final pose: x={x:.3f} m, y={y:.3f} m, theta={theta:.3f} rad").format(
            x=x, y=y, theta=theta),
        _("Odometry (odom frame, from the wheels): x={x:.3f} m, y={y:.3f} m, "
          "theta={theta:.3f} rad").format(x=ox, y=oy, theta=otheta),
        _("Distance travelled: {d:.2f} m").format(d=bridge.recording.distance()),
        _("Collisions: {n}").format(n=len(collisions)),
    ]
    lines += [_("  at {t:.2f} s with {what}").format(t=c.t, what=c.hit_name)
              for c in collisions[:10]]
    if spec.goal is not None:
        reached = math.hypot(x - spec.goal.x, y - spec.goal.y) <= spec.goal.tolerance
        lines.append(_("Goal reached: {answer}").format(
            answer=_("yes") if reached else _("no")))
    return "\n".join(lines)


__all__ = ["COMPANION", "Companion", "sim_cli", "run_world", "world_path"]
