"""A hand run (``autograder sim run --node FILE``): a student's node started with the world
the way grading starts it, so that two hand runs of one node in one world are the same run.

The node runs through the sandbox (:func:`autograder.sandbox.process.student_process`:
a throwaway copy, a minimal environment, ``--ros-args -p use_sim_time:=true``, resource
limits, its own session, everything it started stopped with it) and simulation time is
held until it is up on the graph, by the check grading uses
(:mod:`autograder.plugin.graph`). Its output streams to the terminal.

Two things differ from grading, on purpose: isolation is always basic (strict isolation
puts the whole graph in a network namespace of its own, where ``sim drive`` and
``ros2 topic echo`` in another terminal could not reach it), and there is no time limit
(the student stops a hand run with Ctrl-C or ``--duration``).

``sim`` knows nothing of the autograder: :mod:`autograder.cli.sim_node` gives the
``sim run`` command its ``--node`` and ``--exercise`` options and hands a :class:`NodeRun`
to the world as a :class:`sim.cli.Companion`. A program whose node does not come up is
:class:`NodeNotUp` (exit status 1).
"""

from __future__ import annotations

import dataclasses
import os
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from autograder.commands import stale
from autograder.commands.stale import hand_folder
from autograder.core.errors import ContentError, GraderError, UsageError
from autograder.core.output_budget import describe_exit
from autograder.i18n import _

if TYPE_CHECKING:
    from autograder.core.exercise import Exercise, Limits
    from autograder.sandbox.process import StudentProcess
    from sim.bridge import SimBridge

# A hand run ends when the student says so: no wall or CPU time limit of the grading's.
HAND_RUN_SECONDS = 24 * 3600
# Wall seconds a plain node file (no exercise) has to get its node up.
STARTUP_TIMEOUT = 20.0


class NodeNotUp(Exception):
    """The program did not get its node up: what the student's program did, not ours."""


@dataclasses.dataclass
class NodeRun:
    """A student's node run with the world (a :class:`sim.cli.Companion`)."""

    script: Path
    exercise: Exercise | None = None
    echo: Callable[[bytes], None] | None = None
    params: tuple[str, ...] = ()  # "name:=value", as given to --ros-args -p
    process: StudentProcess | None = None
    _folder: Path | None = None
    _folder_lock: int | None = None  # held while the run lives: its folder is not stale
    _bridge: SimBridge | None = None
    _ended_at: float | None = None

    @property
    def node_name(self) -> str | None:
        """The node to wait for: the exercise's, or any new node for a plain file."""
        return self.exercise.node if self.exercise is not None else None

    def pacing_options(self) -> dict[str, Any]:
        return {"cpu_budget": self.exercise.cpu_budget} if self.exercise is not None else {}

    def start(self, bridge: SimBridge) -> None:
        from autograder.core.submission import stage
        from autograder.plugin.graph import node_endpoints, wait_until_up
        from autograder.sandbox.process import LaunchFailed, student_process

        self._bridge = bridge
        name = self.exercise.file if self.exercise is not None else self.script.name
        self._folder, self._folder_lock = hand_folder(name)
        staged = stage(self.script, name, self._folder / "staged")
        course = self.exercise.folder.parent.parent if self.exercise else self._folder
        args = ["-p", "use_sim_time:=true"]
        for param in self.params:
            args += ["-p", param]
        self.process = student_process(staged, args, self.limits,
                                       domain=bridge.node.context.get_domain_id(),
                                       strict=False, course=course)
        self.process.echo = self.echo
        stale = node_endpoints(bridge.node, self.node_name)
        try:
            self.process.start()
        except LaunchFailed as exc:
            raise GraderError(_("The autograder could not start your program ({detail}); "
                                "this is not your fault, tell your instructor.").format(
                detail=exc)) from None
        bridge.watch_pid(self.process.pid)
        timeout = self.exercise.startup_timeout if self.exercise else STARTUP_TIMEOUT
        found = wait_until_up(bridge, bridge.node, self.node_name, stale,
                              self.process.running, timeout)
        if found:
            click.echo(_("Node {names} is up; simulation time starts now.").format(
                names=", ".join(sorted(set(found.values())))))
            return
        raise self.not_up(timeout)

    @property
    def limits(self) -> Limits:
        """The exercise's limits (the defaults for a plain file) but no wall or CPU time
        limit: a hand run ends when the student says so."""
        from autograder.core.exercise import Limits

        limits = self.exercise.limits if self.exercise is not None else Limits()
        return dataclasses.replace(limits, wall_seconds=HAND_RUN_SECONDS,
                                   cpu_seconds=HAND_RUN_SECONDS)

    def not_up(self, timeout: float) -> NodeNotUp:
        """Why the node is not up after ``timeout`` seconds, for the student: their program
        ended (and how), or it runs but no node of the exercise's name (any, for a plain
        file) appeared."""
        assert self.process is not None
        if not self.process.running():
            code = self.process.returncode
            return NodeNotUp(_("Your program {how} during start-up, before its node was up; "
                                "its output is above.").format(
                how=describe_exit(code if code is not None else 0)))
        if self.exercise is None:
            return NodeNotUp(_("No node appeared on the ROS graph within {seconds:.0f} s."
                                ).format(seconds=timeout))
        return NodeNotUp("\n".join((
            _("No node named '{node}' appeared on the ROS graph within {seconds:.0f} s."
              ).format(node=self.exercise.node, seconds=timeout),
            _("Create the node with `super().__init__('{node}')` and spin it.").format(
                node=self.exercise.node))))

    def running(self) -> bool:
        if self.process is not None and self.process.running():
            return True
        if self._ended_at is None and self._bridge is not None:
            self._ended_at = self._bridge.now
        return False

    def stop(self) -> list[str]:
        notes: list[str] = []
        if self.process is not None:
            ended_by_itself = not self.running()
            if self._bridge is not None and self.process.popen is not None:
                self._bridge.closing_pid(self.process.pid)
            status = self.process.stop()
            if self._bridge is not None and self.process.popen is not None:
                self._bridge.unwatch_pid(self.process.pid)
            if ended_by_itself and status is not None and self._ended_at is not None:
                notes.append(_("Your program {how} at {t:.2f} s of simulation time.").format(
                    how=describe_exit(status), t=self._ended_at))
        if self._folder is not None:
            stale.stop(stale.working_in(self._folder))  # a start cut short by a signal
            shutil.rmtree(self._folder, ignore_errors=True)
        if self._folder_lock is not None:
            os.close(self._folder_lock)
            self._folder_lock = None
        return notes


def refuse_unreadable(node_file: Path) -> None:
    """What grading refuses is refused here, before the world starts (exit 2): a link,
    device or FIFO as the node file (or beside it), and a file that is not a node Python
    runs (a syntax error with Python's own lines: :mod:`autograder.core.source`)."""
    from autograder.core.submission import SubmissionNotFound, check

    try:
        check(node_file, node_file.name)
    except SubmissionNotFound as exc:
        raise UsageError(str(exc)) from None


def node_exercise(script: Path, given: str | None) -> Exercise | None:
    """The exercise ``script`` is the node of: ``given`` (an id or folder), else the one
    exercise whose ``file`` has the script's name, else None (a plain node)."""
    from autograder.core.exercise import find_exercise, list_exercises

    try:
        if given is not None:
            return find_exercise(given)
        matches = [e for e in list_exercises() if e.file == script.name]
    except ContentError as exc:
        raise UsageError(str(exc)) from None
    return matches[0] if len(matches) == 1 else None


def exercise_world(exercise: Exercise) -> str:
    """The exercise's world as ``sim run --world`` takes it (a file in its folder by path)."""
    local = exercise.folder / exercise.world
    return str(local) if local.suffix in (".yaml", ".yml") and local.exists() else exercise.world


def clear_domain(given: int | None) -> int:
    """The domain the hand run takes: ``given`` (else ``$ROS_DOMAIN_ID``, else 0), with
    the student's nodes left there by a hand run that did not end stopped; a free one
    instead where another user's are (only they may stop them). The student is told."""
    domain = int(os.environ.get("ROS_DOMAIN_ID", "0")) if given is None else given
    nodes = stale.find(domain)
    mine = [node for node in nodes if node.uid == os.getuid()]
    if mine:
        stale.stop(mine)
        for node in mine:
            click.echo(_("A node of yours ({file}, pid {pid}) was still running on ROS domain "
                         "{domain}, left by a hand run that did not end; it got the same "
                         "commands as this run's node, so it is stopped now.").format(
                file=node.script or "?", pid=node.pid, domain=domain), err=True)
    if len(mine) < len(nodes):
        free = stale.free_domain(domain)
        if free is not None:
            click.echo(_("Another user's node, left by a hand run, is on ROS domain "
                         "{domain}, and only they can stop it: this run uses domain {free} "
                         "instead. Give the same domain to your other terminals: "
                         "`autograder sim drive --domain {free}`, `export "
                         "ROS_DOMAIN_ID={free}`.").format(domain=domain, free=free), err=True)
            return free
    return domain
