"""``autograder gradebook merge``: later rows win, and the count it prints is plural-aware."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from autograder.cli import main

HEADER = "student,item,score,max_score,passed\n"


def test_merge_counts_its_rows_in_the_right_number(tmp_path: Path) -> None:
    first = tmp_path / "a.csv"
    first.write_text(HEADER + "amna,timer_sync,10,14,yes\n")
    second = tmp_path / "b.csv"
    second.write_text(HEADER + "amna,timer_sync,12,14,yes\nbilal,timer_sync,3,14,no\n")
    one = CliRunner().invoke(main, ["gradebook", "merge", str(tmp_path / "one.csv"),
                                    str(first)])
    assert one.exit_code == 0 and one.output == f"1 row in {tmp_path / 'one.csv'}\n"
    both = CliRunner().invoke(main, ["gradebook", "merge", str(tmp_path / "both.csv"),
                                     str(first), str(second)])
    assert both.output == f"2 rows in {tmp_path / 'both.csv'}\n"
    assert "amna,timer_sync,12,14,yes" in (tmp_path / "both.csv").read_text()
