"""tasks.py installs the same dependencies as pyproject.toml when it uses a system ROS."""

import re
from pathlib import Path

import pytest

import tasks

ROOT = Path(__file__).resolve().parents[2]


def test_non_ros_dependencies_match_pyproject():
    text = (ROOT / "pyproject.toml").read_text()
    block = text.split("dependencies = [", 1)[1].split("]\n", 1)[0]
    declared = set(re.findall(r'^\s*"([^"]+)"', block, re.M))
    ros = {d for d in declared if d.startswith("ros-jazzy-")}
    dev_block = text.split("dev = [", 1)[1].split("]\n", 1)[0]
    dev = set(re.findall(r'^\s*"([^"]+)"', dev_block, re.M))
    assert set(tasks.NON_ROS_DEPENDENCIES) == declared - ros | dev


def test_test_is_the_fast_tier_and_test_all_is_everything():
    """`tasks.py test` leaves out the gradings in the simulator (`slow`); `test-all` runs
    the same, then the slow ones but the machine-wide ones in parallel, then those alone
    (together everything), and is what CI runs."""
    (fast,) = tasks.JOBS["test"]
    first, slow, alone = tasks.JOBS["test-all"]
    assert fast == first
    for command in (fast, slow, alone):
        assert command[:3] == ["python", "-m", "pytest"] and "-k" not in command
    assert fast[fast.index("-m", 3) + 1] == "not slow"
    assert slow[slow.index("-m", 3) + 1] == "slow and not machine_wide" and "-n" in slow
    assert alone[alone.index("-m", 3) + 1] == "machine_wide" and "-n" not in alone
    ci = (ROOT / ".ci" / "run").read_text()
    # The whole suite, then the benchmarks kept with the run (never a test's pass or fail).
    assert re.findall(r"^python3 tasks\.py (\S+)", ci, re.M) == ["test-all", "bench-ci"]
    assert re.search(r"^python3 tasks\.py bench-ci \|\| ", ci, re.M)


def test_make_and_readme_name_only_jobs_of_tasks_py():
    makefile = (ROOT / "Makefile").read_text()
    targets = re.search(r"^\.PHONY: (.*)$", makefile, re.M)[1].split()
    assert set(targets) == set(tasks.JOBS)
    readme = (ROOT / "README.md").read_text()
    opening = readme.split("```sh\n", 1)[1].split("```", 1)[0]
    # The README's test command is the one CI runs (.ci/run), the fast tier named below it.
    assert re.findall(r"^python3 tasks\.py (\S+)", opening, re.M) == ["demo", "test-all"]
    assert "# set up .venv, run the tests" in opening.splitlines()[1]
    for job in re.findall(r"tasks\.py ([\w-]+)", readme):
        assert job in tasks.JOBS, job


def test_dev_only_is_the_dev_extra():
    text = (ROOT / "pyproject.toml").read_text()
    dev_block = text.split("dev = [", 1)[1].split("]\n", 1)[0]
    names = {re.split(r"[<>=\[]", d)[0] for d in re.findall(r'^\s*"([^"]+)"', dev_block, re.M)}
    assert names == set(tasks.DEV_ONLY)


@pytest.mark.parametrize("system_ros", [False, True], ids=["pypi-ros", "system-ros"])
def test_the_demo_installs_no_test_tools_and_says_what_next(monkeypatch, tmp_path, capsys,
                                                            system_ros):
    """The demo, a student's first command, installs the platform without the dev extra
    and ends with the next commands; a test job adds the dev extra once; nothing installs
    twice."""
    venv = tmp_path / "venv"
    (venv / "bin").mkdir(parents=True)
    (venv / "bin" / "python").touch()
    monkeypatch.setattr(tasks, "VENV", venv)
    monkeypatch.setattr(tasks, "BIN", venv / "bin")
    monkeypatch.setattr(tasks, "STAMP", venv / ".installed")
    if system_ros:
        monkeypatch.setenv("ROS_DISTRO", "jazzy")
        monkeypatch.setenv("AMENT_PREFIX_PATH", "/opt/ros/jazzy")
    else:
        monkeypatch.delenv("ROS_DISTRO", raising=False)
    calls: list[list[str]] = []

    class Done:
        returncode = 0

    def run(argv, **_kw):
        calls.append([str(a) for a in argv])
        return Done()

    monkeypatch.setattr(tasks.subprocess, "run", run)
    assert tasks.main(["demo"]) == 0
    installs = [" ".join(c) for c in calls if "install" in c]
    assert installs and not any("[dev]" in c for c in installs)
    assert not any(name in c for c in installs for name in tasks.DEV_ONLY)
    out = capsys.readouterr().out
    assert "[3/3] installing" in out and "MB" in out
    assert f". {venv / 'bin' / 'activate'}" in out and "autograder list" in out
    calls.clear()
    assert tasks.setup("demo") is False and not calls
    assert tasks.setup("test") is True
    assert any(c[-1].endswith("[dev]") for c in calls)
    assert tasks.setup("demo") is False and tasks.setup("test-all") is False
