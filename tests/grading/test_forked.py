"""Child pytests forked from a warm template (autograder/grading/forked.py): each is the
child an exec'd ``python -m pytest`` would be (its descriptors at the numbers asked and
no other, its view of itself), its exit status reaches the grader however it ends, a
template that dies makes the grading the grader's failure, strict isolation gives each
child namespaces of its own, and the exec path stays where the template is off."""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
from collections.abc import Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from autograder.core.exercise import load_exercise
from autograder.core.report import RawReport, RawTest
from autograder.core.settings import RunSettings
from autograder.grading import children, forked
from autograder.grading.children import Child, bytecode_env, pytest_env
from autograder.grading.forked import ForkedChild, Template, TemplateGone
from autograder.grading.run import GRADER_FAULT, verdict
from autograder.sandbox.domains import hold_domain
from autograder.sandbox.isolation import Isolation

# Seconds for a child to start or end on a loaded machine.
WALL = 120.0
SHOUT = Path(__file__).parents[1] / "fixtures" / "mini_course" / "assignments" / "shout"

SELF = """\
import json, os, signal, sys

def test_self():
    fds = {}
    for fd in sorted(os.listdir("/proc/self/fd"), key=int):
        try:
            fds[fd] = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:
            fds[fd] = None  # the listing's own
    seen = {"argv": [os.path.basename(sys.argv[0]), *sys.argv[1:]], "cwd": os.getcwd(),
            "path0": sys.path[0], "env": os.environ.get("MARK"),
            "pycache": sys.pycache_prefix, "sid": os.getsid(0) == os.getpid(),
            "fds": fds, "stdin": os.readlink("/proc/self/fd/0"),
            "signals": {s.name: str(signal.getsignal(s)) for s in (
                signal.SIGINT, signal.SIGTERM, signal.SIGPIPE, signal.SIGCHLD,
                signal.SIGHUP, signal.SIGXFSZ, signal.SIGUSR1)}}
    with open(os.environ["OUT"], "w") as out:
        json.dump(seen, out)
"""


def child_env(**extra: str) -> dict[str, str]:
    """What the grader gives a child pytest, and ``extra``."""
    return {**pytest_env(bytecode_env(dict(os.environ))), **extra}


def pytest_args(test: Path) -> list[str]:
    return ["-q", "-s", "-p", "no:cacheprovider", str(test)]


@pytest.fixture(scope="module")
def warm() -> Iterator[Template]:
    """A template of this test module's own."""
    started = Template(child_env())
    yield started
    started.close()


def spawn(warm: Template, folder: Path, source: str, passed: Sequence[int] = (), *,
          namespaces: bool = False, **env: str) -> ForkedChild:
    """Fork a child pytest running the test module ``source`` in ``folder``."""
    test = folder / "test_it.py"
    test.write_text(source)
    with (folder / "pytest.log").open("wb") as log:
        return warm.spawn(pytest_args(test), str(folder), child_env(**env), log.fileno(),
                          passed, namespaces=namespaces)


def test_a_signal_the_grader_ignores_stays_ignored_in_a_forked_child(tmp_path: Path) -> None:
    """A grader a script started in the background ignores SIGINT, and an exec keeps an
    ignored signal: so does a child forked from a template that grader started (the CI
    run that found it: a forked child raised KeyboardInterrupt where an exec'd one could
    not)."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        template = Template(child_env())
    finally:
        signal.signal(signal.SIGINT, previous)
    try:
        out = tmp_path / "seen.json"
        assert spawn(template, tmp_path, SELF, MARK="m", OUT=str(out)).wait(WALL) == 0
        signals = json.loads(out.read_text())["signals"]
        assert signals["SIGINT"] == str(signal.SIG_IGN), signals
        assert signals["SIGTERM"] == str(signal.SIG_DFL), signals
    finally:
        template.close()


def test_a_forked_child_sees_itself_as_an_execd_one(warm: Template, tmp_path: Path) -> None:
    """The same test module forked and exec'd: the same descriptors (the passed ones at
    the numbers asked, on the same pipes, nothing of the template's), arguments, folder,
    module path, environment, bytecode cache, session, stdin and signal handlers."""
    read_end, write_end = os.pipe()
    passed = [os.dup(read_end), os.dup(write_end)]
    seen = {}
    try:
        for way in ("forked", "exec'd"):
            folder = tmp_path / way
            folder.mkdir()
            out = folder / "seen.json"
            if way == "forked":
                child = spawn(warm, folder, SELF, passed, MARK="m", OUT=str(out))
                assert child.wait(WALL) == 0
            else:
                (folder / "test_it.py").write_text(SELF)
                with (folder / "pytest.log").open("wb") as log:
                    execd = subprocess.Popen(
                        [sys.executable, "-m", "pytest", *pytest_args(folder / "test_it.py")],
                        cwd=folder, env=child_env(MARK="m", OUT=str(out)), stdout=log,
                        stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                        start_new_session=True, pass_fds=passed)
                assert execd.wait(WALL) == 0
            seen[way] = json.loads(out.read_text().replace(str(folder), "FOLDER"))
    finally:
        for fd in (read_end, write_end, *passed):
            os.close(fd)
    assert seen["forked"] == seen["exec'd"]
    fds = seen["forked"]["fds"]
    assert fds[str(passed[0])] == fds[str(passed[1])]  # both ends of one pipe
    assert seen["forked"]["sid"] and seen["forked"]["stdin"] == os.devnull
    assert seen["forked"]["argv"][0] == "__main__.py"


@pytest.mark.parametrize(("source", "code"), [
    ("def test_passes():\n    pass\n", 0),
    ("def test_fails():\n    assert False\n", 1),
    ("", 5),  # no tests collected
], ids=["passed", "failed", "no-tests"])
def test_the_exit_status_reaches_the_grader(warm: Template, tmp_path: Path, source: str,
                                            code: int) -> None:
    before = forked.forked_cpu_seconds()
    child = spawn(warm, tmp_path, source)
    assert child.wait(WALL) == code
    assert child.poll() == code and not child.lost and child.cpu_seconds > 0
    # A batch's CPU clock counts it, as it would count an exec'd child it waited for.
    assert forked.forked_cpu_seconds() - before >= child.cpu_seconds - 1e-6


def test_the_plugin_loads_warm_and_pytest_still_imports_it_itself(
        warm: Template, tmp_path: Path) -> None:
    """What the plugin imports is already loaded; its package module pytest imports for
    ``-p`` (and may rewrite: no warning that it was imported before)."""
    source = ("import sys\n"
              "def test_warm():\n"
              "    assert 'sim.bridge' in sys.modules and 'autograder.plugin' in sys.modules\n")
    test = tmp_path / "test_it.py"
    test.write_text(source)
    with (tmp_path / "pytest.log").open("wb") as log:
        child = warm.spawn(["-q", "-p", "no:cacheprovider", "-p", "autograder.plugin",
                            "-W", "error::pytest.PytestAssertRewriteWarning", str(test)],
                           str(tmp_path), child_env(), log.fileno(), [])
    assert child.wait(WALL) == 0, (tmp_path / "pytest.log").read_text()


def test_threads_ask_one_template_at_once(warm: Template, tmp_path: Path) -> None:
    """``grade-batch`` grades in threads that share the template: each gets its own child
    and its own status."""
    sources = {f"t{i}": f"def test_it():\n    assert {i} % 2 == 0\n" for i in range(4)}

    def run(name: str) -> int:
        folder = tmp_path / name
        folder.mkdir()
        return spawn(warm, folder, sources[name]).wait(WALL)

    with ThreadPoolExecutor(max_workers=4) as pool:
        assert list(pool.map(run, sources)) == [0, 1, 0, 1]


def test_a_child_killed_by_sigkill_says_so(warm: Template, tmp_path: Path) -> None:
    child = spawn(warm, tmp_path, "import time\ndef test_waits():\n    time.sleep(300)\n")
    assert child.poll() is None
    with pytest.raises(subprocess.TimeoutExpired):
        child.wait(0.1)
    os.killpg(child.pid, signal.SIGKILL)  # its own session: its group is itself
    assert child.wait(WALL) == -signal.SIGKILL and not child.lost


def test_a_template_that_dies_mid_run_is_the_graders_failure(tmp_path: Path) -> None:
    """The child outlives its template, so no status comes: once the child is gone it
    reads as lost, and the grading calls that its own failure, not the student's zero."""
    dying = Template(child_env())
    try:
        child = spawn(dying, tmp_path, "import time\ndef test_waits():\n    time.sleep(300)\n")
        dying.process.kill()
        dying.process.wait()
        assert not dying.alive
        assert child.poll() is None  # still running, now an orphan
        os.killpg(child.pid, signal.SIGKILL)
        assert child.wait(WALL) == -signal.SIGKILL and child.lost
        with pytest.raises(TemplateGone):
            spawn(dying, tmp_path, "")
    finally:
        dying.close()
    record = Child(child, tmp_path / "report.json", b"k" * 32, tmp_path / "pytest.log", 0.0)
    ended = children.end(record)
    assert ended.returncode is None and ended.broken
    assert "how it ended is unknown" in ended.pytest_log
    # Even where its report shows every test passed: the grader's failure, not a grade.
    passed = RawTest(nodeid="tests/public/test_p.py::p", name="p", label="p", max_score=1,
                     visibility="visible", reveal="message", done=True, status="passed")
    ended = dataclasses.replace(ended, raw=RawReport(tests=[passed]))
    result = verdict(load_exercise(SHOUT), ended.raw, [ended], 1.0)
    assert result.grader_error == GRADER_FAULT and "unknown" in result.grader_details


def test_a_template_that_cannot_start_is_said_so(tmp_path: Path) -> None:
    with pytest.raises(TemplateGone):
        Template(child_env(PYTHONHOME=str(tmp_path / "nothing")))


def test_a_child_with_another_start_up_is_not_forked(warm: Template) -> None:
    """Variables Python reads as it starts must be those the template started with."""
    assert warm.fits(child_env())
    assert not warm.fits(child_env(PYTHONHASHSEED="7"))
    assert warm.fits(child_env(PYTHONDONTWRITEBYTECODE="1", MARK="any"))


@pytest.mark.skipif(os.geteuid() != 0, reason="strict isolation needs root")
def test_children_in_strict_isolation_have_namespaces_of_their_own(
        warm: Template, tmp_path: Path) -> None:
    """Two children at once: neither shares the other's network namespace (a student
    must not reach another grading's domain) nor the grader's, nor its mounts."""
    hold_read, hold_write = os.pipe()
    waits = "import os\ndef test_waits():\n    os.read(int(os.environ['HOLD']), 1)\n"
    forked = []
    try:
        for index in range(2):
            folder = tmp_path / str(index)
            folder.mkdir()
            try:
                forked.append(spawn(warm, folder, waits, [hold_read], namespaces=True,
                                    HOLD=str(hold_read)))
            except TemplateGone as exc:  # a container that refuses namespaces
                pytest.skip(f"no namespaces here: {exc}")
        nets = [os.readlink(f"/proc/{c.pid}/ns/net") for c in forked]
        mounts = [os.readlink(f"/proc/{c.pid}/ns/mnt") for c in forked]
        assert len({*nets, os.readlink("/proc/self/ns/net")}) == 3
        assert os.readlink("/proc/self/ns/mnt") not in mounts
    finally:
        os.close(hold_write)
        os.close(hold_read)
    assert [c.wait(WALL) for c in forked] == [0, 0]


@pytest.mark.parametrize("switch,mode,forks", [("1", "user", True), ("0", "user", False),
                                                ("1", "basic", False)],
                         ids=["forked", "execd", "basic-execd"])
def test_a_grading_forks_its_children_unless_the_template_is_off(
        switch: str, mode: str, forks: bool, monkeypatch: pytest.MonkeyPatch,
        tmp_path: Path) -> None:
    """The grading's own start of a child: forked from this process's template, or with
    ``AUTOGRADER_CHILD_TEMPLATE=0`` exec'd as before, and exec'd in basic isolation (where
    the student's program could stop the template); either way the child loads the
    plugin, reads its settings and says the same (here: no such exercise)."""
    monkeypatch.setenv(forked.SWITCH, switch)
    assert (forked.shared(child_env()) is None) == (switch == "0")
    test = tmp_path / "tests" / "test_it.py"
    test.parent.mkdir()
    test.write_text("def test_passes():\n    pass\n")
    settings = RunSettings(exercise=str(tmp_path))
    with hold_domain() as lock, children.started(
            Isolation(mode), settings, [str(test)], tmp_path / "child", tmp_path,
            lock) as child:
        kind = ForkedChild if forks else subprocess.Popen
        assert isinstance(child.process, kind)
        assert child.process.wait(WALL) == 3  # pytest's internal error: the plugin's
        assert "No exercise named" in child.log_path.read_text()
