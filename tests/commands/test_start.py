"""``autograder start``: the starter code, the READMEs and the exercise's own world file
copied into the student's folder (the exercise id by default); a shipped world stays
where it is; a file already there is never overwritten."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from autograder.cli import main
from autograder.commands.start import start
from autograder.core.errors import UsageError

MINI = Path(__file__).resolve().parents[1] / "fixtures" / "mini_course"
WORLD = "size: [4, 4]\nstart: {x: 1, y: 1}\n"


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The mini course's shout exercise twice: on a shipped world, and on one of its own."""
    root = tmp_path / "course"
    shutil.copytree(MINI / "assignments" / "shout", root / "assignments" / "shout")
    # A file named as the shipped world it runs in (empty_room) is not a world file.
    (root / "assignments" / "shout" / "empty_room").write_text("a note\n")
    own = root / "assignments" / "walled"
    shutil.copytree(MINI / "assignments" / "shout", own)
    text = (own / "exercise.yaml").read_text().replace("id: shout", "id: walled")
    (own / "exercise.yaml").write_text(text + "world: walled_room.yaml\n")
    (own / "walled_room.yaml").write_text(WORLD)
    (own / "notes.yaml").write_text("not the world\n")
    monkeypatch.setenv("AUTOGRADER_COURSE", str(root))
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    return root


def test_the_starter_and_readmes_into_the_exercise_ids_folder(course: Path) -> None:
    found, target, copied = start("shout", None)
    assert found.id == "shout" and target == Path("shout")
    assert copied == [Path("shout/shouter.py"), Path("shout/README.md"),
                      Path("shout/README.ur.md")]
    folder = course / "assignments" / "shout"
    assert Path("shout/shouter.py").read_bytes() == (folder / "starter" / "shouter.py").read_bytes()
    assert Path("shout/README.ur.md").read_bytes() == (folder / "README.ur.md").read_bytes()


def test_a_world_of_its_own_goes_too(course: Path, tmp_path: Path) -> None:
    _found, target, copied = start("walled", tmp_path / "mine" / "deep")
    assert target == tmp_path / "mine" / "deep"  # made, parents and all
    assert sorted(p.name for p in copied) == ["README.md", "README.ur.md", "shouter.py",
                                              "walled_room.yaml"]
    assert (target / "walled_room.yaml").read_text() == WORLD
    assert not (target / "notes.yaml").exists()  # only the world the exercise names


def test_a_file_already_there_is_never_overwritten(course: Path) -> None:
    Path("shout").mkdir()
    Path("shout/README.md").write_text("my notes\n")
    with pytest.raises(UsageError, match="README.md already exists; not overwriting"):
        start("shout", None)
    assert Path("shout/README.md").read_text() == "my notes\n"


def test_the_command_says_what_it_created_and_what_next(course: Path) -> None:
    result = CliRunner().invoke(main, ["--lang", "en", "start", "shout", "mydir"])
    assert result.exit_code == 0, result.output
    assert result.output.splitlines() == [
        "created mydir/shouter.py", "created mydir/README.md", "created mydir/README.ur.md",
        "Next: edit mydir/shouter.py, then run `autograder check shout mydir/shouter.py`"]
    again = CliRunner().invoke(main, ["--lang", "en", "start", "shout", "mydir"])
    assert again.exit_code == 2 and "already exists" in again.output
    unknown = CliRunner().invoke(main, ["--lang", "en", "start", "shuot"])
    assert unknown.exit_code == 2 and "shuot" in unknown.output
