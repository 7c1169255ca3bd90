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
