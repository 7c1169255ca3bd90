#!/usr/bin/env python3
"""Set up and run the project's jobs with nothing but Python 3.10+ (make is optional).

    python3 tasks.py setup     # only make .venv and install the platform into it
    python3 tasks.py demo      # grade the reference solution of parameter_validation
    python3 tasks.py test      # the fast tier, no gradings: about a minute on 2 cores
    python3 tasks.py test-all  # run every test, the gradings in the simulator too (CI)
    python3 tasks.py lint | bench | bench-ci

Arguments after the job go to its command (``python3 tasks.py test -k reporter``).

Each job creates ``.venv`` and installs the project into it first (once; again when
pyproject.toml changes): the demo without the test tools, the other jobs with them. The
first run says each step and its size, and ends with the commands to type next.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = Path(os.environ.get("AUTOGRADER_VENV", ROOT / ".venv"))
# The interpreter the venv is made from. Strict isolation runs students as another user,
# who must be able to read it: CI uses Debian's /usr/bin/python3 and a venv in /opt.
PYTHON = os.environ.get("AUTOGRADER_PYTHON", sys.executable)
BIN = VENV / "bin"
STAMP = VENV / ".installed"

# pyproject.toml's dependencies less the ROS wheels (used with a system ROS install).
NON_ROS_DEPENDENCIES = ["pymunk>=6.6", "numpy>=1.24", "jinja2>=3.1", "babel>=2.12",
                        "click>=8.1", "pytest>=7.4", "pyyaml>=6.0", "mcap>=1.1",
                        "mcap-ros2-support>=0.5", "ruff>=0.5", "playwright>=1.40",
                        "kubernetes-validate>=1.37", "mkdocs-material>=9.5",
                        "pytest-xdist>=3.5"]

# Files of the fast tier run in parallel, one worker per core and each file whole on one
# worker (its module fixtures made once); no fast test shares state across files.
FAST = ["python", "-m", "pytest", "-m", "not slow", "-n", "auto", "--dist", "loadfile",
        "--durations=10"]
JOBS = {
    # Only the set-up: what a student release offers (it has no solution to grade).
    "setup": [],
    "demo": [["autograder", "grade", "parameter_validation",
              "assignments/parameter_validation/solution"]],
    # The fast tier: everything but the tests marked `slow` (each grades submissions end to
    # end in the simulator), a test file per core at a time (pytest-xdist).
    "test": [FAST],
    # Everything, as CI runs it: the fast tier as above, then the gradings, a file per core
    # at a time (most of their time is simulation time at an exercise's pace, not CPU),
    # then the sandbox's slow tests alone (they look at the whole machine: every student
    # user's processes, /tmp, the network; tests/conftest.py). The slowest steps close
    # each: where the suite's minutes go, in every CI log.
    "test-all": [FAST,
                 ["python", "-m", "pytest", "-m", "slow and not machine_wide", "-n", "auto",
                  "--dist", "loadfile", "--durations=20"],
                 ["python", "-m", "pytest", "-m", "machine_wide", "--durations=20"]],
    "lint": [["ruff", "check", "."]],
    "bench": [["python", "benchmarks/bench_grading.py"], ["python", "benchmarks/bench_sim.py"],
              ["python", "benchmarks/bench_peers.py"]],
    # CI's figures, printed into its log after the tests (never pass or fail on time): a
    # grading of each exercise and a batch of four at --jobs auto; a minute or two.
    "bench-ci": [["python", "benchmarks/bench_grading.py", "--runs", "1"],
                 ["python", "benchmarks/bench_batch.py", "--students", "4", "--jobs", "auto",
                  "--exercise", "parameter_validation"]],
}


# The dev extra's packages: only the project's own tests and docs use them, so the demo,
# a student's set-up, installs without them (playwright alone is 165 MB).
DEV_ONLY = ("ruff", "playwright", "kubernetes-validate", "mkdocs-material", "pytest-xdist")


def _size_mb(folder: Path) -> int:
    total = 0
    for path, _dirs, files in os.walk(folder):
        for name in files:
            try:
                total += os.lstat(os.path.join(path, name)).st_size
            except OSError:
                pass
    return round(total / 1e6)


def _installed() -> set[str]:
    """What the venv holds from this checkout: {"base"}, {"base", "dev"}, or nothing (no
    venv, another checkout's, or pyproject.toml changed since)."""
    pyproject = ROOT / "pyproject.toml"
    if not STAMP.exists() or STAMP.stat().st_mtime < pyproject.stat().st_mtime:
        return set()
    root, _, extras = STAMP.read_text().partition("\n")
    return {"base", *extras.split()} if root == str(ROOT) else set()


def setup(job: str) -> bool:
    """Make the venv and install what JOB needs; say each step, its size and its time.
    True when it installed something."""
    if sys.version_info < (3, 10):  # noqa: UP036 - tasks.py is run by any python3
        sys.exit(f"Python 3.10 or newer is needed (found {sys.version.split()[0]})")
    dev = job not in ("setup", "demo")
    have = _installed()
    if "base" in have and (not dev or "dev" in have):
        return False  # installed, from this checkout, since pyproject.toml last changed
    started = time.monotonic()
    # With a sourced system ROS 2 Jazzy (/opt/ros/jazzy, e.g. on an arm64 board), use its
    # rclpy and messages instead of the PyPI wheels, which exist for x86_64 only.
    system_ros = os.environ.get("ROS_DISTRO") == "jazzy" and "AMENT_PREFIX_PATH" in os.environ
    what = ("the platform" + ("" if system_ros else " and ROS 2 Jazzy's rclpy")
            + (" and the test tools" if dev else ""))
    size = ("about 330 MB" if not system_ros else "less: rclpy comes from the system") + (
        ", about 350 MB more for the test tools" if dev else "")
    print(f"Setting up {VENV}: {what} from PyPI ({size}; a few minutes the first time).",
          flush=True)
    if not (BIN / "python").exists():
        print(f"[1/3] creating the virtual environment {VENV}"
              + (" (with the system's ROS 2 Jazzy)" if system_ros else ""), flush=True)
        try:
            if Path(PYTHON).resolve() == Path(sys.executable).resolve():
                venv.create(VENV, with_pip=True, system_site_packages=system_ros)
            else:
                subprocess.run([PYTHON, "-m", "venv", str(VENV)]
                               + (["--system-site-packages"] if system_ros else []), check=True)
        except subprocess.CalledProcessError:
            sys.exit("Could not create a virtual environment: on Debian or Ubuntu install "
                     "python3-venv first (apt-get install python3-venv).")
    pip = [str(BIN / "python"), "-m", "pip", "install", "--disable-pip-version-check"]
    # pip's own progress in a terminal; a log (CI, a pipe) gets only the steps.
    quiet = [] if sys.stdout.isatty() else ["-q"]
    print("[2/3] updating pip", flush=True)
    subprocess.run([*pip, "-q", "--upgrade", "pip"], check=True)
    print(f"[3/3] installing {what}", flush=True)
    target = f"{ROOT}[dev]" if dev else str(ROOT)
    if system_ros:
        wanted = [d for d in NON_ROS_DEPENDENCIES if dev or not d.startswith(DEV_ONLY)]
        subprocess.run([*pip, *quiet, *wanted], check=True)
        subprocess.run([*pip, *quiet, "--no-deps", "-e", target], check=True)
    else:
        subprocess.run([*pip, *quiet, "-e", target], check=True)
    STAMP.write_text(str(ROOT) + ("\ndev" if dev else ""))
    minutes, seconds = divmod(round(time.monotonic() - started), 60)
    print(f"Set up in {minutes} min {seconds} s: {VENV} holds {_size_mb(VENV)} MB.", flush=True)
    return True


def next_steps() -> str:
    """What to type after the first set-up: the venv on PATH, then the student's commands."""
    guide = "docs/students/quickstart.md" if (ROOT / "docs").is_dir() else "README.md"
    activate = os.path.relpath(BIN / "activate") if VENV == ROOT / ".venv" else BIN / "activate"
    return (f"\nNext, in this terminal and in every new one, put `autograder` on your PATH:\n"
            f"    . {activate}\n"
            f"then:\n"
            f"    autograder list\n"
            f"    autograder start parameter_validation mywork\n"
            f"    autograder check parameter_validation mywork/velocity_governor.py\n"
            f"The student quickstart: {guide}\n")


def main(argv: list[str]) -> int:
    if len(argv) < 1 or argv[0] not in JOBS:
        print(__doc__)
        return 2
    first = setup(argv[0])
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}",
               VIRTUAL_ENV=str(VENV))
    for command in JOBS[argv[0]]:
        status = subprocess.run([*command, *argv[1:]], cwd=ROOT, env=env).returncode
        if status != 0:
            return status
    if first:
        print(next_steps(), end="", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
