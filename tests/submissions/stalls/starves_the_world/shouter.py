"""Hostile: a node that never answers, whose process forks 100 children that spin once
the tests have begun, so the simulated world is starved while the node itself looks idle:
without a cgroup (a container) that stalled every wait, and the grading ended as "the
machine was too busy" (a grader error, graded again) instead of this program's zero.
Graded alone (tests/sandbox/test_shapes.py): beside a classmate it would starve theirs."""
import os
import threading
import time

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


def spin_children():
    time.sleep(0.3)  # the node is up and the tests wait on the world
    for _child in range(100):
        if os.fork() == 0:
            end = time.monotonic() + 600
            while time.monotonic() < end:
                pass
            os._exit(0)


class Shouter(Node):
    def __init__(self):
        super().__init__('shouter')
        self.pub = self.create_publisher(String, 'shout', 10)
        self.create_subscription(String, 'words', self.on_words, 10)

    def on_words(self, msg):
        pass  # never answers


def main(args=None):
    rclpy.init(args=args)
    node = Shouter()
    threading.Thread(target=spin_children, daemon=True).start()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
