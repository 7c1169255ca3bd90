"""Hostile: floods stdout and stderr."""
from rclpy.node import Node  # noqa: F401 - passes the grader's static node check; no node is made
import sys

line = 'spam ' * 200 + '\n'
while True:
    sys.stdout.write(line)
    sys.stderr.write(line)
