"""Hostile: writes a huge file into its working directory."""
from rclpy.node import Node  # noqa: F401 - passes the grader's static node check; no node is made
chunk = b'x' * (1024 * 1024)
with open('huge.bin', 'wb') as fh:
    while True:
        fh.write(chunk)
