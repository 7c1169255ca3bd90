"""Fixtures shared by the project's tests, and the collection of the exercises' proofs."""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path

import pytest
from proving import STANDARD_CHECKS, Proof
from student_runs import StudentRuns

from autograder.core.results import RunResult
from autograder.sandbox.domains import reserve_domain

# pytester runs pytest in pytest: the grading plugin's reporter is tested that way.
pytest_plugins = ["pytester"]


@pytest.fixture
def in_quiz_course(monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """The frozen quiz course (tests/quiz_course.py) is the course: commands that find
    quizzes by id find its, and pages are translated with its content catalog."""
    from quiz_course import QUIZ_COURSE

    from autograder.i18n import translations

    monkeypatch.setenv("AUTOGRADER_COURSE", str(QUIZ_COURSE))
    translations.cache_clear()
    yield QUIZ_COURSE
    translations.cache_clear()


@pytest.fixture(scope="module")
def ros_domain() -> Iterator[int]:
    """A ROS domain id reserved for this module (the same lock files the grader uses)."""
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    with reserve_domain() as domain:
        yield domain


@pytest.fixture(scope="session")
def student_runs(tmp_path_factory: pytest.TempPathFactory) -> Iterator[StudentRuns]:
    """``check`` and ``grade`` as a student runs them, each once for every module that
    reads it (tests/student_runs.py)."""
    runs = StudentRuns(tmp_path_factory.mktemp("student-runs"))
    yield runs
    runs.close()


@contextlib.contextmanager
def modes_kept(paths: Iterable[Path]) -> Iterator[None]:
    """Put back the modes of ``paths`` afterwards: isolation by user closes the course's
    folders to other users at each grading, and this checkout is one of them."""
    kept = {path: path.stat().st_mode for path in paths if path.exists()}
    try:
        yield
    finally:
        for path, mode in kept.items():
            path.chmod(mode)


# -- the exercises' proofs (tests/proving.py) ------------------------------------------------

class ProofModule(pytest.Module):
    """A test module that declares ``PROOF``: its own checks, and the standard ones."""

    def collect(self) -> Iterable[pytest.Item | pytest.Collector]:
        namespace = vars(self.obj)
        if isinstance(namespace.get("PROOF"), Proof):
            for check in STANDARD_CHECKS:
                if namespace.setdefault(check.__name__, check) is not check:
                    raise pytest.UsageError(f"{self.path}: {check.__name__} is a standard "
                                            "proof check (tests/proving.py): rename yours")
        return super().collect()


SANDBOX = Path(__file__).parent / "sandbox"


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The sandbox's slow tests are ``machine_wide``: they grade hostile programs and look
    at the whole machine afterwards (every student user's processes, ``/tmp``, the network
    beyond loopback), which another file's gradings at the same time would disturb, so the
    slow tier runs them alone (``tasks.py test-all``)."""
    for item in items:
        if item.get_closest_marker("slow") and SANDBOX in item.path.parents:
            item.add_marker(pytest.mark.machine_wide)


def pytest_pycollect_makemodule(module_path: Path, parent: pytest.Collector) -> pytest.Module:
    return ProofModule.from_parent(parent, path=module_path)


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """Parametrize the standard checks from the submission folders of the module's PROOF."""
    proof = getattr(metafunc.module, "PROOF", None)
    if not isinstance(proof, Proof):
        return
    if "correct" in metafunc.fixturenames:
        metafunc.parametrize("correct", proof.named("correct"))
    if "known_bad" in metafunc.fixturenames:
        metafunc.parametrize("known_bad", proof.named("mutant", "broken"))


@pytest.fixture(scope="module")
def proof(request: pytest.FixtureRequest) -> Proof:
    """The module's PROOF (tests/proving.py)."""
    return request.module.PROOF


@pytest.fixture(scope="module")
def graded(proof: Proof, tmp_path_factory: pytest.TempPathFactory) -> dict[str, RunResult]:
    """Every submission of the module's PROOF, graded once for all its checks."""
    return proof.grade_all(tmp_path_factory.mktemp("submissions"))


def pytest_sessionfinish(session: pytest.Session) -> None:
    """Close the Chromium that the browser tests share (tests/browser.py), if they ran."""
    browser = sys.modules.get("browser")
    if browser is not None:
        browser.close_browser()
