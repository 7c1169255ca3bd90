"""pytest plugin: write exercise tests as plain pytest against a live ROS 2 graph.

Shaped like pytest's own ``junitxml``: options in :func:`pytest_addoption`; the
:class:`~autograder.plugin.reporter.GradingReporter` is registered in ``config.stash``
only when an exercise is graded (``--autograder-settings`` from the grader, or
``--exercise`` by hand) and removed in :func:`pytest_unconfigure`. Fixtures give tests
the simulated ``world``, the student's running node (``student``, ``start_node``), a
``probe``, ``credit`` and ``evidence``. Points and visibility travel through markers::

    @pytest.mark.points(2)
    @pytest.mark.visibility("hidden")
    def test_clamps_speed(student, probe): ...

The modules: ``reporter`` (outcomes into the raw report), ``world`` (exercise, rclpy
context, world and probe fixtures), ``student`` (starting and watching the student's
program), ``guard`` (tampering), ``msgtypes`` (message types that never match the
grader's), ``credit`` (partial credit and evidence), ``probe`` (the grader's node),
``markers`` (the markers and their check), ``stash`` (the plugin's state on pytest's config).
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading

import pytest

from autograder.core.dumpable import not_dumpable
from autograder.core.errors import GraderError
from autograder.core.settings import RunSettings
from autograder.i18n import set_language
from autograder.plugin.credit import credit, evidence
from autograder.plugin.guard import _graph_guard
from autograder.plugin.markers import MARKERS, marker_problem
from autograder.plugin.reporter import GradingReporter
from autograder.plugin.stash import reporter_key, settings_key
from autograder.plugin.student import start_node, student
from autograder.plugin.world import exercise, probe, ros_context, submission_file, world

# The fixtures, here so that pytest finds them in the plugin it loaded.
__all__ = ["GradingReporter", "_graph_guard", "credit", "evidence", "exercise", "probe",
           "ros_context", "start_node", "student", "submission_file", "world"]



def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("autograder", "rclpy autograder")
    group.addoption("--exercise", default=None,
                    help="exercise id or folder; turns the autograder fixtures on")
    group.addoption("--submission", default=None,
                    help="the student's file, or a folder holding it (default: the solution)")
    group.addoption("--ros-domain", type=int, default=None,
                    help="ROS domain id of this run (default: reserve a free one)")
    group.addoption("--real-time-factor", type=float, default=None,
                    help="override the exercise's real-time factor")
    group.addoption("--record-bags", default=None, metavar="DIR",
                    help="record each test module's graph as a rosbag2 bag in DIR/<module>")
    group.addoption("--autograder-settings", default=None,
                    help="the grader's settings for this run (JSON; see "
                         "autograder.core.settings)")


def _settings(config: pytest.Config) -> RunSettings | None:
    """The run's settings: the grader's document, or the options given by hand."""
    given = config.getoption("autograder_settings", None)
    if given:
        return RunSettings.from_json(given)
    if config.getoption("exercise", None):
        return RunSettings(exercise=config.getoption("exercise"),
                           submission=config.getoption("submission"),
                           domain=config.getoption("ros_domain"),
                           real_time_factor=config.getoption("real_time_factor"),
                           lang=os.environ.get("AUTOGRADER_LANG", "en"),
                           record=_absolute(config.getoption("record_bags")))
    return None


def _absolute(path: str | None) -> str | None:
    return os.path.abspath(path) if path else None


def pytest_configure(config: pytest.Config) -> None:
    for text in MARKERS.values():
        config.addinivalue_line("markers", text)
    settings = _settings(config)
    if settings is None:
        return  # inert: not grading an exercise
    config.stash[settings_key] = settings
    set_language(settings.lang)
    if settings.course:
        os.environ["AUTOGRADER_COURSE"] = settings.course
    not_dumpable()  # before the key is read: no process of our user may read our memory
    key = b""
    if settings.key_fd is not None:  # a pipe from the parent: the student never sees it
        with os.fdopen(settings.key_fd, "rb") as pipe:
            key = pipe.read()
    reporter = GradingReporter(settings.report, settings.exercise, key)
    config.stash[reporter_key] = reporter
    config.pluginmanager.register(reporter, "autograder-reporter")
    if settings.lifeline_fd is not None:
        _watch_lifeline(settings.lifeline_fd, reporter)


def _watch_lifeline(fd: int, reporter: GradingReporter) -> None:
    """When the grader that started this run dies (the pipe's only writer), end every
    student process of the run and then the run itself: an orphaned run would go on
    grading on a domain another run may take."""

    def watch() -> None:
        with contextlib.suppress(OSError):
            while os.read(fd, 1):
                pass
        from autograder.sandbox.process import reap_recorded

        reap_recorded(reporter.ending())
        os.killpg(os.getpgrp(), signal.SIGKILL)

    threading.Thread(target=watch, daemon=True, name="autograder-lifeline").start()


def pytest_runtest_setup(item: pytest.Item) -> None:
    """A test with a malformed marker is the author's fault: a grader error naming it."""
    if settings_key in item.config.stash:
        problem = marker_problem(item)
        if problem is not None:
            raise GraderError(problem)


def pytest_unconfigure(config: pytest.Config) -> None:
    reporter = config.stash.get(reporter_key, None)
    if reporter is not None:
        del config.stash[reporter_key]
        config.pluginmanager.unregister(reporter)
