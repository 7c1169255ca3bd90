"""--jobs auto: the concurrency chosen from the machine and the gradings' CPU share, the
cgroup files it reads, and the batch grading its first student alone, then choosing again
as each grading ends."""

from __future__ import annotations

import dataclasses
import json
import threading
from fractions import Fraction
from pathlib import Path

import pytest
from click.testing import CliRunner

from autograder.cli import main
from autograder.commands.batch import run_batch
from autograder.core.results import ModulePacing, RunResult, TestResult
from autograder.grading import capacity
from autograder.grading.capacity import (
    AutoChooser,
    Choice,
    Tally,
    choose_jobs,
    decide,
    describe,
    max_jobs,
    starved,
)

MACHINE = {"cores": 2.0, "memory_mb": 8000.0, "grading_mb": 400.0}


@pytest.mark.parametrize(("share", "students", "memory", "jobs", "bound"), [
    (1.2, 20, 8000.0, 3, "cpu"),        # more than a core: fewer than two a core
    (1.0, 20, 8000.0, 4, "cpu"),        # CPU-bound: two a core at most
    (1.5, 20, 8000.0, 2, "cpu"),
    (0.2, 3, 8000.0, 3, "students"),    # no more than there are students
    (0.2, 20, 1000.0, 2, "memory"),     # 1000 MB at 400 MB each
    (0.01, 20, 8000.0, 4, "ceiling"),   # a grading that hardly computes: two a core
    (5.0, 20, 100.0, 1, "cpu"),         # nothing fits: still one
    (0.01, 20, float("inf"), 4, "ceiling"),  # free memory unknown: not a bound
], ids=["over-a-core", "cpu-bound", "core-and-a-half", "few-students", "low-memory", "ceiling",
        "never-zero", "memory-unknown"])
def test_choose_jobs(share, students, memory, jobs, bound) -> None:
    choice = choose_jobs(**{**MACHINE, "memory_mb": memory}, cpu_share=share,
                         students=students)
    assert (choice.jobs, choice.bound) == (jobs, bound)


@pytest.mark.parametrize(("cores", "most"), [(2.0, 4), (4.0, 8), (1.5, 3), (0.4, 1)])
def test_the_ceiling_is_two_gradings_a_core(cores, most) -> None:
    """Eight at once on 2 cores lost a correct node's test now and then; four did not."""
    assert max_jobs(cores) == most
    assert choose_jobs(cores=cores, memory_mb=8000.0, cpu_share=0.01, grading_mb=1.0,
                       students=100).jobs == most


def test_a_first_grading_that_only_hangs_is_not_believed_to_cost_nothing() -> None:
    choice = choose_jobs(cores=2, memory_mb=1e6, grading_mb=400, cpu_share=0.0,
                         students=100, ceiling=100)
    assert choice.cpu_share == capacity.MIN_SHARE and choice.jobs == 26


@pytest.mark.parametrize("bound", ["cpu", "memory", "students", "ceiling", "strained"])
def test_describe_says_the_number_and_why(bound) -> None:
    line = describe(Choice(3, bound, 2.0, 0.25, 1200.0, 400.0))
    assert line.startswith("--jobs auto: 3 gradings at a time.")
    assert {"cpu": "0.25 of a core as measured so far, on 2 cores",
            "memory": "1200 MB free", "students": "Every student", "ceiling": "At most 3",
            "strained": "At most 3: with more at once"}[bound] in line
    assert "grading at a time." in describe(Choice(1, "cpu", 2.0, 1.0, 1200.0, 400.0))


def _write(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text + "\n")
    return root


@pytest.mark.parametrize(("files", "cpus"), [
    ({"cpu.max": "150000 100000"}, 1.5),
    ({"cpu.max": "max 100000"}, None),
    ({"cpu/cpu.cfs_quota_us": "50000", "cpu/cpu.cfs_period_us": "100000"}, 0.5),
    ({"cpu/cpu.cfs_quota_us": "-1", "cpu/cpu.cfs_period_us": "100000"}, None),
    ({}, None),
], ids=["v2", "v2-unlimited", "v1", "v1-unlimited", "none"])
def test_cgroup_cpu_quota(tmp_path, files, cpus) -> None:
    assert capacity.cgroup_cpus(_write(tmp_path, files)) == cpus


@pytest.mark.parametrize(("files", "free"), [
    ({"memory.max": str(2 << 30), "memory.current": str(1 << 30)}, 1024.0),
    ({"memory.max": "max", "memory.current": "5"}, None),
    ({"memory/memory.limit_in_bytes": str(3 << 30),
      "memory/memory.usage_in_bytes": str(1 << 30)}, 2048.0),
    ({"memory/memory.limit_in_bytes": str(1 << 62),
      "memory/memory.usage_in_bytes": "5"}, None),
], ids=["v2", "v2-unlimited", "v1", "v1-unlimited"])
def test_cgroup_free_memory(tmp_path, files, free) -> None:
    assert capacity.cgroup_free_mb(_write(tmp_path, files)) == free


def test_machine_cores_takes_the_lesser_of_affinity_and_quota(tmp_path) -> None:
    assert capacity.machine_cores(_write(tmp_path, {"cpu.max": "50000 100000"})) == 0.5
    assert capacity.machine_cores(tmp_path / "none") >= 1


def test_available_memory_from_meminfo(tmp_path) -> None:
    meminfo = _write(tmp_path, {"meminfo": "MemTotal: 100 kB\nMemAvailable:    2048 kB"})
    assert capacity.available_mb(meminfo / "meminfo") == 2.0
    assert capacity.available_mb(tmp_path / "missing") is None


def _result(score: int) -> RunResult:
    test = TestResult(name="t", label="t", score=Fraction(score), max_score=Fraction(3),
                      status="passed" if score == 3 else "failed")
    return RunResult(kind="exercise", id="ex", title="Ex", tests=(test,))


def test_a_tally_shares_the_mean_cpu_over_the_first_wall() -> None:
    tally = Tally().add(wall=10.0, cpu_seconds=4.0, footprint_mb=200.0, strained=False,
                        at_once=1)
    assert (tally.cpu_share, tally.grading_mb()) == (0.4, 200.0 * capacity.MEMORY_MARGIN)
    # Later gradings ran beside others: their stretched walls are not the measure.
    tally = tally.add(wall=30.0, cpu_seconds=2.0, footprint_mb=260.0, strained=False,
                      at_once=4)
    assert (tally.graded, tally.first_wall, tally.cpu_share) == (2, 10.0, 0.3)
    assert tally.grading_mb() == 260.0 * capacity.MEMORY_MARGIN
    assert Tally().grading_mb() == capacity.GRADING_MB  # nothing measured yet


def test_a_starved_student_caps_the_concurrency_below_where_it_happened() -> None:
    tally = Tally().add(wall=10.0, cpu_seconds=0.5, footprint_mb=None, strained=False,
                        at_once=1)
    machine = {"cores": 4.0, "memory_mb": 8000.0, "students": 50}
    assert decide(tally, **machine).bound == "ceiling"
    tally = tally.add(wall=12.0, cpu_seconds=0.5, footprint_mb=None, strained=True,
                      at_once=5)
    assert (decide(tally, **machine).jobs, decide(tally, **machine).bound) == (4, "strained")
    tally = tally.add(wall=12.0, cpu_seconds=0.5, footprint_mb=None, strained=True,
                      at_once=7)  # seen higher too: the lower stays the bound
    assert decide(tally, **machine).jobs == 4
    once = Tally().add(wall=1.0, cpu_seconds=0.1, footprint_mb=None, strained=True,
                       at_once=1)
    assert decide(once, **machine).jobs == 1  # never fewer than one


@pytest.mark.parametrize(("pacing", "expected"), [
    ({}, False), ({"test_a": {"idle": 40, "budget": 2, "cap": 0}}, False),
    ({"test_a": {"idle": 40}, "test_b": {"idle": 9, "cap": 1}}, True)],
    ids=["no-world", "held-within-budget", "cap-hit"])
def test_starved_reads_the_pacing_cap(pacing, expected) -> None:
    typed = {module: ModulePacing.from_dict(counts) for module, counts in pacing.items()}
    assert starved(dataclasses.replace(_result(3), pacing=typed)) is expected


def test_the_chooser_decides_again_and_says_so_only_when_the_number_changes() -> None:
    cpu = iter([0.0, 16.0, 17.0, 24.0, 26.0])  # the batch's CPU at the start and each end
    said: list[str] = []
    chooser = AutoChooser(said.append, cores=lambda: 4.0, memory_mb=lambda: 8000.0,
                          cpu=lambda: next(cpu))
    plain, starving = _result(3), dataclasses.replace(
        _result(3), pacing={"m": ModulePacing.from_dict({"cap": 2})})
    assert chooser(10.0, plain, 1, 10) == 5  # 1.6 cores: 4 cores x 2.0 / 1.6
    assert chooser(20.0, plain, 5, 9) == 8  # a mean of 8.5 s over the first 10 s: the ceiling
    assert chooser(25.0, plain, 8, 8) == 8  # 0.8: still the ceiling, nothing said
    assert chooser(25.0, starving, 7, 7) == 6  # starved at 7
    assert [line.split(".")[0] for line in said] == [
        "--jobs auto: 5 gradings at a time", "--jobs auto: 8 gradings at a time",
        "--jobs auto: 6 gradings at a time"]
    assert "longer than the world holds its clock" in said[-1]


def test_the_chooser_deals_the_cpu_among_the_gradings_that_ran_by_their_time() -> None:
    """The batch's CPU grows as gradings' processes end, whichever grading they were part
    of: what grew since the last reading is dealt among the gradings that ran meanwhile,
    by how long each ran then, so the first to end among five is not charged for all."""
    now, cpu = [0.0], [0.0]
    chooser = AutoChooser(cores=lambda: 2.0, memory_mb=lambda: 8000.0,
                          cpu=lambda: cpu[0], clock=lambda: now[0])
    plain = _result(3)
    chooser.started()                   # the first, alone: 5 CPU-s in 10 s
    now[0], cpu[0] = 10.0, 5.0
    assert chooser(10.0, plain, 1, 9) == 4  # 0.5 of a core: the ceiling, 2 a core
    for _ in range(4):
        chooser.started()               # four at once from t=10
    now[0], cpu[0] = 15.0, 15.0         # 10 CPU-s more: the four ran 5 s each
    chooser.started()                   # a fifth from t=15
    now[0], cpu[0] = 20.0, 30.0         # 15 more: the five ran 5 s each
    assert chooser(10.0, plain, 5, 8) == 4
    assert chooser.tally.cpu_seconds == pytest.approx(5.0 + 10.0 / 4 + 15.0 / 5)
    assert chooser.tally.cpu_share == pytest.approx((5.0 + 5.5) / 2 / 10)
    now[0], cpu[0] = 22.0, 38.0         # 8 more: the four left ran 2 s each
    assert chooser(7.0, plain, 4, 7) == 4  # the fifth (7 s ago): 3 + 2
    assert chooser.tally.cpu_seconds == pytest.approx(10.5 + 15.0 / 5 + 8.0 / 4)
    # Counted as the old way, the second grading's CPU would be the 25 CPU-s that grew
    # while it ran: a share of 1.5, and 2 at once instead of 4.


def test_auto_grades_the_first_alone_then_chooses_as_each_ends(tmp_path) -> None:
    entries = {f"s{i}": tmp_path / f"s{i}" for i in range(5)}
    asked = []
    running, most = [0], [0]
    lock = threading.Lock()
    together = threading.Barrier(2, timeout=60)  # the last two must run at once

    def grade_one(path: Path) -> RunResult:
        with lock:
            running[0] += 1
            most[0] = max(most[0], running[0])
        if path.name in ("s3", "s4"):
            together.wait()
        with lock:
            running[0] -= 1
        return _result(3)

    def chooser(wall: float, result: RunResult, at_once: int, left: int) -> int:
        asked.append((at_once, left, len(list((tmp_path / "out").iterdir()))))
        return 1 if left > 2 else 3

    rows = run_batch(entries, grade_one, tmp_path / "out", tmp_path / "book.csv",
                     jobs=chooser)
    # One at a time while the chooser said 1 (the first alone), asked after each; then
    # both left at once (3 asked, 2 left), and no more asking with none waiting.
    assert asked == [(1, 4, 1), (1, 3, 2), (1, 2, 3)]
    assert most[0] == 2
    assert len(rows) == 5 and {r["score"] for r in rows} == {"3"}
    assert json.loads((tmp_path / "out/s0/results.json").read_text())["score"] == 3


def test_auto_with_one_student_left_chooses_nothing(tmp_path) -> None:
    def chooser(wall: float, result: RunResult, at_once: int, left: int) -> int:
        raise AssertionError("not asked")

    rows = run_batch({"only": tmp_path / "only"}, lambda p: _result(2), tmp_path / "out",
                     tmp_path / "book.csv", jobs=chooser)
    assert [r["score"] for r in rows] == ["2"]


@pytest.mark.parametrize("value", ["0", "65", "many"])
def test_cli_rejects_jobs_that_are_not_a_number_or_auto(tmp_path, value) -> None:
    result = CliRunner().invoke(main, ["grade-batch", "x", str(tmp_path), "--jobs", value,
                                       "--csv", str(tmp_path / "b.csv")])
    assert result.exit_code == 2
    assert "--jobs must be a number from 1 to 64 or auto" in result.output
