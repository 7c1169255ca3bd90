"""Hostile: allocates memory until something stops it."""
from rclpy.node import Node  # noqa: F401 - passes the grader's static node check; no node is made
hoard = []
while True:
    hoard.append(bytearray(64 * 1024 * 1024))
