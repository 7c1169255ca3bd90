"""Hidden tests: Ctrl-C (SIGINT) and SIGTERM leave the robot stopped and exit cleanly.

A shutdown that is clean only most of the time is a bug that shows up on the real robot,
so each signal is tried on TRIALS fresh instances of the node; every one must be clean.
Exiting is the process's business, so it is timed in wall seconds: the contract says
2 s, and EXIT_WITHIN allows for a busy grading machine.
"""

from __future__ import annotations

import math
import signal

import pytest
from geometry_msgs.msg import Twist
from helpers import describe, is_zero, raised

from autograder.core.errors import StudentFailure
from autograder.i18n import _
from autograder.plugin.student import SHUTDOWN_RACE

pytestmark = pytest.mark.world("empty_room")

TRIALS = 3
EXIT_WITHIN = 5.0
# Wall seconds for its last messages to reach us, and of quiet that says all came.  The
# quiet is waited for after the process has ended, when whatever it sent is already in our
# sockets, in the order it was sent (one reliable writer), and the stop has come: anything
# after it would be taken within milliseconds (tests/submissions/error_handling/
# cycle_after_stop sends one right after its stop).  0.2 s of it made six trials' quiet a
# third of the module's wall time at eight times real time.
ARRIVE_WITHIN, STRAGGLERS = 3.0, 0.1
# Wall seconds a fresh node's endpoints may take to match ours (discovery on a busy
# machine), simulation time held meanwhile.
MATCH_WITHIN = 3.0
HINT = _("Use `rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)`, spin an "
         "executor in a thread, wait on a threading.Event set by your own SIGINT/SIGTERM "
         "handlers, then stop spinning, publish Twist(), wait_for_all_acked, destroy the node "
         "and return 0 (see the README).")


def _trial(probe, world, start_node, sig: signal.Signals, trial: int) -> None:
    commands = probe.subscribe(Twist, "/cmd_vel")
    # An earlier instance's endpoints may linger (one that crashed, until its lease ends).
    publishers, listening = commands.publisher_count(), world.scan_listeners()
    node = start_node()
    # Its node is up; its endpoints may still be finding ours, which takes wall time. With
    # simulation time held, wait until its commands reach us and the world's scans reach it
    # (or MATCH_WITHIN passes), so that its 5 s below are the same on any machine.
    with world.held():
        world.wait_for(lambda: commands.publisher_count() > publishers
                       and world.scan_listeners() > listening or not node.running(),
                       sim_timeout=math.inf, wall_timeout=MATCH_WITHIN)
    if not probe.wait_for(lambda: bool(commands.messages) and not is_zero(commands.messages[-1]),
                          5.0):
        raise StudentFailure(
            _("A fresh node (trial {trial} of {trials}) never published a moving command "
              "within 5 s, so its shutdown could not be judged.").format(
                trial=trial, trials=TRIALS),
            _("Drive forward at 0.2 m/s when the way ahead is clear."))
    node.send_signal(sig)
    code = node.wait_exit(EXIT_WITHIN)
    name = sig.name
    if code is None:
        raise StudentFailure(
            _("After {signal} (trial {trial} of {trials}) the process was still running "
              "{seconds:.0f} s later.").format(signal=name, trial=trial, trials=TRIALS,
                                                seconds=EXIT_WITHIN), HINT)
    output = node.output()
    if code != 0 or "Traceback" in output:
        raise StudentFailure(
            _("After {signal} (trial {trial} of {trials}) the process exited with status "
              "{code}{traceback}. Its last lines:\n{tail}").format(
                signal=name, trial=trial, trials=TRIALS, code=code,
                traceback=_(" and a traceback") if "Traceback" in output else "",
                tail=node.output_tail(12)), _exit_hint(output))

    def stopped() -> bool:
        messages = commands.messages
        return bool(messages) and is_zero(messages[-1])

    # The process has ended: what it sent is on its way, and reaches us in wall time
    # (simulation time now runs freely). Wait for the stop, then until nothing more comes.
    commands.wait_until(stopped, ARRIVE_WITHIN)
    commands.wait_quiet(STRAGGLERS, ARRIVE_WITHIN, probe.delivering)
    if not stopped():
        last = commands.messages[-1]
        raise StudentFailure(
            _("After {signal} (trial {trial} of {trials}) the last command on cmd_vel was "
              "{got}: the robot would drive on with nobody in charge. The last message must "
              "be a zero Twist.").format(signal=name, trial=trial, trials=TRIALS,
                                         got=describe(last)),
            _("Publish Twist() as the very last thing, once the executor has stopped, and "
              "wait_for_all_acked before destroying the node, so that the stop is delivered "
              "before the process ends. {fix}").format(fix=HINT))


def _exit_hint(output: str) -> str:
    """Name what went wrong when the traceback shows rclpy's own signal handling."""
    error = raised(output)
    if SHUTDOWN_RACE in output:
        return _("The traceback ends in rclpy's shutdown race (see its note above): the "
                 "signal was turned into a KeyboardInterrupt that landed inside rclpy. Let "
                 "your own handlers only note the signal, and stop in ordinary code. "
                 "{fix}").format(fix=HINT)
    if error in ("RCLError", "ExternalShutdownException") or \
            (error and "context is invalid" in output):
        return _("The traceback ends in {error}: rclpy's own signal handler shut the context "
                 "down before your code published its stop. {fix}").format(error=error,
                                                                          fix=HINT)
    return HINT


@pytest.mark.points(2)
def test_clean_exit_on_sigint(probe, world, start_node):
    """On Ctrl-C (SIGINT) it stops the robot and exits with status 0, no traceback"""
    for trial in range(1, TRIALS + 1):
        _trial(probe, world, start_node, signal.SIGINT, trial)


@pytest.mark.points(2)
def test_clean_exit_on_sigterm(probe, world, start_node):
    """On SIGTERM it stops the robot and exits with status 0, no traceback"""
    for trial in range(1, TRIALS + 1):
        _trial(probe, world, start_node, signal.SIGTERM, trial)
