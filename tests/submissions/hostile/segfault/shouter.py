"""Hostile: crashes the interpreter with a segmentation fault."""
from rclpy.node import Node  # noqa: F401 - passes the grader's static node check; no node is made
import ctypes

ctypes.string_at(0)
