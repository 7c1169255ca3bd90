"""Hostile: leaves at once with os._exit(0)."""
from rclpy.node import Node  # noqa: F401 - passes the grader's static node check; no node is made
import os

os._exit(0)
