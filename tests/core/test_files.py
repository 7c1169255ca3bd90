"""Files a grading writes (autograder.core.files): replaced in one step, and a link planted
where one goes is replaced, never written through."""

from __future__ import annotations

from pathlib import Path

import pytest

from autograder.core.files import write_atomically


def test_the_file_is_replaced_whole(tmp_path: Path) -> None:
    path = tmp_path / "results.json"
    path.write_text("old")
    write_atomically(path, "new ✓")
    assert path.read_text(encoding="utf-8") == "new ✓"
    assert [p.name for p in tmp_path.iterdir()] == ["results.json"]  # no file left beside


def test_a_link_in_its_place_is_replaced_not_followed(tmp_path: Path) -> None:
    target = tmp_path / "someone_elses"
    target.write_text("theirs")
    path = tmp_path / "results.json"
    path.symlink_to(target)
    write_atomically(path, "ours")
    assert not path.is_symlink() and path.read_text() == "ours"
    assert target.read_text() == "theirs"


def test_a_failed_write_leaves_nothing_behind(tmp_path: Path) -> None:
    path = tmp_path / "results.json"
    with pytest.raises(UnicodeEncodeError):
        write_atomically(path, "\ud800")  # a lone surrogate: not UTF-8
    assert list(tmp_path.iterdir()) == []
