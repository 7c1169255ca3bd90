"""The student release's READMEs (English and Urdu) hold commands that work inside the
release, run as pasted from a fresh copy of it, and none needs a solution or a key
(issue 35). The release offers the quizzes as the pages in quizzes-rendered/.

`python3 tasks.py setup`, the set-up, is not run here: it would reinstall the venv these
tests run in. CI's `.ci/deployments` runs it, with the exercise block, from a fresh release
in an ordinary user's home (`test_ci_runs_the_release_setup_as_pasted` holds it to that);
that the release's tasks.py installs no test tools is checked in tests/project/test_tasks.py."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from pasted import Terminal, blocks, terminal_in

from autograder.commands.release import build_release

SETUP = "python3 tasks.py setup"


@pytest.fixture(scope="module")
def release(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_release(tmp_path_factory.mktemp("r") / "release")


@pytest.fixture
def terminal(release: Path) -> Iterator[Terminal]:
    import shutil

    with terminal_in(lambda folder: shutil.copytree(release, folder), skip=(SETUP,)) as t:
        yield t


@pytest.mark.parametrize("name", ["README.md", "README.ur.md"])
def test_the_readme_is_the_students_and_needs_no_solution(release: Path, name: str) -> None:
    text = (release / name).read_text(encoding="utf-8")
    found = blocks(text)
    assert [found[0][0], found[1][0]] == [SETUP, "autograder list"]
    every = [c for block in found for c in block]
    assert not any(word in c for c in every for word in ("solution", "quiz take",
                                                         "quiz score", "tasks.py demo",
                                                         "tasks.py test"))
    # Every path the README names is in the release.
    for path in re.findall(r"`(quizzes-rendered/[^`]+)`", text):
        assert (release / path).is_file(), path
    assert re.search(r'^\s*"setup": \[\]', (release / "tasks.py").read_text(), re.M)
    if name == "README.ur.md":
        assert text.startswith('<div dir="rtl" lang="ur">\n\n') and "</div>" in text


def test_the_english_readme_lists_and_starts_as_pasted(release: Path,
                                                       terminal: Terminal) -> None:
    setup, exercise = blocks((release / "README.md").read_text(encoding="utf-8"))[:2]
    out = terminal.run(setup + exercise[:2])
    assert "parameter_validation" in out
    assert (terminal.folder / "mywork" / "velocity_governor.py").is_file()


@pytest.mark.slow
@pytest.mark.parametrize("name", ["README.md", "README.ur.md"])
def test_the_readme_checks_a_starter_as_pasted(release: Path, terminal: Terminal,
                                               name: str) -> None:
    setup, exercise = blocks((release / name).read_text(encoding="utf-8"))[:2]
    out = terminal.run(setup + exercise)
    assert "mywork/velocity_governor.py" in out
    if name == "README.ur.md":
        assert (terminal.folder / "report.html").is_file()


def test_the_urdu_readme_follows_the_glossary(release: Path) -> None:
    from autograder.i18n.glossary import load_glossary

    glossary = load_glossary(release / "locales" / "ur" / "glossary.yaml")
    assert [str(p) for p in glossary.check_readme(release / "README.ur.md")] == []


def test_ci_runs_the_release_setup_as_pasted() -> None:
    """`.ci/deployments` builds a release, and pastes its README's first two blocks (the
    set-up and the exercise) as an ordinary user, not a copy of them of its own."""
    script = (Path(__file__).resolve().parents[2] / ".ci" / "deployments").read_text()
    body = script.split("release_check() {", 1)[1].split("\n}\n", 1)[0]
    assert "autograder\" release" in body
    assert '"$dir/README.md"' in body and "[:2]" in body
    assert "runuser -u agstudent1" in body
    assert "release_check || failures" in script
    assert not [line for line in body.splitlines() if SETUP in line]
