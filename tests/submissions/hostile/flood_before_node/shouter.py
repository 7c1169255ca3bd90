"""Hostile: writes 64 MB in unbroken lines, half to stdout and half to stderr, then crashes
before it creates its node (the issue's case was 512 MB; 64 MB is far past the budget)."""
from rclpy.node import Node  # noqa: F401 - passes the grader's static node check; no node is made
import sys

MB = 64
chunk = "x" * (1 << 20)  # no newline: one enormous line per stream
print("FLOOD BEGINS", flush=True)
for i in range(MB // 2):
    sys.stdout.write(chunk)
    sys.stderr.write(chunk)
sys.stdout.write("\n")
print("FLOOD ENDS", flush=True)
raise RuntimeError("gave up after the flood")
