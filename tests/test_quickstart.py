"""The student quickstart runs as pasted (issue 35): each of its shell blocks, from a fresh
clone of the course, in a terminal of its own, as an ordinary user where the machine lets
the test make one. The README's quickstart is the same commands as the docs page's.

The set-up block (`python3 tasks.py demo`, then the activation) would reinstall the venv
these tests run in, so here the clone's `.venv` is a link to that venv and only the
activation runs; CI's `.ci/deployments` runs the set-up block as this page prints it, from
fresh clones, as root and as two ordinary users (`test_ci_runs_the_setup_block_as_pasted`
holds it to that)."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from pasted import Terminal, blocks, terminal_in

ROOT = Path(__file__).resolve().parent.parent
PAGE = ROOT / "docs" / "students" / "quickstart.md"
SETUP = "python3 tasks.py demo"


def quickstart() -> dict[str, list[str]]:
    """The page's blocks by what they do: set-up, exercise, the two terminals, the quiz."""
    found = blocks(PAGE.read_text(encoding="utf-8"))
    assert len(found) == 5, found
    return dict(zip(("setup", "exercise", "world", "drive", "quiz"), found, strict=True))


def test_the_readme_quickstart_is_the_docs_quickstart() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Student quickstart", 1)[1].split("\n## ", 1)[0]
    assert blocks(section) == list(quickstart().values())


def test_the_quickstart_shows_what_the_issue_asks() -> None:
    text = " ; ".join(" ; ".join(b) for b in quickstart().values())
    for needed in (SETUP, ". .venv/bin/activate", "autograder list", "autograder start",
                   "autograder check", "--html", "autograder sim run --node",
                   "autograder sim drive", "--record", "autograder quiz take",
                   "autograder quiz score"):
        assert needed in text, needed


# Words a newcomer reads before the command that grades the starter: 5 minutes at 200
# words a minute, a slow pace for technical text (code blocks count as words too).
READING_BUDGET_WORDS = 5 * 200


def _words_before_grading(text: str) -> int:
    before = text.split("autograder grade parameter_validation mywork", 1)
    assert len(before) == 2, "the page never shows the command that grades the starter"
    return len(before[0].split())


@pytest.mark.parametrize("page", ["README.md", "docs/ur/students/quickstart.md"])
def test_a_newcomer_reaches_a_graded_starter_in_five_minutes_of_reading(page: str) -> None:
    """Issue 35: from the top of the README (or the Urdu quickstart, where the README's
    first link sends Urdu readers), the words before `autograder grade ... mywork`."""
    words = _words_before_grading((ROOT / page).read_text(encoding="utf-8"))
    assert words <= READING_BUDGET_WORDS, f"{page}: {words} words before the grading command"


def test_ci_runs_the_setup_block_as_pasted() -> None:
    """The set-up block is not run here (see the module's docstring): `.ci/deployments`
    takes it from this page, not from a copy of its own, and runs it whole in each clone."""
    script = (ROOT / ".ci" / "deployments").read_text(encoding="utf-8")
    assert "docs/students/quickstart.md" in script
    runs = [line for line in script.splitlines()
            if "tasks.py demo" in line and not line.lstrip().startswith("#")]
    assert runs == [], f".ci/deployments runs its own copy of the set-up: {runs}"


def _clone(folder: Path) -> None:
    subprocess.run(["git", "clone", "-q", "--depth", "1", f"file://{ROOT}", str(folder)],
                   check=True)


@pytest.fixture
def terminal() -> Iterator[Terminal]:
    with terminal_in(_clone, skip=(SETUP,)) as student:
        yield student


def test_list_start_and_a_quiz_as_pasted(terminal: Terminal) -> None:
    """The set-up block (its activation), then list and start, then the quiz block,
    answering nothing (Enter on every question)."""
    steps = quickstart()
    exercise = steps["exercise"]
    out = terminal.run(steps["setup"] + [c for c in exercise
                                          if c.split()[:2] in (["autograder", "list"],
                                                               ["autograder", "start"])])
    assert "parameter_validation" in out and "rclpy-part2" in out
    assert (terminal.folder / "mywork" / "velocity_governor.py").is_file()
    out = terminal.run(steps["setup"] + steps["quiz"], stdin="\n" * 100)
    assert "Passing score" in out
    assert (terminal.folder / "answers.json").is_file()
    assert (terminal.folder / "quiz.html").is_file()


@pytest.mark.slow
def test_start_check_and_grade_as_pasted(terminal: Terminal) -> None:
    """The exercise block whole: the starter is checked and graded, with a report and
    bags, and both commands exit 0 whatever the score."""
    steps = quickstart()
    out = terminal.run(steps["setup"] + steps["exercise"])
    assert "Public tests:" in out
    assert (terminal.folder / "report.html").is_file()
    assert any((terminal.folder / "bags").glob("*/metadata.yaml"))


@pytest.mark.slow
def test_watching_by_hand_as_pasted(terminal: Terminal) -> None:
    """Terminal 1 runs the world with the starter as its node; once the node is up,
    terminal 2 (a new terminal: it activates the venv again) drives it; terminal 1 then
    ends by itself after its --duration, with a picture of the path."""
    steps = quickstart()
    terminal.run(steps["setup"] + [c for c in steps["exercise"] if " start " in f" {c} "])
    world = terminal.start(steps["setup"] + steps["world"])
    seen: list[str] = []
    try:
        deadline = time.monotonic() + 120
        assert world.stdout is not None
        while time.monotonic() < deadline:
            line = world.stdout.readline()
            seen.append(line)
            if not line or "simulation time starts now" in line:
                break
        assert "simulation time starts now" in seen[-1], "".join(seen)
        out = terminal.run(steps["drive"], timeout=120)
        rest, _ = world.communicate(timeout=120)
    finally:
        if world.poll() is None:
            world.kill()
            world.wait()
    assert world.returncode == 0, "".join(seen) + rest
    assert "Sim time: 20.00 s" in rest, rest
    assert (terminal.folder / "path.svg").is_file()
    assert out is not None
