#!/usr/bin/env python3
"""Set up and run the project's jobs with nothing but Python 3.10+ (make is optional).

    python3 tasks.py demo      # grade the reference solution of parameter_validation
    python3 tasks.py test      # run the tests: the fast tier, under a minute
    python3 tasks.py test-all  # run every test, the gradings in the simulator too (CI)
    python3 tasks.py lint | bench

Arguments after the job go to its command (``python3 tasks.py test -k reporter``).

Each job creates ``.venv`` and installs the project into it first (once; again when
pyproject.toml changes).
"""

from __future__ import annotations

import os
import subprocess
import sys
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
                        "kubernetes-validate>=1.37"]

JOBS = {
    "demo": [["autograder", "grade", "parameter_validation",
              "assignments/parameter_validation/solution"]],
    # The fast tier: everything but the tests marked `slow` (each grades submissions end to
    # end in the simulator), so a change is checked in under a minute.
    "test": [["python", "-m", "pytest", "-m", "not slow", "--durations=10"]],
    # Everything, as CI runs it (14.5 to 16 minutes). The ten slowest steps close the run:
    # where the suite's minutes go, in every CI log.
    "test-all": [["python", "-m", "pytest", "--durations=10"]],
    "lint": [["ruff", "check", "."]],
    "bench": [["python", "benchmarks/bench_grading.py"], ["python", "benchmarks/bench_sim.py"],
              ["python", "benchmarks/bench_peers.py"]],
}


def setup() -> None:
    if sys.version_info < (3, 10):  # noqa: UP036 - tasks.py is run by any python3
        sys.exit(f"Python 3.10 or newer is needed (found {sys.version.split()[0]})")
    pyproject = ROOT / "pyproject.toml"
    if STAMP.exists() and STAMP.stat().st_mtime >= pyproject.stat().st_mtime \
            and STAMP.read_text() == str(ROOT):
        return  # installed, from this checkout, since pyproject.toml last changed
    # With a sourced system ROS 2 Jazzy (/opt/ros/jazzy, e.g. on an arm64 board), use its
    # rclpy and messages instead of the PyPI wheels, which exist for x86_64 only.
    system_ros = os.environ.get("ROS_DISTRO") == "jazzy" and "AMENT_PREFIX_PATH" in os.environ
    if not (BIN / "python").exists():
        print(f"creating {VENV}" + (" (with the system's ROS 2 Jazzy)" if system_ros else ""),
              flush=True)
        try:
            if Path(PYTHON).resolve() == Path(sys.executable).resolve():
                venv.create(VENV, with_pip=True, system_site_packages=system_ros)
            else:
                subprocess.run([PYTHON, "-m", "venv", str(VENV)]
                               + (["--system-site-packages"] if system_ros else []), check=True)
        except subprocess.CalledProcessError:
            sys.exit("Could not create a virtual environment: on Debian or Ubuntu install "
                     "python3-venv first (apt-get install python3-venv).")
    pip = [str(BIN / "python"), "-m", "pip", "install", "--disable-pip-version-check", "-q"]
    subprocess.run([*pip, "--upgrade", "pip"], check=True)
    if system_ros:
        subprocess.run([*pip, *NON_ROS_DEPENDENCIES], check=True)
        subprocess.run([*pip, "--no-deps", "-e", f"{ROOT}[dev]"], check=True)
    else:
        subprocess.run([*pip, "-e", f"{ROOT}[dev]"], check=True)
    STAMP.write_text(str(ROOT))


def main(argv: list[str]) -> int:
    if len(argv) < 1 or argv[0] not in JOBS:
        print(__doc__)
        return 2
    setup()
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}",
               VIRTUAL_ENV=str(VENV))
    for command in JOBS[argv[0]]:
        status = subprocess.run([*command, *argv[1:]], cwd=ROOT, env=env).returncode
        if status != 0:
            return status
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
