"""The student's program as a test sees it: started through the sandbox, waited for on
the graph with simulation time held, stopped with everything it started."""

from __future__ import annotations

import os
import shutil
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from autograder.core.errors import StudentFailure
from autograder.core.output_budget import (
    TAIL_BYTES,
    TAIL_LINES,
    describe_exit,
    message_tail,
    size_note,
)
from autograder.core.untrusted import visible
from autograder.i18n import _
from autograder.plugin.graph import node_endpoints, wait_until_up
from autograder.plugin.probe import GRADER_NODES
from autograder.plugin.stash import reporter_key, settings_key, startup_key
from autograder.plugin.timing import Timing, module_of
from sim.procstate import runqueue_wait_ns

if TYPE_CHECKING:
    from autograder.core.exercise import Exercise
    from autograder.plugin.probe import Probe
    from autograder.sandbox.process import StudentProcess
    from sim.bridge import SimBridge

# Sim seconds a freshly started node is watched for an immediate exit.
STARTUP_SETTLE = 1.0
# The last line of rclpy's shutdown race: a KeyboardInterrupt that landed while rclpy was
# converting an incoming message (every exercise README explains it).
SHUTDOWN_RACE = "Unable to convert call argument"


def shutdown_race_note(output: str) -> str:
    """A line saying what rclpy's shutdown race is, if ``output`` shows it; else ""."""
    if SHUTDOWN_RACE not in output:
        return ""
    return _("`RuntimeError: Unable to convert call argument '0' to Python object` is "
             "rclpy's shutdown race: the signal that stopped the program landed while rclpy "
             "was converting an incoming message, where `except KeyboardInterrupt` cannot "
             "catch it, so it happens only now and then. The exercise READMEs explain it; "
             "error_handling's (\"Shutting down cleanly, every time\") shows how to take "
             "the signals yourself so that it never happens.")

class StudentNode:
    """The student's running program, seen from the graph."""

    def __init__(self, process: StudentProcess, name: str, probe: Probe,
                 on_stop: Callable[[StudentNode], None] | None = None,
                 shown_folder: str = "") -> None:
        self.process = process
        self.name = name
        self.probe = probe
        self.startup_seconds: float | None = None
        # Sim time when the node was seen on the graph: time stood still while it started,
        # so its timers were created at this time (None: not waited for, or never seen).
        self.appeared_at: float | None = None
        self.on_stop = on_stop
        # The program runs from a throwaway folder; its tracebacks name the student's own
        # folder instead ("" for the file's bare name), line numbers as they are.
        self.shown_folder = shown_folder
        self._stopped = False

    @property
    def returncode(self) -> int | None:
        return self.process.returncode

    def running(self) -> bool:
        return self.process.running()

    def output(self) -> str:
        """What the program wrote, paths of its throwaway folder shown as the student's."""
        return self.process.output_text().replace(f"{self.process.workdir}/",
                                                  self.shown_folder)

    def output_tail(self, lines: int = TAIL_LINES, max_bytes: int = TAIL_BYTES) -> str:
        """The end of the program's output, short enough for a test message (a few lines,
        a few KB), saying so when the program wrote more than the sandbox kept; shown
        :func:`visible` first, so that those limits count what the student reads."""
        tail = message_tail(visible(self.output()), lines, max_bytes)
        output = self.process.output
        note = size_note(output.total, output.budget) if output is not None else ""
        return "\n".join(part for part in (tail, note, shutdown_race_note(tail)) if part)

    def wait_exit(self, wall_timeout: float) -> int | None:
        """Wait (wall time: exiting is the process's business) for it to end; its status."""
        return self.process.wait(wall_timeout)

    def send_signal(self, sig: int) -> None:
        """Signal the program's process group, as Ctrl-C in its terminal would."""
        self.probe.world.closing_pid(self.process.pid)
        self.process.signal(sig)

    def stop(self) -> int | None:
        """Stop the program (SIGINT, then SIGKILL) and remove its folder; once: a later call
        (the module's fixture after a test or a failed start did) only says how it ended,
        and signals no process group whose id may since be another's."""
        if self._stopped:
            return self.process.returncode
        self._stopped = True
        self.probe.world.closing_pid(self.process.pid)
        status = self.process.stop()
        self.probe.world.unwatch_pid(self.process.pid)
        if self.process.uid is not None:  # strict: our own folder in /tmp, not the run's
            shutil.rmtree(self.process.workdir, ignore_errors=True)
        if self.on_stop is not None:
            on_stop, self.on_stop = self.on_stop, None
            on_stop(self)
        return status


def launch(request: pytest.FixtureRequest, exercise: Exercise, script: Path, probe: Probe,
           world: SimBridge, params: dict[str, Any] | None = None,
           wait_for_node: bool = True) -> StudentNode:
    """Start the student's program with ``use_sim_time:=true`` and wait for its node."""
    source = script.read_text(encoding="utf-8", errors="replace")
    try:
        compile(source, script.name, "exec")
    except SyntaxError as exc:
        raise StudentFailure(
            _("{file}, line {line}: {error}").format(file=script.name, line=exc.lineno,
                                                     error=exc.msg),
            _("Fix the syntax error; `python -m py_compile {file}` shows it too.").format(
                file=script.name)) from None
    ros_args = ["-p", "use_sim_time:=true"]
    for key, value in (params or {}).items():
        ros_args += ["-p", f"{key}:={_ros_value(value)}"]
    reporter = request.config.stash.get(reporter_key, None)
    timing = reporter.timing if reporter is not None else Timing()
    with timing.phase(module_of(request.node.nodeid), "node_start"):
        return _launch(request, exercise, script, probe, world, ros_args, wait_for_node)


def _launch(request: pytest.FixtureRequest, exercise: Exercise, script: Path, probe: Probe,
            world: SimBridge, ros_args: list[str], wait_for_node: bool) -> StudentNode:
    """:func:`launch` once the program compiles: start it, wait for its node."""
    from autograder.sandbox.process import student_process

    process = student_process(script, ros_args, exercise.limits,
                              domain=int(os.environ["ROS_DOMAIN_ID"]),
                              mode=request.config.stash[settings_key].isolation,
                              course=exercise.folder.parent.parent)
    # An earlier instance may still be on the graph: its name until its participant's
    # lease runs out, some of its endpoints too. Only publishers that were not there
    # before the start are this instance's.
    stale = endpoints_of(probe, exercise.node) if wait_for_node else set()
    listeners = world.clock_listeners()  # /clock's subscriptions before this instance's
    reporter = request.config.stash.get(reporter_key, None)
    if reporter is not None:
        process.on_spawn = lambda: reporter.note_process(
            process.pid, [str(p) for p in process.cgroup.paths],
            # RLIMIT_NPROC binds every user but root: a uid of the student's own, or an
            # ordinary grading user (where it counts that user's other processes too).
            process.cgroup.bounds(separate_uid=process.uid is not None or os.geteuid() != 0),
            str(process.workdir) if process.uid is not None else None, process.uid)
        process.gate = reporter.spawn_gate
    process.start()
    world.watch_pid(process.pid, process.family)
    node = StudentNode(process, exercise.node, probe, _log_keeper(request),
                       shown_folder(request.config.stash[settings_key].submission_name))
    if wait_for_node:
        earlier = request.config.stash.get(startup_key, None)
        if earlier is not None:  # it already failed to appear once: do not wait again
            node.stop()
            raise StudentFailure(earlier.message, earlier.hint)
        try:
            wait_for_node_up(exercise, node, world, stale, listeners)
        except NodeNeverAppeared as failure:  # stopped already
            request.config.stash[startup_key] = failure
            raise
        except BaseException:  # a wait that raised: nothing may outlive it
            node.stop()
            raise
        if reporter is not None:
            reporter.data.setdefault("startup_seconds", []).append(node.startup_seconds)
    return node




def shown_folder(submission_name: str | None) -> str:
    """The prefix that stands for the program's folder in what it writes: the folder of
    the student's file as they named it, with its slash ("" for a bare file name)."""
    folder = os.path.dirname(submission_name or "")
    return f"{folder}/" if folder else ""


def _ros_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return value if value else "''"
    return repr(value)


class NodeNeverAppeared(StudentFailure):
    """The program ran, but its node never showed up on the graph (not a crash)."""


def endpoints_of(probe: Probe, name: str) -> set[bytes]:
    """The GIDs of the publishers node ``name`` has on the topics every node publishes."""
    return set(node_endpoints(probe.node, name))


def wait_for_node_up(exercise: Exercise, node: StudentNode, world: SimBridge,
                   stale: set[bytes], listeners: int | None = None) -> None:
    """Wait, with simulation time held, until this instance's node is on the graph and the
    world's /clock reaches it (``listeners``: /clock's subscriptions before the start; None:
    not waited for): a start-up is then the same in simulation time however long the
    machine takes (imports, discovery), and the node's first tick is the next one.  A
    grading's world holds sim time from the module's start (its gate), so the node's clock
    begins at the same sim time on any machine."""
    pid = node.process.pid
    found = wait_until_up(world, node.probe.node, exercise.node, stale, node.running,
                          exercise.startup_timeout, lambda: runqueue_wait_ns(pid) / 1e9,
                          None if listeners is None else
                          lambda: world.clock_listeners() > listeners)
    if found:
        node.startup_seconds = time.monotonic() - node.process.started_at
        node.appeared_at = world.now
        return
    if not node.running():
        raise _exited_at_start(node, exercise)
    tail = node.output_tail()  # before SIGINT: what it was doing, not how it stopped
    others = sorted(node.probe.node_names() - set(GRADER_NODES))
    node.stop()
    raise NodeNeverAppeared(
        _("No node named '{node}' appeared on the ROS graph within {seconds:.0f} s "
          "(nodes seen: {others}).\nLast lines of its output:\n{tail}").format(
            node=exercise.node, seconds=exercise.startup_timeout,
            others=", ".join(others) or _("none"), tail=tail or _("(no output)")),
        _("Create the node with `super().__init__('{node}')` and spin it.").format(
            node=exercise.node))


def _exited_at_start(node: StudentNode, exercise: Exercise) -> StudentFailure:
    """A program that ended during its start-up, said the same way whether or not the graph
    showed its node first: that depends on how fast discovery was, not on the program (a
    node created and then crashing in its constructor can go either way). The hint follows
    the exit status, which does not race."""
    code = node.returncode
    node.stop()  # drains the pipe, so the tail ends with its last words
    message = _("Your program {how} during start-up, before its node '{node}' was up and "
                "spinning.\nLast lines of its output:\n{tail}").format(
        how=describe_exit(code if code is not None else 0), node=exercise.node,
        tail=node.output_tail() or _("(no output)"))
    if code == 0:
        return StudentFailure(message, _("Call `rclpy.spin(node)` (or an executor's "
                                         "`spin()`) after creating the node, and keep "
                                         "spinning until the program is stopped."))
    return StudentFailure(message, _(
        "Run it yourself with `python {file} --ros-args -p use_sim_time:=true` and read the "
        "traceback.").format(file=exercise.file))


@pytest.fixture(scope="module")
def student(request: pytest.FixtureRequest, exercise: Exercise, submission_file: Path,
            probe: Probe, world: SimBridge) -> Iterator[StudentNode]:
    """The student's node, started once for this module with its default parameters (or
    those of the module's ``@pytest.mark.parameters({...})``)."""
    marker = request.node.get_closest_marker("parameters")
    node = launch(request, exercise, submission_file, probe, world,
                  marker.args[0] if marker and marker.args else None)
    try:
        # A program that creates its node and quits at once must fail the same way every
        # time, whether or not we saw the node in between: watch it for a moment of sim
        # time (a wait that may raise: a node that keeps the machine too busy).
        if probe.wait_for(lambda: not node.running(), STARTUP_SETTLE):
            raise _exited_at_start(node, exercise)
        yield node
    finally:
        node.stop()  # also its folder, whichever way the module ends


@pytest.fixture
def start_node(request: pytest.FixtureRequest, exercise: Exercise, submission_file: Path,
               probe: Probe, world: SimBridge) -> Iterator[Callable[..., StudentNode]]:
    """Start another instance of the student's program (``params`` as ``-p`` overrides)."""
    started: list[StudentNode] = []

    def start(params: dict[str, Any] | None = None, wait_for_node: bool = True) -> StudentNode:
        node = launch(request, exercise, submission_file, probe, world, params, wait_for_node)
        started.append(node)
        return node

    try:
        yield start
    finally:
        for node in started:
            node.stop()


def _log_keeper(request: pytest.FixtureRequest) -> Callable[[StudentNode], None] | None:
    """What keeps a program's output when it stops, however it stops (a failed start
    too), under the test or module that started it."""
    reporter = request.config.stash.get(reporter_key, None)
    if reporter is None:
        return None
    nodeid = request.node.nodeid
    return lambda node: reporter.keep_log(nodeid, node.output())
