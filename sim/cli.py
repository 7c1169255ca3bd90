"""``autograder sim``: run a world standalone, list worlds, check a world file.

A thin click layer: each command calls plain functions of the ``sim`` package.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from pathlib import Path

import click

from sim.content import ContentError
from sim.i18n import _
from sim.pacing import DEFAULT_CLOCK_HZ
from sim.worldfile import load_world, title_of, world_names, world_path


class WorldFileError(click.ClickException):
    """A world file is malformed (exit code 2, like a usage error)."""

    exit_code = 2


def _load(name_or_path: str):  # noqa: ANN202 - WorldSpec, imported lazily below
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
    for name in world_names():
        spec = _load(name)
        click.echo(f"{name:<12} {title_of(spec)}")


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
@click.option("--seed", type=int, default=None, help="Override the world's seed.")
@click.option("--clock-hz", type=click.FloatRange(min=1.0), default=DEFAULT_CLOCK_HZ,
              show_default=True,
              help="Most /clock messages per wall second (as graded: Jazzy's "
                   "MultiThreadedExecutor stutters from about 50 Hz).")
@click.option("--cmd-vel-type", type=click.Choice(["Twist", "TwistStamped"]), default=None,
              help="Message type the robot takes on /cmd_vel (default: the world's, "
                   "usually Twist; Jazzy's TurtleBot3 takes TwistStamped).")
def run_command(world_name: str, rtf: float, duration: float | None, domain: int | None,
                record: Path | None, svg: Path | None, seed: int | None,
                clock_hz: float, cmd_vel_type: str | None) -> None:
    """Run a world on a ROS domain so a node started by hand can drive the robot.

    Start your node in another terminal with the same ROS_DOMAIN_ID and
    ``--ros-args -p use_sim_time:=true``.
    """
    spec = _load(world_name)
    domain = int(os.environ.get("ROS_DOMAIN_ID", "0")) if domain is None else domain
    if cmd_vel_type is not None:
        spec = dataclasses.replace(spec, cmd_vel_type=cmd_vel_type)
    summary = run_world(spec, rtf=rtf, duration=duration, domain=domain, seed=seed,
                        record=record, svg=svg, clock_hz=clock_hz)
    click.echo(summary)


def run_world(spec, *, rtf: float, duration: float | None, domain: int,  # noqa: ANN001
              seed: int | None = None, record: Path | None = None,
              svg: Path | None = None, clock_hz: float = DEFAULT_CLOCK_HZ) -> str:
    """Run ``spec`` on ``domain`` until ``duration`` sim seconds or Ctrl-C; return a summary."""
    import rclpy
    from rclpy.context import Context

    from sim.bridge import SimBridge
    from sim.physics import World
    from sim.svg import trajectory_svg

    ctx = Context()
    rclpy.init(context=ctx, domain_id=domain)
    bridge = SimBridge(World(spec, seed=seed), ctx, real_time_factor=rtf, max_clock_hz=clock_hz)
    click.echo(_("World {name} on ROS domain {domain}, RTF {rtf}. Ctrl-C stops.").format(
        name=spec.name, domain=domain, rtf=rtf or _("max")))
    bridge.start()
    warned: set[object] = set()
    try:
        while duration is None or bridge.now < duration:
            bridge.wait_until(duration if duration is not None else math.inf, 0.5)
            _warn_mismatches(bridge, warned)
    except KeyboardInterrupt:
        pass
    finally:
        effective = bridge.effective_rtf
        bridge.stop()
        rclpy.try_shutdown(context=ctx)
    recording = bridge.recording
    if record:
        record.write_text(json.dumps(recording.to_dict(), indent=1), encoding="utf-8")
    if svg:
        svg.write_text(trajectory_svg(spec, recording), encoding="utf-8")
    return _summary(spec, bridge, effective)


def _warn_mismatches(bridge, warned: set[object]) -> None:  # noqa: ANN001
    """Say once of each publisher on /cmd_vel whose type the robot does not take."""
    from sim.cmdvel import world_warning

    for mismatch in bridge.cmd_vel_mismatches():
        if mismatch not in warned:
            warned.add(mismatch)
            click.echo(world_warning(mismatch), err=True)


def _summary(spec, bridge, effective: float) -> str:  # noqa: ANN001
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
    lines += [_("  at {t:.2f} s with {what}").format(t=c.t, what=c.description)
              for c in collisions[:10]]
    if spec.goal is not None:
        reached = math.hypot(x - spec.goal.x, y - spec.goal.y) <= spec.goal.tolerance
        lines.append(_("Goal reached: {answer}").format(
            answer=_("yes") if reached else _("no")))
    return "\n".join(lines)


__all__ = ["sim_cli", "run_world", "world_path"]
