"""Hostile: an infinite loop at import; no node is ever created."""
from rclpy.node import Node  # noqa: F401 - passes the grader's static node check; no node is made
while True:
    pass
