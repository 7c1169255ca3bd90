"""tasks.py installs the same dependencies as pyproject.toml when it uses a system ROS."""

import re
from pathlib import Path

import tasks

ROOT = Path(__file__).resolve().parent.parent


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
    them too, and is what CI runs."""
    (fast,) = tasks.JOBS["test"]
    (everything,) = tasks.JOBS["test-all"]
    assert fast[:3] == everything[:3] == ["python", "-m", "pytest"]
    assert fast[fast.index("-m", 3) + 1] == "not slow"
    assert "-m" not in everything[3:] and "-k" not in everything
    ci = (ROOT / ".ci" / "run").read_text()
    assert re.findall(r"^python3 tasks\.py (\S+)", ci, re.M) == ["test-all"]


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
