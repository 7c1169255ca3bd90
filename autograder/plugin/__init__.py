"""pytest plugin: write exercise tests as plain pytest against a live ROS 2 graph.

Shaped like pytest's own ``junitxml``: options in :func:`pytest_addoption`; the
:class:`GradingReporter` is registered in ``config.stash`` only when ``--exercise`` is
given and removed in :func:`pytest_unconfigure`.  Fixtures give tests the simulated
``world``, the student's running node (``student``, ``start_node``) and a ``probe``.
Points and visibility travel through markers::

    @pytest.mark.points(2)
    @pytest.mark.visibility("hidden")
    def test_clamps_speed(student, probe): ...
"""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import shutil
import signal
import threading
import time
import traceback
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from autograder.core.errors import GraderError, StudentFailure
from autograder.core.output import (
    DETAILS_BYTES,
    LOG_TAIL_BYTES,
    LOG_TAIL_LINES,
    MESSAGE_BYTES,
    TAIL_BYTES,
    TAIL_LINES,
    clip_middle,
    digest,
    log_folder,
    message_tail,
    size_note,
)
from autograder.i18n import _, set_language

reporter_key = pytest.StashKey["GradingReporter"]()
credit_key = pytest.StashKey["Credit"]()
evidence_key = pytest.StashKey["Evidence"]()
startup_key = pytest.StashKey[StudentFailure]()


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("autograder", "rclpy autograder")
    group.addoption("--exercise", default=None,
                    help="exercise id or folder; turns the autograder fixtures on")
    group.addoption("--submission", default=None,
                    help="the student's file, or a folder holding it (default: the solution)")
    group.addoption("--autograder-report", default=None,
                    help="write the raw grading report (JSON) to this file")
    group.addoption("--autograder-report-key-fd", type=int, default=None,
                    help="read the report's signing key from this file descriptor")
    group.addoption("--autograder-lifeline-fd", type=int, default=None,
                    help="end this run and its student processes when this pipe closes "
                         "(the grader that started the run died)")
    group.addoption("--ros-domain", type=int, default=None,
                    help="ROS domain id of this run (default: reserve a free one)")
    group.addoption("--real-time-factor", type=float, default=None,
                    help="override the exercise's real-time factor")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "points(n): points the test is worth (default 1)")
    config.addinivalue_line(
        "markers", "visibility(v): 'visible', 'hidden' or 'after_published' (default: "
        "hidden for tests under a hidden/ folder)")
    config.addinivalue_line("markers", "world(name): the world this module's tests run in")
    config.addinivalue_line(
        "markers", "parameters(dict): -p overrides the module's `student` node starts with")
    config.addinivalue_line(
        "markers", "reveal(what): what a student sees of a failure: 'message' or 'status' "
        "(default: 'message' for visible tests, 'status' for hidden ones)")
    if config.getoption("exercise", None):
        if os.environ.get("AUTOGRADER_LANG"):
            set_language(os.environ["AUTOGRADER_LANG"])
        key_fd = config.getoption("autograder_report_key_fd")
        key = b""
        if key_fd is not None:  # a pipe from the parent: the student never sees the key
            with os.fdopen(key_fd, "rb") as pipe:
                key = pipe.read()
        reporter = GradingReporter(config.getoption("autograder_report"),
                                   config.getoption("exercise"), key)
        config.stash[reporter_key] = reporter
        config.pluginmanager.register(reporter, "autograder-reporter")
        lifeline = config.getoption("autograder_lifeline_fd")
        if lifeline is not None:
            _watch_lifeline(lifeline, reporter)


def _watch_lifeline(fd: int, reporter: GradingReporter) -> None:
    """When the grader that started this run dies (the pipe's only writer), end every
    student process of the run and then the run itself: an orphaned run would go on
    grading on a domain another run may take."""

    def watch() -> None:
        with contextlib.suppress(OSError):
            while os.read(fd, 1):
                pass
        from autograder.sandbox.process import reap_recorded

        for process in list(reporter.data["processes"]):
            reap_recorded(process)
        os.killpg(os.getpgrp(), signal.SIGKILL)

    threading.Thread(target=watch, daemon=True, name="autograder-lifeline").start()


def pytest_unconfigure(config: pytest.Config) -> None:
    reporter = config.stash.get(reporter_key, None)
    if reporter is not None:
        del config.stash[reporter_key]
        config.pluginmanager.unregister(reporter)


# -- the reporter ---------------------------------------------------------------------------

def _label(item: pytest.Item) -> str:
    doc = getattr(getattr(item, "function", None), "__doc__", None) or item.name
    return _(doc.strip().splitlines()[0].strip())


def _reveal(item: pytest.Item, visibility: str) -> str:
    """What a student sees of a test: 'message' (all) or 'status' (label and pass/fail)."""
    marker = item.get_closest_marker("reveal")
    if marker and marker.args:
        return str(marker.args[0])
    return "message" if visibility == "visible" else "status"


def _visibility(item: pytest.Item, hidden_default: str) -> str:
    marker = item.get_closest_marker("visibility")
    if marker and marker.args:
        return str(marker.args[0])
    return hidden_default if "hidden" in Path(str(item.path)).parts else "visible"


class GradingReporter:
    """Collects each test's outcome, points and message; writes the raw report as it goes."""

    def __init__(self, path: str | None, exercise: str | None = None,
                 key: bytes = b"") -> None:
        self.path = Path(path) if path else None
        self.exercise = exercise
        self.key = key
        self.tests: dict[str, dict[str, Any]] = {}
        self.data: dict[str, Any] = {"logs": {}, "log_files": [], "recordings": {},
                                     "processes": []}
        self.hidden_default = "after_published"

    def write(self) -> None:
        if self.path is None:
            return
        from autograder.core.signing import sign

        tmp = self.path.with_suffix(".tmp")
        payload = json.dumps({"tests": list(self.tests.values()), "data": self.data},
                             default=str)
        tmp.write_text(sign(payload, self.key))
        tmp.replace(self.path)

    def keep_log(self, nodeid: str, text: str) -> None:
        """Keep a stopped program's output: its end in the report, the whole of it (as the
        sandbox kept it) in a file of its own that the report names with its digest, so
        the report, re-written after every test, stays small."""
        self.data["logs"][nodeid] = message_tail(text, LOG_TAIL_LINES, LOG_TAIL_BYTES)
        if self.path is not None and text:
            folder = log_folder(self.path)
            folder.mkdir(exist_ok=True)
            name = f"{len(self.data['log_files']) + 1:03d}.log"
            raw = text.encode("utf-8", "replace")
            (folder / name).write_bytes(raw)
            self.data["log_files"].append({"test": nodeid, "file": name, "bytes": len(raw),
                                           "sha256": digest(raw)})
        self.write()

    def note_process(self, pid: int, cgroups: list[str], bounds: dict[str, Any]) -> None:
        """Record a student process so the parent can reap it if this run is killed, and
        say which bounds held it."""
        self.data["processes"].append({"pid": pid, "cgroups": cgroups, "bounds": bounds})
        self.write()

    @pytest.hookimpl(trylast=True)
    def pytest_collection_modifyitems(self, items: list[pytest.Item]) -> None:
        if self.exercise:
            from autograder.core.exercise import find_exercise

            self.hidden_default = find_exercise(self.exercise).hidden_visibility
        for item in items:
            marker = item.get_closest_marker("points")
            visibility = _visibility(item, self.hidden_default)
            self.tests[item.nodeid] = {
                "nodeid": item.nodeid,
                "done": False,
                "name": item.name,
                "label": _label(item),
                "max_score": marker.args[0] if marker and marker.args else 1,
                "visibility": visibility,
                "reveal": _reveal(item, visibility),
                "status": "error",
                "message": _("Not run: the grading run ended before this test."),
                "hint": "",
                "details": "",
            }
        self.write()

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_makereport(self, item: pytest.Item,
                                  call: pytest.CallInfo[None]) -> Iterator[None]:
        outcome = yield
        report = outcome.get_result()
        entry = self.tests.get(item.nodeid)
        if entry is None:
            return
        shown = item.stash.get(evidence_key, None)
        if shown is not None and call.when == "call":
            entry["charts"] = shown.charts
        if call.when == "setup" or call.when == "call":
            given = item.stash.get(credit_key, None)
            if report.passed and call.when == "call" and given and given.fraction is not None \
                    and given.fraction < 1:
                entry.update(status="failed", fraction=given.fraction, message=given.message,
                             hint=given.hint)
            elif report.passed and call.when == "call":
                entry.update(status="passed", message="", hint="")
            elif report.skipped:
                entry.update(status="skipped", message=_skip_reason(report))
            elif report.failed:
                entry.update(_classify(call.excinfo))
        elif call.when == "teardown" and report.failed and entry["status"] == "passed":
            entry.update(_classify(call.excinfo))
        _bound(entry)

    def pytest_runtest_logfinish(self, nodeid: str) -> None:
        if nodeid in self.tests:
            self.tests[nodeid]["done"] = True
        self.write()


def _bound(entry: dict[str, Any]) -> None:
    """Cut what a test reports to a few KB: every results format repeats it per test."""
    for key, limit in (("message", MESSAGE_BYTES), ("hint", MESSAGE_BYTES),
                       ("details", DETAILS_BYTES)):
        if isinstance(entry.get(key), str):
            entry[key] = clip_middle(entry[key], limit)


def _skip_reason(report: pytest.TestReport) -> str:
    longrepr = report.longrepr
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2]).removeprefix("Skipped: ")
    return str(longrepr)


def _classify(excinfo: pytest.ExceptionInfo[BaseException] | None) -> dict[str, str]:
    """A failing test's status: the student's failure, or our error."""
    if excinfo is None:
        return {"status": "failed", "message": "", "hint": "", "details": ""}
    details = "".join(traceback.format_exception(excinfo.type, excinfo.value, excinfo.tb))
    error = excinfo.value
    if isinstance(error, StudentFailure):
        return {"status": "failed", "message": error.message, "hint": error.hint,
                "details": details}
    if isinstance(error, AssertionError):
        text = str(error).strip()
        return {"status": "failed", "message": text.split("\nassert")[0].strip() or
                _("A check failed."), "hint": "", "details": details}
    kind = "grader error" if isinstance(error, GraderError) else type(error).__name__
    return {"status": "error", "message": f"{kind}: {error}", "hint": "", "details": details}


# -- fixtures -------------------------------------------------------------------------------

class Credit:
    """Partial credit for the running test: ``credit.award(fraction, message)``.

    A test that awards less than 1 and returns normally is reported as failed with
    ``fraction`` of its points and the message; without an award, pass/fail decides.
    """

    def __init__(self) -> None:
        self.fraction: float | None = None
        self.message = ""
        self.hint = ""

    def award(self, fraction: float, message: str = "", hint: str = "") -> None:
        self.fraction = min(1.0, max(0.0, fraction))
        self.message, self.hint = message, hint


class Evidence:
    """Data a test attaches for the report's pictures (e.g. message intervals)."""

    def __init__(self) -> None:
        self.charts: list[dict[str, Any]] = []

    def intervals(self, title: str, times: list[float], limit: float | None = None) -> None:
        """Plot the gaps between messages over simulation time (``limit``: the allowed gap)."""
        points = [(round(b, 3), round(b - a, 4)) for a, b in itertools.pairwise(times)]
        self.charts.append({"kind": "intervals", "title": title, "points": points,
                            "limit": limit})


@pytest.fixture
def evidence(request: pytest.FixtureRequest) -> Evidence:
    """Attach data to this test's entry in the report (see :class:`Evidence`)."""
    given = Evidence()
    request.node.stash[evidence_key] = given
    return given


@pytest.fixture
def credit(request: pytest.FixtureRequest) -> Credit:
    """Give this test partial credit (see :class:`Credit`)."""
    given = Credit()
    request.node.stash[credit_key] = given
    return given


@pytest.fixture(scope="session")
def exercise(pytestconfig: pytest.Config) -> Any:
    """The exercise under test (from ``--exercise``)."""
    from autograder.core.exercise import find_exercise

    name = pytestconfig.getoption("exercise")
    if not name:
        pytest.skip("run with --exercise to use the autograder fixtures")
    return find_exercise(name)


@pytest.fixture(scope="session")
def submission_file(pytestconfig: pytest.Config, exercise: Any,
                    tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A private copy of the student's file (the reference solution when none is given)."""
    from autograder.core.submission import SubmissionNotFound, locate, stage

    given = pytestconfig.getoption("submission")
    try:
        source = locate(Path(given), exercise.file) if given else exercise.solution
    except SubmissionNotFound as exc:
        raise StudentFailure(str(exc)) from None
    return stage(source, exercise.file, tmp_path_factory.mktemp("submission"))


@pytest.fixture(scope="session")
def ros_context(pytestconfig: pytest.Config) -> Iterator[Any]:
    """An rclpy context on this run's own ROS domain, discovery limited to localhost."""
    import rclpy
    from rclpy.context import Context

    from autograder.sandbox.domains import reserve_domain
    from autograder.sandbox.isolation import bring_up_loopback

    if _strict():
        bring_up_loopback()  # the run's own network namespace starts with lo down
    else:
        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    given = pytestconfig.getoption("ros_domain")
    with reserve_domain(None) if given is None else contextlib.nullcontext(given) as domain:
        os.environ["ROS_DOMAIN_ID"] = str(domain)
        context = Context()
        rclpy.init(context=context, domain_id=domain)
        try:
            yield context
        finally:
            rclpy.try_shutdown(context=context)


def _strict() -> bool:
    """True inside a grading run in its own namespaces (see autograder.sandbox.isolation)."""
    return os.environ.get("AUTOGRADER_RUN_ISOLATION") == "strict"


@pytest.fixture(scope="module")
def world(request: pytest.FixtureRequest, exercise: Any, ros_context: Any) -> Iterator[Any]:
    """The simulated world, running, for this test module (``@pytest.mark.world`` picks it)."""
    from sim.bridge import SimBridge
    from sim.physics import World
    from sim.worldfile import load_world

    marker = request.node.get_closest_marker("world")
    name = marker.args[0] if marker and marker.args else exercise.world
    local = exercise.folder / name
    spec = load_world(local if local.suffix in (".yaml", ".yml") and local.exists() else name)
    rtf = request.config.getoption("real_time_factor")
    bridge = SimBridge(World(spec), ros_context, max_clock_hz=exercise.clock_hz,
                       cpu_budget=exercise.cpu_budget,
                       real_time_factor=exercise.real_time_factor if rtf is None else rtf)
    bridge.start()
    try:
        yield bridge
    finally:
        bridge.stop()
        reporter = request.config.stash.get(reporter_key, None)
        if reporter is not None:
            reporter.data["recordings"][request.node.name] = bridge.recording.to_dict()
            reporter.data.setdefault("pacing", {})[request.node.name] = {
                **bridge.pacing, "longest_hold": round(bridge.longest_hold, 3)}


@pytest.fixture(scope="module")
def probe(ros_context: Any, world: Any) -> Iterator[Any]:
    """The grader's own node on the graph: publish, subscribe, call, set parameters."""
    from autograder.plugin.probe import Probe

    node = Probe(ros_context, world)
    try:
        yield node
    finally:
        node.close()


# Sim seconds a freshly started node is watched for an immediate exit.
STARTUP_SETTLE = 1.0

# Topics only the world publishes, and names only the grader's nodes carry.
WORLD_TOPICS = ("/clock", "/odom", "/scan")
GRADER_NODES = ("autograder_probe", "sim_world")


def tampering(probe: Any) -> list[str]:
    """What on the graph impersonates the world or the grader, in plain words."""
    found = []
    for topic in WORLD_TOPICS:
        for info in probe.node.get_publishers_info_by_topic(topic):
            if info.node_name not in GRADER_NODES:
                found.append(_("node '{node}' publishes on {topic}, which the simulator "
                               "owns").format(node=info.node_name, topic=topic))
    names = [name for name, _ns in probe.node.get_node_names_and_namespaces()]
    for name in GRADER_NODES:
        if names.count(name) > 1:
            found.append(_("a second node is named '{name}', the grader's name").format(
                name=name))
    return found


@pytest.fixture(autouse=True)
def _graph_guard(request: pytest.FixtureRequest) -> Iterator[None]:
    """Fail any test during which the student tampered with the graph: not rewarded."""
    if "probe" not in request.fixturenames or not request.config.getoption("exercise"):
        yield
        return
    probe = request.getfixturevalue("probe")
    before = tampering(probe)
    yield
    seen = before + [t for t in tampering(probe) if t not in before]
    if seen:
        raise StudentFailure(
            _("Tampering with the simulated world: {what}. Tests run while it happens are "
              "not graded.").format(what="; ".join(seen)),
            _("Publish only on the topics the exercise names; the world owns /clock, /odom "
              "and /scan."))


class StudentNode:
    """The student's running program, seen from the graph."""

    def __init__(self, process: Any, name: str, probe: Any,
                 on_stop: Callable[[StudentNode], None] | None = None) -> None:
        self.process = process
        self.name = name
        self.probe = probe
        self.startup_seconds: float | None = None
        self.on_stop = on_stop

    @property
    def returncode(self) -> int | None:
        return self.process.returncode

    def running(self) -> bool:
        return self.process.running()

    def output(self) -> str:
        return self.process.output_text()

    def output_tail(self, lines: int = TAIL_LINES, max_bytes: int = TAIL_BYTES) -> str:
        """The end of the program's output, short enough for a test message (a few lines,
        a few KB), saying so when the program wrote more than the sandbox kept."""
        tail = message_tail(self.output(), lines, max_bytes)
        output = self.process.output
        note = size_note(output.total, output.budget) if output is not None else ""
        return "\n".join(part for part in (tail, note) if part)

    def wait_exit(self, wall_timeout: float) -> int | None:
        """Wait (wall time: exiting is the process's business) for it to end; its status."""
        return self.process.wait(wall_timeout)

    def send_signal(self, sig: int) -> None:
        """Signal the program's process group, as Ctrl-C in its terminal would."""
        self.process.signal(sig)

    def stop(self) -> int | None:
        status = self.process.stop()
        self.probe.world.unwatch_pid(self.process.pid)
        if self.process.uid is not None:  # strict: our own folder in /tmp, not the run's
            shutil.rmtree(self.process.workdir, ignore_errors=True)
        if self.on_stop is not None:  # once: a failed start stops it before the fixture does
            on_stop, self.on_stop = self.on_stop, None
            on_stop(self)
        return status


def _describe_exit(code: int) -> str:
    if code < 0:
        import signal

        try:
            return _("was killed by signal {name}").format(name=signal.Signals(-code).name)
        except ValueError:
            return _("was killed by signal {number}").format(number=-code)
    return _("exited with status {code}").format(code=code)


def launch(request: pytest.FixtureRequest, exercise: Any, script: Path, probe: Any,
           world: Any, params: dict[str, Any] | None = None,
           wait_for_node: bool = True) -> StudentNode:
    """Start the student's program with ``use_sim_time:=true`` and wait for its node."""
    from autograder.sandbox.process import student_process

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
    process = student_process(script, ros_args, exercise.limits,
                              domain=int(os.environ["ROS_DOMAIN_ID"]), strict=_strict(),
                              course=exercise.folder.parent.parent)
    # An earlier instance may still be on the graph: its name until its participant's
    # lease runs out, some of its endpoints too. Only publishers that were not there
    # before the start are this instance's.
    stale = _node_endpoints(probe, exercise.node) if wait_for_node else set()
    reporter = request.config.stash.get(reporter_key, None)
    if reporter is not None:
        process.on_spawn = lambda: reporter.note_process(
            process.pid, [str(p) for p in process.cgroup.paths],
            # RLIMIT_NPROC binds every user but root: a uid of the student's own, or an
            # ordinary grading user (where it counts that user's other processes too).
            process.cgroup.bounds(separate_uid=process.uid is not None or os.geteuid() != 0))
    process.start()
    world.watch_pid(process.pid)
    node = StudentNode(process, exercise.node, probe, _log_keeper(request))
    if wait_for_node:
        earlier = request.config.stash.get(startup_key, None)
        if earlier is not None:  # it already failed to appear once: do not wait again
            node.stop()
            raise StudentFailure(earlier.message, earlier.hint)
        try:
            _wait_for_node(exercise, node, world, stale)
        except NodeNeverAppeared as failure:
            request.config.stash[startup_key] = failure
            raise
        if reporter is not None:
            reporter.data.setdefault("startup_seconds", []).append(node.startup_seconds)
    return node




def _ros_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return value if value else "''"
    return repr(value)


class NodeNeverAppeared(StudentFailure):
    """The program ran, but its node never showed up on the graph (not a crash)."""


# Every rclpy node publishes on these (its log and its parameter events): the endpoints
# that tell one instance of a node from another of the same name.
NODE_TOPICS = ("/rosout", "/parameter_events")


def _node_endpoints(probe: Any, name: str) -> set[bytes]:
    """The GIDs of the publishers node ``name`` has on NODE_TOPICS, as the graph shows."""
    return {bytes(info.endpoint_gid) for topic in NODE_TOPICS
            for info in probe.node.get_publishers_info_by_topic(topic)
            if info.node_name == name}


def _wait_for_node(exercise: Any, node: StudentNode, world: Any, stale: set[bytes]) -> None:
    """Wait, with simulation time held, until this instance's node is on the graph: a
    start-up is then the same in simulation time however long the machine takes (imports,
    discovery), and the node's first tick is the next one."""
    deadline = time.monotonic() + exercise.startup_timeout
    found = False

    def ready() -> bool:
        nonlocal found
        # Not the name: an earlier instance's may linger after its endpoints are gone.
        found = bool(_node_endpoints(node.probe, exercise.node) - stale)
        return found or not node.running() or time.monotonic() > deadline

    with world.held():
        world.wait_for(ready, sim_timeout=float("inf"),
                       wall_timeout=exercise.startup_timeout + 1)
    if found:
        node.startup_seconds = time.monotonic() - node.process.started_at
        return
    if not node.running():
        raise _exited_at_start(node, exercise)
    tail = node.output_tail()  # before SIGINT: what it was doing, not how it stopped
    others = sorted(node.probe.node_names() - {"autograder_probe", "sim_world"})
    node.stop()
    raise NodeNeverAppeared(
        _("No node named '{node}' appeared on the ROS graph within {seconds:.0f} s "
          "(nodes seen: {others}).\nLast lines of its output:\n{tail}").format(
            node=exercise.node, seconds=exercise.startup_timeout,
            others=", ".join(others) or _("none"), tail=tail or _("(no output)")),
        _("Create the node with `super().__init__('{node}')` and spin it.").format(
            node=exercise.node))


def _exited_at_start(node: StudentNode, exercise: Any) -> StudentFailure:
    """A program that ended during its start-up, said the same way whether or not the graph
    showed its node first: that depends on how fast discovery was, not on the program (a
    node created and then crashing in its constructor can go either way). The hint follows
    the exit status, which does not race."""
    code = node.returncode
    node.stop()  # drains the pipe, so the tail ends with its last words
    message = _("Your program {how} during start-up, before its node '{node}' was up and "
                "spinning.\nLast lines of its output:\n{tail}").format(
        how=_describe_exit(code if code is not None else 0), node=exercise.node,
        tail=node.output_tail() or _("(no output)"))
    if code == 0:
        return StudentFailure(message, _("Call `rclpy.spin(node)` (or an executor's "
                                         "`spin()`) after creating the node, and keep "
                                         "spinning until the program is stopped."))
    return StudentFailure(message, _(
        "Run it yourself with `python {file} --ros-args -p use_sim_time:=true` and read the "
        "traceback.").format(file=exercise.file))


@pytest.fixture(scope="module")
def student(request: pytest.FixtureRequest, exercise: Any, submission_file: Path,
            probe: Any, world: Any) -> Iterator[StudentNode]:
    """The student's node, started once for this module with its default parameters (or
    those of the module's ``@pytest.mark.parameters({...})``)."""
    marker = request.node.get_closest_marker("parameters")
    node = launch(request, exercise, submission_file, probe, world,
                  marker.args[0] if marker and marker.args else None)
    # A program that creates its node and quits at once must fail the same way every time,
    # whether or not we saw the node in between: watch it for a moment of sim time.
    if probe.wait_for(lambda: not node.running(), STARTUP_SETTLE):
        raise _exited_at_start(node, exercise)
    try:
        yield node
    finally:
        node.stop()


@pytest.fixture
def start_node(request: pytest.FixtureRequest, exercise: Any, submission_file: Path,
               probe: Any, world: Any) -> Iterator[Callable[..., StudentNode]]:
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
