"""``autograder sim run --node FILE --exercise ID --param NAME:=VALUE``: the options the
autograder gives ``sim``'s ``run`` command (``sim`` knows nothing of students' nodes); the
hand run itself is :mod:`autograder.commands.hand_run`.

Exit codes as for every command (:mod:`autograder.cli.exits`), and 1 when the
program did not get its node up.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
from click.core import ParameterSource

from autograder.commands.hand_run import (
    NodeNotUp,
    NodeRun,
    clear_domain,
    exercise_world,
    node_exercise,
    refuse_unreadable,
)
from autograder.i18n import _
from sim.cli import COMPANION


class NodeFailed(click.ClickException):
    """The program did not get its node up: what the student's program did, not ours."""

    exit_code = 1


def _stdout_writer() -> Callable[[bytes], None]:
    stream = click.get_binary_stream("stdout")

    def write(chunk: bytes) -> None:
        stream.write(chunk)
        stream.flush()

    return write


def _check_params(ctx: click.Context, param: click.Parameter,
                  values: tuple[str, ...]) -> tuple[str, ...]:
    """Each ``--param`` must read ``name:=value``, as ``--ros-args -p`` takes it."""
    for value in values:
        name, sep, _rest = value.partition(":=")
        if not sep or not name.strip():
            raise click.BadParameter(_("{value!r} is not NAME:=VALUE, e.g. goal_x:=1.5").format(
                value=value), ctx=ctx, param=param)
    return values


def add_node_options(run: click.Command) -> None:
    """Give ``sim run`` (``run``) the options ``--node FILE`` and ``--exercise ID``."""
    if any(param.name == "node_file" for param in run.params):
        return  # already given
    run.params += [
        click.Option(["--node", "node_file"], default=None,
                     type=click.Path(exists=True, dir_okay=False, path_type=Path),
                     help="Start this node file with the world, as grading starts it; "
                          "simulation time starts once its node is up."),
        click.Option(["--param", "-p", "params"], multiple=True, metavar="NAME:=VALUE",
                     callback=_check_params,
                     help="A ROS parameter for the node (repeatable), as "
                          "'--ros-args -p NAME:=VALUE' gives it."),
        click.Option(["--exercise"], default=None,
                     help="The exercise the node file is for (default: the one whose file "
                          "has its name); picks the exercise's world and pacing."),
    ]
    run.help = inspect.cleandoc(run.help or "") + (
        "\n\nWith --node FILE the world starts your node itself, the way grading does "
        "(sandboxed, with use_sim_time), and holds simulation time until the node is up, so "
        "two runs of one node give the same trajectory. Drive it from another terminal "
        "with 'autograder sim drive'.")
    original = run.callback
    assert original is not None

    @functools.wraps(original)
    def callback(node_file: Path | None, exercise: str | None, params: tuple[str, ...],
                 **kwargs: Any) -> Any:
        ctx = click.get_current_context()
        if node_file is None:
            if exercise is not None or params:
                raise click.UsageError(_("--exercise and --param go with --node FILE."))
            return original(**kwargs)
        refuse_unreadable(node_file)  # before the world: nothing to watch
        found = node_exercise(node_file, exercise)
        if found is not None:
            click.echo(_("Running {file} as the node '{node}' of exercise {exercise}.").format(
                file=node_file, node=found.node, exercise=found.id))
            if ctx.get_parameter_source("world_name") is ParameterSource.DEFAULT:
                kwargs["world_name"] = exercise_world(found)
            if ctx.get_parameter_source("clock_hz") is ParameterSource.DEFAULT:
                kwargs["clock_hz"] = found.clock_hz
        kwargs["domain"] = clear_domain(kwargs.get("domain"))
        ctx.meta[COMPANION] = NodeRun(node_file, found, echo=_stdout_writer(), params=params)
        try:
            return original(**kwargs)
        except NodeNotUp as exc:
            raise NodeFailed(str(exc)) from None

    run.callback = callback
